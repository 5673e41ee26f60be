// The `serve` flags checked before a server is built: every number in its range, the port of
// --address in 1-65535, so that a mistyped flag stops the server with a message naming the flag
// and its value instead of wrapping around (--memory_budget_mb << 20) or being taken modulo.
#ifndef SPLINEGRID_CLIENT_CLI_SERVE_FLAGS_H_
#define SPLINEGRID_CLIENT_CLI_SERVE_FLAGS_H_

#include "absl/status/status.h"
#include "server/server_options.h"

namespace splinegrid::cli {

// INVALID_ARGUMENT "--flag = value is outside [lo, hi] (...)" for the first serve flag out of
// range; --log_format parsed into `*format`.
absl::Status CheckServeFlags(server::LogFormat* format);

}  // namespace splinegrid::cli

#endif  // SPLINEGRID_CLIENT_CLI_SERVE_FLAGS_H_
