// splinegrid.h: status names, the version, sg_connect and sg_close.
#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>
#include <string>

#include "absl/strings/str_cat.h"
#include "capi/client_state.h"
#include "capi/splinegrid.h"
#include "client/client.h"
#include "core/util/status_macros.h"

namespace {

using splinegrid::capi::ClientState;

// Connects and asks the server's health service, so that a wrong address or a server that is
// down shows at sg_connect rather than at the first real call.
absl::Status Connect(const char* target, const char* token, const char* tls_ca_file,
                     double timeout_seconds, std::unique_ptr<splinegrid::client::Client>* out) {
  namespace client = splinegrid::client;
  if (absl::Status s = splinegrid::capi::RequireString(target, "target"); !s.ok()) return s;
  if (!(timeout_seconds <= 0.0 || timeout_seconds < 1e9)) {  // also NaN
    return absl::InvalidArgumentError(
        absl::StrCat("timeout_seconds: ", timeout_seconds, " (give seconds, or <= 0 for 120)"));
  }
  client::ClientOptions options;
  if (timeout_seconds > 0.0) options.timeout = absl::Seconds(timeout_seconds);
  // A call that breaks off is made again until its deadline, not a fixed number of times: a
  // coupled solver rides out a restart of the server (a trial's C solver gave up 0.76 s into
  // one with a 30 s timeout, after the C++ client's default five attempts).
  options.retry.max_attempts = std::numeric_limits<int>::max();
  // A watch has no deadline: its resumptions keep the bounded default, so that sg_watch_next
  // reports a server that is gone for good.
  options.watch_retry = client::RetryPolicy();
  if (token != nullptr) options.token = token;
  if (tls_ca_file != nullptr && *tls_ca_file != '\0') {
    SG_RETURN_IF_ERROR(client::LoadTlsFiles(tls_ca_file, "", "", &options), "tls_ca_file: ");
  }
  *out = client::Client::Connect(target, options);
  SG_ASSIGN_OR_RETURN(const std::string health, (*out)->Health(), "connect to ", target, ": ");
  if (health != "SERVING") {
    return absl::UnavailableError(absl::StrCat("connect to ", target, ": the server is ", health));
  }
  return absl::OkStatus();
}

}  // namespace

extern "C" {

const char* sg_last_error(const sg_client* client) {
  return client == nullptr ? "" : client->state->Error();
}

size_t sg_last_error_copy(const sg_client* client, char* buffer, size_t size) {
  const char* message = sg_last_error(client);
  const size_t length = std::strlen(message);
  if (buffer != nullptr && size > 0) {
    const size_t n = std::min(length, size - 1);
    std::memcpy(buffer, message, n);
    buffer[n] = '\0';
  }
  return length;
}

const char* sg_status_name(sg_status status) {
  static constexpr const char* kNames[] = {"OK",
                                           "CANCELLED",
                                           "UNKNOWN",
                                           "INVALID_ARGUMENT",
                                           "DEADLINE_EXCEEDED",
                                           "NOT_FOUND",
                                           "ALREADY_EXISTS",
                                           "PERMISSION_DENIED",
                                           "RESOURCE_EXHAUSTED",
                                           "FAILED_PRECONDITION",
                                           "ABORTED",
                                           "OUT_OF_RANGE",
                                           "UNIMPLEMENTED",
                                           "INTERNAL",
                                           "UNAVAILABLE",
                                           "DATA_LOSS",
                                           "UNAUTHENTICATED"};
  if (status < 0 || status >= static_cast<int>(std::size(kNames))) return "UNKNOWN_CODE";
  return kNames[status];
}

const char* sg_version(void) { return SPLINEGRID_VERSION; }

sg_status sg_connect(const char* target, const char* token, const char* tls_ca_file,
                     double timeout_seconds, sg_client** client) {
  if (client == nullptr) return SG_INVALID_ARGUMENT;
  *client = nullptr;
  sg_client* handle = nullptr;
  try {
    handle = new sg_client{std::make_shared<ClientState>(nullptr)};
  } catch (...) {
    return SG_RESOURCE_EXHAUSTED;
  }
  *client = handle;
  return splinegrid::capi::Guard(handle->state.get(), [&]() -> absl::Status {
    std::unique_ptr<splinegrid::client::Client> connected;
    const absl::Status status = Connect(target, token, tls_ca_file, timeout_seconds, &connected);
    // After a failed connect the handle keeps only the message; calls on it are refused.
    if (status.ok()) handle->state->set_client(std::move(connected));
    return status;
  });
}

void sg_close(sg_client* client) { delete client; }

}  // extern "C"
