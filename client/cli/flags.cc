#include "client/cli/flags.h"

#include "absl/flags/flag.h"
#include "server/server_options.h"

ABSL_FLAG(std::string, server, "",
          "splinegrid server to talk to, host:port (default: $SPLINEGRID_SERVER, else "
          "localhost:50051)");
ABSL_FLAG(bool, json, false, "print results as JSON");
ABSL_FLAG(absl::Duration, timeout, absl::Minutes(10), "deadline of each call");

// Security: tokens and TLS. --tls_cert/--tls_key are the client's certificate (mTLS) for client
// commands and the server's certificate for serve.
ABSL_FLAG(std::string, token, "",
          "bearer token sent with every call (default: $SPLINEGRID_TOKEN; prefer the variable: "
          "command lines are visible to other users)");
ABSL_FLAG(std::string, tls_ca, "",
          "connect over TLS, trusting the CA in this PEM file (implies TLS)");
ABSL_FLAG(std::string, tls_cert, "",
          "PEM certificate chain: serve: the server's (enables TLS, with --tls_key); client "
          "commands: the client's, for mutual TLS");
ABSL_FLAG(std::string, tls_key, "", "PEM private key of --tls_cert");
ABSL_FLAG(std::string, tls_server_name, "",
          "the name the server's certificate must carry (default: the host of --server)");
ABSL_FLAG(std::string, tls_client_ca, "",
          "serve: require client certificates signed by the CA in this PEM file (mutual TLS)");
ABSL_FLAG(bool, insecure, false,
          "serve: allow plaintext on an address that is not loopback (e.g. 0.0.0.0:50051)");
ABSL_FLAG(std::string, tokens, "",
          "serve: tokens file, lines 'TOKEN PRINCIPAL ROLE' (ROLE read, write or admin; # "
          "comments); calls then need a token; SIGHUP reloads it");

ABSL_FLAG(std::string, trusted_proxies, "",
          "serve: proxies (addresses or CIDR ranges, comma-separated, e.g. 127.0.0.1 or "
          "10.0.0.0/8) whose 'x-client-address' metadata names the caller when there are no "
          "tokens: behind nginx every call arrives on one of its connections, and fair turns "
          "and per-caller limits need the client's (deploy/nginx sets it)");

ABSL_FLAG(std::string, name, "",
          "fit/offset: id of the new grid (default: from the file name); import: (default: the "
          "archive's)");
ABSL_FLAG(double, tol, 0.0, "fit: largest allowed deviation, in the grid's length unit");
ABSL_FLAG(std::string, ctl, "", "fit: control points per direction, e.g. 24,16 or 24,16,8");
ABSL_FLAG(int, order, 4, "fit: spline order (degree + 1)");
ABSL_FLAG(bool, planar, true, "fit: store the 2D view of grids held as two planes (CFL3D style)");
ABSL_FLAG(std::string, plot3d_layout, "",
          "fit: whole or planes, the value order of 3D Plot3D text and C-stream files (Fortran "
          "record files are detected); default whole");
ABSL_FLAG(int, max_ctl, 0, "fit --tol/--kinds: most control points per direction (0: no cap)");
ABSL_FLAG(bool, kinds, false,
          "fit: tolerances by boundary kind (defaults 0.15e-3 wall, 2e-3 interface, 8e-3 outer "
          "times the reference length; --wall, --interface, --outer, --interior are lengths)");
ABSL_FLAG(double, ref_length, 0.0,
          "fit: reference length of the default tolerances by kind, in the grid's unit (implies "
          "--kinds; 0: detected, the largest extent of a wall, e.g. the chord)");
ABSL_FLAG(double, wall, 0.0, "fit: wall tolerance (implies --kinds; 0: default)");
ABSL_FLAG(double, interface, 0.0, "fit: block interface tolerance (implies --kinds; 0: default)");
ABSL_FLAG(double, outer, 0.0, "fit: outer boundary tolerance (implies --kinds; 0: default)");
ABSL_FLAG(double, interior, 0.0, "fit: tolerance inside blocks (implies --kinds; 0: none)");
ABSL_FLAG(double, edge, -1.0,
          "fit: relative accuracy of grid edges inside blocks, in (0, 1]: the error of an edge "
          "vector over its length (implies --kinds; 0: off; <0: default 0.5)");
