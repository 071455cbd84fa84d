#include <gtest/gtest.h>

#include <cstdlib>
#include <map>

#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// The cabinet database the test plans from: the default build with a smaller roadmap, or a
// prebuilt one named by HILA_TEST_DATABASE (e.g. tools/demo's out/cabinet.hila).
std::string database(const std::string& dir) {
  if (const char* given = std::getenv("HILA_TEST_DATABASE")) return given;
  // The default build with a smaller roadmap (the full one takes minutes).
  offline::BuildSettings s;
  s.jobs = 2;
  s.roadmap.nodes = 1200;
  const std::string out = dir + "/cabinet.hila";
  offline::build_database(test::product_path(), test::cell_path(), out, s);
  return out;
}

std::chrono::steady_clock::time_point in_seconds(double s) {
  return std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(s * 1e6));
}

}  // namespace

// Issue 6 asks for all seven boards; at this stage the first four (base with the tool pick,
// lateral_right, back_lower, shelf_middle) plan and lateral_left does not yet (docs/online.md).
// Each solved plan is checked here: every step's report from the independent validator,
// continuity from step to step per arm, increasing times, the handover events in order, both
// arms home at the end.
TEST(BoardPlanner, TheFirstCabinetBoardsPlanEndToEndAndEveryStepValidates) {
  const std::string dir = test::temp_dir("board_planner");
  const auto model =
      online::PlannerModel::load(database(dir), test::cell_path(), test::product_path());
  online::BoardPlanner planner(*model);
  online::Scene scene =
      online::load_scene(test::data_path("cabinet/scene.yaml"), model->cell(), model->product());
  std::vector<std::string> solved;
  for (const auto& part : model->product().parts) {
    SCOPED_TRACE(part.name);
    const online::World world(model->cell(), model->product(), scene, part.name);
    const auto plan = planner.plan(scene, part.name, in_seconds(120.0));  // a bound, not a goal
    std::string attempts;
    for (const auto& a : plan.attempts)
      attempts += "\n  rank " + std::to_string(a.rank) + ": " + a.outcome;
    std::printf("%s: %s %s in %.1f ms, %zu steps, %zu attempts%s\n", part.name.c_str(),
                online::to_string(plan.status), plan.reason.c_str(), 1e3 * plan.planning_seconds,
                plan.steps.size(), plan.attempts.size(), attempts.c_str());
    if (!plan.solved()) break;
    solved.push_back(part.name);
    EXPECT_TRUE(plan.validated);
    EXPECT_FALSE(plan.attempts.empty());
    EXPECT_EQ(plan.attempts.back().outcome, "planned");
    EXPECT_LE(plan.theta_c_deg, 90.0);
    std::map<std::string, Eigen::VectorXd> at;  // each arm's joints as the plan goes
    for (const auto& [arm, q] : scene.robot) at[arm] = q;
    double clock = 0.0;
    std::string events;
    for (const auto& step : plan.steps) {
      ASSERT_FALSE(step.q.empty()) << step.name;
      EXPECT_TRUE(step.q.front().isApprox(at.at(step.arm), 1e-9))
          << step.name << " starts elsewhere";
      EXPECT_GE(step.time.front(), clock - 1e-12) << step.name;
      clock = step.time.back();
      at[step.arm] = step.q.back();
      if (!step.event.empty()) events += step.event + " ";
      EXPECT_TRUE(step.validation.valid()) << step.name;
    }
    // The handover's events in their order.
    const std::vector<std::string> order{"suction_on", "gripper_close", "suction_off",
                                         "wait_for_human", "gripper_open"};
    std::size_t from = 0;
    for (const auto& e : order) {
      const auto found = events.find(e, from);
      EXPECT_NE(found, std::string::npos) << e << " missing or out of order in: " << events;
      if (found != std::string::npos) from = found;
    }
    // Both arms end at home.
    for (const auto& arm : model->cell().arms()) {
      EXPECT_LT((at.at(arm.spec.name) - arm.spec.home).norm(), 1e-9) << arm.spec.name;
    }
    scene = scene.with_finished(model->product(), part.name);
    scene.tool_in_hand = true;
    for (const auto& arm : model->cell().arms()) scene.robot[arm.spec.name] = arm.spec.home;
  }
  ASSERT_GE(solved.size(), 4u);
  EXPECT_EQ(solved[0], "base");
  EXPECT_EQ(solved[3], "shelf_middle");
}
