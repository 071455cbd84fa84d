#include <filesystem>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <system_error>

#include "commands.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/core/payload.hpp"
#include "hila/core/product.hpp"
#include "hila/offline/part_analysis.hpp"

namespace hila::tools {

namespace {
struct ProductCheckOptions {
  std::string product_file;
  std::string cell_file;
  bool json = false;
};

// Puts every part at the given poses as moving bodies beside the cell's obstacles and returns
// the pairs that interpenetrate.
std::vector<std::string> colliding_parts(const core::Cell& cell, const core::ProductSpec& product,
                                         bool at_targets) {
  core::CollisionModel model;
  for (const auto& o : cell.spec().obstacles) {
    core::GeometrySpec box;
    box.box_size = o.size;
    model.add_body(o.name, {box}, true, o.pose);
  }
  for (const auto& part : product.parts) {
    const core::Pose pose = at_targets ? product.target_in_world(part) : part.initial;
    model.add_mesh_body(part.name, part.mesh, false, pose);
  }
  core::CollisionData data(model);
  std::vector<std::string> pairs;
  // Report every colliding pair: allow each pair once found and ask again.
  core::CollisionPair pair;
  while (core::in_collision(model, data, &pair)) {
    pairs.push_back(core::describe_pair(model, pair));
    model.allow(pair.body_a, pair.body_b);
  }
  return pairs;
}

int run_product_check(const ProductCheckOptions& opt) {
  const auto cell = core::Cell::load(opt.cell_file);
  const core::ProductSpec product = core::load_product(opt.product_file);
  check_part_meshes(product);
  const auto target_pairs = colliding_parts(*cell, product, true);
  const auto initial_pairs = colliding_parts(*cell, product, false);
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
    std::cout << "  payload: "
              << (!all_liftable           ? "a part no arm can lift"
                  : payload_lines.empty() ? "every part within every arm's rated payload"
                                          : "every part liftable")
              << "\n";
    for (const auto& l : payload_lines) std::cout << "    " << l << "\n";
  }
  return target_pairs.empty() && initial_pairs.empty() && all_liftable ? 0 : 1;
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
      throw core::InputError(part.mesh_file + ": mesh of part '" + part.name +
                             "' (" + product.file + "): " + what);
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

}  // namespace hila::tools
