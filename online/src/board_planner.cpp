// BoardPlanner::plan: the board's goals in order of the scene human's comfort, the ways within
// the arms' payload, and the search over goals and ways (direct first, then the exchange's shared
// grasps) with a Run (plan_run.hpp) planning each chain.

#include "hila/online/board_planner.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hila/core/payload.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/core/ur_ik.hpp"
#include "hila/online/receiving_scores.hpp"
#include "plan_run.hpp"

namespace hila::online {

const char* to_string(DeliveryMode mode) {
  switch (mode) {
    case DeliveryMode::kExchange:
      return "exchange";
    case DeliveryMode::kDirect:
      return "direct";
    case DeliveryMode::kRegrasp:
      return "regrasp";
    case DeliveryMode::kSuction:
      return "suction";
  }
  return "?";
}

const char* to_string(StepEvent event) {
  switch (event) {
    case StepEvent::kNone:
      return "";
    case StepEvent::kSuctionOn:
      return "suction_on";
    case StepEvent::kSuctionOff:
      return "suction_off";
    case StepEvent::kGripperClose:
      return "gripper_close";
    case StepEvent::kGripperOpen:
      return "gripper_open";
    case StepEvent::kToolGrasped:
      return "tool_grasped";
    case StepEvent::kToolReleased:
      return "tool_released";
    case StepEvent::kSetDown:
      return "set_down";
    case StepEvent::kWaitForHuman:
      return "wait_for_human";
  }
  return "?";
}

std::string events_text(const PlanStep& step) {
  const std::string start = to_string(step.start_event);
  const std::string end = to_string(step.end_event);
  return start.empty() ? end : end.empty() ? start : start + "," + end;
}

std::string via_text(const PlanStep& step) {
  return std::string(to_string(step.via)) + (step.staged ? "+staging" : "");
}

const char* to_string(AttemptResult result) {
  switch (result) {
    case AttemptResult::kPlanned:
      return "planned";
    case AttemptResult::kFailed:
      return "failed";
    case AttemptResult::kDeadline:
      return "deadline";
  }
  return "unknown";
}

const char* to_string(WayOrder order) {
  switch (order) {
    case WayOrder::kEstimatedTime:
      return "estimated time";
    case WayOrder::kFixed:
      return "fixed";
    case WayOrder::kCheapestFirst:
      return "cheapest first";
  }
  return "unknown";
}

const char* to_string(BoardPlanStatus status) {
  switch (status) {
    case BoardPlanStatus::kSolved:
      return "solved";
    case BoardPlanStatus::kNoGoal:
      return "no goal";
    case BoardPlanStatus::kTimeout:
      return "timeout";
    case BoardPlanStatus::kHumanOutOfReach:
      return "human out of reach";
    case BoardPlanStatus::kOverPayload:
      return "over payload";
  }
  return "unknown";
}

BoardPlanner::BoardPlanner(const PlannerModel& model, const BoardPlanSettings& settings)
    : model_(model), settings_(settings) {
  // The natural posture's check reads the joints of a `hila human` model (its RULA mapping); a
  // cell whose human is another model keeps Eq. 8 order, found out here rather than by an
  // exception while planning.
  const core::Cell& cell = model_.cell();
  if (cell.human_arms().empty()) {
    natural_check_works_ = false;
  } else {
    try {
      const auto& arm = cell.human_arms().front();
      const Eigen::VectorXd neutral = cell.human_neutral();
      Eigen::VectorXd joints(arm.chain.dof());
      for (int i = 0; i < arm.chain.dof(); ++i) {
        joints[i] = neutral[arm.chain.model_variables()[static_cast<std::size_t>(i)]];
      }
      check_receiving_posture(cell, nullptr, cell.spec().human_stance, {{arm.spec.name, joints}},
                              Eigen::Vector3d::Zero(), 1.0);
    } catch (const std::exception&) {
      natural_check_works_ = false;
    }
  }
}

BoardPlanner::~BoardPlanner() = default;

namespace {

// An attempt's end from its chain's failure ("" when planned). A Run's failures begin with the
// step or stage they stopped at ("receiving_grasp: no path ..."), and a step checks the deadline
// before anything else, so a chain that failed after the deadline was cut short by it.
void record(GoalAttempt& attempt, const std::string& round, const std::string& failure,
            std::chrono::steady_clock::time_point deadline) {
  attempt.larger_bridges = !round.empty();
  if (failure.empty()) {
    attempt.result = AttemptResult::kPlanned;
    attempt.outcome = "planned";
    return;
  }
  attempt.result = std::chrono::steady_clock::now() >= deadline ? AttemptResult::kDeadline
                                                                : AttemptResult::kFailed;
  attempt.step = failure.substr(0, failure.find(':'));
  attempt.outcome = round + failure;
}

// Whether `arm` reaches the suction tool's handle standing at `handle` (world) with an IK
// solution within its joint limits. Collisions aside: the tool stages check those. An arm
// without closed-form IK is left to the stages.
bool reaches_handle(const core::Cell& cell, const std::string& arm, const core::Pose& handle) {
  const core::Arm& a = cell.arm(arm);
  if (!a.ur_ik) return true;
  const core::Pose tcp = handle * cell.spec().suction.handle_in_tcp.inverse();
  core::UrIkSolutions ik;
  return a.ur_ik->solve(core::arm_base_in_world(cell, a).inverse() * tcp, a.spec.home, ik) > 0;
}

}  // namespace

BoardPlan BoardPlanner::plan(const Scene& scene, const std::string& board,
                             std::chrono::steady_clock::time_point deadline,
                             const BoardPlanOptions& options) {
  const auto started = std::chrono::steady_clock::now();
  const core::PartSpec* part = nullptr;
  for (const auto& p : model_.product().parts) {
    if (p.name == board) part = &p;
  }
  const BoardRecords* records = model_.board_records(board);
  if (part == nullptr || records == nullptr || scene.is_finished(board)) {
    return plan_here(scene, board, deadline, options);  // says why not
  }
  const core::Cell& cell = model_.cell();
  const std::string suction_arm = model_.suction_arm(board);
  const std::optional<core::Pose>& relay = model_.tool_relay();
  // The tool stays in the hand that used it last. Where that is not the board's suction arm, the
  // holding arm first sets it down where the suction arm takes it (the scene's place, or the
  // relay where the suction arm does not reach that) and goes home.
  if (scene.tool_in_hand && scene.tool_arm != suction_arm) {
    const bool to_relay = relay && !reaches_handle(cell, suction_arm, scene.tool) &&
                          reaches_handle(cell, suction_arm, *relay);
    return plan_after_tool_moved(scene, *part, *records, scene.tool_arm,
                                 to_relay ? *relay : scene.tool, deadline, options, started);
  }
  BoardPlan here = plan_here(scene, board, deadline, options);
  if (here.solved() || here.status != BoardPlanStatus::kNoGoal || scene.tool_in_hand || !relay ||
      relay->isApprox(scene.tool, 1e-9)) {
    return here;
  }
  // The tool stands where the suction arm does not reach it: the other arm, which does, carries
  // it to the relay first.
  std::string mover;
  for (const auto& arm : cell.arms()) {
    if (arm.spec.name != suction_arm && mover.empty()) mover = arm.spec.name;
  }
  if (mover.empty() || reaches_handle(cell, suction_arm, scene.tool) ||
      !reaches_handle(cell, suction_arm, *relay) || !reaches_handle(cell, mover, scene.tool)) {
    return here;
  }
  BoardPlan moved =
      plan_after_tool_moved(scene, *part, *records, mover, *relay, deadline, options, started);
  if (moved.solved()) {
    moved.attempts.insert(moved.attempts.begin(), here.attempts.begin(), here.attempts.end());
    moved.motions_planned += here.motions_planned;
    moved.rejected_motions += here.rejected_motions;
    return moved;
  }
  here.reason +=
      "; with the " + mover + " arm carrying the tool to its relay first: " + moved.reason;
  here.status = moved.status;
  here.attempts.insert(here.attempts.end(), moved.attempts.begin(), moved.attempts.end());
  here.motions_planned += moved.motions_planned;
  here.rejected_motions += moved.rejected_motions;
  here.planning_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return here;
}

BoardPlan BoardPlanner::plan_here(const Scene& scene, const std::string& board,
                                  std::chrono::steady_clock::time_point deadline,
                                  const BoardPlanOptions& options) {
  using detail::ArmsState;
  using detail::Run;
  const auto started = std::chrono::steady_clock::now();
  BoardPlan result;
  result.board = board;
  result.worker = scene.worker;
  Run* running = nullptr;  // once it is under way
  auto finish = [&](BoardPlanStatus status, std::string reason) {
    if (running != nullptr) {
      running->stop_validation();
      result.times = running->times();
      result.rejected_motions = running->rejected_motions();
      result.motions_planned = running->motions_planned();
    }
    result.status = status;
    result.reason = std::move(reason);
    result.planning_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return result;
  };
  const core::PartSpec* part = nullptr;
  for (const auto& p : model_.product().parts) {
    if (p.name == board) part = &p;
  }
  if (part == nullptr) return finish(BoardPlanStatus::kNoGoal, "unknown board '" + board + "'");
  if (scene.is_finished(board)) {
    return finish(BoardPlanStatus::kNoGoal, "'" + board + "' is already finished in the scene");
  }
  const BoardRecords* records = model_.board_records(board);
  if (records == nullptr) {
    return finish(BoardPlanStatus::kNoGoal, "the database has no board '" + board + "'");
  }
  // plan() has the tool in this arm's hand or on the table.
  const std::string suction_arm = model_.suction_arm(board);
  result.suction_arm = suction_arm;
  Run run(model_, settings_, scene, *part, *records, suction_arm, deadline, lazy_prm_);
  running = &run;
  // Payload. The exchange: the suction arm carries the board on the tool, the receiving arm in
  // its jaws. A direct pick: the picking arm in its jaws. A way over an arm's payload is not
  // tried; with none left, the status says so.
  std::string over_payload;
  bool exchange_within_payload = true;
  bool suction_within_payload = true;  // the suction way: the board on the tool, nothing else
  for (const auto& check :
       {core::check_payload(run.suction_arm().spec.name, run.suction_arm().spec.payload, part->mass,
                            core::CarryMode::kSuction, model_.cell().spec().suction.mass),
        core::check_payload(run.receiving_arm().spec.name, run.receiving_arm().spec.payload,
                            part->mass, core::CarryMode::kGripper,
                            model_.cell().spec().suction.mass)}) {
    if (!check.within_allowed()) {
      exchange_within_payload = false;
      if (check.mode == core::CarryMode::kSuction) suction_within_payload = false;
      if (over_payload.empty()) over_payload = "over the payload: " + check.describe();
    }
  }
  std::set<std::string> direct_within_payload;
  for (const core::Arm* arm : {&run.receiving_arm(), &run.suction_arm()}) {
    const auto check =
        core::check_payload(arm->spec.name, arm->spec.payload, part->mass,
                            core::CarryMode::kGripper, model_.cell().spec().suction.mass);
    if (check.within_allowed()) {
      direct_within_payload.insert(arm->spec.name);
    } else if (over_payload.empty()) {
      over_payload = "over the payload: " + check.describe();
    }
  }
  if (!exchange_within_payload && !suction_within_payload && direct_within_payload.empty()) {
    return finish(BoardPlanStatus::kOverPayload, over_payload);
  }
  // The worker the scene names (nullptr: the cell's own human, or a body that is the cell's
  // human). At the stance the goals were built for, the cell human's stored Q is theirs (the
  // same lookup); elsewhere, or for another body, the comfort maps are looked up again.
  const core::HumanBody* body =
      scene.worker != nullptr && !scene.worker->same_as_cell() ? scene.worker.get() : nullptr;
  const bool built_stance =
      body == nullptr && scene.human_stance.isApprox(model_.cell().spec().human_stance, 1e-12);
  const WorkerComfort* comfort = nullptr;
  if (!built_stance) {
    std::string error;
    comfort = model_.worker_comfort(&error);
    if (comfort == nullptr) {
      return finish(BoardPlanStatus::kNoGoal,
                    "the human stands elsewhere than the database's goals were built for, and "
                    "its comfort maps could not be read: " +
                        error);
    }
  }
  // Whether the scene's human reaches a goal's grasp, by the human arms' inverse kinematics
  // (the build's own postures where the human stands as built and the build confirmed the goal),
  // each goal once; a goal they do not reach is never tried.
  std::map<std::int64_t, WorkerComfort::GoalReach> reach_of;
  std::set<std::int64_t> out_of_reach;
  // `count`: a goal found out of reach counts in goals_out_of_reach (the goals to be tried; the
  // natural posture's check looks at every goal without counting them).
  auto reach = [&](const db::HandoverCandidateRecord& goal,
                   bool count = true) -> const WorkerComfort::GoalReach& {
    const auto it = reach_of.find(goal.id);
    if (it != reach_of.end()) {
      if (count && !it->second.reachable && out_of_reach.insert(goal.id).second) {
        ++result.goals_out_of_reach;
      }
      return it->second;
    }
    WorkerComfort::GoalReach r;
    if (built_stance && goal.human_joints.size() > 0 &&
        (goal.second_arm.empty() || goal.second_joints.size() > 0)) {
      r.reachable = true;
      r.quality = goal.quality;
      r.joints = goal.human_joints;
      r.second_joints = goal.second_joints;
    } else {  // the human arms' IK: no comfort maps needed
      ++result.human_postures_solved;
      r = WorkerComfort::goal_reach(model_.cell(), goal, records->human_grasps, scene.human_stance,
                                    body);
      if (built_stance) r.quality = goal.quality;  // the stored Q is this human's
    }
    if (count && !r.reachable && out_of_reach.insert(goal.id).second) ++result.goals_out_of_reach;
    return reach_of.emplace(goal.id, std::move(r)).first->second;
  };
  // The goals in Eq. 8 order that the scene's human can take: first those they take
  // comfortably (by the comfort maps), then those they reach only uncomfortably, as far as the
  // goal count needs them; the first BoardPlanSettings::goals.
  const auto goal_limit = static_cast<std::size_t>(std::max(0, settings_.goals));
  std::vector<const db::HandoverCandidateRecord*> goals, below_comfort;
  std::map<std::int64_t, double> worker_quality;  // by goal id
  double best_out_of_reach = 0.0;
  for (const auto& goal : records->goals) {
    const double q =
        built_stance ? goal.quality
                     : comfort->goal_quality(goal, records->human_grasps, scene.human_stance, body);
    worker_quality[goal.id] = q;
    if (q >= std::min(settings_.worker_comfort_floor, goal.quality)) {
      goals.push_back(&goal);
    } else {
      below_comfort.push_back(&goal);
    }
  }
  // Goals a person would choose first: of the comfortable ones, then of those the worker reaches
  // only uncomfortably, those whose receiving posture is natural (the part's centre between hip
  // and shoulder height first: no inverse kinematics for the others); then the upright ones with
  // a higher RULA (the elbow low and the part in front of the chest wherever a goal allows it).
  // The scan is lazy: the first natural goal is tried before the others are looked for (most
  // boards are planned there), then the scan goes on where it stopped; the order of the goals
  // tried is the same either way.
  std::set<std::int64_t> natural, placed_first;  // natural ones; all put first (upright too)
  const bool natural_first =
      settings_.natural_posture_first && (body != nullptr || natural_check_works_);
  std::vector<const db::HandoverCandidateRecord*> natural_found, upright;
  const Eigen::Vector3d centre = records->part.mass_properties.com;
  const core::HeightBand band =
      natural_first ? core::natural_height_band(model_.cell(), body, scene.human_stance)
                    : core::HeightBand{};
  std::size_t scan_list = 0, scan_at = 0;  // where the natural scan goes on
  // Scans on until `want` natural goals are found or every goal is looked at.
  auto scan_natural = [&](std::size_t want) {
    const std::vector<const db::HandoverCandidateRecord*>* lists[2] = {&goals, &below_comfort};
    for (; scan_list < 2; ++scan_list, scan_at = 0) {
      const auto& list = *lists[scan_list];
      for (; scan_at < list.size(); ++scan_at) {
        if (natural_found.size() >= want) return;
        const auto* goal = list[scan_at];
        const double z = (goal->board * centre).z();
        if (!band.contains(z)) continue;
        const auto& r = reach(*goal, false);
        if (!r.reachable) continue;
        std::vector<std::pair<std::string, Eigen::VectorXd>> held{{goal->human_arm, r.joints}};
        if (!goal->second_arm.empty()) held.emplace_back(goal->second_arm, r.second_joints);
        const PostureCheck check = check_receiving_posture(model_.cell(), body, scene.human_stance,
                                                           held, goal->board * centre, part->mass);
        if (!check.upright()) continue;
        if (scan_list == 1) worker_quality[goal->id] = r.quality;
        if (!check.natural(settings_.natural_max_rula)) {
          upright.push_back(goal);
          continue;
        }
        natural.insert(goal->id);
        natural_found.push_back(goal);
      }
    }
  };
  // The goals to try, in order (goals): the natural ones found (the scan stops at goal_limit of
  // them) and up to goal_limit upright ones, then the first goal_limit of the comfort tiers in
  // Eq. 8 order that are not among them: where every natural and upright goal fails, the goals
  // the Eq. 8 order alone would try.
  auto order_goals = [&] {
    std::vector<const db::HandoverCandidateRecord*> first;
    if (natural_first) {
      scan_natural(goal_limit);
      first = natural_found;
      result.goals_natural = static_cast<int>(first.size());
      first.insert(
          first.end(), upright.begin(),
          upright.begin() + static_cast<std::ptrdiff_t>(std::min(upright.size(), goal_limit)));
      for (const auto* goal : first) placed_first.insert(goal->id);
    }
    std::vector<const db::HandoverCandidateRecord*> rest;
    for (const auto* goal : goals) {
      if (rest.size() >= goal_limit) break;
      if (placed_first.count(goal->id) == 0) rest.push_back(goal);
    }
    for (const auto* goal : below_comfort) {
      if (rest.size() >= goal_limit) break;
      if (placed_first.count(goal->id) > 0) continue;  // already first
      const auto& r = reach(*goal);
      if (r.reachable) {
        rest.push_back(goal);
        worker_quality[goal->id] = r.quality;
      } else {
        best_out_of_reach = std::max(best_out_of_reach, worker_quality[goal->id]);
      }
    }
    first.insert(first.end(), rest.begin(), rest.end());
    goals = std::move(first);
    const std::set<const db::HandoverCandidateRecord*> uncomfortable(below_comfort.begin(),
                                                                     below_comfort.end());
    for (const auto* goal : goals) result.goals_uncomfortable += uncomfortable.count(goal) > 0;
  };
  // The first natural goal, tried alone before the rest are ordered (nullptr: none, or the
  // goals are ordered at once).
  const db::HandoverCandidateRecord* tried_early = nullptr;
  if (natural_first && goal_limit > 0 && settings_.way_order != WayOrder::kCheapestFirst) {
    scan_natural(1);
    if (!natural_found.empty()) tried_early = natural_found.front();
  }
  if (tried_early == nullptr) order_goals();
  // Where the scene's human can take none of the goals: says where they stand and how they face.
  auto human_out_of_reach = [&]() {
    const core::Pose& stance = scene.human_stance;
    const double facing =
        core::rad_to_deg(std::atan2(stance.linear()(1, 0), stance.linear()(0, 0)));
    std::ostringstream reason;
    reason << std::fixed << std::setprecision(2) << "the human at (" << stance.translation().x()
           << ", " << stance.translation().y() << ", " << stance.translation().z() << ") m facing "
           << std::setprecision(0) << facing << " deg cannot take '" << board << "' at any of its "
           << records->goals.size() << " stored goals (best comfort Q " << std::setprecision(3)
           << best_out_of_reach
           << " by the maps; the arms reach none of the grasps tried): move the human or rebuild "
              "the database for this stance";
    return finish(BoardPlanStatus::kHumanOutOfReach, reason.str());
  };
  if (tried_early == nullptr && goals.empty() && !records->goals.empty()) {
    return human_out_of_reach();
  }
  bool any_connected_offline = false;
  // What both ways fill in once a chain of a goal is planned.
  auto planned = [&](const db::HandoverCandidateRecord& goal, std::int64_t robot_grasp_id,
                     std::vector<PlanStep>& steps, const ArmsState& end) {
    result.steps = std::move(steps);
    result.goal_rank = goal.rank;
    result.candidate_id = goal.id;
    result.robot_grasp_id = robot_grasp_id;
    // The cup has no slip limit (its grasps hold the weight at any tilt).
    result.theta_c_deg =
        robot_grasp_id == 0 ? 90.0 : run.robot_grasps().at(robot_grasp_id).theta_c_deg;
    result.quality = worker_quality.at(goal.id);
    result.natural_posture = natural.count(goal.id) > 0;
    const auto& posture = reach_of.at(goal.id);
    result.human_arm = goal.human_arm;
    result.human_joints = posture.joints;
    result.second_human_arm = goal.second_arm;
    result.second_human_joints = posture.second_joints;
    result.human_handover = goal.board;
    result.duration = result.steps.back().time.back();
    for (const auto& st : result.steps) result.path_length += st.path_length;
    result.validated = true;
    result.robot_q_after = end.robot_q;
    result.tool_in_hand_after = end.tool_in_hand;
  };
  // One direct chain of a goal; true when it is planned (result filled in).
  auto try_direct = [&](const std::string& round, const db::HandoverCandidateRecord& goal,
                        const db::DirectGraspRecord& d, double estimate) {
    GoalAttempt attempt;
    attempt.estimated_seconds = estimate;
    attempt.rank = goal.rank;
    attempt.candidate_id = goal.id;
    attempt.mode = DeliveryMode::kDirect;
    attempt.arm = d.arm;
    attempt.robot_grasp_id = d.robot_grasp_id;
    std::vector<PlanStep> steps;
    ArmsState end;
    const std::string failure = run.direct_chain(goal, d, steps, end);
    record(attempt, round, failure, deadline);
    result.attempts.push_back(attempt);
    if (!failure.empty()) return false;
    result.estimated_seconds = estimate;
    planned(goal, d.robot_grasp_id, steps, end);
    result.mode = DeliveryMode::kDirect;
    result.picking_arm = d.arm;
    result.delivering_arm = d.arm;
    result.suction_grasp_id = 0;
    return true;
  };
  // One regrasp chain of a goal; true when it is planned (result filled in).
  auto try_regrasp = [&](const std::string& round, const db::HandoverCandidateRecord& goal,
                         const db::TableRegraspRecord& r, double estimate) {
    GoalAttempt attempt;
    attempt.estimated_seconds = estimate;
    attempt.rank = goal.rank;
    attempt.candidate_id = goal.id;
    attempt.mode = DeliveryMode::kRegrasp;
    attempt.arm = r.repick_arm;
    attempt.robot_grasp_id = r.robot_grasp_id;
    std::vector<PlanStep> steps;
    ArmsState end;
    const std::string failure = run.regrasp_chain(goal, r, steps, end);
    record(attempt, round, failure, deadline);
    result.attempts.push_back(attempt);
    if (!failure.empty()) return false;
    result.estimated_seconds = estimate;
    planned(goal, r.robot_grasp_id, steps, end);
    result.mode = DeliveryMode::kRegrasp;
    result.picking_arm = r.arm;
    result.delivering_arm = r.repick_arm;
    result.suction_grasp_id = 0;
    result.pick_grasp_id = r.pick_grasp_id;
    result.set_down = r.placement;
    return true;
  };
  // One suction chain of a goal; true when it is planned (result filled in).
  auto try_suction = [&](const std::string& round, const db::HandoverCandidateRecord& goal,
                         const db::SuctionDeliveryRecord& d, double estimate) {
    GoalAttempt attempt;
    attempt.estimated_seconds = estimate;
    attempt.rank = goal.rank;
    attempt.candidate_id = goal.id;
    attempt.mode = DeliveryMode::kSuction;
    attempt.arm = d.arm;
    attempt.suction_grasp_id = d.suction_grasp_id;
    std::vector<PlanStep> steps;
    ArmsState end;
    const std::string failure = run.suction_chain(goal, d, steps, end);
    record(attempt, round, failure, deadline);
    result.attempts.push_back(attempt);
    if (!failure.empty()) return false;
    result.estimated_seconds = estimate;
    planned(goal, 0, steps, end);
    result.mode = DeliveryMode::kSuction;
    result.picking_arm = d.arm;
    result.delivering_arm = d.arm;
    result.suction_grasp_id = run.suction_delivery_cup(d, goal);
    return true;
  };
  // One exchange chain of a goal under the round's budgets; true when it is planned (result
  // filled in).
  auto try_shared = [&](const std::string& round, const db::HandoverCandidateRecord& goal,
                        const db::SharedGraspRecord& s, double estimate) {
    GoalAttempt attempt;
    attempt.estimated_seconds = estimate;
    attempt.rank = goal.rank;
    attempt.candidate_id = goal.id;
    attempt.mode = DeliveryMode::kExchange;
    attempt.arm = run.receiving_arm().spec.name;
    attempt.robot_grasp_id = s.robot_grasp_id;
    attempt.robot_handover_id = s.robot_handover_id;
    std::vector<PlanStep> steps;
    ArmsState end;
    const std::string failure = run.chain(goal, s, steps, end);
    record(attempt, round, failure, deadline);
    result.attempts.push_back(attempt);
    if (!failure.empty()) return false;
    const auto& rr = run.handovers().at(s.robot_handover_id);
    result.estimated_seconds = estimate;
    planned(goal, s.robot_grasp_id, steps, end);
    result.mode = DeliveryMode::kExchange;
    result.picking_arm = run.suction_arm().spec.name;
    result.delivering_arm = run.receiving_arm().spec.name;
    result.suction_grasp_id = run.suction_grasp_of(rr);
    result.robot_handover = rr.board;
    return true;
  };
  // A goal's ways, each with its estimated robot time: direct, regrasp, suction, exchange, each
  // in record order, the exchanges the offline regrasp graph connected first (WayOrder::kFixed).
  struct Way {
    const db::HandoverCandidateRecord* goal = nullptr;
    const db::DirectGraspRecord* direct = nullptr;
    const db::TableRegraspRecord* regrasp = nullptr;
    const db::SuctionDeliveryRecord* suction = nullptr;
    const db::SharedGraspRecord* shared = nullptr;
    bool unconnected = false;  // an exchange the offline regrasp graph did not connect
    // An exchange whose suction-arm transfer to the robot-robot pose the build found blocked.
    bool blocked = false;
    double seconds = 0.0;
  };
  // Exchanges the build found blocked go last (BoardPlanSettings::blocked_exchanges_last); off,
  // no way is marked blocked and every order is as without the flag.
  const bool blocked_last =
      settings_.blocked_exchanges_last && settings_.way_order != WayOrder::kFixed;
  auto ways_of = [&](const db::HandoverCandidateRecord& goal, std::vector<Way>& ways) {
    if (const auto direct = records->direct_grasps.find(goal.id);
        direct != records->direct_grasps.end()) {
      for (const auto& d : direct->second) {
        if (direct_within_payload.count(d.arm) == 0) continue;
        ways.push_back({.goal = &goal, .direct = &d, .seconds = run.estimate(goal, d)});
      }
    }
    if (const auto regrasps = records->table_regrasps.find(goal.id);
        regrasps != records->table_regrasps.end()) {
      for (const auto& r : regrasps->second) {
        if (direct_within_payload.count(r.arm) == 0 ||
            direct_within_payload.count(r.repick_arm) == 0) {
          continue;
        }
        ways.push_back({.goal = &goal, .regrasp = &r, .seconds = run.estimate(goal, r)});
      }
    }
    if (const auto deliveries = records->suction_deliveries.find(goal.id);
        suction_within_payload && deliveries != records->suction_deliveries.end()) {
      for (const auto& d : deliveries->second) {
        ways.push_back({.goal = &goal, .suction = &d, .seconds = run.estimate(goal, d)});
      }
    }
    // The shared grasps the offline regrasp graph connected for this goal first: their stored
    // paths and IK branches are what the motions re-validate.
    if (const auto shared = records->shared_grasps.find(goal.id);
        exchange_within_payload && shared != records->shared_grasps.end()) {
      const std::size_t first = ways.size();
      for (const auto& g : shared->second) {
        const bool connected = run.connected_offline(goal, g);
        any_connected_offline = any_connected_offline || connected;
        ways.push_back({.goal = &goal,
                        .shared = &g,
                        .unconnected = !connected,
                        .blocked = blocked_last && !connected && run.exchange_blocked_offline(g),
                        .seconds = run.estimate(goal, g)});
      }
      std::stable_partition(ways.begin() + static_cast<std::ptrdiff_t>(first), ways.end(),
                            [](const Way& w) { return !w.unconnected; });
    }
  };
  // Ways in the given order under the round's budgets; true when one is planned (result filled
  // in). Where the receiving arm did not reach the exchange with a grasp, that grasp at the same
  // board pose (another suction grasp holding it there) is tried after the other ways: what
  // blocked it is still there, so it would most likely fail again.
  auto try_ways = [&](const std::string& round, const std::vector<Way>& ways) {
    auto try_way = [&](const Way& w) {
      const auto& goal = *w.goal;
      if (w.direct != nullptr) return try_direct(round, goal, *w.direct, w.seconds);
      if (w.regrasp != nullptr) return try_regrasp(round, goal, *w.regrasp, w.seconds);
      if (w.suction != nullptr) return try_suction(round, goal, *w.suction, w.seconds);
      return try_shared(round, goal, *w.shared, w.seconds);
    };
    std::vector<const Way*> later;
    for (const auto& w : ways) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      if (w.shared != nullptr && run.receive_failed_at_same_pose(*w.shared)) {
        later.push_back(&w);
        continue;
      }
      if (try_way(w)) return true;
    }
    for (const auto* w : later) {
      if (std::chrono::steady_clock::now() >= deadline) return false;
      if (try_way(*w)) return true;
    }
    return false;
  };
  auto by_estimate = [](const Way& a, const Way& b) {
    return std::make_tuple(a.blocked, a.unconnected, a.seconds) <
           std::make_tuple(b.blocked, b.unconnected, b.seconds);
  };
  // A goal whose every way is an exchange the build found blocked (none direct, by a regrasp or
  // on the cup): tried after the goals of the list that have an open way.
  auto all_blocked = [](const std::vector<Way>& ways) {
    return !ways.empty() &&
           std::all_of(ways.begin(), ways.end(), [](const Way& w) { return w.blocked; });
  };
  // Every goal of `list` under the round's budgets but `skip`; true when one is planned (result
  // filled in).
  auto try_goals = [&](const std::string& round,
                       const std::vector<const db::HandoverCandidateRecord*>& list,
                       const db::HandoverCandidateRecord* skip = nullptr) {
    std::vector<Way> across;                      // kCheapestFirst: every goal's ways
    std::vector<std::vector<Way>> blocked_goals;  // all_blocked, in list order
    for (const auto* goal_record : list) {
      if (goal_record == skip) continue;
      const auto& goal = *goal_record;
      // A goal the maps call comfortable may still be out of reach (a map bin holds the best of
      // the samples near it): confirmed before it is planned.
      if (!reach(goal).reachable) {
        best_out_of_reach = std::max(best_out_of_reach, worker_quality[goal.id]);
        continue;
      }
      if (settings_.way_order == WayOrder::kCheapestFirst) {
        ways_of(goal, across);
        continue;
      }
      std::vector<Way> ways;
      ways_of(goal, ways);
      if (settings_.way_order == WayOrder::kEstimatedTime) {
        std::stable_sort(ways.begin(), ways.end(), by_estimate);
      }
      if (blocked_last && all_blocked(ways)) {
        blocked_goals.push_back(std::move(ways));
        continue;
      }
      if (try_ways(round, ways)) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
    }
    for (const auto& ways : blocked_goals) {
      if (try_ways(round, ways)) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
    }
    // Across the goals, in Eq. 8 order where two ways' estimates are equal.
    std::stable_sort(across.begin(), across.end(), by_estimate);
    return try_ways(round, across);
  };
  // A solved board, with the tool put back when asked.
  auto solved = [&] {
    if (options.return_tool && result.tool_in_hand_after) {
      ArmsState end;
      end.robot_q = result.robot_q_after;
      end.tool_in_hand = true;
      const std::size_t before = result.steps.size();
      result.tool_kept = run.return_tool(result.human_handover, result.steps, end);
      if (result.tool_kept.empty()) {
        for (std::size_t i = before; i < result.steps.size(); ++i) {
          result.path_length += result.steps[i].path_length;
        }
        result.duration = result.steps.back().time.back();
        result.robot_q_after = end.robot_q;
        result.tool_in_hand_after = false;
      }
    }
    return finish(BoardPlanStatus::kSolved, "");
  };
  // A blocked natural goal is tried after the open ones: the first open natural goal is tried
  // early instead, the scan going on only as far as it.
  for (std::size_t found = 1; tried_early != nullptr && blocked_last;) {
    std::vector<Way> ways;
    ways_of(*tried_early, ways);
    if (!all_blocked(ways)) break;
    scan_natural(++found);
    tried_early = natural_found.size() >= found ? natural_found[found - 1] : nullptr;
    if (tried_early == nullptr) order_goals();
  }
  if (tried_early != nullptr) {
    if (try_goals("", {tried_early})) {
      result.goals_natural = static_cast<int>(natural_found.size());
      return solved();
    }
    order_goals();
  }
  if (try_goals("", goals, tried_early)) return solved();
  // Every goal failed within the cheap budgets and time is left: once more with bridges as
  // large as the baselines' from-scratch budget, where the roadmap is cut.
  if (settings_.motion.planner == MotionPlannerKind::kRoadmap &&
      settings_.motion.escalated_bridge_checks > settings_.motion.bridge_checks && !goals.empty() &&
      std::chrono::steady_clock::now() < deadline) {
    run.escalate(settings_.motion.escalated_bridge_checks,
                 settings_.motion.escalated_repair_checks);
    if (try_goals("(larger bridges) ", goals)) {
      result.larger_bridges = true;
      return solved();
    }
  }
  if (!goals.empty() && std::all_of(goals.begin(), goals.end(), [&](const auto* goal) {
        return out_of_reach.count(goal->id) > 0;
      })) {
    return human_out_of_reach();
  }
  if (std::chrono::steady_clock::now() >= deadline) {
    return finish(
        BoardPlanStatus::kTimeout,
        "the deadline passed after " + std::to_string(result.attempts.size()) + " goal attempts");
  }
  return finish(BoardPlanStatus::kNoGoal,
                goals.empty()
                    ? "the database has no handover goal for '" + board + "'"
                    : "none of the first " + std::to_string(goals.size()) +
                          " goals could be planned in this scene (see attempts)" +
                          (any_connected_offline ? ""
                                                 : "; the database connects none of their chains "
                                                   "(hila inspect DB roadmap)"));
}

