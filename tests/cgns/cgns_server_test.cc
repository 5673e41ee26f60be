// CGNS through the real `splinegrid` binary: `fit FILE.cgns` (the server decodes the upload in
// its splinegrid-cgns-decode child), the boundary conditions as default face kinds, `eval
// --level L -o FILE.cgns` and its re-import, and damaged files or a crashing decoder, after
// which the server keeps serving.
#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <memory>

#include "absl/strings/str_cat.h"
#include "client/client.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "io/cgns/cgns_io.h"
#include "tests/cgns/cgns_test_util.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid {
namespace {

using ::splinegrid::testing::ChildProcess;
using ::splinegrid::testing::TempDir;
using ::testing::HasSubstr;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";

// A server on a free port with `extra` flags, and a client of it.
class Server {
 public:
  Server(const TempDir& dir, std::vector<std::string> extra = {}) : port_(testing::FreePort()) {
    std::vector<std::string> argv = {kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port_),
                                     "--drain_notice=0s", "--threads=2"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    process_ = std::make_unique<ChildProcess>(argv, dir.File("server.log"));
    ready_ = testing::WaitForPort(port_, absl::Seconds(20));
    client::ClientOptions options;
    options.timeout = absl::Seconds(120);
    client_ = client::Client::Connect(absl::StrCat("127.0.0.1:", port_), options);
  }

  bool ready() const { return ready_; }
  client::Client& client() { return *client_; }
  std::string log() const { return process_->ReadLog(); }

  // Runs the CLI against this server; its exit code, output in `*out`.
  int Cli(const std::string& args, std::string* out) const {
    return testing::RunShell(absl::StrCat(kBinary, " ", args, " --server=127.0.0.1:", port_), out);
  }

