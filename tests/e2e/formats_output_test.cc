// Plot3D flavours and ParaView output through the real server and CLI: C-stream files written
// by Debian's cgns_to_plot3d, the planes layout, two-plane grids written back in their 3D
// form, derivatives in a Plot3D function file, VTK fields, original block numbers, zlib
// compression and .pvd time series, the VTK files read back by VTK 9 (vtk_read_check.py).
#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_split.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/test_data.h"
#include "tests/store/server_process.h"

namespace splinegrid::testing {
namespace {

using ::testing::HasSubstr;

const std::string kBinary = SPLINEGRID_BINARY_DIR "/splinegrid";
const std::string kVtkCheck = SPLINEGRID_SOURCE_DIR "/tests/e2e/vtk_read_check.py";

struct Result {
  int exit_code;
  std::string out;  // stdout and stderr
};

class FormatsOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    port_ = FreePort();
    dir_ = std::filesystem::temp_directory_path() /
           absl::StrCat("splinegrid-formats-", getpid(), "-",
                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    server_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kBinary, "serve", absl::StrCat("--address=127.0.0.1:", port_),
                                 "--threads=2", "--drain_notice=0s"},
        (dir_ / "server.log").string());
    ASSERT_TRUE(WaitForPort(port_, absl::Seconds(20))) << server_->ReadLog();
  }

  void TearDown() override {
    EXPECT_EQ(server_->Stop(SIGTERM), 0) << server_->ReadLog();
    std::filesystem::remove_all(dir_);
  }

  Result Shell(const std::string& command) {
    Result result;
    result.exit_code =
        RunShell(absl::StrCat("cd '", dir_.string(), "' && ", command, " 2>&1"), &result.out);
    return result;
  }

  Result Cli(const std::string& args) {
    return Shell(absl::StrCat("timeout 120 ", kBinary, " ", args, " --server=127.0.0.1:", port_));
  }

  // Fits `file` as `name` (extra fit flags in `flags`), expecting success.
  void Fit(const std::string& file, const std::string& name, const std::string& flags) {
    const Result fit = Cli(absl::StrCat("fit ", file, " --name=", name, " ", flags));
    ASSERT_EQ(fit.exit_code, 0) << fit.out;
  }

  // VTK 9's view of `files` (vtk_read_check.py), failing the test when it cannot read them.
  std::string VtkRead(const std::string& files) {
    const Result read = Shell(absl::StrCat("/usr/bin/python3 ", kVtkCheck, " ", files));
    EXPECT_EQ(read.exit_code, 0) << read.out
                                 << "\n(VTK 9 for Python: apt-get install python3-vtk9, in "
                                    ".ci/setup)";
    return read.out;
  }

  std::string Path(const std::string& name) const { return (dir_ / name).string(); }

  // The shared ffd box (6 x 2 x 6) as CGNS, then through cgns_to_plot3d `options` to `name`.
  void MakeCStreamFile(const std::string& options, const std::string& name) {
    if (!std::filesystem::exists(Path("ffd.cgns"))) {
      const Result cgns = Shell(absl::StrCat(
          "plot3d_to_cgns -f -d ", SharedDataPath("surfaces/ffd_box_6x2x6.fmt"), " ffd.cgns"));
      ASSERT_EQ(cgns.exit_code, 0) << cgns.out << "\n(install cgns-convert: .ci/setup)";
    }
    const Result convert = Shell(absl::StrCat("cgns_to_plot3d ", options, " ffd.cgns ", name));
    ASSERT_EQ(convert.exit_code, 0) << convert.out;
  }

  // Reads `path` and `expected_path` and expects the same detected format (and size, binary)
  // and points within `tol`.
  void ExpectSameFile(const std::string& path, const std::string& expected_path,
                      const Plot3dReadOptions& options, double tol) {
    Plot3dFormat format, expected_format;
    absl::StatusOr<MultiBlockGrid> written = ReadPlot3dFile(path, options, &format);
    absl::StatusOr<MultiBlockGrid> expected =
        ReadPlot3dFile(expected_path, options, &expected_format);
    ASSERT_TRUE(written.ok()) << written.status();
    ASSERT_TRUE(expected.ok()) << expected.status();
    EXPECT_EQ(DescribePlot3dFormat(format), DescribePlot3dFormat(expected_format));
    if (format.encoding != Plot3dEncoding::kAscii) {  // binary: the same layout, the same size
      EXPECT_EQ(std::filesystem::file_size(path), std::filesystem::file_size(expected_path));
    }
    ASSERT_EQ(written->blocks.size(), expected->blocks.size());
    for (size_t b = 0; b < written->blocks.size(); ++b) {
      ASSERT_EQ(written->blocks[b].extents(), expected->blocks[b].extents());
      for (size_t c = 0; c < written->blocks[b].coords().size(); ++c) {
        ASSERT_NEAR(written->blocks[b].coords()[c], expected->blocks[b].coords()[c], tol);
      }
    }
  }

  int port_ = 0;
  std::filesystem::path dir_;
  std::unique_ptr<ChildProcess> server_;
};

