#include "hila/online/receiving_scores.hpp"

#include <utility>

namespace hila::online {

ReceivingScores receiving_scores(const core::Cell& cell, const BoardPlan& plan, double load_kg) {
  ReceivingScores r;
  if (plan.human_arm.empty() || plan.human_joints.size() == 0) return r;
  std::vector<std::pair<std::string, Eigen::VectorXd>> arms{{plan.human_arm, plan.human_joints}};
  if (!plan.second_human_arm.empty()) {
    if (plan.second_human_joints.size() == 0) return r;
    arms.emplace_back(plan.second_human_arm, plan.second_human_joints);
  }
  // Both hands hold the board at once: one configuration, of the worker's body where the plan
  // was made for one.
  const Eigen::VectorXd q =
      plan.worker != nullptr ? plan.worker->posture(arms) : core::human_posture(cell, arms);
  const core::RobotModel& human = plan.worker != nullptr ? plan.worker->model() : cell.human();
  r.two_hands = arms.size() > 1;
  r.load_kg = load_kg;
  for (const auto& [arm, joints] : arms) {
    HandScores h;
    h.arm = arm;
    h.rula_inputs = core::rula_inputs_from_posture(human, q, arm, load_kg, r.two_hands);
    h.rula = core::rula(h.rula_inputs);
    h.reba_inputs = core::reba_inputs_from_posture(human, q, arm, load_kg);
    h.reba = core::reba(h.reba_inputs);
    r.hands.push_back(std::move(h));
  }
  r.worst_rula = 0;
  r.worst_reba = 0;
  for (int i = 1; i < static_cast<int>(r.hands.size()); ++i) {
    const auto& h = r.hands[static_cast<std::size_t>(i)];
    if (h.rula.grand > r.rula().grand) r.worst_rula = i;
    if (h.reba.reba > r.reba().reba) r.worst_reba = i;
  }
  r.scored = true;
  return r;
}

}  // namespace hila::online
