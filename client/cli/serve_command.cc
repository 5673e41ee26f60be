// `splinegrid serve`: runs the server with the serve flags until a signal.
#include "absl/flags/flag.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/serve_flags.h"
#include "core/util/status_macros.h"
#include "server/server.h"

namespace splinegrid::cli {

absl::Status Serve(const Args& args) {
  if (!args.empty()) return Usage("serve takes no arguments, only flags");
  server::ServerOptions options;
  SG_RETURN_IF_ERROR(CheckServeFlags(&options.log_format));  // before << 20 can overflow
  options.drain_notice = absl::GetFlag(FLAGS_drain_notice);
  options.address = absl::GetFlag(FLAGS_address);
  options.store = absl::GetFlag(FLAGS_store);
  options.redis_password_file = absl::GetFlag(FLAGS_redis_password_file);
  options.worker_threads = absl::GetFlag(FLAGS_threads);
  options.memory_budget_bytes = absl::GetFlag(FLAGS_memory_budget_mb) << 20;
  options.import_idle_timeout = absl::GetFlag(FLAGS_import_idle_timeout);
  options.cgns_decoder.executable = absl::GetFlag(FLAGS_cgns_decoder);
  options.cgns_decoder.memory_limit_bytes = absl::GetFlag(FLAGS_cgns_decoder_memory_mb) << 20;
  options.cgns_decoder.cpu_limit = absl::Seconds(absl::GetFlag(FLAGS_cgns_decoder_cpu_seconds));
  options.cgns_decoder.wall_limit =
      absl::Seconds(absl::GetFlag(FLAGS_cgns_decoder_timeout_seconds));
  options.max_output_points = absl::GetFlag(FLAGS_max_output_points);
  options.shutdown_grace = absl::GetFlag(FLAGS_shutdown_grace);
  options.log_calls = absl::GetFlag(FLAGS_log_calls);
  options.max_deform_revisions = absl::GetFlag(FLAGS_keep_revisions);
  // Transport security and tokens.
  options.tls_cert_file = absl::GetFlag(FLAGS_tls_cert);
  options.tls_key_file = absl::GetFlag(FLAGS_tls_key);
  options.tls_client_ca_file = absl::GetFlag(FLAGS_tls_client_ca);
  options.insecure = absl::GetFlag(FLAGS_insecure);
  options.tokens_file = absl::GetFlag(FLAGS_tokens);
  options.trusted_proxies = absl::GetFlag(FLAGS_trusted_proxies);
  // Fair scheduling and per-principal limits.
  options.max_running_long_tasks = absl::GetFlag(FLAGS_max_running_long_tasks);
  options.max_queued_long_calls_per_principal =
      absl::GetFlag(FLAGS_max_queued_long_calls_per_principal);
  options.max_streams_per_principal = absl::GetFlag(FLAGS_max_streams_per_principal);
  // The Prometheus endpoint.
  options.metrics_address = absl::GetFlag(FLAGS_metrics_address);
  options.metrics_insecure = absl::GetFlag(FLAGS_metrics_insecure);
  return server::RunServerUntilSignal(options);
}

}  // namespace splinegrid::cli