TEST_F(FormatsOutputTest, CStreamFilesOfCgnsToPlot3dComeBackInTheirLayout) {
  // Default (C stream, single precision, block count) and double precision.
  for (const std::string options : {"", "-d", "-s"}) {
    SCOPED_TRACE(options);
    ASSERT_NO_FATAL_FAILURE(MakeCStreamFile(options, "ffd.x"));
    ASSERT_NO_FATAL_FAILURE(Fit("ffd.x", "ffd", "--tol=1e-6"));
    const Result get = Cli("get ffd");
    EXPECT_THAT(get.out, HasSubstr(absl::StrCat(
                             "plot3d binary little-endian C-stream ",
                             options == "-d" ? "double" : "single", " precision 3D, ",
                             options == "-s" ? "no block-count line" : "block-count line")));
    const Result eval = Cli("eval ffd --level=0 -o back.x");
    ASSERT_EQ(eval.exit_code, 0) << eval.out;
    ExpectSameFile(Path("back.x"), Path("ffd.x"), {}, 1e-5);
    ASSERT_EQ(Cli("rm ffd").exit_code, 0);
  }
}

TEST_F(FormatsOutputTest, PlanesLayoutIsDetectedInRecordsAndSelectedInStreams) {
  Plot3dReadOptions planes;
  planes.layout = Plot3dLayout::kPlanes;
  // Fortran records: detected.
  ASSERT_NO_FATAL_FAILURE(MakeCStreamFile("-u -p -d", "up.x"));
  ASSERT_NO_FATAL_FAILURE(Fit("up.x", "up", "--tol=1e-6"));
  EXPECT_THAT(Cli("get up").out, HasSubstr("double precision 3D, block-count line, no iblank, "
                                           "planes layout"));
  ASSERT_EQ(Cli("eval up --level=0 -o up_back.x").exit_code, 0);
  ExpectSameFile(Path("up_back.x"), Path("up.x"), {}, 1e-5);
  // C stream: --plot3d_layout planes.
  ASSERT_NO_FATAL_FAILURE(MakeCStreamFile("-p -d", "p.x"));
  ASSERT_NO_FATAL_FAILURE(Fit("p.x", "p", "--tol=1e-6 --plot3d_layout=planes"));
  EXPECT_THAT(Cli("get p").out, HasSubstr("C-stream double precision 3D, block-count line, no "
                                          "iblank, planes layout"));
  ASSERT_EQ(Cli("eval p --level=0 -o p_back.x").exit_code, 0);
  ExpectSameFile(Path("p_back.x"), Path("p.x"), planes, 1e-5);
  EXPECT_EQ(Cli("fit p.x --name=bad --plot3d_layout=rows").exit_code, 2);
}

