// splinegrid_report: fits every grid of the shared data set to the QUADFLOW paper's tolerances
// by boundary kind and prints one Markdown table row per grid: the reproducible report of the
// README.
//
//   build/bench/splinegrid_report [DATA_DIR]        (default: ../shared/data of the source tree)
//
// Every grid is read (two-plane CFL3D files as their 2D view), fitted by the kernel's FitGrid
// with the defaults (wall 0.15e-3, interface 2e-3, outer 8e-3 of the detected reference length,
// edge criterion 0.5 inside blocks, cell quality refined locally, folds reported rather than
// refused), and reported: the reference length and where it came from, points, control points
// and their ratio, the largest deviation per boundary kind, whether every tolerance was met, the
// connectivity and the largest gap between matched boundaries at refinement levels 0-2, the
// worst Jacobian and cell-size ratios at levels 0-2 with the count of bad cells and of folded
// sub-cells, the wall curvature extrema, the wall time of the fit, and the units check: the same
// grid scaled to millimetres (x1000) fitted alike, "same" when its control, bad-cell and folded
// counts equal the unscaled fit's (else the counts that differ). A synthetic polar disk (one
// block, its j = 0 edge collapsed to the centre, the rim a wall) follows the shared grids. A
// second table fits each grid again to one tolerance for every point (1e-3 of its reference
// length, as `splinegrid fit --tol`): controls, the largest distance, folded sub-cells and the
// repair's fairing weight. Then
// every airfoil of airfoils/ is fitted from its coordinates (FitAirfoil: 1e-4 chord, faired to
// tolerance): control points, the largest distance, curvature extrema before and after fairing
// and the spurious ones. Exit status 1 if a tolerance is not met or a grid cell folds anywhere
// (in either unit).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <vector>

#include "absl/strings/str_format.h"
#include "absl/strings/str_join.h"
#include "core/fit/airfoil/airfoil_fit.h"
#include "core/fit/grid_fit.h"
#include "core/io/airfoil.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"

