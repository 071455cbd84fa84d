#include <gtest/gtest.h>

#include <random>

#include "hila/core/arm_poser.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// Around home, where some configurations collide and some do not.
Eigen::VectorXd random_arm_q(const core::Arm& arm, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q = arm.spec.home;
  for (int j = 0; j < q.size(); ++j) q[j] += u(rng);
  return q;
}

}  // namespace

// Posing one arm (its links and jaw only) leaves every robot body where posing the whole robot
// for the same configuration puts it, and the collision verdicts agree.
TEST(ArmPoser, PosingOneArmMatchesPosingTheWholeRobot) {
  const auto cell = test::reference_cell();
  const core::CellScene scene = core::build_cell_scene(*cell);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> jaw(0.0, cell->spec().gripper.jaw_max);
  int colliding = 0;
  for (const core::Arm& arm : cell->arms()) {
    SCOPED_TRACE(arm.spec.name);
    const core::Arm& other =
        &arm == &cell->arms().front() ? cell->arms().back() : cell->arms().front();
    core::ArmPoser poser(*cell, scene, arm);
    core::CollisionData fast(scene.model);
    core::CollisionData full(scene.model);
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, other, random_arm_q(other, rng));
    core::set_cell_state(*cell, scene, fast, robot_q, cell->human_neutral());
    core::set_cell_state(*cell, scene, full, robot_q, cell->human_neutral());
    poser.pose_robot(fast, robot_q);
    for (int i = 0; i < 200; ++i) {
      cell->set_arm(robot_q, arm, random_arm_q(arm, rng));
      cell->set_jaw(robot_q, arm, jaw(rng));
      poser.pose_arm(fast, robot_q);
      core::set_robot_state(*cell, scene, full, robot_q);
      for (const int body : scene.robot.link_to_body) {
        if (body < 0) continue;
        EXPECT_TRUE(fast.body_pose(body).isApprox(full.body_pose(body), 1e-12))
            << scene.model.body_name(body) << " sample " << i;
      }
      const bool hit = core::in_collision(scene.model, full);
      EXPECT_EQ(core::in_collision(scene.model, fast), hit) << "sample " << i;
      colliding += hit ? 1 : 0;
    }
  }
  // Random configurations: both verdicts occur, so the comparison means something.
  EXPECT_GT(colliding, 0);
  EXPECT_LT(colliding, 400);
}
