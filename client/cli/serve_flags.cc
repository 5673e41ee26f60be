#include "client/cli/serve_flags.h"

#include <cstdint>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "client/cli/flags.h"
#include "core/util/quote.h"
#include "core/util/status_macros.h"
#include "server/listen_address.h"
#include "server/metrics_endpoint.h"

namespace splinegrid::cli {
namespace {

// Upper bounds: generous, but far from overflow and from nonsense.
constexpr int64_t kMaxThreads = 1024;
constexpr int64_t kMaxBudgetMb = int64_t{1} << 30;  // 1 PiB; << 20 stays below 2^51
constexpr int64_t kMaxCount = int64_t{1} << 40;
constexpr int64_t kMaxPerPrincipal = 1'000'000;
constexpr int64_t kMaxDecoderMb = int64_t{1} << 20;  // 1 TiB of address space
constexpr int64_t kMaxSeconds = 24 * 3600;           // a day of CPU or wall time

absl::Status CheckRange(const char* flag, int64_t value, int64_t lo, int64_t hi,
                        const char* meaning = "") {
  if (value >= lo && value <= hi) return absl::OkStatus();
  return absl::InvalidArgumentError(
      absl::StrCat("--", flag, " = ", value, " is outside [", lo, ", ", hi, "]", meaning));
}

absl::Status CheckDuration(const char* flag, absl::Duration value, absl::Duration hi) {
  if (value >= absl::ZeroDuration() && value <= hi) return absl::OkStatus();
  return absl::InvalidArgumentError(absl::StrCat("--", flag, " = ", absl::FormatDuration(value),
                                                 " is outside [0, ", absl::FormatDuration(hi),
                                                 "]"));
}

}  // namespace

absl::Status CheckServeFlags(server::LogFormat* format) {
  const std::string address = absl::GetFlag(FLAGS_address);
  if (const absl::StatusOr<int> port = server::ParseListenPort(address, /*min_port=*/1);
      !port.ok()) {
    return absl::InvalidArgumentError(absl::StrCat("--address: ", port.status().message()));
  }
  SG_RETURN_IF_ERROR(
      CheckRange("threads", absl::GetFlag(FLAGS_threads), 0, kMaxThreads, " (0: one per core)"));
  SG_RETURN_IF_ERROR(CheckRange("memory_budget_mb", absl::GetFlag(FLAGS_memory_budget_mb), 0,
                                kMaxBudgetMb, " MiB (0: the default)"));
  // The CGNS decoder child (server/cgns_decoder.h): 0 or at least what it needs to start.
  if (const int64_t mb = absl::GetFlag(FLAGS_cgns_decoder_memory_mb); mb != 0) {
    SG_RETURN_IF_ERROR(CheckRange("cgns_decoder_memory_mb", mb,
                                  server::kMinCgnsDecoderMemoryBytes >> 20, kMaxDecoderMb,
                                  " MiB (or 0: the default)"));
  }
  SG_RETURN_IF_ERROR(CheckRange("cgns_decoder_cpu_seconds",
                                absl::GetFlag(FLAGS_cgns_decoder_cpu_seconds), 1, kMaxSeconds));
  SG_RETURN_IF_ERROR(CheckRange("cgns_decoder_timeout_seconds",
                                absl::GetFlag(FLAGS_cgns_decoder_timeout_seconds), 1, kMaxSeconds));
  SG_RETURN_IF_ERROR(
      CheckRange("max_output_points", absl::GetFlag(FLAGS_max_output_points), 1, kMaxCount));
  SG_RETURN_IF_ERROR(
      CheckRange("keep_revisions", absl::GetFlag(FLAGS_keep_revisions), 1, kMaxPerPrincipal));
  SG_RETURN_IF_ERROR(CheckRange("max_running_long_tasks",
                                absl::GetFlag(FLAGS_max_running_long_tasks), 0, kMaxThreads,
                                " (0: worker threads - 1)"));
  SG_RETURN_IF_ERROR(CheckRange("max_queued_long_calls_per_principal",
                                absl::GetFlag(FLAGS_max_queued_long_calls_per_principal), 1,
                                kMaxPerPrincipal));
  SG_RETURN_IF_ERROR(CheckRange("max_streams_per_principal",
                                absl::GetFlag(FLAGS_max_streams_per_principal), 1,
                                kMaxPerPrincipal));
  SG_RETURN_IF_ERROR(
      CheckDuration("shutdown_grace", absl::GetFlag(FLAGS_shutdown_grace), absl::Hours(24)));
  SG_RETURN_IF_ERROR(
      CheckDuration("drain_notice", absl::GetFlag(FLAGS_drain_notice), absl::Hours(1)));
  SG_RETURN_IF_ERROR(CheckDuration("import_idle_timeout", absl::GetFlag(FLAGS_import_idle_timeout),
                                   absl::Hours(24 * 365)));
  if (const std::string metrics = absl::GetFlag(FLAGS_metrics_address); !metrics.empty()) {
    SG_RETURN_IF_ERROR(server::CheckMetricsAddress(metrics, absl::GetFlag(FLAGS_metrics_insecure)));
  }
  const std::string log_format = absl::GetFlag(FLAGS_log_format);
  if (log_format == "text") {
    *format = server::LogFormat::kText;
  } else if (log_format == "json") {
    *format = server::LogFormat::kJson;
  } else {
    return absl::InvalidArgumentError(
        absl::StrCat("--log_format = ", QuoteClientString(log_format), " is not text or json"));
  }
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