ABSL_FLAG(double, first_layer, 0.0,
          "fit: relative accuracy of the first layer at the walls, in (0, 1], e.g. 0.05: every "
          "first-layer height (what a solver's y+ follows) within 5% of the grid's (implies "
          "--kinds; 0: off, the fit report still gives the change; costs controls)");
ABSL_FLAG(std::string, fair, "",
          "fit/fair: fairing: 'tol' (largest weight within the tolerances) or a weight lambda");
ABSL_FLAG(std::string, face, "",
          "fit: explicit boundary kinds of faces, BLOCK:FACE=KIND[,...] with FACE imin, imax, "
          "jmin, jmax, kmin or kmax and KIND wall, interface or outer (implies --kinds); e.g. "
          "--face 0:imin=wall,2:jmax=outer");
ABSL_FLAG(bool, allow_folds, false,
          "fit/fair/offset: store the revision even if cells fold at levels 0..2 (exit 3 after "
          "storing it; without the flag such a fit is refused and nothing is stored)");

ABSL_FLAG(int64_t, revision, 0, "get/eval/fair/curvature: revision (0: latest)");
ABSL_FLAG(bool, full, false, "get: include knots, control points and distributions");

ABSL_FLAG(std::optional<int>, level, std::nullopt,
          "eval/curvature: refinement level (0 = original points; curvature: default 2)");
ABSL_FLAG(std::string, res, "", "eval: points per direction, e.g. 400,120");
ABSL_FLAG(std::string, block, "", "eval/curvature: blocks, e.g. 0 or 0,3 (default: all)");
ABSL_FLAG(std::string, box, "", "eval: index box i0:i1,j0:j1[,k0:k1] (inclusive)");
ABSL_FLAG(std::string, dist, "",
          "eval: point distributions, DIR=KIND[,...] with DIR i, j or k and KIND original, "
          "parameter (uniform in the spline parameter), arclength (uniform in arc length) or "
          "geometric:FIRST[:end] (first spacing FIRST at the first index, or at the last with "
          ":end; arc length along each grid line); e.g. --dist j=geometric:2e-6 for a new wall "
          "spacing. At most one direction may be arclength or geometric; -o .cgns refuses it");
ABSL_FLAG(std::string, o, "",
          "eval/offset: output file (.vts, .vtm, .x binary or .xyz text Plot3D, .cgns; eval: "
          ".pvd series); curvature: .csv; export: the archive (.sgrid)");
ABSL_FLAG(bool, derivs, false,
          "eval: also dX/du, dX/dv[, dX/dw] (VTK point arrays; with .x/.xyz a Plot3D function "
          "file NAME.f beside it)");
ABSL_FLAG(bool, float32, false,
          "eval: transfer single precision (values rounded to float; .cgns stores them as float, "
          "the other files as double)");
ABSL_FLAG(
    std::string, steps, "",
    "eval: a:b, the deformed revisions of time steps a to b as a ParaView series (-o NAME.pvd)");
ABSL_FLAG(bool, compress, true, "eval: zlib-compress VTK XML data (--nocompress: raw)");
ABSL_FLAG(int64_t, max_memory_mb, 0,
          "eval/offset -o: memory an evaluation may take here while it is received and written "
          "(MiB; 0: three quarters of what is available: MemAvailable, or what the cgroup has "
          "left under its limit if lower); larger ones are refused when their header arrives");
ABSL_FLAG(bool, jacobian, false, "eval: VTK point field 'jacobian' of the spline mapping");
ABSL_FLAG(bool, quality, false, "eval: VTK cell field 'scaled_jacobian' (1 ideal, <= 0 folded)");
ABSL_FLAG(bool, deviation, false,
          "eval: VTK point field 'deviation' from the source points (--level 0 only)");

ABSL_FLAG(std::optional<double>, rotate, std::nullopt,
          "deform: rotation angle in degrees (2D: counter-clockwise about z) of the moved "
          "boundary; 0 is a motion too (a step of a solver's series at rest)");
