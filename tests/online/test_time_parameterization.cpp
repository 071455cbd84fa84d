#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hila/online/time_parameterization.hpp"

using namespace hila;

namespace {

Eigen::VectorXd limits(double v) {
  return Eigen::VectorXd::Constant(6, v);
}

}  // namespace

TEST(TimeParameterization, OneLongSegmentTakesTheTrapezoidsClosedFormTime) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6), b = a;
  b[1] = 2.0;  // joint 2 moves 2 rad; v 1 rad/s, a 2 rad/s^2: 2/1 + 1/2 = 2.5 s
  b[3] = 0.5;
  const auto timed = online::time_parameterize({a, b}, limits(1.0), limits(2.0));
  EXPECT_NEAR(timed.time.back(), 2.5, 1e-12);
  EXPECT_TRUE(timed.q.back().isApprox(b, 0.0));
  // Short: triangular, 2 sqrt(d / a) = 2 sqrt(0.1 / 2).
  b = a;
  b[0] = 0.1;
  EXPECT_NEAR(online::time_parameterize({a, b}, limits(1.0), limits(2.0)).time.back(),
              2.0 * std::sqrt(0.05), 1e-12);
  // Half the scale: twice as long for a triangular profile's sqrt(1/a)... exactly sqrt(2) times.
  EXPECT_NEAR(online::time_parameterize({a, b}, limits(1.0), limits(2.0), 0.5).time.back(),
              2.0 * std::sqrt(0.1), 1e-12);
}

TEST(TimeParameterization, RandomPathsKeepEveryLimitBetweenSamples) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  Eigen::VectorXd vmax(6), amax(6);
  vmax << 3.14, 3.14, 3.14, 6.28, 6.28, 6.28;
  amax << 2.97, 2.97, 2.97, 5.93, 5.93, 5.93;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Eigen::VectorXd> path;
    for (int i = 0; i < 5; ++i) {
      Eigen::VectorXd q(6);
      for (int j = 0; j < 6; ++j) q[j] = u(rng);
      path.push_back(q);
    }
    path.push_back(path.back());  // a repeated waypoint is skipped
    const double scale = 0.5;
    const auto timed = online::time_parameterize(path, vmax, amax, scale);
    ASSERT_EQ(timed.q.size(), timed.time.size());
    EXPECT_TRUE(timed.q.front().isApprox(path.front(), 0.0));
    EXPECT_TRUE(timed.q.back().isApprox(path.back(), 0.0));
    // Every waypoint is passed (the profile stops there).
    std::size_t found = 0;
    for (const auto& q : timed.q) {
      if (found < path.size() && q.isApprox(path[found], 1e-12)) ++found;
    }
    EXPECT_GE(found, path.size() - 1);
    Eigen::VectorXd previous;
    for (std::size_t i = 1; i < timed.q.size(); ++i) {
      const double dt = timed.time[i] - timed.time[i - 1];
      ASSERT_GT(dt, 0.0);
      const Eigen::VectorXd v = (timed.q[i] - timed.q[i - 1]) / dt;
      for (int j = 0; j < 6; ++j) EXPECT_LE(std::abs(v[j]), scale * vmax[j] * (1 + 1e-9));
      if (previous.size() == 6) {
        const double mid = 0.5 * (timed.time[i] - timed.time[i - 2]);
        const Eigen::VectorXd acc = (v - previous) / mid;
        for (int j = 0; j < 6; ++j) EXPECT_LE(std::abs(acc[j]), scale * amax[j] * (1 + 1e-6));
      }
      previous = v;
    }
  }
}
