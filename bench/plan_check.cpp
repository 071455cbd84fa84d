#include "plan_check.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>

#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/online/validator.hpp"
#include "hila/online/world.hpp"

namespace hila::bench {

namespace {

// Where an attachment may be off the object: FK of an IK solution is exact to ~1e-9, so
// anything visible here means the plan grasps something where it is not.
constexpr double kPositionTolerance = 1e-4;  // m
constexpr double kAngleTolerance = 1e-3;     // rad

std::string pose_error(const core::Pose& is, const core::Pose& should) {
  const double dp = (is.translation() - should.translation()).norm();
  const double da = core::rotation_distance(is.linear(), should.linear());
  if (dp <= kPositionTolerance && da <= kAngleTolerance) return "";
  std::ostringstream s;
  s.precision(3);
  s << 1e3 * dp << " mm and " << core::rad_to_deg(da) << " deg off";
  return s.str();
}

std::vector<std::string> split_events(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string e; std::getline(in, e, ',');) {
    if (!e.empty()) out.push_back(e);
  }
  return out;
}

// Events that happen as their step starts (the arm lets go, then moves away); every other event
// happens when its step has arrived (docs/online.md: a step's starting event comes first).
bool starts_step(const std::string& event) {
  return event == "suction_off" || event == "gripper_open";
}

// The human who is there takes the board where the plan presents it: each receiving hand's
// joints in the plan, within the arm's limits, put that hand by forward kinematics (from the
// scene's stance: the worker's body, else the cell's human at its neutral posture) at the goal's
// human grasp on the board at the robot-human pose.
template <typename Problem>
void check_human_takes_it(const online::PlannerModel& model, const online::Scene& scene,
                          const online::BoardPlan& plan, const db::PartRecord& record,
                          Problem&& problem) {
  const core::Cell& cell = model.cell();
  const db::Database& db = model.database();
  std::optional<db::HandoverCandidateRecord> goal;
  for (const auto& g : db.handover_goals(record.id)) {
    if (g.id == plan.candidate_id) goal = g;
  }
  if (!goal) {
    problem(plan.board, "the plan's goal is not in the database");
    return;
  }
  std::map<std::int64_t, core::Pose> hand_in_part;
  for (const auto& h : db.human_grasps(record.id)) hand_in_part[h.id] = h.hand;
  const core::HumanBody* body = scene.worker.get();
  std::vector<core::Pose> links;
  cell.human().link_poses(cell.human_neutral(), links);
  const std::vector<core::HumanArm>& arms = body != nullptr ? body->arms() : cell.human_arms();
  const auto takes = [&](const std::string& arm_name, const Eigen::VectorXd& q,
                         std::int64_t grasp_id, const std::string& plan_arm) {
    const std::string where = plan.board + ": the human's " + arm_name + " hand";
    const auto a = std::find_if(arms.begin(), arms.end(),
                                [&](const core::HumanArm& h) { return h.spec.name == arm_name; });
    const auto hand = hand_in_part.find(grasp_id);
    if (a == arms.end() || hand == hand_in_part.end()) {
      problem(where, "the goal names a human arm or grasp the model or database has not");
      return;
    }
    if (plan_arm != arm_name || q.size() != a->chain.dof()) {
      problem(where, "the plan's receiving posture is not the goal's arm or has " +
                         std::to_string(q.size()) + " joints");
      return;
    }
    if (!a->chain.within_limits(q, 1e-9)) problem(where, "its joints are outside their limits");
    const core::Pose base =
        body != nullptr
            ? body->base_in_stance(static_cast<int>(a - arms.begin()))
            : links[static_cast<std::size_t>(cell.human().link_index(a->spec.base_link))];
    const std::string off =
        pose_error(scene.human_stance * base * a->chain.fk(q), plan.human_handover * hand->second);
    if (!off.empty()) problem(where, "is " + off + " its grasp on the presented board");
  };
  takes(goal->human_arm, plan.human_joints, goal->human_grasp_id, plan.human_arm);
  if (!goal->second_arm.empty()) {
    takes(goal->second_arm, plan.second_human_joints, goal->second_grasp_id, plan.second_human_arm);
  }
}

}  // namespace

