#include "hila/offline/human_comfort.hpp"

#include <sstream>

#include "hila/core/error.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/robot_model.hpp"
#include "hila/core/comfort.hpp"

namespace hila::offline {

namespace {

std::string body_label(const core::HumanBodySpec& b) {
  return core::format_number(b.stature) + (b.sex == core::Sex::Male ? " male" : " female");
}

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
    shoulder_.push_back(arm.chain.first_joint_position());
  }
  for (const auto& spec : bodies) {
    const std::string label = body_label(spec);
    const core::RobotModel model =
        core::RobotModel::load_urdf_string(core::generate_human_urdf(spec), "human body " + label);
    Body body;
    body.spec = spec;
    for (const auto& arm : arms) {
      const core::KinematicChain chain(model, arm.spec.base_link, arm.spec.tip_link);
      body.world_to_base.push_back(base_in_world(cell, model, arm.spec.base_link).inverse());
      body.shoulder.push_back(chain.first_joint_position());
      body.scale = core::characteristic_length(arm.chain) / core::characteristic_length(chain);
      // The lookup is exact only for a scaled copy of the cell's arm: check it.
      bool copy = chain.dof() == arm.chain.dof() &&
                  chain.lower_limits().isApprox(arm.chain.lower_limits(), 1e-12) &&
                  chain.upper_limits().isApprox(arm.chain.upper_limits(), 1e-12);
      for (int k = 1; copy && k <= 3; ++k) {
        const Eigen::VectorXd q =
            arm.chain.lower_limits() +
            (0.25 * k) * (arm.chain.upper_limits() - arm.chain.lower_limits());
        const core::Pose a = arm.chain.fk(q);
        const core::Pose b = chain.fk(q);
        const Eigen::Vector3d da = a.translation() - arm.chain.first_joint_position();
        const Eigen::Vector3d db = body.scale * (b.translation() - chain.first_joint_position());
        copy = a.linear().isApprox(b.linear(), 1e-9) && (da - db).norm() < 1e-9;
      }
      if (!copy) {
        throw core::InputError(
            "human bodies", "body " + label,
            "arms that are scaled copies of the cell's human arm '" + arm.spec.name +
                "' (bodies of `hila human`, the cell's human generated the same way)",
            "a different arm structure or joint limits");
      }
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
  core::Pose local = b.world_to_base[a] * hand;
  local.translation() = shoulder_[a] + b.scale * (local.translation() - b.shoulder[a]);
  return maps_[a].lookup(local);
}

double HumanComfort::worst_quality(int arm, const core::Pose& hand) const {
  if (bodies_.empty()) return quality(arm, hand);
  double worst = 1.0;
  for (int b = 0; b < body_count(); ++b) worst = std::min(worst, body_quality(b, arm, hand));
  return worst;
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
  return bodies;
}

std::string format_human_bodies(const std::vector<core::HumanBodySpec>& bodies) {
  std::string out;
  for (const auto& b : bodies) out += (out.empty() ? "" : "; ") + body_label(b);
  return out;
}

}  // namespace hila::offline