ABSL_FLAG(std::string, about, "", "deform: centre of the rotation X,Y[,Z] (default: the origin)");
ABSL_FLAG(std::string, axis, "", "deform: rotation axis X,Y,Z (default: z)");
ABSL_FLAG(std::string, translate, "",
          "deform: translation DX,DY[,DZ] applied after the rotation (default: none)");
ABSL_FLAG(std::string, boundary, "",
          "deform: what moves: kinds wall, outer, interface (comma-separated), or face ranges "
          "BLOCK:FACE[:A0:A1[:B0:B1]] with FACE imin..kmax and A, B the face's index ranges in "
          "i, j, k order (default: wall)");
ABSL_FLAG(int64_t, reference, 0,
          "deform: revision whose geometry is moved (0: latest; the fit's makes motions absolute)");
ABSL_FLAG(int64_t, base, 0,
          "deform: the latest revision seen; ABORTED if the grid has a newer one (0: no check)");
ABSL_FLAG(double, time, 0.0, "deform: solver time stamped on the new revision");
ABSL_FLAG(std::optional<int64_t>, step, std::nullopt,
          "deform: solver time step stamped on the new revision (default 0); get/eval: the "
          "latest revision of this time step instead of --revision");
ABSL_FLAG(int, check_level, 0, "deform: refinement level of the fold check, 0 to 4");
ABSL_FLAG(std::string, propagation, "blend",
          "deform: how the interior follows: blend (by distance) or transfinite (Coons)");
ABSL_FLAG(double, decay_radius, 0.0,
          "deform: controls farther from the moved boundary stay (0: the nearest fixed boundary)");
ABSL_FLAG(double, rigid_radius, 0.0,
          "deform: controls within it move with the boundary in full (0: none)");
ABSL_FLAG(int, smoothing, 0, "deform: Laplacian smoothing sweeps of the interior (0: none)");

ABSL_FLAG(std::optional<int>, layers, std::nullopt,
          "offset: cells outward from the wall (default: the server's, 128; a surface 32)");
ABSL_FLAG(std::optional<double>, first, std::nullopt,
          "offset: height of the first layer, in the profile's unit (default 1e-5 of the "
          "profile's chord; a surface 1e-3)");
ABSL_FLAG(std::optional<double>, far, std::nullopt,
          "offset: distance of the outermost layer from the wall (default 50 chords of the "
          "profile; a surface 0.5)");
ABSL_FLAG(std::optional<int>, points, std::nullopt,
          "offset: wall points around the profile, the first repeated as the last (default 257)");
ABSL_FLAG(std::string, method, "",
          "offset: how layers are built: offsets (default), transfinite or elliptic");
ABSL_FLAG(std::optional<bool>, orthogonalize, std::nullopt,
          "offset --method transfinite: grid lines leave the wall normally (default true)");
ABSL_FLAG(std::optional<double>, profile_tol, std::nullopt,
          "offset: largest distance of the profile spline from the file's points, in its unit "
          "(default 1e-4 of the profile's chord)");
ABSL_FLAG(std::string, side, "",
          "offset SURFACE: outward (default: away from the volume the surface bounds), along or "
          "against (the first block's i x j normal)");
ABSL_FLAG(std::optional<int>, normal_smoothing, std::nullopt,
          "offset SURFACE: smoothing sweeps of the normals at the last layer (default 80)");
ABSL_FLAG(std::optional<bool>, symmetry, std::nullopt,
          "offset SURFACE: free edges on a coordinate plane stay on it (default true)");

ABSL_FLAG(int64_t, after, 0,
          "watch: send the revisions after this one (0: every stored one, -1: only new ones)");

ABSL_FLAG(std::string, service, "splinegrid.v1.SplineGrid",
          "health: service to check (empty: the whole server)");

ABSL_FLAG(std::string, address, "localhost:50051", "serve: address to listen on");
ABSL_FLAG(std::string, store, "memory",
          "serve: where grids live: memory (default), dir:PATH (durable) or "
          "redis://[USER[:PASSWORD]@]HOST:PORT[/DB] (shared by replicas)");
