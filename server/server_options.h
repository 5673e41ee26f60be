// Configuration of a splinegrid server (the CLI's `serve` flags map onto it).
#ifndef SPLINEGRID_SERVER_SERVER_OPTIONS_H_
#define SPLINEGRID_SERVER_SERVER_OPTIONS_H_

#include <cstdint>
#include <string>

#include "absl/time/time.h"
#include "server/cgns_decoder.h"
#include "server/scheduler.h"

namespace splinegrid::server {

// The call log's lines: "text" (one line of fields) or "json" (one JSON object per line).
enum class LogFormat { kText, kJson };

struct ServerOptions {
  // host:port to listen on; port 0 picks a free port (see Server::port()); empty: no network
  // port, only Server::InProcessChannel (tests).
  std::string address = "localhost:50051";
  // Where grids live (store/open_store.h): "memory", "dir:PATH" or
  // "redis://[USER[:PASSWORD]@]HOST:PORT[/DB]".
  std::string store = "memory";
  // A redis:// store's password: a file whose first line it is, read at every new connection
  // (a rotated secret needs no restart); empty: the one in the URL, if any.
  std::string redis_password_file;
  // Threads of the worker pool that runs fits and evaluations; 0: one per core.
  int worker_threads = 0;
  // Tasks that may wait for a worker before calls are refused with RESOURCE_EXHAUSTED.
  int max_queued_tasks = 4096;
  // Fair scheduling (server/scheduler.h): long tasks (fits, fairing, generation, imports, large
  // evaluations) running at once, in [1, worker threads]; 0: worker threads - 1, at least 1,
  // so that a worker is always free for cheap calls.
  int max_running_long_tasks = SchedulerOptions{}.max_running_long;
  // Long calls one principal may have waiting for a worker (RESOURCE_EXHAUSTED beyond). >= 1.
  int max_queued_long_calls_per_principal = SchedulerOptions{}.max_queued_long_calls_per_principal;
  // Streaming calls (WatchGrid, EvaluateGrid, ImportGrid, ExportGrid, ImportArchive) one
  // principal may hold open (RESOURCE_EXHAUSTED beyond). >= 1.
  int max_streams_per_principal = 64;
  // Bytes the stored grids and in-flight work may hold (RESOURCE_EXHAUSTED beyond); 0: a share
  // of the process's memory limit, cgroup or physical (server/memory_limit.h).
  int64_t memory_budget_bytes = 0;
  // An ImportGrid or ImportArchive stream that receives no message for this long is ended with
  // DEADLINE_EXCEEDED, releasing what it holds; zero or negative: never.
  absl::Duration import_idle_timeout = absl::Seconds(60);
  // The child process that decodes CGNS uploads (server/cgns_decoder.h); its executable empty:
  // splinegrid-cgns-decode beside the running binary. Its memory limit is held against the
  // memory budget while it runs (0: 1 GiB, at most half the budget).
  CgnsDecoderOptions cgns_decoder;
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
  // The form of those lines (server/call_log.h).
  LogFormat log_format = LogFormat::kText;
  // On SIGTERM, health reports NOT_SERVING this long while calls are still accepted (so load
  // balancers and probes stop sending new ones) before the server refuses new calls and drains
  // for shutdown_grace. Zero: refuse at once.
  absl::Duration drain_notice = absl::Seconds(5);

  // ---- Transport security and tokens ----
  // PEM files of the server's certificate chain and private key: TLS when both are set (one
  // without the other is INVALID_ARGUMENT).
  std::string tls_cert_file;
  std::string tls_key_file;
  // PEM file of the CA that signs client certificates: mutual TLS, a client without a valid
  // certificate is refused at the handshake. Needs tls_cert_file.
  std::string tls_client_ca_file;
  // Plaintext on an address that is not loopback (e.g. 0.0.0.0:50051) is refused unless this is
  // set (behind a TLS-terminating proxy, inside a private network).
  bool insecure = false;
  // The tokens file (server/auth/token_file.h): calls need `authorization: Bearer TOKEN` and
  // the token's role. Empty: no tokens, every caller is an admin. Reloaded on SIGHUP.
  std::string tokens_file;
  // Proxies whose `x-client-address` metadata names the caller when there are no tokens
  // (auth/trusted_proxies.h: comma-separated addresses or CIDR ranges); empty: none.
  std::string trusted_proxies;

  // ---- Metrics (server/metrics_endpoint.h) ----
  // HOST:PORT of the Prometheus endpoint (GET /metrics, plaintext HTTP); empty: none. A host
  // that is not loopback needs metrics_insecure.
  std::string metrics_address;
  bool metrics_insecure = false;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_SERVER_OPTIONS_H_
