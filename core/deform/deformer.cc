#include "core/deform/deformer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "absl/strings/str_cat.h"
#include "core/bspline/evaluation.h"
#include "core/grid/sampling.h"
#include "core/util/status_macros.h"

namespace splinegrid {

// The factored fits of one face range at one level: one RangeFit per tangential direction.
struct Deformer::BoundaryFit {
  int block = 0;
  std::vector<int> tangential;  // 1 or 2 directions
  std::vector<RangeFit> fits;   // per tangential direction
  std::array<std::vector<double>, 3>
      params;  // the samples (a single value in the normal direction)
};

namespace {

Point3 ControlPoint(const TensorSpline& spline, int64_t c) {
  const int s = spline.spatial_dim();
  const double* p = spline.control().data() + s * c;
  return {p[0], p[1], s == 3 ? p[2] : 0.0};
}

void SetControlPoint(TensorSpline& spline, int64_t c, const Point3& x) {
  const int s = spline.spatial_dim();
  double* p = spline.mutable_control().data() + s * c;
  for (int i = 0; i < s; ++i) p[i] = x[i];
}

double Distance2(const Point3& a, const Point3& b) {
  return (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
         (a[2] - b[2]) * (a[2] - b[2]);
}

// f(d) of the file comment of deformer.h.
double Fraction(double d, double r0, double r1) {
  if (d <= r0) return 1.0;
  if (d >= r1) return 0.0;
  const double t = (d - r0) / (r1 - r0);
  return 1.0 - t * t * (3.0 - 2.0 * t);
}

// Hash of a point's exact bits, to find controls that coincide bitwise.
struct BitsHash {
  size_t operator()(const std::array<uint64_t, 3>& b) const {
    return std::hash<uint64_t>()(b[0] * 0x9E3779B97F4A7C15ull ^ (b[1] + 0x7F4A7C15ull) ^
                                 (b[2] << 1));
  }
};

std::array<uint64_t, 3> Bits(const Point3& p) {
  std::array<uint64_t, 3> b;
  for (int c = 0; c < 3; ++c) std::memcpy(&b[c], &p[c], sizeof(double));
  return b;
}

// The Greville abscissa of every control of `knots`: the mean of its k - 1 inner knots.
std::vector<double> Greville(const KnotVector& knots) {
  const int n = knots.num_controls(), k = knots.order();
  std::vector<double> g(n, 0.0);
  if (k == 1) return g;
  for (int a = 0; a < n; ++a) {
    double sum = 0.0;
    for (int q = a + 1; q < a + k; ++q) sum += knots.knot(q);
    g[a] = sum / (k - 1);
  }
  return g;
}

// Coons (transfinite) interpolation of the interior of a control-net displacement D from its
// faces (control index 0 and n - 1 of each active direction), in the Greville abscissae.
void CoonsInterior(const TensorSpline& spline, std::vector<Point3>& D) {
  const Extents n = spline.control_extents();
  std::array<std::vector<double>, 3> g;
  std::vector<int> active;
  for (int d = 0; d < 3; ++d) {
    g[d] = Greville(spline.knots(d));
    if (n[d] > 1) active.push_back(d);
  }
  auto at = [&](int a, int b, int c) -> const Point3& {
    return D[a + int64_t{n[0]} * (b + int64_t{n[1]} * c)];
  };
  // The face index in direction d: 0 or n[d] - 1, and the blend weight of the upper one.
  const int ui = n[0] - 1, uj = n[1] - 1, uk = n[2] - 1;
  std::vector<Point3> out = D;
  for (int c = 0; c < n[2]; ++c) {
    for (int b = 0; b < n[1]; ++b) {
      for (int a = 0; a < n[0]; ++a) {
        const bool face =
            (a == 0 || a == ui) || (b == 0 || b == uj) || (n[2] > 1 && (c == 0 || c == uk));
        if (face) continue;
        const double x = g[0][a], y = g[1][b], z = n[2] > 1 ? g[2][c] : 0.0;
        Point3 p = {0, 0, 0};
        for (int e = 0; e < 3; ++e) {
          if (active.size() == 2) {
            p[e] = (1 - x) * at(0, b, c)[e] + x * at(ui, b, c)[e] + (1 - y) * at(a, 0, c)[e] +
                   y * at(a, uj, c)[e] -
                   ((1 - x) * (1 - y) * at(0, 0, c)[e] + x * (1 - y) * at(ui, 0, c)[e] +
                    (1 - x) * y * at(0, uj, c)[e] + x * y * at(ui, uj, c)[e]);
          } else {
            // U + V + W - UV - VW - WU + UVW.
            const double U = (1 - x) * at(0, b, c)[e] + x * at(ui, b, c)[e];
            const double V = (1 - y) * at(a, 0, c)[e] + y * at(a, uj, c)[e];
            const double W = (1 - z) * at(a, b, 0)[e] + z * at(a, b, uk)[e];
            const double UV = (1 - x) * (1 - y) * at(0, 0, c)[e] + x * (1 - y) * at(ui, 0, c)[e] +
                              (1 - x) * y * at(0, uj, c)[e] + x * y * at(ui, uj, c)[e];
            const double VW = (1 - y) * (1 - z) * at(a, 0, 0)[e] + y * (1 - z) * at(a, uj, 0)[e] +
                              (1 - y) * z * at(a, 0, uk)[e] + y * z * at(a, uj, uk)[e];
            const double WU = (1 - z) * (1 - x) * at(0, b, 0)[e] + z * (1 - x) * at(0, b, uk)[e] +
                              (1 - z) * x * at(ui, b, 0)[e] + z * x * at(ui, b, uk)[e];
            double UVW = 0.0;
            for (int q = 0; q < 8; ++q) {
              const int qa = q & 1, qb = (q >> 1) & 1, qc = (q >> 2) & 1;
              UVW += (qa ? x : 1 - x) * (qb ? y : 1 - y) * (qc ? z : 1 - z) *
                     at(qa ? ui : 0, qb ? uj : 0, qc ? uk : 0)[e];
            }
            p[e] = U + V + W - UV - VW - WU + UVW;
          }
        }
        out[a + int64_t{n[0]} * (b + int64_t{n[1]} * c)] = p;
      }
    }
  }
  D = std::move(out);
}

// The point extents of every block (its distribution's point counts).
std::vector<Extents> PointExtents(const std::vector<FittedBlock>& blocks) {
  std::vector<Extents> extents;
  for (const FittedBlock& b : blocks) {
    extents.push_back(
        {b.distribution.num_points(0), b.distribution.num_points(1), b.distribution.num_points(2)});
  }
  return extents;
}

// The moved controls (block, index), block by block in control order, and their reference
// positions.
void CollectMovedControls(const std::vector<FittedBlock>& reference,
                          const std::vector<std::vector<ControlRole>>& roles,
                          std::vector<std::pair<int, int64_t>>& moved,
                          std::vector<Point3>& positions) {
  const int nb = static_cast<int>(reference.size());
  for (int b = 0; b < nb; ++b) {
    for (int64_t c = 0; c < static_cast<int64_t>(roles[b].size()); ++c) {
      if (roles[b][c] == ControlRole::kMoved) {
        moved.push_back({b, c});
        positions.push_back(ControlPoint(reference[b].spline, c));
      }
    }
  }
}

// The moved boundary, sampled at its grid points.
std::vector<Point3> MovedBoundarySamples(const std::vector<FittedBlock>& reference,
                                         const std::vector<std::vector<uint8_t>>& selected) {
  std::vector<Point3> samples;
  for (size_t b = 0; b < reference.size(); ++b) {
    std::array<std::vector<double>, 3> params;
    for (int d = 0; d < 3; ++d) params[d] = reference[b].distribution.params(d);
    const StructuredBlock points = EvaluateGrid(reference[b].spline, params);
    const int s = points.spatial_dim();
    for (int64_t p = 0; p < points.num_points(); ++p) {
      if (!selected[b][p]) continue;
      const double* x = points.coords().data() + s * p;
      samples.push_back({x[0], x[1], s == 3 ? x[2] : 0.0});
    }
  }
  return samples;
}

// Per block, per control: the distance of a free or fixed control to the nearest of `samples`
// (0 for moved ones); into `*nearest_fixed` the smallest over the fixed ones (infinity: none).
std::vector<std::vector<double>> BoundaryDistances(
    const std::vector<FittedBlock>& reference, const std::vector<std::vector<ControlRole>>& roles,
    const std::vector<Point3>& samples, double* nearest_fixed) {
  std::vector<std::vector<double>> distance(reference.size());
  *nearest_fixed = std::numeric_limits<double>::infinity();
  for (size_t b = 0; b < reference.size(); ++b) {
    distance[b].assign(roles[b].size(), 0.0);
    for (int64_t c = 0; c < static_cast<int64_t>(distance[b].size()); ++c) {
      if (roles[b][c] == ControlRole::kMoved) continue;
      const Point3 p = ControlPoint(reference[b].spline, c);
      double best = std::numeric_limits<double>::infinity();
      for (const Point3& q : samples) best = std::min(best, Distance2(p, q));
      distance[b][c] = std::sqrt(best);
      if (roles[b][c] == ControlRole::kFixed) {
        *nearest_fixed = std::min(*nearest_fixed, distance[b][c]);
      }
    }
  }
  return distance;
}

// Per block, per control: the fraction of the motion it takes, 1 moved, 0 fixed, f(d) free.
std::vector<std::vector<double>> MotionFractions(const std::vector<std::vector<ControlRole>>& roles,
                                                 const std::vector<std::vector<double>>& distance,
                                                 double rigid_radius, double decay_radius) {
  std::vector<std::vector<double>> fraction(distance.size());
  for (size_t b = 0; b < distance.size(); ++b) {
    fraction[b].assign(distance[b].size(), 0.0);
    for (size_t c = 0; c < distance[b].size(); ++c) {
      switch (roles[b][c]) {
        case ControlRole::kMoved:
          fraction[b][c] = 1.0;
          break;
        case ControlRole::kFixed:
          break;
        case ControlRole::kFree:
          fraction[b][c] = Fraction(distance[b][c], rigid_radius, decay_radius);
          break;
      }
    }
  }
  return fraction;
}

// The groups of controls that coincide bitwise (shared boundaries of a watertight grid), each
// sorted, the groups sorted.
std::vector<std::vector<std::pair<int, int64_t>>> CoincidingControls(
    const std::vector<FittedBlock>& reference) {
  std::unordered_map<std::array<uint64_t, 3>, std::vector<std::pair<int, int64_t>>, BitsHash>
      groups;
  for (int b = 0; b < static_cast<int>(reference.size()); ++b) {
    for (int64_t c = 0; c < reference[b].spline.num_control_points(); ++c) {
      groups[Bits(ControlPoint(reference[b].spline, c))].push_back({b, c});
    }
  }
  std::vector<std::vector<std::pair<int, int64_t>>> coinciding;
  for (auto& [bits, members] : groups) {
    if (members.size() > 1) {
      std::sort(members.begin(), members.end());
      coinciding.push_back(std::move(members));
    }
  }
  std::sort(coinciding.begin(), coinciding.end());
  return coinciding;
}

// The accumulated displacements of the moved controls, each averaged over the ranges that gave
// it (`hits`), flattened to spatial_dim `s` values per control.
std::vector<double> AveragedDisplacements(std::vector<Point3>& moved, const std::vector<int>& hits,
                                          int s) {
  for (size_t q = 0; q < moved.size(); ++q) {
    if (hits[q] > 1) {
      for (double& v : moved[q]) v /= hits[q];
    }
  }
  std::vector<double> flat(moved.size() * s);
  for (size_t q = 0; q < moved.size(); ++q) {
    for (int e = 0; e < s; ++e) flat[s * q + e] = moved[q][e];
  }
  return flat;
}

// Whether control (a, b, c) of a net of `n` controls lies on no face (index 0 or n[d] - 1 of
// an active direction d).
bool InteriorControl(const Extents& n, int a, int b, int c) {
  const int idx[3] = {a, b, c};
  for (int d = 0; d < 3; ++d) {
    if (n[d] > 1 && (idx[d] == 0 || idx[d] == n[d] - 1)) return false;
  }
  return true;
}

}  // namespace

absl::Status DeformOptions::Validate() const {
  if (!(rigid_radius >= 0.0) || !std::isfinite(rigid_radius)) {
    return absl::InvalidArgumentError(
        absl::StrCat("rigid_radius = ", rigid_radius, " is not a finite number >= 0"));
  }
  if (!(decay_radius >= 0.0) || !std::isfinite(decay_radius)) {
    return absl::InvalidArgumentError(
        absl::StrCat("decay_radius = ", decay_radius, " is not a finite number >= 0"));
  }
  if (decay_radius > 0.0 && decay_radius <= rigid_radius) {
    return absl::InvalidArgumentError(absl::StrCat("decay_radius = ", decay_radius,
                                                   " must exceed rigid_radius = ", rigid_radius));
  }
  if (smoothing_iterations < 0 || smoothing_iterations > 10000) {
    return absl::InvalidArgumentError(
        absl::StrCat("smoothing_iterations = ", smoothing_iterations, " is outside [0, 10000]"));
  }
  if (propagation != Propagation::kBlend && propagation != Propagation::kTransfinite) {
    return absl::InvalidArgumentError(
        absl::StrCat("propagation = ", static_cast<int>(propagation), " is not a known value"));
  }
  return absl::OkStatus();
}

absl::StatusOr<Deformer> Deformer::Create(std::vector<FittedBlock> reference, BoundaryKinds kinds,
                                          const DeformOptions& options) {
  SG_RETURN_IF_ERROR(options.Validate());
  if (reference.empty()) return absl::InvalidArgumentError("the grid has no blocks");
  if (kinds.point_kinds.size() != reference.size()) {
    return absl::InvalidArgumentError(absl::StrCat("boundary kinds for ", kinds.point_kinds.size(),
                                                   " blocks, the grid has ", reference.size()));
  }
  Deformer deformer;
  deformer.options_ = options;
  SG_ASSIGN_OR_RETURN(deformer.selected_,
                      SelectedPoints(PointExtents(reference), kinds, options.moved));
  deformer.roles_ = ClassifyControls(reference, kinds, deformer.selected_);
  CollectMovedControls(reference, deformer.roles_, deformer.moved_, deformer.moved_positions_);
  if (deformer.moved_.empty()) {
    return absl::FailedPreconditionError(
        "no control point moves: the selection holds no boundary segment or face cell");
  }
  // Distances of the free and fixed controls to the moved boundary; the nearest fixed one
  // bounds the decay.
  double nearest_fixed = 0.0;
  const std::vector<std::vector<double>> distance =
      BoundaryDistances(reference, deformer.roles_,
                        MovedBoundarySamples(reference, deformer.selected_), &nearest_fixed);
  deformer.decay_radius_ = options.decay_radius > 0.0 ? options.decay_radius : nearest_fixed;
  if (!(deformer.decay_radius_ > options.rigid_radius)) {
    return absl::InvalidArgumentError(absl::StrCat(
        "rigid_radius = ", options.rigid_radius, " reaches the nearest fixed boundary control, ",
        deformer.decay_radius_, " from the moved boundary"));
  }
  deformer.fraction_ =
      MotionFractions(deformer.roles_, distance, options.rigid_radius, deformer.decay_radius_);
  deformer.coinciding_ = CoincidingControls(reference);
  deformer.reference_ = std::move(reference);
  deformer.kinds_ = std::move(kinds);
  return deformer;
}

template <typename FreeMotion>
void Deformer::Propagate(std::vector<FittedBlock>& blocks, const FreeMotion& free_motion) const {
  for (size_t b = 0; b < blocks.size(); ++b) {
    TensorSpline& spline = blocks[b].spline;
    for (int64_t c = 0; c < spline.num_control_points(); ++c) {
      if (roles_[b][c] != ControlRole::kFree) continue;
      const Point3 p = ControlPoint(reference_[b].spline, c);
      SetControlPoint(spline, c, free_motion(p, fraction_[b][c]));
    }
  }
  Finish(blocks);
}

// Jacobi sweeps of the spring-analogy Laplacian (deformer.h) over the interior free controls.
void Deformer::SmoothInterior(size_t b, std::vector<Point3>& D) const {
  const Extents n = reference_[b].spline.control_extents();
  for (int sweep = 0; sweep < options_.smoothing_iterations; ++sweep) {
    std::vector<Point3> next = D;
    for (int cc = 0; cc < n[2]; ++cc) {
      for (int bb = 0; bb < n[1]; ++bb) {
        for (int a = 0; a < n[0]; ++a) {
          const int64_t c = a + int64_t{n[0]} * (bb + int64_t{n[1]} * cc);
          if (!InteriorControl(n, a, bb, cc) || roles_[b][c] != ControlRole::kFree) continue;
          Point3 sum = {0, 0, 0};
          double weights = 0.0;
          const int64_t stride[3] = {1, n[0], int64_t{n[0]} * n[1]};
          const Point3 here = ControlPoint(reference_[b].spline, c);
          for (int d = 0; d < 3; ++d) {
            if (n[d] == 1) continue;
            for (int64_t q : {c - stride[d], c + stride[d]}) {
              const double d2 = Distance2(here, ControlPoint(reference_[b].spline, q));
              const double w = d2 > 0.0 ? 1.0 / d2 : 0.0;
              for (int e = 0; e < 3; ++e) sum[e] += w * D[q][e];
              weights += w;
            }
          }
          if (weights > 0.0) {
            for (int e = 0; e < 3; ++e) next[c][e] = sum[e] / weights;
          }
        }
      }
    }
    D = std::move(next);
  }
}

// Coinciding controls end up bitwise equal: the first member's value (a moved or fixed
// member's, when there is one, so boundaries stay exact).
void Deformer::EqualizeCoinciding(std::vector<FittedBlock>& blocks) const {
  for (const auto& group : coinciding_) {
    std::pair<int, int64_t> source = group.front();
    for (const auto& member : group) {
      if (roles_[member.first][member.second] != ControlRole::kFree) {
        source = member;
        break;
      }
    }
    const Point3 value = ControlPoint(blocks[source.first].spline, source.second);
    for (const auto& [b, c] : group) SetControlPoint(blocks[b].spline, c, value);
  }
}

void Deformer::Finish(std::vector<FittedBlock>& blocks) const {
  for (size_t b = 0; b < blocks.size(); ++b) {
    TensorSpline& spline = blocks[b].spline;
    const Extents n = spline.control_extents();
    const bool has_interior =
        spline.active_directions() >= 2 && spline.active_directions() == spline.spatial_dim();
    if (!has_interior) continue;
    if (options_.propagation != Propagation::kTransfinite && options_.smoothing_iterations == 0) {
      continue;
    }
    // The displacement of the net, and which controls are interior and free.
    const int64_t count = spline.num_control_points();
    std::vector<Point3> D(count);
    for (int64_t c = 0; c < count; ++c) {
      const Point3 now = ControlPoint(spline, c), was = ControlPoint(reference_[b].spline, c);
      D[c] = {now[0] - was[0], now[1] - was[1], now[2] - was[2]};
    }
    if (options_.propagation == Propagation::kTransfinite) CoonsInterior(spline, D);
    SmoothInterior(b, D);
    for (int cc = 0; cc < n[2]; ++cc) {
      for (int bb = 0; bb < n[1]; ++bb) {
        for (int a = 0; a < n[0]; ++a) {
          const int64_t c = a + int64_t{n[0]} * (bb + int64_t{n[1]} * cc);
          if (!InteriorControl(n, a, bb, cc) || roles_[b][c] != ControlRole::kFree) continue;
          const Point3 was = ControlPoint(reference_[b].spline, c);
          SetControlPoint(spline, c, {was[0] + D[c][0], was[1] + D[c][1], was[2] + D[c][2]});
        }
      }
    }
  }
  EqualizeCoinciding(blocks);
}

absl::StatusOr<std::vector<FittedBlock>> Deformer::Rigid(const RigidMotion& motion) const {
  SG_RETURN_IF_ERROR(motion.Validate());
  std::vector<FittedBlock> blocks = reference_;
  for (size_t q = 0; q < moved_.size(); ++q) {
    SetControlPoint(blocks[moved_[q].first].spline, moved_[q].second,
                    motion.Apply(moved_positions_[q]));
  }
  Propagate(blocks, [&](const Point3& p, double f) { return motion.Apply(p, f); });
  return blocks;
}

Point3 Deformer::BlendedDisplacement(const Point3& p, double f,
                                     const std::vector<Point3>& moved_displacements) const {
  if (f == 0.0) return {0, 0, 0};
  Point3 sum = {0, 0, 0};
  double weights = 0.0;
  for (size_t q = 0; q < moved_positions_.size(); ++q) {
    const double d2 = Distance2(p, moved_positions_[q]);
    if (d2 == 0.0)
      return {f * moved_displacements[q][0], f * moved_displacements[q][1],
              f * moved_displacements[q][2]};
    const double w = 1.0 / (d2 * std::sqrt(d2));  // |P - B|^-3
    weights += w;
    for (int e = 0; e < 3; ++e) sum[e] += w * moved_displacements[q][e];
  }
  return {f * sum[0] / weights, f * sum[1] / weights, f * sum[2] / weights};
}

absl::StatusOr<std::vector<FittedBlock>> Deformer::DisplaceControls(
    std::span<const double> displacements) const {
  const int s = reference_.front().spline.spatial_dim();
  if (displacements.size() != moved_.size() * s) {
    return absl::InvalidArgumentError(absl::StrCat(
        "displacements: ", displacements.size(), " values for ", moved_.size(),
        " moved control points of ", s, " coordinates (", moved_.size() * s, " values)"));
  }
  std::vector<Point3> moved(moved_.size(), Point3{0, 0, 0});
  for (size_t q = 0; q < moved_.size(); ++q) {
    for (int e = 0; e < s; ++e) {
      const double v = displacements[s * q + e];
      if (!std::isfinite(v)) {
        return absl::InvalidArgumentError(
            absl::StrCat("displacements[", s * q + e, "] = ", v, " is not finite"));
      }
      moved[q][e] = v;
    }
  }
  std::vector<FittedBlock> blocks = reference_;
  for (size_t q = 0; q < moved_.size(); ++q) {
    const Point3& p = moved_positions_[q];
    SetControlPoint(blocks[moved_[q].first].spline, moved_[q].second,
                    {p[0] + moved[q][0], p[1] + moved[q][1], p[2] + moved[q][2]});
  }
  Propagate(blocks, [&](const Point3& p, double f) {
    const Point3 d = BlendedDisplacement(p, f, moved);
    return Point3{p[0] + d[0], p[1] + d[1], p[2] + d[2]};
  });
  return blocks;
}

absl::StatusOr<std::shared_ptr<const Deformer::BoundaryFit>> Deformer::FitFor(
    const FaceRange& range, int level) const {
  const std::vector<int> key = {range.face.block,
                                range.face.normal,
                                range.face.upper ? 1 : 0,
                                range.begin[0],
                                range.begin[1],
                                range.begin[2],
                                range.end[0],
                                range.end[1],
                                range.end[2],
                                level};
  std::lock_guard<std::mutex> lock(*fits_mutex_);
  if (auto it = fits_.find(key); it != fits_.end()) return it->second;
  const FittedBlock& block = reference_[range.face.block];
  auto fit = std::make_shared<BoundaryFit>();
  fit->block = range.face.block;
  for (int d = 0; d < 3; ++d) {
    const int m = block.distribution.num_points(d);
    if (d == range.face.normal || m == 1) {
      const int at = d == range.face.normal ? (range.face.upper ? m - 1 : 0) : 0;
      fit->params[d] = {block.distribution.params(d)[at]};
      continue;
    }
    fit->tangential.push_back(d);
    fit->params[d] = block.distribution.Refined(d, range.begin[d], range.end[d], level);
    absl::StatusOr<RangeFit> f = RangeFit::Create(block.spline.knots(d), fit->params[d]);
    if (!f.ok()) {
      return absl::Status(f.status().code(),
                          absl::StrCat("block ", range.face.block, " direction ", d, ": ",
                                       f.status().message(), "; give the points at a finer level"));
    }
    fit->fits.push_back(*std::move(f));
  }
  fits_[key] = fit;
  return std::shared_ptr<const BoundaryFit>(fit);
}

absl::StatusOr<std::shared_ptr<const Deformer::BoundaryFit>> Deformer::CheckedFit(
    const BoundaryPoints& given, size_t r, const std::vector<Extents>& extents) const {
  const int s = reference_.front().spline.spatial_dim();
  const std::string name = absl::StrCat("boundary points ", r);
  BoundarySelection one;
  one.ranges = {given.range};
  SG_ASSIGN_OR_RETURN(const std::vector<std::vector<uint8_t>> inside,
                      SelectedPoints(extents, kinds_, one), name, ": ");
  const int b = given.range.face.block;
  for (size_t p = 0; p < inside[b].size(); ++p) {
    if (inside[b][p] && !selected_[b][p]) {
      const int64_t ni = extents[b][0], nj = extents[b][1], at = static_cast<int64_t>(p);
      return absl::InvalidArgumentError(absl::StrCat(
          name, ": point (", at % ni, ", ", (at / ni) % nj, ", ", at / (ni * nj), ") of block ", b,
          " is not on the moved boundary (DeformOptions.moved, a request's boundary: the "
          "walls unless it names kinds or face ranges)"));
    }
  }
  if (given.level < 0 || given.level > kMaxRefinementLevel) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": level = ", given.level,
                                                   " is outside [0, ", kMaxRefinementLevel, "]"));
  }
  SG_ASSIGN_OR_RETURN(std::shared_ptr<const BoundaryFit> fit, FitFor(given.range, given.level));
  if (fit->tangential.empty()) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": the range is a single point"));
  }
  int64_t count = 1;
  for (const RangeFit& f : fit->fits) count *= f.num_samples();
  if (static_cast<int64_t>(given.coordinates.size()) != count * s) {
    return absl::InvalidArgumentError(absl::StrCat(name, ": ", given.coordinates.size(),
                                                   " values for ", count, " points of ", s,
                                                   " coordinates at level ", given.level));
  }
  for (size_t v = 0; v < given.coordinates.size(); ++v) {
    if (!std::isfinite(given.coordinates[v])) {
      return absl::InvalidArgumentError(
          absl::StrCat(name, ": coordinates[", v, "] = ", given.coordinates[v], " is not finite"));
    }
  }
  return fit;
}

