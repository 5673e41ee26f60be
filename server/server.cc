#include "server/server.h"

#include <signal.h>

#include <cstdio>
#include <thread>

#include "absl/strings/str_cat.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "server/store/open_store.h"

namespace splinegrid::server {

absl::StatusOr<std::unique_ptr<Server>> Server::Start(const ServerOptions& options) {
  if (options.worker_threads < 0 || options.max_queued_tasks < 1 ||
      options.memory_budget_bytes < 1 || options.max_output_points < 1 ||
      options.max_deform_revisions < 1 || options.max_watch_lag < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "server options out of range: worker_threads = ", options.worker_threads,
        ", max_queued_tasks = ", options.max_queued_tasks, ", memory_budget_bytes = ",
        options.memory_budget_bytes, ", max_output_points = ", options.max_output_points,
        ", max_deform_revisions = ", options.max_deform_revisions,
        ", max_watch_lag = ", options.max_watch_lag));
  }
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  std::unique_ptr<Server> server(new Server());
  server->state_ = std::make_unique<ServiceState>(options);
  absl::StatusOr<std::unique_ptr<GridStore>> store = OpenStore(options, &server->state_->budget);
  if (!store.ok()) return store.status();
  server->state_->store = *std::move(store);
  server->service_ = std::make_unique<SplineGridService>(server->state_.get());
  grpc::ServerBuilder builder;
  // gRPC sets SO_REUSEPORT by default, so a second server on a busy port would start and share
  // its connections with the first: refuse the port instead.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  if (!options.address.empty()) {
    builder.AddListeningPort(options.address, grpc::InsecureServerCredentials(), &server->port_);
  }
  builder.RegisterService(server->service_.get());
  server->server_ = builder.BuildAndStart();
  if (!server->server_ || (!options.address.empty() && server->port_ == 0)) {
    return absl::UnavailableError(absl::StrCat(
        "cannot listen on ", options.address,
        " (is another server using the port? the address must be HOST:PORT of this machine)"));
  }
  server->SetServing(server->state_->store->Available().ok());
  server->health_thread_ = std::thread([s = server.get()] { s->FollowStoreHealth(); });
  return server;
}

Server::~Server() { Shutdown(); }

void Server::SetServing(bool serving) {
  grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService();
  health->SetServingStatus(serving);
  health->SetServingStatus(kServiceName, serving);
}

void Server::FollowStoreHealth() {
  bool serving = state_->store->Available().ok();
  std::unique_lock<std::mutex> lock(health_mu_);
  while (!health_cv_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stopping_; })) {
    const absl::Status available = state_->store->Available();
    if (available.ok() == serving) continue;
    serving = available.ok();
    SetServing(serving);
    std::fprintf(
        stderr, "splinegrid: %s\n",
        serving ? "the store is available again: SERVING"
                : absl::StrCat("the store is unavailable (", available.message(), "): NOT_SERVING")
                      .c_str());
  }
}

std::shared_ptr<grpc::Channel> Server::InProcessChannel() {
  return server_->InProcessChannel(grpc::ChannelArguments());
}

void Server::Shutdown() {
  std::call_once(shutdown_once_, [this] {
    if (!server_) return;
    {
      std::lock_guard<std::mutex> lock(health_mu_);
      stopping_ = true;
    }
    health_cv_.notify_all();
    if (health_thread_.joinable()) health_thread_.join();
    SetServing(false);
    state_->draining.store(true);
    // Watches would otherwise wait for revisions until the grace period ends: end them now
    // (UNAVAILABLE); new ones are refused.
    state_->store->CloseSubscriptions();
    server_->Shutdown(std::chrono::system_clock::now() +
                      absl::ToChronoNanoseconds(state_->options.shutdown_grace));
    server_->Wait();
    // Every call has finished; the workers have nothing left but returning from their last
    // task. Joining them here orders all their work before the service is destroyed.
    state_->pool.Stop();
  });
}

void Server::Wait() {
  if (server_) server_->Wait();
}

absl::Status RunServerUntilSignal(const ServerOptions& options) {
  // Block the signals in every thread (gRPC's and the pool's inherit the mask) and take them
  // synchronously in this one.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  absl::StatusOr<std::unique_ptr<Server>> server = Server::Start(options);
  if (!server.ok()) return server.status();
  std::fprintf(stderr,
               "splinegrid serving on port %d (%s), store %s, %d workers, memory budget %lld MiB\n",
               (*server)->port(), options.address.c_str(), options.store.c_str(),
               (*server)->state().pool.num_threads(),
               static_cast<long long>(options.memory_budget_bytes >> 20));
  int received = 0;
  sigwait(&signals, &received);
  std::fprintf(stderr, "splinegrid: %s received: draining (up to %s) and shutting down\n",
               received == SIGTERM ? "SIGTERM" : "SIGINT",
               absl::FormatDuration(options.shutdown_grace).c_str());
  (*server)->Shutdown();
  server->reset();
  std::fprintf(stderr, "splinegrid: stopped\n");
  return absl::OkStatus();
}

}  // namespace splinegrid::server
