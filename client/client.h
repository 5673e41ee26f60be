// A C++ client of the splinegrid.v1 service: StatusOr results, a deadline on every call, and
// streaming kept inside (uploads in 1 MiB pieces, results reassembled from chunks).
#ifndef SPLINEGRID_CLIENT_CLIENT_H_
#define SPLINEGRID_CLIENT_CLIENT_H_

#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/time/time.h"
#include "client/retry.h"
#include "core/grid/structured_grid.h"
#include "grpcpp/grpcpp.h"
#include "splinegrid/v1/splinegrid_service.grpc.pb.h"

namespace splinegrid::client {

// The header naming the grid a call is about ("naca" for grids/naca), sent with every call that
// names one (and with imports and GenerateGrid when the new id is given): a balancer in front
// of several replicas hashes on it, so the calls about one grid go to one replica.
inline constexpr char kGridRoutingHeader[] = "x-splinegrid-grid";
// WatchGrid's initial metadata: where the stream begins and which creation of the id it
// watches (the proto's WatchGrid), for resuming it.
inline constexpr char kWatchAfterHeader[] = "x-splinegrid-watch-after";
inline constexpr char kIncarnationHeader[] = "x-splinegrid-incarnation";

struct ClientOptions {
  // Deadline of every call, measured from its start; retries run within it.
  absl::Duration timeout = absl::Seconds(120);
  // Calls that break off (BrokeOff: UNAVAILABLE because a replica died, a balancer had no
  // upstream or the server is restarting; INTERNAL "RST_STREAM" from a balancer whose upstream
  // died mid-stream) are made again: every call from its start (EvaluateGrid and ExportGrid
  // drop what had arrived, uploads are sent again whole), WatchGrid resumed after the last
  // revision received (RevisionStream). Health checks are not retried (a probe answers for
  // now). The channel of Connect() also reconnects at this pace (initial/max backoff).
  //
  // An attempt whose answer was lost may still have been carried out, so a retried call that
  // stores something can meet its own earlier attempt: DeformGrid with a base_revision answers
  // ABORTED (the grid has the revision that attempt stored: ask Get with the request's `step`
  // whether it landed, as examples/pitching.cc does); DeformGrid without base_revision, FitGrid
  // and FairGrid may store a second revision; imports and GenerateGrid with an id answer
  // ALREADY_EXISTS, DeleteGrid NOT_FOUND. Set retry.max_attempts = 1 to see every UNAVAILABLE.
  RetryPolicy retry;
  // The resumptions of a watch (WatchGrid has no deadline to bound them): unset, `retry`.
  std::optional<RetryPolicy> watch_retry;

  // The most bytes of values an Evaluate may assemble in this process (0: no limit). A larger
  // evaluation is refused with RESOURCE_EXHAUSTED as soon as its header arrives, before
  // anything is allocated, instead of growing the process until the machine runs out of memory.
  int64_t max_evaluation_bytes = 0;

  // ---- Security (serve --tokens, --tls_cert) ----
  // Sent with every call as `authorization: Bearer TOKEN` (empty: none). Printable ASCII
  // without blanks; anything else is not sent (the server then answers UNAUTHENTICATED).
  std::string token;
  // Connect() over TLS instead of plaintext.
  bool use_tls = false;
  // PEM of the CA(s) the server's certificate must chain to; empty: the system's roots.
  std::string tls_root_certs;
  // PEM of this client's certificate chain and private key, for a server that requires client
  // certificates (mTLS); both or neither.
  std::string tls_cert_chain;
  std::string tls_private_key;
  // The name the server's certificate must carry, when it is not the target's host.
  std::string tls_server_name;
};

// Reads the PEM files of a TLS connection into `options` and sets use_tls when any is given:
// `ca_file` (--tls_ca) the CA to trust, `cert_file`/`key_file` (--tls_cert/--tls_key) the
// client's certificate for mTLS. Empty paths are skipped. NOT_FOUND naming the flag and the path
// for a file that cannot be read; INVALID_ARGUMENT for a cert without a key or vice versa.
absl::Status LoadTlsFiles(const std::string& ca_file, const std::string& cert_file,
                          const std::string& key_file, ClientOptions* options);

// Progress of a transfer: bytes done and the total (0 when unknown).
using ProgressFn = std::function<void(int64_t done, int64_t total)>;

// Points (and derivatives) of one evaluated block.
struct EvaluatedBlock {
  int block = 0;
  StructuredBlock points;
  std::vector<double> du, dv, dw;  // same layout as points.coords(), when asked for
};

struct EvaluatedGrid {
  int64_t revision = 0;
  std::vector<EvaluatedBlock> blocks;
};

// "name" or "grids/name" -> "grids/name".
std::string GridName(const std::string& name_or_id);
// "grids/name" or "name" -> "name" (what kGridRoutingHeader carries).
std::string GridId(const std::string& name_or_id);

// What ExportGrid wrote or ImportArchive read: the archive's header and its size.
struct ArchiveSummary {
  v1::ArchiveHeader header;
  int64_t source_chunks = 0;
  int64_t revisions = 0;
  int64_t bytes = 0;  // of the file
};

// Stops a watch (Client::Watch) from any thread, also before the call has started or after it
// ended. Shared between the caller and the watch.
class WatchCancel {
 public:
  // Cancels the call: a Next() blocked in another thread returns false, the watch's status is
  // CANCELLED (Client::Watch with a callback returns OK). Thread-safe; idempotent.
  void Cancel();
  bool cancelled() const;

