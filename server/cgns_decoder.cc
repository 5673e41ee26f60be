#include "server/cgns_decoder.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>

#include "absl/strings/ascii.h"
#include "absl/strings/numbers.h"
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

// The limits, set by the shell the child starts as (posix_spawn cannot set them), before it
// execs the decoder: "$0" is the decoder, "$1" the upload, so neither path is parsed by the
// shell. dash's ulimit: -v KiB of address space, -t CPU seconds (hard first, then the soft
// limit below it: SIGXCPU at the soft limit, SIGKILL 5 s later), -c core size. The limits are
// at most the server's own hard limits (systemd LimitAS=/LimitCPU=, a container's --ulimit),
// which an unprivileged process cannot raise. A failed ulimit is exit kLimitsFailed, apart from
// a failed exec's 126/127.
constexpr int kLimitsFailed = 125;

// `wanted`, or the server's hard limit of `resource` when that is lower.
int64_t WithinHardLimit(int resource, int64_t wanted) {
  rlimit limit;
  if (getrlimit(resource, &limit) != 0 || limit.rlim_max == RLIM_INFINITY) return wanted;
  return std::min<int64_t>(wanted, static_cast<int64_t>(limit.rlim_max));
}

std::string LimitScript(int64_t memory_bytes, int64_t cpu_seconds) {
  const int64_t memory_kib = WithinHardLimit(RLIMIT_AS, memory_bytes) >> 10;
  const int64_t cpu_hard = WithinHardLimit(RLIMIT_CPU, cpu_seconds + 5);
  const int64_t cpu_soft = std::min(cpu_seconds, cpu_hard);
  return absl::StrCat("ulimit -v ", memory_kib, " && ulimit -t ", cpu_hard, " && ulimit -S -t ",
                      cpu_soft, " && ulimit -c 0 || exit ", kLimitsFailed,
                      "; exec \"$0\" \"$1\"");
}

// posix_spawn attributes and file actions, destroyed on scope exit.
class SpawnSetup {
 public:
  SpawnSetup() {
    ok_ = posix_spawnattr_init(&attr_) == 0;
    ok_ = posix_spawn_file_actions_init(&actions_) == 0 && ok_;
  }
  ~SpawnSetup() {
    posix_spawnattr_destroy(&attr_);
    posix_spawn_file_actions_destroy(&actions_);
  }
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;

  // Its own process group, every signal at its default and none blocked (the server ignores
  // SIGPIPE and blocks the signals its signal thread waits for; a child must not inherit that);
  // stdin and stderr /dev/null (HDF5 prints its error stacks there), stdout `out_fd`, every
  // other descriptor closed (the server's listening sockets, client and Redis connections,
  // whether or not they were opened close-on-exec).
  int Prepare(int out_fd) {
    if (!ok_) return ENOMEM;
    sigset_t all, none;
    sigfillset(&all);
    sigemptyset(&none);
    int error = posix_spawnattr_setflags(
        &attr_, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
    if (error == 0) error = posix_spawnattr_setpgroup(&attr_, 0);
    if (error == 0) error = posix_spawnattr_setsigdefault(&attr_, &all);
    if (error == 0) error = posix_spawnattr_setsigmask(&attr_, &none);
    // The pipe goes to 1 first: were its write end descriptor 0 or 2, opening /dev/null there
    // first would replace it.
    if (error == 0) error = posix_spawn_file_actions_adddup2(&actions_, out_fd, 1);
    if (error == 0)
      error = posix_spawn_file_actions_addopen(&actions_, 0, "/dev/null", O_RDONLY, 0);
    if (error == 0)
      error = posix_spawn_file_actions_addopen(&actions_, 2, "/dev/null", O_WRONLY, 0);
    if (error == 0) error = CloseTheRest();
    return error;
  }

  const posix_spawnattr_t* attr() const { return &attr_; }
  const posix_spawn_file_actions_t* actions() const { return &actions_; }

 private:
  int CloseTheRest() {
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 34))
    // glibc closes them in the child with close_range, and where the kernel has none (before
    // Linux 5.9) by walking /proc/self/fd.
    return posix_spawn_file_actions_addclosefrom_np(&actions_, 3);
#else
    // Without closefrom: every descriptor open now. One another thread opens meanwhile is
    // close-on-exec in this code base (gRPC, Redis and file descriptors all are).
    std::error_code error;
    for (const auto& entry : std::filesystem::directory_iterator("/proc/self/fd", error)) {
      int fd = -1;
      if (!absl::SimpleAtoi(entry.path().filename().string(), &fd) || fd < 3) continue;
      if (int e = posix_spawn_file_actions_addclose(&actions_, fd); e != 0) return e;
    }
    return error ? error.value() : 0;
#endif
  }

  bool ok_ = false;
  posix_spawnattr_t attr_;
  posix_spawn_file_actions_t actions_;
};

std::string SignalName(int signal) {
  const char* name = strsignal(signal);
  return absl::StrCat(signal, name != nullptr ? absl::StrCat(" (", name, ")") : "");
}

