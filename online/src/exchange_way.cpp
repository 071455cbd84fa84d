// The exchange: the suction arm picks the board with the tool and hands it, at a robot-robot
// pose, to the receiving arm's gripper, which delivers it to the human. Its stages, in order and
// each memoised by what determines it: the tool (0), the suction pick (1), the transfer to the
// robot-robot pose (2), the receiving arm's grasp there (3), the suction arm's release (4), the
// transfer to the human (5) and the receiving arm's retreat (6).

#include <algorithm>
#include <cassert>
#include <iterator>
#include <tuple>

#include "hila/core/stage_scene.hpp"
#include "plan_run.hpp"

namespace hila::online::detail {

namespace {

// Two suction grasps hold the board at the same point (m) of the same face (the cosine of the
// angle between their axes): the cup is round, so they differ by a turn about its axis.
constexpr double kSameCupPoint = 1e-6;
constexpr double kSameCupAxis = 1.0 - 1e-9;

}  // namespace

bool Run::connected_offline(const db::HandoverCandidateRecord& goal,
                            const db::SharedGraspRecord& shared) {
  // A connected transfer of the receiving arm, stored by the build, from this exchange with this
  // grasp to this goal (looked up in the index the estimates use).
  return estimate_index().to_human.count(
             {shared.robot_handover_id, shared.robot_grasp_id, goal.id}) > 0;
}

bool Run::exchange_blocked_offline(const db::SharedGraspRecord& shared) {
  const auto rr = handovers_.find(shared.robot_handover_id);
  if (rr == handovers_.end()) return false;
  const EstimateIndex& index = estimate_index();
  return index.exchange_examined.count(rr->first) > 0 &&
         index.to_exchange.count({rr->first, rr->second.suction_grasp_id}) == 0;
}

bool Run::receive_failed_at_same_pose(const db::SharedGraspRecord& shared) const {
  const auto rr = handovers_.find(shared.robot_handover_id);
  if (rr == handovers_.end()) return false;
  for (const auto& [key, stage] : receives_) {
    if (key.second != shared.robot_grasp_id || key.first == shared.robot_handover_id ||
        stage.ok()) {
      continue;
    }
    const auto other = handovers_.find(key.first);
    if (other != handovers_.end() && other->second.board.matrix() == rr->second.board.matrix()) {
      return true;
    }
  }
  return false;
}

std::int64_t Run::suction_grasp_of(const db::RobotHandoverRecord& rr) const {
  const auto found = transfers_.find(rr.id);
  return found == transfers_.end() ? rr.suction_grasp_id : found->second.cup;
}

std::string Run::chain(const db::HandoverCandidateRecord& goal, const db::SharedGraspRecord& shared,
                       std::vector<PlanStep>& steps, ArmsState& end) {
  const auto rr_it = handovers_.find(shared.robot_handover_id);
  if (rr_it == handovers_.end() || suction_grasps_.count(rr_it->second.suction_grasp_id) == 0 ||
      robot_grasps_.count(shared.robot_grasp_id) == 0) {
    return "the database's shared grasp refers to a missing record";
  }
  const db::RobotHandoverRecord& rr = rr_it->second;
  const db::RobotGraspRecord& grasp = robot_grasps_.at(shared.robot_grasp_id);
  const Stage* stages[7] = {};
  const auto plan_stages = [&] {
    stages[0] = &tool();
    // Nothing is planned for a grasp whose goal the receiving arm cannot reach (the present
    // stage's own first check, made first): neither the exchange nor the suction arm's pick and
    // transfer, which fail expensively where the scene moved the exchange out of reach.
    if (stages[0]->ok() && (!settings_.reach_human_pose_first || reaches_human_pose(grasp, goal))) {
      // The transfer chooses the suction grasp (its stand-ins) and plans the pick it follows.
      const Stage& moved = transfer(rr);
      stages[1] = &pick(moved.cup);
      if (stages[1]->ok()) stages[2] = &moved;
    }
    if (stages[2] != nullptr && stages[2]->ok()) stages[3] = &receive(rr, grasp);
    if (stages[3] != nullptr && stages[3]->ok()) stages[4] = &release(rr, grasp);
    if (stages[4] != nullptr && stages[4]->ok()) stages[5] = &present(rr, grasp, goal);
    if (stages[5] != nullptr && stages[5]->ok()) stages[6] = &leave(rr, grasp, goal);
  };
  plan_settled(stages, 0, plan_stages);
  double clock = 0.0;
  std::size_t previous_begin = 0;
  for (const Stage* stage : stages) {
    if (stage == nullptr) {  // the stages before it hold: only the reach check stops so
      assert(settings_.reach_human_pose_first);
      return kNoHumanPoseIk;
    }
    if (!stage->ok()) return stage->failure;
    if (stage->supersedes_previous) {
      steps.resize(previous_begin);
      clock = steps.empty() ? 0.0 : steps.back().time.back();
    }
    previous_begin = steps.size();
    for (PlanStep s : stage->steps) {
      for (double& t : s.time) t += clock;
      steps.push_back(std::move(s));
    }
    if (!steps.empty()) clock = steps.back().time.back();
    end = stage->end;
  }
  return "";
}

const Stage& Run::tool() {
  if (tool_) return *tool_;
  tool_.emplace();
  Stage& st = *tool_;
  st.end = start_;
  if (st.end.tool_in_hand) return st;
  auto fail = [&](std::string why) -> const Stage& {
    st.failure = "tool_pick: " + std::move(why);
    return st;
  };
  const core::Pose tcp = scene_.tool * cell_.spec().suction.handle_in_tcp.inverse();
  const core::Pose pre = shifted(tcp, -settings_.approach * (tcp.linear() * approach_tcp_));
  MotionRequest r;
  r.board_world = board_initial_;
  // The first IK branch at the handle whose way in (the open hand, the branch nearest it) and
  // lift (holding the tool, likewise) are valid too.
  Stage holding = st;
  holding.end.tool_in_hand = true;
  cell_.set_jaw(holding.end.robot_q, suction_, cell_.spec().suction.handle_width);
  const core::Pose up = shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
  std::optional<Eigen::VectorXd> at, before, raised;
  bool any_at = false;
  for (const auto& q : solutions(cell_, suction_, tcp, suction_.spec.home)) {
    if (!first_valid(st, suction_planner_, r, {q})) continue;
    any_at = true;
    const auto in = solutions(cell_, suction_, pre, q);
    const auto lifted = solutions(cell_, suction_, up, q);
    if (in.empty() || lifted.empty() || !first_valid(st, suction_planner_, r, {in.front()}) ||
        !first_valid(holding, suction_planner_, r, {lifted.front()})) {
      continue;
    }
    at = q;
    before = in.front();
    raised = lifted.front();
    break;
  }
  if (!at) {
    return fail(any_at ? "no IK branch at the tool's handle with a valid way in and lift"
                       : "no valid IK at the tool's handle");
  }
  MotionRequest approach = r;
  approach.start = arm_q(st, suction_);
  approach.goal = *before;
  if (auto e = step(st, suction_planner_, suction_, approach, "tool_approach"); !e.empty()) {
    st.failure = e;
    return st;
  }
  MotionRequest in = r;
  in.start = *before;
  in.goal = *at;
  if (auto e = step(st, suction_planner_, suction_, in, "tool_grasp", StepEvent::kNone,
                    StepEvent::kToolGrasped);
      !e.empty()) {
    st.failure = e;
    return st;
  }
  st.end.tool_in_hand = true;
  cell_.set_jaw(st.end.robot_q, suction_, cell_.spec().suction.handle_width);
  MotionRequest lift = r;
  lift.start = *at;
  lift.goal = *raised;
  lift.start_in_contact = true;  // the cup still stands on the table
  if (auto e = step(st, suction_planner_, suction_, lift, "tool_lift"); !e.empty()) {
    st.failure = e;
    return st;
  }
  MotionRequest home = r;
  home.start = *raised;
  home.goal = suction_.spec.home;
  if (auto e = step(st, suction_planner_, suction_, home, "tool_to_home"); !e.empty()) {
    st.failure = e;
  }
  return st;
}

HeldBoard Run::on_cup(const db::SuctionGraspRecord& cup) const {
  HeldBoard h;
  h.held = true;
  h.board_in_tcp = world_.stage().cup_in_tcp * cup.cup.inverse();
  return h;
}

const Stage& Run::pick(std::int64_t cup_id) {
  const auto found = picks_.find(cup_id);
  if (found != picks_.end()) return found->second;
  Stage& st = picks_[cup_id];
  st.end = tool().end;
  const db::SuctionGraspRecord& cup = suction_grasps_.at(cup_id);
  const core::Pose cup_in_tcp = world_.stage().cup_in_tcp;
  const core::Pose cup_world = board_initial_ * cup.cup;
  const core::Pose pick_tcp = cup_world * cup_in_tcp.inverse();
  const Eigen::Vector3d into = cup_world.linear().col(2);  // z into the part
  const core::Pose pre_pick = shifted(pick_tcp, -settings_.approach * into);
  const core::Pose lifted = shifted(pick_tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
  MotionRequest standing;
  standing.board_world = board_initial_;
  MotionRequest carry;
  carry.held = on_cup(cup);
  const auto transits = stored_edges(
      "transit", suction_, [&](const auto& n) { return n.kind == "pick" && n.grasp_id == cup_id; },
      [](const auto&) { return true; });
  const Eigen::VectorXd* preferred = transits.empty() ? nullptr : &transits.front()->path.back();
  const Eigen::VectorXd suction_now = arm_q(st, suction_);
  // Each branch's pre-pick, pick and lift.
  struct Branch {
    Eigen::VectorXd before, at, up;
  };
  std::vector<Branch> branches;
  for (const auto& q : solutions(cell_, suction_, pick_tcp, preferred ? *preferred : suction_now)) {
    if (!first_valid(st, suction_planner_, standing, {q})) continue;
    const auto p = solutions(cell_, suction_, pre_pick, q);
    const auto l = solutions(cell_, suction_, lifted, q);
    if (p.empty() || l.empty() || !first_valid(st, suction_planner_, standing, {p.front()}) ||
        !first_valid(st, suction_planner_, carry, {l.front()})) {
      continue;
    }
    branches.push_back({p.front(), q, l.front()});
  }
  if (branches.empty()) {
    st.failure =
        "suction_pick: no IK branch with a valid approach, pick and lift at the detected board "
        "pose";
    return st;
  }
  const Stage start = st;
  std::string first_failure;
  for (std::size_t b = 0; b < branches.size(); ++b) {
    const Branch& branch = branches[b];
    Stage attempt = start;
    MotionRequest r = standing;
    r.start = suction_now;
    r.goal = branch.before;
    // The stored transits end at the build's branch: they lead only to a branch near it.
    if (b == 0) r.hints = paths_of(transits);
    std::string e = step(attempt, suction_planner_, suction_, r, "suction_approach");
    if (e.empty()) {
      r.hints.clear();
      r.start = branch.before;
      r.goal = branch.at;
      e = step(attempt, suction_planner_, suction_, r, "suction_pick", StepEvent::kNone,
               StepEvent::kSuctionOn);
    }
    if (e.empty()) {
      MotionRequest up = carry;
      up.start = branch.at;
      up.goal = branch.up;
      up.start_in_contact = true;  // the board still rests where it was detected
      e = step(attempt, suction_planner_, suction_, up, "lift");
    }
    if (e.empty()) {
      st = std::move(attempt);
      return st;
    }
    abandon(attempt);
    if (first_failure.empty()) first_failure = e;
    if (attempt.deadline_passed) {
      st.failure = e;
      st.deadline_passed = true;
      return st;
    }
  }
  st.failure = first_failure;
  return st;
}

std::vector<std::int64_t> Run::stand_in_cups(const db::SuctionGraspRecord& cup) const {
  // Rotations between cup frames are those between the TCPs holding them (the same
  // cup-in-TCP on the right).
  const Eigen::Matrix3d nominal = (part_.initial * cup.cup).linear();
  std::vector<std::pair<double, std::int64_t>> turned;
  for (const auto& [id, other] : suction_grasps_) {
    if (id == cup.id || (other.cup.translation() - cup.cup.translation()).norm() > kSameCupPoint ||
        other.cup.linear().col(2).dot(cup.cup.linear().col(2)) < kSameCupAxis) {
      continue;
    }
    const Eigen::Matrix3d here = (board_initial_ * other.cup).linear();
    turned.emplace_back(Eigen::AngleAxisd(nominal.transpose() * here).angle(), id);
  }
  std::sort(turned.begin(), turned.end());
  std::vector<std::int64_t> out{cup.id};
  for (const auto& [angle, id] : turned) out.push_back(id);
  return out;
}

const Stage& Run::transfer(const db::RobotHandoverRecord& rr) {
  if (const auto found = transfers_.find(rr.id); found != transfers_.end()) {
    const Stage& planned = found->second;
    if (!planned.ok()) return planned;
    // A pick planned again after the validator rejected it late may end elsewhere (another
    // branch): the transfer must leave from there.
    const Stage& picked = pick(planned.cup);
    if (picked.ok() && !planned.paths.empty() &&
        planned.paths.front().front() == arm_q(picked, suction_)) {
      return planned;
    }
    abandon(transfers_.at(rr.id));
    transfers_.erase(rr.id);
  }
  forget_after_transfer(rr.id);
  Stage& st = transfers_[rr.id];
  st.cup = rr.suction_grasp_id;
  std::string first_failure;
  for (const std::int64_t cup_id : stand_in_cups(suction_grasps_.at(rr.suction_grasp_id))) {
    const Stage& picked = pick(cup_id);
    std::string e = picked.failure;
    bool deadline_passed = picked.deadline_passed;
    if (picked.ok()) {
      Stage attempt;
      attempt.end = picked.end;
      attempt.cup = cup_id;
      e = transfer_steps(attempt, rr, cup_id);
      if (e.empty()) {
        st = std::move(attempt);
        return st;
      }
      abandon(attempt);
      deadline_passed = attempt.deadline_passed;
    }
    if (first_failure.empty()) first_failure = e;
    if (deadline_passed) {
      st.deadline_passed = true;
      break;
    }
  }
  st.failure = first_failure;
  return st;
}

void Run::forget_after_transfer(std::int64_t rr_id) {
  const auto drop = [&](auto& stages, auto rr_of) {
    for (auto it = stages.begin(); it != stages.end();) {
      if (rr_of(it->first) != rr_id) {
        ++it;
        continue;
      }
      abandon(it->second);
      it = stages.erase(it);
    }
  };
  const auto first = [](const auto& key) { return std::get<0>(key); };
  drop(receives_, first);
  drop(releases_, first);
  drop(presents_, first);
  drop(leaves_, first);
}

std::string Run::transfer_steps(Stage& st, const db::RobotHandoverRecord& rr, std::int64_t cup_id) {
  const db::SuctionGraspRecord& cup = suction_grasps_.at(cup_id);
  const core::Pose rr_tcp = rr.board * cup.cup * world_.stage().cup_in_tcp.inverse();
  const auto stored = stored_edges(
      "transfer", suction_,
      [&](const auto& n) { return n.kind == "robot_handover" && n.robot_handover_id == rr.id; },
      [](const auto&) { return true; });
  MotionRequest carry;
  carry.held = on_cup(cup);
  const Eigen::VectorXd up = arm_q(st, suction_);
  std::vector<Eigen::VectorXd> ends = solutions(
      cell_, suction_, rr_tcp, up, stored.empty() ? nullptr : &stored.front()->path.back());
  if (cup_id != rr.suction_grasp_id) {
    for (auto& q : ends) q = in_roadmap_box(suction_, q);
  }
  const auto rr_q = first_valid(st, suction_planner_, carry, ends);
  if (!rr_q) return "transfer_to_robot_handover: no valid IK at the robot-robot pose";
  carry.start = up;
  carry.goal = *rr_q;
  carry.filter = filter_for(suction_, "suction", cup.id);
  carry.hints = paths_of(stored);
  return step(st, suction_planner_, suction_, carry, "transfer_to_robot_handover");
}

const Stage& Run::receive(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp) {
  const auto key = std::make_pair(rr.id, grasp.id);
  const auto found = receives_.find(key);
  if (found != receives_.end()) return found->second;
  Stage& st = receives_[key];
  st.end = transfer(rr).end;
  const core::Pose grasp_tcp = rr.board * grasp.tcp;
  auto at_exchange = [&](const auto& n) {
    return n.kind == "robot_handover" && n.grasp_id == grasp.id && n.robot_handover_id == rr.id;
  };
  const auto transits =
      stored_edges("transit", receiving_, at_exchange, [](const auto&) { return true; });
  // The branch the offline transfer to the human leaves from, else one a transit reaches.
  const auto onwards = stored_edges(
      "transfer", receiving_, [](const auto&) { return true; }, at_exchange);
  const Eigen::VectorXd* preferred = !onwards.empty()    ? &onwards.front()->path.front()
                                     : !transits.empty() ? &transits.front()->path.back()
                                                         : nullptr;
  MotionRequest reach;
  reach.board_world = rr.board;
  // Every valid branch at the exchange (the preferred first): an arm about to hold a long
  // board under a tight theta_c cannot change branch later, and near the robot's body one
  // branch may be boxed in where another is free. Through the roadmap first, then bridges
  // for the first few, as offline.
  std::vector<Eigen::VectorXd> branches;
  for (const auto& q : solutions(cell_, receiving_, grasp_tcp, receiving_.spec.home, preferred)) {
    if (first_valid(st, receiving_planner_, reach, {q})) branches.push_back(q);
  }
  if (branches.empty()) {
    st.failure = "receiving_grasp: no valid IK at the robot-robot pose";
    return st;
  }
  const Stage before = st;
  std::string first_failure;
  // Through the roadmap first, then (where the board in place blocks every way in) with the
  // receiving arm waiting at its pre-grasp while the suction arm is still at the lift and
  // brings the board to it, and only then with bridges to the board in place: those are
  // planned at the empty arm's resolution beside the held board, and the validator often
  // rejects them, each rejection a bridge's checks spent for nothing.
  const auto direct = [&](bool bridges) {
    for (std::size_t b = 0; b < branches.size(); ++b) {
      if (bridges && static_cast<int>(b) >= settings_.exchange_bridges) break;
      Stage attempt = before;
      const std::string failure = reach_exchange(attempt, rr, grasp, branches[b], bridges,
                                                 bridges ? Hints{} : paths_of(transits));
      if (failure.empty()) {
        st = std::move(attempt);
        cell_.set_jaw(st.end.robot_q, receiving_, jaw_for(grasp));
        return true;
      }
      abandon(attempt);
      if (first_failure.empty()) first_failure = failure;
      if (attempt.deadline_passed) {
        st.failure = failure;
        st.deadline_passed = true;
        return true;
      }
    }
    return false;
  };
  const auto waiting = [&] {
    const Stage& lifted = pick(transfer(rr).cup);
    for (std::size_t b = 0; b < branches.size() && lifted.ok(); ++b) {
      Stage attempt;
      attempt.end = lifted.end;
      if (preposition(attempt, rr, branches[b]).empty()) {
        st = std::move(attempt);
        st.supersedes_previous = true;
        cell_.set_jaw(st.end.robot_q, receiving_, jaw_for(grasp));
        return true;
      }
      abandon(attempt);
    }
    return false;
  };
  if (direct(false) || waiting() || direct(true)) return st;
  st.failure = first_failure;
  return st;
}

std::string Run::preposition(Stage& st, const db::RobotHandoverRecord& rr,
                             const Eigen::VectorXd& grasp_q) {
  MotionRequest at_exchange;
  at_exchange.board_world = rr.board;
  const std::optional<Eigen::VectorXd> pre_q = pre_grasp(st, at_exchange, grasp_q);
  if (!pre_q) return "receiving_approach: no pre-grasp to wait at";
  const std::int64_t cup_id = transfer(rr).cup;
  const db::SuctionGraspRecord& cup = suction_grasps_.at(cup_id);
  const core::Pose up_tcp =
      core::arm_base_in_world(cell_, suction_) * suction_.chain.fk(arm_q(st, suction_));
  MotionRequest wait;
  wait.board_world = up_tcp * on_cup(cup).board_in_tcp;
  wait.start = arm_q(st, receiving_);
  wait.goal = *pre_q;
  if (auto e = step(st, receiving_planner_, receiving_, wait, "receiving_approach"); !e.empty()) {
    return e;
  }
  if (auto e = transfer_steps(st, rr, cup_id); !e.empty()) return e;
  at_exchange.start = *pre_q;
  at_exchange.goal = grasp_q;
  return step(st, receiving_planner_, receiving_, at_exchange, "receiving_grasp", StepEvent::kNone,
              StepEvent::kGripperClose);
}

std::optional<Eigen::VectorXd> Run::pre_grasp(const Stage& st, const MotionRequest& request,
                                              const Eigen::VectorXd& grasp_q) {
  return pre_grasp(st, receiving_, request, grasp_q);
}

std::string Run::reach_exchange(Stage& st, const db::RobotHandoverRecord& rr,
                                const db::RobotGraspRecord& grasp, const Eigen::VectorXd& grasp_q,
                                bool bridges, Hints hints) {
  const core::Pose grasp_tcp = rr.board * grasp.tcp;
  MotionRequest reach;
  reach.board_world = rr.board;
  reach.allow_bridge = bridges;
  const std::optional<Eigen::VectorXd> pre_q = pre_grasp(st, reach, grasp_q);
  // Staging poses for the first motion: further back along the gripper's axis, or above.
  const Eigen::VectorXd& target = pre_q ? *pre_q : grasp_q;
  const Eigen::Vector3d back = -(grasp_tcp.linear() * approach_tcp_);
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  std::vector<Eigen::VectorXd> stagings;
  for (const Eigen::Vector3d& offset :
       {Eigen::Vector3d(0.10 * back), Eigen::Vector3d(0.15 * back),
        Eigen::Vector3d(0.10 * up + 0.05 * back), Eigen::Vector3d(0.15 * up),
        Eigen::Vector3d(0.10 * up + 0.10 * back), Eigen::Vector3d(0.20 * back)}) {
    const auto q = solutions(cell_, receiving_, shifted(grasp_tcp, offset), target);
    if (!q.empty() && first_valid(st, receiving_planner_, reach, {q.front()}) &&
        receiving_planner_.segment_valid(q.front(), target)) {
      stagings.push_back(q.front());
    }
  }
  reach.start = arm_q(st, receiving_);
  reach.hints = std::move(hints);
  if (pre_q) {
    reach.goal = *pre_q;
    if (auto e = step(st, receiving_planner_, receiving_, reach, "receiving_approach",
                      StepEvent::kNone, StepEvent::kNone, stagings);
        !e.empty()) {
      return e;
    }
    reach.start = *pre_q;
    reach.hints.clear();
    stagings.clear();
  }
  reach.goal = grasp_q;
  return step(st, receiving_planner_, receiving_, reach, "receiving_grasp", StepEvent::kNone,
              StepEvent::kGripperClose, stagings);
}

const Stage& Run::release(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp) {
  const auto key = std::make_pair(rr.id, grasp.id);
  const auto found = releases_.find(key);
  if (found != releases_.end()) return found->second;
  Stage& st = releases_[key];
  st.end = receive(rr, grasp).end;
  const db::SuctionGraspRecord& cup = suction_grasps_.at(transfer(rr).cup);
  st.failure = let_go_of_cup(st, cup, rr.board);
  return st;
}

std::string Run::let_go_of_cup(Stage& st, const db::SuctionGraspRecord& cup,
                               const core::Pose& board_world) {
  const Eigen::VectorXd at_q = arm_q(st, suction_);
  const core::Pose tcp = board_world * cup.cup * world_.stage().cup_in_tcp.inverse();
  const Eigen::Vector3d cup_axis = (board_world * cup.cup).linear().col(2);
  const auto back = solutions(cell_, suction_, shifted(tcp, -settings_.approach * cup_axis), at_q);
  MotionRequest leave;
  leave.board_world = board_world;
  leave.start = at_q;
  bool backed_off = false;
  if (!back.empty() && first_valid(st, suction_planner_, leave, {back.front()}) &&
      suction_planner_.segment_valid(at_q, back.front())) {
    leave.goal = back.front();
    if (auto e = step(st, suction_planner_, suction_, leave, "suction_retreat",
                      StepEvent::kSuctionOff, StepEvent::kNone);
        !e.empty()) {
      return e;
    }
    leave.start = back.front();
    backed_off = true;
  }
  leave.goal = suction_.spec.home;
  return step(st, suction_planner_, suction_, leave, "suction_arm_home",
              backed_off ? StepEvent::kNone : StepEvent::kSuctionOff, StepEvent::kNone);
}

const Stage& Run::present(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp,
                          const db::HandoverCandidateRecord& goal) {
  const auto key = std::make_tuple(rr.id, grasp.id, goal.id);
  const auto found = presents_.find(key);
  if (found != presents_.end()) return found->second;
  Stage& st = presents_[key];
  st.end = release(rr, grasp).end;
  const auto stored = stored_edges(
      "transfer", receiving_,
      [&](const auto& n) {
        return n.kind == "human_handover" && n.grasp_id == grasp.id && n.candidate_id == goal.id;
      },
      [&](const auto& n) { return n.robot_handover_id == rr.id; });
  MotionRequest present;
  present.held = in_gripper(grasp);
  const Eigen::VectorXd grasp_q = arm_q(st, receiving_);
  const core::Pose rh_tcp = goal.board * grasp.tcp;
  const auto rh_q = first_valid(st, receiving_planner_, present,
                                solutions(cell_, receiving_, rh_tcp, grasp_q,
                                          stored.empty() ? nullptr : &stored.front()->path.back()));
  assert(rh_q.has_value() == reaches_human_pose(grasp, goal));
  if (!rh_q) {
    st.failure = kNoHumanPoseIk;
    return st;
  }
  present.start = grasp_q;
  present.goal = *rh_q;
  present.filter = filter_for(receiving_, "gripper", grasp.id);
  present.hints = paths_of(stored);
  if (auto e = step(st, receiving_planner_, receiving_, present, "transfer_to_human",
                    StepEvent::kNone, StepEvent::kWaitForHuman);
      !e.empty()) {
    st.failure = e;
  }
  return st;
}

bool Run::reaches_human_pose(const db::RobotGraspRecord& grasp,
                             const db::HandoverCandidateRecord& goal) {
  const auto key = std::make_pair(grasp.id, goal.id);
  if (const auto found = human_reach_.find(key); found != human_reach_.end()) {
    return found->second;
  }
  Stage at;
  at.end = tool().end;  // the suction arm's jaw as it holds the tool; its joints home below
  cell_.set_arm(at.end.robot_q, suction_, suction_.spec.home);
  MotionRequest present;
  present.held = in_gripper(grasp);
  const bool reached =
      first_valid(at, receiving_planner_, present,
                  solutions(cell_, receiving_, goal.board * grasp.tcp, receiving_.spec.home))
          .has_value();
  human_reach_.emplace(key, reached);
  return reached;
}

const Stage& Run::leave(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp,
                        const db::HandoverCandidateRecord& goal) {
  const auto key = std::make_tuple(rr.id, grasp.id, goal.id);
  const auto found = leaves_.find(key);
  if (found != leaves_.end()) return found->second;
  Stage& st = leaves_[key];
  st.end = present(rr, grasp, goal).end;
  const Stage& presented = present(rr, grasp, goal);
  const Stage& received = receive(rr, grasp);
  st.failure = retreat(st, receiving_, goal, "receiving_arm_home",
                       {{&presented, kWayBackSteps[0]},
                        {&received, kWayBackSteps[1]},
                        {&received, kWayBackSteps[2]}});
  return st;
}

}  // namespace hila::online::detail
