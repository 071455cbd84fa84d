#include "hila/online/board_planner.hpp"

#include <algorithm>
#include <map>
#include <optional>

#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/online/time_parameterization.hpp"

namespace hila::online {

namespace {

double path_length(const std::vector<Eigen::VectorXd>& q) {
  double l = 0.0;
  for (std::size_t i = 1; i < q.size(); ++i) l += (q[i] - q[i - 1]).norm();
  return l;
}

// IK solutions of `arm` for a TCP pose in the world, nearest `seed` first (`preferred`, when
// given and among them, first of all).
std::vector<Eigen::VectorXd> solutions(const core::Cell& cell, const core::Arm& arm,
                                       const core::Pose& tcp, const Eigen::VectorXd& seed,
                                       const Eigen::VectorXd* preferred = nullptr) {
  core::UrIkSolutions ik;
  const int n = arm.ur_ik->solve(core::arm_base_in_world(cell, arm).inverse() * tcp, seed, ik);
  std::vector<Eigen::VectorXd> out;
  for (int i = 0; i < n; ++i) out.emplace_back(ik.q[static_cast<std::size_t>(i)]);
  std::sort(out.begin(), out.end(), [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    const bool pa = preferred && (a - *preferred).norm() < 1e-6;
    const bool pb = preferred && (b - *preferred).norm() < 1e-6;
    if (pa != pb) return pa;
    return (a - seed).norm() < (b - seed).norm();
  });
  return out;
}

core::Pose shifted(const core::Pose& pose, const Eigen::Vector3d& by) {
  core::Pose p = pose;
  p.translation() += by;
  return p;
}

}  // namespace

const char* to_string(BoardPlanStatus status) {
  switch (status) {
    case BoardPlanStatus::kSolved:
      return "solved";
    case BoardPlanStatus::kNoGoal:
      return "no goal";
    case BoardPlanStatus::kTimeout:
      return "timeout";
  }
  return "unknown";
}

BoardPlanner::BoardPlanner(const PlannerModel& model, const BoardPlanSettings& settings)
    : model_(model), settings_(settings) {}

BoardPlan BoardPlanner::plan(const Scene& scene, const std::string& board,
                             std::chrono::steady_clock::time_point deadline) {
  const auto started = std::chrono::steady_clock::now();
  BoardPlan result;
  result.board = board;
  auto finish = [&](BoardPlanStatus status, std::string reason) {
    result.status = status;
    result.reason = std::move(reason);
    result.planning_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return result;
  };
  const core::Cell& cell = model_.cell();
  const core::ProductSpec& product = model_.product();
  const db::Database& db = model_.database();
  const core::PartSpec* part = nullptr;
  for (const auto& p : product.parts) {
    if (p.name == board) part = &p;
  }
  if (part == nullptr) return finish(BoardPlanStatus::kNoGoal, "unknown board '" + board + "'");
  if (scene.is_finished(board)) {
    return finish(BoardPlanStatus::kNoGoal, "'" + board + "' is already finished in the scene");
  }
  const db::PartRecord* record = nullptr;
  for (const auto& p : db.parts()) {
    if (p.name == board) record = &p;
  }
  if (record == nullptr) {
    return finish(BoardPlanStatus::kNoGoal, "the database has no board '" + board + "'");
  }

  const World world(cell, product, scene, board);
  const core::StageScene& stage = world.stage();
  const core::Arm& suction = cell.arms()[static_cast<std::size_t>(stage.suction_arm)];
  const core::Arm& receiving = cell.arms()[stage.suction_arm == 0 ? 1u : 0u];
  ArmMotionPlanner suction_planner(world, model_.roadmap(suction.spec.name), suction.spec.name,
                                   settings_.motion);
  ArmMotionPlanner receiving_planner(world, model_.roadmap(receiving.spec.name),
                                     receiving.spec.name, settings_.motion);
  core::CollisionData validation_data = world.make_data();

  std::map<std::int64_t, db::RobotGraspRecord> robot_grasps;
  for (const auto& g : db.robot_grasps(record->id)) robot_grasps[g.id] = g;
  std::map<std::int64_t, db::SuctionGraspRecord> suction_grasps;
  for (const auto& g : db.suction_grasps(record->id)) suction_grasps[g.id] = g;
  std::map<std::int64_t, db::RobotHandoverRecord> handovers;
  for (const auto& h : db.robot_handovers(record->id)) handovers[h.id] = h;
  std::map<std::pair<std::string, std::int64_t>, std::vector<bool>> filters;
  for (const auto& f : db.roadmap_filters(record->id))
    filters[{f.grasp_kind, f.grasp_id}] = f.edges;
  auto filter_for = [&](const std::string& kind, std::int64_t id) -> const std::vector<bool>* {
    const auto it = filters.find({kind, id});
    return it == filters.end() ? nullptr : &it->second;
  };
  // The offline regrasp graph's configurations, as preferred IK branches: its connected
  // transfers end in them, so the stored roadmap connects them (the scene permitting).
  const auto nodes = db.regrasp_nodes(record->id);
  std::map<std::int64_t, const db::RegraspNodeRecord*> node_by_id;
  for (const auto& n : nodes) node_by_id[n.id] = &n;
  std::map<std::int64_t, bool> reached;  // nodes a connected transfer or transit ends in
  for (const auto& e : db.regrasp_edges(record->id)) {
    if (e.connected) reached[e.to_node] = true;
  }
  auto stored = [&](const std::string& kind, const std::string& arm, std::int64_t grasp,
                    std::int64_t rr, std::int64_t candidate) -> const Eigen::VectorXd* {
    const Eigen::VectorXd* any = nullptr;
    for (const auto& n : nodes) {
      if (n.kind != kind || n.arm != arm || n.grasp_id != grasp ||
          (rr != 0 && n.robot_handover_id != rr) ||
          (candidate != 0 && n.candidate_id != candidate)) {
        continue;
      }
      if (reached.count(n.id) != 0) return &n.solutions.front();
      if (any == nullptr) any = &n.solutions.front();
    }
    return any;
  };
  std::vector<db::HandoverCandidateRecord> goals = db.handover_goals(record->id);
  std::sort(goals.begin(), goals.end(),
            [](const auto& a, const auto& b) { return a.rank < b.rank; });

  Eigen::VectorXd start_q = cell.home_configuration();
  for (const auto& arm : cell.arms()) {
    const auto it = scene.robot.find(arm.spec.name);
    if (it != scene.robot.end()) cell.set_arm(start_q, arm, it->second);
  }
  const Eigen::Vector3d opening_tcp = cell.spec().gripper.opening_axis.normalized();
  const Eigen::Vector3d approach_tcp = cell.spec().gripper.approach_axis.normalized();
  const core::Pose cup_in_tcp = stage.cup_in_tcp;
  const core::Pose board_initial = scene.initial_pose(*part);

  // One goal's chain with one shared grasp; the reason when it fails.
  auto try_chain = [&](const db::HandoverCandidateRecord& goal, const db::SharedGraspRecord& shared,
                       std::vector<PlanStep>& steps) -> std::string {
    Eigen::VectorXd robot_q = start_q;
    bool tool_in_hand = scene.tool_in_hand;
    std::map<const core::Arm*, Eigen::VectorXd> now;  // each arm's joints as the plan goes
    for (const core::Arm* arm : {&suction, &receiving}) {
      const auto it = scene.robot.find(arm->spec.name);
      now[arm] = it != scene.robot.end() ? it->second : arm->spec.home;
    }
    double clock = 0.0;
    // Plans, times and validates one motion; on success the step is appended and the arm's
    // joints in robot_q advance to the goal.
    auto step = [&](ArmMotionPlanner& planner, const core::Arm& arm, MotionRequest request,
                    const std::string& name, const std::string& start_event,
                    const std::string& end_event) -> std::string {
      if (std::chrono::steady_clock::now() >= deadline) return name + ": the deadline passed";
      request.robot_q = robot_q;
      request.tool_in_hand = tool_in_hand;
      request.tool_world = scene.tool;
      request.deadline = deadline;
      const MotionResult motion = planner.plan(request);
      if (!motion.solved()) return name + ": " + to_string(motion.status) + ": " + motion.reason;
      const TimedPath timed = time_parameterize(motion.path, arm.spec.max_velocity,
                                                arm.spec.max_acceleration, settings_.speed_scale);
      Motion check;
      check.arm = arm.spec.name;
      check.time = timed.time;
      check.q = timed.q;
      check.robot_q = robot_q;
      check.holds_board = request.held.held;
      check.board_in_tcp = request.held.board_in_tcp;
      check.slip_axis_tcp = request.held.axis_tcp;
      check.slip_lever_tcp = request.held.lever_tcp;
      check.theta_c_deg = request.held.theta_c_deg;
      check.board_world = request.board_world;
      check.tool_in_hand = tool_in_hand;
      check.tool_world = scene.tool;
      check.start_in_contact = request.start_in_contact;
      if (request.held.held && &arm == &receiving)
        cell.set_jaw(check.robot_q, arm, request.held.jaw);
      PlanStep s;
      s.validation = validate_motion(world, validation_data, check, settings_.validator);
      if (!s.validation.valid()) {
        const auto& v = s.validation.violations.front();
        return name + ": the validator rejected the plan (" + v.kind + ": " + v.detail + ")";
      }
      s.name = name;
      s.arm = arm.spec.name;
      s.via = motion.via;
      for (const double t : timed.time) s.time.push_back(clock + t);
      s.q = timed.q;
      s.event = start_event.empty() ? end_event
                                    : start_event + (end_event.empty() ? "" : "," + end_event);
      s.path_length = path_length(motion.path);
      clock = s.time.back();
      cell.set_arm(robot_q, arm, motion.path.back());
      now[&arm] = motion.path.back();
      steps.push_back(std::move(s));
      return "";
    };
    // The first IK solution valid for the planner under `request` (nullopt: none).
    auto first_valid =
        [&](ArmMotionPlanner& planner, MotionRequest request,
            const std::vector<Eigen::VectorXd>& candidates) -> std::optional<Eigen::VectorXd> {
      request.robot_q = robot_q;
      request.tool_in_hand = tool_in_hand;
      request.tool_world = scene.tool;
      planner.prepare(request);
      for (const auto& q : candidates) {
        if (planner.valid(q)) return q;
      }
      return std::nullopt;
    };

    const auto rr_it = handovers.find(shared.robot_handover_id);
    const auto sg_it = rr_it == handovers.end()
                           ? suction_grasps.end()
                           : suction_grasps.find(rr_it->second.suction_grasp_id);
    const auto g_it = robot_grasps.find(shared.robot_grasp_id);
    if (rr_it == handovers.end() || sg_it == suction_grasps.end() || g_it == robot_grasps.end()) {
      return "the database's shared grasp refers to a missing record";
    }
    const db::RobotHandoverRecord& rr = rr_it->second;
    const db::SuctionGraspRecord& cup = sg_it->second;
    const db::RobotGraspRecord& grasp = g_it->second;

    // 0. The tool, when it still stands on the table.
    if (!tool_in_hand) {
      const core::Pose tcp = scene.tool * cell.spec().suction.handle_in_tcp.inverse();
      const core::Pose pre = shifted(tcp, -settings_.approach * (tcp.linear() * approach_tcp));
      MotionRequest r;
      r.board_world = board_initial;
      const auto at =
          first_valid(suction_planner, r, solutions(cell, suction, tcp, suction.spec.home));
      if (!at) return "tool_pick: no valid IK at the tool's handle";
      const auto before = solutions(cell, suction, pre, *at);
      if (before.empty()) return "tool_pick: no IK before the handle";
      MotionRequest approach = r;
      approach.start = now[&suction];
      approach.goal = before.front();
      if (auto e = step(suction_planner, suction, approach, "tool_approach", "", ""); !e.empty())
        return e;
      MotionRequest in = r;
      in.start = before.front();
      in.goal = *at;
      if (auto e = step(suction_planner, suction, in, "tool_grasp", "", "tool_grasped"); !e.empty())
        return e;
      tool_in_hand = true;
      cell.set_jaw(robot_q, suction, cell.spec().suction.handle_width);
      const auto raised =
          solutions(cell, suction, shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift)), *at);
      if (raised.empty()) return "tool_lift: no IK above the tool's place";
      MotionRequest lift = r;
      lift.start = *at;
      lift.goal = raised.front();
      lift.start_in_contact = true;  // the cup still stands on the table
      if (auto e = step(suction_planner, suction, lift, "tool_lift", "", ""); !e.empty()) return e;
      // Home with the tool: where the offline chain (home -> pick) starts.
      MotionRequest home = r;
      home.start = raised.front();
      home.goal = suction.spec.home;
      if (auto e = step(suction_planner, suction, home, "tool_to_home", "", ""); !e.empty())
        return e;
    }

