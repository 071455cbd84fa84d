#include <gtest/gtest.h>

#include "hila/core/human_model.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/robot_model.hpp"
#include "util/test_util.hpp"

using namespace hila;

TEST(HumanModel, DimensionsFollowTheStatureRatios) {
  const auto d = core::human_dimensions({1.722, core::Sex::Male});
  EXPECT_NEAR(d.upper_arm, 0.186 * 1.722, 1e-12);
  EXPECT_NEAR(d.forearm, 0.146 * 1.722, 1e-12);
  EXPECT_NEAR(d.hand, 0.108 * 1.722, 1e-12);
  EXPECT_NEAR(d.shoulder_height, 0.818 * 1.722, 1e-12);
  const auto f = core::human_dimensions({1.595, core::Sex::Female});
  EXPECT_LT(f.shoulder_half_width / f.stature, d.shoulder_half_width / d.stature);
}

TEST(HumanModel, GeneratedUrdfHasTwoSevenDofArmsWithTheRightLengths) {
  for (const double stature : {1.50, 1.722, 1.90}) {
    const core::HumanBodySpec spec{stature, core::Sex::Male};
    const auto d = core::human_dimensions(spec);
    const auto model = core::RobotModel::load_urdf_string(core::generate_human_urdf(spec), "human");
    EXPECT_EQ(model.num_variables(), 1 + 2 * 7);  // torso flexion + two arms
    for (const std::string side : {"left", "right"}) {
      const core::KinematicChain chain(model, core::kHumanArmBase, core::human_grasp_link(side));
      ASSERT_EQ(chain.dof(), 7);
      // Arm hanging straight down at zero: grasp point below the shoulder by the arm length.
      const core::Pose grasp = chain.fk(Eigen::VectorXd::Zero(7));
      const double torso_height = d.shoulder_height - d.hip_height;
      EXPECT_NEAR(grasp.translation().z(), torso_height - d.upper_arm - d.forearm - 0.4 * d.hand,
                  1e-9);
      EXPECT_NEAR(grasp.translation().y(), (side == "left" ? 1 : -1) * d.shoulder_half_width, 1e-9);
      // Shoulder flexion of 90 degrees points the straight arm forward (+x).
      Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
      q[0] = core::deg_to_rad(90);
      EXPECT_GT(chain.fk(q).translation().x(), 0.9 * (d.upper_arm + d.forearm));
      // Abduction of 90 degrees points it sideways, away from the body.
      q.setZero();
      q[1] = core::deg_to_rad(90);
      EXPECT_GT((side == "left" ? 1 : -1) * chain.fk(q).translation().y(),
                d.shoulder_half_width + 0.9 * (d.upper_arm + d.forearm));
      // Elbow flexion brings the hand forward, never backward.
      q.setZero();
      q[3] = core::deg_to_rad(90);
      EXPECT_GT(chain.fk(q).translation().x(), 0.9 * d.forearm);
    }
  }
}

TEST(HumanModel, JointLimitsComeFromTheRangeOfMotionTable) {
  const auto model = core::RobotModel::load_urdf_string(core::generate_human_urdf({}), "human");
  const auto& elbow = model.joints()[model.joint_index("right_elbow_flexion")];
  EXPECT_NEAR(elbow.lower, 0.0, 1e-6);
  EXPECT_NEAR(elbow.upper, core::deg_to_rad(145), 1e-6);
  const auto& flexion = model.joints()[model.joint_index("left_shoulder_flexion")];
  EXPECT_NEAR(flexion.lower, core::deg_to_rad(-50), 1e-6);
  EXPECT_NEAR(flexion.upper, core::deg_to_rad(180), 1e-6);
}

TEST(HumanModel, CommittedDefaultHumanMatchesTheGenerator) {
  EXPECT_EQ(test::read_file(test::data_path("cell/human.urdf")), core::generate_human_urdf({}))
      << "regenerate with: hila human -o meshes/cell/human.urdf";
}

TEST(HumanModel, RejectsImplausibleStature) {
  test::expect_input_error(
      [] {
        core::human_dimensions({1722.0, core::Sex::Male});
      },
      {"stature", "millimetres"});
  test::expect_input_error(
      [] {
        core::human_dimensions({0.0, core::Sex::Female});
      },
      {"stature", "[1.30, 2.20]"});
  test::expect_input_error(
      [] {
        core::human_dimensions({std::nan(""), core::Sex::Male});
      },
      {"stature", "nan"});
}
