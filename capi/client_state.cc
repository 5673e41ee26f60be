#include "capi/client_state.h"

#include <cstring>
#include <exception>
#include <new>

#include "absl/strings/str_cat.h"

namespace splinegrid::capi {

void ClientState::SetError(std::string message) {
  std::lock_guard<std::mutex> lock(mu_);
  // A success erases the thread's entry, so a program that starts and ends threads does not
  // grow the map: it holds only the threads whose last call failed.
  if (message.empty()) {
    errors_.erase(std::this_thread::get_id());
  } else {
    errors_[std::this_thread::get_id()] = std::move(message);
  }
}

const char* ClientState::Error() const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto it = errors_.find(std::this_thread::get_id());
  return it == errors_.end() ? "" : it->second.c_str();
}

absl::StatusOr<client::Client*> ClientState::Connected() const {
  if (client_ == nullptr) {
    return absl::FailedPreconditionError("client: not connected (sg_connect failed on it)");
  }
  return client_.get();
}

sg_status ToCode(const absl::Status& status) { return static_cast<sg_status>(status.code()); }

sg_status Guard(ClientState* state, const std::function<absl::Status()>& body) {
  absl::Status status;
  try {
    status = body();
  } catch (const std::bad_alloc&) {
    status = absl::ResourceExhaustedError("out of memory");
  } catch (const std::exception& e) {
    status = absl::InternalError(absl::StrCat("unexpected exception: ", e.what()));
  } catch (...) {
    status = absl::InternalError("unexpected exception");
  }
  if (state != nullptr) {
    try {
      state->SetError(std::string(status.message()));
    } catch (...) {
      // No memory left for the message: the code still says what happened.
    }
  }
  return ToCode(status);
}

absl::Status RequireString(const char* value, const char* field) {
  if (value == nullptr) return absl::InvalidArgumentError(absl::StrCat(field, ": NULL"));
  if (*value == '\0') return absl::InvalidArgumentError(absl::StrCat(field, ": empty"));
  return absl::OkStatus();
}

absl::Status CopyOut(const std::string& value, char* out, size_t size, const char* field) {
  if (out == nullptr) return absl::OkStatus();
  if (value.size() + 1 > size) {
    if (size > 0) out[0] = '\0';
    return absl::OutOfRangeError(absl::StrCat(field, ": capacity ", size, " bytes, \"", value,
                                              "\" needs ", value.size() + 1));
  }
  std::memcpy(out, value.c_str(), value.size() + 1);
  return absl::OkStatus();
}

}  // namespace splinegrid::capi
