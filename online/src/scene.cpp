#include "hila/online/scene.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hila/core/error.hpp"
#include "hila/core/yaml_reader.hpp"

namespace hila::online {

namespace {

// A board resting on the table may sink this far into it by detection noise (m).
constexpr double kTableTolerance = 0.002;

std::string format_m(double v) {
  std::ostringstream s;
  s.precision(4);
  s << std::fixed << v;
  return s.str();
}

std::string board_names(const core::ProductSpec& product) {
  std::string out;
  for (const auto& p : product.parts) out += (out.empty() ? "" : ", ") + p.name;
  return out;
}

const core::PartSpec& board_named(const core::YamlNode& where, const core::ProductSpec& product,
                                  const std::string& name) {
  for (const auto& p : product.parts) {
    if (p.name == name) return p;
  }
  where.fail("a board of product '" + product.name + "' (" + board_names(product) + ")",
             "'" + name + "'");
}

// The top of the cell's box obstacles under (x, y), or -inf when none is.
double support_top(const core::Cell& cell, const Eigen::Vector3d& p) {
  double top = -std::numeric_limits<double>::infinity();
  for (const auto& box : cell.spec().obstacles) {
    const Eigen::Vector3d local = box.pose.inverse() * p;
    if (std::abs(local.x()) <= 0.5 * box.size.x() && std::abs(local.y()) <= 0.5 * box.size.y()) {
      // The box's highest corner.
      for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d c(((i & 1) ? 0.5 : -0.5) * box.size.x(),
                                ((i & 2) ? 0.5 : -0.5) * box.size.y(),
                                ((i & 4) ? 0.5 : -0.5) * box.size.z());
        top = std::max(top, (box.pose * c).z());
      }
    }
  }
  return top;
}

double lowest_point(const core::TriangleMesh& mesh, const core::Pose& pose) {
  double low = std::numeric_limits<double>::infinity();
  for (const auto& v : mesh.vertices) low = std::min(low, (pose * v).z());
  return low;
}

void check_on_table(const core::YamlNode& where, const core::Cell& cell, const core::PartSpec& part,
                    const core::Pose& pose) {
  const double top = support_top(cell, pose.translation());
  const double low = lowest_point(part.mesh, pose);
  if (std::isfinite(top) && low < top - kTableTolerance) {
    where.fail("a pose with the board on or above the table top (z " + format_m(top) + " m)",
               "its lowest point at z " + format_m(low) + " m, " + format_m(1000.0 * (top - low)) +
                   " mm inside the table");
  }
}

}  // namespace

bool Scene::is_finished(const std::string& board) const {
  return std::any_of(finished.begin(), finished.end(),
                     [&](const FinishedBoard& f) { return f.name == board; });
}

core::Pose Scene::initial_pose(const core::PartSpec& part) const {
  const auto it = detected.find(part.name);
  return it != detected.end() ? it->second : part.initial;
}

Scene Scene::with_finished(const core::ProductSpec& spec, const std::string& board) const {
  Scene next = *this;
  if (is_finished(board)) return next;
  const core::PartSpec& part = spec.part(board);
  next.finished.push_back({board, assembly_frame * part.target});
  next.detected.erase(board);
  return next;
}

Scene nominal_scene(const core::Cell& cell, const core::ProductSpec& product) {
  Scene s;
  s.product = product.name;
  s.tool = product.suction_tool_pose;
  s.assembly_frame = product.assembly_frame;
  s.human_stance = cell.spec().human_stance;
  for (const auto& arm : cell.arms()) s.robot[arm.spec.name] = arm.spec.home;
  return s;
}

SceneFiles read_scene_files(const std::string& path) {
  const core::YamlNode root = core::YamlNode::load_file(path);
  const core::YamlNode files = root.at("files");
  files.expect_only({"cell", "product"});
  return {files.resolve_path(files.at("cell").as_string()),
          files.resolve_path(files.at("product").as_string())};
}

