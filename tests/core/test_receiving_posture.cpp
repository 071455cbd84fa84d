#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/human_body.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/receiving_posture.hpp"
#include "util/test_util.hpp"

using namespace hila;

// Where a receiving posture puts a worker of another body (BoardPlan::worker): the hip and
// shoulder heights are the anthropometric ratios of that body (0.530 H, 0.818 H above the
// stance), the elbow's height against the shoulder comes from a chain of its own (the torso to
// the elbow link), the RULA grand score is that body's model's, and the natural predicate is
// their conjunction. Seeded postures of one and two hands, two bodies, a raised stance.
TEST(ReceivingPosture, APostureCheckOfAWorkersBodyFollowsItsForwardKinematics) {
  const auto cell = test::reference_cell();
  std::mt19937_64 rng(36);
  core::Pose stance = cell->spec().human_stance;
  stance.translation().z() += 0.05;
  int below = 0, above = 0, natural = 0;
  for (const core::HumanBodySpec spec :
       {core::HumanBodySpec{1.50, core::Sex::Female}, core::HumanBodySpec{1.95, core::Sex::Male}}) {
    const core::HumanBody body(*cell, spec);
    const core::HumanDimensions dims = core::human_dimensions(spec);
    for (int trial = 0; trial < 200; ++trial) {
      std::vector<std::pair<std::string, Eigen::VectorXd>> arms;
      const auto& first = body.arms()[static_cast<std::size_t>(trial % 2)];
      arms.emplace_back(first.spec.name, test::random_within(first.chain, rng));
      if (trial % 3 == 0) {
        const auto& second = body.arms()[static_cast<std::size_t>((trial + 1) % 2)];
        arms.emplace_back(second.spec.name, test::random_within(second.chain, rng));
      }
      const Eigen::Vector3d centre = stance * Eigen::Vector3d(0.4, 0.0, 1.0 + 0.25 * (trial % 5));
      const core::PostureCheck c =
          core::check_receiving_posture(*cell, &body, stance, arms, centre, 0.8);
      const double floor_z = stance.translation().z();
      EXPECT_NEAR(c.hip_z, floor_z + dims.hip_height, 1e-9);
      EXPECT_NEAR(c.shoulder_z, floor_z + dims.shoulder_height, 1e-9);
      EXPECT_DOUBLE_EQ(c.part_centre_z, centre.z());
      EXPECT_DOUBLE_EQ(c.trunk_flexion_deg, 0.0);
      bool low = true;
      for (const auto& [side, joints] : arms) {
        const core::KinematicChain to_elbow(body.model(), "torso", side + "_elbow_link");
        low = low && to_elbow.fk(joints.head(4)).translation().z() <
                         dims.shoulder_height - dims.hip_height;
      }
      EXPECT_EQ(c.elbow_below_shoulder, low);
      (low ? below : above) += 1;
      const auto scores = core::receiving_scores(*cell, &body, arms, 0.8);
      EXPECT_EQ(c.rula_grand, scores.rula().grand);
      const bool expected =
          low && c.rula_grand <= 3 && centre.z() >= c.hip_z && centre.z() <= c.shoulder_z;
      EXPECT_EQ(c.natural(3), expected);
      natural += expected ? 1 : 0;
    }
  }
  EXPECT_GT(below, 20);  // both sides of the elbow test are exercised
  EXPECT_GT(above, 20);
  EXPECT_GT(natural, 0);
}

