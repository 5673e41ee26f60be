// The commands on stored grids as they are: get, list, rm and health.
#include <cstdio>
#include <vector>

#include "absl/flags/flag.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "client/cli/command_util.h"
#include "client/cli/commands.h"
#include "client/cli/flags.h"
#include "client/cli/output.h"
#include "client/client.h"
#include "core/util/status_macros.h"

namespace splinegrid::cli {

absl::Status Get(const Args& args) {
  if (args.size() != 1) {
    return Usage("usage: splinegrid get NAME [--revision R | --step N] [--full]");
  }
  v1::GetGridRequest request;
  request.set_name(args[0]);
  request.set_view(absl::GetFlag(FLAGS_full) ? v1::GRID_VIEW_FULL : v1::GRID_VIEW_BASIC);
  SG_RETURN_IF_ERROR(RevisionOrStep([&](int64_t r) { request.set_revision(r); },
                                    [&](int64_t s) { request.set_step(s); }));
  SG_ASSIGN_OR_RETURN(const v1::Grid grid, Connect()->Get(request));
  Print(FormatGrid(grid), grid);
  return absl::OkStatus();
}

absl::Status List(const Args& args) {
  if (!args.empty()) return Usage("usage: splinegrid list");
  SG_ASSIGN_OR_RETURN(const std::vector<v1::Grid> grids, Connect()->List());
  v1::ListGridsResponse all;
  std::string human;
  for (const v1::Grid& grid : grids) {
    *all.add_grids() = grid;
    absl::StrAppend(&human, absl::StrFormat("%-32s %4d blocks %10d points  revision %d\n",
                                            grid.name(), grid.source().blocks_size(),
                                            grid.source().num_points(), grid.latest_revision()));
  }
  Print(human, all);
  return absl::OkStatus();
}

absl::Status Remove(const Args& args) {
  if (args.size() != 1) return Usage("usage: splinegrid rm NAME");
  SG_RETURN_IF_ERROR(Connect()->Delete(args[0]));
  google::protobuf::Empty empty;
  Print(absl::StrCat("deleted ", client::GridName(args[0]), "\n"), empty);
  return absl::OkStatus();
}

absl::Status Health(const Args& args) {
  if (!args.empty()) return Usage("usage: splinegrid health [--service S]");
  SG_ASSIGN_OR_RETURN(const std::string status, Connect()->Health(absl::GetFlag(FLAGS_service)));
  std::printf(absl::GetFlag(FLAGS_json) ? "{\"status\": \"%s\"}\n" : "%s\n", status.c_str());
  if (status != "SERVING") return absl::UnavailableError(absl::StrCat("status ", status));
  return absl::OkStatus();
}

}  // namespace splinegrid::cli
