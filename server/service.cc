#include "server/service.h"

#include <chrono>
#include <thread>

#include "absl/strings/escaping.h"
#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/util/quote.h"
#include "core/util/status_macros.h"
#include "proto/convert/convert.h"
#include "server/grid_encoding.h"
#include "server/happens_before.h"

namespace splinegrid::server {
namespace {

int DefaultThreads(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

}  // namespace

ServiceState::ServiceState(const ServerOptions& opts)
    : options(opts),
      budget(opts.memory_budget_bytes),
      streams(opts.max_streams_per_principal),
      pool(SchedulerOptions{
          .threads = DefaultThreads(opts.worker_threads),
          .max_running_long = opts.max_running_long_tasks,
          .max_queued_tasks = opts.max_queued_tasks,
          .max_queued_long_calls_per_principal = opts.max_queued_long_calls_per_principal}) {}

grpc::Status ToGrpcStatus(const absl::Status& status) {
  // Echoes of client strings are cut already (QuoteClientString); this bounds whatever else
  // (e.g. many of them), so that a message never exceeds gRPC's metadata limit.
  constexpr size_t kMaxMessage = 4096;
  std::string message(status.message());
  if (message.size() > kMaxMessage) {
    message =
        absl::StrCat(message.substr(0, kMaxMessage), "... (", status.message().size(), " bytes)");
  }
  return grpc::Status(static_cast<grpc::StatusCode>(status.code()), std::move(message));
}

CancelCheck CallCancelCheck(grpc::CallbackServerContext* context) {
  const auto deadline = context->deadline();
  return [context, deadline] {
    return context->IsCancelled() || std::chrono::system_clock::now() > deadline;
  };
}

absl::Status WhyCallEnded(const ServiceState& state, grpc::CallbackServerContext* context) {
  if (state.draining.load()) return absl::UnavailableError("the server is shutting down");
  if (std::chrono::system_clock::now() > context->deadline()) {
    return absl::DeadlineExceededError("the call's deadline passed before the work was done");
  }
  return absl::CancelledError("the client cancelled");
}

absl::Status ExplainCancellation(const ServiceState& state, grpc::CallbackServerContext* context,
                                 absl::Status status) {
  if (status.code() != absl::StatusCode::kCancelled) return status;
  return WhyCallEnded(state, context);
}

absl::StatusOr<std::string> ParseGridName(const std::string& name, const std::string& field) {
  constexpr char kPrefix[] = "grids/";
  if (name.rfind(kPrefix, 0) != 0 || !IsValidGridId(name.substr(sizeof(kPrefix) - 1))) {
    return absl::InvalidArgumentError(
        absl::StrCat(field, " = ", QuoteClientString(name),
                     " is not a grid name (grids/{id}, id of [a-z0-9-], 1-63 chars)"));
  }
  return name.substr(sizeof(kPrefix) - 1);
}

absl::StatusOr<Caller> AdmitCall(const ServiceState& state, grpc::CallbackServerContext* context,
                                 Role needed, CallLog* log) {
  if (state.draining.load()) return absl::UnavailableError("the server is shutting down");
  absl::StatusOr<Caller> authenticated = state.authenticator.Authenticate(*context);
  if (!authenticated.ok()) {
    // A refused token's line names where it came from (no principal is known).
    log->set_principal(state.authenticator.Connection(*context));
    return authenticated.status();
  }
  Caller caller = *std::move(authenticated);
  log->set_principal(caller.principal);
  if (caller.role < needed) {
    return absl::PermissionDeniedError(absl::StrCat("this call needs the role ", RoleName(needed),
                                                    "; the caller has ", RoleName(caller.role)));
  }
  return caller;
}

absl::StatusOr<AdmittedStream> AdmitStream(ServiceState& state,
                                           grpc::CallbackServerContext* context, Role needed,
                                           CallLog* log) {
  SG_ASSIGN_OR_RETURN(Caller caller, AdmitCall(state, context, needed, log));
  SG_ASSIGN_OR_RETURN(StreamSlot slot, state.streams.Open(caller.principal));
  return AdmittedStream{std::move(caller), std::move(slot)};
}

namespace {

// Finishes a unary call: its status (a cancellation explained), logged.
std::function<void(const absl::Status&)> Finisher(const ServiceState* state,
                                                  grpc::ServerUnaryReactor* reactor,
                                                  grpc::CallbackServerContext* context,
                                                  CallLog log) {
  return [state, reactor, context, log = std::move(log)](const absl::Status& status) {
    const absl::Status explained = ExplainCancellation(*state, context, status);
    log.Finish(explained);
    reactor->Finish(ToGrpcStatus(explained));
  };
}

}  // namespace

grpc::ServerUnaryReactor* SplineGridService::RunOnPool(grpc::CallbackServerContext* context,
                                                       CallLog log, Role needed, WorkKind kind,
                                                       Work work) {
  return RunSizedOnPool(context, std::move(log), needed, kind, nullptr, std::move(work));
}

grpc::ServerUnaryReactor* SplineGridService::RunSizedOnPool(grpc::CallbackServerContext* context,
                                                            CallLog log, Role needed, WorkKind kind,
                                                            SizeUp size_up, Work work) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::StatusOr<Caller> caller = AdmitCall(*state_, context, needed, &log);
  if (!caller.ok()) {
    log.Finish(caller.status());
    reactor->Finish(ToGrpcStatus(caller.status()));
    return reactor;
  }
  SG_HAPPENS_BEFORE(reactor);
  const std::string principal = caller->principal;
  auto finish = Finisher(state_, reactor, context, std::move(log));
  auto task = [state = state_, reactor, caller = *std::move(caller), size_up = std::move(size_up),
               work = std::move(work), finish] {
    SG_HAPPENS_AFTER(reactor);
    // Unsized work runs here. An error of the sizing (the grid is not there, say) is left to
    // `work`, which fails early with the answer and the precedence of its own checks
    // (ownership before a bad reference).
    const absl::StatusOr<bool> small = size_up ? size_up(caller) : true;
    if (!small.ok() || *small) {
      finish(work(caller));
      return;
    }
    SG_HAPPENS_BEFORE(reactor);
    auto long_task = [reactor, caller, work, finish] {
      SG_HAPPENS_AFTER(reactor);
      finish(work(caller));
    };
    // Counted as the caller's new long call (max_queued_long_calls_per_principal), as it would
    // have been had it been known to be long at admission.
    if (absl::Status status =
            state->pool.TrySubmit(caller.principal, WorkKind::kLong, std::move(long_task));
        !status.ok()) {
      finish(status);
    }
  };
  if (absl::Status status = state_->pool.TrySubmit(principal, kind, std::move(task));
      !status.ok()) {
    finish(status);
  }
  return reactor;
}

grpc::ServerUnaryReactor* SplineGridService::RunInline(grpc::CallbackServerContext* context,
                                                       CallLog log, Role needed, const Work& work) {
  grpc::ServerUnaryReactor* reactor = context->DefaultReactor();
  absl::StatusOr<Caller> caller = AdmitCall(*state_, context, needed, &log);
  const absl::Status status = caller.ok() ? work(*caller) : caller.status();
  log.Finish(status);
  reactor->Finish(ToGrpcStatus(status));
  return reactor;
}

ops::OpsContext SplineGridService::Ops(const Caller& caller) const {
  ops::OpsContext context = state_->Ops();
  if (caller.role < Role::kAdmin) {
    context.may_change = [caller](const std::string& owner, const std::string& name,
                                  absl::string_view action) {
      return MayChangeGrid(caller, owner, name, action);
    };
  }
  return context;
}

grpc::ServerUnaryReactor* SplineGridService::GetGrid(grpc::CallbackServerContext* context,
                                                     const v1::GetGridRequest* request,
                                                     v1::Grid* response) {
  CallLog log("GetGrid", request->name(), state_->options);
  auto work = [this, request, response](const Caller&) -> absl::Status {
    SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request->name(), "name"));
    SG_ASSIGN_OR_RETURN(const std::shared_ptr<const StoredGrid> grid, state_->store->Get(id));
    const std::vector<int> blocks(request->blocks().begin(), request->blocks().end());
    int64_t revision = request->revision();
    if (request->has_step()) {
      SG_ASSIGN_OR_RETURN(const std::shared_ptr<const GridRevision> found,
                          grid->ResolveRevision(revision, OptionalStep(*request)));
      revision = found->number;
    }
    return EncodeGrid(*grid, revision, request->view(), blocks, response,
                      /*with_connectivity=*/true);
  };
  // Encoding a FULL view copies control nets: pool work; the basic view is a lookup.
  if (request->view() == v1::GRID_VIEW_FULL) {
    return RunOnPool(context, log, Role::kRead, WorkKind::kCheap, work);
  }
  return RunInline(context, log, Role::kRead, work);
}

