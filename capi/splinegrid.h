/* splinegrid.h: the C API of the splinegrid client, for solvers written in C or Fortran (the
 * Fortran 2003 module `splinegrid`, capi/fortran/splinegrid.f90, binds exactly these calls).
 *
 * It wraps the C++ client library (client/client.h) for what a coupled solver needs: connect,
 * import and fit a grid, deform it by a rigid motion of a boundary or by new boundary points,
 * evaluate a block into an array the caller owns, and watch a grid's new revisions.
 *
 * Errors. Every call returns an sg_status: SG_OK (0) or one of the gRPC status codes below,
 * with the same meaning as the service's (DESIGN.md "API conventions"): INVALID_ARGUMENT for a
 * malformed argument (the message names the argument and its value, e.g. "points: capacity 10
 * values, block 0 needs 66306"), NOT_FOUND for an unknown grid, FAILED_PRECONDITION for a
 * deformation that folds cells, UNAVAILABLE when the server cannot be reached, ... The message
 * of the last call that a thread made on a client (or on one of its watches) is
 * sg_last_error(client): "" after a call that succeeded. Calls given a NULL client return
 * SG_INVALID_ARGUMENT and have nowhere to keep a message.
 *
 * Threads. A client may be used by several threads at once (each call is a gRPC call on one
 * shared channel); its error messages are kept per thread, so one thread's failure never
 * overwrites the message another thread is reading. There is no global state.
 *
 * Ownership. sg_connect allocates a client, sg_close frees it; sg_watch_open allocates a watch,
 * sg_watch_close frees it (a watch may outlive its client's sg_close: it keeps the connection
 * until it is closed). Every array and string passed in stays the caller's and is only read
 * during the call; arrays filled by a call (points, ids) are the caller's, of the capacity the
 * caller gives. Strings are NUL-terminated UTF-8. No C++ exception ever leaves a call (an
 * allocation failure is SG_RESOURCE_EXHAUSTED).
 *
 * Layout of points: interleaved coordinates, i fastest,
 *   points[s + spatial_dim * (i + ni * (j + nj * k))],  s < spatial_dim
 * which is Fortran's points(spatial_dim, ni, nj, nk).
 */
#ifndef SPLINEGRID_CAPI_SPLINEGRID_H_
#define SPLINEGRID_CAPI_SPLINEGRID_H_

#include <stddef.h>
#include <stdint.h>

#if defined(SPLINEGRID_C_BUILDING)
#define SG_API __attribute__((visibility("default")))
#else
#define SG_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes: the gRPC / absl codes, numerically. */
typedef int sg_status;
enum {
  SG_OK = 0,
  SG_CANCELLED = 1,
  SG_UNKNOWN = 2,
  SG_INVALID_ARGUMENT = 3,
  SG_DEADLINE_EXCEEDED = 4,
  SG_NOT_FOUND = 5,
  SG_ALREADY_EXISTS = 6,
  SG_PERMISSION_DENIED = 7,
  SG_RESOURCE_EXHAUSTED = 8,
  SG_FAILED_PRECONDITION = 9,
  SG_ABORTED = 10,
  SG_OUT_OF_RANGE = 11,
  SG_UNIMPLEMENTED = 12,
  SG_INTERNAL = 13,
  SG_UNAVAILABLE = 14,
  SG_DATA_LOSS = 15,
  SG_UNAUTHENTICATED = 16
};

/* Boundary kinds (a deformation's moved boundary) and block faces (a range of boundary points),
 * numbered as splinegrid.v1 BoundaryKind and BlockFace. */
enum { SG_BOUNDARY_WALL = 1, SG_BOUNDARY_INTERFACE = 2, SG_BOUNDARY_OUTER = 3 };
enum {
  SG_FACE_I_MIN = 1,
  SG_FACE_I_MAX = 2,
  SG_FACE_J_MIN = 3,
  SG_FACE_J_MAX = 4,
  SG_FACE_K_MIN = 5,
  SG_FACE_K_MAX = 6
};

typedef struct sg_client sg_client; /* a connection to one server */
typedef struct sg_watch sg_watch;   /* an open WatchGrid call */

