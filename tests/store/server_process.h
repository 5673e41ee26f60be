// A real `splinegrid serve` (or any helper binary) as a child process on a free loopback port,
// for the tests of durable and shared stores: started, probed until it answers, killed (SIGKILL
// as a crash, SIGTERM as an operator) and waited for, all bounded in time.
#ifndef SPLINEGRID_TESTS_STORE_SERVER_PROCESS_H_
#define SPLINEGRID_TESTS_STORE_SERVER_PROCESS_H_

#include <string>
#include <vector>

#include "absl/time/time.h"

namespace splinegrid::testing {

// A TCP port on 127.0.0.1 that was free a moment ago.
int FreePort();

// Whether something accepts TCP connections on 127.0.0.1:port.
bool PortOpen(int port);

// Runs `command` through the shell; stdout and stderr into `*out`; the exit code.
int RunShell(const std::string& command, std::string* out);

// The path of a program on PATH, or "" (for tests that skip without redis-server or nginx).
std::string FindProgram(const std::string& name);

class ChildProcess {
 public:
  // Starts `argv` (argv[0] a path) with stdout and stderr appended to `log`.
  ChildProcess(std::vector<std::string> argv, std::string log);
  ~ChildProcess();  // SIGKILL if still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  int pid() const { return pid_; }
  bool running();
  // Sends `signal`; then waits up to `timeout` for the exit. The exit code (128 + signal for a
  // killed process), or -1 if it is still running.
  int Stop(int signal, absl::Duration timeout = absl::Seconds(10));
  // Waits up to `timeout` for the process to exit by itself: its exit code, or -1.
  int Wait(absl::Duration timeout);
  const std::string& log() const { return log_; }
  std::string ReadLog() const;

 private:
  int pid_ = -1;
  int exit_code_ = -1;
  std::string log_;
};

// Waits until 127.0.0.1:port accepts connections, up to `timeout`.
bool WaitForPort(int port, absl::Duration timeout);

}  // namespace splinegrid::testing

#endif  // SPLINEGRID_TESTS_STORE_SERVER_PROCESS_H_
