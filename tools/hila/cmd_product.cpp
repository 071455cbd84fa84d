#include <filesystem>
#include <iomanip>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <system_error>

#include "commands.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/core/payload.hpp"
#include "hila/core/product.hpp"
#include "hila/offline/part_analysis.hpp"
#include "io_checks.hpp"

namespace hila::tools {

namespace {
struct ProductCheckOptions {
  std::string product_file;
  std::string cell_file;
  bool json = false;
};

// How far (m) a part's lowest point may lie from the surface it rests on, either way: mesh and
// pose rounding, and the 1 mm gaps products keep so that touching never reads as overlap.
constexpr double kRestTolerance = 0.005;

// The part's mesh at `pose`: its world bounding box.
struct PlacedBox {
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = -Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d centre() const { return 0.5 * (min + max); }
  double radius() const { return 0.5 * (max - min).norm(); }
  bool over(const Eigen::Vector3d& p) const {  // p's x, y within the box's footprint
    return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y();
  }
  bool overlaps_xy(const PlacedBox& o) const {
    return min.x() <= o.max.x() && o.min.x() <= max.x() && min.y() <= o.max.y() &&
           o.min.y() <= max.y();
  }
};

PlacedBox placed_box(const core::TriangleMesh& mesh, const core::Pose& pose) {
  PlacedBox box;
  for (const Eigen::Vector3d& v : mesh.vertices) {
    const Eigen::Vector3d w = pose * v;
    box.min = box.min.cwiseMin(w);
    box.max = box.max.cwiseMax(w);
  }
  return box;
}

PlacedBox obstacle_box(const core::BoxObstacle& o) {
  PlacedBox box;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d local(corner & 1 ? 0.5 : -0.5, corner & 2 ? 0.5 : -0.5,
                                corner & 4 ? 0.5 : -0.5);
    const Eigen::Vector3d w = o.pose * local.cwiseProduct(o.size);
    box.min = box.min.cwiseMin(w);
    box.max = box.max.cwiseMax(w);
  }
  return box;
}

std::string mm(double metres) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(0) << metres * 1000.0 << " mm";
  return out.str();
}
std::string metres(double m) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << m << " m";
  return out.str();
}

// The farthest the chain's tip gets from its first joint (the shoulder), over its joint
// ranges: the zero configuration (a stretched arm) and seeded random ones.
double chain_reach(const core::KinematicChain& chain) {
  std::mt19937_64 rng(1);
  const Eigen::Vector3d shoulder = chain.first_joint_position();
  double reach = 0.0;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(chain.dof());
  for (int i = 0; i < 2000; ++i) {
    if (i > 0) {
      for (int k = 0; k < chain.dof(); ++k) {
        q[k] = std::uniform_real_distribution<double>(chain.lower_limits()[k],
                                                      chain.upper_limits()[k])(rng);
      }
    }
    reach = std::max(reach, (chain.fk(q).translation() - shoulder).norm());
  }
  return reach;
}

// A shoulder in the world and how far from it a hand (TCP, suction cup, grasp frame) gets.
struct Reach {
  std::string name;
  Eigen::Vector3d shoulder;
  double radius = 0.0;
};

// The robot arms at home: the TCP's reach, plus the suction cup's offset from the TCP while the
// tool is held (the farthest point that picks a part).
std::vector<Reach> robot_reaches(const core::Cell& cell) {
  std::vector<core::Pose> poses;
  cell.robot().link_poses(cell.home_configuration(), poses);
  const core::RobotModel& tool = cell.suction_tool();
  std::vector<core::Pose> tool_poses;
  tool.link_poses(tool.neutral_configuration(), tool_poses);
  const core::Pose cup_in_tcp =
      cell.spec().suction.handle_in_tcp *
      tool_poses[tool.link_index(cell.spec().suction.handle_link)].inverse() *
      tool_poses[tool.link_index(cell.spec().suction.cup_link)];
  std::vector<Reach> reaches;
  for (const core::Arm& arm : cell.arms()) {
    const core::Pose base = poses[cell.robot().link_index(arm.spec.base_link)];
    reaches.push_back({arm.spec.name, base * arm.chain.first_joint_position(),
                       chain_reach(arm.chain) + cup_in_tcp.translation().norm()});
  }
  return reaches;
}

// The human's arms at the stance in the neutral posture: the grasp frame's reach.
std::vector<Reach> human_reaches(const core::Cell& cell) {
  std::vector<core::Pose> poses;
  cell.human().link_poses(cell.human_neutral(), poses);
  std::vector<Reach> reaches;
  for (const core::HumanArm& arm : cell.human_arms()) {
    const core::Pose base =
        cell.spec().human_stance * poses[cell.human().link_index(arm.spec.base_link)];
    reaches.push_back(
        {arm.spec.name, base * arm.chain.first_joint_position(), chain_reach(arm.chain)});
  }
  return reaches;
}

