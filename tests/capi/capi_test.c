/* capi_test: every call of the C API (capi/splinegrid.h) against a running server, with its
 * error paths: a NULL client, a bad address, an unknown grid, wrong array sizes, bad enums;
 * each error's code and the field its message names. Started by capi_e2e_test.cc:
 *
 *   capi_test 127.0.0.1:PORT CLOSED_PORT GRID.p2dfmt
 *
 * Prints one line per failed check and a summary; exits 1 if any check failed. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "splinegrid.h"

static int checks = 0;
static int failures = 0;

#define CHECK(condition)                                                            \
  do {                                                                              \
    ++checks;                                                                       \
    if (!(condition)) {                                                             \
      ++failures;                                                                   \
      fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #condition); \
    }                                                                               \
  } while (0)

/* `call` returned `code` and the client's message contains `text`. */
#define CHECK_ERROR(client, call, code, text)                                                      \
  do {                                                                                             \
    const sg_status got_ = (call);                                                                 \
    const char* message_ = sg_last_error(client);                                                  \
    ++checks;                                                                                      \
    if (got_ != (code) || strstr(message_, (text)) == NULL) {                                      \
      ++failures;                                                                                  \
      fprintf(stderr, "%s:%d: %s: got %s \"%s\", want %s containing \"%s\"\n", __FILE__, __LINE__, \
              #call, sg_status_name(got_), message_, sg_status_name(code), text);                  \
    }                                                                                              \
  } while (0)

#define CHECK_OK(client, call)                                                               \
  do {                                                                                       \
    const sg_status got_ = (call);                                                           \
    ++checks;                                                                                \
    if (got_ != SG_OK) {                                                                     \
      ++failures;                                                                            \
      fprintf(stderr, "%s:%d: %s: %s %s\n", __FILE__, __LINE__, #call, sg_status_name(got_), \
              sg_last_error(client));                                                        \
    }                                                                                        \
  } while (0)

/* A sheared 21 x 11 surface in 2D: x = i / 20 + 0.1 j / 10, y = (j / 10)^2. */
enum { kNi = 21, kNj = 11 };
static void SampleBlock(double* points) {
  for (int j = 0; j < kNj; ++j) {
    for (int i = 0; i < kNi; ++i) {
      points[2 * (i + kNi * j)] = i / 20.0 + 0.1 * j / 10.0;
      points[2 * (i + kNi * j) + 1] = (j / 10.0) * (j / 10.0);
    }
  }
}

/* Two threads failing on one client at once: each reads its own message. */
struct ThreadArgs {
  sg_client* client;
  const char* grid;
  int mismatches;
};
static void* FailRepeatedly(void* arg) {
  struct ThreadArgs* args = (struct ThreadArgs*)arg;
  for (int n = 0; n < 20; ++n) {
    if (sg_fit(args->client, args->grid, 1e-3, NULL) != SG_NOT_FOUND ||
        strstr(sg_last_error(args->client), args->grid) == NULL) {
      ++args->mismatches;
    }
  }
  return NULL;
}

/* Cancels a watch after a moment, from another thread. */
static void* CancelLater(void* arg) {
  usleep(300 * 1000);
  sg_watch_cancel((sg_watch*)arg);
  return NULL;
}

static void NullClient(void) {
  sg_fit_result fit;
  sg_grid_info info;
  int32_t extents[3];
  double points[4];
  sg_watch* watch = NULL;
  sg_revision_info revision;
  int32_t has = 7;
  CHECK(sg_connect("127.0.0.1:1", NULL, NULL, 1.0, NULL) == SG_INVALID_ARGUMENT);
  CHECK(sg_import_plot3d(NULL, "f", "g", 0, NULL, 0) == SG_INVALID_ARGUMENT);
  CHECK(sg_import_points(NULL, "g", 2, extents, points, 4, NULL, 0) == SG_INVALID_ARGUMENT);
  CHECK(sg_fit(NULL, "g", 0.0, &fit) == SG_INVALID_ARGUMENT);
  CHECK(sg_grid_info_get(NULL, "g", &info) == SG_INVALID_ARGUMENT);
  CHECK(sg_block_extents(NULL, "g", 0, 0, extents) == SG_INVALID_ARGUMENT);
  CHECK(sg_delete(NULL, "g") == SG_INVALID_ARGUMENT);
  CHECK(sg_deform_rigid(NULL, "g", NULL, 1.0, NULL, NULL, NULL) == SG_INVALID_ARGUMENT);
  CHECK(sg_deform_points(NULL, "g", NULL, 0, SG_FACE_J_MIN, extents, extents, 0, points, 4, 0,
                         NULL) == SG_INVALID_ARGUMENT);
  CHECK(sg_evaluate(NULL, "g", 0, 0, 0, points, 4, NULL, NULL) == SG_INVALID_ARGUMENT);
  CHECK(sg_watch_open(NULL, "g", 0, &watch) == SG_INVALID_ARGUMENT);
  CHECK(sg_watch_next(NULL, &revision, &has) == SG_INVALID_ARGUMENT);
  CHECK(strcmp(sg_last_error(NULL), "") == 0);
  sg_close(NULL);
  sg_watch_cancel(NULL);
  sg_watch_close(NULL);
}

static void Connections(const char* closed_address) {
  sg_client* bad = NULL;
  CHECK_ERROR(bad, sg_connect(closed_address, NULL, NULL, 5.0, &bad), SG_UNAVAILABLE,
              "connect to ");
  CHECK(bad != NULL);
  CHECK(strstr(sg_last_error(bad), closed_address) != NULL);
  /* A failed connection refuses calls. */
  CHECK_ERROR(bad, sg_fit(bad, "g", 0.0, NULL), SG_FAILED_PRECONDITION, "not connected");
  sg_close(bad);
  bad = NULL;
  CHECK_ERROR(bad, sg_connect("", NULL, NULL, 5.0, &bad), SG_INVALID_ARGUMENT, "target: empty");
  sg_close(bad);
  bad = NULL;
  CHECK_ERROR(bad, sg_connect(closed_address, NULL, NULL, NAN, &bad), SG_INVALID_ARGUMENT,
              "timeout_seconds: nan");
  sg_close(bad);
  bad = NULL;
  CHECK_ERROR(bad, sg_connect(closed_address, NULL, "/nonexistent/ca.pem", 5.0, &bad), SG_NOT_FOUND,
              "tls_ca_file");
  sg_close(bad);
}

static void Points(sg_client* client) {
  double points[2 * kNi * kNj];
  SampleBlock(points);
  const int32_t extents[3] = {kNi, kNj, 1};
  char id[64];
  CHECK_ERROR(client, sg_import_points(client, "c-points", 2, extents, points, 10, id, sizeof id),
              SG_INVALID_ARGUMENT, "count: 10 values in points; extents 21 x 11 x 1");
  CHECK_ERROR(client,
              sg_import_points(client, "c-points", 4, extents, points, 4 * kNi * kNj, id, 64),
              SG_INVALID_ARGUMENT, "spatial_dim: 4");
  const int32_t zero[3] = {kNi, 0, 1};
  CHECK_ERROR(client, sg_import_points(client, "c-points", 2, zero, points, 0, id, 64),
              SG_INVALID_ARGUMENT, "extents");
  points[5] = NAN;
  CHECK_ERROR(client,
              sg_import_points(client, "c-points", 2, extents, points, 2 * kNi * kNj, id, 64),
              SG_INVALID_ARGUMENT, "points");
  SampleBlock(points);
  CHECK_OK(client, sg_import_points(client, "c-points", 2, extents, points, 2 * kNi * kNj, id, 64));
  CHECK(strcmp(id, "c-points") == 0);
  CHECK(strcmp(sg_last_error(client), "") == 0);

  sg_fit_result fit;
  CHECK_ERROR(client, sg_fit(client, "c-points", -1.0, &fit), SG_INVALID_ARGUMENT, "tolerance: -1");
  CHECK_ERROR(client, sg_fit(client, "nothing", 1e-4, &fit), SG_NOT_FOUND, "nothing");
  CHECK_OK(client, sg_fit(client, "c-points", 1e-5, &fit));
  CHECK(fit.revision == 1);
  CHECK(fit.num_points == kNi * kNj);
  CHECK(fit.num_control_points > 0 && fit.num_control_points <= kNi * kNj);
  CHECK(fit.max_deviation <= 1e-5);

  sg_grid_info info;
  CHECK_OK(client, sg_grid_info_get(client, "c-points", &info));
  CHECK(info.latest_revision == 1 && info.num_blocks == 1 && info.spatial_dim == 2);
  CHECK_ERROR(client, sg_grid_info_get(client, "nothing", &info), SG_NOT_FOUND, "nothing");
  CHECK_ERROR(client, sg_grid_info_get(client, "c-points", NULL), SG_INVALID_ARGUMENT,
              "info: NULL");

  int32_t refined[3];
  CHECK_OK(client, sg_block_extents(client, "c-points", 0, 1, refined));
  CHECK(refined[0] == 41 && refined[1] == 21 && refined[2] == 1);
  CHECK_ERROR(client, sg_block_extents(client, "c-points", 5, 1, refined), SG_INVALID_ARGUMENT,
              "block: 5 (the grid has 1 blocks)");
  CHECK_ERROR(client, sg_block_extents(client, "c-points", 0, -1, refined), SG_INVALID_ARGUMENT,
              "level: -1");

  /* Level 0 gives the original points back within the tolerance. */
  double evaluated[2 * kNi * kNj];
  int32_t got[3] = {0, 0, 0};
  int64_t revision = 0;
  CHECK_ERROR(client,
              sg_evaluate(client, "c-points", 0, 0, 0, evaluated, 2 * kNi * kNj - 1, got, NULL),
              SG_INVALID_ARGUMENT, "points: capacity 461 values, block 0 at level 0 needs 462");
  CHECK(got[0] == 0); /* nothing written */
  CHECK_OK(client,
           sg_evaluate(client, "c-points", 0, 0, 0, evaluated, 2 * kNi * kNj, got, &revision));
  CHECK(got[0] == kNi && got[1] == kNj && got[2] == 1 && revision == 1);
  double worst = 0.0;
  for (int v = 0; v < 2 * kNi * kNj; ++v) worst = fmax(worst, fabs(evaluated[v] - points[v]));
  CHECK(worst <= 1e-5);
  CHECK_ERROR(client,
              sg_evaluate(client, "c-points", 7, 0, 0, evaluated, 2 * kNi * kNj, NULL, NULL),
              SG_NOT_FOUND, "7");
  CHECK_ERROR(client,
              sg_evaluate(client, "c-points", 0, 3, 0, evaluated, 2 * kNi * kNj, NULL, NULL),
              SG_INVALID_ARGUMENT, "3");
  CHECK_ERROR(client, sg_evaluate(client, "nothing", 0, 0, 0, evaluated, 4, NULL, NULL),
              SG_NOT_FOUND, "nothing");
  /* Shaped arrays (the Fortran module's): (2, ni, nj), (2, ni * nj) and (2, ni, nj, 1) fit;
   * another level's shape, even large enough, does not, and nothing is written. */
  const int64_t fits[3][4] = {{2, kNi, kNj, 1}, {2, kNi * kNj, 1, 1}, {2, kNi, kNj, 1}};
  const int32_t ranks[3] = {3, 2, 4};
  for (int q = 0; q < 3; ++q) {
    CHECK_OK(client, sg_evaluate_shaped(client, "c-points", 0, 0, 0, evaluated, ranks[q], fits[q],
                                        got, NULL));
  }
  const int64_t level1[3] = {2, 2 * kNi - 1, 2 * kNj - 1};
  static double larger[2 * (2 * kNi - 1) * (2 * kNj - 1)];
  larger[0] = -7.0;
  CHECK_ERROR(client, sg_evaluate_shaped(client, "c-points", 0, 0, 0, larger, 3, level1, got, NULL),
              SG_INVALID_ARGUMENT, "points: shape (2, 41, 21) does not fit block 0 at level 0");
  CHECK(larger[0] == -7.0); /* nothing written */
  CHECK_OK(client, sg_delete(client, "c-points"));
  CHECK_ERROR(client, sg_delete(client, "c-points"), SG_NOT_FOUND, "c-points");
}

/* A C-grid with walls: import, fit by kind, rigid and point deformations, a watch. */
static void Airfoil(sg_client* client, const char* grid_file) {
  char id[4];
  CHECK_ERROR(client, sg_import_plot3d(client, "/nonexistent/grid.x", "c-naca", 0, NULL, 0),
              SG_NOT_FOUND, "/nonexistent/grid.x");
  /* Stored, but its id does not fit the buffer. */
  CHECK_ERROR(client, sg_import_plot3d(client, grid_file, "c-naca", 0, id, sizeof id),
              SG_OUT_OF_RANGE, "id: capacity 4 bytes, \"c-naca\" needs 7");
  CHECK_ERROR(client, sg_import_plot3d(client, grid_file, "c-naca", 0, NULL, 0), SG_ALREADY_EXISTS,
              "c-naca");
  sg_fit_result fit;
  CHECK_OK(client, sg_fit(client, "c-naca", 0.0, &fit));
  CHECK(fit.revision == 1);
  /* The first-layer heights a solver's y+ follows: reported, and held when asked. */
  CHECK(fit.first_layer_change > 0.05);
  CHECK_OK(client, sg_import_plot3d(client, grid_file, "c-layer", 0, NULL, 0));
  sg_fit_options held = {0.0, 0.05};
  CHECK_OK(client, sg_fit_with(client, "c-layer", &held, &fit));
  CHECK(fit.revision == 1 && fit.first_layer_change >= 0.0 && fit.first_layer_change <= 0.05);
  held.tolerance = 1e-3;
  CHECK_ERROR(client, sg_fit_with(client, "c-layer", &held, &fit), SG_INVALID_ARGUMENT,
              "first_layer: 0.05 holds with tolerances by kind only");
  held.tolerance = 0.0;
  held.first_layer = 2.0;
  CHECK_ERROR(client, sg_fit_with(client, "c-layer", &held, &fit), SG_INVALID_ARGUMENT,
              "spec.boundary_tolerances.first_layer = 2 is outside [0, 1]");
  CHECK_OK(client, sg_delete(client, "c-layer"));

  sg_deform_options options;
  memset(&options, 0, sizeof options);
  options.reference_revision = 1;
  options.base_revision = 1;
  options.time = 0.01;
  options.step = 1;
  options.check_level = 1;
  const double center[3] = {0.25, 0.0, 0.0};
  sg_deform_result moved;
  CHECK_OK(client, sg_deform_rigid(client, "c-naca", &options, 2.0, center, NULL, &moved));
  CHECK(moved.revision == 2);
  CHECK(moved.min_jacobian_ratio > 0.0 && moved.moved_controls > 0);
  /* base_revision 1 is stale now. */
  CHECK_ERROR(client, sg_deform_rigid(client, "c-naca", &options, 2.0, center, NULL, &moved),
              SG_ABORTED, "stale");
  options.base_revision = 0;
  CHECK_ERROR(client, sg_deform_rigid(client, "c-naca", &options, NAN, center, NULL, &moved),
              SG_INVALID_ARGUMENT, "angle_degrees = nan");
  options.boundary_kind = 7;
  CHECK_ERROR(client, sg_deform_rigid(client, "c-naca", &options, 1.0, center, NULL, &moved),
              SG_INVALID_ARGUMENT, "options.boundary_kind: 7");
  options.boundary_kind = SG_BOUNDARY_WALL;
  CHECK_ERROR(client, sg_deform_rigid(client, "nothing", &options, 1.0, NULL, NULL, &moved),
              SG_NOT_FOUND, "nothing");

  /* The wall points i = 50..60 of j = 0 moved up by a bump of 2e-4 (displacements). */
  const int32_t begin[3] = {50, 0, 0};
  const int32_t end[3] = {60, 0, 0};
  double bump[22];
  for (int p = 0; p < 11; ++p) {
    bump[2 * p] = 0.0;
    bump[2 * p + 1] = 2e-4 * sin(3.14159265358979 * p / 10.0);
  }
  options.step = 2;
  CHECK_ERROR(client,
              sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MIN, begin, end, 0, bump, 7,
                               1, &moved),
              SG_INVALID_ARGUMENT, "7 values for 11");
  CHECK_ERROR(
      client,
      sg_deform_points(client, "c-naca", &options, 0, 9, begin, end, 0, bump, 22, 1, &moved),
      SG_INVALID_ARGUMENT, "face: 9");
  CHECK_ERROR(client,
              sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MIN, begin, end, 0, NULL,
                               22, 1, &moved),
              SG_INVALID_ARGUMENT, "points: NULL");
  /* One point of them moved by 2e-3: the wall's basis cannot follow a spike, misses it by more
   * than the wall tolerance (1.5e-4 chords), and that is refused. */
  double spike[22];
  for (int v = 0; v < 22; ++v) spike[v] = 0.0;
  spike[11] = 2e-3;
  CHECK_ERROR(client,
              sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MIN, begin, end, 0, spike,
                               22, 1, &moved),
              SG_FAILED_PRECONDITION, "the deformed boundary misses boundary_points[0] by ");
  options.max_boundary_error = -1.0;
  CHECK_ERROR(client,
              sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MIN, begin, end, 0, bump,
                               22, 1, &moved),
              SG_INVALID_ARGUMENT, "max_boundary_error = -1");
  options.max_boundary_error = 0.0;
  CHECK_OK(client, sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MIN, begin, end, 0,
                                    bump, 22, 1, &moved));
  CHECK(moved.revision == 3 && moved.min_jacobian_ratio > 0.0);
  CHECK(moved.boundary_error >= 0.0 && moved.boundary_error <= 1.5e-4);

  /* The watch sends the three stored revisions, then blocks until cancelled. */
  sg_watch* watch = NULL;
  CHECK_OK(client, sg_watch_open(client, "c-naca", 0, &watch));
  sg_revision_info info;
  int32_t has = 0;
  for (int64_t r = 1; r <= 3; ++r) {
    CHECK_OK(client, sg_watch_next(watch, &info, &has));
    CHECK(has == 1 && info.revision == r);
  }
  CHECK(info.step == 2 && info.parent_revision == 1 && fabs(info.time - 0.01) < 1e-12);
  pthread_t canceller;
  pthread_create(&canceller, NULL, CancelLater, watch);
  CHECK_OK(client, sg_watch_next(watch, &info, &has));
  CHECK(has == 0);
  pthread_join(canceller, NULL);
  CHECK_OK(client, sg_watch_next(watch, &info, &has)); /* ended stays ended */
  CHECK(has == 0);
  sg_watch_close(watch);
  CHECK_OK(client, sg_watch_open(client, "nothing", 0, &watch));
  CHECK_ERROR(client, sg_watch_next(watch, &info, &has), SG_NOT_FOUND, "nothing");
  CHECK(has == 0);
  sg_watch_close(watch);
  CHECK_ERROR(client, sg_watch_open(client, "c-naca", -5, &watch), SG_INVALID_ARGUMENT,
              "after_revision: -5");

  /* Far-field points (j = 32) move only when the options select the outer boundary; the
   * refusal names the point by its indices. */
  const int32_t far_begin[3] = {50, 32, 0};
  const int32_t far_end[3] = {60, 32, 0};
  double still[22] = {0.0};
  options.base_revision = 0;
  options.step = 4;
  options.boundary_kind = 0; /* the walls */
  CHECK_ERROR(client,
              sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MAX, far_begin, far_end, 0,
                               still, 22, 1, &moved),
              SG_INVALID_ARGUMENT, "point (50, 32, 0) of block 0 is not on the moved boundary");
  options.boundary_kind = SG_BOUNDARY_OUTER;
  CHECK_OK(client, sg_deform_points(client, "c-naca", &options, 0, SG_FACE_J_MAX, far_begin,
                                    far_end, 0, still, 22, 1, &moved));
  CHECK(moved.revision == 4 && moved.min_jacobian_ratio > 0.0);
  CHECK_OK(client, sg_delete(client, "c-naca"));
}

