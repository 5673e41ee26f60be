// splinegrid.h: watching a grid's revisions (WatchGrid), one sg_watch_next at a time.
#include <memory>

#include "absl/strings/str_cat.h"
#include "capi/client_state.h"
#include "capi/splinegrid.h"
#include "client/client.h"
#include "core/util/status_macros.h"

extern "C" {

sg_status sg_watch_open(sg_client* c, const char* grid, int64_t after_revision, sg_watch** watch) {
  namespace client = splinegrid::client;
  if (c == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(c->state.get(), [&]() -> absl::Status {
    if (watch == nullptr) return absl::InvalidArgumentError("watch: NULL");
    *watch = nullptr;
    SG_RETURN_IF_ERROR(splinegrid::capi::RequireString(grid, "grid"));
    if (after_revision < -1) {
      return absl::InvalidArgumentError(
          absl::StrCat("after_revision: ", after_revision, " (-1, 0 or a revision)"));
    }
    SG_ASSIGN_OR_RETURN(client::Client * connected, c->state->Connected());
    auto opened = std::make_unique<sg_watch>();
    opened->state = c->state;
    opened->stream = connected->Watch(client::GridName(grid), after_revision);
    *watch = opened.release();
    return absl::OkStatus();
  });
}

sg_status sg_watch_next(sg_watch* watch, sg_revision_info* info, int32_t* has_revision) {
  if (watch == nullptr) return SG_INVALID_ARGUMENT;
  return splinegrid::capi::Guard(watch->state.get(), [&]() -> absl::Status {
    if (has_revision == nullptr) return absl::InvalidArgumentError("has_revision: NULL");
    *has_revision = 0;
    if (info == nullptr) return absl::InvalidArgumentError("info: NULL");
    if (watch->ended) return absl::OkStatus();
    splinegrid::v1::WatchGridResponse message;
    if (watch->stream->Next(&message)) {
      const splinegrid::v1::RevisionInfo& r = message.revision();
      *info = sg_revision_info{r.revision(),
                               r.parent_revision(),
                               r.step(),
                               r.time(),
                               static_cast<int32_t>(r.origin()),
                               0};
      *has_revision = 1;
      return absl::OkStatus();
    }
    watch->ended = true;
    const absl::Status why = watch->stream->Finish();
    // A cancelled watch ended as asked.
    return absl::IsCancelled(why) ? absl::OkStatus() : why;
  });
}

void sg_watch_cancel(sg_watch* watch) {
  if (watch != nullptr) watch->stream->Cancel();
}

void sg_watch_close(sg_watch* watch) { delete watch; }

}  // extern "C"
