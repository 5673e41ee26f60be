// Writes the seed corpora of the fuzz targets into corpus/<target>/ (argument: the corpus
// directory, default tests/fuzz/corpus of the source tree): small valid inputs of every
// flavour each parser accepts, so the fuzzers start from the accepting paths. Re-run it after
// a format change; the files are committed (a few hundred KB in all).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/strings/str_cat.h"
#include "absl/time/time.h"
#include "core/deform/deformer.h"
#include "core/io/file_util.h"
#include "core/io/plot3d.h"
#include "core/io/record_file.h"
#include "proto/convert/convert.h"
#include "proto/convert/generate_convert.h"
#include "server/grid_store.h"
#include "server/store/grid_archive.h"
#include "splinegrid/v1/splinegrid_service.pb.h"
#include "tests/fuzz/fuzz_grids.h"
#include "tests/fuzz/fuzz_util.h"

namespace splinegrid::fuzz {
namespace {

namespace fs = std::filesystem;

fs::path g_root;

void Write(const std::string& target, const std::string& name, const std::string& bytes) {
  const fs::path dir = g_root / target;
  fs::create_directories(dir);
  std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  FUZZ_CHECK(out.good(), (dir / name).string());
}

void WriteMessage(const std::string& target, const std::string& name,
                  const google::protobuf::Message& message) {
  Write(target, name, message.SerializeAsString());
}

// A 3D block of `extents` with distinct coordinates, and iblank when asked.
StructuredBlock Box(const Extents& extents, int spatial_dim, bool iblank) {
  StructuredBlock block(extents, spatial_dim);
  for (int k = 0; k < extents[2]; ++k) {
    for (int j = 0; j < extents[1]; ++j) {
      for (int i = 0; i < extents[0]; ++i) {
        double* p = block.Point(i, j, k);
        p[0] = 0.5 * i + 0.01 * j;
        p[1] = 0.25 * j - 0.125;
        if (spatial_dim == 3) p[2] = 1.0 + k;
      }
    }
  }
  if (iblank) block.iblank().assign(block.num_points(), 1);
  return block;
}

// C streams (no record markers) of both byte orders and precisions, with and without block
// count and iblank, and Fortran records in the planes layout (a record per k-plane).
void Plot3dStreamAndPlanesSeeds() {
  for (bool iblank : {false, true}) {
    for (bool count : {false, true}) {
      MultiBlockGrid grid;
      grid.blocks.push_back(Box(Extents{3, 2, 2}, 3, iblank));
      if (count) grid.blocks.push_back(Box(Extents{2, 2, 3}, 3, iblank));
      for (Plot3dEncoding encoding :
           {Plot3dEncoding::kBinaryLittleEndian, Plot3dEncoding::kBinaryBigEndian}) {
        for (int bytes_per_real : {4, 8}) {
          Plot3dFormat format{.encoding = encoding,
                              .spatial_dim = 3,
                              .has_block_count = count,
                              .has_iblank = iblank,
                              .bytes_per_real = bytes_per_real};
          const std::string suffix =
              absl::StrCat(encoding == Plot3dEncoding::kBinaryBigEndian ? "be" : "le", "_r",
                           bytes_per_real, "_3d", count ? "_count" : "", iblank ? "_iblank" : "");
          format.framing = Plot3dFraming::kCStream;
          Write("plot3d_binary", "stream_" + suffix, EncodePlot3d(grid, format).value());
          format.framing = Plot3dFraming::kFortranRecords;
          format.layout = Plot3dLayout::kPlanes;
          Write("plot3d_binary", "planes_" + suffix, EncodePlot3d(grid, format).value());
        }
      }
    }
  }
}

// Every Plot3D flavour: text and binary (both byte orders, single and double), block count or
// not, 2D or 3D, iblank or not; one and two blocks; and the real 29 x 9 grid.
void Plot3dSeeds(const MultiBlockGrid& naca) {
  for (int dim : {2, 3}) {
    for (bool iblank : {false, true}) {
      for (bool count : {false, true}) {
        MultiBlockGrid grid;
        grid.blocks.push_back(Box(dim == 3 ? Extents{3, 2, 2} : Extents{4, 3, 1}, dim, iblank));
        if (count)
          grid.blocks.push_back(Box(dim == 3 ? Extents{2, 2, 2} : Extents{2, 3, 1}, dim, iblank));
        for (Plot3dEncoding encoding : {Plot3dEncoding::kAscii, Plot3dEncoding::kBinaryLittleEndian,
                                        Plot3dEncoding::kBinaryBigEndian}) {
          for (int bytes_per_real : {4, 8}) {
            if (encoding == Plot3dEncoding::kAscii && bytes_per_real == 4) continue;
            const Plot3dFormat format{.encoding = encoding,
                                      .spatial_dim = dim,
                                      .has_block_count = count,
                                      .has_iblank = iblank,
                                      .bytes_per_real = bytes_per_real};
            absl::StatusOr<std::string> bytes = EncodePlot3d(grid, format);
            FUZZ_CHECK(bytes.ok(), bytes.status().ToString());
            const bool text = encoding == Plot3dEncoding::kAscii;
            const std::string name = absl::StrCat(
                text ? "text" : (encoding == Plot3dEncoding::kBinaryBigEndian ? "be" : "le"),
                text ? "" : absl::StrCat("_r", bytes_per_real), "_", dim, "d",
                count ? "_count" : "", iblank ? "_iblank" : "");
            Write(text ? "plot3d_text" : "plot3d_binary", name, *bytes);
          }
        }
      }
    }
  }
  Plot3dFormat format = DefaultPlot3dFormat(naca, Plot3dEncoding::kAscii);
  format.has_block_count = false;
  Write("plot3d_text", "naca0012_29x9_2d", EncodePlot3d(naca, format).value());
  // Fortran-style text: repeats, D exponents, commas.
  Write("plot3d_text", "fortran_repeats",
        "1\n3 2 1\n0.0, 0.5 1.0D0 3*0.0\n2*0.0 4*1.0E+00\n0 0 0 0 0 0\n");
  format.encoding = Plot3dEncoding::kBinaryBigEndian;
  format.bytes_per_real = 4;
  Write("plot3d_binary", "naca0012_29x9_2d_be_r4", EncodePlot3d(naca, format).value());
  Plot3dStreamAndPlanesSeeds();
}

void AirfoilSeeds() {
  const fs::path dir = fs::path(SPLINEGRID_SOURCE_DIR) / "../shared/data/airfoils";
  for (const char* name :
       {"naca0012.dat", "rae2822.dat", "sc20714.dat", "30p30n/30p30n_slat.dat"}) {
    absl::StatusOr<std::string> text = ReadFileToString((dir / name).string());
    FUZZ_CHECK(text.ok(), text.status().ToString());
    Write("airfoil", fs::path(name).filename().string(), *text);
  }
  // Lednicer: counts line, upper and lower surfaces from the leading edge, D exponents.
  Write("airfoil", "lednicer.dat",
        "LEDNICER SAMPLE\n  4.  4.\n\n0.0 0.0\n0.3 0.06\n0.7 0.04\n1.0 0.0\n\n"
        "0.0 0.0\n0.3D0 -0.05\n0.7,-0.03\n1.0E0 0.0\n");
}

// The 29 x 9 grid with one fitted revision, as archive records: a 4-byte length framing for
// archive_records, the record file framing for record_file.
void ArchiveSeeds(const MultiBlockGrid& naca, GridFit fit) {
  auto grid = std::make_shared<server::StoredGrid>();
  grid->id = "naca";
  grid->display_name = "NACA 0012 29 x 9";
  grid->create_time = absl::FromUnixSeconds(1700000000);
  auto source = std::make_shared<server::SourcePoints>();
  source->checked = FittableGrid::Check(naca).value();
  source->format = "plot3d ascii 2d single-block";
  grid->source = std::move(source);
  auto revision = std::make_shared<server::GridRevision>();
  revision->number = 1;
  revision->create_time = grid->create_time;
  revision->blocks = fit.blocks;
  revision->kinds = fit.kinds;
  revision->report = fit.report;
  grid->revisions.push_back(revision);

  std::string framed, record_file(kRecordFileMagic);  // NOLINT
  const absl::Status emitted = server::ForEachRecord(*grid, [&](const v1::ArchiveRecord& record) {
    const std::string payload = record.SerializeAsString();
    const uint32_t n = static_cast<uint32_t>(payload.size());
    const char length[4] = {static_cast<char>(n), static_cast<char>(n >> 8),
                            static_cast<char>(n >> 16), static_cast<char>(n >> 24)};
    framed.append(length, 4).append(payload);
    record_file.append(FrameRecord(payload));
    return absl::OkStatus();
  });
  FUZZ_CHECK(emitted.ok(), emitted.ToString());
  Write("archive_records", "naca_rev1", framed);
  Write("record_file", "naca_rev1.sgrid", record_file);
  Write("record_file", "three_small",
        absl::StrCat(std::string(kRecordFileMagic), FrameRecord(""), FrameRecord("a"),
                     FrameRecord("abcdefgh")));
  // The source alone (no revision), as an import of points only would store it.
  grid->revisions.clear();
  framed.clear();
  FUZZ_CHECK(server::ForEachRecord(*grid,
                                   [&](const v1::ArchiveRecord& record) {
                                     const std::string payload = record.SerializeAsString();
                                     const uint32_t n = static_cast<uint32_t>(payload.size());
                                     const char length[4] = {
                                         static_cast<char>(n), static_cast<char>(n >> 8),
                                         static_cast<char>(n >> 16), static_cast<char>(n >> 24)};
                                     framed.append(length, 4).append(payload);
                                     return absl::OkStatus();
                                   })
                 .ok(),
             "source records");
  Write("archive_records", "naca_source_only", framed);
}

void RequestSeeds(const GridFit& fit) {
  // FitSpec: default, tolerance, boundary tolerances, control counts, fairing, face kinds.
  std::vector<std::pair<std::string, GridFitOptions>> specs(6);
  specs[0].first = "default";
  specs[1].first = "tolerance";
  specs[1].second.tolerance = 1e-4;
  specs[2].first = "boundary_tolerances";
  specs[2].second.boundary_tolerances = BoundaryTolerances();
  specs[3].first = "control_counts";
  specs[3].second.control_counts = {12, 6, 0};
  specs[3].second.block_control_counts = {{0, {8, 5, 0}}};
  specs[3].second.max_controls_per_direction = 40;
  specs[4].first = "fairing";
  specs[4].second.tolerance = 1e-3;
  specs[4].second.fairing = {.mode = FairingMode::kToTolerance, .weight = 100.0};
  specs[5].first = "face_kinds";
  specs[5].second.order = 3;
  specs[5].second.parametrization = Parametrization::kCentripetal;
  specs[5].second.face_kinds = {
      {.face = {.block = 0, .normal = 1, .upper = false}, .kind = BoundaryKind::kWall}};
  for (const auto& [name, options] : specs) {
    v1::FitGridRequest request;
    request.set_name("grids/naca");
    EncodeFitSpec(options, request.mutable_spec());
    WriteMessage("fit_spec", name, request);
    v1::GenerateGridRequest generate;
    EncodeFitSpec(options, generate.mutable_spec());
    WriteMessage("generate_request", "spec_" + name, generate);
  }
  for (auto [name, mode, weight] :
       {std::tuple{"off", v1::FAIRING_MODE_OFF, 0.0},
        std::tuple{"weight", v1::FAIRING_MODE_WEIGHT, 10.0},
        std::tuple{"to_tolerance", v1::FAIRING_MODE_TO_TOLERANCE, 0.0}}) {
    v1::FairGridRequest request;
    request.set_name("grids/naca");
    request.set_revision(1);
    request.mutable_fairing()->set_mode(mode);
    request.mutable_fairing()->set_weight(weight);
    WriteMessage("fairing", name, request);
  }
  // EvaluateGrid: level, counts, index box.
  {
    v1::EvaluateGridRequest request;
    request.set_name("grids/naca");
    request.set_refinement_level(2);
    WriteMessage("evaluate_request", "level", request);
    request.mutable_counts()->set_i(50);
    request.mutable_counts()->set_j(20);
    request.mutable_counts()->set_k(1);
    WriteMessage("evaluate_request", "counts", request);
    request.set_refinement_level(1);
    request.mutable_index_box()->mutable_begin()->set_i(2);
    request.mutable_index_box()->mutable_end()->set_i(10);
    request.mutable_index_box()->mutable_end()->set_j(4);
    request.add_blocks(0);
    WriteMessage("evaluate_request", "index_box", request);
  }
  // SplineBlock: the fitted block, full.
  {
    v1::SplineBlock block;
    EncodeSplineBlock(fit.blocks.front().fitted, 0, /*full=*/true, &block);
    WriteMessage("spline_block", "naca_block0", block);
  }
  // GenerateGrid: points, an airfoil file, every layer parameter.
  {
    v1::GenerateGridRequest request;
    request.set_grid_id("gen");
    for (double x : {1.0, 0.0, 0.5, 0.05, 0.0, 0.0, 0.5, -0.05, 1.0, 0.0}) {
      request.mutable_points()->add_xy(x);
    }
    WriteMessage("generate_request", "points", request);
    ProfileGridOptions options;
    EncodeProfileGridOptions(options, &request);
    request.set_method(v1::LAYER_METHOD_TRANSFINITE);
    request.set_airfoil_file("SAMPLE\n1.0 0.0\n0.5 0.05\n0.0 0.0\n0.5 -0.05\n1.0 0.0\n");
    WriteMessage("generate_request", "airfoil_all_options", request);
  }
}

void DeformSeeds(GridFit fit) {
  std::vector<FittedBlock> blocks;
  for (BlockFit& block : fit.blocks) blocks.push_back(std::move(block.fitted));
  const Deformer deformer = Deformer::Create(blocks, fit.kinds, {}).value();
  v1::DeformGridRequest request;
  request.set_name("grids/naca");
  request.mutable_boundary()->add_kinds(v1::BOUNDARY_KIND_WALL);
  request.set_propagation(v1::PROPAGATION_TRANSFINITE);
  request.set_rigid_radius(0.1);
  request.set_decay_radius(2.0);
  request.set_smoothing_iterations(3);
  v1::RigidMotion* rigid = request.mutable_rigid();
  rigid->add_center(0.25);
  rigid->add_center(0.0);
  rigid->set_angle_degrees(5.0);
  rigid->add_translation(0.0);
  rigid->add_translation(0.01);
  WriteMessage("deform_request", "rigid", request);
  // Controls: the first three moved controls, spatial_dim values each.
  v1::ControlDisplacements* controls = request.mutable_controls()->add_blocks();
  for (size_t q = 0; q < 3 && q < deformer.moved_controls().size(); ++q) {
    controls->set_block(deformer.moved_controls()[q].first);
    controls->add_controls(deformer.moved_controls()[q].second);
    controls->add_values(0.001);
    controls->add_values(-0.002);
  }
  WriteMessage("deform_request", "controls", request);
  // Boundary points on a face range (j = 0, the wall side), and a selection by range.
  v1::BoundaryPointMotion* range = request.mutable_boundary_points()->add_ranges();
  range->mutable_range()->set_block(0);
  range->mutable_range()->set_face(v1::BLOCK_FACE_J_MIN);
  range->mutable_range()->mutable_end()->set_i(4);
  range->set_refinement_level(1);
  range->set_displacements(true);
  for (int q = 0; q < 2 * 9; ++q) range->add_coordinates(0.001 * q);
  *request.mutable_boundary()->add_ranges() = range->range();
  request.mutable_boundary()->clear_kinds();
  WriteMessage("deform_request", "boundary_points", request);
}

}  // namespace
}  // namespace splinegrid::fuzz

int main(int argc, char** argv) {
  using namespace splinegrid::fuzz;
  g_root = argc > 1 ? argv[1] : std::string(SPLINEGRID_SOURCE_DIR) + "/tests/fuzz/corpus";
  const splinegrid::MultiBlockGrid naca = SmallNaca0012();
  const splinegrid::GridFit fit = FitSmall(naca);
  Plot3dSeeds(naca);
  AirfoilSeeds();
  ArchiveSeeds(naca, fit);
  RequestSeeds(fit);
  DeformSeeds(fit);
  std::printf("seeds written to %s\n", g_root.c_str());
  return 0;
}
