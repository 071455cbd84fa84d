#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/online/board_planner.hpp"
#include "io_checks.hpp"
#include "option_checks.hpp"
#include "plan_sequence.hpp"
#include "receiving_ergonomics.hpp"

namespace hila::tools {

namespace {

// The longest --deadline: a day per board (the steady clock's nanoseconds overflow past 292
// years; anything near that is a typo).
constexpr double kMaxDeadlineSeconds = 86400.0;
// The shortest --deadline: a millisecond. Below it a board ends before its first goal attempt
// (1e-300 s reads as "no time at all"), which is never what the caller meant.
constexpr double kMinDeadlineSeconds = 0.001;

struct PlanOptions {
  std::string database;
  std::string scene;
  std::string board;
  bool all = false;
  std::string output;
  bool output_given = false;  // -o was on the command line (perhaps as '')
  bool json = false;
  double deadline_s = kDefaultBoardDeadlineSeconds;
  bool eq8_order = false;  // BoardPlanSettings::natural_posture_first off
};

nlohmann::json pose_to_json(const core::Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  return {{"xyz", {t.x(), t.y(), t.z()}}, {"quat_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

// The worker a plan is for: the scene's `worker` (stature and sex) or the cell's own human.
nlohmann::json worker_json(const std::shared_ptr<const core::HumanBody>& worker,
                           const core::Cell& cell) {
  if (worker == nullptr) return {{"from", "cell"}, {"urdf", cell.spec().human_urdf}};
  return {{"from", "scene"},
          {"stature", worker->spec().stature},
          {"sex", worker->spec().sex == core::Sex::Male ? "male" : "female"}};
}

nlohmann::json plan_json(const online::BoardPlan& plan, const core::Cell& cell, double load_kg,
                         const core::Pose& stance, const Eigen::Vector3d& centre_of_mass) {
  nlohmann::json attempts = nlohmann::json::array();
  for (const auto& a : plan.attempts) {
    attempts.push_back({{"rank", a.rank},
                        {"candidate", a.candidate_id},
                        {"mode", online::to_string(a.mode)},
                        {"arm", a.arm},
                        {"robot_grasp", a.robot_grasp_id},
                        {"suction_grasp", a.suction_grasp_id},
                        {"robot_handover", a.robot_handover_id},
                        {"estimated_s", a.estimated_seconds},
                        {"result", online::to_string(a.result)},
                        {"larger_bridges", a.larger_bridges},
                        {"step", a.step},
                        {"outcome", a.outcome}});
  }
  nlohmann::json steps = nlohmann::json::array();
  for (const auto& s : plan.steps) {
    nlohmann::json q = nlohmann::json::array();
    for (const auto& v : s.q) q.push_back(std::vector<double>(v.data(), v.data() + v.size()));
    steps.push_back({{"name", s.name},
                     {"arm", s.arm},
                     {"via", online::via_text(s)},
                     {"events", online::events_text(s)},
                     {"path_length_rad", s.path_length},
                     {"smoothed", s.smoothed},
                     {"validated", s.validation.valid()},
                     {"time_s", s.time},
                     {"joints_rad", q}});
  }
  nlohmann::json j = {{"board", plan.board},
                      {"status", online::to_string(plan.status)},
                      {"reason", plan.reason},
                      {"worker", worker_json(plan.worker, cell)},
                      {"planning_ms", 1e3 * plan.planning_seconds},
                      {"planning_split_ms",
                       {{"motions", 1e3 * plan.times.motions},
                        {"smoothing", 1e3 * plan.times.smoothing},
                        {"validation", 1e3 * plan.times.validation},
                        {"queued_validation", 1e3 * plan.times.queued_validation},
                        {"queued_smoothing", 1e3 * plan.times.queued_smoothing}}},
                      {"attempts", attempts},
                      {"rejected_motions", plan.rejected_motions},
                      {"goals_out_of_reach", plan.goals_out_of_reach},
                      {"goals_uncomfortable", plan.goals_uncomfortable},
                      {"goals_natural", plan.goals_natural},
                      {"human_postures_solved", plan.human_postures_solved}};
  if (plan.solved()) {
    // The way: who picks and how, the exchanges (from the cup to the other arm's gripper), who
    // delivers.
    nlohmann::json exchanges = nlohmann::json::array();
    if (plan.mode == online::DeliveryMode::kExchange) {
      exchanges.push_back({{"from", plan.picking_arm},
                           {"to", plan.delivering_arm},
                           {"board", pose_to_json(plan.robot_handover)}});
    }
    j["mode"] = {
        {"way", online::to_string(plan.mode)},
        {"pick",
         {{"arm", plan.picking_arm},
          {"by", plan.mode == online::DeliveryMode::kExchange ||
                         plan.mode == online::DeliveryMode::kSuction
                     ? "suction"
                     : "gripper"}}},
        {"exchanges", exchanges},
        {"delivered_by", plan.delivering_arm},
        {"suction_tool", {{"arm", plan.suction_arm}, {"in_hand_after", plan.tool_in_hand_after}}}};
    if (plan.tool_move_steps > 0 && plan.tool_place) {
      j["mode"]["suction_tool"]["moved_first"] = {
          {"arm", plan.tool_move_arm},
          {"steps", plan.tool_move_steps},
          {"from", plan.tool_taken_from_table ? "table" : "hand"},
          {"to", pose_to_json(*plan.tool_place)}};
    }
    if (plan.mode == online::DeliveryMode::kRegrasp) {
      j["mode"]["set_down"] = {{"board", pose_to_json(plan.set_down)},
                               {"pick_grasp", plan.pick_grasp_id},
                               {"grasp_again", plan.robot_grasp_id},
                               {"taken_again_by", plan.delivering_arm}};
    }
    j["goal_rank"] = plan.goal_rank;
    j["candidate"] = plan.candidate_id;
    j["robot_grasp"] = plan.robot_grasp_id;
    j["suction_grasp"] = plan.suction_grasp_id;
    j["theta_c_deg"] = plan.theta_c_deg;
    j["quality"] = plan.quality;
    nlohmann::json posture = nlohmann::json::object();
    auto joints = [](const Eigen::VectorXd& q) {
      return std::vector<double>(q.data(), q.data() + q.size());
    };
    if (!plan.human_arm.empty()) posture[plan.human_arm] = joints(plan.human_joints);
    if (!plan.second_human_arm.empty())
      posture[plan.second_human_arm] = joints(plan.second_human_joints);
    j["human_posture_rad"] = posture;
    j["natural_posture"] = plan.natural_posture;
    j["ergonomics"] = receiving_ergonomics_json(
        plan_receiving_ergonomics(cell, plan, load_kg, stance, centre_of_mass));
    if (plan.mode == online::DeliveryMode::kExchange) {
      j["robot_handover"] = pose_to_json(plan.robot_handover);
    }
    j["human_handover"] = pose_to_json(plan.human_handover);
    j["duration_s"] = plan.duration;
    j["estimated_s"] = plan.estimated_seconds;
    j["path_length_rad"] = plan.path_length;
    j["validated"] = plan.validated;
    j["larger_bridges"] = plan.larger_bridges;
    j["steps"] = steps;
  }
  return j;
}

int run_plan(const PlanOptions& opt) {
  if (opt.all == !opt.board.empty()) {
    throw core::InputError("hila plan", "--board/--all", "exactly one of --board NAME or --all",
                           opt.all ? "both" : "neither");
  }
  std::vector<InputFile> inputs{{opt.database, "the database"}, {opt.scene, "the scene file"}};
  if (opt.output_given) check_output_path("-o", opt.output, inputs);
  const online::SceneFiles files = online::read_scene_files(opt.scene);
  if (opt.output_given) {
    for (auto&& more : {cell_input_files(files.cell), product_input_files(files.product)}) {
      inputs.insert(inputs.end(), more.begin(), more.end());
    }
    check_output_path("-o", opt.output, inputs);
  }
  const auto model = online::PlannerModel::load(opt.database, files.cell, files.product);
  online::Scene scene = online::load_scene(opt.scene, model->cell(), model->product());
  std::vector<std::string> boards;
  if (opt.all) {
    boards = boards_to_plan(*model, scene);
  } else {
    model->product().part(opt.board);  // InputError naming the product file for an unknown board
    if (scene.is_finished(opt.board)) {
      throw core::InputError(opt.scene, "finished", "'" + opt.board + "' still to be handled",
                             "it is listed as finished");
    }
    boards.push_back(opt.board);
  }
  online::BoardPlanSettings settings;
  settings.natural_posture_first = !opt.eq8_order;
  online::BoardPlanner planner(*model, settings);
  nlohmann::json out = {{"hila_plan", 1},
                        {"database", opt.database},
                        {"scene", opt.scene},
                        {"product", model->product().name},
                        {"worker", worker_json(scene.worker, model->cell())},
                        {"boards", nlohmann::json::array()}};
  int failed = 0;
  if (!opt.json) {
    std::cout
        << "  board           theta_c   Q      goals  plan ms   path rad  motion s  validated\n";
  }
  plan_in_sequence(
      *model, planner, scene, boards, opt.deadline_s,
      [&](const online::BoardPlan& plan, const online::Scene& planned_in) {
        const std::string& board = plan.board;
        const online::BoardRecords* records = model->board_records(board);
        out["boards"].push_back(plan_json(
            plan, model->cell(), model->product().part(board).mass, planned_in.human_stance,
            records != nullptr ? records->part.mass_properties.com : Eigen::Vector3d::Zero()));
        if (!opt.json) {
          std::cout << "  " << std::left << std::setw(15) << board << std::right << std::fixed;
          if (plan.solved()) {
            std::cout << std::setprecision(0) << std::setw(8) << plan.theta_c_deg
                      << std::setprecision(3) << std::setw(7) << plan.quality << std::setw(7)
                      << plan.attempts.size() << std::setprecision(1) << std::setw(9)
                      << 1e3 * plan.planning_seconds << std::setprecision(2) << std::setw(11)
                      << plan.path_length << std::setw(10) << plan.duration << "  "
                      << (plan.validated ? "yes" : "NO") << "\n";
          } else {
            std::cout << "  not planned (" << online::to_string(plan.status) << ", "
                      << plan.attempts.size() << " attempts, " << std::setprecision(1)
                      << 1e3 * plan.planning_seconds << " ms): " << plan.reason << "\n";
          }
        }
        if (!plan.solved()) ++failed;
      });
  if (opt.output_given) write_file_atomically(opt.output, out.dump(1) + "\n");
  if (opt.json) std::cout << out.dump(1) << "\n";
  if (failed > 0) {
    std::cerr << "hila: " << failed << " board(s) not planned; the plan file says why\n";
    return 1;
  }
  return 0;
}

}  // namespace

void add_plan_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<PlanOptions>();
  CLI::App* cmd = app.add_subcommand(
      "plan", "plan the robot's motions for boards from a database, for the scene as it is");
  cmd->add_option("--db", opt->database, "the product database (hila build)")->required();
  cmd->add_option("--scene", opt->scene, "the scene file (docs/scene.md)")->required();
  cmd->add_option("--board", opt->board, "plan this board");
  cmd->add_flag("--all", opt->all, "plan every board still to be handled, in assembly order");
  CLI::Option* output =
      cmd->add_option("-o,--output", opt->output, "write the plan (JSON, docs/online.md)");
  cmd->add_flag("--json", opt->json, "print the plan as JSON instead of the table");
  cmd->add_flag("--eq8-order", opt->eq8_order,
                "try the goals in Eq. 8 order within the comfort tiers only, not the goals with a "
                "natural receiving posture first");
  cmd->add_option("--deadline", opt->deadline_s, "seconds per board (default 30)")
      ->check(number_in(kMinDeadlineSeconds, kMaxDeadlineSeconds, false, "seconds"));
  cmd->callback([opt, output, &action] {
    opt->output_given = output->count() > 0;
    action = [opt] { return run_plan(*opt); };
  });
}

}  // namespace hila::tools
