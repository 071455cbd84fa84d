#include <gtest/gtest.h>

#include <random>

#include "hila/core/collision.hpp"
#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/offline/arm_workspace.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// A configuration near the arm's home (a random one over the UR's +-2 pi mostly folds the arm
// into itself).
Eigen::VectorXd near_home(const core::Arm& arm, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> offset(-1.2, 1.2);
  Eigen::VectorXd q = arm.spec.home;
  for (Eigen::Index j = 0; j < q.size(); ++j) q[j] += offset(rng);
  return q;
}

}  // namespace

// pose_rest() puts the other arm and the tool in its hand where the robot configuration says:
// the receiving arm's verdict then equals a brute-force check of the same cell with both arms
// posed through the whole robot's FK (every pair through FCL's narrow phase).
TEST(ArmWorkspace, PoseRestAgreesWithBruteForceWithBothArmsPosed) {
  const auto cell = test::reference_cell();
  const core::Arm& left = cell->arm("left");
  const core::Arm& right = cell->arm("right");
  offline::ArmWorkspace workspace(*cell, "left", "right");

  const core::ProductSpec product = core::load_product(test::product_path());
  core::StageScene reference =
      core::build_stage_scene(*cell, product.parts.front().mesh, {}, "right");
  reference.cell.model.set_enabled(reference.board, false);
  core::CollisionData data(reference.cell.model);
  const std::vector<int>& left_bodies = reference.cell.arm_bodies[0];
  ASSERT_EQ(&cell->arms()[0], &left);

  std::mt19937_64 rng(7);
  int clear = 0;
  int colliding = 0;
  int only_with_right_moved = 0;  // clear with the right arm at home, not where it is posed
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::VectorXd q_left = near_home(left, rng);
    const Eigen::VectorXd q_right = near_home(right, rng);
    if (!left.chain.within_limits(q_left) || !right.chain.within_limits(q_right)) continue;
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, right, q_right);
    cell->set_arm(robot_q, left, q_left);
    core::set_cell_state(*cell, reference.cell, data, robot_q, cell->human_neutral());
    core::set_tool_held(*cell, reference, data,
                        core::arm_base_in_world(*cell, right) * right.chain.fk(q_right));
    const bool expected = !core::in_collision_brute_force(reference.cell.model, data, left_bodies);

    workspace.pose_rest(cell->home_configuration());
    const bool at_home = workspace.arm_valid(q_left);
    workspace.pose_rest(robot_q);
    EXPECT_EQ(workspace.arm_valid(q_left), expected) << "trial " << trial;
    (expected ? clear : colliding) += 1;
    only_with_right_moved += at_home && !expected ? 1 : 0;
  }
  EXPECT_GT(clear, 20);
  EXPECT_GT(colliding, 20);
  // Random arms seldom meet: both grippers pointing down at one spot above the table do. The
  // left arm there is clear with the right at home and collides once the right is posed there.
  for (const double x : {0.25, 0.30, 0.35}) {
    const Eigen::Vector3d spot(x, 0.0, 1.35);
    const Eigen::VectorXd q_left = test::arm_pointing_down_at(*cell, left, spot);
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, right, test::arm_pointing_down_at(*cell, right, spot));
    workspace.pose_rest(cell->home_configuration());
    const bool at_home = workspace.arm_valid(q_left);
    workspace.pose_rest(robot_q);
    only_with_right_moved += at_home && !workspace.arm_valid(q_left) ? 1 : 0;
  }
  EXPECT_EQ(only_with_right_moved, 3);
}
