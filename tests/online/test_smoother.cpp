#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "hila/online/smoother.hpp"

using namespace hila;

namespace {

Eigen::VectorXd q2(double x, double y) {
  Eigen::VectorXd q(2);
  q << x, y;
  return q;
}

// An L-shaped path, each leg exactly 1 rad: resampled every 0.05 it has 41 points.
std::vector<Eigen::VectorXd> corner() {
  return {q2(0.0, 0.0), q2(1.0, 0.0), q2(1.0, 1.0)};
}

std::vector<Eigen::VectorXd> resampled_corner() {
  std::vector<Eigen::VectorXd> out;
  for (int i = 0; i <= 20; ++i) out.push_back(q2(0.05 * i, 0.0));
  for (int i = 1; i <= 20; ++i) out.push_back(q2(1.0, 0.05 * i));
  return out;
}

double acceleration_energy(const std::vector<Eigen::VectorXd>& x) {
  double e = 0.0;
  for (std::size_t i = 1; i + 1 < x.size(); ++i) {
    e += (x[i - 1] - 2.0 * x[i] + x[i + 1]).squaredNorm();
  }
  return e;
}

const auto always = [](const Eigen::VectorXd&, const Eigen::VectorXd&) { return true; };

}  // namespace

TEST(Smoother, FreeSpaceSolutionMatchesADenseSolveOfTheSameProblem) {
  online::SmootherSettings settings;  // spacing 0.05, length 0.5: weight (0.1)^4
  const auto result = online::smooth_path(corner(), always, settings);
  ASSERT_TRUE(result.smoothed);
  EXPECT_EQ(result.rounds, 1);
  const auto x0 = resampled_corner();
  ASSERT_EQ(result.path.size(), x0.size());
  EXPECT_TRUE(result.path.front().isApprox(x0.front(), 0.0));
  EXPECT_TRUE(result.path.back().isApprox(x0.back(), 0.0));

  // Reference: the normal equations assembled densely and solved by Eigen's LDLT.
  const int n = static_cast<int>(x0.size());
  const double w = std::pow(0.05 / 0.5, 4);
  Eigen::MatrixXd d2 = Eigen::MatrixXd::Zero(n - 2, n);
  for (int r = 0; r + 2 < n; ++r) d2.row(r).segment(r, 3) << 1.0, -2.0, 1.0;
  const Eigen::MatrixXd k = d2.transpose() * d2;
  Eigen::MatrixXd x0m(n, 2), ends = Eigen::MatrixXd::Zero(n, 2);
  for (int i = 0; i < n; ++i) x0m.row(i) = x0[static_cast<std::size_t>(i)].transpose();
  ends.row(0) = x0m.row(0);
  ends.row(n - 1) = x0m.row(n - 1);
  const Eigen::MatrixXd a =
      k.block(1, 1, n - 2, n - 2) + w * Eigen::MatrixXd::Identity(n - 2, n - 2);
  const Eigen::MatrixXd b = w * x0m.middleRows(1, n - 2) - k.middleRows(1, n - 2) * ends;
  const Eigen::MatrixXd reference = a.ldlt().solve(b);
  for (int i = 1; i + 1 < n; ++i) {
    EXPECT_LT((result.path[static_cast<std::size_t>(i)].transpose() - reference.row(i - 1)).norm(),
              1e-8)
        << "point " << i;
  }
  // It is smoother than the corner it came from, and cuts inside it.
  EXPECT_LT(acceleration_energy(result.path), 0.2 * acceleration_energy(x0));
  EXPECT_LT(result.path[20][0], 1.0 - 0.05);
  EXPECT_GT(result.path[20][1], 0.05);
}

TEST(Smoother, AnObstacleInsideTheCornerIsKeptOutByPinning) {
  // Everything within 0.38 of (0.6, 0.4) is blocked: the legs are 0.4 away and the corner
  // (1, 0) 0.57, but the free-space smoothing cuts into the disc.
  const Eigen::VectorXd centre = q2(0.6, 0.4);
  auto clear = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    for (int k = 0; k <= 20; ++k) {
      if ((a + (k / 20.0) * (b - a) - centre).norm() < 0.38) return false;
    }
    return true;
  };
  ASSERT_TRUE(clear(corner()[0], corner()[1]) && clear(corner()[1], corner()[2]));
  const auto free_space = online::smooth_path(corner(), always);
  bool cut = false;
  for (std::size_t i = 1; i < free_space.path.size(); ++i) {
    cut = cut || !clear(free_space.path[i - 1], free_space.path[i]);
  }
  ASSERT_TRUE(cut) << "the test's obstacle must be in the free-space solution's way";

  const auto result = online::smooth_path(corner(), clear);
  ASSERT_TRUE(result.smoothed);
  EXPECT_GT(result.rounds, 1);
  for (std::size_t i = 1; i < result.path.size(); ++i) {
    EXPECT_TRUE(clear(result.path[i - 1], result.path[i])) << "segment " << i;
  }
  // Still smoother than the corner (the legs' ends are smoothed where nothing is pinned).
  EXPECT_LT(acceleration_energy(result.path), acceleration_energy(resampled_corner()));
}

TEST(Smoother, NothingToSmoothOrNoValidSmoothingReturnsTheInput) {
  const std::vector<Eigen::VectorXd> line{q2(0.0, 0.0), q2(1.0, 1.0)};
  const auto two = online::smooth_path(line, always);
  EXPECT_FALSE(two.smoothed);
  EXPECT_EQ(two.path.size(), 2u);
  EXPECT_EQ(two.rounds, 0);
  // A checker that accepts nothing: every round fails, the input (valid by the caller's own
  // checks) is returned as it was.
  auto nothing = [](const Eigen::VectorXd&, const Eigen::VectorXd&) { return false; };
  online::SmootherSettings few;
  few.max_rounds = 3;
  const auto kept = online::smooth_path(corner(), nothing, few);
  EXPECT_FALSE(kept.smoothed);
  EXPECT_EQ(kept.rounds, 3);
  ASSERT_EQ(kept.path.size(), corner().size());
  for (std::size_t i = 0; i < kept.path.size(); ++i) {
    EXPECT_TRUE(kept.path[i].isApprox(corner()[i], 0.0));
  }
}
