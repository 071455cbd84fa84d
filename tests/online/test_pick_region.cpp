// The stack where the cameras find it (issue: each board is planned wherever its stack is
// detected): the cabinet's whole stack moved and turned on the table, its boards planned in
// assembly order by the exchange, each picked with the suction grasp and IK branch that reach it.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "hila/core/pose.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

std::chrono::steady_clock::time_point in_seconds(double s) {
  return std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(s * 1e6));
}

// The nominal scene with every board not finished moved by `offset` (m, in the table's plane)
// and turned by `yaw_deg` about the vertical through `centre` (world, m): the whole stack as the
// cameras would find it moved.
online::Scene moved_stack(const online::PlannerModel& model, const online::Scene& nominal,
                          const Eigen::Vector2d& centre, const Eigen::Vector2d& offset,
                          double yaw_deg) {
  core::Pose move = core::Pose::Identity();
  move.linear() =
      Eigen::AngleAxisd(core::deg_to_rad(yaw_deg), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d c(centre.x(), centre.y(), 0.0);
  move.translation() = c + Eigen::Vector3d(offset.x(), offset.y(), 0.0) - move.linear() * c;
  online::Scene scene = nominal;
  for (const auto& part : model.product().parts) {
    if (!nominal.is_finished(part.name)) {
      scene.detected[part.name] = move * nominal.initial_pose(part);
    }
  }
  return scene;
}

// The scene after `board`: finished at its target, the tool in hand, both arms home.
online::Scene after(const online::PlannerModel& model, const online::Scene& scene,
                    const std::string& board) {
  online::Scene next = scene.with_finished(model.product(), board);
  next.tool_in_hand = true;
  for (const auto& arm : model.cell().arms()) next.robot[arm.spec.name] = arm.spec.home;
  return next;
}


// Every board the database has goals for is planned with the stack moved, each plan validated
// and continuous: each step starts where its arm is.
void expect_stack_picked(const online::PlannerModel& model, online::Scene scene) {
  online::BoardPlanner planner(model);
  for (const auto& part : model.product().parts) {
    SCOPED_TRACE(part.name);
    const auto plan = planner.plan(scene, part.name, in_seconds(30.0));
    if (!model.board_records(part.name)->goals.empty()) {
      ASSERT_TRUE(plan.solved()) << plan.reason;
      EXPECT_TRUE(plan.validated);
      std::map<std::string, Eigen::VectorXd> at(scene.robot.begin(), scene.robot.end());
      for (const auto& step : plan.steps) {
        EXPECT_TRUE(step.q.front().isApprox(at.at(step.arm), 1e-9)) << step.name;
        EXPECT_TRUE(step.validation.valid()) << step.name;
        at[step.arm] = step.q.back();
      }
      if (plan.mode == online::DeliveryMode::kExchange) {
        EXPECT_GT(plan.suction_grasp_id, 0);
      }
    }
    scene = after(model, scene, part.name);
  }
}

}  // namespace

// A small cabinet database (tests/util/quick_build.hpp), built once per process.
class PickRegion : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::temp_dir("pick_region");
    const std::string path = dir_ + "/cabinet.hila";
    offline::build_database(test::product_path(), test::cell_path(), path,
                            test::quick_build_settings(7, 2));
    model_ = online::PlannerModel::load(path, test::cell_path(), test::product_path());
    nominal_ = online::load_scene(test::data_path("cabinet/scene.yaml"), model_->cell(),
                                  model_->product());
  }

  static void TearDownTestSuite() {
    model_.reset();
    std::filesystem::remove_all(dir_);
  }

  // The nominal scene with the stack moved by (dx, dy) m and turned by `yaw_deg` about the
  // stack's centre (0.30, -0.30) m, as bench_generality --pick-region moves it.
  static online::Scene stack_at(double dx, double dy, double yaw_deg) {
    return moved_stack(*model_, nominal_, Eigen::Vector2d(0.30, -0.30), Eigen::Vector2d(dx, dy),
                       yaw_deg);
  }

  static inline std::string dir_;
  static inline std::shared_ptr<const online::PlannerModel> model_;
  static inline online::Scene nominal_;
};

// The example: the stack 8 cm nearer the robot and turned 45 degrees.
TEST_F(PickRegion, AStackMoved8cmAndTurned45DegIsPicked) {
  expect_stack_picked(*model_, stack_at(-0.08, 0.0, 45.0));
}

// The stack 9.7 cm nearer the robot and turned 162.5 degrees: on this database, back_lower's
// pick with each robot-robot pose's own suction grasp and first IK branch leaves a pre-pick that
// reaches no roadmap node; another branch, or a grasp turned about the cup's axis (which turns
// the wrist on the way to the exchange instead of at the stack), picks it.
TEST_F(PickRegion, AStackTurnedNearlyHalfAroundIsPickedWithAnotherSuctionGrasp) {
  expect_stack_picked(*model_, stack_at(-0.095, 0.018, 162.5));
}