// How far the nearest point of a part (its bounding sphere) lies beyond the nearest reach: > 0
// when no point of the part is within any; `nearest` names that reach.
double beyond_reach(const PlacedBox& box, const std::vector<Reach>& reaches, std::string& nearest) {
  double best = std::numeric_limits<double>::infinity();
  for (const Reach& r : reaches) {
    const double beyond = (box.centre() - r.shoulder).norm() - r.radius - box.radius();
    if (beyond < best) {
      best = beyond;
      nearest = r.name + " (reach " + metres(r.radius) + ", shoulder " +
                metres((box.centre() - r.shoulder).norm()) + " from the part's centre)";
    }
  }
  return best;
}

// The obstacle whose top face is highest under the point (x, y), or none.
const core::BoxObstacle* surface_under(const core::Cell& cell, const Eigen::Vector3d& point,
                                       double& top) {
  const core::BoxObstacle* found = nullptr;
  for (const auto& o : cell.spec().obstacles) {
    const PlacedBox box = obstacle_box(o);
    if (box.over(point) && (found == nullptr || box.max.z() > top)) {
      found = &o;
      top = box.max.z();
    }
  }
  return found;
}
}  // namespace

std::vector<std::string> colliding_parts(const core::Cell& cell, const core::ProductSpec& product,
                                         bool at_targets) {
  core::CollisionModel model;
  std::vector<int> obstacles;
  for (const auto& o : cell.spec().obstacles) {
    core::GeometrySpec box;
    box.box_size = o.size;
    obstacles.push_back(model.add_body(o.name, {box}, true, o.pose));
  }
  for (const auto& part : product.parts) {
    const core::Pose pose = at_targets ? product.target_in_world(part) : part.initial;
    model.add_mesh_body(part.name, part.mesh, false, pose);
  }
  // Before the first board the suction tool stands at suction_tool_pose: the parts lying at
  // their initial poses must clear it. It stands on its cup (its contact with the obstacles is
  // no overlap).
  core::RobotBodies tool;
  const core::RobotModel& tool_model = cell.suction_tool();
  if (!at_targets) {
    tool = core::add_robot(model, tool_model, "tool/");
    for (const int b : tool.link_to_body) {
      if (b < 0) continue;
      for (const int o : obstacles) model.allow(b, o);
    }
  }
  core::CollisionData data(model);
  if (!at_targets) {
    std::vector<core::Pose> poses;
    tool_model.link_poses(tool_model.neutral_configuration(), poses);
    const core::Pose handle = poses[tool_model.link_index(cell.spec().suction.handle_link)];
    core::set_robot_pose(data, tool, poses, product.suction_tool_pose * handle.inverse());
  }
  std::vector<std::string> pairs;
  // Report every colliding pair: allow each pair once found and ask again.
  core::CollisionPair pair;
  while (core::in_collision(model, data, &pair)) {
    pairs.push_back(core::describe_pair(model, pair));
    model.allow(pair.body_a, pair.body_b);
  }
  return pairs;
}

std::vector<PoseFinding> check_part_poses(const core::Cell& cell,
                                          const core::ProductSpec& product) {
  std::vector<PoseFinding> findings;
  std::vector<PlacedBox> initial, target;
  for (const auto& part : product.parts) {
    initial.push_back(placed_box(part.mesh, part.initial));
    target.push_back(placed_box(part.mesh, product.target_in_world(part)));
  }
  const std::vector<Reach> arms = robot_reaches(cell);
  const std::vector<Reach> human = human_reaches(cell);
  for (std::size_t i = 0; i < product.parts.size(); ++i) {
    const std::string& name = product.parts[i].name;
    // Initial pose: resting on a surface (an obstacle's top, or another part lying there).
    double top = 0.0;
    const core::BoxObstacle* surface = surface_under(cell, initial[i].centre(), top);
    const double lowest = initial[i].min.z();
    bool on_part = false;
    for (std::size_t j = 0; j < product.parts.size(); ++j) {
      on_part = on_part || (j != i && std::abs(lowest - initial[j].max.z()) <= kRestTolerance &&
                            initial[i].overlaps_xy(initial[j]));
    }
    if (surface == nullptr) {
      if (!on_part) {
        findings.push_back({name, "initial", true,
                            "not over the table or any obstacle (nothing under its centre to "
                            "rest on)"});
      }
    } else if (lowest < top - kRestTolerance) {
      findings.push_back({name, "initial", true,
                          "its lowest point is " + mm(top - lowest) + " below the top of '" +
                              surface->name + "'"});
    } else if (lowest > top + kRestTolerance && !on_part) {
      findings.push_back({name, "initial", true,
                          "its lowest point floats " + mm(lowest - top) + " above the top of '" +
                              surface->name + "' and rests on no other part"});
    }
    // Initial pose: some arm reaches it, with the gripper or the suction cup.
    std::string nearest;
    const double beyond = beyond_reach(initial[i], arms, nearest);
    if (beyond > 0.0) {
      findings.push_back(
          {name, "initial", true,
           "out of every robot arm's reach by " + mm(beyond) + "; nearest: arm " + nearest});
    }
    // Target: not inside or below the surface the assembly stands on.
    double target_top = 0.0;
    const core::BoxObstacle* target_surface = surface_under(cell, target[i].centre(), target_top);
    if (target_surface != nullptr && target[i].min.z() < target_top - kRestTolerance) {
      findings.push_back({name, "target", true,
                          "its lowest point is " + mm(target_top - target[i].min.z()) +
                              " below the top of '" + target_surface->name + "'"});
    }
    // Target: the human, who assembles the part there, reaches it without stepping. A person
    // may step or lean, so this is a warning.
    const double human_beyond = beyond_reach(target[i], human, nearest);
    if (human_beyond > 0.0) {
      findings.push_back({name, "target", false,
                          "out of the human's reach from the stance by " + mm(human_beyond) +
                              "; nearest: arm " + nearest});
    }
  }
  return findings;
}