PlanCheck check_plan(const online::PlannerModel& model, const online::Scene& scene,
                     const online::BoardPlan& plan, const online::BoardPlanSettings& settings) {
  PlanCheck out;
  auto problem = [&](const std::string& where, const std::string& what) {
    out.problems.push_back(where + ": " + what);
  };
  if (!plan.solved()) {
    problem(plan.board, "not a solved plan");
    return out;
  }
  if (!plan.validated) problem(plan.board, "the planner did not mark it validated");
  if (plan.steps.empty()) {
    problem(plan.board, "a solved plan without steps");
    return out;
  }
  const core::Cell& cell = model.cell();
  const core::ProductSpec& product = model.product();
  const core::PartSpec& part = product.part(plan.board);
  const db::Database& db = model.database();
  const db::PartRecord* record = nullptr;
  for (const auto& p : db.parts()) {
    if (p.name == plan.board) record = &p;
  }
  std::optional<db::RobotGraspRecord> grasp, first_grasp;  // first: the regrasp's pick grasp
  std::optional<db::SuctionGraspRecord> cup;
  const bool regrasp = plan.mode == online::DeliveryMode::kRegrasp;
  if (record != nullptr) {
    for (const auto& g : db.robot_grasps(record->id)) {
      if (g.id == plan.robot_grasp_id) grasp = g;
      if (regrasp && g.id == plan.pick_grasp_id) first_grasp = g;
    }
    for (const auto& c : db.suction_grasps(record->id)) {
      if (c.id == plan.suction_grasp_id) cup = c;
    }
  }
  const bool exchange = plan.mode == online::DeliveryMode::kExchange;
  // The suction way: the board on the cup from the pick to the human, no gripper.
  const bool on_cup_only = plan.mode == online::DeliveryMode::kSuction;
  if ((!grasp && !on_cup_only) || ((exchange || on_cup_only) && !cup) ||
      (regrasp && !first_grasp)) {
    problem(plan.board, "the plan's robot or suction grasp is not in the database");
    return out;
  }
  if (on_cup_only && plan.theta_c_deg != 90.0) {
    problem(plan.board, "a suction delivery with a slip limit (the cup has none)");
  }
  if (grasp && std::abs(grasp->theta_c_deg - plan.theta_c_deg) > 1e-9) {
    problem(plan.board, "the plan's theta_c is not its grasp's");
  }

  // The board's own steps see the tool where the plan's first steps set it down, if they moved it.
  online::Scene board_scene = scene;
  if (plan.tool_place) {
    board_scene.tool = *plan.tool_place;
    board_scene.tool_in_hand = false;
  }
  const online::World world(
      cell, product, board_scene, plan.board,
      plan.suction_arm.empty() ? online::kDefaultSuctionArm : plan.suction_arm);
  core::CollisionData data = world.make_data();
  const core::StageScene& stage = world.stage();
  const core::Arm& suction = cell.arms()[static_cast<std::size_t>(stage.suction_arm)];
  const core::Arm& receiving = cell.arms()[stage.suction_arm == 0 ? 1u : 0u];

  // The board in each hand, and the slip of the gripper's hold (the cup has no slip limit).
  const core::Pose board_in_cup_tcp =
      cup ? stage.cup_in_tcp * cup->cup.inverse() : core::Pose::Identity();
  // The gripper's grasp: the regrasp's pick grasp until the board is set down, then the plan's.
  struct GripperHold {
    core::Pose board_in_tcp;
    Eigen::Vector3d lever_tcp;
    double theta_c_deg = 90.0;
    double jaw = 0.0;
  };
  const Eigen::Vector3d opening = cell.spec().gripper.opening_axis.normalized();
  auto hold_of = [&](const db::RobotGraspRecord& g) {
    GripperHold h;
    h.board_in_tcp = g.tcp.inverse();
    const Eigen::Vector3d lever_part = core::lever_direction(
        g.tcp.linear() * opening, 0.5 * (g.contact_1 + g.contact_2), record->mass_properties.com);
    h.lever_tcp = g.tcp.linear().transpose() * lever_part;
    h.theta_c_deg = g.theta_c_deg;
    h.jaw = std::min(cell.spec().gripper.jaw_max, g.jaw_width + settings.jaw_margin);
    return h;
  };
  GripperHold hold;
  if (grasp) hold = hold_of(regrasp ? *first_grasp : *grasp);
  bool set_down = false;  // the regrasp's set-down happened

  // The cell at the scene's start.
  Eigen::VectorXd robot_q = cell.home_configuration();
  for (const auto& arm : cell.arms()) {
    const auto it = scene.robot.find(arm.spec.name);
    if (it != scene.robot.end()) cell.set_arm(robot_q, arm, it->second);
  }
  bool tool_in_hand = board_scene.tool_in_hand && board_scene.tool_arm == suction.spec.name;
  bool on_cup = false, handed_over = false;
  const core::Arm* in_gripper = nullptr;              // the arm whose gripper holds the board
  core::Pose board_world = scene.initial_pose(part);  // while neither hand holds it
  auto tcp_of = [&](const core::Arm& arm) {
    return core::arm_base_in_world(cell, arm) * arm.chain.fk(cell.arm_joints(robot_q, arm));
  };
  auto board_now = [&]() {
    if (on_cup) return tcp_of(suction) * board_in_cup_tcp;
    if (in_gripper) return tcp_of(*in_gripper) * hold.board_in_tcp;
    return board_world;
  };

  double clock = -1e300;
  // The tool moved first by the other arm (BoardPlan::tool_move_steps): taken from the table
  // where the scene has it (unless that arm holds it), set down at the plan's tool_place, the arm
  // home; checked in a world where that arm carries the tool. The board lies where it was detected
  // meanwhile.
  const auto moving = static_cast<std::size_t>(std::max(0, plan.tool_move_steps));
  if (moving > 0) {
    const online::World holder_world(cell, product, scene, plan.board, plan.tool_move_arm);
    core::CollisionData holder_data = holder_world.make_data();
    const core::Arm& holder =
        cell.arms()[static_cast<std::size_t>(holder_world.stage().suction_arm)];
    bool held = scene.tool_in_hand && scene.tool_arm == holder.spec.name;
    if (&holder == &suction || moving > plan.steps.size() || !plan.tool_place ||
        (!held && (scene.tool_in_hand || !plan.tool_taken_from_table))) {
      problem(plan.board, "moves a tool the other arm neither holds nor finds on the table");
      return out;
    }
    core::Pose tool_at = scene.tool;  // while on the table
    bool lifting_tool = false, tool_set_down = false;
    for (std::size_t i = 0; i < moving; ++i) {
      const online::PlanStep& step = plan.steps[i];
      ++out.steps;
      const std::string where = plan.board + ": " + step.name;
      if (step.arm != holder.spec.name || step.q.empty() || step.q.size() != step.time.size()) {
        problem(where, "expected the arm moving the tool and one time per waypoint");
        return out;
      }
      const Eigen::VectorXd now = cell.arm_joints(robot_q, holder);
      if (step.q.front().size() != now.size() || (step.q.front() - now).norm() > 1e-6) {
        problem(where, "starts away from where its arm is");
      }
      if (step.time.front() < clock - 1e-9) problem(where, "starts before the previous step ends");
      clock = step.time.back();
      const auto events = split_events(online::events_text(step));
      bool released = false, grasped = false;
      for (const auto& e : events) {
        if (e == "tool_released") {
          released = true;
        } else if (e == "tool_grasped") {
          grasped = true;
        } else {
          problem(where, "unexpected event '" + e + "' moving the tool");
        }
      }
      online::Motion motion;
      motion.arm = holder.spec.name;
      motion.time = step.time;
      motion.q = step.q;
      motion.robot_q = robot_q;
      motion.board_world = board_world;
      motion.tool_in_hand = held;
      motion.tool_world = tool_at;
      motion.start_in_contact = lifting_tool;
      motion.end_in_contact = released;
      const online::ValidationReport report =
          online::validate_motion(holder_world, holder_data, motion, settings.validator);
      out.samples += report.samples;
      for (const auto& v : report.violations) {
        std::ostringstream s;
        s.precision(3);
        s << v.kind << " at " << v.time << " s: " << v.detail;
        problem(where, s.str());
      }
      cell.set_arm(robot_q, holder, step.q.back());
      lifting_tool = false;
      const core::Pose handle = tcp_of(holder) * cell.spec().suction.handle_in_tcp;
      if (grasped) {
        if (held) problem(where, "grasps a tool it holds");
        const std::string off = pose_error(handle, tool_at);
        if (!off.empty()) problem(where, "grasps the tool's handle " + off);
        held = true;
        lifting_tool = true;
        cell.set_jaw(robot_q, holder, cell.spec().suction.handle_width);
      }
      if (released) {
        if (!held) problem(where, "sets down a tool it does not hold");
        const std::string off = pose_error(handle, *plan.tool_place);
        if (!off.empty()) problem(where, "sets the tool down " + off + " the plan's place");
        held = false;
        tool_set_down = true;
        tool_at = *plan.tool_place;
        cell.set_jaw(robot_q, holder, cell.spec().gripper.jaw_max);
      }
    }
    if (held || !tool_set_down) problem(plan.board, "the tool moved first is not set down");
  }
  bool lifting = false;  // the step after a pick starts with the object still on the table
  for (std::size_t index = moving; index < plan.steps.size(); ++index) {
    const online::PlanStep& step = plan.steps[index];
    ++out.steps;
    const std::string where = plan.board + ": " + step.name;
    const core::Arm* arm = step.arm == suction.spec.name     ? &suction
                           : step.arm == receiving.spec.name ? &receiving
                                                             : nullptr;
    if (arm == nullptr || step.q.empty() || step.q.size() != step.time.size()) {
      problem(where, "expected a known arm and one time per waypoint");
      return out;
    }
    const auto events = split_events(online::events_text(step));
    bool started = true;
    for (const auto& e : events) {
      if (!starts_step(e)) {
        started = false;
      } else if (!started) {
        problem(where, "starting event '" + e + "' after an arriving one");
      }
    }
    for (const auto& e : events) {
      if (e == "suction_off") {
        if (arm != &suction || !on_cup) problem(where, "suction off without the cup on the board");
        board_world = board_now();
        on_cup = false;
        if (on_cup_only) handed_over = true;  // the human holds it
      } else if (e == "gripper_open") {
        if (arm != in_gripper) problem(where, "gripper opens without the board");
        board_world = board_now();
        in_gripper = nullptr;
        handed_over = true;
        cell.set_jaw(robot_q, *arm, cell.spec().gripper.jaw_max);
      }
    }

    const Eigen::VectorXd now = cell.arm_joints(robot_q, *arm);
    if (step.q.front().size() != now.size() || (step.q.front() - now).norm() > 1e-6) {
      problem(where, "starts away from where its arm is");
    }
    if (step.time.front() < clock - 1e-9) problem(where, "starts before the previous step ends");
    clock = step.time.back();
    if (on_cup && in_gripper) problem(where, "an arm moves while both hold the board");

    online::Motion motion;
    motion.arm = arm->spec.name;
    motion.time = step.time;
    motion.q = step.q;
    motion.robot_q = robot_q;
    const bool holds_on_cup = arm == &suction && on_cup;
    motion.holds_board = holds_on_cup || arm == in_gripper;
    if (motion.holds_board) {
      motion.board_in_tcp = holds_on_cup ? board_in_cup_tcp : hold.board_in_tcp;
      if (!holds_on_cup) {
        motion.slip_axis_tcp = opening;
        motion.slip_lever_tcp = hold.lever_tcp;
        motion.theta_c_deg = hold.theta_c_deg;
      }
    } else {
      motion.board_world = board_now();
    }
    motion.tool_in_hand = tool_in_hand;
    motion.tool_world = board_scene.tool;
    motion.start_in_contact = lifting;
    // The tool's foot, or a board set down for a regrasp, meets the table at the last sample.
    motion.end_in_contact =
        std::find(events.begin(), events.end(), "tool_released") != events.end() ||
        std::find(events.begin(), events.end(), "set_down") != events.end();
    const online::ValidationReport report =
        online::validate_motion(world, data, motion, settings.validator);
    out.samples += report.samples;
    for (const auto& v : report.violations) {
      std::ostringstream s;
      s.precision(3);
      s << v.kind << " at " << v.time << " s: " << v.detail;
      problem(where, s.str());
    }
    cell.set_arm(robot_q, *arm, step.q.back());
    lifting = false;

    for (const auto& e : events) {
      if (starts_step(e)) continue;
      if (e == "tool_grasped") {
        if (arm != &suction || tool_in_hand) problem(where, "grasps a tool it cannot");
        const std::string off =
            pose_error(tcp_of(suction) * cell.spec().suction.handle_in_tcp, board_scene.tool);
        if (!off.empty()) problem(where, "grasps the tool's handle " + off);
        tool_in_hand = true;
        cell.set_jaw(robot_q, suction, cell.spec().suction.handle_width);
        lifting = true;
      } else if (e == "tool_released") {
        if (arm != &suction || !tool_in_hand || on_cup) {
          problem(where, "sets down a tool it does not hold, or the board with it");
        }
        const std::string off =
            pose_error(tcp_of(suction) * cell.spec().suction.handle_in_tcp, board_scene.tool);
        if (!off.empty()) problem(where, "sets the tool down " + off + " its place");
        tool_in_hand = false;
        cell.set_jaw(robot_q, suction, cell.spec().gripper.jaw_max);
      } else if (e == "set_down") {
        if (!regrasp || set_down || in_gripper != arm || on_cup) {
          problem(where, "sets down a board it does not hold, or not for a regrasp");
        }
        const std::string at = pose_error(board_now(), plan.set_down);
        if (!at.empty()) problem(where, "sets the board down " + at + " the plan's set-down pose");
        board_world = board_now();
        in_gripper = nullptr;
        set_down = true;
        hold = hold_of(*grasp);  // the next close takes it with the delivering grasp
        cell.set_jaw(robot_q, *arm, cell.spec().gripper.jaw_max);
      } else if (e == "suction_on") {
        if (arm != &suction || !tool_in_hand || on_cup || in_gripper != nullptr || handed_over) {
          problem(where, "suction on without the tool or with the board already taken");
        }
        const std::string off = pose_error(tcp_of(suction) * board_in_cup_tcp, board_world);
        if (!off.empty()) problem(where, "the cup meets the board " + off + " its detected pose");
        on_cup = true;
        lifting = true;
      } else if (e == "gripper_close") {
        const std::string off = pose_error(tcp_of(*arm) * hold.board_in_tcp, board_now());
        if (!off.empty()) problem(where, "the gripper closes " + off + " the board");
        if (on_cup) {  // the exchange: from the suction arm's cup to the other arm's gripper
          if (arm == &suction) problem(where, "the suction arm closes on the board on its cup");
          const std::string at = pose_error(board_now(), plan.robot_handover);
          if (!at.empty()) problem(where, "the exchange is " + at + " the plan's robot-robot pose");
        } else {  // a direct pick where the board lies
          if (exchange || on_cup_only || in_gripper != nullptr || handed_over) {
            problem(where,
                    "closes on a board that is not standing where it was detected or set "
                    "down");
          }
          if (arm == &suction && tool_in_hand) problem(where, "closes a gripper holding the tool");
          lifting = true;
        }
        in_gripper = arm;
        cell.set_jaw(robot_q, *arm, hold.jaw);
      } else if (e == "wait_for_human") {
        const bool holding = on_cup_only ? (arm == &suction && on_cup && in_gripper == nullptr)
                                         : (in_gripper == arm && !on_cup);
        if (!holding) problem(where, "waits for the human without the board");
        const std::string at = pose_error(board_now(), plan.human_handover);
        if (!at.empty()) problem(where, "presents the board " + at + " the robot-human pose");
      } else {
        problem(where, "unknown event '" + e + "'");
      }
    }
  }
  if (!handed_over || on_cup || in_gripper) {
    problem(plan.board, "the board does not end with the human");
  }
  if (record != nullptr) check_human_takes_it(model, scene, plan, *record, problem);
  return out;
}

}  // namespace hila::bench
