// Roles per board: the cabinet's back_upper laid on the left of the table, where only the left arm
// picks it by suction, with the tool standing where both arms reach it. The build gives that
// board to the left arm's suction (offline::HandoverSettings::swap_roles); the board before it
// is the right arm's, which puts the tool back on its stand (BoardPlanOptions::return_tool, or
// first thing in back_upper's plan) so that the left arm can take it; the right arm receives
// back_upper and delivers it.
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "hila/core/stage_scene.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/offline/tool_place.hpp"
#include "hila/online/board_planner.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

std::chrono::steady_clock::time_point in_seconds(double s) {
  return std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(s * 1e6));
}

void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

// The cabinet with back_upper on the left (mirrored from the stack) and the tool between the
// arms (beside the stack, where both reach its handle, lift it and set it down), or with
// `stand_between_arms` false on its own stand, which the right arm alone reaches.
std::string product_with_a_board_on_the_left(const std::string& dir,
                                             bool stand_between_arms = true) {
  std::string text = test::read_file(test::product_path());
  for (const char* mesh : {"shelf.stl", "lateral.stl", "back_panel.stl"}) {
    const std::string rel = std::string("mesh: ") + mesh;
    for (auto at = text.find(rel); at != std::string::npos; at = text.find(rel, at + 1)) {
      text.replace(at, rel.size(), "mesh: " + test::data_path(std::string("cabinet/") + mesh));
    }
  }
  replace_once(text, "initial: {xyz: [0.30, -0.30, 1.0965]", "initial: {xyz: [0.30, 0.30, 1.0965]");
  if (stand_between_arms) {
    replace_once(text, "suction_tool_pose: {xyz: [0.30, -0.72, 1.229]",
                 "suction_tool_pose: {xyz: [0.25, 0.05, 1.229]");
  }
  return test::write_file(dir, "product.yaml", text);
}

// The steps chain (each arm's from where it last stopped) and are valid; the events in order as
// "arm:event".
std::string events_of(const online::BoardPlan& plan, Eigen::VectorXd& robot_q,
                      const core::Cell& cell) {
  std::string events;
  double clock = 0.0;
  for (const auto& step : plan.steps) {
    EXPECT_GE(step.time.front(), clock - 1e-9) << step.name << " starts before the last ends";
    clock = step.time.back();
    const core::Arm& arm = cell.arm(step.arm);
    EXPECT_TRUE(step.q.front().isApprox(cell.arm_joints(robot_q, arm), 1e-9)) << step.name;
    cell.set_arm(robot_q, arm, step.q.back());
    EXPECT_TRUE(step.validation.valid()) << step.name;
    if (const std::string e = online::events_text(step); !e.empty())
      events += step.arm + ":" + e + " ";
  }
  return events;
}

// The product built with the quick settings and 500 candidates (the left side has few
// comfortable candidates among the quick build's 60), loaded.
std::shared_ptr<const online::PlannerModel> build_and_load(const std::string& dir,
                                                           const std::string& product) {
  offline::BuildSettings settings = test::quick_build_settings(7, 2);
  settings.handover.candidates = 500;
  settings.handover.max_candidates = 500;
  const std::string db_path = dir + "/cabinet.hila";
  offline::build_database(product, test::cell_path(), db_path, settings);
  return online::PlannerModel::load(db_path, test::cell_path(), product);
}

}  // namespace

