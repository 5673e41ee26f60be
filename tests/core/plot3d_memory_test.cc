// Plot3dParseBytesBound: at least what the parser's grid takes, for real files and for text
// repeats that make a few bytes stand for many values.
#include "core/io/plot3d_memory.h"

#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"

namespace splinegrid {
namespace {

int64_t GridBytes(const MultiBlockGrid& grid) {
  int64_t bytes = 0;
  for (const StructuredBlock& block : grid.blocks) {
    bytes += static_cast<int64_t>(block.coords().size() * sizeof(double) +
                                  block.iblank().size() * sizeof(int));
  }
  return bytes;
}

TEST(Plot3dParseBytesBoundTest, TextRepeatsCountEveryValue) {
  const std::string bytes = "1\n1024 1024 1024\n1073741824*0.5 1073741824*0.5 1073741824*0.5\n";
  EXPECT_GE(Plot3dParseBytesBound(bytes), 3 * (int64_t{8} << 30));
}

TEST(Plot3dParseBytesBoundTest, CoversTheGridOfRealFilesWithoutGrossOvercharge) {
  for (const char* name : {"grids/n0012_113-33.p2dfmt", "grids/rae2822_257x97.fmt"}) {
    const std::string text = ReadFileToString(SharedDataPath(name)).value();
    const MultiBlockGrid grid = ParsePlot3d(text, name).value();
    const int64_t bound = Plot3dParseBytesBound(text);
    EXPECT_GE(bound, GridBytes(grid)) << name;
    EXPECT_LE(bound, 3 * static_cast<int64_t>(text.size())) << name;  // 15-24 bytes a number
    Plot3dFormat format = DefaultPlot3dFormat(grid, Plot3dEncoding::kBinaryLittleEndian);
    format.bytes_per_real = 4;
    const std::string binary = EncodePlot3d(grid, format).value();
    EXPECT_GE(Plot3dParseBytesBound(binary), GridBytes(grid)) << name;
    EXPECT_LE(Plot3dParseBytesBound(binary), 3 * static_cast<int64_t>(binary.size())) << name;
  }
}

}  // namespace
}  // namespace splinegrid