/* What a fit stored (FitGridResponse). */
typedef struct sg_fit_result {
  int64_t revision;           /* the new revision */
  int64_t num_points;         /* points fitted */
  int64_t num_control_points; /* control points of every block together */
  double max_deviation;       /* largest distance of a point from the spline, grid units */
  double seconds;             /* the server's fit time */
  double first_layer_change;  /* largest relative change of a wall's first-layer height (what a
                                 solver's y+ follows), e.g. 0.05 for 5%; -1: no wall measured */
} sg_fit_result;

/* How sg_fit_with fits; all zero is sg_fit(client, grid, 0, result): tolerances by kind. */
typedef struct sg_fit_options {
  double tolerance;   /* > 0: the largest deviation of any point; 0: tolerances by boundary kind */
  double first_layer; /* by kind only: hold the first-layer heights at walls to this relative
                         change (e.g. 0.05); 0: not held (they may change by tens of percent) */
} sg_fit_options;

/* How a deformation is stamped and checked (DeformGridRequest); all zero is a valid default:
 * deform the latest revision, no staleness check, time 0, step 0, fold check at level 0, the
 * walls move. */
typedef struct sg_deform_options {
  int64_t reference_revision; /* revision whose geometry is deformed; 0: the latest. Giving
                                 the fitted revision every step makes motions absolute. */
  int64_t base_revision;      /* the latest revision the caller has seen: ABORTED if the grid
                                 has a newer one; 0: no check */
  double time;                /* solver time stamped on the new revision */
  int64_t step;               /* solver time step stamped on the new revision */
  int32_t check_level;        /* refinement level of the server's fold check, 0 to 4 */
  int32_t boundary_kind;      /* SG_BOUNDARY_*: the moved boundary (rigid and point motions); 0: walls */
  double max_boundary_error;  /* sg_deform_points: how far the deformed boundary may miss the
                                 points (else SG_FAILED_PRECONDITION); 0: twice the fit's
                                 tolerance of the moved boundary's kind */
} sg_deform_options;

/* What a deformation stored (DeformGridResponse and its DeformReport). */
typedef struct sg_deform_result {
  int64_t revision;          /* the new revision */
  double min_jacobian_ratio; /* deformed / reference cell measure at the check level (> 0) */
  double max_jacobian_ratio;
  double seconds; /* the server's deformation and check time */
  int32_t moved_controls;
  int32_t reserved;
  double boundary_error; /* sg_deform_points: how far the deformed boundary lies from the
                            points given (rigid motions: 0, met exactly) */
} sg_deform_result;

/* A grid's shape (GetGrid, basic view). */
typedef struct sg_grid_info {
  int64_t latest_revision; /* 0 before the first fit */
  int32_t num_blocks;
  int32_t spatial_dim; /* coordinates per point: 2 or 3 */
} sg_grid_info;

/* One stored revision, as a watch reports it (RevisionInfo). */
typedef struct sg_revision_info {
  int64_t revision;
  int64_t parent_revision; /* FAIR, DEFORM: the revision it was made from */
  int64_t step;            /* DEFORM: the solver's step */
  double time;             /* DEFORM: the solver's time */
  int32_t origin;          /* splinegrid.v1 RevisionOrigin */
  int32_t reserved;
} sg_revision_info;

/* ---- Status ---- */

/* The message of the last call this thread made on `client` or one of its watches ("" after a
 * success). Valid until this thread's next call on `client`; "" for a NULL client. */
SG_API const char* sg_last_error(const sg_client* client);
/* The same, copied into `buffer` of `size` bytes (NUL-terminated, truncated to fit; nothing is
 * written when size is 0): the message's full length in bytes. For Fortran. */
SG_API size_t sg_last_error_copy(const sg_client* client, char* buffer, size_t size);
/* The code's name ("INVALID_ARGUMENT"); "UNKNOWN_CODE" for a number that is none. Static. */
SG_API const char* sg_status_name(sg_status status);
/* The library's version, "0.2.0". Static. */
SG_API const char* sg_version(void);

/* ---- Connection ---- */

