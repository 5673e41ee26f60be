#include "server/metrics_text.h"

#include <unistd.h>

#include <cstdint>
#include <fstream>

#include "absl/strings/str_cat.h"
#include "server/call_metrics.h"

namespace splinegrid::server {
namespace {

void Gauge(std::string* out, absl::string_view name, absl::string_view help, int64_t value) {
  absl::StrAppend(out, "# HELP ", name, " ", help, "\n# TYPE ", name, " gauge\n", name, " ",
                  value, "\n");
}

// Grids and revisions held by the store (GridStore::Count: no listing, no revision read); a
// store that cannot count (Redis down) gives no lines rather than a wrong zero, and a count the
// store does not keep (revisions in Redis) no line either.
void AppendStoreGauges(const ServiceState& state, std::string* out) {
  absl::StatusOr<GridStore::Counts> counts = state.store->Count();
  if (!counts.ok()) return;
  Gauge(out, "splinegrid_grids", "Grids held by the store.", counts->grids);
  if (counts->revisions) {
    Gauge(out, "splinegrid_revisions", "Revisions held by the store, all grids together.",
          *counts->revisions);
  }
}

// Resident set size from /proc/self/statm (pages), or -1 where there is none.
int64_t ResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  int64_t size = 0, resident = 0;
  if (!(statm >> size >> resident)) return -1;
  return resident * static_cast<int64_t>(sysconf(_SC_PAGESIZE));
}

}  // namespace

std::string EscapeLabelValue(absl::string_view value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\' || c == '"') {
      out.push_back('\\');
      out.push_back(c);
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out.push_back(c);
    }
  }
  return out;
}

std::string MetricsText(const ServiceState& state) {
  std::string out;
  CallMetrics::Global().AppendText(&out);
  AppendStoreGauges(state, &out);
  Gauge(&out, "splinegrid_memory_budget_used_bytes",
        "Bytes reserved against the memory budget: stored grids and work in flight.",
        state.budget.used());
  Gauge(&out, "splinegrid_memory_budget_limit_bytes", "The memory budget (--memory_budget_mb).",
        state.budget.limit());
  const Scheduler::QueueLengths queues = state.pool.queue_lengths();
  absl::StrAppend(&out,
                  "# HELP splinegrid_scheduler_queued_tasks Tasks waiting for a worker, by kind "
                  "(cheap go first; long are shared fairly across callers).\n"
                  "# TYPE splinegrid_scheduler_queued_tasks gauge\n"
                  "splinegrid_scheduler_queued_tasks{kind=\"cheap\"} ",
                  queues.cheap, "\nsplinegrid_scheduler_queued_tasks{kind=\"long\"} ",
                  queues.long_tasks, "\n");
  // Per caller only with a tokens file: its principals are a fixed set of names. Without one the
  // principal is the peer's address and port, a new label value (a new series) per connection.
  if (state.authenticator.num_tokens() > 0) {
    absl::StrAppend(&out,
                    "# HELP splinegrid_scheduler_queued_long_tasks Long tasks waiting, by caller "
                    "(callers with none are not listed).\n"
                    "# TYPE splinegrid_scheduler_queued_long_tasks gauge\n");
    for (const auto& [principal, count] : queues.long_by_principal) {
      absl::StrAppend(&out, "splinegrid_scheduler_queued_long_tasks{principal=\"",
                      EscapeLabelValue(principal), "\"} ", count, "\n");
    }
  }
  Gauge(&out, "splinegrid_scheduler_workers", "Worker threads.", state.pool.num_threads());
  Gauge(&out, "splinegrid_open_streams",
        "Streaming calls open (WatchGrid, EvaluateGrid, ImportGrid, ExportGrid, ImportArchive).",
        state.streams.open_total());
  Gauge(&out, "splinegrid_draining", "1 once the server began shutting down, else 0.",
        state.draining.load() ? 1 : 0);
  if (const int64_t rss = ResidentBytes(); rss >= 0) {
    Gauge(&out, "process_resident_memory_bytes", "Resident memory size in bytes.", rss);
  }
  return out;
}

}  // namespace splinegrid::server
