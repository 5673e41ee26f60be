#include "core/fit/solve/banded_qr.h"

#include <random>

#include "Eigen/Dense"
#include "gtest/gtest.h"

namespace splinegrid {
namespace {

// A random banded least-squares problem: rows with `bandwidth` nonzeros at non-decreasing
// starting columns that cover every column.
struct BandedProblem {
  Eigen::MatrixXd dense;
  std::vector<int> first;
};

BandedProblem RandomBanded(std::mt19937& rng, int rows, int cols, int bandwidth) {
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  BandedProblem p{Eigen::MatrixXd::Zero(rows, cols), {}};
  for (int r = 0; r < rows; ++r) {
    const int first = static_cast<int>(static_cast<int64_t>(r) * (cols - bandwidth + 1) / rows);
    p.first.push_back(first);
    for (int t = 0; t < bandwidth; ++t) p.dense(r, first + t) = value(rng);
  }
  return p;
}

// Solves with BandedQR for all right-hand sides at once (rows of B are replayed as vectors).
Eigen::MatrixXd SolveBanded(const BandedProblem& p, int bandwidth, const Eigen::MatrixXd& rhs) {
  const int rows = p.dense.rows(), cols = p.dense.cols(), width = rhs.cols();
  BandedQR qr(cols, bandwidth);
  for (int r = 0; r < rows; ++r) {
    std::vector<double> values(bandwidth);
    for (int t = 0; t < bandwidth; ++t) values[t] = p.dense(r, p.first[r] + t);
    qr.AddRow(p.first[r], values);
  }
  EXPECT_TRUE(qr.CheckRank().ok());
  // acc is row-major (cols x width).
  std::vector<double> acc(static_cast<size_t>(cols) * width, 0.0), v(width);
  for (int r = 0; r < rows; ++r) {
    for (int x = 0; x < width; ++x) v[x] = rhs(r, x);
    qr.ReduceRow(r, v.data(), acc.data(), width, width);
  }
  qr.BackSubstitute(acc.data(), width, width);
  Eigen::MatrixXd x(cols, width);
  for (int j = 0; j < cols; ++j) {
    for (int c = 0; c < width; ++c) x(j, c) = acc[j * width + c];
  }
  return x;
}

// The dense Householder QR is the oracle (Ceres' habit: the dense backend checks the fast one).
TEST(BandedQRTest, MatchesDenseQrOnRandomProblems) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  for (const auto& [rows, cols, bandwidth] : std::vector<std::tuple<int, int, int>>{
           {10, 10, 2}, {40, 12, 4}, {101, 37, 4}, {64, 64, 5}, {300, 20, 3}, {17, 9, 6}}) {
    const BandedProblem p = RandomBanded(rng, rows, cols, bandwidth);
    Eigen::MatrixXd rhs(rows, 3);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < 3; ++c) rhs(r, c) = value(rng);
    }
    const Eigen::MatrixXd banded = SolveBanded(p, bandwidth, rhs);
    const Eigen::MatrixXd dense = p.dense.colPivHouseholderQr().solve(rhs);
    const double scale = dense.cwiseAbs().maxCoeff();
    EXPECT_LT((banded - dense).cwiseAbs().maxCoeff(), 1e-10 * scale)
        << rows << "x" << cols << " bandwidth " << bandwidth;
    // Same residual as the oracle, to rounding.
    const double r_banded = (p.dense * banded - rhs).norm();
    const double r_dense = (p.dense * dense - rhs).norm();
    EXPECT_NEAR(r_banded, r_dense, 1e-12 * (1.0 + r_dense));
  }
}

TEST(BandedQRTest, DetectsRankDeficiency) {
  // Column 2 never receives a nonzero: the data leave it undetermined.
  BandedQR qr(4, 2);
  qr.AddRow(0, std::vector<double>{1.0, 2.0});
  qr.AddRow(0, std::vector<double>{0.5, -1.0});
  qr.AddRow(3, std::vector<double>{1.0});
  qr.AddRow(3, std::vector<double>{2.0});
  const absl::Status status = qr.CheckRank();
  EXPECT_EQ(status.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(status.message().find("column 2"), std::string::npos) << status;
}

TEST(BandedQRTest, RowsShorterThanTheBandAreAccepted) {
  // Mixed widths, as when penalty rows are wider than the collocation rows.
  BandedQR qr(3, 3);
  qr.AddRow(0, std::vector<double>{1.0});
  qr.AddRow(0, std::vector<double>{1.0, 1.0, 1.0});
  qr.AddRow(1, std::vector<double>{1.0, -1.0});
  qr.AddRow(2, std::vector<double>{2.0});
  ASSERT_TRUE(qr.CheckRank().ok());
  Eigen::MatrixXd a(4, 3);
  a << 1, 0, 0, 1, 1, 1, 0, 1, -1, 0, 0, 2;
  const Eigen::Vector4d b(1, 2, 3, 4);
  std::vector<double> acc(3, 0.0);
  for (int r = 0; r < 4; ++r) {
    double v = b[r];
    qr.ReduceRow(r, &v, acc.data(), 1, 1);
  }
  qr.BackSubstitute(acc.data(), 1, 1);
  const Eigen::Vector3d expected = a.colPivHouseholderQr().solve(b);
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(acc[j], expected[j], 1e-13);
}

}  // namespace
}  // namespace splinegrid
