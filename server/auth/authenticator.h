// Turns a call's credentials into a Caller. Without tokens: the peer, as admin.
#ifndef SPLINEGRID_SERVER_AUTH_AUTHENTICATOR_H_
#define SPLINEGRID_SERVER_AUTH_AUTHENTICATOR_H_

#include "absl/status/statusor.h"
#include "grpcpp/grpcpp.h"
#include "server/auth/caller.h"

namespace splinegrid::server {

class Authenticator {
 public:
  Authenticator() = default;

  // The caller of `context`, or UNAUTHENTICATED.
  absl::StatusOr<Caller> Authenticate(const grpc::CallbackServerContext& context) const;
};

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_AUTH_AUTHENTICATOR_H_
