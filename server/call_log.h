// One log line per RPC: method, grid, status code and milliseconds, written to stderr when the
// call finishes, e.g.
//   2026-11-21T10:00:00.123Z EvaluateGrid grids/wing OK 12.3 ms
#ifndef SPLINEGRID_SERVER_CALL_LOG_H_
#define SPLINEGRID_SERVER_CALL_LOG_H_

#include <string>

#include "absl/status/status.h"
#include "absl/time/time.h"

namespace splinegrid::server {

class CallLog {
 public:
  CallLog(std::string method, std::string grid, bool enabled)
      : method_(std::move(method)),
        grid_(std::move(grid)),
        enabled_(enabled),
        start_(absl::Now()) {}

  void set_grid(std::string grid) { grid_ = std::move(grid); }
  void set_principal(std::string principal) { principal_ = std::move(principal); }

  // Writes the line (once per call).
  void Finish(const absl::Status& status) const;

 private:
  std::string method_;
  std::string grid_;
  std::string principal_;
  bool enabled_;
  absl::Time start_;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_CALL_LOG_H_