/* A CGNS file (written by Debian's plot3d_to_cgns): imported, fitted by its kinds; a Plot3D file
 * given as CGNS is the decoder's INVALID_ARGUMENT. */
static void Cgns(sg_client* client, const char* cgns_file, const char* plot3d_file) {
  CHECK(sg_import_cgns(NULL, cgns_file, "c-cgns", NULL, 0) == SG_INVALID_ARGUMENT);
  CHECK_ERROR(client, sg_import_cgns(client, NULL, "c-cgns", NULL, 0), SG_INVALID_ARGUMENT,
              "path: NULL");
  CHECK_ERROR(client, sg_import_cgns(client, "/nonexistent/grid.cgns", "c-cgns", NULL, 0),
              SG_NOT_FOUND, "/nonexistent/grid.cgns");
  CHECK_ERROR(client, sg_import_cgns(client, plot3d_file, "c-cgns", NULL, 0), SG_INVALID_ARGUMENT,
              "cgns");
  char id[64];
  CHECK_OK(client, sg_import_cgns(client, cgns_file, "c-cgns", id, sizeof id));
  CHECK(strcmp(id, "c-cgns") == 0);
  sg_fit_result fit;
  CHECK_OK(client, sg_fit(client, "c-cgns", 1e-3, &fit));
  CHECK(fit.revision == 1);
  CHECK_OK(client, sg_delete(client, "c-cgns"));
}