ABSL_FLAG(std::string, redis_password_file, "",
          "serve: a file whose first line is the Redis password (of the default user, or of "
          "USER in redis://USER@HOST:PORT), read at every new connection, so a rotated secret "
          "needs no restart; keeps the password out of process listings");
ABSL_FLAG(int, threads, 0, "serve: worker threads (0: one per core)");
ABSL_FLAG(int64_t, memory_budget_mb, 0,
          "serve: memory budget for grids and work, MiB (0: half of the cgroup memory limit, or "
          "of the physical memory when there is none; printed at start)");
ABSL_FLAG(absl::Duration, import_idle_timeout, absl::Seconds(60),
          "serve: an ImportGrid or ImportArchive stream that sends nothing for this long is "
          "ended (DEADLINE_EXCEEDED) and its memory released (0: never)");
ABSL_FLAG(std::string, cgns_decoder, "",
          "serve: the executable that decodes CGNS uploads in a child process (empty: "
          "splinegrid-cgns-decode beside this binary)");
ABSL_FLAG(int64_t, cgns_decoder_memory_mb, 0,
          "serve: address-space limit of a CGNS decoder child, MiB, reserved against the memory "
          "budget while it runs (0: 1024, or half the budget when that is less; at least 64)");
ABSL_FLAG(int64_t, cgns_decoder_cpu_seconds,
          absl::ToInt64Seconds(splinegrid::server::CgnsDecoderOptions().cpu_limit),
          "serve: CPU seconds a CGNS decoder child may use (SIGXCPU, then SIGKILL 5 s later)");
ABSL_FLAG(int64_t, cgns_decoder_timeout_seconds,
          absl::ToInt64Seconds(splinegrid::server::CgnsDecoderOptions().wall_limit),
          "serve: wall-clock seconds a CGNS decoder child may take before it is killed");
ABSL_FLAG(int64_t, max_output_points, int64_t{1} << 30,
          "serve: the most points one evaluation may ask for");
ABSL_FLAG(absl::Duration, shutdown_grace, absl::Seconds(10),
          "serve: time in-flight calls get on SIGTERM before they are cancelled");
ABSL_FLAG(bool, log_calls, true, "serve: one log line per call on stderr");
ABSL_FLAG(std::string, log_format, "text",
          "serve: the call log's lines: text, or json (one object per call: time, method, grid, "
          "principal, status, ms, message)");
ABSL_FLAG(absl::Duration, drain_notice, splinegrid::server::ServerOptions().drain_notice,
          "serve: on SIGTERM, health reports NOT_SERVING this long while calls are still served "
          "(for load balancers and probes), before new calls are refused (0: refuse at once)");
ABSL_FLAG(int, keep_revisions, splinegrid::server::ServerOptions().max_deform_revisions,
          "serve: deformed revisions kept per grid (older ones are dropped; fitted and faired "
          "revisions are always kept)");

// serve: fair scheduling and per-principal limits (server/scheduler.h, server/stream_limits.h).
ABSL_FLAG(int, max_running_long_tasks, splinegrid::server::ServerOptions().max_running_long_tasks,
          "serve: long calls (fits, fairing, generation, imports, large evaluations) running at "
          "once (0: worker threads - 1, at least 1; the other workers keep to quick calls)");
ABSL_FLAG(int, max_queued_long_calls_per_principal,
          splinegrid::server::ServerOptions().max_queued_long_calls_per_principal,
          "serve: long calls one caller may have waiting (RESOURCE_EXHAUSTED beyond)");
ABSL_FLAG(int, max_streams_per_principal,
          splinegrid::server::ServerOptions().max_streams_per_principal,
          "serve: streaming calls (watch, eval, import, export) one caller may hold open "
          "(RESOURCE_EXHAUSTED beyond)");

// serve: the Prometheus endpoint (server/metrics_endpoint.h).
ABSL_FLAG(std::string, metrics_address, "",
          "serve: HOST:PORT of a Prometheus endpoint, GET /metrics in plaintext HTTP (empty: "
          "none; a host that is not loopback needs --metrics_insecure)");
ABSL_FLAG(bool, metrics_insecure, false,
          "serve: allow --metrics_address on a host that is not loopback (the metrics are "
          "unauthenticated plaintext: a trusted network only)");
