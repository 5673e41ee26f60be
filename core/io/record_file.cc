#include "core/io/record_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <limits>
#include <utility>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/util/check.h"

namespace splinegrid {
namespace {

constexpr int kFrameHeaderBytes = 8;
// Payload bytes read per step: memory follows the data actually present, not the announced size.
constexpr int64_t kReadChunkBytes = int64_t{1} << 20;

// CRC-32 of every byte value (Sarwate's table for the reflected polynomial 0xEDB88320).
constexpr std::array<uint32_t, 256> MakeCrcTable() {
  std::array<uint32_t, 256> table{};
  for (uint32_t n = 0; n < 256; ++n) {
    uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}
constexpr std::array<uint32_t, 256> kCrcTable = MakeCrcTable();

void PutLittleEndian32(uint32_t value, char* out) {
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>((value >> (8 * i)) & 0xFF);
}

uint32_t GetLittleEndian32(const unsigned char* in) {
  return uint32_t{in[0]} | uint32_t{in[1]} << 8 | uint32_t{in[2]} << 16 | uint32_t{in[3]} << 24;
}

// Opens `path` with O_CLOEXEC as a stdio stream, for writing (created or truncated) or reading.
absl::StatusOr<std::FILE*> OpenStream(const std::string& path, bool write) {
  const int flags = write ? O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC : O_RDONLY | O_CLOEXEC;
  const int fd = open(path.c_str(), flags, 0644);
  if (fd < 0) return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot open '", path, "'"));
  std::FILE* file = fdopen(fd, write ? "wb" : "rb");
  if (file == nullptr) {
    const int error = errno;
    close(fd);
    return ErrnoToStatusWithMessage(error, absl::StrCat("cannot open '", path, "'"));
  }
  return file;
}

}  // namespace

uint32_t Crc32(std::string_view bytes, uint32_t crc) {
  crc = ~crc;
  for (const char byte : bytes) {
    crc = kCrcTable[(crc ^ static_cast<uint8_t>(byte)) & 0xFF] ^ (crc >> 8);
  }
  return ~crc;
}

std::string FrameRecord(std::string_view payload) {
  // A length that does not fit the 32-bit field would silently wrap: a bug in the caller.
  SG_CHECK(payload.size() <= std::numeric_limits<uint32_t>::max());
  std::string framed(kFrameHeaderBytes + payload.size(), '\0');
  PutLittleEndian32(static_cast<uint32_t>(payload.size()), framed.data());
  PutLittleEndian32(Crc32(payload), framed.data() + 4);
  framed.replace(kFrameHeaderBytes, payload.size(), payload);
  return framed;
}

// ---- RecordWriter ----

void RecordWriter::FileCloser::operator()(std::FILE* file) const { std::fclose(file); }

RecordWriter::RecordWriter(std::string path, std::FILE* file)
    : path_(std::move(path)), file_(file) {}
RecordWriter::RecordWriter(RecordWriter&&) noexcept = default;
RecordWriter& RecordWriter::operator=(RecordWriter&&) noexcept = default;
RecordWriter::~RecordWriter() = default;

absl::StatusOr<RecordWriter> RecordWriter::Create(const std::string& path) {
  absl::StatusOr<std::FILE*> file = OpenStream(path, /*write=*/true);
  if (!file.ok()) return file.status();
  RecordWriter writer(path, *file);
  if (std::fwrite(kRecordFileMagic.data(), 1, kRecordFileMagic.size(), *file) !=
      kRecordFileMagic.size()) {
    return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot write '", path, "'"));
  }
  return writer;
}

absl::Status RecordWriter::Append(std::string_view payload) {
  if (file_ == nullptr) {
    return absl::FailedPreconditionError(absl::StrCat("record file '", path_, "' is closed"));
  }
  if (payload.size() > std::numeric_limits<uint32_t>::max()) {
    return absl::InvalidArgumentError(absl::StrCat("record of ", payload.size(), " bytes for '",
                                                   path_, "' exceeds the 4 GiB record limit"));
  }
  // The header goes separately so a large payload is not copied into a framed string.
  char header[kFrameHeaderBytes];
  PutLittleEndian32(static_cast<uint32_t>(payload.size()), header);
  PutLittleEndian32(Crc32(payload), header + 4);
  if (std::fwrite(header, 1, kFrameHeaderBytes, file_.get()) != kFrameHeaderBytes ||
      std::fwrite(payload.data(), 1, payload.size(), file_.get()) != payload.size()) {
    return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot write '", path_, "'"));
  }
  return absl::OkStatus();
}

absl::Status RecordWriter::Close(bool sync) {
  if (file_ == nullptr) {
    return absl::FailedPreconditionError(absl::StrCat("record file '", path_, "' is closed"));
  }
  std::FILE* file = file_.release();
  absl::Status status;
  if (std::fflush(file) != 0) {
    status = ErrnoToStatusWithMessage(errno, absl::StrCat("cannot write '", path_, "'"));
  } else if (sync && fsync(fileno(file)) != 0) {
    status = ErrnoToStatusWithMessage(errno, absl::StrCat("cannot fsync '", path_, "'"));
  }
  if (std::fclose(file) != 0 && status.ok()) {
    status = ErrnoToStatusWithMessage(errno, absl::StrCat("cannot close '", path_, "'"));
  }
  return status;
}

// ---- RecordReader ----

void RecordReader::FileCloser::operator()(std::FILE* file) const { std::fclose(file); }

RecordReader::RecordReader(std::string path, std::FILE* file, int64_t max_record_bytes)
    : path_(std::move(path)),
      file_(file),
      max_record_bytes_(max_record_bytes),
      offset_(static_cast<int64_t>(kRecordFileMagic.size())) {}
RecordReader::RecordReader(RecordReader&&) noexcept = default;
RecordReader& RecordReader::operator=(RecordReader&&) noexcept = default;
RecordReader::~RecordReader() = default;

absl::StatusOr<RecordReader> RecordReader::Open(const std::string& path, int64_t max_record_bytes) {
  absl::StatusOr<std::FILE*> file = OpenStream(path, /*write=*/false);
  if (!file.ok()) return file.status();
  RecordReader reader(path, *file, max_record_bytes);
  std::string magic(kRecordFileMagic.size(), '\0');
  const size_t got = std::fread(magic.data(), 1, magic.size(), *file);
  if (std::ferror(*file)) {
    return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot read '", path, "'"));
  }
  if (got != magic.size() || magic != kRecordFileMagic) {
    return absl::InvalidArgumentError(
        absl::StrCat("'", path, "' is not a record file (it does not start with the line \"",
                     std::string(kRecordFileMagic.substr(0, kRecordFileMagic.size() - 1)), "\")"));
  }
  return reader;
}

absl::Status RecordReader::Fault(const std::string& what) const {
  return absl::InvalidArgumentError(absl::StrCat("record file '", path_, "': record ", record_,
                                                 " at byte offset ", offset_, ": ", what));
}

absl::StatusOr<bool> RecordReader::Next(std::string* payload) {
  if (!error_.ok()) return error_;
  if (file_ == nullptr) return absl::FailedPreconditionError("record reader was moved from");
  std::FILE* file = file_.get();
  unsigned char header[kFrameHeaderBytes];
  const size_t header_got = std::fread(header, 1, kFrameHeaderBytes, file);
  if (std::ferror(file)) {
    return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot read '", path_, "'"));
  }
  if (header_got == 0) return false;  // clean end: the file ends right after a record
  if (header_got < kFrameHeaderBytes) {
    error_ = Fault(absl::StrCat("truncated record: the file ends ", header_got,
                                " bytes into the 8-byte frame header"));
    return error_;
  }
  const int64_t length = GetLittleEndian32(header);
  const uint32_t expected_crc = GetLittleEndian32(header + 4);
  if (length > max_record_bytes_) {
    error_ = Fault(absl::StrCat("announced length ", length, " bytes exceeds the limit of ",
                                max_record_bytes_, " bytes"));
    return error_;
  }
  payload->clear();
  while (static_cast<int64_t>(payload->size()) < length) {
    const size_t before = payload->size();
    const size_t want =
        static_cast<size_t>(std::min(length - static_cast<int64_t>(before), kReadChunkBytes));
    payload->resize(before + want);
    const size_t got = std::fread(payload->data() + before, 1, want, file);
    if (got < want) {
      if (std::ferror(file)) {
        return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot read '", path_, "'"));
      }
      error_ = Fault(absl::StrCat("truncated record: ", before + got, " of ", length,
                                  " payload bytes present"));
      payload->clear();
      return error_;
    }
  }
  const uint32_t actual_crc = Crc32(*payload);
  if (actual_crc != expected_crc) {
    error_ = Fault(absl::StrCat("CRC mismatch: stored 0x", absl::Hex(expected_crc, absl::kZeroPad8),
                                ", payload has 0x", absl::Hex(actual_crc, absl::kZeroPad8)));
    payload->clear();
    return error_;
  }
  offset_ += kFrameHeaderBytes + length;
  ++record_;
  return true;
}

}  // namespace splinegrid
