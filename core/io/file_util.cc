#include "core/io/file_util.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "absl/strings/str_cat.h"

namespace splinegrid {
namespace {

// Closes a POSIX file descriptor when it goes out of scope.
class FdCloser {
 public:
  // Takes ownership of `fd` (may be -1).
  explicit FdCloser(int fd) : fd_(fd) {}
  ~FdCloser() {
    if (fd_ >= 0) close(fd_);
  }
  FdCloser(const FdCloser&) = delete;
  FdCloser& operator=(const FdCloser&) = delete;
  // Closes now; the errno of a failed close() is returned as a nonzero value.
  int Close() {
    const int fd = fd_;
    fd_ = -1;
    return close(fd) == 0 ? 0 : errno;
  }

 private:
  int fd_;
};

// A name for a temporary file next to `path` that no other writer uses at the same time.
std::string TemporaryPathFor(const std::string& path, int attempt) {
  static std::atomic<uint64_t> counter{0};
  return absl::StrCat(path, ".tmp.", static_cast<int64_t>(getpid()), ".",
                      counter.fetch_add(1, std::memory_order_relaxed), ".", attempt);
}

}  // namespace

absl::Status ErrnoToStatusWithMessage(int error_number, const std::string& message) {
  const std::string text = absl::StrCat(message, ": ", std::strerror(error_number));
  switch (error_number) {
    case ENOENT:
    case ENOTDIR:
      return absl::NotFoundError(text);
    case EACCES:
    case EPERM:
    case EROFS:
      return absl::PermissionDeniedError(text);
    case EISDIR:
    case ENAMETOOLONG:
    case EINVAL:
      return absl::InvalidArgumentError(text);
    case ENOSPC:
    case EDQUOT:
    case ENOMEM:
      return absl::ResourceExhaustedError(text);
    default:
      return absl::InternalError(text);
  }
}

absl::StatusOr<std::string> ReadFileToString(const std::string& path) {
  const int fd = open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot open '", path, "'"));
  FdCloser closer(fd);
  struct stat info;
  if (fstat(fd, &info) != 0) {
    return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot stat '", path, "'"));
  }
  if (S_ISDIR(info.st_mode)) {
    return absl::InvalidArgumentError(absl::StrCat("'", path, "' is a directory, not a file"));
  }
  std::string contents;
  if (S_ISREG(info.st_mode)) contents.reserve(static_cast<size_t>(info.st_size));
  char buffer[1 << 16];
  while (true) {
    const ssize_t n = read(fd, buffer, sizeof(buffer));
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      return ErrnoToStatusWithMessage(errno, absl::StrCat("cannot read '", path, "'"));
    }
    contents.append(buffer, static_cast<size_t>(n));
  }
  return contents;
}

absl::Status WriteFileAtomically(const std::string& path, std::string_view contents) {
  if (path.empty()) return absl::InvalidArgumentError("cannot write a file with an empty path");
  std::string temp;
  int fd = -1;
  for (int attempt = 0; attempt < 16 && fd < 0; ++attempt) {
    temp = TemporaryPathFor(path, attempt);
    fd = open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    return ErrnoToStatusWithMessage(
        errno, absl::StrCat("cannot create a temporary file to write '", path, "'"));
  }
  FdCloser closer(fd);
  auto fail = [&](const char* what) {
    const int error_number = errno;
    unlink(temp.c_str());
    return ErrnoToStatusWithMessage(error_number, absl::StrCat("cannot ", what, " '", path, "'"));
  };
  const char* data = contents.data();
  size_t remaining = contents.size();
  while (remaining > 0) {
    const ssize_t n = write(fd, data, remaining);
    if (n < 0) {
      if (errno == EINTR) continue;
      return fail("write");
    }
    data += n;
    remaining -= static_cast<size_t>(n);
  }
  if (fsync(fd) != 0) return fail("flush");
  if (const int error_number = closer.Close(); error_number != 0) {
    errno = error_number;
    return fail("close");
  }
  if (rename(temp.c_str(), path.c_str()) != 0) return fail("rename the temporary file onto");
  return absl::OkStatus();
}

}  // namespace splinegrid
