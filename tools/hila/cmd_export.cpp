#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "db_scenes.hpp"
#include "hila/core/error.hpp"
#include "hila/viz/cell_export.hpp"
#include "io_checks.hpp"
#include "option_checks.hpp"
#include "scene_exports.hpp"

namespace hila::tools {

namespace {

struct ExportCellOptions {
  std::string cell_file;
  std::string product_file;         // empty: the cell only
  std::vector<std::string> joints;  // "ARM=q1,q2,...": an arm's joints (rad); others at home
  std::string output;
};

struct ExportPlanOptions {
  std::string database;
  std::string plan_file;
  std::string scene;  // empty: the scene the plan file names
  std::string output;
};

// `export grasps` and `export goals`: a part of a database.
struct ExportPartOptions {
  std::string database;
  std::string part;
  std::string cell_file;     // the database's cell (empty: the bundled one)
  std::string product_file;  // the database's product (empty: the bundled one)
  std::string arm;           // grasps: whose gripper (empty: the first arm)
  int count = 10;            // goals: how many, best first
  std::string colour = "q";  // goals: "q" (comfort Q) or "rula" (RULA grand score)
  std::string output;
};

// "--joints ARM=q1,...,qn" into the robot's configuration `robot_q`.
void set_joints(const core::Cell& cell, const std::string& text, Eigen::VectorXd& robot_q) {
  const auto equals = text.find('=');
  if (equals == std::string::npos) {
    throw core::InputError("hila export cell", "--joints", "ARM=q1,q2,... (rad)", text);
  }
  const core::Arm& arm = cell.arm(text.substr(0, equals));
  std::vector<double> values;
  std::stringstream list(text.substr(equals + 1));
  for (std::string item; std::getline(list, item, ',');) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v)) {
      throw core::InputError("hila export cell", "--joints", "finite numbers (rad)", item);
    }
    values.push_back(v);
  }
  const Eigen::VectorXd q =
      Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  if (q.size() != arm.chain.dof() || !arm.chain.within_limits(q)) {
    throw core::InputError(
        "hila export cell", "--joints",
        std::to_string(arm.chain.dof()) + " joints of arm " + arm.spec.name + " within its limits",
        text);
  }
  cell.set_arm(robot_q, arm, q);
}

int run_export_cell(const ExportCellOptions& opt) {
  std::vector<InputFile> inputs = cell_input_files(opt.cell_file);
  if (!opt.product_file.empty()) {
    const auto more = product_input_files(opt.product_file);
    inputs.insert(inputs.end(), more.begin(), more.end());
  }
  check_output_path("-o", opt.output, inputs);
  const auto cell = core::Cell::load(opt.cell_file);
  core::ProductSpec product;
  viz::CellView view;
  if (!opt.product_file.empty()) {
    product = core::load_product(opt.product_file);
    view = viz::product_view(product);
  }
  view.robot_q = cell->home_configuration(cell->spec().gripper.jaw_max);
  for (const std::string& j : opt.joints) set_joints(*cell, j, view.robot_q);
  const std::string glb = viz::cell_glb(*cell, view);
  write_file_atomically(opt.output, glb);
  std::cout << "wrote " << opt.output << " (" << glb.size() << " bytes)\n";
  return 0;
}

int run_export_plan(const ExportPlanOptions& opt) {
  check_output_path("-o", opt.output,
                    {{opt.database, "the database"}, {opt.plan_file, "the plan file"}});
  const PlanScene plan = read_plan_scene(opt.database, opt.plan_file, opt.scene);
  check_output_path("-o", opt.output, plan.inputs);
  const std::string glb = plan_scene_glb(plan);
  write_file_atomically(opt.output, glb);
  std::cout << "wrote " << opt.output << " (" << glb.size() << " bytes, " << plan.plan.boards.size()
            << " board(s), " << plan.plan.duration() << " s)\n";
  return 0;
}

CheckedDatabase open_part_database(const ExportPartOptions& opt) {
  const std::string cell_file = opt.cell_file.empty() ? default_cell_path() : opt.cell_file;
  const std::string product_file =
      opt.product_file.empty() ? default_product_path() : opt.product_file;
  check_output_path("-o", opt.output, database_input_files(opt.database, cell_file, product_file));
  return open_checked_database(opt.database, cell_file, product_file);
}

int run_export_grasps(const ExportPartOptions& opt) {
  const CheckedDatabase d = open_part_database(opt);
  const viz::GraspsView view = grasps_view(d, opt.part, opt.arm);
  const std::string glb = viz::grasps_glb(*d.cell, view);
  write_file_atomically(opt.output, glb);
  std::cout << "wrote " << opt.output << " (" << glb.size() << " bytes, " << view.gripper.size()
            << " gripper grasp(s), " << view.suction.size() << " suction grasp(s) of " << opt.part
            << ")\n";
  return 0;
}