TEST(SwappedRoles, ABoardOnlyTheLeftArmPicksBySuctionIsDeliveredByTheRightArm) {
  const std::string dir = test::temp_dir("swapped_roles");
  const auto model = build_and_load(dir, product_with_a_board_on_the_left(dir));
  ASSERT_EQ(model->suction_arm("back_upper"), "left")
      << model->database().handover_stage(model->board_records("back_upper")->part.id)->failure;
  ASSERT_EQ(model->suction_arm("top"), "right");

  // The boards before top are assembled; the right arm holds the tool, as after them.
  online::Scene scene = online::nominal_scene(model->cell(), model->product());
  for (const auto& part : model->product().parts) {
    if (part.name == "top") break;
    scene = scene.with_finished(model->product(), part.name);
  }
  scene.tool_in_hand = true;
  scene.tool_arm = "right";
  online::BoardPlanner planner(*model);

  // back_upper now, the tool in the right hand: the right arm puts it back on its stand and goes
  // home first, then the left arm takes it, as below.
  {
    const online::Scene early = scene.with_finished(model->product(), "top");
    const online::BoardPlan first = planner.plan(early, "back_upper", in_seconds(60));
    ASSERT_TRUE(first.solved()) << first.reason;
    EXPECT_TRUE(first.validated);
    EXPECT_EQ(first.suction_arm, "left");
    EXPECT_EQ(first.tool_move_arm, "right");
    EXPECT_FALSE(first.tool_taken_from_table);
    ASSERT_TRUE(first.tool_place);
    EXPECT_TRUE(first.tool_place->isApprox(early.tool, 1e-12));  // the left arm reaches the stand
    ASSERT_EQ(first.tool_move_steps, 4);
    for (int i = 0; i < first.tool_move_steps; ++i) EXPECT_EQ(first.steps[i].arm, "right");
    EXPECT_EQ(first.steps[3].name, "tool_to_home_empty");
    Eigen::VectorXd q = model->cell().home_configuration();
    const std::string events = events_of(first, q, model->cell());
    EXPECT_EQ(events.rfind("right:tool_released left:tool_grasped left:suction_on ", 0), 0u)
        << events;
    EXPECT_NE(events.find("right:wait_for_human right:gripper_open"), std::string::npos) << events;
    EXPECT_NEAR(first.duration, first.steps.back().time.back(), 1e-12);
  }

  // top, the tool put back at the end.
  online::BoardPlanOptions options;
  options.return_tool = true;
  const online::BoardPlan top = planner.plan(scene, "top", in_seconds(60), options);
  ASSERT_TRUE(top.solved()) << top.reason;
  EXPECT_TRUE(top.validated);
  EXPECT_TRUE(top.tool_kept.empty()) << top.tool_kept;
  EXPECT_FALSE(top.tool_in_hand_after);
  EXPECT_EQ(top.suction_arm, "right");
  Eigen::VectorXd robot_q = model->cell().home_configuration();
  const std::string top_events = events_of(top, robot_q, model->cell());
  EXPECT_EQ(top_events.substr(top_events.size() - std::string("right:tool_released ").size()),
            "right:tool_released ")
      << top_events;
  EXPECT_EQ(top.steps.back().name, "tool_to_home_empty");
  EXPECT_TRUE(robot_q.isApprox(model->cell().home_configuration(), 1e-9));
  EXPECT_NEAR(top.duration, top.steps.back().time.back(), 1e-12);

  // back_upper: the left arm takes the tool from its stand and picks, the right arm delivers.
  scene = scene.with_finished(model->product(), "top");
  scene.tool_in_hand = top.tool_in_hand_after;
  scene.tool_arm = top.suction_arm;
  const online::BoardPlan plan = planner.plan(scene, "back_upper", in_seconds(60));
  ASSERT_TRUE(plan.solved()) << plan.reason;
  EXPECT_TRUE(plan.validated);
  EXPECT_EQ(plan.mode, online::DeliveryMode::kExchange);
  EXPECT_EQ(plan.picking_arm, "left");
  EXPECT_EQ(plan.delivering_arm, "right");
  EXPECT_EQ(plan.suction_arm, "left");
  robot_q = model->cell().home_configuration();
  const std::string events = events_of(plan, robot_q, model->cell());
  EXPECT_EQ(events.rfind("left:tool_grasped left:suction_on ", 0), 0u) << events;
  EXPECT_NE(events.find("right:gripper_close left:suction_off "), std::string::npos) << events;
  EXPECT_NE(events.find("right:wait_for_human right:gripper_open"), std::string::npos) << events;
}

