#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "hila/core/generic_ik.hpp"
#include "util/test_util.hpp"

using namespace hila;

TEST(GenericIk, PoseErrorIsZeroForEqualPosesAndSignedOtherwise) {
  const core::Pose a = core::make_pose({0.1, 0.2, 0.3}, {0.1, 0.2, 0.3});
  EXPECT_LT(core::pose_error(a, a).norm(), 1e-15);
  const core::Pose b = a * core::make_pose({0, 0, 0}, {0, 0, 0.2});
  const auto e = core::pose_error(b, a);
  EXPECT_NEAR(e.tail<3>().norm(), 0.2, 1e-12);
}

TEST(GenericIk, HumanArmRoundTrip) {
  const auto cell = test::reference_cell();
  std::mt19937_64 rng(8);
  int successes = 0, trials = 0;
  for (const core::HumanArm& arm : cell->human_arms()) {
    for (int i = 0; i < 150; ++i) {
      const Eigen::VectorXd q = core::random_configuration(arm.chain, rng);
      const core::Pose target = arm.chain.fk(q);
      const Eigen::VectorXd seed = core::random_configuration(arm.chain, rng);
      const auto result = core::solve_ik(arm.chain, target, seed, rng);
      ++trials;
      if (!result.success) continue;
      ++successes;
      EXPECT_TRUE(arm.chain.within_limits(result.q, 1e-12));
      const core::Pose reached = arm.chain.fk(result.q);
      EXPECT_LT((reached.translation() - target.translation()).norm(), 1e-9);
      EXPECT_LT(core::rotation_distance(reached.linear(), target.linear()), 1e-9);
    }
  }
  // Reachable by construction: with 20 restarts the solver must find nearly all.
  EXPECT_GE(successes, trials * 97 / 100);
}

TEST(GenericIk, UrArmAgreesWithForwardKinematics) {
  const auto& arm = test::reference_cell()->arm("right");
  std::mt19937_64 rng(9);
  for (int i = 0; i < 100; ++i) {
    const core::Pose target = arm.chain.fk(core::random_configuration(arm.chain, rng));
    const auto result = core::solve_ik(arm.chain, target, Eigen::VectorXd::Zero(6), rng);
    ASSERT_TRUE(result.success);
    EXPECT_LT((arm.chain.fk(result.q).translation() - target.translation()).norm(), 1e-9);
  }
}

TEST(GenericIk, UnreachableTargetFailsWithItsResidual) {
  const auto& arm = test::reference_cell()->human_arms()[0];
  std::mt19937_64 rng(10);
  core::GenericIkSettings settings;
  settings.max_attempts = 3;
  const auto result = core::solve_ik(arm.chain, core::make_pose({3.0, 0, 0}),
                                     Eigen::VectorXd::Zero(7), rng, settings);
  EXPECT_FALSE(result.success);
  EXPECT_GT(result.position_error, 1.0);
  EXPECT_EQ(result.attempts, 3);
}

TEST(GenericIk, PositionOnlyIgnoresOrientation) {
  const auto& arm = test::reference_cell()->human_arms()[1];
  std::mt19937_64 rng(12);
  const core::Pose reachable = arm.chain.fk(core::random_configuration(arm.chain, rng));
  core::Pose target = reachable;
  target.linear() = Eigen::Matrix3d::Identity();  // orientation generally unreachable
  core::GenericIkSettings settings;
  settings.position_only = true;
  const auto result = core::solve_ik(arm.chain, target, Eigen::VectorXd::Zero(7), rng, settings);
  ASSERT_TRUE(result.success);
  EXPECT_LT((arm.chain.fk(result.q).translation() - target.translation()).norm(), 1e-9);
}

// Targets a human arm reaches with a joint at its limit (a wrist or an elbow at its end stop, as
// receiving postures often are), one attempt each from a random seed: with the joints at a limit
// held out of the step, the solver ends on the limit instead of crawling along it, so it needs
// fewer iterations and solves at least as many; each solution checked by forward kinematics.
TEST(GenericIk, JointsHeldAtTheirLimitsConvergeInFewerIterations) {
  const auto cell = test::reference_cell();
  core::GenericIkSettings clipped;
  clipped.max_attempts = 1;
  core::GenericIkSettings held = clipped;
  held.hold_joints_at_limits = true;
  int solved_clipped = 0, solved_held = 0, trials = 0;
  long iterations_clipped = 0, iterations_held = 0;
  std::mt19937_64 draw(11);
  for (const core::HumanArm& arm : cell->human_arms()) {
    for (int i = 0; i < 100; ++i) {
      Eigen::VectorXd q = core::random_configuration(arm.chain, draw);
      const auto j = static_cast<Eigen::Index>(i % arm.chain.dof());
      q[j] = i % 2 == 0 ? arm.chain.lower_limits()[j] : arm.chain.upper_limits()[j];
      const core::Pose target = arm.chain.fk(q);
      const Eigen::VectorXd seed = core::random_configuration(arm.chain, draw);
      std::mt19937_64 rng_a(static_cast<std::uint64_t>(i)), rng_b(static_cast<std::uint64_t>(i));
      const auto a = core::solve_ik(arm.chain, target, seed, rng_a, clipped);
      const auto b = core::solve_ik(arm.chain, target, seed, rng_b, held);
      ++trials;
      iterations_clipped += a.iterations;
      iterations_held += b.iterations;
      solved_clipped += a.success ? 1 : 0;
      if (!b.success) continue;
      ++solved_held;
      EXPECT_TRUE(arm.chain.within_limits(b.q, 1e-12));
      const core::Pose reached = arm.chain.fk(b.q);
      EXPECT_LT((reached.translation() - target.translation()).norm(), 1e-9);
      EXPECT_LT(core::rotation_distance(reached.linear(), target.linear()), 1e-9);
    }
  }
  std::printf("%d targets with a joint at a limit, one attempt each: clipped steps solve %d in %ld "
              "iterations, held joints %d in %ld\n",
              trials, solved_clipped, iterations_clipped, solved_held, iterations_held);
  EXPECT_GE(solved_held, solved_clipped);
  EXPECT_LT(iterations_held, iterations_clipped * 3 / 4);
}
