#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hila/core/time_parameterization.hpp"

using namespace hila;

namespace {

Eigen::VectorXd limits(double v) {
  return Eigen::VectorXd::Constant(6, v);
}

// `n` random waypoints in [-1.5, 1.5]^6, the last repeated (a repeated waypoint is dropped).
std::vector<Eigen::VectorXd> random_path(std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  std::vector<Eigen::VectorXd> path;
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd q(6);
    for (int j = 0; j < 6; ++j) q[j] = u(rng);
    path.push_back(q);
  }
  path.push_back(path.back());
  return path;
}

}  // namespace

TEST(TimeParameterization, OneLongSegmentTakesTheTrapezoidsClosedFormTime) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6), b = a;
  b[1] = 2.0;  // joint 2 moves 2 rad; v 1 rad/s, a 2 rad/s^2: 2/1 + 1/2 = 2.5 s
  b[3] = 0.5;
  const auto timed = core::time_parameterize({a, b}, limits(1.0), limits(2.0));
  EXPECT_NEAR(timed.time.back(), 2.5, 1e-12);
  EXPECT_TRUE(timed.q.back().isApprox(b, 0.0));
  // Short: triangular, 2 sqrt(d / a) = 2 sqrt(0.1 / 2).
  b = a;
  b[0] = 0.1;
  EXPECT_NEAR(core::time_parameterize({a, b}, limits(1.0), limits(2.0)).time.back(),
              2.0 * std::sqrt(0.05), 1e-12);
  // Half the scale: twice as long for a triangular profile's sqrt(1/a)... exactly sqrt(2) times.
  EXPECT_NEAR(core::time_parameterize({a, b}, limits(1.0), limits(2.0), 0.5).time.back(),
              2.0 * std::sqrt(0.1), 1e-12);
}

TEST(TimeParameterization, RandomPathsKeepEveryLimitBetweenSamples) {
  std::mt19937_64 rng(11);
  Eigen::VectorXd vmax(6), amax(6);
  vmax << 3.14, 3.14, 3.14, 6.28, 6.28, 6.28;
  amax << 2.97, 2.97, 2.97, 5.93, 5.93, 5.93;
  for (int trial = 0; trial < 50; ++trial) {
    const std::vector<Eigen::VectorXd> path = random_path(rng, 5);
    const double scale = 0.5;
    const auto timed = core::time_parameterize(path, vmax, amax, scale);
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

namespace {

// Every velocity on each piece and every acceleration between consecutive pieces, measured as
// the validator measures them, plus from rest into the first piece and out of the last to rest;
// the largest ratio to its scaled limit.
double worst_rate_ratio(const core::TimedPath& timed, const Eigen::VectorXd& vmax,
                        const Eigen::VectorXd& amax) {
  double worst = 0.0;
  const std::size_t n = timed.q.size();
  std::vector<Eigen::VectorXd> v;
  std::vector<double> dt;
  for (std::size_t i = 1; i < n; ++i) {
    dt.push_back(timed.time[i] - timed.time[i - 1]);
    v.push_back((timed.q[i] - timed.q[i - 1]) / dt.back());
    worst = std::max(worst, (v.back().array().abs() / vmax.array()).maxCoeff());
  }
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(vmax.size());
  for (std::size_t i = 0; i <= v.size(); ++i) {
    const Eigen::VectorXd& before = i == 0 ? rest : v[i - 1];
    const Eigen::VectorXd& after = i == v.size() ? rest : v[i];
    const double mean = 0.5 * ((i == 0 ? 0.0 : dt[i - 1]) + (i == v.size() ? 0.0 : dt[i]));
    worst = std::max(worst, ((after - before).array().abs() / (amax.array() * mean)).maxCoeff());
  }
  return worst;
}

}  // namespace

// The closed form by hand (the trapezoid of the slowest joint, segment by segment) against the
// sampled timing's last time stamp.
TEST(RestToRestDuration, EqualsTheSampledTimingsDurationAndTheTrapezoidsByHand) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6), b = a, c = a;
  b[1] = 2.0;  // 2/1 + 1/2 = 2.5 s (trapezoid)
  c = b;
  c[0] = 0.1;  // then 0.1 rad: triangular, 2 sqrt(0.1 / 2)
  EXPECT_NEAR(core::rest_to_rest_duration({a, b, c}, limits(1.0), limits(2.0)),
              2.5 + 2.0 * std::sqrt(0.05), 1e-12);
  EXPECT_EQ(core::rest_to_rest_duration({a}, limits(1.0), limits(2.0)), 0.0);
  EXPECT_EQ(core::rest_to_rest_duration({a, a}, limits(1.0), limits(2.0)), 0.0);
  std::mt19937_64 rng(5);
  Eigen::VectorXd vmax(6), amax(6);
  vmax << 3.14, 3.14, 3.14, 6.28, 6.28, 6.28;
  amax << 2.97, 2.97, 2.97, 5.93, 5.93, 5.93;
  for (int trial = 0; trial < 20; ++trial) {
    const auto path = random_path(rng, 4);
    for (const double scale : {1.0, 0.5, 0.2}) {
      EXPECT_NEAR(core::rest_to_rest_duration(path, vmax, amax, scale),
                  core::time_parameterize(path, vmax, amax, scale).time.back(), 1e-9);
    }
  }
}

