// One log line per RPC, written to stderr when the call finishes. Client-supplied strings (the
// grid, the principal, the status message) are escaped and cut, so every call gives exactly one
// line of bounded length whatever the request holds: in text lines C-escaped
// (core/util/quote.h), in JSON lines JSON-escaped once, so that a field's value is the string
// itself (the message as the client received it; invalid UTF-8 as U+FFFD).
//
// LogFormat::kText:
//   2026-11-21T10:00:00.123Z EvaluateGrid grids/wing OK 12.3 ms by alice
//   2026-11-21T10:00:00.123Z GetGrid 'grids/a\nb' INVALID_ARGUMENT 0.1 ms by alice: name = ...
// LogFormat::kJson, one object per line:
//   {"time":"2026-11-21T10:00:00.123Z","method":"GetGrid","grid":"grids/wing",
//    "principal":"alice","status":"OK","ms":0.1,"message":""}
#ifndef SPLINEGRID_SERVER_CALL_LOG_H_
#define SPLINEGRID_SERVER_CALL_LOG_H_

#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"
#include "server/server_options.h"

namespace splinegrid::server {

class CallLog {
 public:
  // Logs as `options` say (log_calls, log_format).
  CallLog(std::string method, std::string grid, const ServerOptions& options)
      : method_(std::move(method)),
        grid_(std::move(grid)),
        enabled_(options.log_calls),
        format_(options.log_format),
        start_(absl::Now()) {}

  void set_grid(std::string grid) { grid_ = std::move(grid); }
  void set_principal(std::string principal) { principal_ = std::move(principal); }

  // Writes the line (once per call) and counts the call in CallMetrics (server/call_metrics.h),
  // also when lines are off.
  void Finish(const absl::Status& status) const;

  // The line Finish writes at `now`, with its newline.
  std::string Line(const absl::Status& status, absl::Time now) const;

 private:
  std::string method_;
  std::string grid_;
  std::string principal_;
  bool enabled_;
  LogFormat format_;
  absl::Time start_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_CALL_LOG_H_
