// An open CGNS file (cg_open/cg_close) with the library's error text in statuses.
#ifndef SPLINEGRID_IO_CGNS_CGNS_FILE_H_
#define SPLINEGRID_IO_CGNS_CGNS_FILE_H_

#include <string>

#include "absl/status/statusor.h"

namespace splinegrid {

class CgnsFile {
 public:
  // cg_open(path, mode); INVALID_ARGUMENT with the library's message when the file cannot be
  // opened as CGNS (read) or NOT_FOUND/PERMISSION errors are reported alike.
  static absl::StatusOr<CgnsFile> Open(const std::string& path, int mode);

  CgnsFile(CgnsFile&& other) noexcept : fn_(other.fn_), path_(std::move(other.path_)) {
    other.fn_ = -1;
  }
  CgnsFile& operator=(CgnsFile&&) = delete;
  CgnsFile(const CgnsFile&) = delete;
  ~CgnsFile();

  int fn() const { return fn_; }

  // OK for CG_OK; else INVALID_ARGUMENT "<path>: <doing>: <cg_get_error()>".
  absl::Status Check(int result, const std::string& doing) const;

  // cg_close; for writers the file is complete only when this is OK.
  absl::Status Close();

 private:
  CgnsFile(int fn, std::string path) : fn_(fn), path_(std::move(path)) {}

  int fn_ = -1;
  std::string path_;
};

}  // namespace splinegrid

#endif  // SPLINEGRID_IO_CGNS_CGNS_FILE_H_
