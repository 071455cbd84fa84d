#include "hila/offline/human_comfort.hpp"

#include <cmath>
#include <sstream>

#include "hila/core/comfort.hpp"
#include "hila/core/error.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::offline {

namespace {

// Torso pose in the world at the neutral posture.
core::Pose base_in_world(const core::Cell& cell, const core::RobotModel& human,
                         const std::string& base_link) {
  std::vector<core::Pose> poses;
  human.link_poses(cell.human_neutral(), poses);
  return cell.spec().human_stance * poses[static_cast<std::size_t>(human.link_index(base_link))];
}

}  // namespace

HumanComfort::HumanComfort(const core::Cell& cell, std::vector<core::ComfortMap> maps,
                           const std::vector<core::HumanBodySpec>& bodies)
    : maps_(std::move(maps)) {
  const auto& arms = cell.human_arms();
  if (maps_.size() != arms.size()) {
    throw std::invalid_argument("HumanComfort: one comfort map per human arm expected");
  }
  for (const auto& arm : arms) {
    arm_names_.push_back(arm.spec.name);
    arm_base_.push_back(base_in_world(cell, cell.human(), arm.spec.base_link));
    world_to_base_.push_back(arm_base_.back().inverse());
  }
  for (const auto& spec : bodies) {
    Body body{std::make_shared<const core::HumanBody>(cell, spec), {}};
    for (std::size_t a = 0; a < arms.size(); ++a) {
      body.world_to_base.push_back(
          (cell.spec().human_stance * body.body->base_in_stance(static_cast<int>(a))).inverse());
    }
    bodies_.push_back(std::move(body));
  }
}

double HumanComfort::quality(int arm, const core::Pose& hand) const {
  const auto a = static_cast<std::size_t>(arm);
  return maps_[a].lookup(world_to_base_[a] * hand);
}

double HumanComfort::body_quality(int body, int arm, const core::Pose& hand) const {
  const auto a = static_cast<std::size_t>(arm);
  const Body& b = bodies_[static_cast<std::size_t>(body)];
  return maps_[a].lookup(b.body->to_cell_arm(arm, b.world_to_base[a] * hand));
}

namespace {

// One body: STATURE (m) and SEX ("male" or "female"), from `item` as given (for messages).
core::HumanBodySpec parse_body(const std::string& stature, const std::string& sex,
                               const std::string& item, const std::string& file,
                               const std::string& field, const std::string& form) {
  core::HumanBodySpec body;
  std::size_t used = 0;
  try {
    body.stature = std::stod(stature, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != stature.size()) {
    throw core::InputError(file, field, form, "'" + item + "'");
  }
  if (!std::isfinite(body.stature) || body.stature < core::kMinStature ||
      body.stature > core::kMaxStature) {
    throw core::InputError(file, field,
                           "a stature in metres within [" + core::format_number(core::kMinStature) +
                               ", " + core::format_number(core::kMaxStature) + "] in '" + item +
                               "'",
                           core::format_number(body.stature) +
                               (body.stature > 100.0 ? " (millimetres given as metres?)" : ""));
  }
  if (sex != "male" && sex != "female") {
    throw core::InputError(file, field, "sex 'male' or 'female' in '" + item + "'",
                           "'" + sex + "'");
  }
  body.sex = sex == "male" ? core::Sex::Male : core::Sex::Female;
  return body;
}

// Each goal records the bodies that take it as bits of a 32-bit mask.
void check_body_count(const std::vector<core::HumanBodySpec>& bodies, const std::string& file,
                      const std::string& field) {
  if (bodies.empty()) {
    throw core::InputError(file, field, "at least one STATURE[:SEX] item", "nothing");
  }
  if (bodies.size() > kMaxHumanBodies) {
    throw core::InputError(file, field, "at most " + std::to_string(kMaxHumanBodies) + " bodies",
                           std::to_string(bodies.size()));
  }
}

}  // namespace

std::vector<core::HumanBodySpec> parse_human_bodies(const std::string& text,
                                                    const std::string& field) {
  std::vector<core::HumanBodySpec> bodies;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    const auto colon = item.find(':');
    bodies.push_back(parse_body(item.substr(0, colon),
                                colon == std::string::npos ? "male" : item.substr(colon + 1), item,
                                "command line", field, "STATURE[:SEX] items such as 1.50:female"));
  }
  check_body_count(bodies, "command line", field);
  return bodies;
}

std::vector<core::HumanBodySpec> parse_stored_human_bodies(const std::string& stored,
                                                           const std::string& file) {
  static const std::string kSeparator = "; ";
  std::vector<core::HumanBodySpec> bodies;
  std::size_t begin = 0;
  while (begin < stored.size()) {
    std::size_t end = stored.find(kSeparator, begin);
    if (end == std::string::npos) end = stored.size();
    const std::string item = stored.substr(begin, end - begin);
    const auto space = item.find(' ');
    bodies.push_back(parse_body(
        item.substr(0, space), space == std::string::npos ? "" : item.substr(space + 1), item, file,
        "meta.human_bodies", "'STATURE SEX' items joined by '; ' such as '1.5 female'"));
    begin = end + kSeparator.size();
  }
  check_body_count(bodies, file, "meta.human_bodies");
  return bodies;
}

std::string format_human_bodies(const std::vector<core::HumanBodySpec>& bodies) {
  std::string out;
  for (const auto& b : bodies) out += (out.empty() ? "" : "; ") + core::human_body_label(b);
  return out;
}

}  // namespace hila::offline
