// Fits reuse the connectivity a grid keeps with its source points (found once, at import). An
// archive carries it too, so ImportArchive checks it against the archive's points: a changed
// list of boundary matches is refused, and an unchanged archive fits exactly as the original.
#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "core/io/record_file.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "splinegrid/v1/archive.pb.h"
#include "tests/server/service_fixture.h"

namespace splinegrid::testing {
namespace {

class ArchiveConnectivityTest : public ServiceTest {
 protected:
  std::string TempPath(const std::string& name) {
    return (std::filesystem::path(::testing::TempDir()) / name).string();
  }

  // The records of archive `path`.
  std::vector<v1::ArchiveRecord> ReadRecords(const std::string& path) {
    std::vector<v1::ArchiveRecord> records;
    absl::StatusOr<RecordReader> reader = RecordReader::Open(path);
    EXPECT_TRUE(reader.ok()) << reader.status();
    std::string payload;
    while (reader.ok()) {
      absl::StatusOr<bool> next = reader->Next(&payload);
      EXPECT_TRUE(next.ok()) << next.status();
      if (!next.ok() || !*next) break;
      EXPECT_TRUE(records.emplace_back().ParseFromString(payload));
    }
    return records;
  }

  void WriteRecords(const std::string& path, const std::vector<v1::ArchiveRecord>& records) {
    absl::StatusOr<RecordWriter> writer = RecordWriter::Create(path);
    ASSERT_TRUE(writer.ok()) << writer.status();
    for (const v1::ArchiveRecord& record : records) {
      ASSERT_TRUE(writer->Append(record.SerializeAsString()).ok());
    }
    ASSERT_TRUE(writer->Close(/*sync=*/false).ok());
  }
};

TEST_F(ArchiveConnectivityTest, AChangedConnectivityIsRefusedAndAnIntactOneFitsAlike) {
  // The C-grid's wake cut is a match of block 0 with itself.
  ImportShared("grids/rae2822_257x97.fmt", "rae", /*planar=*/true);
  const std::string path = TempPath("rae-connectivity.sgrid");
  ASSERT_TRUE(client_->ExportGrid("rae", path).ok());
  std::vector<v1::ArchiveRecord> records = ReadRecords(path);
  ASSERT_FALSE(records.empty());
  ASSERT_TRUE(records[0].has_header());
  ASSERT_GE(records[0].header().connectivity().matches_size(), 1);

  // Intact: imported, and fitted exactly as the original.
  absl::StatusOr<v1::Grid> copy = client_->ImportArchive(path, "rae-copy");
  ASSERT_TRUE(copy.ok()) << copy.status();
  FitCounts("rae", 24, 12);
  FitCounts("rae-copy", 24, 12);
  const v1::Grid original = client_->Get("rae", 0, v1::GRID_VIEW_FULL).value();
  const v1::Grid copied = client_->Get("rae-copy", 0, v1::GRID_VIEW_FULL).value();
  ASSERT_GT(original.revision().blocks(0).control_points_size(), 0);
  const v1::SplineBlock& a = original.revision().blocks(0);
  const v1::SplineBlock& b = copied.revision().blocks(0);
  EXPECT_TRUE(std::equal(a.control_points().begin(), a.control_points().end(),
                         b.control_points().begin(), b.control_points().end()))
      << "the copy's control net differs";
  EXPECT_EQ(original.revision().report().num_matches(), copied.revision().report().num_matches());

  // Without its wake cut: refused, naming the field, and nothing stored.
  records[0].mutable_header()->mutable_connectivity()->clear_matches();
  const std::string changed = TempPath("rae-no-cut.sgrid");
  WriteRecords(changed, records);
  EXPECT_THAT(client_->ImportArchive(changed, "rae-no-cut").status(),
              StatusIs(absl::StatusCode::kInvalidArgument,
                       "header.connectivity does not match the archive's source points"));
  EXPECT_EQ(client_->Get("rae-no-cut").status().code(), absl::StatusCode::kNotFound);
}

}  // namespace
}  // namespace splinegrid::testing
