#include "core/io/record_file.h"

#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "core/io/file_util.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

using ::testing::HasSubstr;

// A fresh path in the test's temporary directory.
std::string TempPath(const std::string& name) {
  return ::testing::TempDir() + "/record_file_test_" + std::to_string(getpid()) + "_" + name;
}

void WriteRecords(const std::string& path, const std::vector<std::string>& payloads) {
  absl::StatusOr<RecordWriter> writer = RecordWriter::Create(path);
  ASSERT_TRUE(writer.ok()) << writer.status();
  for (const std::string& payload : payloads) ASSERT_TRUE(writer->Append(payload).ok());
  ASSERT_TRUE(writer->Close(/*sync=*/true).ok());
}

// Every payload of `path` until the end or the first error (returned in `*error`).
std::vector<std::string> ReadRecords(const std::string& path, absl::Status* error,
                                     int64_t max_record_bytes = int64_t{64} << 20) {
  std::vector<std::string> payloads;
  absl::StatusOr<RecordReader> reader = RecordReader::Open(path, max_record_bytes);
  if (!reader.ok()) {
    *error = reader.status();
    return payloads;
  }
  *error = absl::OkStatus();
  std::string payload;
  for (;;) {
    absl::StatusOr<bool> more = reader->Next(&payload);
    if (!more.ok()) {
      *error = more.status();
      return payloads;
    }
    if (!*more) return payloads;
    payloads.push_back(payload);
  }
}

std::string MessageOf(const absl::Status& status) { return std::string(status.message()); }

TEST(RecordFileTest, Crc32MatchesZlibCheckValue) {
  EXPECT_EQ(Crc32("123456789"), 0xCBF43926u);
  EXPECT_EQ(Crc32(""), 0u);
  // Incremental: the crc argument continues a previous computation, as zlib's crc32().
  EXPECT_EQ(Crc32("6789", Crc32("12345")), 0xCBF43926u);
}

TEST(RecordFileTest, FrameRecordLayout) {
  const std::string framed = FrameRecord("abc");
  ASSERT_EQ(framed.size(), 11u);
  EXPECT_EQ(framed.substr(0, 4), std::string("\x03\x00\x00\x00", 4));
  const uint32_t crc = Crc32("abc");  // 0x352441C2
  EXPECT_EQ(static_cast<uint8_t>(framed[4]), crc & 0xFF);
  EXPECT_EQ(static_cast<uint8_t>(framed[7]), crc >> 24);
  EXPECT_EQ(framed.substr(8), "abc");
}

TEST(RecordFileTest, RoundTripWithEmptyAndBinaryPayloads) {
  const std::string path = TempPath("round_trip");
  const std::vector<std::string> payloads = {"first", "", std::string("\0\xff\n\x01", 4),
                                             std::string(100000, 'x'), ""};
  WriteRecords(path, payloads);
  absl::StatusOr<std::string> bytes = ReadFileToString(path);
  ASSERT_TRUE(bytes.ok());
  std::string expected(kRecordFileMagic);
  for (const std::string& payload : payloads) expected += FrameRecord(payload);
  EXPECT_EQ(*bytes, expected);

  absl::Status error;
  EXPECT_EQ(ReadRecords(path, &error), payloads);
  EXPECT_TRUE(error.ok()) << error;

  absl::StatusOr<RecordReader> reader = RecordReader::Open(path);
  ASSERT_TRUE(reader.ok());
  EXPECT_EQ(reader->offset(), static_cast<int64_t>(kRecordFileMagic.size()));
  std::string payload;
  ASSERT_TRUE(*reader->Next(&payload));
  EXPECT_EQ(reader->offset(), static_cast<int64_t>(kRecordFileMagic.size() + 8 + 5));
}

TEST(RecordFileTest, FileWithOnlyTheMagicHasNoRecords) {
  const std::string path = TempPath("empty");
  WriteRecords(path, {});
  absl::Status error;
  EXPECT_TRUE(ReadRecords(path, &error).empty());
  EXPECT_TRUE(error.ok()) << error;
}