// At a whole configuration: upright, the same scores and check as from the arms' joints; with the
// torso bent forward 30 degrees, the trunk scores its 20-60 degree band (RULA 3, REBA 3), the
// check reads the bend, the hip stays where it is and the shoulder comes down by the torso's
// turn about the hip (forward kinematics of the torso's link); one hand's posture standing for
// two hands carries half the load in RULA and the whole load in REBA.
TEST(ReceivingPosture, AWholeConfigurationIsScoredAsItIs) {
  const auto cell = test::reference_cell();
  const core::HumanBody body(*cell, {1.60, core::Sex::Female});
  std::mt19937_64 rng(37);
  const auto& arm = body.arms().front();
  const core::Pose stance = cell->spec().human_stance;
  const Eigen::Vector3d centre = stance * Eigen::Vector3d(0.4, 0.0, 1.1);
  const int torso =
      body.model()
          .joints()[static_cast<std::size_t>(body.model().joint_index("torso_flexion"))]
          .variable;
  for (int trial = 0; trial < 20; ++trial) {
    const std::vector<std::pair<std::string, Eigen::VectorXd>> arms{
        {arm.spec.name, test::random_within(arm.chain, rng)}};
    Eigen::VectorXd q = body.posture(arms);
    const auto joints = core::receiving_scores(*cell, &body, arms, 3.0);
    const auto whole = core::receiving_scores(*cell, &body, q, {arm.spec.name}, 3.0, false);
    EXPECT_EQ(whole.rula().grand, joints.rula().grand);
    EXPECT_EQ(whole.reba().reba, joints.reba().reba);
    const auto upright = core::check_receiving_posture(*cell, &body, stance, arms, centre, 3.0);
    const auto same =
        core::check_receiving_posture(*cell, &body, stance, q, {arm.spec.name}, centre, 3.0, false);
    EXPECT_EQ(same.shoulder_z, upright.shoulder_z);
    EXPECT_EQ(same.elbow_below_shoulder, upright.elbow_below_shoulder);
    EXPECT_EQ(same.rula_grand, upright.rula_grand);

    q[torso] = core::deg_to_rad(30.0);
    const auto bent = core::receiving_scores(*cell, &body, q, {arm.spec.name}, 3.0, true);
    ASSERT_TRUE(bent.scored);
    EXPECT_TRUE(bent.two_hands);
    EXPECT_EQ(bent.hands[0].rula.trunk, 3);
    EXPECT_EQ(bent.hands[0].reba.trunk, 3);
    EXPECT_DOUBLE_EQ(bent.hands[0].rula_inputs.load_kg, 1.5);
    EXPECT_DOUBLE_EQ(bent.hands[0].reba_inputs.load_kg, 3.0);
    const auto check =
        core::check_receiving_posture(*cell, &body, stance, q, {arm.spec.name}, centre, 3.0, true);
    EXPECT_NEAR(check.trunk_flexion_deg, 30.0, 1e-9);
    EXPECT_EQ(check.rula_grand, bent.rula().grand);
    EXPECT_NEAR(check.hip_z, upright.hip_z, 1e-12);
    // The shoulder in the torso's frame, turned 30 degrees forward about the hip (the torso
    // link's y axis; forward flexion takes +x down).
    const Eigen::Vector3d s = arm.chain.first_joint_position();
    const double turned =
        s.z() * std::cos(core::deg_to_rad(30.0)) - s.x() * std::sin(core::deg_to_rad(30.0));
    EXPECT_NEAR(check.shoulder_z, check.hip_z + turned, 1e-9);
  }
  test::expect_input_error(
      [&] {
        core::receiving_scores(*cell, &body, Eigen::VectorXd::Zero(3), {arm.spec.name}, 1.0, false);
      },
      {"human configuration", "finite values", "got 3"});
  test::expect_input_error(
      [&] {
        core::check_receiving_posture(*cell, &body, stance, body.neutral(), {"middle"}, centre, 1.0,
                                      false);
      },
      {"'middle'", "left"});
}

// core::reach_hand, how the planner reaches a receiving hand: for hands placed by forward
// kinematics of the whole human model (random arm joints within the limits, the cell's human and
// a 1.50 m woman standing at a raised stance), the posture returned puts the hand link there by
// the model's own forward kinematics; seeded with the joints that placed it, it returns them (a
// stored posture is kept). A hand beyond the stretched arm and an arm the body has not are
// unreachable.
TEST(ReceivingPosture, AReachedHandIsWhereItWasAsked) {
  const auto cell = test::reference_cell();
  const core::HumanBody woman(*cell, {1.50, core::Sex::Female});
  core::Pose stance = cell->spec().human_stance;
  stance.translation() += Eigen::Vector3d(0.1, -0.05, 0.03);
  std::mt19937_64 rng(39);
  int reached = 0;
  for (const core::HumanBody* body : {static_cast<const core::HumanBody*>(nullptr), &woman}) {
    const core::RobotModel& human = body != nullptr ? body->model() : cell->human();
    const auto& arms = body != nullptr ? body->arms() : cell->human_arms();
    for (int trial = 0; trial < 40; ++trial) {
      const auto& arm = arms[static_cast<std::size_t>(trial % 2)];
      const Eigen::VectorXd placed = test::random_within(arm.chain, rng);
      const std::vector<std::pair<std::string, Eigen::VectorXd>> held{{arm.spec.name, placed}};
      auto hand_at = [&](const Eigen::VectorXd& joints) {
        const Eigen::VectorXd q = body != nullptr
                                      ? body->posture({{arm.spec.name, joints}})
                                      : core::human_posture(*cell, {{arm.spec.name, joints}});
        std::vector<core::Pose> links;
        human.link_poses(q, links);
        return core::Pose(stance *
                          links[static_cast<std::size_t>(human.link_index(arm.spec.tip_link))]);
      };
      const core::Pose hand = hand_at(placed);
      const core::ComfortResult r =
          core::reach_hand(*cell, body, stance, arm.spec.name, hand, Eigen::VectorXd());
      if (r.reachable) {
        ++reached;
        const core::Pose got = hand_at(r.joints);
        EXPECT_LT((got.translation() - hand.translation()).norm(), 1e-6);
        EXPECT_LT(Eigen::AngleAxisd(got.linear().transpose() * hand.linear()).angle(), 1e-6);
      }
      const core::ComfortResult kept =
          core::reach_hand(*cell, body, stance, arm.spec.name, hand, placed);
      ASSERT_TRUE(kept.reachable);
      EXPECT_LT((kept.joints - placed).cwiseAbs().maxCoeff(), 1e-6);
      core::Pose far = hand;
      far.translation() += 2.0 * stance.linear().col(0);
      EXPECT_FALSE(core::reach_hand(*cell, body, stance, arm.spec.name, far, placed).reachable);
      EXPECT_FALSE(core::reach_hand(*cell, body, stance, "middle", hand, placed).reachable);
    }
  }
  EXPECT_GT(reached, 40);  // most random hands are reached from zero
}