    // 1. Suction pick at the detected pose: approach along the cup's axis, pick, lift.
    const core::Pose cup_world = board_initial * cup.cup;
    const core::Pose pick_tcp = cup_world * cup_in_tcp.inverse();
    const Eigen::Vector3d into = cup_world.linear().col(2);  // z into the part
    const core::Pose pre_pick = shifted(pick_tcp, -settings_.approach * into);
    const core::Pose lifted = shifted(pick_tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
    MotionRequest standing;
    standing.board_world = board_initial;
    const Eigen::VectorXd suction_now = now[&suction];
    HeldBoard on_cup;
    on_cup.held = true;
    on_cup.board_in_tcp = cup_in_tcp * cup.cup.inverse();
    MotionRequest carry;
    carry.held = on_cup;
    // A pick branch whose approach and lift stay in it (their nearest solutions) and are valid:
    // the approach with the board standing, the lift with it on the cup.
    std::optional<Eigen::VectorXd> pick, up;
    std::vector<Eigen::VectorXd> pre;
    const Eigen::VectorXd* stored_pick = stored("pick", suction.spec.name, cup.id, 0, 0);
    for (const auto& q :
         solutions(cell, suction, pick_tcp, stored_pick ? *stored_pick : suction_now)) {
      if (!first_valid(suction_planner, standing, {q})) continue;
      const auto p = solutions(cell, suction, pre_pick, q);
      const auto l = solutions(cell, suction, lifted, q);
      if (p.empty() || l.empty() || !first_valid(suction_planner, standing, {p.front()}) ||
          !first_valid(suction_planner, carry, {l.front()})) {
        continue;
      }
      pick = q;
      pre = {p.front()};
      up = l.front();
      break;
    }
    if (!pick) {
      return "suction_pick: no IK branch with a valid approach, pick and lift at the detected "
             "board pose";
    }
    MotionRequest r = standing;
    r.start = suction_now;
    r.goal = pre.front();
    if (auto e = step(suction_planner, suction, r, "suction_approach", "", ""); !e.empty())
      return e;
    r.start = pre.front();
    r.goal = *pick;
    if (auto e = step(suction_planner, suction, r, "suction_pick", "", "suction_on"); !e.empty())
      return e;
    carry.start = *pick;
    carry.goal = *up;
    carry.start_in_contact = true;  // the board still rests where it was detected
    if (auto e = step(suction_planner, suction, carry, "lift", "", ""); !e.empty()) return e;

    // 2. To the robot-robot pose, through the suction grasp's filtered roadmap.
    const core::Pose rr_tcp = rr.board * cup.cup * cup_in_tcp.inverse();
    const auto rr_q =
        first_valid(suction_planner, carry,
                    solutions(cell, suction, rr_tcp, *up,
                              stored("robot_handover", suction.spec.name, cup.id, rr.id, 0)));
    if (!rr_q) return "transfer_to_robot_handover: no valid IK at the robot-robot pose";
    carry.start = *up;
    carry.goal = *rr_q;
    carry.start_in_contact = false;
    carry.filter = filter_for("suction", cup.id);
    if (auto e = step(suction_planner, suction, carry, "transfer_to_robot_handover", "", "");
        !e.empty())
      return e;

    // 3. The receiving arm's approach and grasp, the board held by the suction arm.
    const double jaw =
        std::min(cell.spec().gripper.jaw_max, grasp.jaw_width + settings_.jaw_margin);
    const core::Pose grasp_tcp = rr.board * grasp.tcp;
    MotionRequest reach;
    reach.board_world = rr.board;
    const auto grasp_q =
        first_valid(receiving_planner, reach,
                    solutions(cell, receiving, grasp_tcp, receiving.spec.home,
                              stored("robot_handover", receiving.spec.name, grasp.id, rr.id, 0)));
    if (!grasp_q) return "receiving_grasp: no valid IK at the robot-robot pose";
    // The approach backs off along the gripper's axis as far as the scene lets it (the exchange
    // may be close to the robot's body), else the arm goes to the grasp directly.
    std::optional<Eigen::VectorXd> pre_q;
    for (const double fraction : {1.0, 0.5, 0.2}) {
      const auto p = solutions(
          cell, receiving,
          shifted(grasp_tcp, -fraction * settings_.approach * (grasp_tcp.linear() * approach_tcp)),
          *grasp_q);
      if (p.empty()) continue;
      reach.robot_q = robot_q;
      reach.tool_in_hand = tool_in_hand;
      receiving_planner.prepare(reach);
      if (receiving_planner.valid(p.front()) &&
          receiving_planner.segment_valid(p.front(), *grasp_q)) {
        pre_q = p.front();
        break;
      }
    }
    reach.start = now[&receiving];
    if (pre_q) {
      reach.goal = *pre_q;
      if (auto e = step(receiving_planner, receiving, reach, "receiving_approach", "", "");
          !e.empty())
        return e;
      reach.start = *pre_q;
    }
    reach.goal = *grasp_q;
    if (auto e = step(receiving_planner, receiving, reach, "receiving_grasp", "", "gripper_close");
        !e.empty())
      return e;
    cell.set_jaw(robot_q, receiving, jaw);

    // 4. Suction off; the suction arm backs off along the cup's axis where it can (else it
    // leaves directly) and goes home.
    const Eigen::Vector3d cup_axis = (rr.board * cup.cup).linear().col(2);
    const auto back =
        solutions(cell, suction, shifted(rr_tcp, -settings_.approach * cup_axis), *rr_q);
    MotionRequest leave;
    leave.board_world = rr.board;
    leave.start = *rr_q;
    bool backed_off = false;
    if (!back.empty()) {
      leave.robot_q = robot_q;
      leave.tool_in_hand = tool_in_hand;
      suction_planner.prepare(leave);
      if (suction_planner.valid(back.front()) &&
          suction_planner.segment_valid(*rr_q, back.front())) {
        leave.goal = back.front();
        if (auto e = step(suction_planner, suction, leave, "suction_retreat", "suction_off", "");
            !e.empty())
          return e;
        leave.start = back.front();
        backed_off = true;
      }
    }
    leave.goal = suction.spec.home;
    if (auto e = step(suction_planner, suction, leave, "suction_arm_home",
                      backed_off ? "" : "suction_off", "");
        !e.empty())
      return e;

    // 5. The slip-constrained transfer to the human.
    HeldBoard in_gripper;
    in_gripper.held = true;
    in_gripper.board_in_tcp = grasp.tcp.inverse();
    in_gripper.jaw = jaw;
    const Eigen::Vector3d axis_part = grasp.tcp.linear() * opening_tcp;
    const Eigen::Vector3d lever_part = core::lever_direction(
        axis_part, 0.5 * (grasp.contact_1 + grasp.contact_2), record->mass_properties.com);
    in_gripper.axis_tcp = opening_tcp;
    in_gripper.lever_tcp = grasp.tcp.linear().transpose() * lever_part;
    in_gripper.theta_c_deg = grasp.theta_c_deg;
    MotionRequest present;
    present.held = in_gripper;
    const core::Pose rh_tcp = goal.board * grasp.tcp;
    const auto rh_q =
        first_valid(receiving_planner, present,
                    solutions(cell, receiving, rh_tcp, *grasp_q,
                              stored("human_handover", receiving.spec.name, grasp.id, 0, goal.id)));
    if (!rh_q) return "transfer_to_human: no valid IK at the robot-human pose";
    present.start = *grasp_q;
    present.goal = *rh_q;
    present.filter = filter_for("gripper", grasp.id);
    if (auto e =
            step(receiving_planner, receiving, present, "transfer_to_human", "", "wait_for_human");
        !e.empty())
      return e;

    // 6. The human takes it (wrist F/T): open, back off, home.
    cell.set_jaw(robot_q, receiving, cell.spec().gripper.jaw_max);
    const auto away =
        solutions(cell, receiving,
                  shifted(rh_tcp, -settings_.approach * (rh_tcp.linear() * approach_tcp)), *rh_q);
    if (away.empty()) return "release_retreat: no IK behind the robot-human pose";
    MotionRequest release;
    release.board_world = goal.board;
    release.start = *rh_q;
    release.goal = away.front();
    if (auto e = step(receiving_planner, receiving, release, "release_retreat", "gripper_open", "");
        !e.empty())
      return e;
    release.start = away.front();
    release.goal = receiving.spec.home;
    // The board is the human's now; it no longer stands where the arm goes home.
    if (auto e = step(receiving_planner, receiving, release, "receiving_arm_home", "", "");
        !e.empty())
      return e;
    result.robot_q_after = robot_q;
    return "";
  };