 private:
  int port_;
  bool ready_ = false;
  std::unique_ptr<ChildProcess> process_;
  std::unique_ptr<client::Client> client_;
};

// The points of `name` (its revision `revision`, 0: the latest) at refinement level `level`.
MultiBlockGrid Evaluate(client::Client& client, const std::string& name, int level,
                        int64_t revision = 0) {
  v1::EvaluateGridRequest request;
  request.set_name(name);
  request.set_revision(revision);
  request.set_refinement_level(level);
  absl::StatusOr<client::EvaluatedGrid> result = client.Evaluate(request);
  EXPECT_TRUE(result.ok()) << result.status();
  MultiBlockGrid grid;
  if (result.ok()) {
    for (const client::EvaluatedBlock& block : result->blocks) grid.blocks.push_back(block.points);
  }
  return grid;
}

// Writes `grid` with `conditions` (and its found connectivity) as CGNS.
void WriteWithConditions(const std::string& path, const MultiBlockGrid& grid,
                         const std::vector<SourceBoundary>& conditions) {
  CgnsWriteOptions options;
  for (const StructuredBlock& b : grid.blocks) options.source_extents.push_back(b.extents());
  options.conditions = conditions;
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(grid);
  ASSERT_TRUE(connectivity.ok());
  options.matches = connectivity->matches;
  ASSERT_TRUE(WriteCgnsFile(path, grid, options, nullptr).ok());
}

TEST(CgnsServerTest, Plot3dToCgnsFileFitsToTheSamePointsAsThePlot3dFile) {
  TempDir dir("cgns-server");
  Server server(dir);
  ASSERT_TRUE(server.ready()) << server.log();
  const std::string plot3d = SharedDataPath("surfaces/m6_small.fmt");
  testing::Plot3dToCgns(plot3d, dir.File("m6.cgns"), "-d");
  std::string out;
  ASSERT_EQ(server.Cli(absl::StrCat("fit ", dir.File("m6.cgns"), " --name m6c --ctl 12,12"), &out),
            0)
      << out;
  ASSERT_EQ(server.Cli(absl::StrCat("fit ", plot3d, " --name m6p --ctl 12,12"), &out), 0) << out;
  absl::StatusOr<v1::Grid> grid = server.client().Get("grids/m6c");
  ASSERT_TRUE(grid.ok()) << grid.status();
  EXPECT_THAT(grid->source().format(), HasSubstr("cgns hdf5, 3d, 9 zones, double"));
  EXPECT_EQ(grid->source().blocks_size(), 9);
  const MultiBlockGrid from_cgns = Evaluate(server.client(), "grids/m6c", 1);
  const MultiBlockGrid from_plot3d = Evaluate(server.client(), "grids/m6p", 1);
  ASSERT_EQ(from_cgns.blocks.size(), 9u);
  EXPECT_EQ(testing::MaxDifference(from_cgns, from_plot3d), 0.0);  // same data, same fit
}

TEST(CgnsServerTest, CGridConditionsAreDefaultKindsAndRoundTripThroughEvalAtALevel) {
  TempDir dir("cgns-server");
  Server server(dir);
  ASSERT_TRUE(server.ready()) << server.log();
  absl::StatusOr<MultiBlockGrid> naca = ReadPlot3dFile(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  ASSERT_TRUE(naca.ok());
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(*naca);
  ASSERT_TRUE(connectivity.ok());
  const std::vector<SourceBoundary> conditions = testing::CGridConditions(*naca, *connectivity);
  WriteWithConditions(dir.File("naca.cgns"), *naca, conditions);

  std::string out;
  ASSERT_EQ(server.Cli(absl::StrCat("fit ", dir.File("naca.cgns"), " --name naca --kinds"), &out),
            0)
      << out;
  v1::GetGridRequest get;
  get.set_name("grids/naca");
  get.set_view(v1::GRID_VIEW_FULL);
  absl::StatusOr<v1::Grid> grid = server.client().Get(get);
  ASSERT_TRUE(grid.ok()) << grid.status();
  const v1::SourceBoundaries& stored = grid->source().boundaries();
  ASSERT_EQ(stored.conditions_size(), 4);
  EXPECT_EQ(stored.conditions(0).family(), "airfoil");
  EXPECT_EQ(stored.conditions(0).kind(), v1::BOUNDARY_KIND_WALL);
  EXPECT_EQ(stored.face_kinds_size(), 4);
  // The fit took the file's kinds: its spec lists them (no --face kinds were given).
  EXPECT_EQ(grid->revision().fit_spec().face_kinds_size(), 4);
  // A kind given in the FitSpec wins for its face; the file's kinds fill in the others.
  v1::FitSpec spec;
  spec.mutable_control_counts()->set_i(60);
  spec.mutable_control_counts()->set_j(20);
  spec.set_allow_folds(true);
  v1::FaceKind* given = spec.add_face_kinds();
  given->set_face(v1::BLOCK_FACE_J_MIN);
  given->set_kind(v1::BOUNDARY_KIND_OUTER);
  absl::StatusOr<v1::FitGridResponse> refit = server.client().Fit("grids/naca", spec);
  ASSERT_TRUE(refit.ok()) << refit.status();
  absl::StatusOr<v1::Grid> second = server.client().Get("grids/naca", refit->revision());
  ASSERT_TRUE(second.ok()) << second.status();
  const auto& kinds = second->revision().fit_spec().face_kinds();
  ASSERT_EQ(kinds.size(), 4);
  EXPECT_EQ(kinds[0].face(), v1::BLOCK_FACE_J_MIN);
  EXPECT_EQ(kinds[0].kind(), v1::BOUNDARY_KIND_OUTER);
  for (const v1::FaceKind& k : kinds) {
    if (k.face() == v1::BLOCK_FACE_J_MIN) {
      EXPECT_EQ(k.kind(), v1::BOUNDARY_KIND_OUTER);
    }
  }

  // eval --level 1 -o: the same conditions and the wake cut at twice the indices.
  ASSERT_EQ(
      server.Cli(absl::StrCat("eval naca --revision 1 --level 1 -o ", dir.File("l1.cgns")), &out),
      0)
      << out;
  absl::StatusOr<ImportedGrid> l1 = ReadCgnsFile(dir.File("l1.cgns"));
  ASSERT_TRUE(l1.ok()) << l1.status();
  EXPECT_EQ(testing::MaxDifference(l1->grid, Evaluate(server.client(), "grids/naca", 1, 1)), 0.0);
  EXPECT_EQ(l1->grid.blocks[0].extents(), (Extents{225, 65, 1}));
  ASSERT_EQ(l1->boundaries.conditions.size(), conditions.size());
  for (size_t q = 0; q < conditions.size(); ++q) {
    EXPECT_EQ(l1->boundaries.conditions[q].name, conditions[q].name);
    EXPECT_EQ(l1->boundaries.conditions[q].bc_type, conditions[q].bc_type);
    EXPECT_EQ(l1->boundaries.conditions[q].family, conditions[q].family);
    for (int d = 0; d < 3; ++d) {
      EXPECT_EQ(l1->boundaries.conditions[q].range.begin[d], 2 * conditions[q].range.begin[d]);
      EXPECT_EQ(l1->boundaries.conditions[q].range.end[d], 2 * conditions[q].range.end[d]);
    }
  }
  ASSERT_EQ(l1->connections.size(), 2u);
  absl::StatusOr<Connectivity> l1_found = FindConnectivity(l1->grid);
  ASSERT_TRUE(l1_found.ok());
  EXPECT_TRUE(CompareConnections(l1->connections, *l1_found, {}).empty());

  // ... and the file splinegrid wrote imports again with the same conditions and connectivity
  // (import only: refitting a fitted grid is not the point here).
  absl::StatusOr<v1::Grid> back =
      server.client().ImportCgns(*ReadFileToString(dir.File("l1.cgns")), "back", "l1.cgns");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->source().num_points(), 225 * 65);
  EXPECT_THAT(back->source().format(), HasSubstr("cgns hdf5, 2d, 1 zone, double"));
  EXPECT_EQ(back->source().num_matches(), 1);
  ASSERT_EQ(back->source().boundaries().conditions_size(), 4);
  EXPECT_EQ(back->source().boundaries().conditions(0).range().end().i(),
            2 * conditions[0].range.end[0]);
  EXPECT_TRUE(back->source().boundaries().notes().empty());
}

TEST(CgnsServerTest, VolumeRoundTripKeepsConditionsAndTheTransformAtLevelOne) {
  TempDir dir("cgns-server");
  Server server(dir);
  ASSERT_TRUE(server.ready()) << server.log();
  const MultiBlockGrid boxes = testing::TwoBoxes();
  const std::vector<SourceBoundary> conditions = {
      {FaceRange{Face{0, 0, false}, {0, 0, 0}, {0, 6, 4}}, BoundaryKind::kWall, "wall", "BCWall",
       ""},
      {FaceRange{Face{1, 0, true}, {8, 0, 0}, {8, 4, 6}}, BoundaryKind::kOuter, "out", "BCOutflow",
       ""},
      {FaceRange{Face{0, 2, false}, {0, 0, 0}, {8, 6, 0}}, BoundaryKind::kInterface, "sym",
       "BCSymmetryPlane", "mirror"}};
  WriteWithConditions(dir.File("boxes.cgns"), boxes, conditions);
  std::string out;
  ASSERT_EQ(
      server.Cli(absl::StrCat("fit ", dir.File("boxes.cgns"), " --name boxes --ctl 5,5,4"), &out),
      0)
      << out;
  EXPECT_THAT(out, HasSubstr("note: BC 'sym' of zone 'block_0' is BCSymmetryPlane"));
  ASSERT_EQ(server.Cli(absl::StrCat("eval boxes --level 1 -o ", dir.File("b1.cgns")), &out), 0)
      << out;
  absl::StatusOr<ImportedGrid> b1 = ReadCgnsFile(dir.File("b1.cgns"));
  ASSERT_TRUE(b1.ok()) << b1.status();
  EXPECT_EQ(b1->grid.blocks[0].extents(), (Extents{17, 13, 9}));
  EXPECT_EQ(b1->grid.blocks[1].extents(), (Extents{17, 9, 13}));
  ASSERT_EQ(b1->boundaries.conditions.size(), 3u);  // zone by zone: wall, sym, out
  EXPECT_EQ(b1->boundaries.conditions[1].family, "mirror");
  EXPECT_EQ(b1->boundaries.conditions[1].range.end, (Extents{16, 12, 0}));
  EXPECT_EQ(b1->boundaries.conditions[2].range.end, (Extents{16, 8, 12}));
  ASSERT_EQ(b1->connections.size(), 2u);
  EXPECT_EQ(b1->connections[0].transform, (std::array<int, 3>{1, 3, 2}));
  // INVALID_ARGUMENT: exit status 2.
  EXPECT_EQ(server.Cli(absl::StrCat("eval boxes --level 1 --derivs -o ", dir.File("d.cgns")), &out),
            2);
  EXPECT_THAT(out, HasSubstr("--derivs"));
  EXPECT_EQ(server.Cli(absl::StrCat("eval boxes --res 4,4,4 -o ", dir.File("r.cgns")), &out), 2);
  EXPECT_THAT(out, HasSubstr("use --level"));
}

// The boundary conditions live in the stored grid's header (ArchiveHeader.source_boundaries):
// a server started afresh on the same dir: or Redis store has them and fits with them.
void ExpectStoreKeepsConditions(const TempDir& dir, const std::string& store) {
  absl::StatusOr<MultiBlockGrid> naca = ReadPlot3dFile(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  ASSERT_TRUE(naca.ok());
  absl::StatusOr<Connectivity> connectivity = FindConnectivity(*naca);
  ASSERT_TRUE(connectivity.ok());
  WriteWithConditions(dir.File("naca.cgns"), *naca, testing::CGridConditions(*naca, *connectivity));
  {
    Server first(dir, {store});
    ASSERT_TRUE(first.ready()) << first.log();
    absl::StatusOr<v1::Grid> imported =
        first.client().ImportCgns(*ReadFileToString(dir.File("naca.cgns")), "kept", "naca.cgns");
    ASSERT_TRUE(imported.ok()) << imported.status();
  }  // SIGKILL: acknowledged data must survive a crash
  Server second(dir, {store});
  ASSERT_TRUE(second.ready()) << second.log();
  absl::StatusOr<v1::Grid> grid = second.client().Get("grids/kept");
  ASSERT_TRUE(grid.ok()) << grid.status();
  const v1::SourceBoundaries& kept = grid->source().boundaries();
  ASSERT_EQ(kept.conditions_size(), 4) << store;
  EXPECT_EQ(kept.conditions(0).name(), "wall");
  EXPECT_EQ(kept.conditions(0).family(), "airfoil");
  EXPECT_EQ(kept.conditions(3).bc_type(), "BCOutflow");
  EXPECT_EQ(kept.face_kinds_size(), 4);
  EXPECT_EQ(kept.block_names_size(), 1);
  v1::FitSpec spec;
  spec.mutable_control_counts()->set_i(60);
  spec.mutable_control_counts()->set_j(20);
  spec.set_allow_folds(true);
  absl::StatusOr<v1::FitGridResponse> fit = second.client().Fit("grids/kept", spec);
  ASSERT_TRUE(fit.ok()) << fit.status();
  absl::StatusOr<v1::Grid> fitted = second.client().Get("grids/kept");
  ASSERT_TRUE(fitted.ok());
  EXPECT_EQ(fitted->revision().fit_spec().face_kinds_size(), 4);
}

TEST(CgnsServerTest, DirStoreKeepsTheConditionsAcrossARestart) {
  TempDir dir("cgns-server");
  ExpectStoreKeepsConditions(dir, absl::StrCat("--store=dir:", dir.File("store")));
}

TEST(CgnsServerTest, RedisStoreKeepsTheConditionsForAFreshServer) {
  const std::string redis_server = testing::FindProgram("redis-server");
  if (redis_server.empty()) GTEST_SKIP() << "redis-server is not installed (.ci/setup installs it)";
  TempDir dir("cgns-server");
  const int port = testing::FreePort();
  std::filesystem::create_directories(dir.File("redis"));
  std::ofstream(dir.File("redis.conf"))
      << "bind 127.0.0.1\nport " << port << "\nprotected-mode yes\ndaemonize no\ndir "
      << dir.File("redis") << "\nsave \"\"\n";
  ChildProcess redis({redis_server, dir.File("redis.conf")}, dir.File("redis.log"));
  ASSERT_TRUE(testing::WaitForPort(port, absl::Seconds(10))) << redis.ReadLog();
  ExpectStoreKeepsConditions(dir, absl::StrCat("--store=redis://127.0.0.1:", port));
}

TEST(CgnsServerTest, DamagedFilesAreInvalidArgumentAndTheServerKeepsServing) {
  TempDir dir("cgns-server");
  Server server(dir);
  ASSERT_TRUE(server.ready()) << server.log();
  testing::Plot3dToCgns(SharedDataPath("surfaces/m6_small.fmt"), dir.File("m6.cgns"), "-d");
  absl::StatusOr<std::string> bytes = ReadFileToString(dir.File("m6.cgns"));
  ASSERT_TRUE(bytes.ok());
  // Truncated at half, and the HDF5 signature followed by noise.
  std::ofstream(dir.File("half.cgns"), std::ios::binary) << bytes->substr(0, bytes->size() / 2);
  std::string noise = bytes->substr(0, 8);
  for (int q = 0; q < 100000; ++q) noise.push_back(static_cast<char>((q * 7919) % 251));
  std::ofstream(dir.File("noise.cgns"), std::ios::binary) << noise;
  for (const char* name : {"half.cgns", "noise.cgns"}) {
    absl::StatusOr<v1::Grid> imported =
        server.client().ImportCgns(*ReadFileToString(dir.File(name)), "", name);
    EXPECT_EQ(imported.status().code(), absl::StatusCode::kInvalidArgument) << name;
    EXPECT_THAT(imported.status().message(), HasSubstr("cgns: ")) << name;
    std::string out;
    EXPECT_EQ(server.Cli(absl::StrCat("fit ", dir.File(name)), &out), 2) << out;
    EXPECT_THAT(out, HasSubstr("INVALID_ARGUMENT: cgns: ")) << out;
  }
  // A file that is no CGNS at all is named so (libcgns spoke of ADF internals): by the server
  // for an upload, by the CLI for a file named .cgns, before any upload.
  const std::string plot3d = *ReadFileToString(SharedDataPath("grids/n0012_113-33.p2dfmt"));
  const absl::Status not_cgns = server.client().ImportCgns(plot3d, "", "n0012.cgns").status();
  EXPECT_EQ(not_cgns.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(not_cgns.message(),
              HasSubstr("not a CGNS file: it starts with neither the HDF5 signature nor an ADF "
                        "header"));
  std::ofstream(dir.File("plot3d.cgns"), std::ios::binary) << plot3d;
  std::string misnamed;
  EXPECT_EQ(server.Cli(absl::StrCat("fit ", dir.File("plot3d.cgns")), &misnamed), 2) << misnamed;
  EXPECT_THAT(misnamed, HasSubstr("plot3d.cgns is named .cgns but is not a CGNS file"));
  // A zone whose coordinates are not finite: the decoder names the zone in quotes, and the
  // server passes that on once (a trial saw zone \'blk\' when it was quoted again).
  MultiBlockGrid nan_grid;
  nan_grid.blocks.emplace_back(Extents{3, 3, 1}, 2);
  for (int p = 0; p < 9; ++p) {
    nan_grid.blocks[0].coords()[2 * p] = p % 3;
    nan_grid.blocks[0].coords()[2 * p + 1] = p / 3;
  }
  nan_grid.blocks[0].coords()[2 * 4 + 1] = std::nan("");
  CgnsWriteOptions named;
  named.block_names = {"blk"};
  ASSERT_TRUE(WriteCgnsFile(dir.File("nan.cgns"), nan_grid, named, nullptr).ok());
  const absl::Status nan_status =
      server.client().ImportCgns(*ReadFileToString(dir.File("nan.cgns")), "", "nan").status();
  EXPECT_EQ(nan_status.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_THAT(nan_status.message(), HasSubstr("cgns: zone 'blk': point (1, 1, 0)"));
  EXPECT_THAT(nan_status.message(), ::testing::Not(HasSubstr("\\'")));
  EXPECT_TRUE(server.client().List().ok());
  std::string out;
  EXPECT_EQ(server.Cli(absl::StrCat("fit ", dir.File("m6.cgns"), " --name ok --ctl 8,8"), &out), 0)
      << out;
}

TEST(CgnsServerTest, ACrashingDecoderIsInvalidArgumentAndAMissingOneFailedPrecondition) {
  TempDir dir("cgns-server");
  // A decoder that dies of SIGSEGV, as libcgns may on a hostile file.
  const std::string crasher = dir.File("crash-decode");
  std::ofstream(crasher) << "#!/bin/sh\nkill -SEGV $$\n";
  ASSERT_EQ(chmod(crasher.c_str(), 0755), 0);
  testing::Plot3dToCgns(SharedDataPath("surfaces/even_sphere.fmt"), dir.File("s.cgns"), "-d");
  const std::string bytes = *ReadFileToString(dir.File("s.cgns"));
  {
    Server server(dir, {absl::StrCat("--cgns_decoder=", crasher)});
    ASSERT_TRUE(server.ready()) << server.log();
    absl::StatusOr<v1::Grid> imported = server.client().ImportCgns(bytes, "s", "s.cgns");
    EXPECT_EQ(imported.status().code(), absl::StatusCode::kInvalidArgument);
    EXPECT_THAT(imported.status().message(), HasSubstr("crashed (signal 11"));
    EXPECT_TRUE(server.client().List().ok());
  }
  {
    Server server(dir, {absl::StrCat("--cgns_decoder=", dir.File("missing"))});
    ASSERT_TRUE(server.ready()) << server.log();
    absl::StatusOr<v1::Grid> imported = server.client().ImportCgns(bytes, "s", "s.cgns");
    EXPECT_EQ(imported.status().code(), absl::StatusCode::kFailedPrecondition);
    EXPECT_THAT(imported.status().message(), HasSubstr("--cgns_decoder"));
  }
}

}  // namespace
}  // namespace splinegrid
