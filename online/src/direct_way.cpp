// The direct way: one arm's gripper picks the board where it lies and delivers it (no tool, no
// exchange). The suction arm first sets its tool down (tool_down); then the gripper's pick, the
// transfer to the human and the retreat, each memoised by what determines it.

#include <algorithm>
#include <iterator>
#include <span>
#include <tuple>

#include "plan_run.hpp"

namespace hila::online::detail {

std::string Run::direct_chain(const db::HandoverCandidateRecord& goal,
                              const db::DirectGraspRecord& direct, std::vector<PlanStep>& steps,
                              ArmsState& end) {
  const auto grasp_it = robot_grasps_.find(direct.robot_grasp_id);
  const core::Arm* arm = arm_named(direct.arm);
  if (grasp_it == robot_grasps_.end() || arm == nullptr) {
    return "the database's direct grasp refers to a missing record";
  }
  const db::RobotGraspRecord& grasp = grasp_it->second;
  // The suction arm's gripper is free once the tool is set down.
  const bool sets_tool_down = arm == &suction_ && start_.tool_in_hand;
  const Stage* stages[4] = {};
  const auto plan_stages = [&] {
    stages[0] = sets_tool_down ? &tool_down() : nullptr;
    if (stages[0] != nullptr && !stages[0]->ok()) return;
    stages[1] = &gripper_pick(*arm, grasp, direct);
    if (stages[1]->ok()) stages[2] = &direct_present(*arm, grasp, goal, direct);
    if (stages[2] != nullptr && stages[2]->ok()) {
      stages[3] = &direct_leave(*arm, grasp, goal, direct);
    }
  };
  // settle() reads a null as a chain stopped before it: without the tool stage, from the pick.
  plan_settled(stages, sets_tool_down ? 0 : 1, plan_stages);
  return join_stages(stages, steps, end);
}

std::string Run::join_stages(std::span<const Stage* const> stages, std::vector<PlanStep>& steps,
                             ArmsState& end) {
  double clock = 0.0;
  for (std::size_t k = 0; k < stages.size(); ++k) {
    const Stage* stage = stages[k];
    if (stage == nullptr && k == 0) continue;  // the tool stays where it is
    if (stage == nullptr) break;
    if (!stage->ok()) return stage->failure;
    for (PlanStep s : stage->steps) {
      for (double& t : s.time) t += clock;
      steps.push_back(std::move(s));
    }
    if (!steps.empty()) clock = steps.back().time.back();
    end = stage->end;
  }
  return "";
}

const core::Arm* Run::arm_named(const std::string& name) const {
  if (name == suction_.spec.name) return &suction_;
  if (name == receiving_.spec.name) return &receiving_;
  return nullptr;
}

const Stage& Run::tool_down() {
  if (tool_down_) return *tool_down_;
  tool_down_.emplace();
  Stage& st = *tool_down_;
  st.end = start_;
  if (!st.end.tool_in_hand) return st;
  put_tool_down(st, board_initial_);
  return st;
}

void Run::put_tool_down(Stage& st, const core::Pose& board_world) {
  auto fail = [&](std::string why) { st.failure = "tool_place: " + std::move(why); };
  const core::Pose tcp = scene_.tool * cell_.spec().suction.handle_in_tcp.inverse();
  const core::Pose pre = shifted(tcp, -settings_.approach * (tcp.linear() * approach_tcp_));
  const core::Pose raised = shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
  MotionRequest r;
  r.board_world = board_world;
  // At the place the tool stands on the table in the open hand (as the tool pick sees it).
  Stage standing = st;
  standing.end.tool_in_hand = false;
  // The first IK branch at the place whose pose above (holding the tool) and way back (the open
  // hand), each the branch nearest it, are valid too.
  std::optional<Eigen::VectorXd> at;
  std::vector<Eigen::VectorXd> above, before;
  std::string why = "no valid IK at the tool's place";
  for (const auto& q : solutions(cell_, suction_, tcp, suction_.spec.home)) {
    if (!first_valid(standing, suction_planner_, r, {q})) continue;
    above = solutions(cell_, suction_, raised, q);
    before = solutions(cell_, suction_, pre, q);
    if (above.empty() || !first_valid(st, suction_planner_, r, {above.front()})) {
      why = "no valid IK above the tool's place";
      continue;
    }
    if (before.empty() || !first_valid(standing, suction_planner_, r, {before.front()})) {
      why = "no valid IK to back off from the tool's handle";
      continue;
    }
    at = q;
    break;
  }
  if (!at) return fail(why);
  MotionRequest to = r;
  to.start = arm_q(st, suction_);
  to.goal = above.front();
  if (auto e = step(st, suction_planner_, suction_, to, "tool_to_place"); !e.empty()) {
    st.failure = e;
    return;
  }
  MotionRequest down = r;
  down.start = above.front();
  down.goal = *at;
  down.end_in_contact = true;
  if (auto e = step(st, suction_planner_, suction_, down, "tool_lower", StepEvent::kNone,
                    StepEvent::kToolReleased);
      !e.empty()) {
    st.failure = e;
    return;
  }
  st.end.tool_in_hand = false;
  cell_.set_jaw(st.end.robot_q, suction_, cell_.spec().gripper.jaw_max);
  MotionRequest back = r;
  back.start = *at;
  back.goal = before.front();
  if (auto e = step(st, suction_planner_, suction_, back, "tool_retreat"); !e.empty()) {
    st.failure = e;
  }
}

namespace {

// The stage's steps appended to `steps` with their times after the last one's, `end` its end.
void append_after(const Stage& st, std::vector<PlanStep>& steps, ArmsState& end) {
  const double clock = steps.empty() ? 0.0 : steps.back().time.back();
  for (PlanStep s : st.steps) {
    for (double& t : s.time) t += clock;
    steps.push_back(std::move(s));
  }
  end = st.end;
}

}  // namespace

std::string Run::return_tool(const core::Pose& board_world, std::vector<PlanStep>& steps,
                             ArmsState& end) {
  if (!end.tool_in_hand) return "";
  const Stage* stages[1] = {};
  plan_settled(stages, 0, [&] {
    if (tool_return_ && queue_) abandon(*tool_return_);  // re-planned after a late rejection
    Stage& st = tool_return_.emplace();
    st.end = end;
    put_tool_down(st, board_world);
    if (st.ok()) {
      MotionRequest home;
      home.board_world = board_world;
      home.start = arm_q(st, suction_);
      home.goal = suction_.spec.home;
      if (auto e = step(st, suction_planner_, suction_, home, "tool_to_home_empty"); !e.empty()) {
        st.failure = e;
      }
    }
    stages[0] = &st;
  });
  const Stage& st = *tool_return_;
  if (!st.ok()) return st.failure;
  append_after(st, steps, end);
  return "";
}

std::string Run::take_tool(std::vector<PlanStep>& steps, ArmsState& end) {
  const Stage* stages[1] = {};
  plan_settled(stages, 0, [&] { stages[0] = &tool(); });
  const Stage& st = *tool_;
  if (!st.ok()) return st.failure;
  append_after(st, steps, end);
  return "";
}

const Stage& Run::gripper_pick(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                               const db::DirectGraspRecord& direct) {
  const auto key = std::make_pair(arm.spec.name, grasp.id);
  const auto found = gripper_picks_.find(key);
  if (found != gripper_picks_.end()) return found->second;
  Stage& st = gripper_picks_[key];
  st.end = &arm == &suction_ && start_.tool_in_hand ? tool_down().end : start_;
  take(st, arm, grasp, board_initial_, direct.joints_pick, false);
  return st;
}

void Run::take(Stage& st, const core::Arm& arm, const db::RobotGraspRecord& grasp,
               const core::Pose& board, const Eigen::VectorXd& preferred, bool again) {
  const std::string what = again ? "regrasp_pick" : "gripper_pick";
  if (&arm == &suction_ && st.end.tool_in_hand) {
    st.failure = what + ": the " + arm.spec.name + " arm holds the suction tool";
    return;
  }
  ArmMotionPlanner& planner = planner_of(arm);
  const core::Pose tcp = board * grasp.tcp;
  const core::Pose lifted = shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
  MotionRequest standing;
  standing.board_world = board;
  MotionRequest carry;
  carry.held = in_gripper(grasp);
  const Eigen::VectorXd now = arm_q(st, arm);
  std::optional<Eigen::VectorXd> at, before, up;
  for (const auto& q : solutions(cell_, arm, tcp, now, &preferred)) {
    if (!first_valid(st, planner, standing, {q})) continue;
    const auto pre = pre_grasp(st, arm, standing, q);
    const auto l = solutions(cell_, arm, lifted, q);
    if (!pre || l.empty()) continue;
    Stage holding = st;
    cell_.set_jaw(holding.end.robot_q, arm, jaw_for(grasp));
    if (!first_valid(holding, planner, carry, {l.front()})) continue;
    at = q;
    before = *pre;
    up = l.front();
    break;
  }
  if (!at) {
    st.failure = what + ": no IK branch with a way in, a valid grasp and lift at the " +
                 (again ? "set-down" : "detected") + " board pose";
    return;
  }
  MotionRequest r = standing;
  r.start = now;
  r.goal = *before;
  if (auto e = step(st, planner, arm, r, again ? "regrasp_approach" : "gripper_approach");
      !e.empty()) {
    st.failure = e;
    return;
  }
  r.start = *before;
  r.goal = *at;
  if (auto e = step(st, planner, arm, r, again ? "regrasp_grasp" : "gripper_grasp",
                    StepEvent::kNone, StepEvent::kGripperClose);
      !e.empty()) {
    st.failure = e;
    return;
  }
  cell_.set_jaw(st.end.robot_q, arm, jaw_for(grasp));
  carry.start = *at;
  carry.goal = *up;
  carry.start_in_contact = true;  // the board still rests where it was detected or set down
  if (auto e = step(st, planner, arm, carry, again ? "regrasp_lift" : "lift"); !e.empty()) {
    st.failure = e;
  }
}

const Stage& Run::direct_present(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                                 const db::HandoverCandidateRecord& goal,
                                 const db::DirectGraspRecord& direct) {
  const auto key = std::make_tuple(arm.spec.name, grasp.id, goal.id);
  const auto found = direct_presents_.find(key);
  if (found != direct_presents_.end()) return found->second;
  Stage& st = direct_presents_[key];
  st.end = gripper_pick(arm, grasp, direct).end;
  present_held(st, arm, grasp, goal, direct.joints_rh);
  return st;
}

void Run::present_held(Stage& st, const core::Arm& arm, const db::RobotGraspRecord& grasp,
                       const db::HandoverCandidateRecord& goal, const Eigen::VectorXd& preferred) {
  ArmMotionPlanner& planner = planner_of(arm);
  MotionRequest present;
  present.held = in_gripper(grasp);
  const Eigen::VectorXd up = arm_q(st, arm);
  const auto rh_q = first_valid(st, planner, present,
                                solutions(cell_, arm, goal.board * grasp.tcp, up, &preferred));
  if (!rh_q) {
    st.failure = kNoHumanPoseIk;
    return;
  }
  present.start = up;
  present.goal = *rh_q;
  present.filter = filter_for(arm, "gripper", grasp.id);
  if (auto e = step(st, planner, arm, present, "transfer_to_human", StepEvent::kNone,
                    StepEvent::kWaitForHuman);
      !e.empty()) {
    st.failure = e;
  }
}

const Stage& Run::direct_leave(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                               const db::HandoverCandidateRecord& goal,
                               const db::DirectGraspRecord& direct) {
  const auto key = std::make_tuple(arm.spec.name, grasp.id, goal.id);
  const auto found = direct_leaves_.find(key);
  if (found != direct_leaves_.end()) return found->second;
  Stage& st = direct_leaves_[key];
  const Stage& presented = direct_present(arm, grasp, goal, direct);
  st.end = presented.end;
  st.failure = retreat(st, arm, goal, "arm_home", {{&presented, kWayBackSteps[0]}});
  return st;
}

}  // namespace hila::online::detail