  int tried = 0;
  for (const auto& goal : goals) {
    if (tried++ >= settings_.goals) break;
    for (const auto& shared : db.shared_grasps(goal.id)) {
      if (std::chrono::steady_clock::now() >= deadline) {
        return finish(BoardPlanStatus::kTimeout, "the deadline passed after " +
                                                     std::to_string(result.attempts.size()) +
                                                     " goal attempts");
      }
      GoalAttempt attempt;
      attempt.rank = goal.rank;
      attempt.candidate_id = goal.id;
      attempt.robot_grasp_id = shared.robot_grasp_id;
      attempt.robot_handover_id = shared.robot_handover_id;
      std::vector<PlanStep> steps;
      const std::string failure = try_chain(goal, shared, steps);
      attempt.outcome = failure.empty() ? "planned" : failure;
      result.attempts.push_back(attempt);
      if (!failure.empty()) continue;
      result.steps = std::move(steps);
      result.goal_rank = goal.rank;
      result.candidate_id = goal.id;
      result.robot_grasp_id = shared.robot_grasp_id;
      result.suction_grasp_id = handovers.at(shared.robot_handover_id).suction_grasp_id;
      result.theta_c_deg = robot_grasps.at(shared.robot_grasp_id).theta_c_deg;
      result.quality = goal.quality;
      result.robot_handover = handovers.at(shared.robot_handover_id).board;
      result.human_handover = goal.board;
      result.duration = result.steps.back().time.back();
      for (const auto& s : result.steps) result.path_length += s.path_length;
      result.validated = true;
      return finish(BoardPlanStatus::kSolved, "");
    }
  }
  return finish(BoardPlanStatus::kNoGoal,
                goals.empty()
                    ? "the database has no handover goal for '" + board + "'"
                    : "none of the first " + std::to_string(std::min<int>(tried, settings_.goals)) +
                          " goals could be planned in this scene (see attempts)");
}

}  // namespace hila::online
