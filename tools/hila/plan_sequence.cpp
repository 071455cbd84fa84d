#include "plan_sequence.hpp"

#include <chrono>

namespace hila::tools {

std::vector<std::string> boards_to_plan(const online::PlannerModel& model,
                                        const online::Scene& scene) {
  std::vector<std::string> boards;
  for (const auto& p : model.product().parts) {
    if (!scene.is_finished(p.name)) boards.push_back(p.name);
  }
  return boards;
}

void plan_in_sequence(
    const online::PlannerModel& model, online::BoardPlanner& planner, online::Scene scene,
    const std::vector<std::string>& boards, double deadline_s,
    const std::function<void(const online::BoardPlan&, const online::Scene&)>& planned) {
  for (const std::string& board : boards) {
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::microseconds(static_cast<long>(deadline_s * 1e6));
    // Where the suction arm cannot take the tool where it is, the plan begins with the other arm
    // setting it down where it can (BoardPlan::tool_place).
    const online::BoardPlan plan = planner.plan(scene, board, deadline);
    planned(plan, scene);
    // A board the robot cannot handle is assembled by hand: the next boards' scenes have it
    // finished, so one failure does not hide whether the rest can be planned.
    scene = scene.with_finished(model.product(), board);
    if (plan.solved()) {
      scene.tool_in_hand = plan.tool_in_hand_after;
      scene.tool_arm = plan.suction_arm;
      if (plan.tool_place) scene.tool = *plan.tool_place;
    }
    for (const auto& arm : model.cell().arms()) scene.robot[arm.spec.name] = arm.spec.home;
  }
}

}  // namespace hila::tools