BoardPlan BoardPlanner::plan_after_tool_moved(const Scene& scene, const core::PartSpec& part,
                                              const BoardRecords& records, const std::string& mover,
                                              const core::Pose& place,
                                              std::chrono::steady_clock::time_point deadline,
                                              const BoardPlanOptions& options,
                                              std::chrono::steady_clock::time_point started) {
  // The moving arm plays the suction arm's part: its world carries the tool. The board lies where
  // it was detected meanwhile.
  std::vector<PlanStep> steps;
  std::string failure;
  Scene after = scene;
  int motions = 0, rejected = 0;
  PlanTimes times;
  auto account = [&](detail::Run& run) {
    run.stop_validation();
    motions += run.motions_planned();
    rejected += run.rejected_motions();
    const PlanTimes t = run.times();
    times.motions += t.motions;
    times.smoothing += t.smoothing;
    times.validation += t.validation;
    times.queued_validation += t.queued_validation;
    times.queued_smoothing += t.queued_smoothing;
  };
  if (!scene.tool_in_hand) {
    after.tool_arm = mover;
    detail::Run take(model_, settings_, after, part, records, mover, deadline, lazy_prm_);
    detail::ArmsState end = take.start();
    failure = take.take_tool(steps, end);
    account(take);
    after.tool_in_hand = true;
    after.robot[mover] = model_.cell().arm_joints(end.robot_q, take.suction_arm());
  }
  if (failure.empty()) {
    after.tool = place;  // where the holder sets it down; it is in hand until then
    detail::Run put(model_, settings_, after, part, records, mover, deadline, lazy_prm_);
    detail::ArmsState end = put.start();
    failure = put.return_tool(scene.initial_pose(part), steps, end);
    account(put);
    after.tool_in_hand = false;
    after.robot[mover] = model_.cell().arm_joints(end.robot_q, put.suction_arm());
  }
  BoardPlan result;
  if (!failure.empty()) {
    result.board = part.name;
    result.worker = scene.worker;
    result.suction_arm = model_.suction_arm(part.name);
    result.status = BoardPlanStatus::kNoGoal;
    result.reason =
        std::string(scene.tool_in_hand
                        ? "the suction tool is in the " + mover + " arm's hand"
                        : "the " + result.suction_arm + " arm does not reach the suction tool") +
        ", and '" + part.name + "' is the " + result.suction_arm +
        " arm's to pick by suction, but the " + mover +
        " arm cannot set the tool down where that arm takes it (" + failure + ")";
  } else {
    result = plan_here(after, part.name, deadline, options);
  }
  result.motions_planned += motions;
  result.rejected_motions += rejected;
  result.times.motions += times.motions;
  result.times.smoothing += times.smoothing;
  result.times.validation += times.validation;
  result.times.queued_validation += times.queued_validation;
  result.times.queued_smoothing += times.queued_smoothing;
  result.planning_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (!result.solved() || steps.empty()) return result;
  const double clock = steps.back().time.back();
  for (PlanStep& s : result.steps) {
    for (double& t : s.time) t += clock;
  }
  for (const PlanStep& s : steps) result.path_length += s.path_length;
  result.duration += clock;
  result.steps.insert(result.steps.begin(), steps.begin(), steps.end());
  result.tool_move_steps = static_cast<int>(steps.size());
  result.tool_move_arm = mover;
  result.tool_taken_from_table = !scene.tool_in_hand;
  result.tool_place = place;
  return result;
}

}  // namespace hila::online
