#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hila/core/comfort.hpp"
#include "hila/core/human_body.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

Eigen::VectorXd random_joints(std::mt19937_64& rng, const core::KinematicChain& chain) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::VectorXd q(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    q[i] = chain.lower_limits()[i] + u(rng) * (chain.upper_limits()[i] - chain.lower_limits()[i]);
  }
  return q;
}

}  // namespace

// The scaled lookup: the body's hand at joints q, moved into the cell arm's frame, is where the
// cell human's hand is at the same joints (forward kinematics of both chains), so the cell's
// comfort map reads the body's Q there. Checked for the smallest and the tallest tested bodies.
TEST(HumanBody, TheScaledLookupIsTheCellHumansHandAtTheSameJoints) {
  const auto cell = test::reference_cell();
  std::mt19937_64 rng(35);
  for (const core::HumanBodySpec spec :
       {core::HumanBodySpec{core::kFemaleStatureP5, core::Sex::Female},
        core::HumanBodySpec{core::kTallStature, core::Sex::Male}}) {
    const core::HumanBody body(*cell, spec);
    ASSERT_EQ(body.arms().size(), cell->human_arms().size());
    for (std::size_t a = 0; a < body.arms().size(); ++a) {
      const auto& mine = body.arms()[a].chain;
      const auto& theirs = cell->human_arms()[a].chain;
      // Every segment scales with stature: the reach ratio is the statures'.
      EXPECT_NEAR(body.scale(static_cast<int>(a)), core::kDefaultStature / spec.stature, 1e-9);
      for (int i = 0; i < 200; ++i) {
        const Eigen::VectorXd q = random_joints(rng, theirs);
        const core::Pose mapped = body.to_cell_arm(static_cast<int>(a), mine.fk(q));
        const core::Pose cell_hand = theirs.fk(q);
        EXPECT_LT((mapped.translation() - cell_hand.translation()).norm(), 1e-9);
        EXPECT_TRUE(mapped.linear().isApprox(cell_hand.linear(), 1e-9));
      }
    }
    EXPECT_FALSE(body.same_as_cell()) << body.label();
  }
  // The cell's own human (hila human --stature 1.722 --sex male) is recognised as such.
  EXPECT_TRUE(core::HumanBody(*cell, core::HumanBodySpec{}).same_as_cell());
}

// The posture puts the arm's joints into the whole configuration: the hand's link pose by the
// model's forward pass equals the chain's forward kinematics; the rest stays neutral.
TEST(HumanBody, APostureHoldsTheArmJointsAndTheRestNeutral) {
  const auto cell = test::reference_cell();
  const core::HumanBody body(*cell, {1.60, core::Sex::Female});
  std::mt19937_64 rng(7);
  const auto& arm = body.arms().front();
  const Eigen::VectorXd joints = random_joints(rng, arm.chain);
  const Eigen::VectorXd q = body.posture({{arm.spec.name, joints}});
  std::vector<core::Pose> links;
  body.model().link_poses(q, links);
  const core::Pose base =
      links[static_cast<std::size_t>(body.model().link_index(arm.spec.base_link))];
  const core::Pose tip =
      links[static_cast<std::size_t>(body.model().link_index(arm.spec.tip_link))];
  EXPECT_TRUE((base.inverse() * tip).isApprox(arm.chain.fk(joints), 1e-9));
  EXPECT_TRUE(base.isApprox(body.base_in_stance(0), 1e-12));
  const auto& other = body.arms().back().chain.model_variables();
  for (const int v : other) EXPECT_DOUBLE_EQ(q[v], body.neutral()[v]);
  test::expect_input_error([&] { body.posture({{"middle", joints}}); }, {"'middle'", "left"});
  test::expect_input_error(
      [&] {
        body.posture({{arm.spec.name, Eigen::VectorXd::Zero(3)}});
      },
      {"joints", "7 finite values"});
}