// Cutting the file at any byte gives a prefix of the records, and an error unless the cut falls
// exactly on a record boundary: never a wrong payload.
TEST(RecordFileTest, TruncationAtEveryByteIsDetected) {
  const std::string path = TempPath("full");
  const std::vector<std::string> payloads = {"alpha", "", "gamma-delta", "z"};
  WriteRecords(path, payloads);
  const std::string bytes = *ReadFileToString(path);
  std::vector<size_t> boundaries = {kRecordFileMagic.size()};
  for (const std::string& payload : payloads)
    boundaries.push_back(boundaries.back() + 8 + payload.size());
  ASSERT_EQ(boundaries.back(), bytes.size());

  const std::string cut_path = TempPath("cut");
  for (size_t cut = 0; cut < bytes.size(); ++cut) {
    SCOPED_TRACE(cut);
    ASSERT_TRUE(WriteFileAtomically(cut_path, bytes.substr(0, cut)).ok());
    absl::Status error;
    const std::vector<std::string> read = ReadRecords(cut_path, &error);
    ASSERT_LE(read.size(), payloads.size());
    for (size_t r = 0; r < read.size(); ++r) EXPECT_EQ(read[r], payloads[r]);
    const bool on_boundary =
        std::find(boundaries.begin(), boundaries.end(), cut) != boundaries.end();
    if (on_boundary) {
      EXPECT_TRUE(error.ok()) << error;
    } else {
      EXPECT_EQ(error.code(), absl::StatusCode::kInvalidArgument);
      EXPECT_THAT(MessageOf(error), cut < kRecordFileMagic.size() ? HasSubstr("not a record file")
                                                                  : HasSubstr("truncated"));
    }
  }
}

TEST(RecordFileTest, FlippedBitIsACrcMismatch) {
  const std::string path = TempPath("flip");
  WriteRecords(path, {"one", "two-two"});
  std::string bytes = *ReadFileToString(path);
  const size_t second_payload = kRecordFileMagic.size() + 8 + 3 + 8;
  bytes[second_payload + 2] ^= 0x10;
  ASSERT_TRUE(WriteFileAtomically(path, bytes).ok());
  absl::Status error;
  EXPECT_EQ(ReadRecords(path, &error), std::vector<std::string>{"one"});
  EXPECT_EQ(error.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(error), HasSubstr("CRC mismatch"));
  EXPECT_THAT(MessageOf(error), HasSubstr(path));
  EXPECT_THAT(MessageOf(error), HasSubstr("record 1 at byte offset 30"));
}

// A length of 4 GiB - 1 with no data behind it: refused by the limit before any allocation.
TEST(RecordFileTest, HugeAnnouncedLengthIsRefused) {
  const std::string path = TempPath("huge");
  ASSERT_TRUE(WriteFileAtomically(
                  path, std::string(kRecordFileMagic) + std::string("\xff\xff\xff\xff\0\0\0\0", 8))
                  .ok());
  absl::Status error;
  EXPECT_TRUE(ReadRecords(path, &error).empty());
  EXPECT_EQ(error.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(error), HasSubstr("announced length 4294967295 bytes exceeds the limit"));

  // Within the limit but torn: reported as truncated, having read only what is there.
  WriteRecords(path, {std::string(1000, 'q')});
  std::string bytes = *ReadFileToString(path);
  bytes.resize(bytes.size() - 1);
  ASSERT_TRUE(WriteFileAtomically(path, bytes).ok());
  EXPECT_TRUE(ReadRecords(path, &error).empty());
  EXPECT_THAT(MessageOf(error), HasSubstr("999 of 1000 payload bytes"));
  // A custom limit below the record size.
  WriteRecords(path, {std::string(1000, 'q')});
  EXPECT_TRUE(ReadRecords(path, &error, /*max_record_bytes=*/999).empty());
  EXPECT_THAT(MessageOf(error), HasSubstr("exceeds the limit of 999 bytes"));
}

TEST(RecordFileTest, BadMagicIsNotARecordFile) {
  const std::string path = TempPath("magic");
  ASSERT_TRUE(WriteFileAtomically(path, "splinegrid-recordz\n\0\0\0\0\0\0\0\0").ok());
  absl::Status error;
  ReadRecords(path, &error);
  EXPECT_EQ(error.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(MessageOf(error), HasSubstr("is not a record file"));
  EXPECT_THAT(MessageOf(error), HasSubstr(path));
}

TEST(RecordFileTest, MissingFileAndClosedWriter) {
  EXPECT_EQ(RecordReader::Open(TempPath("does_not_exist")).status().code(),
            absl::StatusCode::kNotFound);
  absl::StatusOr<RecordWriter> writer = RecordWriter::Create(TempPath("closed"));
  ASSERT_TRUE(writer.ok());
  RecordWriter moved = std::move(*writer);
  ASSERT_TRUE(moved.Close(/*sync=*/false).ok());
  EXPECT_EQ(moved.Append("late").code(), absl::StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace splinegrid
