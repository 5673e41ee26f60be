// What the C API's handles hold (splinegrid.h): a C++ client shared by the client handle and
// its watches, with the error message of each thread's last call, and the guard every C entry
// point runs its body under (status code + message, no exception across the C boundary).
#ifndef SPLINEGRID_CAPI_CLIENT_STATE_H_
#define SPLINEGRID_CAPI_CLIENT_STATE_H_

#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "capi/splinegrid.h"
#include "client/client.h"

namespace splinegrid::capi {

// A connection and the messages of the calls made on it, one per calling thread: a message
// returned by sg_last_error stays valid while other threads fail (std::map nodes never move).
class ClientState {
 public:
  // `client` may be null (a failed sg_connect keeps the handle for its message).
  explicit ClientState(std::unique_ptr<client::Client> client) : client_(std::move(client)) {}

  // Set once, by sg_connect, before the handle is returned.
  void set_client(std::unique_ptr<client::Client> client) { client_ = std::move(client); }

  // The client to call: FAILED_PRECONDITION when sg_connect failed on this handle.
  absl::StatusOr<client::Client*> Connected() const;

  // The calling thread's message: "" after a success.
  void SetError(std::string message);
  const char* Error() const;

 private:
  std::unique_ptr<client::Client> client_;
  mutable std::mutex mu_;
  std::map<std::thread::id, std::string> errors_;
};

// `status`'s code as an sg_status.
sg_status ToCode(const absl::Status& status);

// Runs `body` for a C entry point: records its status's message on `state` (when not null) for
// the calling thread and returns its code. An exception (std::bad_alloc above all) becomes
// RESOURCE_EXHAUSTED or INTERNAL with its what().
sg_status Guard(ClientState* state, const std::function<absl::Status()>& body);

// The string argument `value` named `field` ("grid", "path"), which must be non-null and
// non-empty: INVALID_ARGUMENT naming it otherwise.
absl::Status RequireString(const char* value, const char* field);

// Copies `value` into `out` (`size` bytes, NUL-terminated) when `out` is not null:
// OUT_OF_RANGE naming `field` when it does not fit.
absl::Status CopyOut(const std::string& value, char* out, size_t size, const char* field);

}  // namespace splinegrid::capi

// The handles of splinegrid.h.
struct sg_client {
  std::shared_ptr<splinegrid::capi::ClientState> state;
};

struct sg_watch {
  std::shared_ptr<splinegrid::capi::ClientState> state;  // keeps the connection open
  std::unique_ptr<splinegrid::client::RevisionStream> stream;
  bool ended = false;
};

#endif  // SPLINEGRID_CAPI_CLIENT_STATE_H_