namespace {
int run_product_check(const ProductCheckOptions& opt) {
  const auto cell = core::Cell::load(opt.cell_file);
  const core::ProductSpec product = core::load_product(opt.product_file);
  check_part_meshes(product);
  const auto target_pairs = colliding_parts(*cell, product, true);
  const auto initial_pairs = colliding_parts(*cell, product, false);
  const auto pose_findings = check_part_poses(*cell, product);
  bool pose_errors = false;
  for (const auto& f : pose_findings) pose_errors = pose_errors || f.error;
  nlohmann::json report;
  report["product"] = product.name;
  report["parts"] = nlohmann::json::array();
  for (const auto& part : product.parts) {
    const Eigen::Vector3d extent = part.mesh.max_corner() - part.mesh.min_corner();
    const Eigen::Vector3d target = product.target_in_world(part).translation();
    report["parts"].push_back({{"name", part.name},
                               {"order", part.order},
                               {"mass", part.mass},
                               {"size", {extent.x(), extent.y(), extent.z()}},
                               {"triangles", part.mesh.triangles.size()},
                               {"target_xyz", {target.x(), target.y(), target.z()}}});
  }
  // Payload: every arm carrying every part in its jaws and on the suction tool. A part no arm
  // lifts either way is a problem; one over an arm's rated payload (within what the cell
  // allows) is reported.
  bool all_liftable = true;
  report["payload"] = nlohmann::json::array();
  std::vector<std::string> payload_lines;
  for (const auto& part : product.parts) {
    bool liftable = false;
    nlohmann::json carries = nlohmann::json::array();
    std::string over_rated, best_refusal;
    for (const auto& arm : cell->arms()) {
      for (const auto mode : {core::CarryMode::kGripper, core::CarryMode::kSuction}) {
        const core::PayloadCheck c = core::check_payload(arm.spec.name, arm.spec.payload, part.mass,
                                                         mode, cell->spec().suction.mass);
        liftable = liftable || c.within_allowed();
        carries.push_back({{"arm", arm.spec.name},
                           {"mode", core::to_string(mode)},
                           {"stated", c.stated},
                           {"total_kg", c.total()},
                           {"allowed_kg", c.allowed},
                           {"rated_kg", c.rated},
                           {"within_allowed", c.within_allowed()},
                           {"within_rated", c.within_rated()}});
        if (c.within_allowed() && !c.within_rated() && over_rated.empty()) {
          over_rated =
              std::string(core::to_string(mode)) + " at '" + arm.spec.name + "': " + c.describe();
        }
        if (!c.within_allowed() && best_refusal.empty()) best_refusal = c.describe();
      }
    }
    all_liftable = all_liftable && liftable;
    report["payload"].push_back(
        {{"part", part.name}, {"liftable", liftable}, {"carries", carries}});
    if (!liftable) {
      payload_lines.push_back(part.name + ": OVER THE PAYLOAD of every arm (" + best_refusal + ")");
    } else if (!over_rated.empty()) {
      payload_lines.push_back(
          part.name + ": over the rated payload, within what the cell allows (" + over_rated + ")");
    }
  }
  report["all_parts_liftable"] = all_liftable;
  report["targets_collision_free"] = target_pairs.empty();
  report["target_collisions"] = target_pairs;
  report["initial_collision_free"] = initial_pairs.empty();
  report["initial_collisions"] = initial_pairs;
  report["pose_errors"] = nlohmann::json::array();
  report["pose_warnings"] = nlohmann::json::array();
  for (const auto& f : pose_findings) {
    report[f.error ? "pose_errors" : "pose_warnings"].push_back(
        {{"part", f.part}, {"pose", f.pose}, {"problem", f.problem}});
  }
  if (opt.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << "product " << product.name << " (" << opt.product_file << ")\n";
    std::cout << "  #  part            mass kg  size mm               target xyz m\n";
    for (const auto& p : report["parts"]) {
      std::cout << "  " << p["order"].get<int>() << "  " << std::left << std::setw(16)
                << p["name"].get<std::string>() << std::right << std::setw(6) << std::fixed
                << std::setprecision(2) << p["mass"].get<double>() << "   " << std::setprecision(0)
                << std::setw(4) << p["size"][0].get<double>() * 1000 << " x " << std::setw(4)
                << p["size"][1].get<double>() * 1000 << " x " << std::setw(3)
                << p["size"][2].get<double>() * 1000 << "   " << std::setprecision(3)
                << p["target_xyz"][0].get<double>() << " " << p["target_xyz"][1].get<double>()
                << " " << p["target_xyz"][2].get<double>() << "\n";
    }
    std::cout << "  finished assembly: "
              << (target_pairs.empty() ? "no parts interpenetrate" : "INTERPENETRATING") << "\n";
    for (const auto& p : target_pairs) std::cout << "    " << p << "\n";
    std::cout << "  initial poses: "
              << (initial_pairs.empty() ? "no parts interpenetrate" : "INTERPENETRATING") << "\n";
    for (const auto& p : initial_pairs) std::cout << "    " << p << "\n";
    std::cout << "  poses (initial on the table within an arm's reach, targets on the table "
                 "within the human's reach): "
              << (pose_errors             ? "ERRORS"
                  : pose_findings.empty() ? "ok"
                                          : "warnings")
              << "\n";
    for (const auto& f : pose_findings) {
      std::cout << "    " << (f.error ? "error: " : "warning: ") << f.part << ": " << f.pose
                << " pose: " << f.problem << "\n";
    }
    std::cout << "  payload: "
              << (!all_liftable           ? "a part no arm can lift"
                  : payload_lines.empty() ? "every part within every arm's rated payload"
                                          : "every part liftable")
              << "\n";
    for (const auto& l : payload_lines) std::cout << "    " << l << "\n";
  }
  return target_pairs.empty() && initial_pairs.empty() && all_liftable && !pose_errors ? 0 : 1;
}
}  // namespace