Scene load_scene(const std::string& path, const core::Cell& cell,
                 const core::ProductSpec& product) {
  const core::YamlNode root = core::YamlNode::load_file(path);
  root.expect_only({"product", "files", "boards", "tool", "tool_in_hand", "assembly_frame",
                    "finished", "human", "worker", "obstacles", "robot"});
  Scene s = nominal_scene(cell, product);
  s.file = path;
  const core::YamlNode name = root.at("product");
  s.product = name.as_string();
  if (s.product != product.name) {
    name.fail("the product '" + product.name + "' (" + product.file + ")", "'" + s.product + "'");
  }
  if (const auto n = root.find("assembly_frame")) s.assembly_frame = n->as_pose();
  if (const auto n = root.find("tool")) s.tool = n->as_pose();
  // true / false, or the name of the arm that holds the tool (true: the right arm's).
  if (const auto n = root.find("tool_in_hand")) {
    const std::string value = n->as_string();
    if (value == "true" || value == "false") {
      s.tool_in_hand = n->as_bool();
    } else if (value.empty() || value.find_first_of(" \t\n") != std::string::npos) {
      n->fail("true, false or the name of the arm holding the tool", "'" + value + "'");
    } else {
      s.tool_in_hand = true;
      s.tool_arm = value;
    }
  }

  if (const auto list = root.find("finished")) {
    if (!list->is_sequence()) list->fail("a list of finished boards", "not a list");
    for (std::size_t i = 0; i < list->size(); ++i) {
      const core::YamlNode item = list->at(i);
      FinishedBoard f;
      std::optional<core::Pose> pose;
      if (item.is_map()) {
        item.expect_only({"name", "pose"});
        f.name = item.at("name").as_string();
        if (const auto p = item.find("pose")) pose = p->as_pose();
      } else {
        f.name = item.as_string();
      }
      const core::PartSpec& part = board_named(item, product, f.name);
      if (s.is_finished(f.name)) item.fail("each board finished once", "'" + f.name + "' again");
      f.pose = pose ? *pose : s.assembly_frame * part.target;
      s.finished.push_back(f);
    }
  }

  if (const auto boards = root.find("boards")) {
    if (!boards->is_map()) boards->fail("a map of board name to detected pose", "not a map");
    for (const auto& key : boards->keys()) {
      const core::YamlNode item = boards->at(key);
      const core::PartSpec& part = board_named(item, product, key);
      if (s.is_finished(key)) {
        item.fail("a board still to be handled", "'" + key + "', listed as finished");
      }
      const core::Pose pose = item.as_pose();
      check_on_table(item, cell, part, pose);
      s.detected[key] = pose;
    }
  }

  if (const auto human = root.find("human")) {
    human->expect_only({"stance"});
    const core::YamlNode stance = human->at("stance");
    s.human_stance = stance.as_pose();
    const double top = support_top(cell, s.human_stance.translation());
    if (std::isfinite(top)) {
      stance.fail("a stance where the human stands clear of the table",
                  "(" + format_m(s.human_stance.translation().x()) + ", " +
                      format_m(s.human_stance.translation().y()) +
                      ") m, under a cell obstacle's footprint");
    }
  }

  // The worker who is there: stature and sex, as `hila human` takes them.
  if (const auto worker = root.find("worker")) {
    if (!worker->is_map()) worker->fail("{stature: METRES, sex: male|female}", "not a map");
    worker->expect_only({"stature", "sex"});
    core::HumanBodySpec body;
    const core::YamlNode stature = worker->at("stature");
    body.stature = stature.as_double();
    if (!std::isfinite(body.stature) || body.stature < core::kMinStature ||
        body.stature > core::kMaxStature) {
      stature.fail("an adult stature in metres within [" + core::format_number(core::kMinStature) +
                       ", " + core::format_number(core::kMaxStature) + "]",
                   core::format_number(body.stature) +
                       (body.stature > 100.0 ? " (millimetres given as metres?)" : ""));
    }
    const core::YamlNode sex = worker->at("sex");
    const std::string sex_name = sex.as_string();
    if (sex_name != "male" && sex_name != "female")
      sex.fail("male or female", "'" + sex_name + "'");
    body.sex = sex_name == "male" ? core::Sex::Male : core::Sex::Female;
    // The body's arms must be scaled copies of the cell's human arms (core::HumanBody).
    s.worker = std::make_shared<const core::HumanBody>(cell, body, path, "worker");
  }

  if (const auto list = root.find("obstacles")) {
    if (!list->is_sequence()) list->fail("a list of obstacles", "not a list");
    for (std::size_t i = 0; i < list->size(); ++i) {
      const core::YamlNode item = list->at(i);
      item.expect_only({"name", "box", "mesh", "scale", "pose"});
      SceneObstacle o;
      o.name = item.at("name").as_string();
      for (const auto& other : s.obstacles) {
        if (other.name == o.name) item.at("name").fail("a unique obstacle name", o.name);
      }
      o.pose = item.at("pose").as_pose();
      const bool box = item.has("box");
      if (box == item.has("mesh")) item.fail("exactly one of box: [x, y, z] or mesh: FILE", "");
      if (box) {
        const core::YamlNode size = item.at("box");
        const auto v = size.as_doubles(3);
        for (const double d : v) {
          if (!(d > 0.0) || d > 5.0)
            size.fail("box sizes in metres, each in (0, 5]", "a size of " + format_m(d));
        }
        o.box_size = Eigen::Vector3d(v[0], v[1], v[2]);
      } else {
        const core::YamlNode mesh = item.at("mesh");
        o.mesh_file = item.resolve_path(mesh.as_string());
        const double scale = item.has("scale") ? item.at("scale").as_positive() : 1.0;
        try {
          o.mesh = core::load_mesh(o.mesh_file, scale);
        } catch (const core::InputError& e) {
          mesh.fail("a readable mesh file", e.what());  // names the scene file and the field
        }
      }
      s.obstacles.push_back(std::move(o));
    }
  }

  if (const auto robot = root.find("robot")) {
    if (!robot->is_map()) robot->fail("a map of arm name to joints", "not a map");
    for (const auto& key : robot->keys()) {
      const core::YamlNode item = robot->at(key);
      const core::Arm* arm = nullptr;
      std::string names;
      for (const auto& a : cell.arms()) {
        names += (names.empty() ? "" : ", ") + a.spec.name;
        if (a.spec.name == key) arm = &a;
      }
      if (arm == nullptr) item.fail("an arm of the cell (" + names + ")", "'" + key + "'");
      const auto v = item.as_doubles(static_cast<std::size_t>(arm->chain.dof()));
      const Eigen::VectorXd q =
          Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
      if (!arm->chain.within_limits(q, 1e-9)) {
        std::ostringstream got;
        got << q.transpose();
        item.fail("joints (rad) within the arm's limits", got.str());
      }
      s.robot[key] = q;
    }
  }
  return s;
}

}  // namespace hila::online