int run_export_goals(const ExportPartOptions& opt) {
  const CheckedDatabase d = open_part_database(opt);
  const viz::GoalsView view = goals_view(d, opt.part, opt.count);
  viz::GoalsSettings settings;
  settings.colour = opt.colour == "rula" ? viz::GoalColour::kRula : viz::GoalColour::kQuality;
  const std::string glb = viz::goals_glb(*d.cell, view, settings);
  write_file_atomically(opt.output, glb);
  int exchanges = 0;
  for (const auto& g : view.goals) exchanges += g.exchange ? 1 : 0;
  std::cout << "wrote " << opt.output << " (" << glb.size() << " bytes, " << view.goals.size()
            << " goal(s) of " << opt.part << ", " << exchanges << " with a robot-robot exchange)\n";
  if (view.goals.empty()) {
    const db::HandoverStageRecord* stage = d.database.handover_stage(d.database.part(opt.part).id);
    std::cout << "  " << opt.part << " has no handover goal"
              << (stage && !stage->failure.empty() ? ": " + stage->failure : std::string()) << "\n";
  }
  return 0;
}

// The options `export grasps` and `export goals` share.
CLI::App* add_part_subcommand(CLI::App& cmd, const std::string& name,
                              const std::string& description, ExportPartOptions& opt) {
  auto* sub = cmd.add_subcommand(name, description);
  sub->add_option("--db", opt.database, "the product database")->required();
  sub->add_option("--part", opt.part, "the part (its name in the product)")->required();
  sub->add_option("--cell", opt.cell_file, "the database's cell YAML (default: the bundled)");
  sub->add_option("--product", opt.product_file,
                  "the database's product YAML (default: the cabinet)");
  sub->add_option("-o,--output", opt.output, "the .glb to write")->required();
  return sub;
}

}  // namespace

void add_export_command(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand(
      "export", "write the cell, a plan, a part's grasps or goals as glTF 2.0 binary (.glb)");
  cmd->require_subcommand(1);

  auto cell_opt = std::make_shared<ExportCellOptions>();
  cell_opt->cell_file = default_cell_path();
  auto* cell = cmd->add_subcommand(
      "cell", "the cell: robot, tool, table and human; with --product the parts");
  cell->add_option("--cell", cell_opt->cell_file, "cell YAML file")->capture_default_str();
  cell->add_option("--product", cell_opt->product_file,
                   "product YAML file: the tool where it puts it, the parts at their targets and "
                   "their initial poses");
  cell->add_option("--joints", cell_opt->joints,
                   "ARM=q1,q2,... an arm's joints (rad; repeatable); other arms at home");
  cell->add_option("-o,--output", cell_opt->output, "the .glb to write")->required();
  cell->callback(
      [cell_opt, &action] { action = [cell_opt] { return run_export_cell(*cell_opt); }; });

  auto plan_opt = std::make_shared<ExportPlanOptions>();
  auto* plan = cmd->add_subcommand("plan", "a plan (hila plan -o) animated along its time stamps");
  plan->add_option("--db", plan_opt->database, "the product database the plan was made with")
      ->required();
  plan->add_option("--plan", plan_opt->plan_file, "the plan file (hila plan -o)")->required();
  plan->add_option("--scene", plan_opt->scene, "the scene file (default: the one the plan names)");
  plan->add_option("-o,--output", plan_opt->output, "the .glb to write")->required();
  plan->callback(
      [plan_opt, &action] { action = [plan_opt] { return run_export_plan(*plan_opt); }; });

  auto grasps_opt = std::make_shared<ExportPartOptions>();
  auto* grasps = add_part_subcommand(
      *cmd, "grasps",
      "a part with the gripper at each of its grasps (coloured by theta_c) and the suction tool "
      "at each suction grasp (coloured by holding margin)",
      *grasps_opt);
  grasps->add_option("--arm", grasps_opt->arm, "whose gripper to draw (default: the first arm)");
  grasps->callback(
      [grasps_opt, &action] { action = [grasps_opt] { return run_export_grasps(*grasps_opt); }; });

  auto goals_opt = std::make_shared<ExportPartOptions>();
  auto* goals = add_part_subcommand(*cmd, "goals",
                                    "a part's best handover goals side by side: the part (coloured "
                                    "by Q or RULA), the human receiving "
                                    "it, the robot at the goal's robot-robot exchange",
                                    *goals_opt);
  goals->add_option("--count", goals_opt->count, "how many goals, best first")
      ->check(int_in(1, 1000))
      ->capture_default_str();
  goals
      ->add_option("--colour", goals_opt->colour,
                   "colour the part by q (comfort Q, lowest shown red to highest green) or by rula "
                   "(the receiving posture's RULA grand score: 1 green to 7 red)")
      ->check(CLI::IsMember({"q", "rula"}))
      ->capture_default_str();
  goals->callback(
      [goals_opt, &action] { action = [goals_opt] { return run_export_goals(*goals_opt); }; });
}

}  // namespace hila::tools
