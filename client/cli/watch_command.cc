// `splinegrid watch`: one line per new revision of a grid until interrupted (WatchGrid).
#include <pthread.h>
#include <signal.h>

#include <atomic>
#include <cstdio>
#include <memory>
#include <thread>

#include "absl/flags/flag.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"

namespace splinegrid::cli {

absl::Status Watch(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid watch NAME [--after R]");
  // SIGINT and SIGTERM end the watch cleanly: blocked here (before gRPC starts threads, which
  // inherit the mask) and taken by a thread that cancels the call.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  auto cancel = std::make_shared<client::WatchCancel>();
  std::atomic<bool> done{false};
  std::thread waiter([&] {
    int signal = 0;
    sigwait(&signals, &signal);
    if (!done) cancel->Cancel();
  });
  const std::string name = client::GridName(args[0]);
  const bool json = absl::GetFlag(FLAGS_json);
  // A watch is a monitor: it rides out a server restart or a failover of about a minute (waits
  // of 0.1, 0.2, 0.4 ... 2 s; the count starts afresh once a resumed call is up), where a
  // one-off command gives up after about a second.
  client::RetryPolicy retry;
  retry.max_attempts = 40;
  retry.initial_backoff = absl::Milliseconds(100);
  retry.max_backoff = absl::Seconds(2);
  const absl::Status status = Connect(retry)->Watch(
      name, absl::GetFlag(FLAGS_after),
      [&](const v1::WatchGridResponse& message) {
        const std::string line =
            json ? ToJsonLine(message) : FormatRevisionLine(message.revision());
        std::fwrite(line.data(), 1, line.size(), stdout);
        std::fflush(stdout);
        return true;
      },
      cancel);
  done = true;
  pthread_kill(waiter.native_handle(), SIGTERM);  // wakes the waiter (the signal stays blocked)
  waiter.join();
  if (!status.ok()) return status;
  std::fprintf(stderr, "splinegrid watch: %s: %s\n", name.c_str(),
               cancel->cancelled() ? "interrupted"
                                   : "the stream ended (the grid was deleted, or deleted "
                                     "and created again)");
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