 private:
  friend class RevisionStream;
  // Registers the call's context (nullptr: the call is over); cancels it at once when Cancel
  // came first.
  void Attach(grpc::ClientContext* context);

  mutable std::mutex mu_;
  bool cancelled_ = false;
  grpc::ClientContext* context_ = nullptr;
};

// A WatchGrid call: the grid's revisions as they are stored, read one at a time.
//
//   auto watch = client.Watch("naca", 0);
//   v1::WatchGridResponse message;
//   while (watch->Next(&message)) Use(message.revision());
//   absl::Status why = watch->Finish();
//
// Next() blocks until the server sends the next revision. Cancel() (or cancel()->Cancel()) may
// be called from any other thread while Next() blocks; the stream must outlive those calls.
// Destroying an unfinished stream cancels the call.
//
// A call that breaks off (BrokeOff: the replica died or stopped, a balancer reset the stream)
// is resumed inside Next(), under the client's RetryPolicy, after the last revision received
// (or where the first call began, which the server states in its initial metadata): no
// revision is missed or repeated. When retention dropped revisions it had not received (more
// than --keep_revisions deformed ones stored while it was away), the server refuses the resumed
// call with OUT_OF_RANGE, which ends the stream. The retries start afresh once a resumed call is
// up. When the resumed call finds the grid deleted, or another creation under its id, the stream
// ends as a deletion ends it (OK).
class RevisionStream {
 public:
  struct Call {
    std::unique_ptr<grpc::ClientContext> context;
    std::unique_ptr<grpc::ClientReader<v1::WatchGridResponse>> reader;
  };
  // `open(after)` starts the call for the revisions after `after` on `channel`; the first with
  // `after_revision` (0: every stored one, -1: only new ones).
  RevisionStream(std::function<Call(int64_t after)> open, int64_t after_revision,
                 const RetryPolicy& retry, std::shared_ptr<grpc::Channel> channel,
                 std::shared_ptr<WatchCancel> cancel);
  ~RevisionStream();
  RevisionStream(const RevisionStream&) = delete;
  RevisionStream& operator=(const RevisionStream&) = delete;

  // The next message; false when the stream has ended (the grid was deleted, the server
  // stopped, the call failed or was cancelled): then Finish() says why.
  bool Next(v1::WatchGridResponse* message);
  // Thread-safe: ends the call, a blocked Next() returns false.
  void Cancel() { cancel_->Cancel(); }
  const std::shared_ptr<WatchCancel>& cancel() const { return cancel_; }
  // The call's status once Next() has returned false (cancels the call first otherwise): OK
  // when the grid was deleted (or replaced by another creation under its id), CANCELLED after
  // Cancel(), the error otherwise (NOT_FOUND for an unknown grid, UNAVAILABLE when the
  // retries gave up, RESOURCE_EXHAUSTED when the client fell too far behind, ...).
  absl::Status Finish();

 private:
  // Starts the call (again) for the revisions after after_.
  void Open();
  // Takes in the current call's initial metadata, if it has arrived: where the first call
  // began (for -1) and which creation of the id is watched. False when the call watches
  // another creation than the stream did.
  bool SameCreation();
  // Whether the ended call (finished_) is resumed; waits before it.
  bool Resume();

