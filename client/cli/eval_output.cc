#include "client/cli/eval_output.h"

#include <cmath>
#include <deque>
#include <filesystem>
#include <set>
#include <span>

#include "absl/strings/str_cat.h"
#include "core/io/file_util.h"
#include "core/io/planar_view.h"
#include "core/io/plot3d.h"
#include "core/io/plot3d_function.h"
#include "core/io/vtk.h"
#include "core/io/vtk_fields.h"
#include "core/io/vtk_pvd.h"
#include "core/util/status_macros.h"
#include "proto/convert/plot3d_format_convert.h"

namespace splinegrid::cli {
namespace {

// The parametric dimension of evaluated `block` (facts first, else its extents).
int ParametricDim(const EvalGridFacts& facts, const client::EvaluatedBlock& block) {
  const auto it = facts.parametric_dim.find(block.block);
  if (it != facts.parametric_dim.end()) return it->second;
  int dims = 0;
  for (int d = 0; d < 3; ++d) dims += block.points.extent(d) > 1;
  return std::max(dims, 1);
}

// A block's VTK arrays with the storage of the derived ones.
struct BlockFields {
  std::deque<std::vector<double>> storage;  // deque: elements never move, spans stay valid
  std::vector<VtkPointArray> arrays;
};

// The VTK arrays of `block` that `options` ask for.
absl::StatusOr<BlockFields> FieldsOf(const client::EvaluatedBlock& block,
                                     const EvalGridFacts& facts, const EvalOutputOptions& options) {
  BlockFields fields;
  const StructuredBlock& points = block.points;
  const int s = points.spatial_dim();
  const int pdim = ParametricDim(facts, block);
  const std::string where = absl::StrCat("block ", block.block, ": ");
  const bool have_derivatives = !block.du.empty();
  if ((options.derivatives || options.jacobian) && !have_derivatives) {
    return absl::InternalError(absl::StrCat(where, "the server sent no derivatives"));
  }
  if (options.derivatives) {
    // Only the directions the block has: no dX_dw on surfaces and 2D blocks, only dX_du on
    // curves (the server sends zeros for the others).
    fields.arrays.push_back({"dX_du", s, block.du});
    if (pdim >= 2) fields.arrays.push_back({"dX_dv", s, block.dv});
    if (pdim >= 3) fields.arrays.push_back({"dX_dw", s, block.dw});
  }
  if (options.jacobian) {
    absl::StatusOr<std::vector<double>> jacobian =
        JacobianField(points, block.du, block.dv, block.dw, pdim);
    if (!jacobian.ok())
      return absl::InvalidArgumentError(absl::StrCat(where, jacobian.status().message()));
    fields.arrays.push_back({"jacobian", 1, fields.storage.emplace_back(*std::move(jacobian))});
  }
  if (options.quality) {
    absl::StatusOr<std::vector<double>> quality = ScaledJacobianCells(points);
    if (!quality.ok())
      return absl::InvalidArgumentError(absl::StrCat(where, quality.status().message()));
    fields.arrays.push_back({"scaled_jacobian", 1, fields.storage.emplace_back(*std::move(quality)),
                             VtkArrayLocation::kCell});
  }
  if (options.deviation) {
    if (block.block < 0 || block.block >= static_cast<int>(facts.source.blocks.size())) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "no source points for the deviation field"));
    }
    const StructuredBlock& source = facts.source.blocks[block.block];
    if (source.extents() != points.extents() || source.spatial_dim() != s) {
      return absl::InvalidArgumentError(
          absl::StrCat(where, "the deviation is measured at the source points: the evaluation has ",
                       points.extent(0), " x ", points.extent(1), " x ", points.extent(2),
                       " points, the source ", source.extent(0), " x ", source.extent(1), " x ",
                       source.extent(2), " (evaluate with --level 0 and no --box)"));
    }
    std::vector<double>& deviation = fields.storage.emplace_back(points.num_points());
    for (int64_t p = 0; p < points.num_points(); ++p) {
      double sum = 0.0;
      for (int c = 0; c < s; ++c) {
        const double d = points.coords()[p * s + c] - source.coords()[p * s + c];
        sum += d * d;
      }
      deviation[p] = std::sqrt(sum);
    }
    fields.arrays.push_back({"deviation", 1, deviation});
  }
  return fields;
}

