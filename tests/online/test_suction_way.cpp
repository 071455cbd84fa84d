// The suction way (BoardPlanner, DeliveryMode::kSuction): a panel lying flat on the table, which
// no gripper takes where it lies, reaches the human on the suction cup of the arm that picked it
// where no exchange serves a goal (here: no robot-robot pose to search). Without suction
// deliveries the build finds no goal for it.
#include <gtest/gtest.h>

#include <string>

#include "hila/core/mesh.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

std::chrono::steady_clock::time_point in_seconds(double s) {
  return std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(s * 1e6));
}

// A 300 x 200 x 15 mm, 0.5 kg panel lying flat where the cabinet's stack stands (the right arm's
// side); its target lies on the table in front of the human.
std::string panel_product(const std::string& dir) {
  core::write_mesh(core::make_box_mesh(Eigen::Vector3d(0.30, 0.20, 0.015)), dir + "/panel.stl",
                   "stlb");
  return test::write_file(dir, "product.yaml", R"(name: panel
assembly_frame: {xyz: [0.62, 0.0, 1.094], rpy_deg: [0, 0, 0]}
suction_tool_pose: {xyz: [0.30, -0.72, 1.229], rpy_deg: [0, 0, 0]}
parts:
  - name: panel
    order: 1
    mesh: panel.stl
    mesh_unit: m
    mass: 0.5
    target: {xyz: [0.0, 0.0, 0.0075], rpy_deg: [0, 0, 0]}
    initial: {xyz: [0.30, -0.30, 1.1015], rpy_deg: [0, 0, 90]}
)");
}

}  // namespace

TEST(SuctionWay, APanelNoExchangeServesIsPresentedOnTheCupOfTheArmThatPickedIt) {
  const std::string dir = test::temp_dir("suction_way");
  const std::string product = panel_product(dir);
  offline::BuildSettings settings = test::quick_build_settings(7, 2);
  settings.handover.rr_positions.clear();  // no exchange
  settings.handover.direct = false;
  // Few of the quick build's 60 candidates are comfortable for so large a part.
  settings.handover.candidates = 400;
  settings.handover.max_candidates = 400;

  settings.handover.suction_delivery = false;
  const std::string without = dir + "/without.hila";
  offline::build_database(product, test::cell_path(), without, settings);
  {
    const db::Database database = db::Database::open(without);
    const auto* stage = database.handover_stage(database.parts().front().id);
    ASSERT_NE(stage, nullptr);
    EXPECT_EQ(stage->goals, 0) << stage->failure;
    EXPECT_NE(stage->failure.find("no robot-robot handover pose"), std::string::npos)
        << stage->failure;
  }

  settings.handover.suction_delivery = true;
  const std::string db_path = dir + "/panel.hila";
  offline::build_database(product, test::cell_path(), db_path, settings);
  const auto model = online::PlannerModel::load(db_path, test::cell_path(), product);
  const online::BoardRecords& records = *model->board_records("panel");
  ASSERT_FALSE(records.goals.empty()) << model->database().handover_stage(records.part.id)->failure;
  const core::Cell& cell = model->cell();
  const core::Arm& right = cell.arm("right");
  // The cup in the TCP while the tool is held, from the stage scene (the tool's kinematics).
  const core::Pose cup_in_tcp =
      core::build_stage_scene(cell, model->product().part("panel").mesh, {}, "right").cup_in_tcp;
  int deliveries = 0;
  for (const auto& goal : records.goals) {
    EXPECT_TRUE(records.shared_grasps.at(goal.id).empty());
    for (const auto& d : records.suction_deliveries.at(goal.id)) {
      EXPECT_EQ(d.arm, "right");
      // The stored IK holds the cup where the suction grasp meets the panel at the goal (FK).
      const core::Pose tcp = core::arm_base_in_world(cell, right) * right.chain.fk(d.joints_rh);
      const core::Pose want = goal.board * records.suction_grasps.at(d.suction_grasp_id).cup;
      const core::Pose cup = tcp * cup_in_tcp;
      EXPECT_LT((cup.translation() - want.translation()).norm(), 1e-6);
      EXPECT_TRUE(cup.linear().isApprox(want.linear(), 1e-6));
      ++deliveries;
    }
  }
  ASSERT_GT(deliveries, 0);

  online::BoardPlanner planner(*model);
  const online::Scene scene = online::nominal_scene(cell, model->product());
  const online::BoardPlan plan = planner.plan(scene, "panel", in_seconds(60));
  ASSERT_TRUE(plan.solved()) << plan.reason;
  EXPECT_EQ(plan.mode, online::DeliveryMode::kSuction);
  EXPECT_EQ(plan.picking_arm, "right");
  EXPECT_EQ(plan.delivering_arm, "right");
  EXPECT_EQ(plan.robot_grasp_id, 0);
  EXPECT_NE(plan.suction_grasp_id, 0);
  EXPECT_TRUE(plan.validated);
  EXPECT_TRUE(plan.tool_in_hand_after);

  // Only the right arm moves, each step from where the last left it; the events in order; the
  // panel on the cup at the robot-human pose when the arm waits for the human.
  Eigen::VectorXd at = scene.robot.at("right");
  std::string events;
  const auto& cup = records.suction_grasps.at(plan.suction_grasp_id);
  for (const auto& step : plan.steps) {
    EXPECT_EQ(step.arm, "right") << step.name;
    EXPECT_TRUE(step.q.front().isApprox(at, 1e-9)) << step.name;
    at = step.q.back();
    EXPECT_TRUE(step.validation.valid()) << step.name;
    EXPECT_GT(step.validation.samples, 0) << step.name;  // the validator's report is in
    if (const std::string e = online::events_text(step); !e.empty()) events += e + " ";
    if (step.end_event == online::StepEvent::kWaitForHuman) {
      const core::Pose board = core::arm_base_in_world(cell, right) *
                               right.chain.fk(step.q.back()) * cup_in_tcp * cup.cup.inverse();
      EXPECT_LT((board.translation() - plan.human_handover.translation()).norm(), 1e-6);
      EXPECT_TRUE(board.linear().isApprox(plan.human_handover.linear(), 1e-6));
    }
  }
  EXPECT_EQ(events, "tool_grasped suction_on wait_for_human suction_off ");
  EXPECT_LT((at - right.spec.home).norm(), 1e-9);
}