int main(int argc, char** argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: capi_test HOST:PORT CLOSED_HOST:PORT GRID_FILE CGNS_FILE\n");
    return 2;
  }
  CHECK(strcmp(sg_version(), SPLINEGRID_EXPECTED_VERSION) == 0);
  CHECK(strcmp(sg_status_name(SG_NOT_FOUND), "NOT_FOUND") == 0);
  CHECK(strcmp(sg_status_name(99), "UNKNOWN_CODE") == 0);
  NullClient();
  Connections(argv[2]);

  sg_client* client = NULL;
  CHECK_OK(client, sg_connect(argv[1], "", "", 60.0, &client));
  if (failures == 0) {
    Points(client);
    Airfoil(client, argv[3]);
    Cgns(client, argv[4], argv[3]);

    /* A truncated copy of a message still reports the full length. */
    CHECK(sg_fit(client, "nothing", 1e-3, NULL) == SG_NOT_FOUND);
    char small[8];
    const size_t length = sg_last_error_copy(client, small, sizeof small);
    CHECK(length == strlen(sg_last_error(client)) && length > 7);
    CHECK(strlen(small) == 7 && strncmp(small, sg_last_error(client), 7) == 0);

    struct ThreadArgs a = {client, "grids/thread-a", 0}, b = {client, "grids/thread-b", 0};
    pthread_t ta, tb;
    pthread_create(&ta, NULL, FailRepeatedly, &a);
    pthread_create(&tb, NULL, FailRepeatedly, &b);
    pthread_join(ta, NULL);
    pthread_join(tb, NULL);
    CHECK(a.mismatches == 0 && b.mismatches == 0);
  }
  sg_close(client);
  printf("capi_test: %d checks, %d failed\n", checks, failures);
  return failures == 0 ? 0 : 1;
}