void add_product_command(CLI::App& app, Action& action) {
  auto* product = app.add_subcommand("product", "Inspect and check a product description");
  product->require_subcommand(1);
  auto opt = std::make_shared<ProductCheckOptions>();
  opt->product_file = default_product_path();
  opt->cell_file = default_cell_path();
  auto* check = product->add_subcommand(
      "check", "Load the parts; check the finished assembly and the initial poses for overlaps");
  check->add_option("product", opt->product_file, "product YAML file")->capture_default_str();
  check->add_option("--cell", opt->cell_file, "cell YAML file")->capture_default_str();
  check->add_flag("--json", opt->json, "print the report as JSON");
  check->callback([opt, &action] { action = [opt] { return run_product_check(*opt); }; });
}

void check_part_meshes(const core::ProductSpec& product) {
  for (const core::PartSpec& part : product.parts) {
    try {
      offline::analyze_part(part.name, part.mesh, part.mass);
    } catch (const core::InputError& e) {
      if (e.field() != "mesh") throw;
      // analyze_part names the part only: "<part>: mesh: expected ..., got ...".
      std::string what = e.what();
      const std::string prefix = e.file() + ": " + e.field() + ": ";
      if (what.rfind(prefix, 0) == 0) what = what.substr(prefix.size());
      throw core::InputError(part.mesh_file + ": mesh of part '" + part.name + "' (" +
                             product.file + "): " + what);
    }
  }
}

namespace {
// The bundled cell and product: installed, HILA_INSTALLED_DATA_DIR from the folder the hila
// command is in (share/hila/meshes beside bin/); in the build tree, the source's meshes/.
std::string data_dir() {
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) {
    const std::filesystem::path installed =
        (exe.parent_path() / HILA_INSTALLED_DATA_DIR).lexically_normal();
    if (std::filesystem::exists(installed / "cell" / "cell.yaml", error)) return installed.string();
  }
  return HILA_DATA_DIR;
}
}  // namespace

std::string default_cell_path() {
  return data_dir() + "/cell/cell.yaml";
}
std::string default_product_path() {
  return data_dir() + "/cabinet/product.yaml";
}
std::string default_scene_path(const std::string& product) {
  // A name that is no plain folder name has no bundled folder.
  if (product.empty() || product == "." || product == ".." ||
      product.find('/') != std::string::npos) {
    return "";
  }
  return data_dir() + "/" + product + "/scene.yaml";
}

}  // namespace hila::tools
