#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>

#include "commands.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"

namespace hila::tools {

namespace {

struct CellCheckOptions {
  std::string cell_file;
  bool json = false;
};

nlohmann::json vec_json(const Eigen::VectorXd& v, double scale = 1.0, int decimals = 6) {
  nlohmann::json out = nlohmann::json::array();
  const double f = std::pow(10.0, decimals);
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(std::round(v[i] * scale * f) / f);
  return out;
}

// Largest distance from the shoulder to the grasp frame, over seeded random configurations.
double human_arm_reach(const core::Cell& cell, const core::HumanArm& arm) {
  const core::RobotModel& human = cell.human();
  const int shoulder_joint = human.joint_index(arm.spec.name + "_shoulder_flexion");
  std::vector<core::Pose> poses;
  Eigen::VectorXd q = human.neutral_configuration();
  human.link_poses(q, poses);
  const core::Pose base_in_root = poses[human.link_index(arm.spec.base_link)];
  const Eigen::Vector3d shoulder =
      base_in_root.inverse() * poses[human.joints()[shoulder_joint].child_link].translation();
  std::mt19937_64 rng(1);
  double reach = 0.0;
  for (int i = 0; i < 2000; ++i) {
    Eigen::VectorXd qa(arm.chain.dof());
    for (int k = 0; k < arm.chain.dof(); ++k) {
      qa[k] = std::uniform_real_distribution<double>(arm.chain.lower_limits()[k],
                                                     arm.chain.upper_limits()[k])(rng);
    }
    if (i == 0) qa.setZero();  // straight arm
    reach = std::max(reach, (arm.chain.fk(qa).translation() - shoulder).norm());
  }
  return reach;
}

int run_cell_check(const CellCheckOptions& opt) {
  const auto cell = core::Cell::load(opt.cell_file);
  const core::CellScene scene = core::build_cell_scene(*cell, {.human_moves = true});
  core::CollisionData data(scene.model);
  const Eigen::VectorXd robot_q = cell->home_configuration(cell->spec().gripper.jaw_max);
  core::set_cell_state(*cell, scene, data, robot_q, cell->human_neutral());
  core::CollisionPair pair;
  const bool colliding = core::in_collision(scene.model, data, &pair);
  core::CollisionPair closest;
  const double clearance = colliding ? 0.0 : core::min_distance(scene.model, data, &closest);

  nlohmann::json report;
  report["cell"] = opt.cell_file;
  report["robot_urdf"] = cell->spec().robot_urdf;
  report["arms"] = nlohmann::json::array();
  std::vector<core::Pose> link_poses;
  cell->robot().link_poses(robot_q, link_poses);
  for (const core::Arm& arm : cell->arms()) {
    const core::Pose base = link_poses[cell->robot().link_index(arm.spec.base_link)];
    const core::Pose tcp = base * arm.chain.fk(arm.spec.home);
    nlohmann::json limits = nlohmann::json::array();
    for (int i = 0; i < arm.chain.dof(); ++i) {
      limits.push_back({std::round(core::rad_to_deg(arm.chain.lower_limits()[i])),
                        std::round(core::rad_to_deg(arm.chain.upper_limits()[i]))});
    }
    report["arms"].push_back({
        {"name", arm.spec.name},
        {"dof", arm.chain.dof()},
        {"base_link", arm.spec.base_link},
        {"tip_link", arm.spec.tip_link},
        {"analytic_ik", arm.ur_ik.has_value()},
        {"joint_limits_deg", limits},
        {"home_deg", vec_json(arm.spec.home, 180.0 / core::kPi, 3)},
        {"home_tcp",
         {{"xyz", vec_json(tcp.translation())},
          {"rpy_deg", vec_json(core::matrix_to_rpy(tcp.linear()), 180.0 / core::kPi, 3)}}},
    });
  }
  report["human_arms"] = nlohmann::json::array();
  for (const core::HumanArm& arm : cell->human_arms()) {
    report["human_arms"].push_back(
        {{"name", arm.spec.name},
         {"dof", arm.chain.dof()},
         {"reach", std::round(human_arm_reach(*cell, arm) * 1e4) / 1e4}});
  }
  report["home_collision_free"] = !colliding;
  report["home_colliding_pair"] =
      colliding ? nlohmann::json(core::describe_pair(scene.model, pair)) : nlohmann::json(nullptr);
  report["home_clearance"] = colliding ? 0.0 : std::round(clearance * 1e4) / 1e4;
  report["home_closest_pair"] = colliding ? "" : core::describe_pair(scene.model, closest);
  report["collision_bodies"] = scene.model.num_bodies();

  if (opt.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << "cell " << opt.cell_file << "\n";
    for (const auto& arm : report["arms"]) {
      std::cout << "  arm " << arm["name"].get<std::string>() << ": " << arm["dof"] << " DoF ("
                << arm["base_link"].get<std::string>() << " -> "
                << arm["tip_link"].get<std::string>() << ")"
                << (arm["analytic_ik"].get<bool>() ? ", analytic UR IK" : "") << "\n"
                << "    joint limits (deg): " << arm["joint_limits_deg"].dump() << "\n"
                << "    home (deg): " << arm["home_deg"].dump() << "\n"
                << "    home TCP xyz (m): " << arm["home_tcp"]["xyz"].dump()
                << "  rpy (deg): " << arm["home_tcp"]["rpy_deg"].dump() << "\n";
    }
    for (const auto& arm : report["human_arms"]) {
      std::cout << "  human arm " << arm["name"].get<std::string>() << ": " << arm["dof"]
                << " DoF, reach " << arm["reach"].get<double>() << " m\n";
    }
    if (colliding) {
      std::cout << "  home: IN COLLISION (" << report["home_colliding_pair"].get<std::string>()
                << ")\n";
    } else {
      std::cout << "  home: collision-free, clearance " << report["home_clearance"].get<double>()
                << " m (" << report["home_closest_pair"].get<std::string>() << ")\n";
    }
  }
  return colliding ? 1 : 0;
}

}  // namespace

void add_cell_command(CLI::App& app, Action& action) {
  auto* cell = app.add_subcommand("cell", "Inspect and check a cell description");
  cell->require_subcommand(1);
  auto opt = std::make_shared<CellCheckOptions>();
  opt->cell_file = default_cell_path();
  auto* check = cell->add_subcommand(
      "check", "Load the cell, print arms, home TCPs, human reach; exit 1 if home collides");
  check->add_option("cell", opt->cell_file, "cell YAML file")->capture_default_str();
  check->add_flag("--json", opt->json, "print the report as JSON");
  check->callback([opt, &action] { action = [opt] { return run_cell_check(*opt); }; });
}

}  // namespace hila::tools