/* Connects to `target` ("host:port") and checks that the server answers its health check
 * within `timeout_seconds` (also the deadline of every later call, retries included; <= 0: 120
 * s). A call that breaks off (UNAVAILABLE: the server restarting, a replica gone) is made again
 * with backoff (50 ms doubling to 2 s) until that deadline; a retried call that stores
 * something can meet its own earlier attempt (a deform with base_revision then answers
 * SG_ABORTED, a fit may store a second revision). `token` (bearer token) and `tls_ca_file` (PEM of the CA to trust: TLS instead of
 * plaintext) may be NULL or "". On SG_OK `*client` is a connected client. On an error other
 * than INVALID_ARGUMENT for a NULL `client`, `*client` is still set, to a client whose
 * sg_last_error says what went wrong (as sqlite3_open does): close it with sg_close. */
SG_API sg_status sg_connect(const char* target, const char* token, const char* tls_ca_file,
                            double timeout_seconds, sg_client** client);
/* Frees a client; NULL is ignored. No call may be running on it. */
SG_API void sg_close(sg_client* client);

/* ---- Grids ---- */

/* Imports a Plot3D file (any flavour the server reads) as a new grid. `grid_id` may be NULL or
 * "" (the server picks one); with planar_view != 0 a two-plane 3D file is stored as its 2D
 * view. The new grid's id is copied into `id` (capacity `id_size` bytes, NUL-terminated;
 * OUT_OF_RANGE naming `id` if it does not fit, the grid is still stored) unless `id` is NULL. */
SG_API sg_status sg_import_plot3d(sg_client* client, const char* path, const char* grid_id,
                                  int32_t planar_view, char* id, size_t id_size);
/* Imports a CGNS file (structured zones; the server decodes it in a sandboxed child process) as
 * a new grid: its boundary conditions become the default boundary kinds of later fits.
 * `grid_id`, `id`, `id_size` as for sg_import_plot3d. INVALID_ARGUMENT ("cgns: ...") for a file
 * the decoder cannot read. */
SG_API sg_status sg_import_cgns(sg_client* client, const char* path, const char* grid_id,
                                char* id, size_t id_size);
/* Imports one block of points as a new grid: extents[3] points per direction (1 for unused
 * ones), `spatial_dim` (2 or 3) coordinates each, `count` values in `points` (must equal
 * ni * nj * nk * spatial_dim). `grid_id`, `id`, `id_size` as for sg_import_plot3d. */
SG_API sg_status sg_import_points(sg_client* client, const char* grid_id, int32_t spatial_dim,
                                  const int32_t extents[3], const double* points, int64_t count,
                                  char* id, size_t id_size);
/* Fits the grid's latest source: tolerance > 0 is the largest deviation of any point;
 * tolerance == 0 fits to tolerances by boundary kind (the QUADFLOW defaults: 0.15e-3 on walls,
 * 2e-3 on interfaces, 8e-3 outer, relative to the detected reference length). `result` may be
 * NULL. */
SG_API sg_status sg_fit(sg_client* client, const char* grid, double tolerance,
                        sg_fit_result* result);
/* sg_fit with `options` (NULL: all zero). A first_layer with a tolerance > 0, outside [0, 1],
 * or on a grid without walls is INVALID_ARGUMENT naming it. */
SG_API sg_status sg_fit_with(sg_client* client, const char* grid, const sg_fit_options* options,
                             sg_fit_result* result);
/* The grid's shape. */
SG_API sg_status sg_grid_info_get(sg_client* client, const char* grid, sg_grid_info* info);
/* Point counts of block `block` evaluated at refinement `level`: (n - 1) 2^level + 1 in every
 * direction with n > 1 original points. */
SG_API sg_status sg_block_extents(sg_client* client, const char* grid, int32_t block, int32_t level,
                                  int32_t extents[3]);
/* Deletes a grid and all its revisions. */
SG_API sg_status sg_delete(sg_client* client, const char* grid);

/* ---- Deformation ---- */

