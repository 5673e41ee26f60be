// libFuzzer target: the framed record file reader (core/io/record_file.cc) on arbitrary bytes,
// read through a memfd so RecordReader::Open sees a real file. Every input must read as records
// then a clean end or an INVALID_ARGUMENT fault, never allocate beyond the data present plus
// one read chunk (peak heap use at most 32 KiB for stdio and messages + 2 bytes per input byte,
// with a 4096-byte record limit), and every record read must carry its CRC.
#include "core/io/record_file.h"

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "absl/strings/str_cat.h"
#include "tests/fuzz/fuzz_memory.h"
#include "tests/fuzz/fuzz_util.h"

namespace {

// One memfd for the whole run, rewritten per input; its /proc path is what Open gets.
int InputFd() {
  static const int fd = memfd_create("splinegrid-fuzz", MFD_CLOEXEC);
  return fd;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const int fd = InputFd();
  FUZZ_CHECK(fd >= 0, "memfd_create failed");
  FUZZ_CHECK(ftruncate(fd, 0) == 0, "ftruncate failed");
  FUZZ_CHECK(pwrite(fd, data, size, 0) == static_cast<ssize_t>(size), "pwrite failed");
  const std::string path = absl::StrCat("/proc/self/fd/", fd);
  splinegrid::fuzz::PeakAllocation peak;
  // A small record limit, so the "over the limit" path is reachable with small inputs.
  absl::StatusOr<splinegrid::RecordReader> reader =
      splinegrid::RecordReader::Open(path, /*max_record_bytes=*/4096);
  if (!reader.ok()) {
    splinegrid::fuzz::CheckRejection(reader.status());
    return 0;
  }
  std::string payload;
  int64_t records = 0;
  for (;;) {
    absl::StatusOr<bool> next = reader->Next(&payload);
    if (!next.ok()) {
      splinegrid::fuzz::CheckRejection(next.status());
      // Sticky: the same fault again.
      absl::StatusOr<bool> again = reader->Next(&payload);
      FUZZ_CHECK(!again.ok() && again.status() == next.status(), "fault is not sticky");
      break;
    }
    if (!*next) break;
    ++records;
    FUZZ_CHECK(payload.size() <= 4096, "record over the limit was returned");
    FUZZ_CHECK(reader->offset() <= static_cast<int64_t>(size), "offset past the end");
  }
  const int64_t used = peak.Peak();
  FUZZ_CHECK(
      used <= 32768 + 2 * static_cast<int64_t>(size),
      absl::StrCat(size, " bytes in ", records, " records took ", used, " heap bytes at once"));
  return 0;
}