TEST(TimeParameterizationThrough, OneStraightSegmentMatchesTheTrapezoid) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6), b = a;
  b << 2.0, 1.5, -1.0, 0.5, 0.3, 0.1;
  const auto rest = core::time_parameterize({a, b}, limits(3.14), limits(2.97), 0.5);
  const auto through =
      core::time_parameterize_through({a, b}, limits(3.14), limits(2.97), 0.5, 0.05);
  // Pieces of 0.05 rad at constant speed approximate the continuous ramp (v^2 = 2 a x).
  EXPECT_NEAR(through.time.back(), rest.time.back(), 0.02 * rest.time.back());
  EXPECT_TRUE(through.q.back().isApprox(b, 0.0));
  EXPECT_LE(worst_rate_ratio(through, 0.5 * limits(3.14), 0.5 * limits(2.97)), 1.0 + 1e-9);
}

TEST(TimeParameterizationThrough, CollinearWaypointsAreNotStoppedAt) {
  // Ten waypoints on one line: rest-to-rest stops nine times, through them it does not.
  std::vector<Eigen::VectorXd> path;
  for (int i = 0; i <= 9; ++i) path.push_back(Eigen::VectorXd::Constant(6, 0.3 * i));
  const auto rest = core::time_parameterize(path, limits(3.14), limits(2.97));
  const auto through = core::time_parameterize_through(path, limits(3.14), limits(2.97));
  const auto single =
      core::time_parameterize({path.front(), path.back()}, limits(3.14), limits(2.97));
  EXPECT_LT(through.time.back(), 0.5 * rest.time.back());
  EXPECT_NEAR(through.time.back(), single.time.back(), 0.02 * single.time.back());
}

TEST(TimeParameterizationThrough, ACircularArcRunsAtItsCentripetalLimit) {
  // q0 = R cos s, q1 = R sin s: each joint's acceleration reaches v^2 / R, so the cruise speed
  // is sqrt(amax R); the arc's time is at least its length over that and, with the ramps, not
  // much more.
  const double radius = 1.0;
  std::vector<Eigen::VectorXd> path;
  for (int i = 0; i <= 120; ++i) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
    q[0] = radius * std::cos(0.05 * i);
    q[1] = radius * std::sin(0.05 * i);
    path.push_back(q);
  }
  const double amax = 1.5;
  const auto timed = core::time_parameterize_through(path, limits(10.0), limits(amax));
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  const double cruise = length / std::sqrt(amax * radius);
  EXPECT_GT(timed.time.back(), 0.95 * cruise);
  EXPECT_LT(timed.time.back(), 1.35 * cruise);
  EXPECT_LE(worst_rate_ratio(timed, limits(10.0), limits(amax)), 1.0 + 1e-9);
}

TEST(TimeParameterizationThrough, RandomPathsKeepEveryLimitFromRestToRest) {
  std::mt19937_64 rng(12);
  Eigen::VectorXd vmax(6), amax(6);
  vmax << 3.14, 3.14, 3.14, 6.28, 6.28, 6.28;
  amax << 2.97, 2.97, 2.97, 5.93, 5.93, 5.93;
  for (int trial = 0; trial < 50; ++trial) {
    const std::vector<Eigen::VectorXd> path = random_path(rng, 6);
    const auto timed = core::time_parameterize_through(path, vmax, amax, 0.5, 0.05);
    ASSERT_EQ(timed.q.size(), timed.time.size());
    EXPECT_TRUE(timed.q.front().isApprox(path.front(), 0.0));
    EXPECT_TRUE(timed.q.back().isApprox(path.back(), 0.0));
    for (std::size_t i = 1; i < timed.q.size(); ++i) {
      ASSERT_GT(timed.time[i], timed.time[i - 1]);
      EXPECT_LE((timed.q[i] - timed.q[i - 1]).norm(), 0.05 + 1e-12);
    }
    // Every waypoint is on the timed path (it only adds points between them).
    std::size_t found = 0;
    for (const auto& q : timed.q) {
      if (found < path.size() && q.isApprox(path[found], 1e-12)) ++found;
    }
    EXPECT_GE(found, path.size() - 1);
    EXPECT_LE(worst_rate_ratio(timed, 0.5 * vmax, 0.5 * amax), 1.0 + 1e-9) << "trial " << trial;
    // Sharp corners need near stops, but never a slower run than stopping at every waypoint.
    EXPECT_LT(timed.time.back(),
              1.05 * core::time_parameterize(path, vmax, amax, 0.5).time.back());
  }
}
