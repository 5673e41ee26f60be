// Shared helpers of the CGNS tests: temporary directories, Debian's cgns-convert tools, grids
// with boundary conditions.
#ifndef SPLINEGRID_TESTS_CGNS_CGNS_TEST_UTIL_H_
#define SPLINEGRID_TESTS_CGNS_CGNS_TEST_UTIL_H_

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "absl/strings/str_cat.h"
#include "core/grid/connectivity.h"
#include "core/grid/source_boundaries.h"
#include "core/io/plot3d.h"
#include "gtest/gtest.h"

namespace splinegrid::testing {

// A fresh directory under the system temp dir, removed by the destructor.
class TempDir {
 public:
  explicit TempDir(const std::string& tag)
      : path_(std::filesystem::temp_directory_path() /
              absl::StrCat("splinegrid-", tag, "-", getpid(), "-", counter_++)) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

// Runs Debian's plot3d_to_cgns (cgns-convert) on an ASCII Plot3D file; `flags` e.g. "-d".
inline void Plot3dToCgns(const std::string& plot3d, const std::string& cgns,
                         const std::string& flags) {
  const std::string command =
      absl::StrCat("plot3d_to_cgns -f ", flags, " '", plot3d, "' '", cgns, "' > /dev/null 2>&1");
  ASSERT_EQ(std::system(command.c_str()), 0) << command;
}

// What Debian's checker of the standard (cgns-convert's cgnscheck) says of the file at `path`,
// standard output and error together.
inline std::string CgnsCheckReport(const std::string& path) {
  const std::string command = absl::StrCat("cgnscheck '", path, "' 2>&1");
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return "cannot run " + command;
  std::string report;
  char line[512];
  while (fgets(line, sizeof(line), pipe) != nullptr) report += line;
  pclose(pipe);
  return report;
}

// Largest coordinate difference of two grids of equal shapes (infinity when shapes differ).
inline double MaxDifference(const MultiBlockGrid& a, const MultiBlockGrid& b) {
  if (a.blocks.size() != b.blocks.size()) return INFINITY;
  double worst = 0.0;
  for (size_t q = 0; q < a.blocks.size(); ++q) {
    if (a.blocks[q].extents() != b.blocks[q].extents() ||
        a.blocks[q].spatial_dim() != b.blocks[q].spatial_dim()) {
      return INFINITY;
    }
    for (size_t v = 0; v < a.blocks[q].coords().size(); ++v) {
      worst = std::max(worst, std::abs(a.blocks[q].coords()[v] - b.blocks[q].coords()[v]));
    }
  }
  return worst;
}

// The boundary conditions of the NACA 0012 C-grid (113 x 33, one block): the airfoil between
// the two sides of the wake cut is a wall given through family "airfoil" (BCWallViscous), the
// far field (j=max) BCFarfield, the outflow planes (i=0, i=max) family "exit" (BCOutflow).
inline std::vector<SourceBoundary> CGridConditions(const MultiBlockGrid& grid,
                                                   const Connectivity& connectivity) {
  const Extents e = grid.blocks[0].extents();
  // The wake cut: block 0 j=0 matched with itself, i[0..w] ~ i[ni-1-w..ni-1].
  int wake_end = 0;
  for (const BoundaryMatch& m : connectivity.matches) {
    if (m.a.face.normal == 1 && !m.a.face.upper) wake_end = std::max(wake_end, m.a.end[0]);
  }
  std::vector<SourceBoundary> conditions;
  auto add = [&](Face face, Extents begin, Extents end, BoundaryKind kind, std::string name,
                 std::string type, std::string family) {
    conditions.push_back({FaceRange{face, begin, end}, kind, name, type, family});
  };
  add({0, 1, false}, {wake_end, 0, 0}, {e[0] - 1 - wake_end, 0, 0}, BoundaryKind::kWall, "wall",
      "BCWallViscous", "airfoil");
  add({0, 1, true}, {0, e[1] - 1, 0}, {e[0] - 1, e[1] - 1, 0}, BoundaryKind::kOuter, "far",
      "BCFarfield", "");
  add({0, 0, false}, {0, 0, 0}, {0, e[1] - 1, 0}, BoundaryKind::kOuter, "exit-low", "BCOutflow",
      "exit");
  add({0, 0, true}, {e[0] - 1, 0, 0}, {e[0] - 1, e[1] - 1, 0}, BoundaryKind::kOuter, "exit-up",
      "BCOutflow", "exit");
  return conditions;
}

// Two 3D blocks of 9 x 7 x 5 points sharing the face x = 1: block 0 on [0, 1] x [0, 1] x
// [0, 0.5], block 1 on [1, 2] x ... stored with j and k swapped (its j runs along z), so the
// connection's transform is not the identity.
inline MultiBlockGrid TwoBoxes() {
  MultiBlockGrid grid;
  const int ni = 9, nj = 7, nk = 5;
  StructuredBlock a({ni, nj, nk}, 3), b({ni, nk, nj}, 3);
  for (int k = 0; k < nk; ++k) {
    for (int j = 0; j < nj; ++j) {
      for (int i = 0; i < ni; ++i) {
        // Clustered towards x = 0 (a wall) in block 0.
        const double s = static_cast<double>(i) / (ni - 1);
        double* p = a.Point(i, j, k);
        p[0] = s * s;
        p[1] = static_cast<double>(j) / (nj - 1);
        p[2] = 0.5 * k / (nk - 1);
        double* q = b.Point(i, k, j);
        q[0] = 1.0 + s;
        q[1] = p[1];
        q[2] = p[2];
      }
    }
  }
  grid.blocks.push_back(std::move(a));
  grid.blocks.push_back(std::move(b));
  return grid;
}

}  // namespace splinegrid::testing

#endif  // SPLINEGRID_TESTS_CGNS_CGNS_TEST_UTIL_H_