// rae2822_257x97.fmt is 2 x 257 x 97 with y = 0 and y = -1 on its planes; stored as its 2D view
// it is written back as such a 3D file (not a 2D 257 x 97 one), at any level.
TEST_F(FormatsOutputTest, TwoPlaneGridIsWrittenBackAsTwoPlanes) {
  const std::string source = SharedDataPath("grids/rae2822_257x97.fmt");
  ASSERT_NO_FATAL_FAILURE(Fit(source, "rae", "--kinds"));
  ASSERT_EQ(Cli("eval rae --level=0 -o rae.xyz").exit_code, 0);
  // Within the fit's largest deviation (0.0279 inside the field, --kinds).
  ExpectSameFile(Path("rae.xyz"), source, {}, 0.03);
  ASSERT_EQ(Cli("eval rae --level=1 --derivs -o rae1.x").exit_code, 0);
  Plot3dFormat format;
  absl::StatusOr<MultiBlockGrid> level1 = ReadPlot3dFile(Path("rae1.x"), &format);
  ASSERT_TRUE(level1.ok()) << level1.status();
  EXPECT_EQ(format.spatial_dim, 3);
  const StructuredBlock& block = level1->blocks[0];
  ASSERT_EQ(block.extents(), (Extents{2, 513, 193}));
  for (int k = 0; k < 193; k += 16) {
    for (int j = 0; j < 513; j += 16) {
      EXPECT_EQ(block.Point(0, j, k)[1], 0.0);
      EXPECT_EQ(block.Point(1, j, k)[1], -1.0);
      EXPECT_EQ(block.Point(0, j, k)[0], block.Point(1, j, k)[0]);
      EXPECT_EQ(block.Point(0, j, k)[2], block.Point(1, j, k)[2]);
    }
  }
  // The derivatives beside it: rae1.f, Fortran records like rae1.x (the source was text), one
  // block of 2 x 513 x 193 points and 6 functions: dX_du and dX_dv in x, y, z (y = 0).
  absl::StatusOr<std::string> f = ReadFileToString(Path("rae1.f"));
  ASSERT_TRUE(f.ok()) << f.status();
  const int64_t points = 2 * 513 * 193;
  ASSERT_EQ(f->size(), static_cast<size_t>(12 + 24 + 8 + points * 6 * 8));
  int32_t header[9];
  std::memcpy(header, f->data(), sizeof(header));
  EXPECT_EQ(std::vector<int32_t>(header, header + 9),
            (std::vector<int32_t>{4, 1, 4, 16, 2, 513, 193, 6, 16}));
  std::vector<double> values(static_cast<size_t>(points * 6));
  std::memcpy(values.data(), f->data() + 12 + 24 + 4, values.size() * 8);
  double largest_du_x = 0.0;
  for (int64_t p = 0; p < points; ++p) {
    EXPECT_EQ(values[1 * points + p], 0.0);  // dX_du, y
    EXPECT_EQ(values[4 * points + p], 0.0);  // dX_dv, y
    largest_du_x = std::max(largest_du_x, std::abs(values[p]));
  }
  EXPECT_GT(largest_du_x, 1.0);
}

