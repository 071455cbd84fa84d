#include <gtest/gtest.h>

#include <random>

#include "hila/core/generic_ik.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/ur_ik.hpp"
#include "util/test_util.hpp"

using namespace hila;
using hila::core::deg_to_rad;

namespace {

const core::Arm& left_arm() {
  return test::reference_cell()->arm("left");
}

// UR3 DH values of DESIGN §4, written out so the tests do not reuse the code under test.
constexpr double kD1 = 0.1519, kA2 = -0.24365, kA3 = -0.21325, kD4 = 0.11235, kD5 = 0.08535,
                 kD6 = 0.0819, kTcp = 0.20;

}  // namespace

TEST(KinematicChain, ZeroConfigurationMatchesHandComputedUrPose) {
  // At q = 0 the UR arm lies along base -x: the flange sits at (a2 + a3, -(d4 + d6), d1 - d5)
  // with its z axis along base -y, and the TCP 0.20 m further along that axis.
  const core::Pose tcp = left_arm().chain.fk(Eigen::VectorXd::Zero(6));
  EXPECT_NEAR(tcp.translation().x(), kA2 + kA3, 1e-12);
  EXPECT_NEAR(tcp.translation().y(), -(kD4 + kD6 + kTcp), 1e-12);
  EXPECT_NEAR(tcp.translation().z(), kD1 - kD5, 1e-12);
  EXPECT_TRUE(tcp.linear().col(2).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
}

TEST(KinematicChain, ShoulderPanRotatesTheZeroPoseAboutBaseZ) {
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  q[0] = deg_to_rad(90);
  const core::Pose tcp = left_arm().chain.fk(q);
  EXPECT_NEAR(tcp.translation().x(), kD4 + kD6 + kTcp, 1e-12);
  EXPECT_NEAR(tcp.translation().y(), kA2 + kA3, 1e-12);
  EXPECT_NEAR(tcp.translation().z(), kD1 - kD5, 1e-12);
}

TEST(KinematicChain, ArmStraightUpReachesAboveTheShoulder) {
  // q2 = -90 deg, q4 = -90 deg: upper arm and forearm vertical, wrist 1 horizontal.
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  q[1] = deg_to_rad(-90);
  q[3] = deg_to_rad(-90);
  const core::Pose flange_to_tcp = core::make_pose({0, 0, kTcp});
  const core::Pose tcp = left_arm().chain.fk(q);
  const core::Pose flange = tcp * flange_to_tcp.inverse();
  EXPECT_NEAR(flange.translation().x(), 0.0, 1e-12);
  EXPECT_NEAR(flange.translation().y(), -(kD4 + kD6), 1e-12);
  EXPECT_NEAR(flange.translation().z(), kD1 - kA2 - kA3 + kD5, 1e-12);
}

TEST(KinematicChain, MatchesTreeForwardKinematicsOfTheRobotModel) {
  const auto cell = test::reference_cell();
  std::mt19937_64 rng(11);
  std::vector<core::Pose> links;
  for (int trial = 0; trial < 200; ++trial) {
    Eigen::VectorXd robot_q = cell->home_configuration();
    for (const core::Arm& arm : cell->arms()) {
      cell->set_arm(robot_q, arm, core::random_configuration(arm.chain, rng));
    }
    cell->robot().link_poses(robot_q, links);
    for (const core::Arm& arm : cell->arms()) {
      Eigen::VectorXd q(6);
      for (int i = 0; i < 6; ++i) q[i] = robot_q[arm.chain.model_variables()[i]];
      const core::Pose expected = links[cell->robot().link_index(arm.spec.base_link)].inverse() *
                                  links[cell->robot().link_index(arm.spec.tip_link)];
      EXPECT_TRUE(arm.chain.fk(q).isApprox(expected, 1e-12));
    }
  }
}

namespace {
void expect_jacobian_matches_finite_differences(const core::KinematicChain& chain, int seed) {
  std::mt19937_64 rng(seed);
  const double h = 1e-6;
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::VectorXd q = core::random_configuration(chain, rng);
    const core::Jacobian j = chain.jacobian(q);
    const core::Pose t0 = chain.fk(q);
    for (int i = 0; i < chain.dof(); ++i) {
      Eigen::VectorXd qp = q, qm = q;
      qp[i] += h;
      qm[i] -= h;
      const core::Pose tp = chain.fk(qp), tm = chain.fk(qm);
      const Eigen::Vector3d v = (tp.translation() - tm.translation()) / (2 * h);
      // Angular velocity from the rotation difference: log(Rp Rm^T) / 2h.
      const Eigen::AngleAxisd aa(tp.linear() * tm.linear().transpose());
      const Eigen::Vector3d w = aa.angle() * aa.axis() / (2 * h);
      EXPECT_LT((j.block<3, 1>(0, i) - v).norm(), 1e-7) << "joint " << i << " trial " << trial;
      EXPECT_LT((j.block<3, 1>(3, i) - w).norm(), 1e-7) << "joint " << i << " trial " << trial;
    }
    (void)t0;
  }
}
}  // namespace

TEST(KinematicChain, UrJacobianMatchesFiniteDifferences) {
  expect_jacobian_matches_finite_differences(left_arm().chain, 3);
  expect_jacobian_matches_finite_differences(test::reference_cell()->arm("right").chain, 4);
}

TEST(KinematicChain, HumanArmJacobianMatchesFiniteDifferences) {
  for (const core::HumanArm& arm : test::reference_cell()->human_arms()) {
    EXPECT_EQ(arm.chain.dof(), 7);
    expect_jacobian_matches_finite_differences(arm.chain, 5);
  }
}

TEST(KinematicChain, RejectsABaseThatIsNotAnAncestorOfTheTip) {
  const auto cell = test::reference_cell();
  test::expect_input_error(
      [&] { core::KinematicChain(cell->robot(), "left_tcp", "left_base_link"); },
      {"dual_ur3.urdf", "ancestor"});
  test::expect_input_error(
      [&] { core::KinematicChain(cell->robot(), "left_base_link", "no_such_link"); },
      {"dual_ur3.urdf", "no_such_link"});
}

TEST(KinematicChain, WithinLimits) {
  const auto& chain = left_arm().chain;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(6);
  EXPECT_TRUE(chain.within_limits(q));
  q[2] = deg_to_rad(361);
  EXPECT_FALSE(chain.within_limits(q));
  EXPECT_FALSE(chain.within_limits(Eigen::VectorXd::Zero(5)));
}