// The same board with the tool on the cabinet's own stand, which the left arm does not reach: the
// build keeps the left arm's suction for back_upper because the tool has a relay both arms reach
// (offline::find_tool_relay); online the right arm takes the tool from its stand and sets it down
// there first, then the left arm takes it and picks. The next scene has the tool at the relay.
TEST(SwappedRoles, TheRightArmCarriesTheToolToTheRelayWhereTheLeftArmTakesIt) {
  const std::string dir = test::temp_dir("tool_relay");
  const auto model = build_and_load(dir, product_with_a_board_on_the_left(dir, false));
  const core::ProductSpec& spec = model->product();
  std::size_t index = 0;
  while (spec.parts[index].name != "back_upper") ++index;
  // Without the relay the left arm could not have the tool: it does not reach the stand.
  const offline::HandoverSettings handover;
  ASSERT_FALSE(offline::reaches_tool_stand(model->cell(), spec, index, "left",
                                           handover.exchange_approach, handover.pick_lift));
  ASSERT_TRUE(model->tool_relay());
  ASSERT_EQ(model->suction_arm("back_upper"), "left")
      << model->database().handover_stage(model->board_records("back_upper")->part.id)->failure;

  // Every board before back_upper assembled, the tool on its stand.
  online::Scene scene = online::nominal_scene(model->cell(), spec);
  for (std::size_t i = 0; i < index; ++i) scene = scene.with_finished(spec, spec.parts[i].name);
  ASSERT_FALSE(scene.tool_in_hand);
  online::BoardPlanner planner(*model);
  const online::BoardPlan plan = planner.plan(scene, "back_upper", in_seconds(60));
  std::string attempts;
  for (const auto& a : plan.attempts) attempts += "\n  " + a.arm + ": " + a.outcome;
  ASSERT_TRUE(plan.solved()) << plan.reason << attempts;
  EXPECT_TRUE(plan.validated);
  EXPECT_EQ(plan.picking_arm, "left");
  EXPECT_EQ(plan.tool_move_arm, "right");
  EXPECT_TRUE(plan.tool_taken_from_table);
  ASSERT_TRUE(plan.tool_place);
  EXPECT_TRUE(plan.tool_place->isApprox(*model->tool_relay(), 1e-12));
  ASSERT_GE(plan.tool_move_steps, 6);
  Eigen::VectorXd robot_q = model->cell().home_configuration();
  const std::string events = events_of(plan, robot_q, model->cell());
  EXPECT_EQ(
      events.rfind("right:tool_grasped right:tool_released left:tool_grasped left:suction_on ", 0),
      0u)
      << events;
  // Where the right arm let go, by its joints' FK: the handle at the relay; and the left arm
  // grasps it there.
  const core::Pose handle_in_tcp = model->cell().spec().suction.handle_in_tcp;
  auto handle_after = [&](const online::PlanStep& step) {
    const core::Arm& arm = model->cell().arm(step.arm);
    return core::arm_base_in_world(model->cell(), arm) * arm.chain.fk(step.q.back()) *
           handle_in_tcp;
  };
  for (const auto& step : plan.steps) {
    if (step.end_event == online::StepEvent::kToolReleased && step.arm == "right") {
      EXPECT_TRUE(handle_after(step).isApprox(*plan.tool_place, 1e-6)) << step.name;
    }
    if (step.end_event == online::StepEvent::kToolGrasped && step.arm == "left") {
      EXPECT_TRUE(handle_after(step).isApprox(*plan.tool_place, 1e-6)) << step.name;
    }
  }
  EXPECT_EQ(plan.steps[static_cast<std::size_t>(plan.tool_move_steps) - 1].name,
            "tool_to_home_empty");
  EXPECT_NEAR(plan.duration, plan.steps.back().time.back(), 1e-12);
}
