#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <random>

#include "hila/core/generic_ik.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/robot_model.hpp"
#include "hila/core/comfort.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {
core::KinematicChain human_arm(double stature, const std::string& side = "right") {
  // A chain copies what it needs from the model.
  const auto model = core::RobotModel::load_urdf_string(
      core::generate_human_urdf({stature, core::Sex::Male}), "human");
  return core::KinematicChain(model, core::kHumanArmBase, core::human_grasp_link(side));
}
}  // namespace

TEST(Comfort, IndexIsTheRatioOfExtremeSingularValuesOfTheScaledJacobian) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < 100; ++i) {
    core::Jacobian j(6, 7);
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 7; ++c) j(r, c) = n(rng);
    }
    const double length = 0.3 + 0.5 * std::abs(n(rng));
    Eigen::MatrixXd scaled = j;
    scaled.topRows(3) /= length;
    const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(scaled).singularValues();
    EXPECT_NEAR(core::comfort_index(j, length), s.minCoeff() / s.maxCoeff(), 1e-12);
  }
  // A rank-deficient Jacobian (a zero column pair making rank 5) has Q = 0.
  core::Jacobian deficient = core::Jacobian::Zero(6, 7);
  for (int c = 0; c < 5; ++c) deficient(c, c) = 1.0;
  EXPECT_NEAR(core::comfort_index(deficient, 0.5), 0.0, 1e-15);
}

TEST(Comfort, DimensionlessTheSameForEveryStatureAtTheSamePosture) {
  // The paper picks sigma_min / sigma_max because it does not depend on the arm's scale.
  const auto small = human_arm(1.50);
  const auto large = human_arm(1.90);
  std::mt19937_64 rng(4);
  for (int i = 0; i < 200; ++i) {
    const Eigen::VectorXd q = core::random_configuration(small, rng);
    EXPECT_NEAR(core::comfort_index(small.jacobian(q), core::characteristic_length(small)),
                core::comfort_index(large.jacobian(q), core::characteristic_length(large)),
                1e-9);
  }
  EXPECT_NEAR(core::characteristic_length(large) / core::characteristic_length(small),
              1.90 / 1.50, 1e-9);
}

TEST(Comfort, CharacteristicLengthIsTheStretchedArm) {
  const auto arm = human_arm(1.722);
  const auto d = core::human_dimensions({1.722, core::Sex::Male});
  EXPECT_NEAR(core::characteristic_length(arm), d.upper_arm + d.forearm + 0.4 * d.hand, 1e-9);
}

TEST(Comfort, BestComfortIsAtLeastThatOfTheGeneratingPostureAndReachesThePose) {
  const auto arm = human_arm(1.722);
  const double length = core::characteristic_length(arm);
  std::mt19937_64 rng(5);
  for (int i = 0; i < 40; ++i) {
    const Eigen::VectorXd q = core::random_configuration(arm, rng);
    const core::Pose hand = arm.fk(q);
    const auto best = core::best_comfort(arm, hand, q);
    ASSERT_TRUE(best.reachable);
    EXPECT_GE(best.quality, core::comfort_index(arm.jacobian(q), length) - 1e-12);
    EXPECT_LE(best.quality, 1.0);
    EXPECT_LT((arm.fk(best.joints).translation() - hand.translation()).norm(), 1e-8);
    EXPECT_TRUE(arm.within_limits(best.joints, 1e-12));
  }
}

TEST(Comfort, UnreachablePoseHasZeroComfort) {
  const auto arm = human_arm(1.722);
  const auto best =
      core::best_comfort(arm, core::make_pose({2.0, 0, 0}), Eigen::VectorXd::Zero(7));
  EXPECT_FALSE(best.reachable);
  EXPECT_EQ(best.quality, 0.0);
}

TEST(Comfort, StretchedArmIsLessComfortableThanABentOne) {
  // A stretched arm is at the elbow singularity; a bent elbow in front of the body is not.
  const auto arm = human_arm(1.722);
  const double length = core::characteristic_length(arm);
  Eigen::VectorXd stretched = Eigen::VectorXd::Zero(7);
  stretched[0] = core::deg_to_rad(90);  // arm straight forward
  Eigen::VectorXd bent = stretched;
  bent[0] = core::deg_to_rad(40);
  bent[3] = core::deg_to_rad(90);  // elbow at a right angle
  EXPECT_LT(core::comfort_index(arm.jacobian(stretched), length), 1e-9);
  EXPECT_GT(core::comfort_index(arm.jacobian(bent), length), 0.05);
}
