#include "io/cgns/cgns_file.h"

#include <cgnslib.h>

#include <algorithm>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "io/cgns/cgns_io.h"

namespace splinegrid {

absl::StatusOr<CgnsFile> CgnsFile::Open(const std::string& path, int mode) {
  int fn = -1;
  if (cg_open(path.c_str(), mode, &fn) != CG_OK) {
    const std::string error = cg_get_error();
    if (mode == CG_MODE_READ) {
      // libcgns's own words for a file of another kind are about ADF internals ("Memory
      // boundary tag bad"): say first whether the file is CGNS at all.
      std::string start(8192 + 8, '\0');  // LooksLikeCgns tries offsets up to 8192
      std::ifstream file(path, std::ios::binary);
      file.read(start.data(), static_cast<std::streamsize>(start.size()));
      start.resize(static_cast<size_t>(std::max<std::streamsize>(file.gcount(), 0)));
      if (file.is_open() && !LooksLikeCgns(start)) {
        return absl::InvalidArgumentError(
            absl::StrCat(path,
                         ": not a CGNS file: it starts with neither the HDF5 signature nor an ADF "
                         "header"));
      }
    }
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a readable CGNS file (", error, ")"));
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