  std::function<Call(int64_t)> open_;
  RetryPolicy retry_;
  Backoff backoff_;
  std::shared_ptr<grpc::Channel> channel_;
  Call call_;
  std::shared_ptr<WatchCancel> cancel_;
  int64_t after_;            // the last revision received, or where the stream began
  std::string incarnation_;  // the creation watched, once a call has said
  bool ended_ = false;
  std::optional<grpc::Status> finished_;  // the reader's Finish(), once called
  std::optional<absl::Status> status_;
};

// grpc::Status -> absl::Status.
absl::Status FromGrpc(const grpc::Status& status);

// Whether a call ended because it broke off rather than being answered: UNAVAILABLE (the
// server went away or is stopping, a balancer had no upstream), or INTERNAL "RST_STREAM" (a
// balancer reset a half-sent stream when its upstream died: nginx does, and gRPC reports it as
// INTERNAL "Received RST_STREAM with error code 2").
bool BrokeOff(const grpc::Status& status);

// Waits `wait` before the next attempt of a call on `channel`, watching the channel meanwhile:
// gRPC takes in the outcome of a reconnection only while something waits on the channel
// (otherwise its backup poller does, every 5 s), so a plain sleep would leave a restarted
// server unseen for seconds. Ends early, returning true, when `stop` (checked every 100 ms)
// says so.
bool PauseBeforeRetry(grpc::Channel& channel, absl::Duration wait,
                      const std::function<bool()>& stop = {});

class Client {
 public:
  Client(std::shared_ptr<grpc::Channel> channel, ClientOptions options = {});
  // A channel to host:port: plaintext, or TLS with options.use_tls.
  static std::unique_ptr<Client> Connect(const std::string& target, ClientOptions options = {});

  // Uploads a Plot3D file's bytes as a new grid. grid_id may be empty (the server picks one).
  absl::StatusOr<v1::Grid> ImportPlot3d(const std::string& bytes, const std::string& grid_id,
                                        const std::string& display_name, bool planar_view,
                                        const ProgressFn& progress = {});
  // The same with every Plot3dSource option (planar_view, layout); total_bytes is set here.
  absl::StatusOr<v1::Grid> ImportPlot3d(const std::string& bytes, const std::string& grid_id,
                                        const std::string& display_name,
                                        const v1::Plot3dSource& options,
                                        const ProgressFn& progress = {});
  // Uploads a CGNS file's bytes as a new grid (the server decodes them; the response's
  // source.boundaries holds the file's boundary conditions and the import's notes).
  absl::StatusOr<v1::Grid> ImportCgns(const std::string& bytes, const std::string& grid_id,
                                      const std::string& display_name,
                                      const ProgressFn& progress = {});
  // Uploads in-memory points as a new grid.
  absl::StatusOr<v1::Grid> ImportPoints(const MultiBlockGrid& grid, const std::string& grid_id,
                                        const std::string& display_name,
                                        const ProgressFn& progress = {});
  absl::StatusOr<v1::FitGridResponse> Fit(const std::string& name, const v1::FitSpec& spec);
  // A faired refit of `revision` (0: latest); fairing null: the server's default (to tolerance).
  // allow_folds: store the revision even if its cells fold (FairGridRequest.allow_folds).
  absl::StatusOr<v1::FitGridResponse> Fair(const std::string& name, int64_t revision,
                                           const v1::Fairing* fairing = nullptr,
                                           bool allow_folds = false);
  // Deforms a grid (request.name may be an id); see DeformGridRequest. A deformation that
  // folds cells is FAILED_PRECONDITION with the server's message (nothing was stored).
  absl::StatusOr<v1::DeformGridResponse> Deform(v1::DeformGridRequest request);
  // Generates a grid around a profile and fits it (GenerateGrid; see GenerateGridRequest):
  // the new grid with its revision 1, the generation report and the fit's summary. Nothing is
  // stored on an error.
  absl::StatusOr<v1::GenerateGridResponse> Generate(const v1::GenerateGridRequest& request);
  // Watches a grid's revisions (WatchGrid): those after `after_revision` (0: every stored one
  // first, -1: only new ones), then each new one as it is stored. The call has no deadline; it
  // lasts until the grid is deleted or the call is cancelled (`cancel`, or the stream's
  // Cancel(), from any thread); a call that breaks off is resumed (RevisionStream).
  std::unique_ptr<RevisionStream> Watch(const std::string& name, int64_t after_revision,
                                        std::shared_ptr<WatchCancel> cancel = nullptr);
  // The same with a callback per revision, on the calling thread; returning false stops the
  // watch. Returns OK when the callback stopped it, `cancel` cancelled it or the server ended
  // the stream (the grid was deleted); the call's error otherwise.
  absl::Status Watch(const std::string& name, int64_t after_revision,
                     const std::function<bool(const v1::WatchGridResponse&)>& on_revision,
                     std::shared_ptr<WatchCancel> cancel = nullptr);
  // Curvature samples along the walls of `revision` at `refinement_level`.
  absl::StatusOr<v1::GetWallCurvatureResponse> WallCurvature(const std::string& name,
                                                             int64_t revision, int refinement_level,
                                                             const std::vector<int>& blocks = {});
  absl::StatusOr<v1::Grid> Get(const std::string& name, int64_t revision = 0,
                               v1::GridView view = v1::GRID_VIEW_BASIC,
                               const std::vector<int>& blocks = {});
  // Any GetGridRequest (request.name may be an id), e.g. with `step` instead of a revision.
  absl::StatusOr<v1::Grid> Get(v1::GetGridRequest request);
  // Every grid, following the pages.
  absl::StatusOr<std::vector<v1::Grid>> List();
  absl::Status Delete(const std::string& name);
  // Streams an evaluation and reassembles it (request.name may be an id).
  absl::StatusOr<EvaluatedGrid> Evaluate(v1::EvaluateGridRequest request,
                                         const ProgressFn& progress = {});
  absl::StatusOr<v1::EvaluatePointsResponse> EvaluatePoints(v1::EvaluatePointsRequest request);
  // Writes a grid with its source points and every revision it keeps (ExportGrid) to `path`
  // as a record file (core/io/record_file.h) of ArchiveRecords: header, source chunks,
  // revisions. The records go to a temporary file beside `path`, fsynced and renamed onto it
  // when the stream is complete (its counts match the header): on any error nothing is left
  // behind and an existing file at `path` stays as it was. `progress` gets the bytes written
  // (total 0: unknown).
  absl::StatusOr<ArchiveSummary> ExportGrid(const std::string& name, const std::string& path,
                                            const ProgressFn& progress = {});
  // Creates a grid from a record file written by ExportGrid (ImportArchive): under `new_id`,
  // or the archive's own id when empty, with every revision under its original number. A file
  // that is not a record file, or is damaged or truncated (a torn record, a CRC mismatch,
  // fewer records than its header announces, a first record that is not a header), is
  // INVALID_ARGUMENT naming the file, the record and its byte offset; found while sending, the
  // call is cancelled, so nothing is stored. `progress` gets bytes sent of the file's size.
  absl::StatusOr<v1::Grid> ImportArchive(const std::string& path, const std::string& new_id,
                                         const ProgressFn& progress = {});
  // grpc.health.v1 status of `service` ("" = the whole server): "SERVING", "NOT_SERVING", ...
  absl::StatusOr<std::string> Health(const std::string& service = "");

