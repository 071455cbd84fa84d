#include "hila/offline/human_comfort.hpp"

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

std::vector<core::HumanBodySpec> parse_human_bodies(const std::string& text,
                                                    const std::string& field) {
  std::vector<core::HumanBodySpec> bodies;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    const auto colon = item.find(':');
    const std::string stature = item.substr(0, colon);
    const std::string sex = colon == std::string::npos ? "male" : item.substr(colon + 1);
    core::HumanBodySpec body;
    std::size_t used = 0;
    try {
      body.stature = std::stod(stature, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != stature.size()) {
      throw core::InputError("command line", field, "STATURE[:SEX] items such as 1.50:female",
                             "'" + item + "'");
    }
    if (sex != "male" && sex != "female") {
      throw core::InputError("command line", field, "sex 'male' or 'female'", "'" + sex + "'");
    }
    body.sex = sex == "male" ? core::Sex::Male : core::Sex::Female;
    core::human_dimensions(body);  // validates the stature
    bodies.push_back(body);
  }
  if (bodies.empty()) {
    throw core::InputError("command line", field, "at least one STATURE[:SEX] item", "nothing");
  }
  // Each goal records the bodies that take it as bits of a 32-bit mask.
  if (bodies.size() > kMaxHumanBodies) {
    throw core::InputError("command line", field,
                           "at most " + std::to_string(kMaxHumanBodies) + " bodies",
                           std::to_string(bodies.size()));
  }
  return bodies;
}

std::string format_human_bodies(const std::vector<core::HumanBodySpec>& bodies) {
  std::string out;
  for (const auto& b : bodies) out += (out.empty() ? "" : "; ") + core::human_body_label(b);
  return out;
}

}  // namespace hila::offline
