// The regrasp way (BoardPlanner, DeliveryMode::kRegrasp): a steel L bracket lying on the table is
// picked by the gripper at its walls' top edges, where the human's hand at every comfortable goal
// would meet the gripper; set down on another resting pose, it is taken again with a grasp that
// leaves the human room. Without regrasps on the table the build finds no goal for it.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <map>
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

}  // namespace

TEST(RegraspWay, ABracketTheGripperCannotDeliverAsItLiesIsSetDownAndTakenAgain) {
  const std::string dir = test::temp_dir("regrasp_way");
  const std::string product = test::bracket_product(dir);
  offline::BuildSettings settings = test::quick_build_settings(7, 2);
  // Few of the quick build's 60 candidates are comfortable for so small a part.
  settings.handover.candidates = 400;
  settings.handover.max_candidates = 400;
  settings.handover.table_regrasp.relay = false;  // one arm does it all (relays: the test below)

  // Without regrasps on the table: no goal (the gripper picks it, but holds it nowhere the human
  // can take it).
  settings.handover.table_regrasp.enabled = false;
  const std::string without = dir + "/without.hila";
  offline::build_database(product, test::cell_path(), without, settings);
  {
    const db::Database database = db::Database::open(without);
    const auto* stage = database.handover_stage(database.parts().front().id);
    ASSERT_NE(stage, nullptr);
    EXPECT_EQ(stage->goals, 0) << stage->failure;
    EXPECT_NE(stage->failure.find("gripper from where the part lies"), std::string::npos)
        << stage->failure;
  }

  settings.handover.table_regrasp.enabled = true;
  const std::string db_path = dir + "/bracket.hila";
  offline::build_database(product, test::cell_path(), db_path, settings);
  const auto model = online::PlannerModel::load(db_path, test::cell_path(), product);
  const online::BoardRecords& records = *model->board_records("bracket");
  ASSERT_FALSE(records.goals.empty()) << model->database().handover_stage(records.part.id)->failure;
  int regrasps = 0;
  for (const auto& goal : records.goals) {
    EXPECT_TRUE(records.direct_grasps.at(goal.id).empty());
    for (const auto& r : records.table_regrasps.at(goal.id)) {
      EXPECT_NE(r.pick_grasp_id, r.robot_grasp_id);
      ++regrasps;
    }
  }
  ASSERT_GT(regrasps, 0);

  online::BoardPlanner planner(*model);
  const online::Scene scene = online::nominal_scene(model->cell(), model->product());
  const online::BoardPlan plan = planner.plan(scene, "bracket", in_seconds(60));
  ASSERT_TRUE(plan.solved()) << plan.reason;
  EXPECT_EQ(plan.mode, online::DeliveryMode::kRegrasp);
  EXPECT_EQ(plan.picking_arm, plan.delivering_arm);
  EXPECT_NE(plan.pick_grasp_id, plan.robot_grasp_id);
  EXPECT_TRUE(plan.validated);

  // One arm moves, each step from where the last left it; the events in order.
  const core::Arm& arm = model->cell().arm(plan.picking_arm);
  Eigen::VectorXd at = scene.robot.at(arm.spec.name);
  std::string events;
  for (const auto& step : plan.steps) {
    EXPECT_EQ(step.arm, arm.spec.name) << step.name;
    EXPECT_TRUE(step.q.front().isApprox(at, 1e-9)) << step.name;
    at = step.q.back();
    EXPECT_GT(step.validation.samples, 0) << step.name;
    EXPECT_TRUE(step.validation.valid()) << step.name;
    if (const std::string e = online::events_text(step); !e.empty()) events += e + " ";
  }
  EXPECT_EQ(events, "gripper_close set_down gripper_close wait_for_human gripper_open ");
  EXPECT_LT((at - arm.spec.home).norm(), 1e-9);

  // Where it is set down the bracket rests on the table as it lay (its lowest point at the same
  // height, 1.5 mm over the table's top as the generator lays parts; checked on the mesh, not the
  // build's placements), turned away from how it lay; the gripper closes first at the pick grasp
  // where it lay, then at the delivering grasp where it was set down.
  const core::TriangleMesh& mesh = model->product().part("bracket").mesh;
  const core::Pose initial = scene.initial_pose(model->product().part("bracket"));
  double lowest = std::numeric_limits<double>::infinity();
  double lay = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : mesh.vertices) {
    lowest = std::min(lowest, (plan.set_down * v).z());
    lay = std::min(lay, (initial * v).z());
  }
  double table_top = 0.0;
  for (const auto& o : model->cell().spec().obstacles) {
    if (o.name == "table") table_top = o.pose.translation().z() + 0.5 * o.size.z();
  }
  EXPECT_NEAR(lowest, lay, 1e-6);
  EXPECT_NEAR(lowest, table_top, 0.002);
  EXPECT_GT(core::rotation_distance(plan.set_down.linear(), initial.linear()), 0.1);
  const auto& grasps = records.robot_grasps;
  const core::Pose base = core::arm_base_in_world(model->cell(), arm);
  std::vector<core::Pose> closes;
  for (const auto& step : plan.steps) {
    if (step.end_event == online::StepEvent::kGripperClose)
      closes.push_back(base * arm.chain.fk(step.q.back()));
  }
  ASSERT_EQ(closes.size(), 2u);
  const core::Pose first = initial * grasps.at(plan.pick_grasp_id).tcp;
  const core::Pose again = plan.set_down * grasps.at(plan.robot_grasp_id).tcp;
  EXPECT_LT((closes[0].translation() - first.translation()).norm(), 1e-6);
  EXPECT_TRUE(closes[0].linear().isApprox(first.linear(), 1e-6));
  EXPECT_LT((closes[1].translation() - again.translation()).norm(), 1e-6);
  EXPECT_TRUE(closes[1].linear().isApprox(again.linear(), 1e-6));
}

