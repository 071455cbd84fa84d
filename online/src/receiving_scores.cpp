#include "hila/online/receiving_scores.hpp"

#include <string>
#include <utility>
#include <vector>

namespace hila::online {

ReceivingScores receiving_scores(const core::Cell& cell, const BoardPlan& plan, double load_kg) {
  if (plan.human_arm.empty() || plan.human_joints.size() == 0) return {};
  std::vector<std::pair<std::string, Eigen::VectorXd>> arms{{plan.human_arm, plan.human_joints}};
  if (!plan.second_human_arm.empty()) {
    if (plan.second_human_joints.size() == 0) return {};
    arms.emplace_back(plan.second_human_arm, plan.second_human_joints);
  }
  return receiving_scores(cell, plan.worker.get(), arms, load_kg);
}

}  // namespace hila::online
