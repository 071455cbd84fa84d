// The direct way (BoardPlanner, DeliveryMode::kDirect): a part too small for the suction cup is
// picked where it lies by the gripper of the arm that reaches it and delivered by that arm, no
// tool and no exchange. Without direct picks neither block has a single handover goal.
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

// Two 120 x 35 x 30 mm blocks (no face takes the 40 mm cup) lying on the table: one on the
// robot's left, 0.65 m from the left arm's base and 0.90 m from the right arm's, one mirrored on
// its right. Their targets stand on the table in front of the human.
std::string blocks_product(const std::string& dir) {
  core::write_mesh(core::make_box_mesh(Eigen::Vector3d(0.12, 0.035, 0.03)), dir + "/block.stl",
                   "stlb");
  return test::write_file(dir, "product.yaml", R"(name: blocks
assembly_frame: {xyz: [0.62, 0.0, 1.094], rpy_deg: [0, 0, 0]}
suction_tool_pose: {xyz: [0.30, -0.72, 1.229], rpy_deg: [0, 0, 0]}
parts:
  - name: block_left
    order: 1
    mesh: block.stl
    mesh_unit: m
    mass: 0.15
    target: {xyz: [0.0, 0.08, 0.0155], rpy_deg: [0, 0, 0]}
    initial: {xyz: [0.35, 0.40, 1.1095], rpy_deg: [0, 0, 0]}
  - name: block_right
    order: 2
    mesh: block.stl
    mesh_unit: m
    mass: 0.15
    target: {xyz: [0.0, -0.08, 0.0155], rpy_deg: [0, 0, 0]}
    initial: {xyz: [0.35, -0.40, 1.1095], rpy_deg: [0, 0, 0]}
)");
}

// Each arm's events in order and both arms home at the end; the block goes from the table to the
// human in one arm's gripper.
void expect_direct_plan(const online::PlannerModel& model, const online::Scene& scene,
                        const online::BoardPlan& plan, const std::string& arm,
                        const std::string& first_events = "") {
  ASSERT_TRUE(plan.solved()) << plan.reason;
  EXPECT_EQ(plan.mode, online::DeliveryMode::kDirect);
  EXPECT_EQ(plan.picking_arm, arm);
  EXPECT_EQ(plan.delivering_arm, arm);
  EXPECT_EQ(plan.suction_grasp_id, 0);
  EXPECT_TRUE(plan.validated);
  EXPECT_FALSE(plan.tool_in_hand_after);  // the tool was never needed
  std::map<std::string, Eigen::VectorXd> at(scene.robot.begin(), scene.robot.end());
  std::string events;
  double clock = 0.0;
  for (const auto& step : plan.steps) {
    EXPECT_EQ(step.arm, arm) << step.name << ": only the picking arm moves";
    EXPECT_TRUE(step.q.front().isApprox(at.at(step.arm), 1e-9)) << step.name;
    at[step.arm] = step.q.back();
    // Timed and validated (a queued step's report is in): increasing times, samples checked.
    ASSERT_EQ(step.time.size(), step.q.size()) << step.name;
    EXPECT_GE(step.time.front(), clock - 1e-12) << step.name;
    for (std::size_t k = 1; k < step.time.size(); ++k) {
      EXPECT_GT(step.time[k], step.time[k - 1]) << step.name << " waypoint " << k;
    }
    clock = step.time.back();
    EXPECT_GT(step.validation.samples, 0) << step.name;
    EXPECT_TRUE(step.validation.valid()) << step.name;
    if (const std::string e = online::events_text(step); !e.empty()) events += e + " ";
  }
  EXPECT_EQ(events, first_events + "gripper_close wait_for_human gripper_open ");
  for (const auto& a : model.cell().arms()) {
    EXPECT_LT((at.at(a.spec.name) - a.spec.home).norm(), 1e-9) << a.spec.name;
  }
  // Where the gripper closes, it holds the block at its grasp where the block lies.
  const auto& grasp = model.board_records(plan.board)->robot_grasps.at(plan.robot_grasp_id);
  const core::Arm& picker = model.cell().arm(arm);
  for (const auto& step : plan.steps) {
    if (step.end_event != online::StepEvent::kGripperClose) continue;
    const core::Pose tcp =
        core::arm_base_in_world(model.cell(), picker) * picker.chain.fk(step.q.back());
    const core::Pose want = scene.initial_pose(model.product().part(plan.board)) * grasp.tcp;
    EXPECT_LT((tcp.translation() - want.translation()).norm(), 1e-6);
    EXPECT_TRUE(tcp.linear().isApprox(want.linear(), 1e-6));
  }
}

}  // namespace

TEST(DirectDelivery, ASmallPartIsPickedByTheGripperOfTheArmThatReachesIt) {
  const std::string dir = test::temp_dir("direct_delivery");
  const std::string product = blocks_product(dir);
  const std::string db = dir + "/blocks.hila";
  offline::build_database(product, test::cell_path(), db, test::quick_build_settings(7, 2));
  const auto model = online::PlannerModel::load(db, test::cell_path(), product);
  // The build stored direct grasps for both blocks, by the arm that reaches each, and no
  // exchange (no suction grasp).
  for (const auto& [board, arm] : {std::pair{"block_left", "left"}, {"block_right", "right"}}) {
    SCOPED_TRACE(board);
    const online::BoardRecords& records = *model->board_records(board);
    ASSERT_FALSE(records.goals.empty());
    EXPECT_TRUE(records.suction_grasps.empty());
    int direct = 0;
    for (const auto& goal : records.goals) {
      EXPECT_TRUE(records.shared_grasps.at(goal.id).empty());
      for (const auto& d : records.direct_grasps.at(goal.id)) {
        EXPECT_EQ(d.arm, arm);
        ++direct;
      }
    }
    EXPECT_GT(direct, 0);
  }

  online::BoardPlanner planner(*model);
  online::Scene scene = online::nominal_scene(model->cell(), model->product());
  {
    SCOPED_TRACE("block_left, by the left arm");
    const online::BoardPlan plan = planner.plan(scene, "block_left", in_seconds(60));
    expect_direct_plan(*model, scene, plan, "left");
  }
  scene = scene.with_finished(model->product(), "block_left");
  {
    SCOPED_TRACE("block_right, by the right arm, the tool standing on the table");
    const online::BoardPlan plan = planner.plan(scene, "block_right", in_seconds(60));
    expect_direct_plan(*model, scene, plan, "right");
  }
  {
    // The right arm sets the tool down at its place first; its steps are validated as the
    // others (the tool's foot meets the table at the last sample of the lowering only).
    SCOPED_TRACE("block_right with the tool in the right arm's hand");
    scene.tool_in_hand = true;
    const online::BoardPlan plan = planner.plan(scene, "block_right", in_seconds(60));
    expect_direct_plan(*model, scene, plan, "right", "tool_released ");
    ASSERT_GE(plan.steps.size(), 3u);
    EXPECT_EQ(plan.steps[0].name, "tool_to_place");
    EXPECT_EQ(plan.steps[1].name, "tool_lower");
    EXPECT_EQ(plan.steps[2].name, "tool_retreat");
    const core::Arm& right = model->cell().arm("right");
    const core::Pose handle = core::arm_base_in_world(model->cell(), right) *
                              right.chain.fk(plan.steps[1].q.back()) *
                              model->cell().spec().suction.handle_in_tcp;
    EXPECT_LT((handle.translation() - scene.tool.translation()).norm(), 1e-6);
  }
}
