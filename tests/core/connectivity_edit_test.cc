// Connectivities derived by index arithmetic (connectivity_edit.h) against FindConnectivity on
// the grid they describe: a volume marched off the shared six-block sphere, one of whose blocks
// is turned back to front so that its volume is stored with i reversed; the same point pairs
// either way. CheckConnectivity refuses a match that does not hold.
#include "core/grid/connectivity_edit.h"

#include <algorithm>
#include <set>
#include <utility>

#include "core/generate/surface_offset.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// Every pair of coinciding points a connectivity states, as (block, point index) pairs in a
// canonical order.
std::set<std::pair<std::pair<int, int64_t>, std::pair<int, int64_t>>> PointPairs(
    const MultiBlockGrid& grid, const Connectivity& connectivity) {
  std::set<std::pair<std::pair<int, int64_t>, std::pair<int, int64_t>>> pairs;
  for (const BoundaryMatch& m : connectivity.matches) {
    const StructuredBlock& a = grid.blocks[m.a.face.block];
    const StructuredBlock& b = grid.blocks[m.b.face.block];
    for (int k = m.a.begin[2]; k <= m.a.end[2]; ++k) {
      for (int j = m.a.begin[1]; j <= m.a.end[1]; ++j) {
        for (int i = m.a.begin[0]; i <= m.a.end[0]; ++i) {
          const Extents y = m.MapToB({i, j, k});
          std::pair<int, int64_t> p{m.a.face.block, a.Index(i, j, k)};
          std::pair<int, int64_t> q{m.b.face.block, b.Index(y[0], y[1], y[2])};
          if (q < p) std::swap(p, q);
          pairs.insert({p, q});
        }
      }
    }
  }
  return pairs;
}

StructuredBlock ReversedI(const StructuredBlock& block) {
  StructuredBlock out = block;
  const int ni = block.extent(0);
  for (int k = 0; k < block.extent(2); ++k) {
    for (int j = 0; j < block.extent(1); ++j) {
      for (int i = 0; i < ni; ++i) {
        const double* x = block.Point(ni - 1 - i, j, k);
        std::copy(x, x + 3, out.Point(i, j, k));
      }
    }
  }
  return out;
}

TEST(ConnectivityEditTest, ExtrudedAndReversedMatchesAreTheOnesFoundAgain) {
  absl::StatusOr<MultiBlockGrid> sphere =
      ReadPlot3dFile(SharedDataPath("surfaces/even_sphere.fmt"));
  ASSERT_TRUE(sphere.ok()) << sphere.status();
  sphere->blocks[2] = ReversedI(sphere->blocks[2]);
  const absl::StatusOr<Connectivity> surface = FindConnectivity(*sphere);
  ASSERT_TRUE(surface.ok());
  SurfaceOffsetOptions options;
  options.layers = 6;
  options.first_height = 0.05;
  options.distance = 0.6;
  options.outward = true;
  absl::StatusOr<SurfaceOffsetGrid> marched = OffsetSurfaceGrid(*sphere, *surface, options);
  ASSERT_TRUE(marched.ok()) << marched.status();
  Connectivity derived = Extruded(*surface, options.layers);
  MultiBlockGrid volume;
  int reversed = 0;
  for (size_t b = 0; b < marched->blocks.size(); ++b) {
    StructuredBlock block = marched->blocks[b];
    if (marched->sides[b] < 0) {
      block = ReversedI(block);
      ReverseBlockDirection(derived, static_cast<int>(b), 0, block.extents());
      ++reversed;
    }
    volume.blocks.push_back(std::move(block));
  }
  EXPECT_GE(reversed, 1);
  const absl::StatusOr<Connectivity> found = FindConnectivity(volume);
  ASSERT_TRUE(found.ok()) << found.status();
  EXPECT_EQ(derived.matches.size(), found->matches.size());
  EXPECT_EQ(PointPairs(volume, derived), PointPairs(volume, *found));
  EXPECT_TRUE(CheckConnectivity(volume, derived, 0.0).ok());

  // A match shifted by one point along its edge no longer holds.
  Connectivity wrong = derived;
  BoundaryMatch& m = wrong.matches[0];
  const int along = m.a.face.normal == 0 ? 1 : 0;
  m.a.begin[along] += 1;
  const absl::Status status = CheckConnectivity(volume, wrong, 1e-9);
  EXPECT_EQ(status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(status.message(), HasSubstr("apart at"));
}

}  // namespace
}  // namespace splinegrid