absl::StatusOr<int64_t> WriteVtk(const std::string& out, const std::string& ext,
                                 client::EvaluatedGrid result, const EvalGridFacts& facts,
                                 const EvalOutputOptions& options) {
  MultiBlockGrid grid;
  // A deque: growing it never moves (or copies) earlier blocks, whose arrays point into them.
  std::deque<BlockFields> fields;
  std::vector<std::vector<VtkPointArray>> arrays;
  std::vector<int> numbers;
  int64_t points = 0;
  for (client::EvaluatedBlock& block : result.blocks) {
    SG_ASSIGN_OR_RETURN(BlockFields f, FieldsOf(block, facts, options));
    fields.push_back(std::move(f));  // points into block.du, dv, dw (kept), not its points
    numbers.push_back(block.block);
    points += block.points.num_points();
    grid.blocks.push_back(std::move(block.points));
  }
  for (const BlockFields& f : fields) arrays.push_back(f.arrays);
  VtkWriteOptions vtk;
  vtk.compress = options.compress;
  if (ext == ".vts") {
    if (grid.blocks.size() != 1) {
      return absl::InvalidArgumentError(
          absl::StrCat(grid.blocks.size(), " blocks: write .vtm, or choose one with --block"));
    }
    SG_RETURN_IF_ERROR(WriteVts(out, grid.blocks[0], arrays[0], vtk));
  } else {
    SG_RETURN_IF_ERROR(WriteVtm(out, grid, arrays, vtk, numbers));
  }
  return points;
}

// The derivative functions of `block` (its points moved out; `extents` were theirs) as the
// Plot3D grid file holds it (`written`, restored to two planes when `planes` is given): dX_du,
// dX_dv[, dX_dw], each with the file's coordinates.
absl::StatusOr<Plot3dFunctionBlock> DerivativeFunctions(const client::EvaluatedBlock& block,
                                                        int pdim, const Extents& extents,
                                                        const StructuredBlock& written,
                                                        const TwoPlaneLayout* planes) {
  std::vector<std::span<const double>> derivatives = {block.du};
  if (pdim >= 2) derivatives.push_back(block.dv);
  if (pdim >= 3) derivatives.push_back(block.dw);
  const int s = written.spatial_dim();
  Plot3dFunctionBlock functions;
  functions.extents = written.extents();
  functions.num_functions = static_cast<int>(derivatives.size()) * s;
  functions.values.resize(static_cast<size_t>(written.num_points() * functions.num_functions));
  for (size_t d = 0; d < derivatives.size(); ++d) {
    std::vector<double> vectors(derivatives[d].begin(), derivatives[d].end());
    if (planes != nullptr) {
      // A tangent of the planar view is a vector in the plane: 0 along the normal coordinate.
      StructuredBlock tangent(extents, 2);
      std::copy(vectors.begin(), vectors.end(), tangent.coords().begin());
      TwoPlaneLayout in_plane = *planes;
      in_plane.plane_values[0] = in_plane.plane_values[1] = 0.0;
      SG_ASSIGN_OR_RETURN(const StructuredBlock restored, TwoPlaneBlock(tangent, in_plane));
      vectors.assign(restored.coords().begin(), restored.coords().end());
    }
    for (int64_t p = 0; p < written.num_points(); ++p) {
      for (int c = 0; c < s; ++c) {
        functions.values[p * functions.num_functions + d * s + c] = vectors[p * s + c];
      }
    }
  }
  return functions;
}

absl::StatusOr<int64_t> WritePlot3d(const std::string& out, const std::string& ext,
                                    client::EvaluatedGrid result, const EvalGridFacts& facts,
                                    const EvalOutputOptions& options) {
  if (options.jacobian || options.quality || options.deviation) {
    return absl::InvalidArgumentError(
        absl::StrCat("-o ", out,
                     ": --jacobian, --quality and --deviation are VTK fields; write "
                     ".vts, .vtm or .pvd"));
  }
  const Plot3dEncoding encoding =
      ext == ".x" ? Plot3dEncoding::kBinaryLittleEndian : Plot3dEncoding::kAscii;
  MultiBlockGrid evaluated;
  std::vector<int> indices;
  int64_t points = 0;
  // The derivative functions below need each block's extents, parametric dimension and
  // derivatives, not its points.
  std::vector<Extents> extents;
  std::vector<int> pdims;
  for (client::EvaluatedBlock& block : result.blocks) {
    extents.push_back(block.points.extents());
    pdims.push_back(ParametricDim(facts, block));
    evaluated.blocks.push_back(std::move(block.points));
    indices.push_back(block.block);
  }
  Plot3dWriteBack write;
  if (facts.plot3d.has_value()) {
    SG_ASSIGN_OR_RETURN(write,
                        ToPlot3dSourceForm(std::move(evaluated), indices, *facts.plot3d, encoding));
  } else {
    write.format = DefaultPlot3dFormat(evaluated, encoding);
    write.grid = std::move(evaluated);
  }
  SG_ASSIGN_OR_RETURN(const std::string grid_bytes, EncodePlot3d(write.grid, write.format));
  std::string function_bytes;
  if (options.derivatives) {
    std::vector<Plot3dFunctionBlock> functions;
    for (size_t b = 0; b < result.blocks.size(); ++b) {
      const client::EvaluatedBlock& block = result.blocks[b];
      if (block.du.empty()) return absl::InternalError("the server sent no derivatives");
      const TwoPlaneLayout* planes =
          facts.plot3d.has_value() && !facts.plot3d->two_planes.empty()
              ? &facts.plot3d->two_planes.at(static_cast<size_t>(block.block))
              : nullptr;
      SG_ASSIGN_OR_RETURN(Plot3dFunctionBlock f, DerivativeFunctions(block, pdims[b], extents[b],
                                                                     write.grid.blocks[b], planes));
      functions.push_back(std::move(f));
    }
    SG_ASSIGN_OR_RETURN(function_bytes, EncodePlot3dFunction(functions, write.format));
  }
  SG_RETURN_IF_ERROR(WriteFileAtomically(out, grid_bytes));
  if (options.derivatives) {
    SG_RETURN_IF_ERROR(WriteFileAtomically(FunctionFilePath(out), function_bytes));
  }
  for (const StructuredBlock& block : write.grid.blocks) points += block.num_points();
  return points;
}

}  // namespace

