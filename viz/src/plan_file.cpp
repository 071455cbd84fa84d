#include "hila/viz/plan_file.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "hila/core/error.hpp"

namespace hila::viz {

namespace {

using nlohmann::json;

// Step boundaries are written from the same doubles: a later step starts exactly where the
// previous one ended. The tolerance only absorbs the JSON's decimal round trip.
constexpr double kTimeTolerance = 1e-9;

const json& at(const json& object, const std::string& key, const std::string& file,
               const std::string& field) {
  if (!object.is_object() || !object.contains(key)) {
    throw core::InputError(file, field + key, "a key '" + key + "'", "none");
  }
  return object.at(key);
}

double number(const json& value, const std::string& file, const std::string& field) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    throw core::InputError(file, field, "a finite number", value.dump());
  }
  return value.get<double>();
}

std::string text(const json& value, const std::string& file, const std::string& field) {
  if (!value.is_string()) throw core::InputError(file, field, "a string", value.dump());
  return value.get<std::string>();
}

core::Pose pose(const json& value, const std::string& file, const std::string& field) {
  const json& xyz = at(value, "xyz", file, field + ".");
  const json& quat = at(value, "quat_wxyz", file, field + ".");
  if (!xyz.is_array() || xyz.size() != 3 || !quat.is_array() || quat.size() != 4) {
    throw core::InputError(file, field, "{xyz: [x, y, z], quat_wxyz: [w, x, y, z]}", value.dump());
  }
  double q[4];
  for (int i = 0; i < 4; ++i) q[i] = number(quat[i], file, field + ".quat_wxyz");
  core::Pose p = core::Pose::Identity();
  for (int i = 0; i < 3; ++i) p.translation()[i] = number(xyz[i], file, field + ".xyz");
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (std::abs(rotation.norm() - 1.0) > 1e-6) {
    throw core::InputError(file, field + ".quat_wxyz", "a unit quaternion", value.dump());
  }
  p.linear() = rotation.normalized().toRotationMatrix();
  return p;
}

PlanFileStep step(const json& value, const std::string& file, const std::string& field) {
  PlanFileStep s;
  s.name = text(at(value, "name", file, field), file, field + "name");
  s.arm = text(at(value, "arm", file, field), file, field + "arm");
  std::stringstream events(text(at(value, "events", file, field), file, field + "events"));
  for (std::string e; std::getline(events, e, ',');) {
    if (!e.empty()) s.events.push_back(e);
  }
  const json& times = at(value, "time_s", file, field);
  const json& joints = at(value, "joints_rad", file, field);
  if (!times.is_array() || !joints.is_array() || times.size() != joints.size() || times.empty()) {
    throw core::InputError(file, field + "time_s/joints_rad", "arrays of the same, non-zero length",
                           std::to_string(times.size()) + " and " + std::to_string(joints.size()));
  }
  for (std::size_t i = 0; i < times.size(); ++i) {
    const std::string where = std::string("[") + std::to_string(i) + "]";
    s.time.push_back(number(times[i], file, field + "time_s" + where));
    if (i > 0 && s.time[i] < s.time[i - 1]) {
      throw core::InputError(
          file, field + "time_s" + where, "times that do not decrease",
          core::format_number(s.time[i]) + " after " + core::format_number(s.time[i - 1]));
    }
    const json& q = joints[i];
    if (!q.is_array() || q.empty() || (i > 0 && q.size() != joints[0].size())) {
      throw core::InputError(file, field + "joints_rad" + where,
                             "one joint vector of the step's size", q.dump());
    }
    Eigen::VectorXd v(static_cast<Eigen::Index>(q.size()));
    for (std::size_t k = 0; k < q.size(); ++k) {
      v[static_cast<Eigen::Index>(k)] = number(q[k], file, field + "joints_rad" + where);
    }
    s.joints.push_back(std::move(v));
  }
  return s;
}

PlanFileBoard board(const json& value, const std::string& file, const std::string& field) {
  PlanFileBoard b;
  b.board = text(at(value, "board", file, field), file, field + "board");
  b.status = text(at(value, "status", file, field), file, field + "status");
  if (!b.solved()) return b;
  b.duration = number(at(value, "duration_s", file, field), file, field + "duration_s");
  if (value.contains("robot_handover")) {
    b.robot_handover = pose(value.at("robot_handover"), file, field + "robot_handover");
  }
  if (value.contains("human_handover")) {
    b.human_handover = pose(value.at("human_handover"), file, field + "human_handover");
  }
  const json& steps = at(value, "steps", file, field);
  if (!steps.is_array()) throw core::InputError(file, field + "steps", "an array", steps.dump());
  double end = 0.0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const std::string where = field + "steps[" + std::to_string(i) + "].";
    b.steps.push_back(step(steps[i], file, where));
    const PlanFileStep& s = b.steps.back();
    if (s.time.front() < end - kTimeTolerance || s.time.back() > b.duration + kTimeTolerance) {
      throw core::InputError(
          file, where + "time_s",
          "times within [" + core::format_number(end) + ", " + core::format_number(b.duration) +
              "] (after the previous step, "
              "by the board's duration_s)",
          core::format_number(s.time.front()) + " to " + core::format_number(s.time.back()));
    }
    end = s.time.back();
  }
  return b;
}

}  // namespace

double PlanFile::duration() const {
  double total = 0.0;
  for (const PlanFileBoard& b : boards) total += b.duration;
  return total;
}

PlanFile parse_plan_file(const std::string& content, const std::string& file) {
  json root;
  try {
    root = json::parse(content);
  } catch (const json::parse_error& e) {
    throw core::InputError(file, "(file)", "a plan file (JSON, hila plan -o)", e.what());
  }
  const json& version = at(root, "hila_plan", file, "");
  if (version != 1) {
    throw core::InputError(file, "hila_plan", "1 (a plan file of this hila)", version.dump());
  }
  PlanFile plan;
  plan.file = file;
  plan.database = text(at(root, "database", file, ""), file, "database");
  plan.scene = text(at(root, "scene", file, ""), file, "scene");
  plan.product = text(at(root, "product", file, ""), file, "product");
  const json& boards = at(root, "boards", file, "");
  if (!boards.is_array()) throw core::InputError(file, "boards", "an array", boards.dump());
  for (std::size_t i = 0; i < boards.size(); ++i) {
    plan.boards.push_back(board(boards[i], file, "boards[" + std::to_string(i) + "]."));
  }
  return plan;
}

PlanFile read_plan_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError(path, "(file)", "a readable plan file", "cannot open it");
  std::ostringstream content;
  content << in.rdbuf();
  return parse_plan_file(content.str(), path);
}

}  // namespace hila::viz
