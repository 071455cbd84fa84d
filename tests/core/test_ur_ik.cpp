#include <gtest/gtest.h>

#include <random>

#include "hila/core/generic_ik.hpp"
#include "hila/core/ur_ik.hpp"
#include "util/test_util.hpp"

using namespace hila;
using core::kPi;
using core::Vector6d;

namespace {

const core::Arm& arm(const std::string& name) {
  return test::reference_cell()->arm(name);
}

double pose_gap(const core::Pose& a, const core::Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

// Same configuration up to multiples of 2*pi per joint.
bool same_modulo_2pi(const Vector6d& a, const Vector6d& b, double tol) {
  for (int i = 0; i < 6; ++i) {
    const double d = std::remainder(a[i] - b[i], 2 * kPi);
    if (std::abs(d) > tol) return false;
  }
  return true;
}

Vector6d random_q(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-kPi, kPi);
  Vector6d q;
  for (int i = 0; i < 6; ++i) q[i] = u(rng);
  return q;
}

struct RoundTripStats {
  int poses = 0;
  int original_found = 0;
  int solutions = 0;
  double worst_gap = 0.0;
};

void round_trip(const core::Arm& a, const Vector6d& q, const Vector6d& seed, RoundTripStats& stats,
                double found_tolerance) {
  const core::Pose target = a.chain.fk(q);
  core::UrIkSolutions sols;
  a.ur_ik->solve(target, seed, sols);
  ++stats.poses;
  stats.solutions += sols.count;
  bool found = false;
  for (int k = 0; k < sols.count; ++k) {
    const double gap = pose_gap(a.chain.fk(sols.q[k]), target);
    stats.worst_gap = std::max(stats.worst_gap, gap);
    EXPECT_TRUE(a.chain.within_limits(sols.q[k]));
    if (k > 0) {
      EXPECT_LE((sols.q[k - 1] - seed).squaredNorm(), (sols.q[k] - seed).squaredNorm() + 1e-12);
    }
    found = found || same_modulo_2pi(sols.q[k], q, found_tolerance);
  }
  if (found) ++stats.original_found;
}

}  // namespace

TEST(UrIk, DhModelMatchesTheUrdfChain) {
  // UrIk's constructor throws on a mismatch; check the tool offset is the 0.20 m TCP.
  const auto& ik = *arm("left").ur_ik;
  EXPECT_TRUE(ik.tool().isApprox(core::make_pose({0, 0, 0.20}), 1e-12));
}

TEST(UrIk, RoundTripOnOneHundredThousandRandomPoses) {
  std::mt19937_64 rng(2024);
  RoundTripStats stats;
  for (int i = 0; i < 100000; ++i) {
    const core::Arm& a = arm(i % 2 ? "left" : "right");
    round_trip(a, random_q(rng), random_q(rng), stats, 1e-6);
  }
  EXPECT_LT(stats.worst_gap, 1e-9);
  // Random configurations are almost never singular: the generating configuration must be
  // among the solutions essentially always.
  EXPECT_GE(stats.original_found, stats.poses - 5);
  // Up to 8 per pose; fewer where the other shoulder or wrist branch cannot reach the wrist
  // centre. On this seed set the mean is about 6.8.
  EXPECT_GE(stats.solutions, 6 * stats.poses);
  RecordProperty("worst_fk_gap", std::to_string(stats.worst_gap));
}

TEST(UrIk, RoundTripNearSingularities) {
  std::mt19937_64 rng(99);
  RoundTripStats stats;
  for (int i = 0; i < 20000; ++i) {
    Vector6d q = random_q(rng);
    const double eps = std::pow(10.0, -std::uniform_int_distribution<int>(3, 9)(rng));
    switch (i % 4) {
      case 0:
        q[4] = eps;
        break;  // wrist singularity (q5 ~ 0)
      case 1:
        q[4] = kPi - eps;
        break;  // wrist singularity (q5 ~ pi)
      case 2:
        q[2] = eps;
        break;  // elbow stretched (q3 ~ 0)
      case 3:
        q[1] = -kPi / 2;
        q[2] = eps;
        q[3] = -kPi / 2;
        break;  // near upright
    }
    round_trip(arm("left"), q, random_q(rng), stats, 1e-3);
  }
  EXPECT_LT(stats.worst_gap, 1e-9);
  EXPECT_GT(stats.solutions, 0);
}

TEST(UrIk, ExactWristSingularityStillReproducesThePose) {
  Vector6d q;
  q << 0.3, -1.0, 1.2, -0.4, 0.0, 0.7;
  const core::Pose target = arm("left").chain.fk(q);
  core::UrIkSolutions sols;
  ASSERT_GT(arm("left").ur_ik->solve(target, q, sols), 0);
  for (int k = 0; k < sols.count; ++k) {
    EXPECT_LT(pose_gap(arm("left").chain.fk(sols.q[k]), target), 1e-9);
  }
}

TEST(UrIk, UnreachablePoseHasNoSolution) {
  core::UrIkSolutions sols;
  EXPECT_EQ(arm("left").ur_ik->solve(core::make_pose({2.0, 0.0, 0.0}), Vector6d::Zero(), sols), 0);
  EXPECT_EQ(sols.count, 0);
}

TEST(UrIk, SolutionsAreWrappedNearTheSeed) {
  std::mt19937_64 rng(5);
  const Vector6d q = random_q(rng);
  Vector6d seed = q;
  seed[0] += q[0] > 0 ? -2 * kPi : 2 * kPi;  // the same joint-1 angle one turn away, in limits
  core::UrIkSolutions sols;
  ASSERT_GT(arm("left").ur_ik->solve(arm("left").chain.fk(q), seed, sols), 0);
  EXPECT_LT((sols.q[0] - seed).norm(), 1e-7);
}

TEST(UrIk, MissesNoSolutionFoundByGenericIkFromManyRestarts) {
  // Every configuration the numerical solver reaches from random restarts must be one of the
  // analytic solutions (modulo 2*pi): the closed form misses no branch.
  std::mt19937_64 rng(77);
  core::GenericIkSettings settings;
  settings.max_attempts = 1;
  int generic_successes = 0;
  int matched = 0;
  const core::Arm& a = arm("left");
  for (int pose = 0; pose < 150; ++pose) {
    const core::Pose target = a.chain.fk(random_q(rng));
    core::UrIkSolutions sols;
    a.ur_ik->solve(target, Vector6d::Zero(), sols);
    for (int restart = 0; restart < 24; ++restart) {
      const auto result = core::solve_ik(a.chain, target, random_q(rng), rng, settings);
      if (!result.success) continue;
      ++generic_successes;
      bool found = false;
      for (int k = 0; k < sols.count && !found; ++k)
        found = same_modulo_2pi(sols.q[k], result.q, 1e-6);
      if (found) {
        ++matched;
      } else {
        ADD_FAILURE() << "generic IK found a solution the analytic IK missed at pose " << pose;
      }
    }
  }
  EXPECT_GT(generic_successes, 1000);
  EXPECT_EQ(matched, generic_successes);
}
