#include "server/server.h"

#include <signal.h>

#include <cstdio>
#include <thread>

#include "absl/strings/str_cat.h"
#include "grpcpp/ext/proto_server_reflection_plugin.h"
#include "grpcpp/health_check_service_interface.h"
#include "server/auth/transport.h"
#include "server/listen_address.h"
#include "server/memory_limit.h"
#include "server/metrics_endpoint.h"
#include "server/metrics_text.h"
#include "server/store/open_store.h"
#include "server/store/redis_connection.h"

namespace splinegrid::server {

absl::StatusOr<std::unique_ptr<Server>> Server::Start(const ServerOptions& options) {
  if (options.worker_threads < 0 || options.max_queued_tasks < 1 ||
      options.memory_budget_bytes < 0 || options.max_output_points < 1 ||
      options.max_deform_revisions < 1 || options.max_watch_lag < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "server options out of range: worker_threads = ", options.worker_threads,
        ", max_queued_tasks = ", options.max_queued_tasks, ", memory_budget_bytes = ",
        options.memory_budget_bytes, ", max_output_points = ", options.max_output_points,
        ", max_deform_revisions = ", options.max_deform_revisions,
        ", max_watch_lag = ", options.max_watch_lag));
  }
  if (options.max_running_long_tasks < 0 ||
      (options.worker_threads > 0 && options.max_running_long_tasks > options.worker_threads) ||
      options.max_queued_long_calls_per_principal < 1 || options.max_streams_per_principal < 1) {
    return absl::InvalidArgumentError(absl::StrCat(
        "scheduling options out of range: max_running_long_tasks = ",
        options.max_running_long_tasks, " (0 or [1, worker_threads = ", options.worker_threads,
        "]), max_queued_long_calls_per_principal = ", options.max_queued_long_calls_per_principal,
        " (>= 1), max_streams_per_principal = ", options.max_streams_per_principal, " (>= 1)"));
  }
  if (!options.address.empty()) {
    const absl::StatusOr<int> port = ParseListenPort(options.address, /*min_port=*/0);
    if (!port.ok()) {
      return absl::InvalidArgumentError(absl::StrCat("address: ", port.status().message()));
    }
    // A busy port is refused here, in one line and before the store is opened; gRPC's own
    // refusal below (a race lost after this check) comes after a page of its log.
    if (absl::Status free = CheckCanListen(options.address); !free.ok()) return free;
  }
  if (options.drain_notice < absl::ZeroDuration() ||
      options.shutdown_grace < absl::ZeroDuration()) {
    return absl::InvalidArgumentError(absl::StrCat(
        "drain_notice = ", absl::FormatDuration(options.drain_notice), " and shutdown_grace = ",
        absl::FormatDuration(options.shutdown_grace), " must not be negative"));
  }
  absl::StatusOr<std::shared_ptr<grpc::ServerCredentials>> credentials =
      MakeServerCredentials(options);
  if (!credentials.ok()) return credentials.status();
  grpc::EnableDefaultHealthCheckService(true);
  grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  std::unique_ptr<Server> server(new Server());
  // 0: the default budget, a share of the memory limit (server/memory_limit.h).
  ServerOptions resolved = options;
  resolved.memory_budget_bytes = ResolveMemoryBudget(options.memory_budget_bytes).bytes;
  server->state_ = std::make_unique<ServiceState>(resolved);
  if (!options.tokens_file.empty()) {
    absl::StatusOr<int> tokens = server->state_->authenticator.LoadTokens(options.tokens_file);
    if (!tokens.ok()) return tokens.status();
  }
  absl::StatusOr<TrustedProxies> proxies = TrustedProxies::Parse(options.trusted_proxies);
  if (!proxies.ok()) return proxies.status();
  server->state_->authenticator.SetTrustedProxies(*std::move(proxies));
  absl::StatusOr<std::unique_ptr<GridStore>> store = OpenStore(options, &server->state_->budget);
  if (!store.ok()) return store.status();
  server->state_->store = *std::move(store);
  server->service_ = std::make_unique<SplineGridService>(server->state_.get());
  grpc::ServerBuilder builder;
  // gRPC sets SO_REUSEPORT by default, so a second server on a busy port would start and share
  // its connections with the first: refuse the port instead.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  if (!options.address.empty()) {
    builder.AddListeningPort(options.address, *credentials, &server->port_);
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

absl::StatusOr<int> Server::ReloadTokens() {
  absl::StatusOr<int> tokens = state_->authenticator.Reload();
  // Open watches check their tokens again: one whose token went or lost its role ends now.
  if (tokens.ok()) state_->watches.WakeAll();
  return tokens;
}

void Server::SetServing(bool serving) {
  grpc::HealthCheckServiceInterface* health = server_->GetHealthCheckService();
  health->SetServingStatus(serving);
  health->SetServingStatus(kServiceName, serving);
}

