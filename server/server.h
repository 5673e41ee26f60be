// A running splinegrid server: the SplineGrid service plus grpc.health.v1 (overall and for
// "splinegrid.v1.SplineGrid") and server reflection.
#ifndef SPLINEGRID_SERVER_SERVER_H_
#define SPLINEGRID_SERVER_SERVER_H_

#include <condition_variable>
#include <memory>
#include <mutex>
#include <thread>

#include "absl/status/statusor.h"
#include "grpcpp/grpcpp.h"
#include "server/server_options.h"
#include "server/service.h"

namespace splinegrid::server {

inline constexpr char kServiceName[] = "splinegrid.v1.SplineGrid";

class Server {
 public:
  // Builds, starts and marks the server SERVING. Errors: INVALID_ARGUMENT for bad options,
  // UNAVAILABLE when the address cannot be bound.
  static absl::StatusOr<std::unique_ptr<Server>> Start(const ServerOptions& options);
  ~Server();

  // The bound port (useful with port 0).
  int port() const { return port_; }

  // A channel to this server that bypasses the network (for tests).
  std::shared_ptr<grpc::Channel> InProcessChannel();

  // NOT_SERVING, refuse new calls and end WatchGrid streams (UNAVAILABLE), let in-flight calls
  // finish within
  // options.shutdown_grace, cancel the rest, stop the workers. Idempotent.
  void Shutdown();

  // Blocks until Shutdown has completed.
  void Wait();

  // The drain notice before Shutdown: health turns NOT_SERVING (overall and for kServiceName)
  // and stays so (the store's health no longer changes it), while calls are still accepted and
  // served, so that load balancers and probes stop sending new ones. Idempotent.
  void BeginDrain();

  const ServiceState& state() const { return *state_; }

  // Reads the tokens file again (ServerOptions::tokens_file); on error the previous tokens stay.
  // The number of tokens, or why the file was refused.
  absl::StatusOr<int> ReloadTokens();

 private:
  Server() = default;

  // Health follows the store: NOT_SERVING while it is unavailable (e.g. Redis is down), SERVING
  // again when it returns. Polls until Shutdown.
  void FollowStoreHealth();
  void SetServing(bool serving);

  std::unique_ptr<ServiceState> state_;
  std::unique_ptr<SplineGridService> service_;
  std::unique_ptr<grpc::Server> server_;
  int port_ = 0;
  std::once_flag shutdown_once_;
  std::mutex health_mu_;
  std::condition_variable health_cv_;
  bool stopping_ = false;
  bool drain_begun_ = false;  // BeginDrain was called: health stays NOT_SERVING
  std::thread health_thread_;
};

// Starts a server and runs it until SIGTERM or SIGINT, then drains: NOT_SERVING while calls are
// still accepted for options.drain_notice (Server::BeginDrain; a second SIGTERM or SIGINT cuts
// it short), then Shutdown (new calls refused, in-flight ones get options.shutdown_grace).
// Returns OK after a clean shutdown.
absl::Status RunServerUntilSignal(const ServerOptions& options);

}  // namespace splinegrid::server

#endif  // SPLINEGRID_SERVER_SERVER_H_
