// The regrasp way: one arm's gripper picks the board where it lies (the direct way's pick), sets
// it down on the table on another resting pose, lets go, and it (or, for a relay, the other arm
// once the first is home) takes it again with the grasp that serves the goal and delivers it.
// Each stage memoised by its table regrasp record.

#include <iterator>

#include "plan_run.hpp"

namespace hila::online::detail {

std::string Run::regrasp_chain(const db::HandoverCandidateRecord& goal,
                               const db::TableRegraspRecord& regrasp, std::vector<PlanStep>& steps,
                               ArmsState& end) {
  const auto first_it = robot_grasps_.find(regrasp.pick_grasp_id);
  const auto again_it = robot_grasps_.find(regrasp.robot_grasp_id);
  const core::Arm* arm = arm_named(regrasp.arm);
  const core::Arm* again_arm = arm_named(regrasp.repick_arm);
  if (first_it == robot_grasps_.end() || again_it == robot_grasps_.end() || arm == nullptr ||
      again_arm == nullptr) {
    return "the database's table regrasp refers to a missing record";
  }
  const db::RobotGraspRecord& first = first_it->second;
  const db::RobotGraspRecord& again = again_it->second;
  // The pick is the direct way's, memoised by arm and grasp; the record gives its IK branch.
  db::DirectGraspRecord pick;
  pick.robot_grasp_id = first.id;
  pick.arm = regrasp.arm;
  pick.joints_pick = regrasp.joints_pick;
  const bool sets_tool_down = arm == &suction_ && start_.tool_in_hand;
  // A relay to the suction arm: it sets its tool down once the part is set down.
  const bool relay_tool_down = arm != &suction_ && again_arm == &suction_ && start_.tool_in_hand;
  const Stage* stages[7] = {};
  const auto plan_stages = [&] {
    stages[0] = sets_tool_down ? &tool_down() : nullptr;
    if (stages[0] != nullptr && !stages[0]->ok()) return;
    stages[1] = &gripper_pick(*arm, first, pick);
    if (!stages[1]->ok()) return;
    stages[2] = &set_down(*arm, first, regrasp, *stages[1]);
    if (!stages[2]->ok()) return;
    const Stage* before = stages[2];
    if (relay_tool_down) {
      stages[3] = &tool_down_after_set_down(regrasp, *stages[2]);
      if (!stages[3]->ok()) return;
      before = stages[3];
    }
    // The stages from the repick on, after the set-down (and the tool's) in the chain.
    const std::size_t k = relay_tool_down ? 4 : 3;
    stages[k] = &repick(*again_arm, again, regrasp, *before);
    if (!stages[k]->ok()) return;
    stages[k + 1] = &regrasp_present(*again_arm, again, goal, regrasp, *stages[k]);
    if (stages[k + 1]->ok()) {
      stages[k + 2] = &regrasp_leave(*again_arm, goal, regrasp, *stages[k + 1]);
    }
  };
  // The chain's stages only: settle() reads a null as a chain stopped before it.
  const std::span<const Stage*> chain(stages, relay_tool_down ? 7 : 6);
  plan_settled(chain, sets_tool_down ? 0 : 1, plan_stages);
  return join_stages(chain, steps, end);
}

const Stage& Run::set_down(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                           const db::TableRegraspRecord& regrasp, const Stage& picked) {
  const auto found = set_downs_.find(regrasp.id);
  if (found != set_downs_.end()) return found->second;
  Stage& st = set_downs_[regrasp.id];
  st.end = picked.end;
  ArmMotionPlanner& planner = planner_of(arm);
  const core::Pose tcp = regrasp.placement * grasp.tcp;
  const core::Pose above = shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
  MotionRequest standing;
  standing.board_world = regrasp.placement;
  MotionRequest carry;
  carry.held = in_gripper(grasp);
  const Eigen::VectorXd up = arm_q(st, arm);
  // The open gripper around the board set down (as a pick sees it), its way out, and above it
  // the board held.
  Stage open = st;
  cell_.set_jaw(open.end.robot_q, arm, cell_.spec().gripper.jaw_max);
  std::optional<Eigen::VectorXd> at, out, over;
  for (const auto& q : solutions(cell_, arm, tcp, up, &regrasp.joints_place)) {
    if (!first_valid(open, planner, standing, {q})) continue;
    const auto back = pre_grasp(open, arm, standing, q);
    const auto o = solutions(cell_, arm, above, q);
    if (!back || o.empty() || !first_valid(st, planner, carry, {o.front()})) continue;
    at = q;
    out = *back;
    over = o.front();
    break;
  }
  if (!at) {
    st.failure =
        "set_down: no IK branch with a way down, the board set down and a way out at the "
        "set-down pose";
    return st;
  }
  MotionRequest to = carry;
  to.start = up;
  to.goal = *over;
  to.filter = filter_for(arm, "gripper", grasp.id);
  if (auto e = step(st, planner, arm, to, "set_down_transfer"); !e.empty()) {
    st.failure = e;
    return st;
  }
  MotionRequest down = carry;
  down.start = *over;
  down.goal = *at;
  down.end_in_contact = true;  // the board meets the table at the last sample
  if (auto e =
          step(st, planner, arm, down, "set_down_lower", StepEvent::kNone, StepEvent::kSetDown);
      !e.empty()) {
    st.failure = e;
    return st;
  }
  cell_.set_jaw(st.end.robot_q, arm, cell_.spec().gripper.jaw_max);
  MotionRequest back = standing;
  back.start = *at;
  back.goal = *out;
  if (auto e = step(st, planner, arm, back, "set_down_retreat"); !e.empty()) {
    st.failure = e;
    return st;
  }
  // A relay: the arm goes home, out of the other arm's way.
  if (regrasp.repick_arm != arm.spec.name) {
    MotionRequest home = standing;
    home.start = *out;
    home.goal = arm.spec.home;
    if (auto e = step(st, planner, arm, home, "set_down_arm_home"); !e.empty()) {
      st.failure = e;
    }
  }
  return st;
}

const Stage& Run::tool_down_after_set_down(const db::TableRegraspRecord& regrasp,
                                           const Stage& set) {
  const auto found = relay_tool_downs_.find(regrasp.id);
  if (found != relay_tool_downs_.end()) return found->second;
  Stage& st = relay_tool_downs_[regrasp.id];
  st.end = set.end;
  put_tool_down(st, regrasp.placement);
  return st;
}

const Stage& Run::repick(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                         const db::TableRegraspRecord& regrasp, const Stage& set) {
  const auto found = repicks_.find(regrasp.id);
  if (found != repicks_.end()) return found->second;
  Stage& st = repicks_[regrasp.id];
  st.end = set.end;
  take(st, arm, grasp, regrasp.placement, regrasp.joints_repick, true);
  return st;
}

const Stage& Run::regrasp_present(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                                  const db::HandoverCandidateRecord& goal,
                                  const db::TableRegraspRecord& regrasp, const Stage& taken) {
  const auto found = regrasp_presents_.find(regrasp.id);
  if (found != regrasp_presents_.end()) return found->second;
  Stage& st = regrasp_presents_[regrasp.id];
  st.end = taken.end;
  present_held(st, arm, grasp, goal, regrasp.joints_rh);
  return st;
}

const Stage& Run::regrasp_leave(const core::Arm& arm, const db::HandoverCandidateRecord& goal,
                                const db::TableRegraspRecord& regrasp, const Stage& presented) {
  const auto found = regrasp_leaves_.find(regrasp.id);
  if (found != regrasp_leaves_.end()) return found->second;
  Stage& st = regrasp_leaves_[regrasp.id];
  st.end = presented.end;
  st.failure = retreat(st, arm, goal, "arm_home", {{&presented, kWayBackSteps[0]}});
  return st;
}

}  // namespace hila::online::detail