grpc::ServerUnaryReactor* SplineGridService::ListGrids(grpc::CallbackServerContext* context,
                                                       const v1::ListGridsRequest* request,
                                                       v1::ListGridsResponse* response) {
  CallLog log("ListGrids", "", state_->options);
  auto work = [this, request, response](const Caller&) -> absl::Status {
    const int size = request->page_size();
    if (size < 0 || size > 1000) {
      return absl::InvalidArgumentError(
          absl::StrCat("page_size = ", size, " is outside [0, 1000]"));
    }
    std::string after;
    if (!request->page_token().empty() &&
        (!absl::WebSafeBase64Unescape(request->page_token(), &after) || !IsValidGridId(after))) {
      return absl::InvalidArgumentError(
          absl::StrCat("page_token = ", QuoteClientString(request->page_token()),
                       " is not a token of ListGrids"));
    }
    bool more = false;
    SG_ASSIGN_OR_RETURN(const auto page, state_->store->List(after, size == 0 ? 50 : size, &more));
    for (const auto& grid : page) {
      SG_RETURN_IF_ERROR(EncodeGrid(*grid, 0, v1::GRID_VIEW_BASIC, {}, response->add_grids()));
    }
    if (more && !page.empty()) {
      response->set_next_page_token(absl::WebSafeBase64Escape(page.back()->id));
    }
    return absl::OkStatus();
  };
  return RunInline(context, log, Role::kRead, work);
}

grpc::ServerUnaryReactor* SplineGridService::DeleteGrid(grpc::CallbackServerContext* context,
                                                        const v1::DeleteGridRequest* request,
                                                        google::protobuf::Empty* /*response*/) {
  CallLog log("DeleteGrid", request->name(), state_->options);
  auto work = [this, request](const Caller& caller) -> absl::Status {
    SG_ASSIGN_OR_RETURN(const std::string id, ParseGridName(request->name(), "name"));
    GridStore::DeleteCheck check;
    if (caller.role < Role::kAdmin) {  // a writer deletes only its own grids
      check = [&](const std::string& owner) {
        return MayChangeGrid(caller, owner, request->name(), "deleting");
      };
    }
    SG_RETURN_IF_ERROR(state_->store->Delete(id, check));
    state_->deformers.Forget(DeformerKeyPrefix(id));
    return absl::OkStatus();
  };
  return RunInline(context, log, Role::kWrite, work);
}

}  // namespace splinegrid::server
