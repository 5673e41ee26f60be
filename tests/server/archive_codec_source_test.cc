// The archive's source points: ForEachSourceChunk and SourceAssembler round trips, memory that
// follows the data, chunks out of order or damaged, and the format version.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "proto/convert/archive_convert.h"
#include "proto/convert/convert.h"
#include "tests/core/io_test_util.h"
#include "tests/server/service_fixture.h"

namespace splinegrid {
namespace {

using ::splinegrid::testing::StatusIs;
constexpr auto kInvalid = absl::StatusCode::kInvalidArgument;

v1::ArchiveHeader HeaderOf(const MultiBlockGrid& grid) {
  v1::ArchiveHeader header;
  header.set_format_version(kArchiveFormatVersion);
  header.set_spatial_dim(grid.blocks[0].spatial_dim());
  header.set_source_iblank(!grid.blocks[0].iblank().empty());
  for (const StructuredBlock& block : grid.blocks) {
    EncodeExtents(block.extents(), header.add_source_blocks());
  }
  return header;
}

std::vector<v1::SourceChunk> ChunksOf(const MultiBlockGrid& grid, int64_t max_values) {
  std::vector<v1::SourceChunk> chunks;
  EXPECT_TRUE(ForEachSourceChunk(grid, max_values, [&](const v1::SourceChunk& chunk) {
                chunks.push_back(chunk);
                return absl::OkStatus();
              }).ok());
  return chunks;
}

TEST(ArchiveCodecSourceTest, MultiBlockGridWithIblankRoundTripsBitwise) {
  for (int dim : {2, 3}) {
    const MultiBlockGrid grid = MakeAwkwardGrid(dim, 4, /*with_iblank=*/true);
    const std::vector<v1::SourceChunk> chunks = ChunksOf(grid, 7);
    int64_t values = 0;
    for (const v1::SourceChunk& chunk : chunks) {
      EXPECT_LE(chunk.coords_size() + chunk.iblank_size(), 7);
      EXPECT_TRUE(chunk.coords_size() == 0 || chunk.iblank_size() == 0);
      values += chunk.coords_size() + chunk.iblank_size();
    }
    int64_t expected = 0;
    for (const StructuredBlock& block : grid.blocks) expected += (dim + 1) * block.num_points();
    EXPECT_EQ(values, expected);

    absl::StatusOr<SourceAssembler> assembler = SourceAssembler::Create(HeaderOf(grid));
    ASSERT_TRUE(assembler.ok()) << assembler.status();
    for (const v1::SourceChunk& chunk : chunks) {
      EXPECT_FALSE(assembler->complete());
      ASSERT_TRUE(assembler->Add(chunk).ok()) << assembler->Add(chunk);
    }
    EXPECT_TRUE(assembler->complete());
    EXPECT_EQ(
        assembler->bytes(), expected * 8 - [&] {
          int64_t iblank = 0;  // iblank values take 4 bytes, not 8
          for (const StructuredBlock& block : grid.blocks) iblank += 4 * block.num_points();
          return iblank;
        }());
    absl::StatusOr<MultiBlockGrid> read = std::move(*assembler).Finish();
    ASSERT_TRUE(read.ok()) << read.status();
    ASSERT_EQ(read->blocks.size(), grid.blocks.size());
    for (size_t b = 0; b < grid.blocks.size(); ++b) {
      const StructuredBlock &x = grid.blocks[b], &y = read->blocks[b];
      EXPECT_EQ(x.extents(), y.extents());
      EXPECT_EQ(x.spatial_dim(), y.spatial_dim());
      ASSERT_EQ(x.coords().size(), y.coords().size());
      EXPECT_EQ(std::memcmp(x.coords().data(), y.coords().data(), x.coords().size() * 8), 0);
      EXPECT_EQ(x.iblank(), y.iblank());
    }
  }
}

TEST(ArchiveCodecSourceTest, GridWithoutIblankRoundTrips) {
  const MultiBlockGrid grid = MakeAwkwardGrid(3, 2, /*with_iblank=*/false);
  SourceAssembler assembler = SourceAssembler::Create(HeaderOf(grid)).value();
  for (const v1::SourceChunk& chunk : ChunksOf(grid, 1 << 17))
    ASSERT_TRUE(assembler.Add(chunk).ok());
  const MultiBlockGrid read = std::move(assembler).Finish().value();
  EXPECT_TRUE(read.blocks[1].iblank().empty());
  EXPECT_EQ(std::memcmp(read.blocks[1].coords().data(), grid.blocks[1].coords().data(),
                        grid.blocks[1].coords().size() * 8),
            0);
}

// 4096 x 4096 x 5 points (2 GB of coordinates) announced: nothing is allocated for them; memory
// follows the chunks that actually come.
TEST(ArchiveCodecSourceTest, HugeAnnouncedGridAllocatesOnlyWhatArrives) {
  v1::ArchiveHeader header;
  header.set_format_version(1);
  header.set_spatial_dim(3);
  v1::Extents* extents = header.add_source_blocks();
  extents->set_i(4096);
  extents->set_j(4096);
  extents->set_k(5);
  absl::StatusOr<SourceAssembler> assembler = SourceAssembler::Create(header);
  ASSERT_TRUE(assembler.ok()) << assembler.status();
  EXPECT_EQ(assembler->bytes(), 0);
  v1::SourceChunk chunk;
  for (int c = 0; c < 1000; ++c) chunk.add_coords(c);
  ASSERT_TRUE(assembler->Add(chunk).ok());
  EXPECT_LE(assembler->bytes(), 1000 * 8);
  EXPECT_FALSE(assembler->complete());
  EXPECT_THAT(std::move(*assembler).Finish().status(),
              StatusIs(kInvalid, "block 0 of 1 has 1000 of 251658240 coordinates"));

  extents->set_i((1 << 24) + 1);  // beyond ValidateExtents
  EXPECT_THAT(SourceAssembler::Create(header).status(),
              StatusIs(kInvalid, "header.source_blocks[0]: ni = 16777217"));
  extents->set_i(-3);
  EXPECT_THAT(SourceAssembler::Create(header).status(),
              StatusIs(kInvalid, "header.source_blocks[0]: ni = -3"));
  extents->set_i(1 << 20);  // each extent fine, the product 2^42 is not
  extents->set_j(1 << 20);
  EXPECT_THAT(SourceAssembler::Create(header).status(), StatusIs(kInvalid, "exceeds the limit"));
}

TEST(ArchiveCodecSourceTest, BadChunksAreRefused) {
  const MultiBlockGrid grid = MakeAwkwardGrid(2, 2, /*with_iblank=*/true);
  const v1::ArchiveHeader header = HeaderOf(grid);
  const std::vector<v1::SourceChunk> chunks = ChunksOf(grid, 4);
  ASSERT_GE(chunks.size(), 4u);
  auto fresh = [&] { return SourceAssembler::Create(header).value(); };
  {  // out of order: the second chunk first
    SourceAssembler a = fresh();
    EXPECT_THAT(a.Add(chunks[1]), StatusIs(kInvalid,
                                           "source chunk for block 0 at 4: out of order "
                                           "or overlapping; the next coordinate is 0"));
  }
  {  // overlapping: the first chunk twice
    SourceAssembler a = fresh();
    ASSERT_TRUE(a.Add(chunks[0]).ok());
    EXPECT_THAT(a.Add(chunks[0]), StatusIs(kInvalid, "out of order or overlapping"));
  }
  {  // a chunk of block 1 while block 0 is incomplete
    SourceAssembler a = fresh();
    v1::SourceChunk wrong = chunks[0];
    wrong.set_block(1);
    EXPECT_THAT(a.Add(wrong), StatusIs(kInvalid, "source chunk for block 1 while block 0"));
  }
  {  // more values than the block has
    SourceAssembler a = fresh();
    v1::SourceChunk big;
    for (int c = 0; c < 2 * grid.blocks[0].num_points() + 1; ++c) big.add_coords(0.5);
    EXPECT_THAT(a.Add(big), StatusIs(kInvalid, "coordinates, but the block has 12 left of 12"));
  }
  {  // non-finite coordinate, named by point
    SourceAssembler a = fresh();
    v1::SourceChunk nan = chunks[0];
    nan.set_coords(3, std::numeric_limits<double>::infinity());
    EXPECT_THAT(a.Add(nan), StatusIs(kInvalid, "point (1, 0, 0) coordinate y is inf"));
  }
  {  // iblank before the coordinates are complete; both or neither of coords and iblank
    SourceAssembler a = fresh();
    v1::SourceChunk flags;
    flags.add_iblank(1);
    EXPECT_THAT(a.Add(flags), StatusIs(kInvalid, "before the block's coordinates are complete"));
    flags.add_coords(0.0);
    EXPECT_THAT(a.Add(flags), StatusIs(kInvalid, "both coords and iblank"));
    EXPECT_THAT(a.Add(v1::SourceChunk()), StatusIs(kInvalid, "neither coords nor iblank"));
  }
  {  // iblank that the header did not announce; a chunk after the last block
    v1::ArchiveHeader plain = header;
    plain.set_source_iblank(false);
    SourceAssembler a = SourceAssembler::Create(plain).value();
    for (size_t c = 0; chunks[c].coords_size() > 0; ++c) ASSERT_TRUE(a.Add(chunks[c]).ok());
    v1::SourceChunk flags;  // block 0 is complete without iblank: block 1 is next
    flags.set_block(1);
    flags.add_iblank(1);
    EXPECT_THAT(a.Add(flags), StatusIs(kInvalid, "but header.source_iblank is false"));
  }
  {
    SourceAssembler a = fresh();
    for (const v1::SourceChunk& chunk : chunks) ASSERT_TRUE(a.Add(chunk).ok());
    EXPECT_THAT(a.Add(chunks.back()), StatusIs(kInvalid, "after every block is complete"));
  }
  {  // truncated: Finish names the block
    SourceAssembler a = fresh();
    for (size_t c = 0; c + 1 < chunks.size(); ++c) ASSERT_TRUE(a.Add(chunks[c]).ok());
    EXPECT_THAT(std::move(a).Finish().status(),
                StatusIs(kInvalid, "source points incomplete: block 1 of 2"));
  }
}

TEST(ArchiveCodecSourceTest, HeaderIsValidated) {
  v1::ArchiveHeader header = HeaderOf(MakeAwkwardGrid(2, 1, false));
  header.set_spatial_dim(4);
  EXPECT_THAT(SourceAssembler::Create(header).status(),
              StatusIs(kInvalid, "header.spatial_dim = 4"));
  header.set_spatial_dim(2);
  header.clear_source_blocks();
  EXPECT_THAT(SourceAssembler::Create(header).status(),
              StatusIs(kInvalid, "header.source_blocks: 0 blocks"));
}

TEST(ArchiveCodecSourceTest, FutureFormatVersionIsRefused) {
  v1::ArchiveHeader header = HeaderOf(MakeAwkwardGrid(2, 1, false));
  EXPECT_TRUE(CheckArchiveVersion(header).ok());
  header.set_format_version(2);
  EXPECT_THAT(CheckArchiveVersion(header),
              StatusIs(kInvalid, "header.format_version = 2: this build reads archive format 1"));
  EXPECT_THAT(SourceAssembler::Create(header).status(), StatusIs(kInvalid, "format_version = 2"));
  header.set_format_version(0);  // unset: not an archive header
  EXPECT_THAT(CheckArchiveVersion(header), StatusIs(kInvalid, "format_version = 0"));
}

TEST(ArchiveCodecSourceTest, ForEachSourceChunkChecksItsInputAndStopsOnError) {
  MultiBlockGrid grid = MakeAwkwardGrid(2, 2, /*with_iblank=*/true);
  int calls = 0;
  const absl::Status stop = absl::CancelledError("stop");
  EXPECT_EQ(ForEachSourceChunk(grid, 3,
                               [&](const v1::SourceChunk&) {
                                 ++calls;
                                 return stop;
                               }),
            stop);
  EXPECT_EQ(calls, 1);
  auto ignore = [](const v1::SourceChunk&) { return absl::OkStatus(); };
  EXPECT_THAT(ForEachSourceChunk(grid, 0, ignore), StatusIs(kInvalid, "max_values = 0"));
  grid.blocks[1].iblank().clear();  // the header has one iblank flag: all blocks or none
  EXPECT_THAT(ForEachSourceChunk(grid, 3, ignore),
              StatusIs(kInvalid, "block 1 has 0 iblank values"));
}

}  // namespace
}  // namespace splinegrid