  v1::SplineGrid::Stub& stub() { return *stub_; }

 private:
  // One attempt of a call on `context`: its status. An attempt starts from scratch (a stream's
  // partial results are dropped), so every call may be repeated when it broke off.
  using Attempt = std::function<grpc::Status(grpc::ClientContext* context)>;

  // A context with `deadline` (InfiniteFuture: none), for a non-empty `grid` of printable
  // ASCII (anything else is no grid id the server accepts) the routing header naming it, and
  // for a non-empty `token` the authorization header.
  static std::unique_ptr<grpc::ClientContext> NewContext(absl::Time deadline,
                                                         const std::string& grid,
                                                         const std::string& token);
  // Runs `attempt` on a fresh context (deadline options_.timeout from now, shared by all
  // attempts; routing header `grid`) until it does not break off (BrokeOff) or options_.retry
  // gives up; the last attempt's status (annotated with the attempt count when there were
  // retries).
  absl::Status Call(const std::string& grid, const Attempt& attempt) const;

  // Puts one piece of a file into an upload request (its plot3d_chunk or cgns_chunk).
  using ChunkSetter = std::function<void(v1::ImportGridRequest& request, std::string chunk)>;
  // One ImportGrid upload of a file's `bytes`: a request holding `header` (whose grid_id routes
  // the call and whose format message carries total_bytes), then the bytes in kUploadChunkBytes
  // pieces placed by `set_chunk`, retried as Call says. The new grid, or the call's status.
  absl::StatusOr<v1::Grid> UploadFile(const v1::ImportHeader& header, const std::string& bytes,
                                      const ChunkSetter& set_chunk, const ProgressFn& progress);

  // The grid a request is about, for the routing header: the id of its `name`, else its
  // `grid_id` (a new grid's), else none.
  template <typename Request>
  static std::string RoutingGrid(const Request& request) {
    if constexpr (requires { request.name(); }) {
      return GridId(request.name());
    } else if constexpr (requires { request.grid_id(); }) {
      return request.grid_id();
    } else {
      return "";
    }
  }

  // One unary call of `method`, retried as Call says: the response, or the call's status.
  template <typename Request, typename Response>
  absl::StatusOr<Response> Unary(grpc::Status (v1::SplineGrid::Stub::*method)(grpc::ClientContext*,
                                                                              const Request&,
                                                                              Response*),
                                 const Request& request) const {
    Response response;
    const absl::Status status = Call(RoutingGrid(request), [&](grpc::ClientContext* context) {
      response.Clear();
      return (stub_.get()->*method)(context, request, &response);
    });
    if (!status.ok()) return status;
    return response;
  }

  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::SplineGrid::Stub> stub_;
  ClientOptions options_;
};

}  // namespace splinegrid::client

#endif  // SPLINEGRID_CLIENT_CLIENT_H_
