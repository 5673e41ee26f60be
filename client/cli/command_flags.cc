#include "client/cli/command_flags.h"

#include <algorithm>

namespace splinegrid::cli {
namespace {

// The fit flags (command_util.cc SpecFromFlags and ParseFairFlag): fit and offset both build a
// FitSpec from them.
#define SG_FIT_SPEC_FLAGS                                                                \
  "tol", "ctl", "order", "max_ctl", "kinds", "ref_length", "wall", "interface", "outer", \
      "interior", "edge", "first_layer", "face", "fair", "allow_folds"

std::vector<CommandSpec> MakeCommands() {
  return {
      {"serve",
       "serve [--address localhost:50051] [--store memory|dir:PATH|redis://[U@]H:P[/DB]] "
       "[flags]",
       "run the gRPC server (in the foreground; SIGTERM drains and stops it)",
       /*client=*/false,
       {"address",
        "store",
        "redis_password_file",
        "threads",
        "memory_budget_mb",
        "keep_revisions",
        "log_calls",
        "log_format",
        "drain_notice",
        "shutdown_grace",
        "import_idle_timeout",
        "max_output_points",
        "max_running_long_tasks",
        "max_queued_long_calls_per_principal",
        "max_streams_per_principal",
        "tls_cert",
        "tls_key",
        "tls_client_ca",
        "insecure",
        "tokens",
        "trusted_proxies",
        "metrics_address",
        "metrics_insecure",
        "cgns_decoder",
        "cgns_decoder_memory_mb",
        "cgns_decoder_cpu_seconds",
        "cgns_decoder_timeout_seconds"},
       {"Plaintext only on a loopback address unless --insecure; --tls_cert and --tls_key "
        "enable TLS."}},
      {"fit",
       "fit FILE|NAME [--name N] [--tol T | --kinds [--wall W --interface I --outer O] | "
       "--ctl a,b,c] [--fair tol|LAMBDA] [--allow_folds]",
       "import a Plot3D or CGNS grid and fit it (revision 1), or fit a stored grid's points again "
       "(a new revision; NAME when no such file exists); prints the fit report",
       /*client=*/true,
       {"name", "planar", "plot3d_layout", SG_FIT_SPEC_FLAGS},
       {"--kinds: tolerances 0.15e-3 (wall), 2e-3 (interface), 8e-3 (outer) times the reference "
        "length (the largest extent of a wall, e.g. the chord; --ref_length overrides).",
        "A fit whose cells fold at levels 0..2 is refused (exit 1, nothing stored); with "
        "--allow_folds it is stored and the command exits 3. Exit 3 also when a revision was "
        "stored that misses its tolerances (a --max_ctl cap held it back)."}},
      {"fair",
       "fair NAME [--revision R] [--fair tol|LAMBDA] [--allow_folds]",
       "a faired revision of a grid (default: the largest weight within its tolerances)",
       /*client=*/true,
       {"revision", "fair", "allow_folds"},
       {"--fair LAMBDA fairs with that weight and refines where the tolerances need it; a weight "
        "too strong for them refines to interpolation and still misses them: the revision is "
        "stored and the command exits 3 (the default finds the largest weight that keeps them)."}},
      {"curvature",
       "curvature NAME [--revision R] [--level L] [--block b] [-o OUT.csv]",
       "wall curvature of a revision (CSV with -o)",
       /*client=*/true,
       {"revision", "level", "block", "o"},
       {}},
      {"airfoil",
       "airfoil FILE.dat [--tol T] [--fair tol|LAMBDA|off] [-o OUT.csv]",
       "fit an airfoil's coordinates locally (no server); curvature CSV with -o",
       /*client=*/false,
       {"tol", "fair", "o"},
       {"The default --tol is 1e-4 of the profile's chord (its largest distance from the first "
        "point), so a file in millimetres is fitted as one in chords.",
        "Local: the connection flags (--server, --json, TLS ...) are refused, not ignored."}},
      {"get",
       "get NAME [--revision R | --step N] [--full]",
       "a grid's description (with --full its knots and control points)",
       /*client=*/true,
       {"revision", "step", "full"},
       {}},
      {"list", "list", "the grids held by the server", /*client=*/true, {}, {}},
      {"rm", "rm NAME", "delete a grid and its revisions", /*client=*/true, {}, {}},
      {"health",
       "health [--service S]",
       "the server's health status (exit 1 unless SERVING)",
       /*client=*/true,
       {"service"},
       {}},
      {"eval",
       "eval NAME (--level L | --res a,b,c) [--revision R | --step N | --steps A:B] [--block b] "
       "[--box i0:i1,j0:j1[,k0:k1]] [--dist DIR=KIND,...] [--derivs] [--float32] "
       "-o OUT.{vts,vtm,x,xyz,cgns,pvd}",
       "evaluate a revision at a refinement level or resolution into a file",
       /*client=*/true,
       {"o", "level", "res", "revision", "step", "block", "box", "dist", "derivs", "float32",
        "steps", "compress", "jacobian", "quality", "deviation", "max_memory_mb"},
       {}},
      {"deform",
       "deform NAME [--rotate DEG [--about X,Y[,Z]] [--axis X,Y,Z]] [--translate DX,DY[,DZ]] "
       "[--boundary wall|outer|interface|BLOCK:FACE[:A0:A1[:B0:B1]],...] [--reference R] "
       "[--base R] [--time T] [--step N] [flags]",
       "rigidly move part of a grid's boundary; the interior follows (a new revision)",
       /*client=*/true,
       {"rotate", "about", "axis", "translate", "boundary", "reference", "base", "time", "step",
        "check_level", "propagation", "decay_radius", "rigid_radius", "smoothing"},
       {"A fold is FAILED_PRECONDITION (exit 1), nothing stored."}},
      {"offset",
       "offset FILE.dat|SURFACE [--name N] [--layers 128] [--first H] [--far D] "
       "[--points 257] [--method offsets|transfinite|elliptic] [--side outward|along|against] "
       "[--normal_smoothing 80] [--symmetry=false] [--tol T | --kinds ... | --ctl a,b,c] "
       "[-o OUT.{vts,vtm,x,xyz,cgns}]",
       "an O-grid around an airfoil file, or a volume grid off a stored surface grid "
       "(GenerateGrid), stored and fitted",
       /*client=*/true,
       {"name", "o", "max_memory_mb", "layers", "first", "far", "points", "method", "orthogonalize",
        "profile_tol", "side", "normal_smoothing", "symmetry", SG_FIT_SPEC_FLAGS},
       {"The profile file is Selig or Lednicer. An argument that is no file (or grids/NAME) names "
        "a "
        "stored grid of 3D surface blocks: hexahedral layers are marched off all its blocks (k "
        "outward), "
        "watertight; the new grid is NAME-volume unless --name. -o writes the grid at level 0."}},
      {"watch",
       "watch NAME [--after R]",
       "one line per new revision of a grid until ^C or its deletion",
       /*client=*/true,
       {"after"},
       {}},
      {"export",
       "export NAME -o FILE.sgrid",
       "write a grid with its source and revisions to an archive",
       /*client=*/true,
       {"o"},
       {}},
      {"import",
       "import FILE.sgrid [--name NEW]",
       "a grid from an archive; revisions keep their numbers (a Plot3D file: use fit)",
       /*client=*/true,
       {"name"},
       {}},
  };
}

#undef SG_FIT_SPEC_FLAGS

}  // namespace

const std::vector<CommandSpec>& Commands() {
  static const std::vector<CommandSpec>* const commands =
      new std::vector<CommandSpec>(MakeCommands());
  return *commands;
}

const std::vector<std::string>& ClientFlags() {
  static const std::vector<std::string>* const flags = new std::vector<std::string>{
      "server", "json", "timeout", "token", "tls_ca", "tls_cert", "tls_key", "tls_server_name"};
  return *flags;
}

const CommandSpec* FindCommand(absl::string_view name) {
  for (const CommandSpec& command : Commands()) {
    if (command.name == name) return &command;
  }
  return nullptr;
}

std::vector<std::string> AcceptedFlags(const CommandSpec& command) {
  std::vector<std::string> flags = command.flags;
  // Only the commands that talk to a server take the connection flags: serve has transport
  // flags of its own (--tls_cert is the server's certificate there), and the local airfoil would
  // only ignore them (`airfoil --server h:1` must not look as if it ran on h).
  if (command.client) {
    for (const std::string& flag : ClientFlags()) {
      if (std::find(flags.begin(), flags.end(), flag) == flags.end()) flags.push_back(flag);
    }
  }
  return flags;
}

}  // namespace splinegrid::cli
