// Grids and comparisons shared by the core/io tests.
#ifndef SPLINEGRID_TESTS_CORE_IO_TEST_UTIL_H_
#define SPLINEGRID_TESTS_CORE_IO_TEST_UTIL_H_

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/grid/structured_grid.h"
#include "gtest/gtest.h"

namespace splinegrid {

// The message of `status` as a std::string (for HasSubstr).
inline std::string MessageOf(const absl::Status& status) { return std::string(status.message()); }

// A double that exercises formatting: random sign, 53-bit mantissa and exponent in [-300, 300],
// with every 7th value one of the awkward cases (-0, denormals, extremes, 0.1, integers).
inline double AwkwardDouble(std::mt19937_64& rng) {
  static const double kSpecial[] = {
      -0.0, 5e-324, -2.2250738585072014e-308, DBL_MAX, 0.1, 1.0 / 3, 2.0, -123456789.0, 1e16, 1e-5,
      4.35, 0.0};
  const uint64_t bits = rng();
  if (bits % 7 == 0) return kSpecial[(bits >> 8) % (sizeof(kSpecial) / sizeof(kSpecial[0]))];
  const double mantissa = static_cast<double>(rng() >> 11) / 9007199254740992.0;  // [0, 1)
  const int exponent = static_cast<int>((bits >> 16) % 601) - 300;
  return ((bits >> 40) & 1 ? -1.0 : 1.0) * std::ldexp(0.5 + mantissa / 2, exponent);
}

// A grid of `num_blocks` blocks with `spatial_dim` coordinates, extents varying per block
// (3D blocks have nk > 1 except the last), awkward coordinate values, and iblank when asked.
inline MultiBlockGrid MakeAwkwardGrid(int spatial_dim, int num_blocks, bool with_iblank,
                                      uint64_t seed = 42) {
  std::mt19937_64 rng(seed);
  MultiBlockGrid grid;
  for (int b = 0; b < num_blocks; ++b) {
    const Extents extents = {3 + b, 2 + (b % 2), spatial_dim == 3 && b + 1 < num_blocks ? 2 : 1};
    StructuredBlock block(extents, spatial_dim);
    for (double& c : block.coords()) c = AwkwardDouble(rng);
    if (with_iblank) {
      for (int64_t p = 0; p < block.num_points(); ++p) {
        block.iblank().push_back(static_cast<int>(p % 3) - 1 - 100 * (p % 5 == 4));
      }
    }
    grid.blocks.push_back(std::move(block));
  }
  return grid;
}

// A smooth grid (a sheared box) with values that print briefly, for text fixtures.
inline MultiBlockGrid MakeSimpleGrid(int spatial_dim, const std::vector<Extents>& extents,
                                     bool with_iblank = false) {
  MultiBlockGrid grid;
  for (size_t b = 0; b < extents.size(); ++b) {
    StructuredBlock block(extents[b], spatial_dim);
    for (int k = 0; k < extents[b][2]; ++k) {
      for (int j = 0; j < extents[b][1]; ++j) {
        for (int i = 0; i < extents[b][0]; ++i) {
          double* p = block.Point(i, j, k);
          p[0] = 0.5 * i + 0.25 * j + static_cast<double>(b);
          p[1] = 0.125 * j - 0.5;
          if (spatial_dim == 3) p[2] = 0.75 * k + 0.0625 * i;
          if (with_iblank) block.iblank().push_back((i + j + k) % 2);
        }
      }
    }
    grid.blocks.push_back(std::move(block));
  }
  return grid;
}

// Expects `actual` to equal `expected` bit for bit: extents, spatial_dim, coordinates, iblank.
inline void ExpectBitIdentical(const MultiBlockGrid& expected, const MultiBlockGrid& actual) {
  ASSERT_EQ(expected.blocks.size(), actual.blocks.size());
  for (size_t b = 0; b < expected.blocks.size(); ++b) {
    SCOPED_TRACE(testing::Message() << "block " << b);
    const StructuredBlock& e = expected.blocks[b];
    const StructuredBlock& a = actual.blocks[b];
    ASSERT_EQ(e.extents(), a.extents());
    ASSERT_EQ(e.spatial_dim(), a.spatial_dim());
    ASSERT_EQ(e.coords().size(), a.coords().size());
    for (size_t c = 0; c < e.coords().size(); ++c) {
      ASSERT_EQ(std::bit_cast<uint64_t>(e.coords()[c]), std::bit_cast<uint64_t>(a.coords()[c]))
          << "coordinate " << c << ": expected " << e.coords()[c] << ", got " << a.coords()[c];
    }
    EXPECT_EQ(e.iblank(), a.iblank());
  }
}

}  // namespace splinegrid

#endif  // SPLINEGRID_TESTS_CORE_IO_TEST_UTIL_H_
