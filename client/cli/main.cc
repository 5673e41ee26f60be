// splinegrid: the command-line tool of the splinegrid service.
//
//   splinegrid serve [--address host:port] [--threads N] [--memory_budget_mb M] [--keep_revisions
//   N] splinegrid fit FILE [--name N] [--tol T | --kinds [--wall W ...] | --ctl a,b,c] [--fair F]
//   splinegrid fair NAME [--revision R] [--fair tol|LAMBDA]
//   splinegrid curvature NAME [--revision R] [--level L] [-o OUT.csv]
//   splinegrid airfoil FILE.dat [--tol T] [--fair tol|LAMBDA|off] [-o OUT.csv]   (no server)
//   splinegrid get NAME [--full]      splinegrid list      splinegrid rm NAME
//   splinegrid eval NAME (--level L | --res a,b,c) [--step N] [--block b] -o OUT.{vts,...}
//   splinegrid deform NAME --rotate DEG [--about X,Y[,Z]] [--translate DX,DY[,DZ]] ...
//   splinegrid offset FILE.dat [--name N] [--layers 128] [--first 1e-5] [--far 50] ... [-o OUT]
//   splinegrid watch NAME [--after R]
//   splinegrid export NAME -o FILE.sgrid      splinegrid import FILE.sgrid [--name NEW]
//   splinegrid health
// Client commands talk to --server (default localhost:50051); --json prints JSON.
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "absl/flags/parse.h"
#include "absl/flags/usage.h"
#include "client/cli/commands.h"

namespace {

constexpr char kUsage[] =
    "splinegrid: structured grids as B-spline mappings.\n"
    "  splinegrid serve [--address localhost:50051] [--store memory|dir:PATH|redis://H:P[/DB]]\n"
    "                   [--threads N] [--memory_budget_mb M (0: half the memory limit)]\n"
    "                   [--keep_revisions N]   (deformed revisions kept per grid, default 64)\n"
    "                   [--log_format text|json] [--drain_notice 5s] [--shutdown_grace 10s]\n"
    "                   [--import_idle_timeout 60s] [--max_running_long_tasks N]\n"
    "                   [--max_queued_long_calls_per_principal 8]\n"
    "                   [--max_streams_per_principal 64]\n"
    "  splinegrid fit FILE [--name N] [--tol T | --kinds [--ref_length L] [--wall W --interface I\n"
    "                 --outer O] | --ctl a,b,c] [--fair tol|LAMBDA] [--allow_folds]\n"
    "      --kinds: defaults 0.15e-3, 2e-3, 8e-3 times the reference length (the largest\n"
    "      extent of a wall, e.g. the chord; --ref_length overrides); --tol, --wall ... are\n"
    "      lengths in the grid's unit\n"
    "      --face BLOCK:FACE=KIND[,...]: kinds of faces (FACE imin..kmax, KIND wall, interface,\n"
    "      outer; implies --kinds), e.g. --face 0:imin=wall,2:jmax=outer\n"
    "  splinegrid fair NAME [--revision R] [--fair tol|LAMBDA] [--allow_folds]\n"
    "      fit/fair/offset: a grid whose cells fold at levels 0..2 (after repair) is\n"
    "      FAILED_PRECONDITION (exit 1), nothing stored; with --allow_folds it is stored\n"
    "      and the command exits 3 after printing its report (exit 1: a failed call)\n"
    "  splinegrid curvature NAME [--revision R] [--level L] [--block b] [-o OUT.csv]\n"
    "  splinegrid airfoil FILE.dat [--tol 1e-4] [--fair tol|LAMBDA|off] [-o OUT.csv]   (local)\n"
    "  splinegrid get NAME [--revision R | --step N] [--full] | list | rm NAME | health\n"
    "  splinegrid eval NAME (--level L | --res a,b,c) [--revision R | --step N] [--block b]\n"
    "                  -o OUT.{vts,vtm,x,xyz}\n"
    "  splinegrid deform NAME [--rotate DEG [--about X,Y[,Z]] [--axis X,Y,Z]]\n"
    "                  [--translate DX,DY[,DZ]] [--boundary wall|outer|interface|\n"
    "                  BLOCK:FACE[:A0:A1[:B0:B1]],...] [--reference R] [--base R] [--time T]\n"
    "                  [--step N] [--check_level L] [--propagation blend|transfinite]\n"
    "                  [--decay_radius D] [--rigid_radius R] [--smoothing N]\n"
    "      a fold is FAILED_PRECONDITION (exit 1), nothing stored\n"
    "  splinegrid offset FILE.dat [--name N] [--layers 128] [--first 1e-5] [--far 50]\n"
    "                  [--points 257] [--method offsets|transfinite|elliptic] [--orthogonalize=false]\n"
    "                  [--profile_tol 1e-4] [--tol T | --kinds ... | --ctl a,b,c]\n"
    "                  [-o OUT.{vts,x,xyz}]   an O-grid around an airfoil file (Selig or\n"
    "      Lednicer), stored and fitted (default: interpolated); -o writes it at level 0\n"
    "  splinegrid watch NAME [--after R]   one line per new revision until ^C or deletion\n"
    "  splinegrid export NAME -o FILE.sgrid   the grid with its source and revisions (archive)\n"
    "  splinegrid import FILE.sgrid [--name NEW]   a grid from an archive, revisions keep their\n"
    "      numbers (a Plot3D file is not an archive: use fit)\n"
    "Client commands use --server host:port (default localhost:50051) and --json.\n"
    "Security: serve [--tls_cert C.pem --tls_key K.pem [--tls_client_ca CA.pem]] [--tokens FILE]\n"
    "      [--insecure] (plaintext on a non-loopback address); client commands [--tls_ca CA.pem]\n"
    "      [--tls_cert C.pem --tls_key K.pem] [--token T | $SPLINEGRID_TOKEN]";

}  // namespace