void Server::FollowStoreHealth() {
  bool serving = state_->store->Available().ok();
  std::unique_lock<std::mutex> lock(health_mu_);
  while (!health_cv_.wait_for(lock, std::chrono::milliseconds(250), [this] { return stopping_; })) {
    if (drain_begun_) continue;  // NOT_SERVING until the end
    // Without the lock: a dir: store may probe its disk here, which must not hold up Shutdown.
    lock.unlock();
    const absl::Status available = state_->store->Available();
    lock.lock();
    if (stopping_ || drain_begun_) continue;
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

void Server::BeginDrain() {
  std::lock_guard<std::mutex> lock(health_mu_);
  if (!server_ || drain_begun_ || stopping_) return;
  drain_begun_ = true;
  SetServing(false);
}

void Server::Wait() {
  if (server_) server_->Wait();
}

namespace {

// Waits up to `timeout` for SIGTERM or SIGINT among the blocked `signals` (others that arrive
// meanwhile are taken and ignored).
void WaitForStopSignal(const sigset_t& signals, absl::Duration timeout) {
  const absl::Time end = absl::Now() + timeout;
  for (absl::Duration left = timeout; left > absl::ZeroDuration(); left = end - absl::Now()) {
    const timespec wait = absl::ToTimespec(left);
    const int received = sigtimedwait(&signals, nullptr, &wait);
    if (received == SIGTERM || received == SIGINT) return;
  }
}

}  // namespace

absl::Status RunServerUntilSignal(const ServerOptions& options) {
  // Block the signals in every thread (gRPC's and the pool's inherit the mask) and take them
  // synchronously in this one.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);  // reloads the tokens file
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  absl::StatusOr<std::unique_ptr<Server>> server = Server::Start(options);
  if (!server.ok()) return server.status();
  // Everything that can fail at start comes before the banner, which says the server is up.
  // The metrics endpoint lives from here until the server has shut down: scrapes see the drain.
  std::unique_ptr<MetricsEndpoint> metrics;
  if (!options.metrics_address.empty()) {
    const ServiceState* state = &(*server)->state();
    absl::StatusOr<std::unique_ptr<MetricsEndpoint>> started = MetricsEndpoint::Start(
        options.metrics_address, options.metrics_insecure, [state] { return MetricsText(*state); });
    if (!started.ok()) {
      (*server)->Shutdown();
      return started.status();
    }
    metrics = *std::move(started);
  }
  std::fprintf(stderr,
               "splinegrid serving on port %d (%s), store %s, %d workers, memory budget %s, "
               "import idle timeout %s, keeps the newest %d deformed revisions of a grid "
               "(--keep_revisions)\n",
               (*server)->port(), options.address.c_str(), RedactRedisSpec(options.store).c_str(),
               (*server)->state().pool.num_threads(),
               ResolveMemoryBudget(options.memory_budget_bytes).description.c_str(),
               options.import_idle_timeout > absl::ZeroDuration()
                   ? absl::FormatDuration(options.import_idle_timeout).c_str()
                   : "none",
               options.max_deform_revisions);
  const int num_tokens = (*server)->state().authenticator.num_tokens();
  std::fprintf(stderr, "splinegrid: %s, %s\n", TransportName(options).c_str(),
               num_tokens == 0 ? "no tokens (every caller is an admin)"
                               : absl::StrCat(num_tokens, " tokens from ", options.tokens_file,
                                              " (SIGHUP reloads)")
                                     .c_str());
  if (num_tokens > 0 && options.insecure && options.tls_cert_file.empty()) {
    std::fprintf(stderr,
                 "splinegrid: warning: bearer tokens travel in plaintext (--insecure without "
                 "TLS): anyone on the network path can read and reuse them\n");
  }
  if (metrics) {
    std::fprintf(stderr, "splinegrid: metrics on port %d (%s, GET /metrics, plaintext HTTP)\n",
                 metrics->port(), options.metrics_address.c_str());
  }
  int received = 0;
  while (sigwait(&signals, &received) == 0 && received == SIGHUP) {
    const absl::StatusOr<int> tokens = (*server)->ReloadTokens();
    const std::string outcome = tokens.ok()
                                    ? absl::StrCat("tokens reloaded: ", *tokens, " tokens")
                                    : absl::StrCat("tokens not reloaded, the previous ones stay: ",
                                                   tokens.status().message());
    std::fprintf(stderr, "splinegrid: SIGHUP received: %s\n", outcome.c_str());
  }
  // The notice is for orchestrators and load balancers, which stop a server with SIGTERM; an
  // interactive Ctrl-C (SIGINT) stops at once.
  const char* signal_name = received == SIGTERM ? "SIGTERM" : "SIGINT";
  if (received == SIGTERM && options.drain_notice > absl::ZeroDuration()) {
    (*server)->BeginDrain();
    std::fprintf(stderr,
                 "splinegrid: SIGTERM received: NOT_SERVING, still accepting calls for %s "
                 "(--drain_notice; a second signal ends it)\n",
                 absl::FormatDuration(options.drain_notice).c_str());
    WaitForStopSignal(signals, options.drain_notice);
  }
  std::fprintf(stderr,
               "splinegrid: %s received: refusing new calls, in-flight ones get up to %s, then "
               "stopping\n",
               signal_name, absl::FormatDuration(options.shutdown_grace).c_str());
  (*server)->Shutdown();
  metrics.reset();  // before the state its scrapes read
  server->reset();
  std::fprintf(stderr, "splinegrid: stopped\n");
  return absl::OkStatus();
}

}  // namespace splinegrid::server