TEST_F(FormatsOutputTest, VtkFieldsBlockNumbersAndCompressionReadInVtk9) {
  ASSERT_NO_FATAL_FAILURE(Fit(SharedDataPath("surfaces/even_sphere.fmt"), "sphere", "--tol=1e-3"));
  const Result eval =
      Cli("eval sphere --level=1 --block=0,3 --derivs --jacobian --quality -o sphere.vtm");
  ASSERT_EQ(eval.exit_code, 0) << eval.out;
  EXPECT_TRUE(std::filesystem::exists(Path("sphere/sphere_3.vts")));
  EXPECT_FALSE(std::filesystem::exists(Path("sphere/sphere_1.vts")));
  const std::string read = VtkRead("sphere.vtm");
  // Surfaces: dX_du and dX_dv only, a positive area element, quads of good quality.
  EXPECT_THAT(read, HasSubstr("sphere.vtm block_3 points=81 cells=64 point:dX_du/3/"));
  EXPECT_THAT(read, HasSubstr("point:dX_dv/3/"));
  EXPECT_THAT(read, ::testing::Not(HasSubstr("dX_dw")));
  for (const std::string& line : std::vector<std::string>(absl::StrSplit(read, '\n'))) {
    if (line.find("block_") == std::string::npos) continue;
    const size_t jacobian = line.find("point:jacobian/1/");
    ASSERT_NE(jacobian, std::string::npos) << line;
    EXPECT_GT(std::stod(line.substr(jacobian + 17)), 0.0) << line;
    const size_t quality = line.find("cell:scaled_jacobian/1/");
    ASSERT_NE(quality, std::string::npos) << line;
    EXPECT_GT(std::stod(line.substr(quality + 23)), 0.5) << line;
  }
  // zlib on by default, --nocompress for raw: the same points, compressed smaller.
  ASSERT_NO_FATAL_FAILURE(Fit(SharedDataPath("grids/n0012_225-65.p2dfmt"), "naca", "--kinds"));
  ASSERT_EQ(Cli("eval naca --level=2 -o z.vts").exit_code, 0);
  ASSERT_EQ(Cli("eval naca --level=2 --nocompress -o r.vts").exit_code, 0);
  const auto compressed = std::filesystem::file_size(Path("z.vts"));
  const auto raw = std::filesystem::file_size(Path("r.vts"));
  EXPECT_LT(compressed * 10, raw * 8) << compressed << " vs " << raw;
  std::cout << "naca level 2: " << raw << " bytes raw, " << compressed << " with zlib\n";
  const std::string both = VtkRead("z.vts r.vts");
  EXPECT_THAT(both, HasSubstr("z.vts - points=230529"));
  EXPECT_THAT(both, HasSubstr("r.vts - points=230529"));
  // At level 0 the deviation from the source points peaks at the fit's max deviation.
  ASSERT_EQ(Cli("eval naca --level=0 --deviation -o d.vts").exit_code, 0);
  EXPECT_THAT(VtkRead("d.vts"), HasSubstr("point:deviation/1/0/"));
  EXPECT_EQ(Cli("eval naca --level=1 --deviation -o d.vts").exit_code, 2);
  const Result plot3d = Cli("eval naca --level=1 --quality -o q.x");
  EXPECT_EQ(plot3d.exit_code, 2);
  EXPECT_THAT(plot3d.out, HasSubstr("are VTK fields"));
}

TEST_F(FormatsOutputTest, DeformStepsBecomeAParaViewTimeSeries) {
  ASSERT_NO_FATAL_FAILURE(Fit(SharedDataPath("grids/n0012_113-33.p2dfmt"), "pitch", "--kinds"));
  for (int step = 1; step <= 3; ++step) {
    const Result deform = Cli(absl::StrCat(
        "deform pitch --rotate=", step,
        " --about=0.25,0 --boundary=wall --reference=1 --time=", 0.5 * step, " --step=", step));
    ASSERT_EQ(deform.exit_code, 0) << deform.out;
  }
  const Result series = Cli("eval pitch --steps=1:4 --level=1 --quality -o run.pvd");
  ASSERT_EQ(series.exit_code, 0) << series.out;
  EXPECT_THAT(series.out, HasSubstr("3 time step(s) (steps 1 to 3)"));
  EXPECT_THAT(series.out, HasSubstr("1 step(s) from 1 to 4 have no deformed revision"));
  const std::string read = VtkRead("run.pvd");
  EXPECT_THAT(read, HasSubstr("run.pvd timestep=0.5 file=run/run_1.vts"));
  EXPECT_THAT(read, HasSubstr("run.pvd timestep=1.5 file=run/run_3.vts"));
  EXPECT_THAT(read, HasSubstr("run/run_3.vts - points=14625 cells=14336 cell:scaled_jacobian"));
  EXPECT_EQ(Cli("eval pitch --steps=7:9 --level=1 -o none.pvd").exit_code, 1);
  EXPECT_EQ(Cli("eval pitch --steps=3:1 --level=1 -o bad.pvd").exit_code, 2);
  EXPECT_EQ(Cli("eval pitch --level=1 -o nosteps.pvd").exit_code, 2);
}

