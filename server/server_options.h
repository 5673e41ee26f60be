// Configuration of a splinegrid server (the CLI's `serve` flags map onto it).
#ifndef SPLINEGRID_SERVER_SERVER_OPTIONS_H_
#define SPLINEGRID_SERVER_SERVER_OPTIONS_H_

#include <cstdint>
#include <string>

#include "absl/time/time.h"

namespace splinegrid::server {

struct ServerOptions {
  // host:port to listen on; port 0 picks a free port (see Server::port()); empty: no network
  // port, only Server::InProcessChannel (tests).
  std::string address = "localhost:50051";
  // Where grids live (store/open_store.h): "memory", "dir:PATH" or "redis://HOST:PORT[/DB]".
  std::string store = "memory";
  // Threads of the worker pool that runs fits and evaluations; 0: one per core.
  int worker_threads = 0;
  // Tasks that may wait for a worker before calls are refused with RESOURCE_EXHAUSTED.
  int max_queued_tasks = 4096;
  // Bytes the stored grids and in-flight work may hold (RESOURCE_EXHAUSTED beyond).
  int64_t memory_budget_bytes = int64_t{4} << 30;
  // The most points one EvaluateGrid or EvaluatePoints call may ask for (OUT_OF_RANGE beyond).
  int64_t max_output_points = int64_t{1} << 30;
  // Deformed revisions kept per grid: publishing a revision drops the older ones (fitted and
  // faired revisions are always kept). At least 1.
  int max_deform_revisions = 64;
  // Revisions a WatchGrid call may fall behind (published, not yet written to the client)
  // before it is ended with RESOURCE_EXHAUSTED. At least 1.
  int max_watch_lag = 1024;
  // On shutdown, in-flight calls get this long to finish before they are cancelled.
  absl::Duration shutdown_grace = absl::Seconds(10);
  // One line per call on stderr.
  bool log_calls = true;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_SERVER_OPTIONS_H_