std::vector<double> Deformer::SampleDisplacements(const BoundaryPoints& given,
                                                  const BoundaryFit& fit) const {
  std::vector<double> delta = given.coordinates;
  if (!given.displacements) {
    const StructuredBlock was = EvaluateGrid(reference_[fit.block].spline, fit.params);
    for (size_t v = 0; v < delta.size(); ++v) delta[v] -= was.coords()[v];
  }
  return delta;
}

std::vector<double> Deformer::FitRangeControls(const BoundaryFit& fit,
                                               const std::vector<double>& delta, int s) {
  // Direction by direction: first tangential direction (fastest), then the second.
  const RangeFit& f0 = fit.fits[0];
  const int64_t rows1 = fit.fits.size() > 1 ? fit.fits[1].num_samples() : 1;
  std::vector<double> stage(static_cast<size_t>(f0.num_controls()) * rows1 * s);
  for (int64_t j = 0; j < rows1; ++j) {
    f0.Apply(delta.data() + j * f0.num_samples() * s, s, stage.data() + j * f0.num_controls() * s);
  }
  if (fit.fits.size() == 1) return stage;
  const RangeFit& f1 = fit.fits[1];
  // Lines of direction 1 are strided by f0.num_controls() * s: transpose through a buffer.
  const int64_t width = int64_t{f0.num_controls()} * s;
  std::vector<double> controls(static_cast<size_t>(width) * f1.num_controls(), 0.0);
  f1.Apply(stage.data(), width, controls.data());
  return controls;
}

