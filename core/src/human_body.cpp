#include "hila/core/human_body.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hila/core/comfort.hpp"
#include "hila/core/error.hpp"

namespace hila::core {

std::string human_body_label(const HumanBodySpec& spec) {
  return format_number(spec.stature) + (spec.sex == Sex::Male ? " male" : " female");
}

HumanBody::HumanBody(const Cell& cell, const HumanBodySpec& spec, const std::string& where,
                     const std::string& field)
    : spec_(spec),
      model_(RobotModel::load_urdf_string(generate_human_urdf(spec),
                                          "human body " + human_body_label(spec))) {
  const std::string label = human_body_label(spec);
  const std::string what = field.empty() ? "body " + label : field;
  const Eigen::VectorXd& cell_neutral = cell.spec().human_neutral;
  neutral_ = cell_neutral.size() == model_.num_variables() ? cell_neutral
                                                           : human_neutral_configuration(model_);
  std::vector<Pose> links, cell_links;
  model_.link_poses(neutral_, links);
  cell.human().link_poses(cell.human_neutral(), cell_links);
  same_as_cell_ = true;
  for (const auto& cell_arm : cell.human_arms()) {
    const auto base = model_.find_link(cell_arm.spec.base_link);
    const auto tip = model_.find_link(cell_arm.spec.tip_link);
    if (!base || !tip) {
      throw InputError(where, what,
                       "a body with the cell's human arm '" + cell_arm.spec.name + "' (links " +
                           cell_arm.spec.base_link + ", " + cell_arm.spec.tip_link + ")",
                       "a model without them");
    }
    const KinematicChain chain(model_, cell_arm.spec.base_link, cell_arm.spec.tip_link);
    const double scale = characteristic_length(cell_arm.chain) / characteristic_length(chain);
    // The lookup is exact only for a scaled copy of the cell's arm: check it.
    bool copy = chain.dof() == cell_arm.chain.dof() &&
                chain.lower_limits().isApprox(cell_arm.chain.lower_limits(), 1e-12) &&
                chain.upper_limits().isApprox(cell_arm.chain.upper_limits(), 1e-12);
    for (int k = 1; copy && k <= 3; ++k) {
      const Eigen::VectorXd q =
          cell_arm.chain.lower_limits() +
          (0.25 * k) * (cell_arm.chain.upper_limits() - cell_arm.chain.lower_limits());
      const Pose a = cell_arm.chain.fk(q);
      const Pose b = chain.fk(q);
      const Eigen::Vector3d da = a.translation() - cell_arm.chain.first_joint_position();
      const Eigen::Vector3d db = scale * (b.translation() - chain.first_joint_position());
      copy = a.linear().isApprox(b.linear(), 1e-9) && (da - db).norm() < 1e-9;
    }
    if (!copy) {
      throw InputError(where, what,
                       "arms that are scaled copies of the cell's human arm '" +
                           cell_arm.spec.name +
                           "' (bodies of `hila human`, the cell's human generated the same way)",
                       "a different arm structure or joint limits");
    }
    const Pose base_pose = links[static_cast<std::size_t>(*base)];
    const Pose cell_base =
        cell_links[static_cast<std::size_t>(cell.human().link_index(cell_arm.spec.base_link))];
    same_as_cell_ =
        same_as_cell_ && std::abs(scale - 1.0) <= 1e-12 &&
        (chain.first_joint_position() - cell_arm.chain.first_joint_position()).norm() <= 1e-12 &&
        base_pose.isApprox(cell_base, 1e-12);
    arms_.push_back(HumanArm{cell_arm.spec, chain});
    base_in_stance_.push_back(base_pose);
    shoulder_.push_back(chain.first_joint_position());
    cell_shoulder_.push_back(cell_arm.chain.first_joint_position());
    scale_.push_back(scale);
  }
}

std::string HumanBody::label() const {
  return human_body_label(spec_);
}

int HumanBody::arm_index(const std::string& name) const {
  for (std::size_t i = 0; i < arms_.size(); ++i) {
    if (arms_[i].spec.name == name) return static_cast<int>(i);
  }
  return -1;
}

Pose HumanBody::to_cell_arm(int arm, const Pose& hand_in_base) const {
  const std::size_t a = index(arm);
  Pose local = hand_in_base;
  local.translation() = cell_shoulder_[a] + scale_[a] * (hand_in_base.translation() - shoulder_[a]);
  return local;
}

Eigen::VectorXd HumanBody::posture(
    const std::vector<std::pair<std::string, Eigen::VectorXd>>& arm_joints) const {
  Eigen::VectorXd q = neutral_;
  for (const auto& entry : arm_joints) {
    const int a = arm_index(entry.first);
    if (a < 0) {
      std::string names;
      for (const HumanArm& h : arms_) names += (names.empty() ? "" : ", ") + h.spec.name;
      throw InputError("human body " + label(), "human arms", "one of: " + names,
                       "'" + entry.first + "'");
    }
    const auto& vars = arms_[index(a)].chain.model_variables();
    const Eigen::VectorXd& joints = entry.second;
    if (joints.size() != static_cast<Eigen::Index>(vars.size()) || !joints.allFinite()) {
      throw InputError("human body " + label(), "human arm '" + entry.first + "' joints",
                       std::to_string(vars.size()) + " finite values",
                       std::to_string(joints.size()) + (joints.allFinite() ? "" : " (not finite)"));
    }
    for (std::size_t i = 0; i < vars.size(); ++i) q[vars[i]] = joints[static_cast<Eigen::Index>(i)];
  }
  return q;
}

HeightBand natural_height_band(const Cell& cell, const HumanBody* body, const Pose& stance) {
  const RobotModel& human = body != nullptr ? body->model() : cell.human();
  std::vector<Pose> links;
  human.link_poses(body != nullptr ? body->neutral() : cell.human_neutral(), links);
  const std::vector<HumanArm>& arms = body != nullptr ? body->arms() : cell.human_arms();
  HeightBand band;
  band.hip_z = std::numeric_limits<double>::infinity();
  band.shoulder_z = -band.hip_z;
  for (const HumanArm& arm : arms) {
    const Pose base =
        stance * links[static_cast<std::size_t>(human.link_index(arm.spec.base_link))];
    band.hip_z = std::min(band.hip_z, base.translation().z());
    band.shoulder_z = std::max(band.shoulder_z, (base * arm.chain.first_joint_position()).z());
  }
  return band;
}

}  // namespace hila::core