// A flag the output or the input would ignore is refused (exit 2, naming it), not dropped:
// zlib for a file that is not VTK, Plot3D read options for a CGNS file. Defaults never count.
TEST_F(FormatsOutputTest, FlagsTheOutputOrInputWouldIgnoreAreRefused) {
  ASSERT_NO_FATAL_FAILURE(Fit(SharedDataPath("grids/n0012_113-33.p2dfmt"), "naca", "--kinds"));
  for (const std::string line : {"--nocompress -o a.x", "--compress -o a.xyz",
                                 "--nocompress -o a.cgns", "--compress=false -o a.x"}) {
    const Result eval = Cli(absl::StrCat("eval naca --level=0 ", line));
    EXPECT_EQ(eval.exit_code, 2) << line << "\n" << eval.out;
    EXPECT_THAT(eval.out,
                HasSubstr(absl::StrContains(line, "no") || absl::StrContains(line, "false")
                              ? "--nocompress applies to VTK files (.vts, .vtm, .pvd)"
                              : "--compress applies to VTK files (.vts, .vtm, .pvd)"))
        << line;
    EXPECT_FALSE(std::filesystem::exists(Path(line.substr(line.find("-o ") + 3)))) << line;
  }
  // VTK takes it, and Plot3D without it is fine.
  EXPECT_EQ(Cli("eval naca --level=0 --nocompress -o a.vts").exit_code, 0);
  EXPECT_EQ(Cli("eval naca --level=0 --compress -o a.vtm").exit_code, 0);
  EXPECT_EQ(Cli("eval naca --level=0 -o a.x").exit_code, 0);

  // CGNS (Debian's plot3d_to_cgns): --planar (default true), --noplanar and --plot3d_layout
  // given are refused before any upload; the same fit without them stores the grid.
  ASSERT_NO_FATAL_FAILURE(MakeCStreamFile("-d", "ffd.x"));  // writes ffd.cgns first
  for (const std::string flag :
       {"--planar", "--noplanar", "--planar=true", "--plot3d_layout=planes"}) {
    const Result fit = Cli(absl::StrCat("fit ffd.cgns --name=ffd --tol=1e-6 ", flag));
    EXPECT_EQ(fit.exit_code, 2) << flag << "\n" << fit.out;
    EXPECT_THAT(fit.out, HasSubstr("is about Plot3D files; ffd.cgns is CGNS")) << flag;
  }
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("grids/ffd")));
  const Result cgns = Cli("fit ffd.cgns --name=ffd --tol=1e-6");
  EXPECT_EQ(cgns.exit_code, 0) << cgns.out;
  // A Plot3D file keeps its flags.
  EXPECT_EQ(Cli("fit ffd.x --name=ffd-p --tol=1e-6 --planar --plot3d_layout=whole").exit_code, 0);
}