void Deformer::AccumulateMoved(const BoundaryPoints& given, const BoundaryFit& fit,
                               const std::vector<double>& controls,
                               const std::vector<Extents>& extents,
                               const std::map<std::pair<int, int64_t>, size_t>& moved_index,
                               std::vector<Point3>& moved, std::vector<int>& hits) const {
  const int s = reference_.front().spline.spatial_dim();
  const int b = given.range.face.block;
  const RangeFit& f0 = fit.fits[0];
  const int cols1 = fit.fits.size() > 1 ? fit.fits[1].num_controls() : 1;
  const int first1 = fit.fits.size() > 1 ? fit.fits[1].first() : 0;
  const Extents n = reference_[b].spline.control_extents();
  const int t0 = fit.tangential[0];
  const int t1 = fit.tangential.size() > 1 ? fit.tangential[1] : -1;
  for (int a1 = 0; a1 < cols1; ++a1) {
    for (int a0 = 0; a0 < f0.num_controls(); ++a0) {
      Extents c = {0, 0, 0};
      const int normal = given.range.face.normal;
      if (reference_[b].spline.knots(normal).num_controls() > 1 && extents[b][normal] > 1) {
        c[normal] = given.range.face.upper ? n[normal] - 1 : 0;
      }
      c[t0] = f0.first() + a0;
      if (t1 >= 0) c[t1] = first1 + a1;
      const int64_t index = c[0] + int64_t{n[0]} * (c[1] + int64_t{n[1]} * c[2]);
      const auto it = moved_index.find({b, index});
      if (it == moved_index.end()) continue;  // carries none of the moved boundary
      const double* v = controls.data() + (int64_t{a1} * f0.num_controls() + a0) * s;
      for (int e = 0; e < s; ++e) moved[it->second][e] += v[e];
      ++hits[it->second];
    }
  }
}

