#include "hila/online/worker_comfort.hpp"

#include <algorithm>

#include "hila/core/error.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::online {

WorkerComfort::WorkerComfort(const core::Cell& cell, const std::vector<db::ComfortMapRecord>& maps,
                             const std::string& database_path) {
  std::vector<core::Pose> links;
  cell.human().link_poses(cell.human_neutral(), links);
  for (const auto& arm : cell.human_arms()) {
    const auto it = std::find_if(maps.begin(), maps.end(),
                                 [&](const auto& m) { return m.arm == arm.spec.name; });
    if (it == maps.end()) {
      throw core::InputError(database_path, "comfort_maps",
                             "a comfort map for the human arm '" + arm.spec.name + "'",
                             "none (rebuild the database with hila build)");
    }
    arms_.push_back(
        Arm{arm.spec.name,
            core::ComfortMap::from_grid(it->origin, it->spacing, it->dims, it->orientations,
                                        it->values, it->coverage),
            links[static_cast<std::size_t>(cell.human().link_index(arm.spec.base_link))]});
  }
}

const WorkerComfort::Arm* WorkerComfort::arm(const std::string& name) const {
  for (const auto& a : arms_) {
    if (a.name == name) return &a;
  }
  return nullptr;
}

WorkerComfort::GoalReach WorkerComfort::goal_reach(
    const core::Cell& cell, const db::HandoverCandidateRecord& goal,
    const std::map<std::int64_t, db::HumanGraspRecord>& human_grasps, const core::Pose& stance,
    const core::HumanBody* body, const core::ComfortSettings& ik) {
  auto hand = [&](const std::string& name, std::int64_t grasp_id, const Eigen::VectorXd& built) {
    const auto it = human_grasps.find(grasp_id);
    if (it == human_grasps.end()) return core::ComfortResult{};
    return core::reach_hand(cell, body, stance, name, goal.board * it->second.hand, built, ik);
  };
  GoalReach r;
  if (goal.human_arm.empty()) return r;
  const core::ComfortResult first = hand(goal.human_arm, goal.human_grasp_id, goal.human_joints);
  if (!first.reachable) return r;
  r.quality = first.quality;
  r.joints = first.joints;
  if (!goal.second_arm.empty()) {
    const core::ComfortResult second =
        hand(goal.second_arm, goal.second_grasp_id, goal.second_joints);
    if (!second.reachable) return GoalReach{};
    r.quality = std::min(r.quality, second.quality);
    r.second_joints = second.joints;
  }
  r.reachable = true;
  return r;
}

double WorkerComfort::hand_quality(const std::string& arm, const core::Pose& part,
                                   const core::Pose& hand_in_part, const core::Pose& stance,
                                   const core::HumanBody* body) const {
  const Arm* a = this->arm(arm);
  if (a == nullptr) return 0.0;
  if (body != nullptr) {  // the body's hand in its arm base, moved into the cell arm's map
    const int b = body->arm_index(arm);
    if (b < 0) return 0.0;
    const core::Pose base = stance * body->base_in_stance(b);
    return a->map.lookup(body->to_cell_arm(b, base.inverse() * (part * hand_in_part)));
  }
  // As the build computes it: the arm base in the world, inverted, times the hand in the world.
  const core::Pose base = stance * a->base_in_stance;
  return a->map.lookup(base.inverse() * (part * hand_in_part));
}

double WorkerComfort::goal_quality(const db::HandoverCandidateRecord& goal,
                                   const std::map<std::int64_t, db::HumanGraspRecord>& human_grasps,
                                   const core::Pose& stance, const core::HumanBody* body) const {
  auto hand = [&](const std::string& arm, std::int64_t grasp_id) {
    const auto it = human_grasps.find(grasp_id);
    if (it == human_grasps.end()) return 0.0;
    return hand_quality(arm, goal.board, it->second.hand, stance, body);
  };
  if (goal.human_arm.empty()) return 0.0;
  double q = hand(goal.human_arm, goal.human_grasp_id);
  if (!goal.second_arm.empty()) q = std::min(q, hand(goal.second_arm, goal.second_grasp_id));
  return q;
}

}  // namespace hila::online
