#include "io/cgns/cgns_file.h"

#include <cgnslib.h>

#include "absl/strings/str_cat.h"

namespace splinegrid {

absl::StatusOr<CgnsFile> CgnsFile::Open(const std::string& path, int mode) {
  int fn = -1;
  if (cg_open(path.c_str(), mode, &fn) != CG_OK) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a readable CGNS file (", cg_get_error(), ")"));
  }
  return CgnsFile(fn, path);
}

CgnsFile::~CgnsFile() {
  if (fn_ >= 0) cg_close(fn_);
}

absl::Status CgnsFile::Check(int result, const std::string& doing) const {
  if (result == CG_OK) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat(path_, ": ", doing, ": ", cg_get_error()));
}

absl::Status CgnsFile::Close() {
  if (fn_ < 0) return absl::OkStatus();
  const int result = cg_close(fn_);
  fn_ = -1;
  return Check(result, "closing the file");
}

}  // namespace splinegrid