absl::StatusOr<BoundaryMiss> Deformer::Miss(const std::vector<FittedBlock>& moved,
                                            std::span<const BoundaryPoints> points) const {
  const int s = reference_.front().spline.spatial_dim();
  const std::vector<Extents> extents = PointExtents(reference_);
  BoundaryMiss miss;
  for (size_t r = 0; r < points.size(); ++r) {
    SG_ASSIGN_OR_RETURN(const std::shared_ptr<const BoundaryFit> fit,
                        CheckedFit(points[r], r, extents));
    const StructuredBlock now = EvaluateGrid(moved[fit->block].spline, fit->params);
    // The positions asked: given, or the reference's plus the displacements given.
    std::vector<double> asked = points[r].coordinates;
    if (points[r].displacements) {
      const StructuredBlock was = EvaluateGrid(reference_[fit->block].spline, fit->params);
      for (size_t v = 0; v < asked.size(); ++v) asked[v] += was.coords()[v];
    }
    const int64_t count = now.num_points();
    for (int64_t p = 0; p < count; ++p) {
      double squared = 0.0;
      for (int e = 0; e < s; ++e) {
        const double d = now.coords()[p * s + e] - asked[p * s + e];
        squared += d * d;
      }
      if (std::sqrt(squared) > miss.distance) {
        miss.distance = std::sqrt(squared);
        miss.range = static_cast<int>(r);
        const int64_t n0 = now.extent(0), n1 = now.extent(1);
        const Extents at = {static_cast<int>(p % n0), static_cast<int>((p / n0) % n1),
                            static_cast<int>(p / (n0 * n1))};
        // The face's own index in its normal direction (a range's begin there is not read:
        // SelectedPoints), the range's lower corner scaled plus the sample's position along
        // the others, at the range's level.
        const FaceRange& range = points[r].range;
        const int64_t scale = int64_t{1} << points[r].level;
        for (int d = 0; d < 3; ++d) {
          const int64_t index =
              d == range.face.normal
                  ? (range.face.upper ? (extents[fit->block][d] - int64_t{1}) * scale : 0)
                  : range.begin[d] * scale + at[d];
          miss.point[d] = index;
        }
      }
    }
  }
  return miss;
}

absl::StatusOr<std::vector<FittedBlock>> Deformer::MoveBoundaryPoints(
    std::span<const BoundaryPoints> points) const {
  const int s = reference_.front().spline.spatial_dim();
  std::vector<Point3> moved(moved_.size(), Point3{0, 0, 0});
  std::vector<int> hits(moved_.size(), 0);
  std::map<std::pair<int, int64_t>, size_t> moved_index;
  for (size_t q = 0; q < moved_.size(); ++q) moved_index[moved_[q]] = q;
  const std::vector<Extents> extents = PointExtents(reference_);
  for (size_t r = 0; r < points.size(); ++r) {
    SG_ASSIGN_OR_RETURN(const std::shared_ptr<const BoundaryFit> fit,
                        CheckedFit(points[r], r, extents));
    // Displacements at the samples, fitted by the range's controls, accumulated into the moved
    // controls of the range's face.
    const std::vector<double> controls =
        FitRangeControls(*fit, SampleDisplacements(points[r], *fit), s);
    AccumulateMoved(points[r], *fit, controls, extents, moved_index, moved, hits);
  }
  return DisplaceControls(AveragedDisplacements(moved, hits, s));
}

}  // namespace splinegrid
