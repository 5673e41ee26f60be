// Requests that do not decode are answered INVALID_ARGUMENT with a message, not gRPC's bare
// UNIMPLEMENTED.
//
// gRPC's callback handlers (grpcpp/impl/codegen/server_callback_handlers.h) fail a call whose
// request does not parse with Status(UNIMPLEMENTED, "") before any of our code runs, and a
// client-stream message that does not parse ends the reads as if the client had closed its side.
// So the service registers its methods with handlers over Decoded<Request> instead of Request:
// decoding a Decoded<Request> always succeeds as far as gRPC can tell, and records in `status`
// whether the bytes parsed as a Request. SplineGridService::DecodeRequests (request_decoding.cc)
// puts such a handler in front of every method: a unary or server-streaming call whose request
// does not decode is answered INVALID_ARGUMENT without reaching its handler; otherwise the typed
// handler runs on `message` as before. Client-streaming reactors read Decoded<Request> and fail
// the call on the first message that does not decode.
#ifndef SPLINEGRID_SERVER_DECODED_REQUEST_H_
#define SPLINEGRID_SERVER_DECODED_REQUEST_H_

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"
#include "grpcpp/impl/codegen/proto_utils.h"
#include "grpcpp/support/byte_buffer.h"

namespace splinegrid::server {

// A request message and whether it decoded.
template <typename Message>
struct Decoded {
  Message message;
  // INVALID_ARGUMENT "the request does not decode as splinegrid.v1.XRequest" when the bytes did
  // not parse (then `message` holds whatever parsed before the error).
  absl::Status status;
};

}  // namespace splinegrid::server

namespace grpc {

// Decodes into Decoded<Message>::message and reports success to gRPC whatever the outcome (see
// above). Serialize is there for completeness: requests are only decoded on the server.
template <typename Message>
class SerializationTraits<splinegrid::server::Decoded<Message>, void> {
 public:
  static Status Serialize(const splinegrid::server::Decoded<Message>& decoded, ByteBuffer* buffer,
                          bool* own_buffer) {
    return SerializationTraits<Message>::Serialize(decoded.message, buffer, own_buffer);
  }

  static Status Deserialize(ByteBuffer* buffer, splinegrid::server::Decoded<Message>* decoded) {
    const Status parsed = SerializationTraits<Message>::Deserialize(buffer, &decoded->message);
    decoded->status =
        parsed.ok() ? absl::OkStatus()
                    : absl::InvalidArgumentError(absl::StrCat("the request does not decode as ",
                                                              Message::descriptor()->full_name()));
    return Status::OK;
  }
};

}  // namespace grpc

#endif  // SPLINEGRID_SERVER_DECODED_REQUEST_H_
