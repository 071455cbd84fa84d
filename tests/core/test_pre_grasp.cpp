#include <gtest/gtest.h>

#include "hila/core/pre_grasp.hpp"
#include "hila/core/stage_scene.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

struct Fixture {
  std::shared_ptr<const core::Cell> cell = test::reference_cell();
  const core::Arm& arm = cell->arm("left");
  core::Pose base = core::arm_base_in_world(*cell, arm);
  Eigen::VectorXd grasp_q = arm.spec.home;
  core::Pose tcp(const Eigen::VectorXd& q) const { return base * arm.chain.fk(q); }
};

}  // namespace

// The offsets against the gripper's axes written out: back along approach, then along the edge
// (perpendicular to both approach and opening), each of the stated length.
TEST(PreGrasp, OffsetsFollowTheGrippersAxes) {
  Fixture f;
  const core::Pose g = f.tcp(f.grasp_q);
  const auto& gripper = f.cell->spec().gripper;
  const Eigen::Vector3d approach = g.linear() * gripper.approach_axis.normalized();
  const Eigen::Vector3d opening = g.linear() * gripper.opening_axis.normalized();
  const auto offsets =
      core::pre_grasp_offsets(g, gripper.approach_axis, gripper.opening_axis, 0.05);
  ASSERT_EQ(offsets.size(), 7u);
  EXPECT_TRUE(offsets[0].isApprox(-0.05 * approach, 1e-12));
  EXPECT_TRUE(offsets[1].isApprox(-0.025 * approach, 1e-12));
  EXPECT_TRUE(offsets[2].isApprox(-0.01 * approach, 1e-12));
  for (std::size_t i = 3; i < offsets.size(); ++i) {
    EXPECT_NEAR(offsets[i].dot(approach), 0.0, 1e-12);
    EXPECT_NEAR(offsets[i].dot(opening), 0.0, 1e-12);
  }
  EXPECT_NEAR(offsets[3].norm(), 0.05, 1e-12);
  EXPECT_NEAR(offsets[5].norm(), 0.025, 1e-12);
}

// With nothing in the way, the first offset; its FK is where the offset says, in the grasp's
// branch (near in joints).
TEST(PreGrasp, FreeSpaceGivesTheBackOffByFk) {
  Fixture f;
  const auto pre = core::find_pre_grasp(*f.cell, f.arm, f.grasp_q, 0.05, 0.01,
                                        [](const Eigen::VectorXd&) { return true; });
  ASSERT_TRUE(pre.has_value());
  const core::Pose g = f.tcp(f.grasp_q);
  const Eigen::Vector3d back =
      -(g.linear() * f.cell->spec().gripper.approach_axis.normalized()) * 0.05;
  EXPECT_LT((f.tcp(*pre).translation() - (g.translation() + back)).norm(), 1e-6);
  EXPECT_TRUE(f.tcp(*pre).linear().isApprox(g.linear(), 1e-6));
  EXPECT_LT((*pre - f.grasp_q).norm(), 0.5);
}

// A wall behind the gripper: the back-offs are refused (their straight way in crosses it), a
// slide along the edge is taken; with everything blocked, nothing.
TEST(PreGrasp, BlockedBehindSlidesAlongTheEdge) {
  Fixture f;
  const core::Pose g = f.tcp(f.grasp_q);
  const Eigen::Vector3d approach = g.linear() * f.cell->spec().gripper.approach_axis.normalized();
  // Any TCP more than 5 mm behind the grasp along the approach axis is "in the wall".
  auto behind_wall = [&](const Eigen::VectorXd& q) {
    return (f.tcp(q).translation() - g.translation()).dot(-approach) <= 0.005;
  };
  const auto pre = core::find_pre_grasp(*f.cell, f.arm, f.grasp_q, 0.05, 0.01, behind_wall);
  ASSERT_TRUE(pre.has_value());
  const Eigen::Vector3d moved = f.tcp(*pre).translation() - g.translation();
  EXPECT_NEAR(moved.dot(approach), 0.0, 1e-6);
  EXPECT_NEAR(moved.norm(), 0.05, 1e-6);
  EXPECT_FALSE(
      core::find_pre_grasp(*f.cell, f.arm, f.grasp_q, 0.05, 0.01, [&](const Eigen::VectorXd& q) {
        return (q - f.grasp_q).norm() < 1e-9;
      }).has_value());
}