absl::StatusOr<EvalGridFacts> EvalFactsFromGrid(const v1::Grid& grid) {
  EvalGridFacts facts;
  if (grid.source().has_plot3d()) {
    SG_ASSIGN_OR_RETURN(facts.plot3d,
                        ParsePlot3dSourceFormat(grid.source().plot3d(), grid.source().blocks_size(),
                                                "source.plot3d"));
  }
  for (const v1::SplineBlock& block : grid.revision().blocks()) {
    int dims = 0;
    for (const v1::SplineDirection& direction : block.directions()) {
      dims += direction.num_controls() > 1;
    }
    facts.parametric_dim[block.index()] = std::max(dims, 1);
  }
  return facts;
}

std::string FunctionFilePath(const std::string& grid_path) {
  return std::filesystem::path(grid_path).replace_extension(".f").string();
}

absl::StatusOr<int64_t> WriteEvaluation(const std::string& out, client::EvaluatedGrid result,
                                        const EvalGridFacts& facts,
                                        const EvalOutputOptions& options) {
  const std::string ext = std::filesystem::path(out).extension().string();
  if (ext == ".vts" || ext == ".vtm") return WriteVtk(out, ext, std::move(result), facts, options);
  if (ext == ".x" || ext == ".xyz") {
    return WritePlot3d(out, ext, std::move(result), facts, options);
  }
  return absl::InvalidArgumentError(
      absl::StrCat("-o ", out, ": WriteEvaluation writes .vts, .vtm, .x or .xyz"));
}

absl::StatusOr<int64_t> WriteSeries(
    const std::string& pvd, const std::vector<SeriesStep>& steps,
    const std::function<absl::StatusOr<client::EvaluatedGrid>(const SeriesStep&)>& evaluate,
    const EvalGridFacts& facts, const EvalOutputOptions& options, std::string* note) {
  const std::filesystem::path path(pvd);
  if (path.extension() != ".pvd" || path.stem().empty()) {
    return absl::InvalidArgumentError(absl::StrCat("-o ", pvd, ": a series is a <name>.pvd"));
  }
  const std::string stem = path.stem().string();
  const std::filesystem::path directory = path.parent_path() / stem;
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) {
    return ErrnoToStatusWithMessage(
        error.value(), absl::StrCat("cannot create the directory '", directory.string(), "'"));
  }
  std::set<double> times;
  for (const SeriesStep& step : steps) times.insert(step.time);
  const bool use_steps = times.size() != steps.size();
  if (use_steps) {
    *note = absl::StrCat("revision times repeat (", steps.size(), " steps, ", times.size(),
                         " distinct times: deformed without --time?); the .pvd uses the step "
                         "numbers as TimeValue");
  }
  std::vector<PvdEntry> entries;
  int64_t points = 0;
  for (const SeriesStep& step : steps) {
    SG_ASSIGN_OR_RETURN(client::EvaluatedGrid result, evaluate(step));
    const std::string name =
        absl::StrCat(stem, "_", step.step, result.blocks.size() == 1 ? ".vts" : ".vtm");
    SG_ASSIGN_OR_RETURN(const int64_t written, WriteEvaluation((directory / name).string(),
                                                               std::move(result), facts, options));
    points += written;
    entries.push_back(
        {use_steps ? static_cast<double>(step.step) : step.time, absl::StrCat(stem, "/", name)});
  }
  SG_RETURN_IF_ERROR(WritePvd(pvd, entries));
  return points;
}

}  // namespace splinegrid::cli
