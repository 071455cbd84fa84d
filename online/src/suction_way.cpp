// The suction way: the suction arm picks the board with the tool where it lies (the exchange's
// pick) and presents it on its cup at the goal's robot-human pose; once the human holds it (wrist
// F/T) the suction goes off, the arm backs off along the cup's axis and goes home with the tool.
// Stages: the tool (0), the pick (1), the presentation (2) and the leave (3); the last two
// memoised by the delivery's cup and goal.

#include "plan_run.hpp"

namespace hila::online::detail {

std::string Run::suction_chain(const db::HandoverCandidateRecord& goal,
                               const db::SuctionDeliveryRecord& delivery,
                               std::vector<PlanStep>& steps, ArmsState& end) {
  if (suction_grasps_.count(delivery.suction_grasp_id) == 0 || delivery.arm != suction_.spec.name) {
    return "the database's suction delivery refers to a missing record or another arm";
  }
  const Stage* stages[4] = {};
  const auto plan_stages = [&] {
    stages[0] = &tool();
    if (!stages[0]->ok()) return;
    // The presentation chooses the cup (its stand-ins) and plans the pick it follows.
    const Stage& presented = suction_present(delivery, goal);
    stages[1] = &pick(presented.cup);
    if (!stages[1]->ok()) return;
    stages[2] = &presented;
    if (presented.ok()) stages[3] = &suction_leave(delivery, goal);
  };
  plan_settled(stages, 0, plan_stages);
  return join_stages(stages, steps, end);
}

std::int64_t Run::suction_delivery_cup(const db::SuctionDeliveryRecord& delivery,
                                       const db::HandoverCandidateRecord& goal) const {
  const auto found = suction_presents_.find({delivery.suction_grasp_id, goal.id});
  return found == suction_presents_.end() ? delivery.suction_grasp_id : found->second.cup;
}

const Stage& Run::suction_present(const db::SuctionDeliveryRecord& delivery,
                                  const db::HandoverCandidateRecord& goal) {
  const auto key = std::make_pair(delivery.suction_grasp_id, goal.id);
  if (const auto found = suction_presents_.find(key); found != suction_presents_.end()) {
    const Stage& planned = found->second;
    if (!planned.ok()) return planned;
    // A pick planned again after the validator rejected it late may end elsewhere.
    const Stage& picked = pick(planned.cup);
    if (picked.ok() && !planned.paths.empty() &&
        planned.paths.front().front() == arm_q(picked, suction_)) {
      return planned;
    }
    abandon(suction_presents_.at(key));
    suction_presents_.erase(key);
    if (const auto left = suction_leaves_.find(key); left != suction_leaves_.end()) {
      abandon(left->second);
      suction_leaves_.erase(left);
    }
  }
  Stage& st = suction_presents_[key];
  st.cup = delivery.suction_grasp_id;
  std::string first_failure;
  for (const std::int64_t cup_id : stand_in_cups(suction_grasps_.at(delivery.suction_grasp_id))) {
    const Stage& picked = pick(cup_id);
    std::string e = picked.failure;
    bool deadline_passed = picked.deadline_passed;
    if (picked.ok()) {
      Stage attempt;
      attempt.end = picked.end;
      attempt.cup = cup_id;
      const db::SuctionGraspRecord& cup = suction_grasps_.at(cup_id);
      const core::Pose rh_tcp = goal.board * cup.cup * world_.stage().cup_in_tcp.inverse();
      const auto stored = stored_edges(
          "transfer", suction_,
          [&](const auto& n) {
            return n.kind == "human_handover" && n.grasp_kind == "suction" &&
                   n.grasp_id == cup_id && n.candidate_id == goal.id;
          },
          [](const auto&) { return true; });
      MotionRequest carry;
      carry.held = on_cup(cup);
      const Eigen::VectorXd up = arm_q(attempt, suction_);
      // The build's branch first: its stored transfer's end, else the delivery's (for the
      // database's cup; a stand-in's TCP is turned).
      const Eigen::VectorXd* preferred = !stored.empty() ? &stored.front()->path.back()
                                         : cup_id == delivery.suction_grasp_id ? &delivery.joints_rh
                                                                               : nullptr;
      const auto rh_q = first_valid(attempt, suction_planner_, carry,
                                    solutions(cell_, suction_, rh_tcp, up, preferred));
      if (!rh_q) {
        e = kNoHumanPoseIk;
      } else {
        carry.start = up;
        carry.goal = *rh_q;
        carry.filter = filter_for(suction_, "suction", cup_id);
        carry.hints = paths_of(stored);
        e = step(attempt, suction_planner_, suction_, carry, "transfer_to_human", StepEvent::kNone,
                 StepEvent::kWaitForHuman);
      }
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

const Stage& Run::suction_leave(const db::SuctionDeliveryRecord& delivery,
                                const db::HandoverCandidateRecord& goal) {
  const auto key = std::make_pair(delivery.suction_grasp_id, goal.id);
  if (const auto found = suction_leaves_.find(key); found != suction_leaves_.end()) {
    return found->second;
  }
  const Stage& presented = suction_present(delivery, goal);
  Stage& st = suction_leaves_[key];
  st.end = presented.end;
  // The human holds the board where it was presented.
  st.failure = let_go_of_cup(st, suction_grasps_.at(presented.cup), goal.board);
  return st;
}

}  // namespace hila::online::detail
