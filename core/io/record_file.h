// A framed record file: a sequence of opaque payloads, each with its length and CRC-32, so a
// reader tells a complete file from a torn or damaged one. Proto-agnostic (core has no protobuf);
// the grid archive (.sgrid), the directory store and the Redis store all put their serialised
// messages in this framing.
//
// Layout: the magic line kRecordFileMagic once, then per record
//   uint32 little-endian payload length | uint32 little-endian CRC-32 of the payload | payload.
// A file cut at a record boundary reads as a clean shorter file; anywhere else it is reported as
// truncated. The framing says nothing about what a complete file contains: callers that need a
// trailer (an end marker, a count) put it in their own last record.
#ifndef SPLINEGRID_CORE_IO_RECORD_FILE_H_
#define SPLINEGRID_CORE_IO_RECORD_FILE_H_

#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include "absl/status/status.h"
#include "absl/status/statusor.h"

namespace splinegrid {

// The first bytes of every record file.
inline constexpr std::string_view kRecordFileMagic = "splinegrid-records\n";

// CRC-32 with the IEEE 802.3 polynomial (reflected 0xEDB88320, init and final xor 0xFFFFFFFF),
// the checksum of zlib's crc32() and Python's zlib.crc32. `crc` is the value of the preceding
// bytes, so Crc32(b, Crc32(a)) == Crc32(a + b). Table driven (one byte per step), O(size).
uint32_t Crc32(std::string_view bytes, uint32_t crc = 0);

// The 8-byte frame header (length, CRC-32) followed by `payload`, as RecordWriter appends it.
// `payload` must be shorter than 4 GiB (checked).
std::string FrameRecord(std::string_view payload);

// Writes a record file from the start. Buffered (stdio); nothing is durable before Close(true).
// Movable, not copyable; destroying an unclosed writer closes it without fsync.
class RecordWriter {
 public:
  // Creates or truncates `path` and writes the magic line. Errors name `path`.
  static absl::StatusOr<RecordWriter> Create(const std::string& path);

  RecordWriter(RecordWriter&&) noexcept;
  RecordWriter& operator=(RecordWriter&&) noexcept;
  ~RecordWriter();

  // Appends one framed record. INVALID_ARGUMENT for a payload of 4 GiB or more,
  // FAILED_PRECONDITION after Close, an errno-derived status for write failures.
  absl::Status Append(std::string_view payload);

  // Flushes the buffer; with `sync` fsyncs the file so its bytes survive a crash; then closes.
  // The writer is closed afterwards even when an error is returned.
  absl::Status Close(bool sync);

 private:
  struct FileCloser {
    void operator()(std::FILE* file) const;
  };
  RecordWriter(std::string path, std::FILE* file);

  std::string path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
};

// Reads a record file front to back. Movable, not copyable.
class RecordReader {
 public:
  // Opens `path` and checks the magic line (INVALID_ARGUMENT "not a record file" otherwise).
  // A record announcing more than `max_record_bytes` is refused before anything is allocated;
  // payload memory otherwise grows with the bytes actually read, so a torn record announcing a
  // large length costs at most one read chunk beyond the data present.
  static absl::StatusOr<RecordReader> Open(const std::string& path,
                                           int64_t max_record_bytes = int64_t{64} << 20);

  RecordReader(RecordReader&&) noexcept;
  RecordReader& operator=(RecordReader&&) noexcept;
  ~RecordReader();

  // Reads the next record into `*payload`: true, or false at a clean end of file (right after a
  // complete record). INVALID_ARGUMENT naming the path, the record number (0-based), its byte
  // offset and the fault: truncated (torn) record, length over the limit, CRC mismatch. After
  // an error the reader stays at the failed record (further calls repeat the error).
  absl::StatusOr<bool> Next(std::string* payload);

  // The byte offset of the next record to read (just past the last complete record).
  int64_t offset() const { return offset_; }

 private:
  struct FileCloser {
    void operator()(std::FILE* file) const;
  };
  RecordReader(std::string path, std::FILE* file, int64_t max_record_bytes);
  absl::Status Fault(const std::string& what) const;

  std::string path_;
  std::unique_ptr<std::FILE, FileCloser> file_;
  int64_t max_record_bytes_;
  int64_t offset_;
  int64_t record_ = 0;
  absl::Status error_;  // sticky: the first fault, returned again by later calls
};

}  // namespace splinegrid

#endif  // SPLINEGRID_CORE_IO_RECORD_FILE_H_