// The relay: a bracket only the left arm's gripper picks where it lies (on the robot's left),
// whose comfortable goals only the right arm's gripper serves (its target on the human's right).
// The left arm sets it down where both arms reach and goes home; the right arm, having set its
// tool down, takes it again and delivers it. Without relays the build finds no comfortable goal
// for it (only goals below the comfort threshold, from its fallback down to the comfort floor).
TEST(RegraspWay, ABracketOnlyTheOtherArmDeliversIsRelayedOnTheTable) {
  const std::string dir = test::temp_dir("relay_way");
  const std::string product = std::string(HILA_TEST_DATA_DIR) + "/relay_bracket/product.yaml";
  offline::BuildSettings settings = test::quick_build_settings(7, 2);
  settings.handover.candidates = 400;
  settings.handover.max_candidates = 400;

  settings.handover.table_regrasp.relay = false;
  const std::string without = dir + "/without.hila";
  offline::build_database(product, test::cell_path(), without, settings);
  double best_without = 0.0;
  {
    const db::Database database = db::Database::open(without);
    const auto part = database.parts().front().id;
    for (const auto& goal : database.handover_goals(part)) {
      best_without = std::max(best_without, goal.quality);
      for (const auto& r : database.table_regrasps(goal.id)) EXPECT_EQ(r.repick_arm, r.arm);
      EXPECT_TRUE(database.direct_grasps(goal.id).empty());
    }
  }

  settings.handover.table_regrasp.relay = true;
  const std::string db_path = dir + "/relay.hila";
  offline::build_database(product, test::cell_path(), db_path, settings);
  const auto model = online::PlannerModel::load(db_path, test::cell_path(), product);
  const online::BoardRecords& records = *model->board_records("bracket");
  ASSERT_FALSE(records.goals.empty()) << model->database().handover_stage(records.part.id)->failure;
  int relays = 0;
  for (const auto& goal : records.goals) {
    for (const auto& r : records.table_regrasps.at(goal.id)) {
      EXPECT_EQ(r.arm, "left");  // the only arm that picks it where it lies
      relays += r.repick_arm == "right" ? 1 : 0;
    }
  }
  EXPECT_GT(relays, 0);
  EXPECT_LT(best_without, settings.handover.comfort_threshold);

  online::BoardPlanner planner(*model);
  const online::Scene scene = online::nominal_scene(model->cell(), model->product());
  const online::BoardPlan plan = planner.plan(scene, "bracket", in_seconds(60));
  ASSERT_TRUE(plan.solved()) << plan.reason;
  EXPECT_EQ(plan.mode, online::DeliveryMode::kRegrasp);
  EXPECT_EQ(plan.picking_arm, "left");
  EXPECT_EQ(plan.delivering_arm, "right");
  EXPECT_TRUE(plan.validated);
  EXPECT_GT(plan.quality, settings.handover.comfort_threshold);

  // Each arm's steps start where it was; the events in order with the arm that does them; both
  // arms home at the end. The left gripper closes where the bracket lies and lets go where it is
  // set down, the right gripper closes there (FK of each arm).
  const core::Cell& cell = model->cell();
  std::map<std::string, Eigen::VectorXd> at(scene.robot.begin(), scene.robot.end());
  std::string events;
  std::vector<std::pair<std::string, core::Pose>> closes;
  for (const auto& step : plan.steps) {
    EXPECT_TRUE(step.q.front().isApprox(at.at(step.arm), 1e-9)) << step.name;
    at[step.arm] = step.q.back();
    EXPECT_TRUE(step.validation.valid()) << step.name;
    EXPECT_GT(step.validation.samples, 0) << step.name;  // the validator's report is in
    if (const std::string e = online::events_text(step); !e.empty())
      events += step.arm + ":" + e + " ";
    if (step.end_event == online::StepEvent::kGripperClose) {
      const core::Arm& arm = cell.arm(step.arm);
      closes.emplace_back(step.arm,
                          core::arm_base_in_world(cell, arm) * arm.chain.fk(step.q.back()));
    }
  }
  EXPECT_EQ(events, std::string(scene.tool_in_hand ? "right:tool_released " : "") +
                        "left:gripper_close left:set_down right:gripper_close "
                        "right:wait_for_human right:gripper_open ");
  for (const auto& a : cell.arms()) {
    EXPECT_LT((at.at(a.spec.name) - a.spec.home).norm(), 1e-9) << a.spec.name;
  }
  ASSERT_EQ(closes.size(), 2u);
  const core::Pose initial = scene.initial_pose(model->product().part("bracket"));
  const core::Pose first = initial * records.robot_grasps.at(plan.pick_grasp_id).tcp;
  const core::Pose again = plan.set_down * records.robot_grasps.at(plan.robot_grasp_id).tcp;
  EXPECT_EQ(closes[0].first, "left");
  EXPECT_LT((closes[0].second.translation() - first.translation()).norm(), 1e-6);
  EXPECT_EQ(closes[1].first, "right");
  EXPECT_LT((closes[1].second.translation() - again.translation()).norm(), 1e-6);
  EXPECT_TRUE(closes[1].second.linear().isApprox(again.linear(), 1e-6));
  // Set down elsewhere than it lay.
  EXPECT_GT((plan.set_down.translation() - initial.translation()).head<2>().norm(), 0.05);
}
