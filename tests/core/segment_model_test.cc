// SegmentModel::Build on small grids: which block directions share a class, their splits,
// shared (normalised) parameters and knots through full, partial, reversed and hanging-node
// matches, feature splits, MatchedControls, and the errors for matches that cannot hold, and
// the model's promise: blocks fitted with its knots have the same boundary controls.
#include "core/fit/adaptive/segment_model.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/bspline/basis.h"
#include "core/bspline/parametrization.h"
#include "core/fit/solve/tensor_fit.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/core/synthetic_grids.h"

namespace splinegrid {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Normalised parameters of the same class computed in two blocks: an affine map of the same
// values, so equal up to a few rounding errors.
constexpr double kAffineRoundingTol = 1e-15;

using Features = std::vector<std::array<std::vector<int>, 3>>;

std::vector<std::array<std::vector<double>, 3>> OwnParams(const MultiBlockGrid& grid) {
  std::vector<std::array<std::vector<double>, 3>> params;
  for (const StructuredBlock& b : grid.blocks) {
    params.push_back(ParametrizeBlock(b, Parametrization::kChordLength));
  }
  return params;
}

absl::StatusOr<SegmentModel> BuildModel(const MultiBlockGrid& grid, Features features = {},
                                        int order = 4, int max_controls = 0,
                                        const Connectivity* connectivity = nullptr) {
  features.resize(grid.blocks.size());
  const Connectivity c = connectivity ? *connectivity : FindConnectivity(grid).value();
  return SegmentModel::Build(grid, OwnParams(grid), c, features, order, max_controls);
}

SegmentModel Model(const MultiBlockGrid& grid, Features features = {}) {
  absl::StatusOr<SegmentModel> model = BuildModel(grid, std::move(features));
  EXPECT_TRUE(model.ok()) << model.status();
  return model.ok() ? *std::move(model) : SegmentModel();
}

std::vector<double> Knots(const SegmentModel& model, int b, int d) {
  const auto kp = model.DirectionKnots(b, d);
  EXPECT_TRUE(kp.ok()) << kp.status();
  if (!kp.ok()) return {};
  return {kp->first.knots().begin(), kp->first.knots().end()};
}

TEST(SegmentModelTest, SingleBlockHasOneClassPerDirection) {
  MultiBlockGrid grid;
  grid.blocks.push_back(SideBySide(6).blocks[0]);
  const SegmentModel model = Model(grid);
  EXPECT_EQ(model.num_blocks(), 1);
  EXPECT_EQ(model.num_classes(), 2);
  const auto own = OwnParams(grid)[0];
  for (int d = 0; d < 2; ++d) {
    EXPECT_TRUE(model.active(0, d));
    EXPECT_EQ(model.order(0, d), 4);
    EXPECT_EQ(model.cap(0, d), 6);
    EXPECT_TRUE(model.splits(0, d).empty());
    ASSERT_EQ(model.segment_classes(0, d).size(), 1u);
    for (int r = 0; r < 6; ++r) EXPECT_NEAR(model.params(0, d)[r], own[d][r], kAffineRoundingTol);
    EXPECT_EQ(model.Controls(0, d), 4);  // one cubic piece: no class knots yet
    EXPECT_THAT(Knots(model, 0, d), ElementsAre(0, 0, 0, 0, 1, 1, 1, 1));
    EXPECT_TRUE(model.WellPosed(model.segment_classes(0, d)[0]));
  }
  EXPECT_FALSE(model.active(0, 2));
  EXPECT_EQ(model.Controls(0, 2), 1);
  // The cap never goes below the order, nor above the points.
  const SegmentModel capped = BuildModel(grid, {}, 4, 2).value();
  EXPECT_EQ(capped.cap(0, 0), 4);
  EXPECT_EQ(BuildModel(grid, {}, 4, 100).value().cap(0, 0), 6);
}

TEST(SegmentModelTest, FullEdgeSharesParametersAndKnots) {
  // B's j lines bulge away from the shared edge, so its own j parameters differ from A's.
  MultiBlockGrid grid = SideBySide(7);
  grid.blocks[1] = PlanarBlock(7, 7, [](int i, int j) {
    const double x = i / 6.0, y = j / 6.0;
    return Bend(1.0 + x, y + 0.3 * x * y * (1.0 - y));
  });
  SegmentModel model = Model(grid);
  EXPECT_EQ(model.num_classes(), 3);  // A's i, B's i, and A's j with B's j
  const int shared = model.segment_classes(0, 1)[0];
  EXPECT_EQ(model.segment_classes(1, 1)[0], shared);
  EXPECT_NE(model.segment_classes(0, 0)[0], model.segment_classes(1, 0)[0]);
  // The class parameters average the two blocks' own; both blocks then use them.
  const auto own = OwnParams(grid);
  const SegmentModel::Class& cls = model.segment_class(shared);
  EXPECT_EQ(cls.length, 6);
  EXPECT_EQ(cls.members.size(), 2u);
  EXPECT_GT(std::abs(own[0][1][3] - own[1][1][3]), 1e-4);
  for (int r = 0; r <= 6; ++r) {
    EXPECT_NEAR(cls.params[r], 0.5 * (own[0][1][r] + own[1][1][r]), kAffineRoundingTol);
  }
  EXPECT_EQ(model.params(0, 1), model.params(1, 1));
  model.mutable_class(shared).knots = {0.3, 0.6};
  EXPECT_EQ(Knots(model, 0, 1), Knots(model, 1, 1));
  EXPECT_EQ(model.Controls(0, 1), 6);
  // The i directions keep their own parameters.
  for (int r = 0; r < 7; ++r) EXPECT_NEAR(model.params(1, 0)[r], own[1][0][r], kAffineRoundingTol);
}

// Knots of `model` in (lo, hi) for block direction (b, d), normalised to [0, 1] over [lo, hi].
std::vector<double> NormalisedKnots(const SegmentModel& model, int b, int d, double lo, double hi) {
  std::vector<double> out;
  for (double t : Knots(model, b, d)) {
    if (t > lo && t < hi) out.push_back((t - lo) / (hi - lo));
  }
  return out;
}

TEST(SegmentModelTest, PartialMatchSplitsBothBlocks) {
  // A's j 4..8 are B's j 0..4.
  const MultiBlockGrid grid = SideBySide(9, 0.5);
  SegmentModel model = Model(grid);
  EXPECT_THAT(model.splits(0, 1), ElementsAre(4));
  EXPECT_THAT(model.splits(1, 1), ElementsAre(4));
  ASSERT_EQ(model.segment_classes(0, 1).size(), 2u);
  ASSERT_EQ(model.segment_classes(1, 1).size(), 2u);
  const int shared = model.segment_classes(0, 1)[1];
  EXPECT_EQ(model.segment_classes(1, 1)[0], shared);
  EXPECT_NE(model.segment_classes(0, 1)[0], shared);
  EXPECT_NE(model.segment_classes(1, 1)[1], shared);
  EXPECT_EQ(model.num_classes(), 2 + 3);
  // Each block keeps its own parameter at the split; in between both use the class's.
  const auto own = OwnParams(grid);
  const std::vector<double>& pa = model.params(0, 1);
  const std::vector<double>& pb = model.params(1, 1);
  EXPECT_EQ(pa[4], own[0][1][4]);
  EXPECT_EQ(pb[4], own[1][1][4]);
  for (int r = 0; r <= 4; ++r) {
    EXPECT_NEAR((pa[4 + r] - pa[4]) / (1.0 - pa[4]), pb[r] / pb[4], kAffineRoundingTol) << r;
  }
  model.mutable_class(shared).knots = {0.25, 0.5};
  // A split is a knot of multiplicity order - 1 with a pinned control.
  const auto kp = model.DirectionKnots(0, 1).value();
  EXPECT_EQ(kp.first.Multiplicity(pa[4]), 3);
  ASSERT_EQ(kp.second.size(), 1u);
  EXPECT_EQ(kp.second[0].data_row, 4);
  const SampledBasis basis = SampleBasis(kp.first, std::vector<double>{pa[4]});
  EXPECT_EQ(basis.Row(0)[kp.second[0].control - basis.first[0]], 1.0);
  EXPECT_EQ(model.Controls(0, 1), 4 + 3 + 2);
  const std::vector<double> ka = NormalisedKnots(model, 0, 1, pa[4], 1.0);
  const std::vector<double> kb = NormalisedKnots(model, 1, 1, 0.0, pb[4]);
  ASSERT_EQ(ka.size(), 2u);
  ASSERT_EQ(kb.size(), 2u);
  for (int q = 0; q < 2; ++q) EXPECT_NEAR(ka[q], kb[q], kAffineRoundingTol);

  // The shared boundary's controls: A's last i column from the pin up, B's first from 0 to its
  // pin, one to one.
  const int na_j = model.Controls(0, 1), nb_j = model.Controls(1, 1);
  const std::vector<Extents> extents = {{model.Controls(0, 0), na_j, 1},
                                        {model.Controls(1, 0), nb_j, 1}};
  const Connectivity c = FindConnectivity(grid).value();
  const auto pairs = model.MatchedControls(c, extents);
  const int pin_b = model.DirectionKnots(1, 1).value().second[0].control;
  ASSERT_EQ(static_cast<int>(pairs.size()), na_j - kp.second[0].control);
  ASSERT_EQ(static_cast<int>(pairs.size()), pin_b + 1);
  for (size_t q = 0; q < pairs.size(); ++q) {
    const int ya = kp.second[0].control + static_cast<int>(q);
    EXPECT_EQ(pairs[q].first, std::make_pair(0, int64_t{extents[0][0] - 1 + extents[0][0] * ya}));
    EXPECT_EQ(pairs[q].second, std::make_pair(1, int64_t{extents[1][0] * static_cast<int>(q)}));
  }
}

TEST(SegmentModelTest, ReversedMatchMirrorsParametersAndKnots) {
  const MultiBlockGrid grid = SideBySide(7, 0.0, 0, /*reversed=*/true);
  SegmentModel model = Model(grid);
  const int shared = model.segment_classes(0, 1)[0];
  ASSERT_EQ(model.segment_classes(1, 1)[0], shared);
  const SegmentModel::Class& cls = model.segment_class(shared);
  ASSERT_EQ(cls.members.size(), 2u);
  EXPECT_NE(cls.members[0].reversed, cls.members[1].reversed);
  const std::vector<double>& pa = model.params(0, 1);
  const std::vector<double>& pb = model.params(1, 1);
  for (int r = 0; r < 7; ++r) EXPECT_NEAR(pb[r], 1.0 - pa[6 - r], kAffineRoundingTol) << r;
  model.mutable_class(shared).knots = {0.2, 0.35, 0.7};
  const std::vector<double> ka = Knots(model, 0, 1), kb = Knots(model, 1, 1);
  ASSERT_EQ(ka.size(), kb.size());
  for (size_t q = 0; q < ka.size(); ++q) {
    EXPECT_NEAR(kb[q], 1.0 - ka[ka.size() - 1 - q], kAffineRoundingTol) << q;
  }
  // The knots are not symmetric, so the mirroring is not a coincidence.
  EXPECT_GT(std::abs(ka[5] - kb[5]), 0.05);
  // MatchedControls pairs A's control y with B's n - 1 - y.
  const std::vector<Extents> extents = {{4, 7, 1}, {4, 7, 1}};
  const auto pairs = model.MatchedControls(FindConnectivity(grid).value(), extents);
  ASSERT_EQ(pairs.size(), 7u);
  for (int y = 0; y < 7; ++y) {
    EXPECT_EQ(pairs[y].first, std::make_pair(0, int64_t{3 + 4 * y}));
    EXPECT_EQ(pairs[y].second, std::make_pair(1, int64_t{4 * (6 - y)}));
  }
}

TEST(SegmentModelTest, HangingNodesShareTheFineParameters) {
  const MultiBlockGrid grid = SideBySide(5, 0.0, 9);
  SegmentModel model = Model(grid);
  const int shared = model.segment_classes(0, 1)[0];
  ASSERT_EQ(model.segment_classes(1, 1)[0], shared);
  const SegmentModel::Class& cls = model.segment_class(shared);
  EXPECT_EQ(cls.length, 8);
  for (const SegmentModel::Member& m : cls.members) {
    EXPECT_EQ(m.stride, m.block == 0 ? 2 : 1);
    EXPECT_EQ(m.ClassCoord(m.r1), 8);
  }
  for (int r = 0; r < 5; ++r) EXPECT_EQ(model.params(0, 1)[r], model.params(1, 1)[2 * r]) << r;
  model.mutable_class(shared).knots = {0.4};
  EXPECT_EQ(Knots(model, 0, 1), Knots(model, 1, 1));
  EXPECT_TRUE(model.WellPosed(shared));
  // Too many knots for the coarse side's five points: no longer well posed.
  model.mutable_class(shared).knots = {0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7};
  EXPECT_FALSE(model.WellPosed(shared));
}

TEST(SegmentModelTest, FeaturesSplitEveryMatchedDirectionOrAreDropped) {
  const MultiBlockGrid grid = SideBySide(11);
  Features features(2);
  features[0][1] = {5};     // carried over to B's j
  features[1][0] = {1, 9};  // too close to the ends for a cubic: dropped
  const SegmentModel model = Model(grid, features);
  EXPECT_THAT(model.splits(0, 1), ElementsAre(5));
  EXPECT_THAT(model.splits(1, 1), ElementsAre(5));
  EXPECT_TRUE(model.splits(1, 0).empty());
  EXPECT_EQ(model.segment_classes(0, 1), model.segment_classes(1, 1));
  // A feature on a hanging node (between two coarse points) is dropped.
  Features odd(2);
  odd[1][1] = {3};
  const SegmentModel hanging = Model(SideBySide(5, 0.0, 9), odd);
  EXPECT_TRUE(hanging.splits(1, 1).empty());
  EXPECT_TRUE(hanging.splits(0, 1).empty());
}

// Features are dropped where one of their images through the matches would leave a segment
// too short for the order: the fine side of a hanging-node edge may have a feature whose coarse
// image is too close to the end (fine index 4 is coarse index 2 of 9). (Judged on its own
// direction only, such a feature made Build fail: "the matches cut a segment [0, 2] with fewer
// points than the spline order 4".)
TEST(SegmentModelTest, FeatureWhoseImageIsTooCloseToASplitIsDropped) {
  Features features(2);
  features[1][1] = {4, 10};  // coarse 2 (too close to 0) and 5
  absl::StatusOr<SegmentModel> model = BuildModel(SideBySide(9, 0.0, 17), features);
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_THAT(model->splits(0, 1), ElementsAre(5));
  EXPECT_THAT(model->splits(1, 1), ElementsAre(10));
  // Likewise where the image would be too close to another split: fine 6 and 10 are 4 apart,
  // their coarse images 3 and 5 only 2.
  features[1][1] = {6, 10};
  model = BuildModel(SideBySide(9, 0.0, 17), features);
  ASSERT_TRUE(model.ok()) << model.status();
  EXPECT_THAT(model->splits(0, 1), ElementsAre(3));
  EXPECT_THAT(model->splits(1, 1), ElementsAre(6));
}

TEST(SegmentModelTest, MatchesThatCannotHoldAreErrors) {
  // Cut too short: B touches A's edge in 3 points, fewer than a cubic needs (fine for order 3).
  const MultiBlockGrid short_overlap = SideBySide(5, 0.5);
  absl::StatusOr<SegmentModel> model = BuildModel(short_overlap);
  EXPECT_EQ(model.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(model.status().message(), HasSubstr("block 0 direction j"));
  EXPECT_THAT(model.status().message(), HasSubstr("fewer points than the spline order 4"));
  EXPECT_TRUE(BuildModel(short_overlap, {}, 3).ok());

  // The Moebius strip: the two blocks' j directions are linked forwards and reversed.
  const MultiBlockGrid strip = MoebiusStrip();
  const Connectivity c = FindConnectivity(strip).value();
  ASSERT_EQ(c.matches.size(), 2u);
  model = BuildModel(strip, {}, 4, 0, &c);
  EXPECT_EQ(model.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(model.status().message(), HasSubstr("contradicts the other matches"));
  EXPECT_THAT(model.status().message(), ::testing::AnyOf(HasSubstr(c.matches[0].Describe()),
                                                         HasSubstr(c.matches[1].Describe())));

  // The fine side of a hanging-node edge cut at an odd point (where a third block's match ends)
  // cannot carry the cut over to the coarse side.
  MultiBlockGrid three = SideBySide(9, 0.0, 17);
  three.blocks.push_back(BentRectangle(2.0, 0.25, 5, 0.0, 1.0 / 16, 4));  // B's j 0..3
  const Connectivity c3 = FindConnectivity(three).value();
  ASSERT_EQ(c3.matches.size(), 2u);
  model = BuildModel(three, {}, 4, 0, &c3);
  EXPECT_EQ(model.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_THAT(model.status().message(), HasSubstr("block 1 direction j is cut at 3"));
  EXPECT_THAT(model.status().message(), HasSubstr("(hanging nodes)"));
}

// The model's promise: blocks fitted with its knots and pins fit a shared boundary to the same
// curve, so their boundary controls agree (to rounding; MatchedControls copies make them equal).
TEST(SegmentModelTest, SharedKnotsGiveTheSameBoundaryControls) {
  const MultiBlockGrid grid = SideBySide(13, 0.5);  // A's j 6..12 ~ B's j 0..6
  SegmentModel model = Model(grid);
  for (int c = 0; c < model.num_classes(); ++c) model.mutable_class(c).knots = {0.5};
  std::vector<TensorSpline> fits;
  std::vector<Extents> extents;
  for (int b = 0; b < 2; ++b) {
    std::array<std::vector<double>, 3> params;
    std::array<KnotVector, 3> knots;
    DirectionPins pins;
    for (int d = 0; d < 3; ++d) {
      params[d] = model.params(b, d);
      const auto kp = model.DirectionKnots(b, d).value();
      knots[d] = kp.first;
      pins[d] = kp.second;
    }
    fits.push_back(
        FitTensor(grid.blocks[b], params, knots, EndCondition::kInterpolate, {}, pins).value());
    extents.push_back(fits.back().control_extents());
  }
  const auto pairs = model.MatchedControls(FindConnectivity(grid).value(), extents);
  ASSERT_EQ(pairs.size(), 5u);  // order 4 + one class knot
  for (const auto& [x, y] : pairs) {
    for (int c = 0; c < 2; ++c) {
      EXPECT_NEAR(fits[x.first].control()[2 * x.second + c],
                  fits[y.first].control()[2 * y.second + c], 1e-13);
    }
  }
}

}  // namespace
}  // namespace splinegrid