/* Rotates the selected boundary (options->boundary_kind) by `angle_degrees` about the axis
 * through `center` (3 values; NULL: the origin; the axis is z, for 2D grids too), then
 * translates it by `translation` (3 values; NULL: none); the interior follows and the outer
 * boundary stays. `options` may be NULL (all zero), `result` may be NULL. */
SG_API sg_status sg_deform_rigid(sg_client* client, const char* grid,
                                 const sg_deform_options* options, double angle_degrees,
                                 const double center[3], const double translation[3],
                                 sg_deform_result* result);
/* Moves the boundary points of one face range of `block` (face SG_FACE_*, begin[3] .. end[3]
 * inclusive in original grid indices) to `points` (or by them, with displacements != 0): the
 * range's points at refinement `level` in point order (i fastest), spatial_dim values each,
 * `count` values; the server fits them with the stored basis. The range must lie on the
 * boundary options->boundary_kind selects (0: the walls; SG_BOUNDARY_OUTER to move far-field
 * points), whose other points stay. */
SG_API sg_status sg_deform_points(sg_client* client, const char* grid,
                                  const sg_deform_options* options, int32_t block, int32_t face,
                                  const int32_t begin[3], const int32_t end[3], int32_t level,
                                  const double* points, int64_t count, int32_t displacements,
                                  sg_deform_result* result);

/* ---- Evaluation ---- */

/* Evaluates block `block` of `revision` (0: the latest) at refinement `level` (0: the original
 * points; 2^level - 1 new points in every interval) into `points`, which holds `capacity`
 * doubles: ni * nj * nk * spatial_dim are written (see sg_block_extents; a smaller capacity is
 * INVALID_ARGUMENT naming `points`, and nothing is written). `extents` (3 values) and
 * `revision_out` receive the block's point counts and the revision evaluated; either may be
 * NULL. */
SG_API sg_status sg_evaluate(sg_client* client, const char* grid, int64_t revision, int32_t block,
                             int32_t level, double* points, int64_t capacity, int32_t extents[3],
                             int64_t* revision_out);

/* sg_evaluate into an array of `rank` (1 to 4) dimensions `shape` (`rank` values, column-major,
 * as Fortran's shape()) that must fit the block: rank 1 any size from the needed one up; otherwise
 * (spatial_dim, ni, nj, nk) with the directions after the last dimension merged into it, e.g.
 * (spatial_dim, ni, nj) for nk = 1 or (spatial_dim, ni * nj * nk). Anything else is
 * INVALID_ARGUMENT naming both shapes, and nothing is written. The Fortran module's sg_evaluate
 * calls it, so that an array of another level's shape is refused rather than filled with this
 * level's points in the wrong layout. */
SG_API sg_status sg_evaluate_shaped(sg_client* client, const char* grid, int64_t revision,
                                    int32_t block, int32_t level, double* points, int32_t rank,
                                    const int64_t* shape, int32_t extents[3],
                                    int64_t* revision_out);

/* ---- Watching ---- */

/* Opens a watch of the grid's revisions: those after `after_revision` (0: every stored one
 * first, -1: only new ones), then each new one as it is stored. The call has no deadline. Its
 * errors (an unknown grid shows at the first sg_watch_next) are reported by the status codes and
 * by sg_last_error(client) of the thread that called. */
SG_API sg_status sg_watch_open(sg_client* client, const char* grid, int64_t after_revision,
                               sg_watch** watch);
/* Blocks until the next revision: SG_OK with *has_revision = 1 and `info` filled; SG_OK with
 * *has_revision = 0 when the watch has ended without an error (the grid was deleted, the server
 * stopped, sg_watch_cancel); the call's error otherwise (NOT_FOUND for an unknown grid). */
SG_API sg_status sg_watch_next(sg_watch* watch, sg_revision_info* info, int32_t* has_revision);
/* Ends the watch from any thread: a blocked sg_watch_next returns with *has_revision = 0.
 * Idempotent; NULL is ignored. */
SG_API void sg_watch_cancel(sg_watch* watch);
/* Cancels (if still open) and frees a watch; NULL is ignored. No sg_watch_next may be running
 * on it. */
SG_API void sg_watch_close(sg_watch* watch);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* SPLINEGRID_CAPI_SPLINEGRID_H_ */