namespace splinegrid {
namespace {

std::string Deviation(double d) { return d < 0.0 ? "-" : absl::StrFormat("%.3g", d); }

// The grids of `dir`/grids and `dir`/surfaces, sorted.
std::vector<std::filesystem::path> GridFiles(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  for (const char* sub : {"grids", "surfaces"}) {
    const std::filesystem::path path = dir / sub;
    if (!std::filesystem::is_directory(path)) continue;
    for (const auto& entry : std::filesystem::directory_iterator(path)) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".fmt" || ext == ".p2dfmt" || ext == ".x" || ext == ".xyz") {
        files.push_back(entry.path());
      }
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Fits `grid` by kind to the default tolerances (fractions of the reference length). Folds are
// accepted so that the report counts them; the exit status still fails on them.
absl::StatusOr<GridFit> FitByKinds(const MultiBlockGrid& grid,
                                   const std::vector<FaceKindOverride>& face_kinds) {
  GridFitOptions options;
  options.boundary_tolerances = BoundaryTolerances();
  options.face_kinds = face_kinds;
  options.allow_folds = true;
  return FitGrid(grid, options);
}

// Bad cells and folded sub-cells (levels 0-2) over the blocks of a fit.
struct CellCounts {
  int64_t bad = 0;
  int64_t folded = 0;
};

CellCounts CountCells(const GridFit& fit) {
  CellCounts counts;
  for (const BlockFit& b : fit.blocks) {
    counts.bad += b.quality.num_bad_cells;
    counts.folded += b.quality.folded;
  }
  return counts;
}

// The units column: `grid` scaled to millimetres (x1000) and fitted alike; "same" when its
// control, bad-cell and folded counts and its reference length (x1000) equal `fit`'s, else the
// ones that differ. `ok` is cleared when the millimetre fit fails, misses a tolerance or folds.
std::string MillimetreCheck(MultiBlockGrid grid, const std::vector<FaceKindOverride>& face_kinds,
                            const GridFit& fit, bool& ok) {
  for (StructuredBlock& block : grid.blocks) {
    for (double& x : block.coords()) x *= 1000.0;
  }
  const absl::StatusOr<GridFit> mm = FitByKinds(grid, face_kinds);
  if (!mm.ok()) {
    ok = false;
    return "fit failed: " + std::string(mm.status().message());
  }
  const CellCounts a = CountCells(fit), b = CountCells(*mm);
  ok = ok && mm->report.tolerance_met && b.folded == 0;
  std::vector<std::string> differ;
  auto compare = [&](const char* what, int64_t x, int64_t y) {
    if (x != y) {
      differ.push_back(absl::StrFormat("%s %lld vs %lld", what, static_cast<long long>(x),
                                       static_cast<long long>(y)));
    }
  };
  compare("controls", fit.report.num_control_points, mm->report.num_control_points);
  compare("bad", a.bad, b.bad);
  compare("folded", a.folded, b.folded);
  const double ratio = mm->report.reference.length / fit.report.reference.length;
  if (std::abs(ratio - 1000.0) > 1e-9 * 1000.0) {
    differ.push_back(absl::StrFormat("reference x%.9g", ratio));
  }
  if (!mm->report.tolerance_met) differ.push_back("tolerance missed");
  return differ.empty() ? "same" : absl::StrJoin(differ, ", ");
}

// The one-tolerance fit of `grid` (as `splinegrid fit --tol`): every point within
// kOneTolerance of `reference_length`, folds repaired where they can be (adaptive_engine.h step
// 3b) and counted. Its row of the second table; `ok` is cleared when it misses or folds.
constexpr double kOneTolerance = 1e-3;

std::string OneToleranceRow(const std::string& name, const MultiBlockGrid& grid,
                            double reference_length, bool& ok) {
  GridFitOptions options;
  options.tolerance = kOneTolerance * reference_length;
  options.allow_folds = true;
  const absl::StatusOr<GridFit> fit = FitGrid(grid, options);
  if (!fit.ok()) {
    ok = false;
    return absl::StrFormat("| %s | fit failed: %s |\n", name, fit.status().message());
  }
  const GridFitReport& r = fit->report;
  const int64_t folded = CountCells(*fit).folded;
  ok = ok && r.tolerance_met && folded == 0;
  return absl::StrFormat("| %s | %.3g | %d | %d | %.1f | %.3g | %s | %d | %.3g | %.0f |\n", name,
                         *options.tolerance, r.num_points, r.num_control_points,
                         static_cast<double>(r.num_points) / r.num_control_points, r.max_deviation,
                         r.tolerance_met ? "yes" : "NO", folded, r.fairing_weight,
                         1e3 * r.seconds);
}

// Fits `grid` by kind (and in millimetres) and prints its row named `name`, and adds its row of
// the one-tolerance table to `one_tolerance`; false if either is not met or folds.
bool ReportGrid(const std::string& name, const MultiBlockGrid& grid,
                std::vector<std::string>& one_tolerance,
                const std::vector<FaceKindOverride>& face_kinds = {}) {
  absl::StatusOr<GridFit> fit = FitByKinds(grid, face_kinds);
  if (!fit.ok()) {
    std::printf("| %s | fit failed: %s |\n", name.c_str(),
                std::string(fit.status().message()).c_str());
    return false;
  }
  const GridFitReport& r = fit->report;
  KindDeviation worst;
  double min_ratio = INFINITY, size_ratio = 0.0;
  for (const BlockFit& b : fit->blocks) {
    worst.wall = std::max(worst.wall, b.deviation_by_kind.wall);
    worst.interface = std::max(worst.interface, b.deviation_by_kind.interface);
    worst.outer = std::max(worst.outer, b.deviation_by_kind.outer);
    if (b.quality.cells_checked == 0) continue;
    min_ratio = std::min(min_ratio, b.quality.min_ratio);
    size_ratio = std::max({size_ratio, b.quality.max_ratio, 1.0 / b.quality.min_ratio});
  }
  const CellCounts counts = CountCells(*fit);
  bool ok = r.tolerance_met && counts.folded == 0;
  const std::string mm = MillimetreCheck(grid, face_kinds, *fit, ok);
  std::printf(
      "| %s | %.4g (%s) | %zu | %lld | %lld | %.1f | %s | %s | %s | %s | %d | %.1e | %.2f | %.2f "
      "| %lld | %lld | %lld | %.0f | %s |\n",
      name.c_str(), r.reference.length,
      std::string(ReferenceLengthSourceName(r.reference.source)).c_str(), fit->blocks.size(),
      static_cast<long long>(r.num_points), static_cast<long long>(r.num_control_points),
      static_cast<double>(r.num_points) / r.num_control_points, Deviation(worst.wall).c_str(),
      Deviation(worst.interface).c_str(), Deviation(worst.outer).c_str(),
      r.tolerance_met ? "yes" : "NO", r.num_matches, r.max_gap, min_ratio, size_ratio,
      static_cast<long long>(counts.bad), static_cast<long long>(counts.folded),
      static_cast<long long>(r.wall_curvature.extrema), 1e3 * r.seconds, mm.c_str());
  std::fflush(stdout);
  one_tolerance.push_back(OneToleranceRow(name, grid, r.reference.length, ok));
  return ok;
}

// Reads one file and reports it.
bool ReportGridFile(const std::filesystem::path& file, std::vector<std::string>& one_tolerance) {
  absl::StatusOr<MultiBlockGrid> read = ReadPlot3dFile(file.string());
  if (!read.ok()) {
    std::printf("| %s | read failed: %s |\n", file.filename().c_str(),
                std::string(read.status().message()).c_str());
    return false;
  }
  MultiBlockGrid grid = *std::move(read);
  if (IsTwoPlaneGrid(grid)) grid = PlanarView(grid).value();
  return ReportGrid(file.filename().string(), grid, one_tolerance);
}

// The collapsed-edge case (poles.h), as tests/core/collapsed_edges_test.cc builds it: a polar
// disk of one block of 65 x 17 points, i counter-clockwise with the periodic seam i = 0 ~ i = max,
// j outwards from the centre (0.3, -0.2) (j = 0: every point at the centre) with a radius
// clustered towards a wobbly rim; the rim is a wall.
bool ReportPolarDisk(std::vector<std::string>& one_tolerance) {
  constexpr int ni = 65, nj = 17;
  StructuredBlock block({ni, nj, 1}, 2);
  for (int j = 0; j < nj; ++j) {
    const double s = static_cast<double>(j) / (nj - 1);
    const double r = (std::exp(2.0 * s) - 1.0) / (std::exp(2.0) - 1.0);
    for (int i = 0; i < ni; ++i) {
      const double t = 2.0 * std::numbers::pi * (i % (ni - 1)) / (ni - 1);
      double* p = block.Point(i, j, 0);
      p[0] = 0.3 + r * std::cos(t) * (1.0 + 0.1 * r * std::sin(2.0 * t));
      p[1] = -0.2 + r * std::sin(t) * (1.0 + 0.05 * std::cos(3.0 * t));
    }
  }
  MultiBlockGrid grid;
  grid.blocks.push_back(std::move(block));
  return ReportGrid("polar disk 65x17 (synthetic)", grid, one_tolerance,
                    {{{.block = 0, .normal = 1, .upper = true}, BoundaryKind::kWall}});
}

// Fits one airfoil file (FitAirfoil defaults: 1e-4 chord, faired to tolerance) and prints its
// row; false if the tolerance is missed.
bool ReportAirfoil(const std::filesystem::path& file) {
  const auto start = std::chrono::steady_clock::now();
  absl::StatusOr<AirfoilCoordinates> read = ReadAirfoilFile(file.string());
  if (!read.ok()) {
    std::printf("| %s | read failed: %s |\n", file.filename().c_str(),
                std::string(read.status().message()).c_str());
    return false;
  }
  absl::StatusOr<AirfoilFit> fit = FitAirfoil(read->points, AirfoilFitOptions());
  if (!fit.ok()) {
    std::printf("| %s | fit failed: %s |\n", file.filename().c_str(),
                std::string(fit.status().message()).c_str());
    return false;
  }
  const double ms =
      1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("| %s | %lld | %s | %d | %.2e | %s | %lld -> %lld | %lld | %.3g | %.0f |\n",
              file.filename().c_str(), static_cast<long long>(read->points.num_points()),
              fit->sharp_trailing_edge ? "sharp" : "blunt", fit->num_control_points,
              fit->max_deviation, fit->met ? "yes" : "NO",
              static_cast<long long>(fit->unfaired_curvature.total.extrema),
              static_cast<long long>(fit->curvature.total.extrema),
              static_cast<long long>(fit->curvature.spurious()), fit->fairing_weight, ms);
  std::fflush(stdout);
  return fit->met;
}

// The airfoil files of `dir`/airfoils, sorted.
std::vector<std::filesystem::path> AirfoilFiles(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  if (!std::filesystem::is_directory(dir / "airfoils")) return files;
  for (const auto& entry : std::filesystem::directory_iterator(dir / "airfoils")) {
    if (entry.path().extension() == ".dat") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

int Run(int argc, char** argv) {
  const std::filesystem::path dir =
      argc > 1 ? std::filesystem::path(argv[1])
               : std::filesystem::path(SPLINEGRID_SOURCE_DIR) / ".." / "shared" / "data";
  const auto start = std::chrono::steady_clock::now();
  std::printf(
      "| grid | reference length | blocks | points | controls | ratio | wall dev | interface dev | "
      "outer dev | met | matches | max gap | min Jacobian ratio | max size ratio | bad cells | "
      "folded | wall curvature extrema | ms | mm |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|"
      ":-:|---:|---:|---:|---:|---:|---:|---:|---:|:-:|\n");
  bool ok = true;
  std::vector<std::string> one_tolerance;
  for (const std::filesystem::path& file : GridFiles(dir)) {
    ok = ReportGridFile(file, one_tolerance) && ok;
  }
  ok = ReportPolarDisk(one_tolerance) && ok;
  std::printf(
      "\n| grid, one tolerance | tolerance | points | controls | ratio | max dev | met | folded | "
      "fairing weight | ms |\n|---|---:|---:|---:|---:|---:|:-:|---:|---:|---:|\n");
  for (const std::string& row : one_tolerance) std::fputs(row.c_str(), stdout);
  std::printf(
      "\n| airfoil | points | trailing edge | controls | max distance | within 1e-4 | curvature "
      "extrema unfaired -> faired | spurious | fairing weight | ms |\n"
      "|---|---:|:-:|---:|---:|:-:|---:|---:|---:|---:|\n");
  // Spurious extrema are reported, not failed: the SC(2)-0714 file is rounded to 4 decimals,
  // noise the fit follows at 1e-4.
  for (const std::filesystem::path& file : AirfoilFiles(dir)) ok = ReportAirfoil(file) && ok;
  std::printf("\ntotal %.1f s\n",
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return ok ? 0 : 1;
}

}  // namespace
}  // namespace splinegrid

int main(int argc, char** argv) { return splinegrid::Run(argc, argv); }