// eval --deviation exports the source to a private mkdtemp directory under $TMPDIR and removes
// it: nothing is left there after the run, and a TMPDIR that is no directory is a clear error.
TEST_F(FormatsOutputTest, DeviationLeavesNoTemporaryFiles) {
  ASSERT_NO_FATAL_FAILURE(Fit(SharedDataPath("grids/n0012_113-33.p2dfmt"), "naca", "--kinds"));
  std::filesystem::create_directories(Path("tmp"));
  const std::string eval =
      absl::StrCat(kBinary, " eval naca --level=0 --deviation --server=127.0.0.1:", port_);
  const Result ok = Shell(absl::StrCat("TMPDIR=", Path("tmp"), " ", eval, " -o d.vts"));
  ASSERT_EQ(ok.exit_code, 0) << ok.out;
  EXPECT_THAT(VtkRead("d.vts"), HasSubstr("point:deviation/1/0/"));
  EXPECT_TRUE(std::filesystem::is_empty(Path("tmp")));
  // A failure after the export (the output directory does not exist): removed as well.
  const Result failed = Shell(absl::StrCat("TMPDIR=", Path("tmp"), " ", eval, " -o no/such/d.vts"));
  EXPECT_EQ(failed.exit_code, 1) << failed.out;
  EXPECT_TRUE(std::filesystem::is_empty(Path("tmp")));
  ASSERT_TRUE(WriteFileAtomically(Path("not-a-dir"), "x").ok());
  const Result bad = Shell(absl::StrCat("TMPDIR=", Path("not-a-dir"), " ", eval, " -o e.vts"));
  EXPECT_EQ(bad.exit_code, 1) << bad.out;
  EXPECT_THAT(bad.out, HasSubstr("--deviation: "));
  EXPECT_THAT(bad.out, HasSubstr("set TMPDIR"));
  EXPECT_FALSE(
      std::filesystem::exists(Path("e.vts")));  // Of a deformed revision the deviation is mostly
                                                // the deformation, and eval says so.
  ASSERT_EQ(Cli("deform naca --rotate 2 --about 0.25,0").exit_code, 0);
  const Result deformed = Shell(absl::StrCat("TMPDIR=", Path("tmp"), " ", eval,
                                             " --revision=2 "
                                             "-o dd.vts"));
  EXPECT_EQ(deformed.exit_code, 0) << deformed.out;
  EXPECT_THAT(deformed.out, HasSubstr("note: revision 2 is deformed: its deviation from the "
                                      "imported points is mostly the deformation"));
  // An extension eval does not write: the list names the series too.
  const Result txt = Cli("eval naca --level=0 -o out.txt");
  EXPECT_EQ(txt.exit_code, 2) << txt.out;
  EXPECT_THAT(txt.out, HasSubstr("-o out.txt: the extension must be .vts, .vtm, .x, .xyz or "
                                 ".cgns, or .pvd with --steps A:B"));
}

// offset -o goes through eval's writers: the same extensions (.vtm and .cgns too), checked
// before the grid is generated, and no derivative fields in a points-only file.
TEST_F(FormatsOutputTest, OffsetWritesThroughTheEvalWriters) {
  const std::string profile = SharedDataPath("airfoils/rae2822.dat");
  const std::string generate =
      absl::StrCat("offset ", profile, " --layers=8 --first=1e-3 --far=5 --points=65 ");
  const Result bad = Cli(absl::StrCat(generate, "--name=bad -o og.vtk"));
  EXPECT_EQ(bad.exit_code, 2) << bad.out;
  EXPECT_THAT(bad.out, HasSubstr("-o og.vtk: the extension must be .vts, .vtm, .x, .xyz or .cgns"));
  EXPECT_THAT(Cli("list").out, ::testing::Not(HasSubstr("grids/bad")));
  int n = 0;
  for (const std::string out : {"og.vts", "og.vtm", "og.xyz", "og.cgns"}) {
    const Result offset = Cli(absl::StrCat(generate, "--name=og", n++, " -o ", out));
    EXPECT_EQ(offset.exit_code, 0) << out << "\n" << offset.out;  // no folds, seam included
    EXPECT_THAT(offset.out, HasSubstr(absl::StrCat("wrote ", out, ": 585 points (revision 1)")))
        << out;
  }
  const std::string read = VtkRead("og.vts og.vtm");
  EXPECT_THAT(read, HasSubstr("og.vts - points=585 cells=512"));
  EXPECT_THAT(read, HasSubstr("og.vtm block_0 points=585"));
  EXPECT_THAT(read, ::testing::Not(HasSubstr("dX_")));
  absl::StatusOr<MultiBlockGrid> xyz = ReadPlot3dFile(Path("og.xyz"));
  ASSERT_TRUE(xyz.ok()) << xyz.status();
  EXPECT_EQ(xyz->blocks[0].extents(), (Extents{65, 9, 1}));
  // The .cgns carries the seam as eval writes it (offset wrote points only).
  const Result tree = Shell(absl::StrCat("cgnslist ", Path("og.cgns")));
  ASSERT_EQ(tree.exit_code, 0) << tree.out;
  EXPECT_THAT(tree.out, HasSubstr("ZoneGridConnectivity"));
  EXPECT_THAT(tree.out, HasSubstr("match0a"));
  EXPECT_THAT(tree.out, HasSubstr("match0b"));
}

}  // namespace
}  // namespace splinegrid::testing