int main(int argc, char** argv) {
  absl::SetProgramUsageMessage(kUsage);
  std::vector<char*> positional = absl::ParseCommandLine(argc, argv);
  if (positional.size() < 2) {
    std::fprintf(stderr, "%s\n", kUsage);
    return 2;
  }
  using Command = absl::Status (*)(const splinegrid::cli::Args&);
  const std::map<std::string, Command> commands = {
      {"serve", splinegrid::cli::Serve},     {"fit", splinegrid::cli::Fit},
      {"get", splinegrid::cli::Get},         {"list", splinegrid::cli::List},
      {"eval", splinegrid::cli::Eval},       {"rm", splinegrid::cli::Remove},
      {"fair", splinegrid::cli::Fair},       {"curvature", splinegrid::cli::Curvature},
      {"airfoil", splinegrid::cli::Airfoil}, {"health", splinegrid::cli::Health},
      {"deform", splinegrid::cli::Deform},   {"watch", splinegrid::cli::Watch},
      {"offset", splinegrid::cli::Offset},   {"export", splinegrid::cli::Export},
      {"import", splinegrid::cli::Import}};
  const auto command = commands.find(positional[1]);
  if (command == commands.end()) {
    std::fprintf(stderr, "unknown command '%s'\n%s\n", positional[1], kUsage);
    return 2;
  }
  const splinegrid::cli::Args args(positional.begin() + 2, positional.end());
  absl::Status status =
      command->first == "serve" ? absl::OkStatus() : splinegrid::cli::PrepareConnection();
  if (status.ok()) status = command->second(args);
  if (!status.ok()) {
    // Code and message, without payloads (the exit status is one).
    std::fprintf(stderr, "splinegrid %s: %s: %s\n", positional[1],
                 absl::StatusCodeToString(status.code()).c_str(),
                 std::string(status.message()).c_str());
    return splinegrid::cli::ExitCodeOf(status);
  }
  return 0;
}
