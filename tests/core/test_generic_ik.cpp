#include <gtest/gtest.h>

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