// How the reading of the child ended.
enum class Stop { kNone, kWallTime, kCancelled, kReadError };

// The running child: its pid (also its process group) and the read end of its stdout.
struct Child {
  pid_t pid = -1;
  int out_fd = -1;
};

// Starts the decoder on `upload` under `memory_bytes` and `options`' CPU limit.
absl::StatusOr<Child> SpawnDecoder(const std::string& executable, const std::string& upload,
                                   int64_t memory_bytes, const CgnsDecoderOptions& options) {
  int fds[2];
  if (pipe2(fds, O_CLOEXEC) != 0) {
    return absl::ResourceExhaustedError(absl::StrCat("CGNS import: pipe: ", strerror(errno)));
  }
  SpawnSetup setup;
  int error = setup.Prepare(fds[1]);
  const int64_t cpu_seconds = std::max<int64_t>(1, absl::ToInt64Seconds(options.cpu_limit));
  std::string sh = "/bin/sh", dash_c = "-c", script = LimitScript(memory_bytes, cpu_seconds);
  std::string decoder = executable, path = upload;
  char* const argv[] = {sh.data(),      dash_c.data(), script.data(),
                        decoder.data(), path.data(),   nullptr};
  pid_t pid = -1;
  if (error == 0)
    error = posix_spawn(&pid, sh.c_str(), setup.actions(), setup.attr(), argv, environ);
  close(fds[1]);
  if (error != 0) {
    close(fds[0]);
    return absl::ResourceExhaustedError(
        absl::StrCat("CGNS import: starting the decoder ", executable, ": ", strerror(error)));
  }
  return Child{pid, fds[0]};
}

// Whether the child has exited (it is not reaped: its pid and process group stay reserved).
bool Exited(pid_t pid) {
  siginfo_t info = {};
  while (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOHANG | WNOWAIT) != 0) {
    if (errno != EINTR) return true;  // nothing to wait for: the final waitpid reports it
  }
  return info.si_pid == pid;
}

// Reads the child's stdout into `*output` until EOF and then waits for its exit, charging the
// output to `budget` through `reservation`; stops early at the wall-time deadline, on
// cancellation or when the budget refuses (`*read_status`). Polls every 100 ms.
Stop ReadUntilExit(const Child& child, absl::Time deadline, const std::function<bool()>& cancelled,
                   MemoryBudget* budget, MemoryReservation* reservation, std::string* output,
                   absl::Status* read_status) {
  std::string piece(kReadPiece, '\0');
  bool eof = false;
  while (true) {
    const int64_t wait_ms = absl::ToInt64Milliseconds(deadline - absl::Now());
    if (wait_ms <= 0) return Stop::kWallTime;
    if (cancelled && cancelled()) return Stop::kCancelled;
    const int slice = static_cast<int>(std::min<int64_t>(wait_ms, 100));
    if (eof) {  // stdout closed: wait for the exit, still bounded by the deadline
      if (Exited(child.pid)) return Stop::kNone;
      absl::SleepFor(absl::Milliseconds(std::min(slice, 10)));
      continue;
    }
    pollfd p = {child.out_fd, POLLIN, 0};
    const int ready = poll(&p, 1, slice);
    if (ready < 0 && errno != EINTR) {
      *read_status = absl::InternalError(absl::StrCat("CGNS import: poll: ", strerror(errno)));
      return Stop::kReadError;
    }
    if (ready <= 0) continue;
    const ssize_t n = read(child.out_fd, piece.data(), piece.size());
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n <= 0) {  // EOF (or a read error: the exit status tells)
      eof = true;
      continue;
    }
    if (output->size() + n > output->capacity()) {
      *read_status = budget->Resize(
          reservation, static_cast<int64_t>(std::max(output->size() + n, 2 * output->capacity())),
          "the decoded CGNS file");
      if (!read_status->ok()) return Stop::kReadError;
    }
    output->append(piece.data(), static_cast<size_t>(n));
  }
}

