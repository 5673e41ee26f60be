#include "client/cli/output.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "absl/time/time.h"
#include "core/bspline/differential_geometry.h"
#include "core/bspline/evaluation.h"
#include "google/protobuf/util/json_util.h"

namespace splinegrid::cli {

std::string ToJson(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.add_whitespace = true;
  options.preserve_proto_field_names = true;
  std::string json;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json;
}

std::string ToJsonLine(const google::protobuf::Message& message) {
  google::protobuf::util::JsonPrintOptions options;
  options.preserve_proto_field_names = true;
  std::string json;
  (void)google::protobuf::util::MessageToJsonString(message, &json, options);
  return json + "\n";
}

std::string OriginName(v1::RevisionOrigin origin) {
  const std::string name = v1::RevisionOrigin_Name(origin);
  constexpr char kPrefix[] = "REVISION_ORIGIN_";
  return name.rfind(kPrefix, 0) == 0 ? name.substr(sizeof(kPrefix) - 1)
                                     : absl::StrCat(static_cast<int>(origin));
}

std::string FormatDeformReport(const v1::DeformReport& r) {
  const v1::Extents& c = r.worst_cell();
  return absl::StrFormat(
      "  fold check at level %d: %d cells, Jacobian ratio min %.4g (block %d, cell %d,%d,%d) "
      "max %.4g\n"
      "  wall orthogonality change %.3g degrees; %d moved controls, decay radius %.4g; %.2f ms\n"
      "%s",
      r.check_level(), r.cells_checked(), r.min_jacobian_ratio(), r.worst_block(), c.i(), c.j(),
      c.k(), r.max_jacobian_ratio(), r.max_orthogonality_change_degrees(), r.moved_controls(),
      r.decay_radius(), 1e3 * r.seconds(),
      r.boundary_error() > 0.0
          ? absl::StrFormat("  boundary points missed by up to %.4g\n", r.boundary_error())
          : std::string());
}

std::string FormatDeform(const std::string& name, const v1::DeformGridRequest& request,
                         const v1::DeformGridResponse& response) {
  std::string out = absl::StrFormat(
      "%s revision %d: deformed %s, time %.6g, step %d\n", name, response.revision(),
      request.reference_revision() == 0 ? std::string("the latest revision")
                                        : absl::StrCat("revision ", request.reference_revision()),
      request.time(), request.step());
  absl::StrAppend(&out, FormatDeformReport(response.report()));
  return out;
}

std::string FormatRevisionLine(const v1::RevisionInfo& r) {
  std::string out = absl::StrFormat("revision %d origin %s", r.revision(), OriginName(r.origin()));
  if (r.parent_revision() != 0) absl::StrAppend(&out, " parent ", r.parent_revision());
  if (r.origin() == v1::REVISION_ORIGIN_DEFORM) {
    absl::StrAppend(&out, absl::StrFormat(" time %.6g step %d", r.time(), r.step()));
  }
  if (r.has_create_time()) {
    absl::StrAppend(&out, " created ",
                    absl::FormatTime(absl::RFC3339_full,
                                     absl::FromUnixSeconds(r.create_time().seconds()) +
                                         absl::Nanoseconds(r.create_time().nanos()),
                                     absl::UTCTimeZone()));
  }
  return out + "\n";
}

std::string FormatExtents(const v1::Extents& e) {
  return absl::StrCat(e.i(), "x", e.j(), "x", e.k());
}

namespace {

// "0.000145" or "-" for an absent optional deviation.
template <typename T>
std::string Optional(bool has, T value) {
  return has ? absl::StrFormat("%.3g", value) : std::string("-");
}

std::string FormatCurvatureLine(const char* label, const v1::CurvatureReport& c) {
  return absl::StrFormat(
      "  %s: %d lines, %d samples, %d curvature extrema, sum of squared differences %.4g, "
      "max |curvature| %.4g\n",
      label, c.lines(), c.samples(), c.extrema(), c.sum_squared_differences(),
      c.max_abs_curvature());
}

// "wall 0.000137 <= 0.00015 met, interface ..., interior 0.205 (no tolerance)": the largest
// deviation of each kind over `blocks`, against the tolerance the fit was held to where one was
// asked (FitReport.tolerances); "met" only there; then "; first-layer heights at walls changed by
// up to 22%", the largest over `blocks` (DeviationByKind.first_layer), when measured, against
// the tolerances' first_layer when one was asked.
std::string FormatKindDeviations(
    const v1::FitReport& r, const google::protobuf::RepeatedPtrField<v1::BlockFitSummary>& blocks) {
  struct Kind {
    const char* name;
    bool has = false;
    double deviation = 0.0;
    double tolerance = 0.0;  // 0: none
  };
  const v1::BoundaryTolerances& t = r.tolerances();
  const bool held = r.tolerances_given() && r.has_tolerances();
  Kind kinds[4] = {{"wall", false, 0.0, held ? t.wall() : 0.0},
                   {"interface", false, 0.0, held ? t.interface() : 0.0},
                   {"outer", false, 0.0, held ? t.outer() : 0.0},
                   {"interior", false, 0.0, held ? t.interior() : 0.0}};
  double first_layer = -1.0;  // not a deviation: a relative change (none measured: < 0)
  for (const v1::BlockFitSummary& b : blocks) {
    const v1::DeviationByKind& d = b.deviation_by_kind();
    const bool has[4] = {d.has_wall(), d.has_interface(), d.has_outer(), d.has_interior()};
    const double value[4] = {d.wall(), d.interface(), d.outer(), d.interior()};
    for (int k = 0; k < 4; ++k) {
      if (!has[k]) continue;
      kinds[k].deviation = kinds[k].has ? std::max(kinds[k].deviation, value[k]) : value[k];
      kinds[k].has = true;
    }
    if (d.has_first_layer()) first_layer = std::max(first_layer, d.first_layer());
  }
  std::string out;
  for (const Kind& k : kinds) {
    if (!k.has) continue;
    if (!out.empty()) absl::StrAppend(&out, ", ");
    if (k.tolerance > 0.0) {
      const bool met = k.deviation <= k.tolerance;
      absl::StrAppend(&out,
                      absl::StrFormat("%s %.3g %s %.3g %s", k.name, k.deviation, met ? "<=" : ">",
                                      k.tolerance, met ? "met" : "NOT MET"));
    } else {
      absl::StrAppend(
          &out, absl::StrFormat("%s %.3g%s", k.name, k.deviation, held ? " (no tolerance)" : ""));
    }
  }
  // What a solver's y+ follows: held to BoundaryTolerances.first_layer where one was asked.
  if (first_layer >= 0.0) {
    absl::StrAppend(&out, absl::StrFormat("; first-layer heights at walls changed by up to %.3g%%",
                                          100.0 * first_layer));
    if (held && t.first_layer() > 0.0) {
      const bool met = first_layer <= t.first_layer();
      absl::StrAppend(&out, absl::StrFormat(" %s %.3g%% %s", met ? "<=" : ">",
                                            100.0 * t.first_layer(), met ? "met" : "NOT MET"));
    }
  }
  return out;
}

// A block's largest size change either way (grown or shrunk), as the report's summary line
// gives it for the grid (convert.cc); the quality's max_ratio alone is growth only.
double SizeRatio(const v1::CellQualityReport& q) {
  return q.min_ratio() > 0.0 ? std::max(q.max_ratio(), 1.0 / q.min_ratio()) : q.max_ratio();
}

// A block's cell figure, or "-" for a block without cells (a curve, a point).
std::string CellFigure(const v1::CellQualityReport& q, double value) {
  return q.cells_checked() > 0 ? absl::StrFormat("%.3g", value) : "-";
}

}  // namespace

std::string FormatReport(const v1::FitReport& r, bool interpolating, bool has_cells) {
  std::string out;
  if (!r.tolerances_given()) {
    absl::StrAppend(&out, interpolating
                              ? "  tolerances: none given (interpolating: a control per point)\n"
                              : "  tolerances: none given (a fit to control counts)\n");
  } else {
    absl::StrAppend(&out,
                    absl::StrFormat("  tolerances: %s%s\n", r.tolerance_met() ? "met" : "NOT MET",
                                    r.unmet_reason().empty() ? "" : ": " + r.unmet_reason()));
  }
  for (const std::string& adjustment : r.adjustments()) {
    absl::StrAppend(&out, "  not as asked: ", adjustment, "\n");
  }
  if (r.reference_length() > 0.0) {
    absl::StrAppend(&out, absl::StrFormat("  reference length %.6g (%s)%s\n", r.reference_length(),
                                          r.reference_length_description(),
                                          // A fit to counts or an interpolating one
                                          // has no tolerances to be fractions of it.
                                          r.tolerances_given() && !r.has_tolerances()
                                              ? ": the default tolerances by kind are fractions "
                                                "of it"
                                              : ""));
  }
  if (has_cells) {
    absl::StrAppend(
        &out, absl::StrFormat("  cells at levels 0-2: %d folded sub-cells, %d original cells "
                              "folded or resized beyond 2x; worst Jacobian ratio %.3g, largest "
                              "size ratio %.3g\n",
                              r.folded_cells(), r.bad_cells(), r.min_jacobian_ratio(),
                              r.max_size_ratio()));
  } else {  // the ratios would read 0, as if every cell were degenerate
    absl::StrAppend(&out, "  cells: none (a curve or a point)\n");
  }
  absl::StrAppend(&out, absl::StrFormat("  connectivity: %d matches, largest gap %.3g\n",
                                        r.num_matches(), r.max_gap()));
  if (r.iterations() > 0 || r.knots_inserted() > 0) {
    absl::StrAppend(&out, absl::StrFormat("  knots: %d inserted in %d rounds (%d quality rounds), "
                                          "%d removed\n",
                                          r.knots_inserted(), r.iterations(), r.quality_rounds(),
                                          r.knots_removed()));
  }
  if (r.fairing_weight() > 0.0) {
    absl::StrAppend(&out, absl::StrFormat("  fairing weight %.3g\n", r.fairing_weight()));
  }
  if (r.has_unfaired_wall_curvature()) {
    // The same knots without the fairing (not the parent revision, whose knots differ).
    absl::StrAppend(&out,
                    FormatCurvatureLine("walls, same knots unfaired", r.unfaired_wall_curvature()));
  }
  if (r.wall_curvature().lines() > 0) {
    absl::StrAppend(&out, FormatCurvatureLine("walls", r.wall_curvature()));
  }
  return out;
}

std::string FormatFit(const std::string& name, const v1::FitGridResponse& fit) {
  std::string out = absl::StrFormat(
      "%s revision %d: %d points -> %d control points (%.1fx), %.1f ms\n", name, fit.revision(),
      fit.num_points(), fit.num_control_points(), fit.compression_ratio(), 1e3 * fit.seconds());
  // The deviation of each kind against its tolerance, not one maximum beside "met" (the interior
  // of a fit by kind has no tolerance).
  const std::string kinds = FormatKindDeviations(fit.report(), fit.blocks());
  absl::StrAppend(&out, "  deviation: ",
                  kinds.empty() ? absl::StrFormat("max %.3g", fit.max_deviation()) : kinds,
                  fit.report().tolerances_given() ? "" : " (no tolerance given)", "\n");
  int64_t cells = 0;
  for (const v1::BlockFitSummary& block : fit.blocks()) cells += block.quality().cells_checked();
  absl::StrAppend(
      &out, FormatReport(fit.report(), fit.num_control_points() == fit.num_points(), cells > 0));
  absl::StrAppend(
      &out, absl::StrFormat("%6s %10s %9s %7s %10s %10s %10s %10s %10s %9s %8s %8s %6s\n", "block",
                            "points", "controls", "ratio", "max dev", "wall", "interface", "outer",
                            "interior", "1st layer", "min jac", "max size", "bad"));
  for (int b = 0; b < fit.blocks_size(); ++b) {
    const v1::BlockFitSummary& s = fit.blocks(b);
    const v1::DeviationByKind& k = s.deviation_by_kind();
    const v1::CellQualityReport& q = s.quality();
    absl::StrAppend(
        &out, absl::StrFormat(
                  "%6d %10d %9d %7.1f %10.3g %10s %10s %10s %10s %9s %8s %8s %6d%s\n", b,
                  s.num_points(), s.num_control_points(), s.compression_ratio(), s.max_deviation(),
                  Optional(k.has_wall(), k.wall()), Optional(k.has_interface(), k.interface()),
                  Optional(k.has_outer(), k.outer()), Optional(k.has_interior(), k.interior()),
                  // relative, as a percentage (the deviation line's figure, block by block)
                  k.has_first_layer() ? absl::StrFormat("%.3g%%", 100.0 * k.first_layer()) : "-",
                  CellFigure(q, q.min_ratio()), CellFigure(q, SizeRatio(q)), q.num_bad_cells(),
                  s.has_tolerance_met() && !s.tolerance_met()
                      ? absl::StrCat("  TOLERANCE NOT MET: ", s.unmet_reason())
                      : ""));
  }
  return out;
}

std::string FormatGenerate(const v1::GenerateGridResponse& response) {
  const v1::GenerationReport& r = response.report();
  const v1::GenerateGridRequest& p = r.parameters();
  const v1::ProfileFitReport& f = r.profile();
  const v1::OGridQuality& q = r.quality();
  const std::string method = p.method() == v1::LAYER_METHOD_TRANSFINITE ? "transfinite"
                             : p.method() == v1::LAYER_METHOD_ELLIPTIC  ? "elliptic"
                                                                        : "offsets";
  std::string out = absl::StrFormat(
      "%s: %s O-grid %s around %s, %.1f ms\n", response.grid().name(), method,
      FormatExtents(r.extents()),
      f.name().empty() ? "the points" : absl::StrCat("'", f.name(), "'"), 1e3 * r.seconds());
  absl::StrAppend(&out,
                  absl::StrFormat("  profile: %d points -> %d control points, max deviation %.3g "
                                  "(tolerance %.3g), %s trailing edge, %d features, fairing %.3g\n",
                                  f.num_points(), f.num_control_points(), f.max_deviation(),
                                  p.fit_tolerance(), f.sharp_trailing_edge() ? "sharp" : "blunt",
                                  f.features(), f.fairing_weight()));
  absl::StrAppend(&out, absl::StrFormat("  layers: %d, first height %.3g, distance %.4g, growth "
                                        "ratio %.5f, %d retries, %d wall corners\n",
                                        p.layers(), p.first_height(), p.distance(),
                                        r.growth_ratio(), r.retries(), r.wall_corners()));
  if (r.marched_layers() > 0) {
    absl::StrAppend(&out, absl::StrFormat("  from offset layer %d on (the lines from the wall "
                                          "would cross in a cove)\n",
                                          r.marched_layers()));
  }
  if (r.has_elliptic()) {
    const v1::EllipticReport& e = r.elliptic();
    absl::StrAppend(
        &out, absl::StrFormat(
                  "  elliptic: %s, coarse level %d sweeps (%.1f ms), fine level %d "
                  "sweeps (%.1f ms), relaxation %.3g, %d restarts%s\n",
                  e.converged() ? "converged" : "NOT converged", e.coarse_sweeps(),
                  1e3 * e.coarse_seconds(), e.fine_sweeps(), 1e3 * e.fine_seconds(), e.relaxation(),
                  e.restarts(),
                  e.converged() ? ""
                                : " (the grid has no negative cell but does not "
                                  "solve the equations: try fewer layers or the offsets method)"));
  }
  absl::StrAppend(
      &out,
      absl::StrFormat("  quality: %d negative cells (min area %.3g), first layer %.4g .. %.4g, "
                      "wall orthogonality %.3g degrees, outer distance %.4g .. %.4g, %d "
                      "self-intersecting layers\n",
                      q.negative_cells(), q.min_cell_area(), q.first_height_min(),
                      q.first_height_max(), q.wall_orthogonality_degrees(), q.outer_distance_min(),
                      q.outer_distance_max(), q.self_intersecting_layers()));
  absl::StrAppend(&out, absl::StrFormat("  stages: profile fit %.1f ms, wall %.1f ms, layers %.1f "
                                        "ms, measure %.1f ms\n",
                                        1e3 * r.fit_seconds(), 1e3 * r.wall_seconds(),
                                        1e3 * r.layer_seconds(), 1e3 * r.measure_seconds()));
  absl::StrAppend(&out, FormatFit(response.grid().name(), response.fit()));
  return out;
}

std::string FormatGenerateVolume(const v1::GenerateGridResponse& response) {
  const v1::GenerationReport& r = response.report();
  const v1::GenerateGridRequest& p = r.parameters();
  const v1::VolumeReport& v = r.volume();
  int64_t points = 0;
  for (const v1::Extents& e : v.block_extents()) points += int64_t{e.i()} * e.j() * e.k();
  std::string out =
      absl::StrFormat("%s: volume grid of %d blocks, %d points, marched %s, %.1f ms\n",
                      response.grid().name(), v.blocks(), points,
                      p.side() == v1::MARCH_SIDE_OUTWARD        ? "outward"
                      : p.side() == v1::MARCH_SIDE_ALONG_NORMAL ? "along the normals"
                                                                : "against the normals",
                      1e3 * r.seconds());
  std::string planes;
  for (const v1::SymmetryPlane& plane : v.symmetry_planes()) {
    absl::StrAppend(&planes, planes.empty() ? "" : ", ", plane.axis(), " = ", plane.value());
  }
  int reversed = 0;
  for (bool b : v.reversed_i()) reversed += b ? 1 : 0;
  absl::StrAppend(&out,
                  absl::StrFormat("  layers: %d, first height %.3g, distance %.4g, growth "
                                  "ratio %.5f, normal smoothing %d, %d retries, %.1f ms\n",
                                  p.layers(), p.first_height(), p.distance(), r.growth_ratio(),
                                  p.normal_smoothing(), r.retries(), 1e3 * r.layer_seconds()));
  absl::StrAppend(
      &out,
      absl::StrFormat("  surface: %d connected, gap %.3g, symmetry planes: %s; %d blocks "
                      "with i reversed (right-handed cells)\n",
                      v.components(), v.surface_gap(), planes.empty() ? "none" : planes, reversed));
  absl::StrAppend(&out, absl::StrFormat("  quality: min scaled Jacobian %.3g, %d limited steps, "
                                        "shortfall %.3g, %d faired layers dropped, %d concave "
                                        "crease vertices\n",
                                        v.min_scaled_jacobian(), v.limited_steps(), v.shortfall(),
                                        v.refits_dropped(), v.crease_vertices()));
  absl::StrAppend(&out, FormatFit(response.grid().name(), response.fit()));
  return out;
}

std::string FormatCurvature(const std::string& name, const v1::GetWallCurvatureResponse& curvature,
                            const std::string& csv_path) {
  std::string out = absl::StrFormat("%s revision %d wall curvature\n", name, curvature.revision());
  absl::StrAppend(&out, FormatCurvatureLine("walls", curvature.metrics()));
  if (!csv_path.empty()) absl::StrAppend(&out, "  samples written to ", csv_path, "\n");
  return out;
}

std::string CurvatureCsv(const v1::GetWallCurvatureResponse& curvature) {
  std::string out =
      "block,direction,start_i,start_j,start_k,line,sample,arc_length,x,y,z,curvature\n";
  const int dim = curvature.spatial_dim();
  for (int l = 0; l < curvature.lines_size(); ++l) {
    const v1::WallCurvatureLine& line = curvature.lines(l);
    for (int q = 0; q < line.curvature_size(); ++q) {
      const double z = dim == 3 ? line.points(3 * q + 2) : 0.0;
      absl::StrAppend(
          &out, absl::StrFormat("%d,%d,%d,%d,%d,%d,%d,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                                line.block(), line.direction(), line.start().i(), line.start().j(),
                                line.start().k(), l, q, line.arc_length(q), line.points(dim * q),
                                line.points(dim * q + 1), z, line.curvature(q)));
    }
  }
  return out;
}

std::string FormatGrid(const v1::Grid& grid) {
  std::string out =
      absl::StrFormat("%s%s\n  source: %d blocks, %d points, %dD, %s\n", grid.name(),
                      grid.display_name().empty() ? "" : " (" + grid.display_name() + ")",
                      grid.source().blocks_size(), grid.source().num_points(),
                      grid.source().spatial_dim(), grid.source().format());
  if (grid.latest_revision() == 0) {
    absl::StrAppend(&out, "  not fitted yet\n");
    return out;
  }
  const v1::Revision& r = grid.revision();
  absl::StrAppend(
      &out, absl::StrFormat("  revision %d of %d: %d control points (%.1fx), max deviation %.3g\n",
                            r.revision(), grid.latest_revision(), r.num_control_points(),
                            r.compression_ratio(), r.max_deviation()));
  absl::StrAppend(&out, "  origin ", OriginName(r.origin()));
  if (r.parent_revision() != 0) absl::StrAppend(&out, " of revision ", r.parent_revision());
  if (r.origin() == v1::REVISION_ORIGIN_DEFORM) {
    absl::StrAppend(&out, absl::StrFormat(", time %.6g, step %d", r.time(), r.step()));
  }
  absl::StrAppend(&out, "\n");
  if (r.has_deform_report()) absl::StrAppend(&out, FormatDeformReport(r.deform_report()));
  for (const v1::SplineBlock& b : r.blocks()) {
    absl::StrAppend(
        &out,
        absl::StrFormat("  block %d: controls %dx%dx%d, order %d/%d/%d, "
                        "max deviation %.3g\n",
                        b.index(), b.directions(0).num_controls(), b.directions(1).num_controls(),
                        b.directions(2).num_controls(), b.directions(0).order(),
                        b.directions(1).order(), b.directions(2).order(), b.fit().max_deviation()));
  }
  return out;
}

ProgressLine::ProgressLine(std::string label)
    : label_(std::move(label)), enabled_(isatty(STDERR_FILENO) == 1) {}

client::ProgressFn ProgressLine::callback() {
  return [this](int64_t done, int64_t total) {
    if (!enabled_) return;
    const int64_t percent = total > 0 ? 100 * done / total : 0;
    if (percent == last_) return;
    last_ = percent;
    drawn_ = true;
    std::fprintf(stderr, "\r%s %.1f / %.1f MiB (%lld%%)   ", label_.c_str(), done / 1048576.0,
                 total / 1048576.0, static_cast<long long>(percent));
    std::fflush(stderr);
  };
}

void ProgressLine::Done() {
  if (drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

std::string FormatAirfoilFit(const std::string& name, double tolerance, const AirfoilFit& fit) {
  std::string out = absl::StrFormat(
      "%s: %d points -> %d control points, %s trailing edge, largest distance %.3g (%s %.3g)\n",
      name, static_cast<int>(fit.params.size()), fit.num_control_points,
      fit.sharp_trailing_edge ? "sharp" : "blunt", fit.max_deviation,
      fit.met ? "within" : "NOT within", tolerance);
  if (!fit.met) absl::StrAppend(&out, "  ", fit.unmet_reason, "\n");
  absl::StrAppend(&out, absl::StrFormat("  fairing weight %.3g; curvature extrema %d unfaired, "
                                        "%d faired, %d spurious (per piece:",
                                        fit.fairing_weight, fit.unfaired_curvature.total.extrema,
                                        fit.curvature.total.extrema, fit.curvature.spurious()));
  for (int64_t e : fit.curvature.piece_extrema) absl::StrAppend(&out, " ", e);
  absl::StrAppend(&out, ")\n");
  return out;
}

std::string AirfoilCurvatureCsv(const AirfoilFit& fit) {
  std::string out = "u,x,y,curvature\n";
  const int n = 8 * static_cast<int>(std::max<size_t>(fit.params.size(), 2) - 1);
  for (int q = 0; q <= n; ++q) {
    const double u = static_cast<double>(q) / n;
    const Point3 p = EvaluatePoint(fit.curve, {u, 0.0, 0.0});
    absl::StrAppend(&out, absl::StrFormat("%.17g,%.17g,%.17g,%.17g\n", u, p[0], p[1],
                                          CurveCurvature(fit.curve, 0, u)));
  }
  return out;
}

}  // namespace splinegrid::cli
