#include "server/cgns_decoder.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_replace.h"
#include "core/util/quote.h"
#include "core/util/status_macros.h"
#include "proto/convert/source_boundaries_convert.h"

namespace splinegrid::server {
namespace {

constexpr char kDecoderName[] = "splinegrid-cgns-decode";
// The decoder's output is read and charged in pieces of this size.
constexpr int64_t kReadPiece = int64_t{1} << 20;
// The text of a failed decode that reaches the client.
constexpr size_t kMaxMessage = 2000;

// A private temporary file holding the upload (mode 0600 from mkstemp), removed on scope exit.
class TempUpload {
 public:
  ~TempUpload() {
    if (!path_.empty()) unlink(path_.c_str());
  }

  absl::Status Write(const std::string& bytes) {
    const char* dir = getenv("TMPDIR");
    std::string pattern =
        absl::StrCat(dir != nullptr && *dir != '\0' ? dir : "/tmp", "/splinegrid-cgns-XXXXXX");
    const int fd = mkostemp(pattern.data(), O_CLOEXEC);
    if (fd < 0) {
      return absl::InternalError(absl::StrCat("creating a temporary file for the CGNS upload in ",
                                              pattern, ": ", strerror(errno)));
    }
    path_ = pattern;
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = write(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        const int error = errno;
        close(fd);
        return absl::ResourceExhaustedError(
            absl::StrCat("writing the CGNS upload to ", path_, ": ", strerror(error)));
      }
      done += static_cast<size_t>(n);
    }
    if (close(fd) != 0) {
      return absl::InternalError(absl::StrCat("closing ", path_, ": ", strerror(errno)));
    }
    return absl::OkStatus();
  }

  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

// In the child between fork and exec (async-signal-safe calls only): limits, stdout to the
// pipe, stdin and stderr to /dev/null (HDF5 prints its error stacks there), every other
// descriptor closed, then the decoder.
[[noreturn]] void RunChild(const char* executable, char* const argv[], int out_fd,
                           const CgnsDecoderOptions& options) {
  const rlim_t memory = static_cast<rlim_t>(options.memory_limit_bytes);
  const rlimit as = {memory, memory};
  const rlim_t cpu =
      static_cast<rlim_t>(std::max<int64_t>(1, absl::ToInt64Seconds(options.cpu_limit)));
  const rlimit cpu_limit = {cpu, cpu + 5};  // SIGXCPU at the soft limit, SIGKILL at the hard
  const rlimit no_core = {0, 0};
  if (setrlimit(RLIMIT_AS, &as) != 0 || setrlimit(RLIMIT_CPU, &cpu_limit) != 0 ||
      setrlimit(RLIMIT_CORE, &no_core) != 0) {
    _exit(126);
  }
  const int null_fd = open("/dev/null", O_RDWR);
  if (null_fd < 0 || dup2(null_fd, 0) < 0 || dup2(null_fd, 2) < 0 || dup2(out_fd, 1) < 0)
    _exit(126);
  // Nothing else of the server's crosses into the child: not its listening sockets, client
  // connections or Redis connection, whether or not they were opened close-on-exec.
  if (close_range(3, ~0U, 0) != 0) _exit(126);
  execv(executable, argv);
  _exit(127);
}

std::string SignalName(int signal) {
  const char* name = strsignal(signal);
  return absl::StrCat(signal, name != nullptr ? absl::StrCat(" (", name, ")") : "");
}

}  // namespace

absl::StatusOr<std::string> FindCgnsDecoder(const CgnsDecoderOptions& options) {
  std::string path = options.executable;
  if (path.empty()) {
    std::error_code error;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", error);
    if (error) {
      return absl::FailedPreconditionError(absl::StrCat(
          "CGNS import: cannot find this binary's directory (/proc/self/exe: ", error.message(),
          "); give the decoder with serve --cgns_decoder"));
    }
    path = (self.parent_path() / kDecoderName).string();
  }
  if (access(path.c_str(), X_OK) != 0) {
    return absl::FailedPreconditionError(absl::StrCat(
        "CGNS import: the decoder ", path, " is not an executable file (", strerror(errno),
        "); build ", kDecoderName, " beside the server or give it with serve --cgns_decoder"));
  }
  return path;
}

absl::StatusOr<ImportedGrid> DecodeCgnsUpload(const std::string& bytes,
                                              const CgnsDecoderOptions& options,
                                              MemoryBudget* budget, MemoryReservation* reservation,
                                              const std::function<bool()>& cancelled) {
  SG_ASSIGN_OR_RETURN(const std::string executable, FindCgnsDecoder(options));
  TempUpload upload;
  SG_RETURN_IF_ERROR(upload.Write(bytes));
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    return absl::ResourceExhaustedError(absl::StrCat("CGNS import: pipe: ", strerror(errno)));
  }
  std::string arg0 = kDecoderName, arg1 = upload.path();
  char* const argv[] = {arg0.data(), arg1.data(), nullptr};
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return absl::ResourceExhaustedError(absl::StrCat("CGNS import: fork: ", strerror(errno)));
  }
  if (pid == 0) RunChild(executable.c_str(), argv, fds[1], options);
  close(fds[1]);

  // Read until EOF, charging the budget; a child that outlives the wall limit is killed.
  std::string output;
  absl::Status read_status;
  bool timed_out = false;
  bool stopped = false;  // the call was cancelled
  const absl::Time deadline = absl::Now() + options.wall_limit;
  std::string piece(kReadPiece, '\0');
  while (true) {
    const int64_t wait_ms = absl::ToInt64Milliseconds(deadline - absl::Now());
    if (wait_ms <= 0) {
      timed_out = true;
      break;
    }
    if (cancelled && cancelled()) {
      stopped = true;
      break;
    }
    pollfd p = {fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(std::min<int64_t>(wait_ms, 1000)));
    if (ready < 0 && errno != EINTR) {
      read_status = absl::InternalError(absl::StrCat("CGNS import: poll: ", strerror(errno)));
      break;
    }
    if (ready <= 0) continue;
    const ssize_t n = read(fds[0], piece.data(), piece.size());
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) break;  // EOF (or a read error: the exit status tells)
    if (output.size() + n > output.capacity()) {
      read_status = budget->Resize(
          reservation, static_cast<int64_t>(std::max(output.size() + n, 2 * output.capacity())),
          "the decoded CGNS file");
      if (!read_status.ok()) break;
    }
    output.append(piece.data(), static_cast<size_t>(n));
  }
  close(fds[0]);
  if (timed_out || stopped || !read_status.ok()) kill(pid, SIGKILL);  // our child, by its pid
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!read_status.ok()) return read_status;
  if (stopped)
    return absl::CancelledError("the call was cancelled while its CGNS file was decoded");
  if (timed_out) {
    return absl::InvalidArgumentError(absl::StrCat("cgns: decoding the upload took longer than ",
                                                   absl::FormatDuration(options.wall_limit),
                                                   "; it was stopped"));
  }
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    const std::string why =
        signal == SIGXCPU || signal == SIGKILL
            ? absl::StrCat("reached its CPU limit of ", absl::FormatDuration(options.cpu_limit))
            : "crashed";
    return absl::InvalidArgumentError(absl::StrCat(
        "cgns: the decoder ", why, " (signal ", SignalName(signal),
        ") reading the upload: the file is damaged, or its content is beyond what libcgns "
        "reads within the server's limits"));
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 2) {
    std::string message =
        absl::StrReplaceAll(output.substr(0, kMaxMessage), {{upload.path(), "the upload"}});
    return absl::InvalidArgumentError(absl::StrCat("cgns: ", QuoteClientString(message)));
  }
  if (code != 0) {
    return absl::InternalError(absl::StrCat("CGNS import: the decoder ", executable,
                                            " exited with status ", code,
                                            code >= 126 ? " (it could not be started)" : ""));
  }
  // The parsed message beside its bytes.
  SG_RETURN_IF_ERROR(budget->Resize(reservation, 2 * static_cast<int64_t>(output.size()),
                                    "the decoded CGNS file"));
  v1::CgnsDecoded decoded;
  if (!decoded.ParseFromString(output)) {
    return absl::InvalidArgumentError("cgns: the decoder's output is not a CgnsDecoded message");
  }
  output = std::string();
  absl::StatusOr<ImportedGrid> grid = ParseCgnsDecoded(decoded);
  if (!grid.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("cgns: the decoded file: ", grid.status().message()));
  }
  return grid;
}

}  // namespace splinegrid::server