// Kills the child's process group (the child itself when it still runs -- wall time,
// cancellation, budget -- and after an exit anything it left running) and reaps the child:
// its wait status, or INTERNAL when waitpid does not return it.
absl::StatusOr<int> KillAndReap(pid_t pid) {
  // Our child's group, by its id: the unreaped child keeps the id from being reused.
  kill(-pid, SIGKILL);
  int status = 0;
  pid_t reaped;
  while ((reaped = waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
  }
  if (reaped != pid) {
    return absl::InternalError(
        absl::StrCat("CGNS import: waiting for the decoder (pid ", pid, ") returned ", reaped,
                     reaped < 0 ? absl::StrCat(": ", strerror(errno)) : std::string(),
                     "; its result is unknown"));
  }
  return status;
}

// The result of a child that ran to its end: its exit status and output judged.
absl::StatusOr<ImportedGrid> Judge(int status, std::string output, const std::string& upload,
                                   const std::string& executable, const CgnsDecoderOptions& options,
                                   int64_t memory_bytes, MemoryBudget* budget,
                                   MemoryReservation* reservation) {
  if (WIFSIGNALED(status)) {
    const int signal = WTERMSIG(status);
    const std::string cpu = absl::FormatDuration(options.cpu_limit);
    const std::string memory = absl::StrCat(memory_bytes >> 20, " MiB");
    // SIGXCPU is RLIMIT_CPU's soft limit; SIGKILL, which the server did not send, is its hard
    // limit or the kernel's out-of-memory killer.
    // SIGABRT: an allocation refused at RLIMIT_AS ends in std::terminate or an HDF5 abort,
    // which is how reaching the memory limit shows (a trial's valid 44 MB file at 64 MiB).
    const std::string why =
        signal == SIGXCPU   ? absl::StrCat("reached its CPU limit of ", cpu)
        : signal == SIGKILL ? absl::StrCat("was killed at its CPU limit (", cpu,
                                           ") or its memory limit (", memory, ")")
        : signal == SIGABRT
            ? absl::StrCat("aborted, as it does when an allocation fails at its memory limit (",
                           memory, ")")
            : "crashed";
    return absl::InvalidArgumentError(absl::StrCat(
        "cgns: the decoder ", why, " (signal ", SignalName(signal),
        ") reading the upload: the file is damaged, or its content is beyond what libcgns "
        "reads within the server's limits (serve --cgns_decoder_cpu_seconds, "
        "--cgns_decoder_memory_mb)"));
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 2) {
    // The decoder's message names the temporary file: never shown to the client. Replaced in
    // the whole output (already charged to the budget), so no cut can leave a part of the name,
    // then escaped (control characters and non-ASCII bytes: one printable line) and cut at
    // kMaxMessage characters with the length noted. Not quoted as a whole: the decoder puts
    // what it names from the file in quotes itself, and a second quoting turned its 'blk' into
    // \'blk\'.
    const std::string message = absl::StrReplaceAll(output, {{upload, "the upload"}});
    return absl::InvalidArgumentError(absl::StrCat(
        "cgns: ", EscapeForLog(absl::StripTrailingAsciiWhitespace(message), kMaxMessage)));
  }
  if (code == kLimitsFailed) {
    return absl::InternalError(absl::StrCat(
        "CGNS import: the decoder's resource limits could not be set (memory ", memory_bytes >> 20,
        " MiB, CPU ", absl::FormatDuration(options.cpu_limit),
        "): check the server's own limits (ulimit -a) against serve --cgns_decoder_memory_mb "
        "and --cgns_decoder_cpu_seconds"));
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

}  // namespace

int64_t CgnsDecoderMemoryLimit(const CgnsDecoderOptions& options, int64_t budget_limit) {
  if (options.memory_limit_bytes > 0) return options.memory_limit_bytes;
  return std::min(kDefaultCgnsDecoderMemoryBytes,
                  std::max(kMinCgnsDecoderMemoryBytes, budget_limit / 2));
}

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
  // Absolute, so that the shell the child starts as runs this file and does not search PATH.
  std::error_code error;
  if (std::filesystem::path absolute = std::filesystem::absolute(path, error); !error) {
    path = absolute.string();
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
  // The child's memory, held until it is reaped (declared before anything it outlives).
  const int64_t memory_bytes = CgnsDecoderMemoryLimit(options, budget->limit());
  SG_ASSIGN_OR_RETURN(
      MemoryReservation child_memory,
      budget->Reserve(memory_bytes, absl::StrCat("the CGNS decoder's memory limit (serve "
                                                 "--cgns_decoder_memory_mb = ",
                                                 memory_bytes >> 20, ")")));
  TempUpload upload;
  SG_RETURN_IF_ERROR(upload.Write(bytes));
  SG_ASSIGN_OR_RETURN(const Child child,
                      SpawnDecoder(executable, upload.path(), memory_bytes, options));
  std::string output;
  absl::Status read_status;
  const Stop stop = ReadUntilExit(child, absl::Now() + options.wall_limit, cancelled, budget,
                                  reservation, &output, &read_status);
  close(child.out_fd);
  SG_ASSIGN_OR_RETURN(const int status, KillAndReap(child.pid));
  child_memory = MemoryReservation();  // the child is gone: its allowance goes back now
  switch (stop) {
    case Stop::kReadError:
      return read_status;
    case Stop::kCancelled:
      return absl::CancelledError(
          "the call was cancelled while its CGNS file was decoded; the decoder was killed");
    case Stop::kWallTime:
      return absl::InvalidArgumentError(
          absl::StrCat("cgns: decoding the upload took longer than the wall-time limit of ",
                       absl::FormatDuration(options.wall_limit),
                       " (serve --cgns_decoder_timeout_seconds); the decoder was killed"));
    case Stop::kNone:
      break;
  }
  return Judge(status, std::move(output), upload.path(), executable, options, memory_bytes, budget,
               reservation);
}

}  // namespace splinegrid::server
