#include "hila/online/receiving_scores.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "hila/core/error.hpp"
#include "hila/core/pose.hpp"

namespace hila::online {

namespace {

// The whole configuration and the model it belongs to: the body's where there is one.
Eigen::VectorXd posture_of(const core::Cell& cell, const core::HumanBody* body,
                           const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms) {
  return body != nullptr ? body->posture(arms) : core::human_posture(cell, arms);
}

std::vector<std::string> arm_names(
    const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms) {
  std::vector<std::string> names;
  for (const auto& entry : arms) names.push_back(entry.first);
  return names;
}

// Refuses a configuration of another model (another length) or with a NaN or an infinity.
void check_configuration(const core::RobotModel& human, const Eigen::VectorXd& q) {
  if (q.size() != human.num_variables() || !q.allFinite()) {
    throw core::InputError("receiving posture", "human configuration",
                           std::to_string(human.num_variables()) + " finite values",
                           std::to_string(q.size()) + (q.allFinite() ? "" : " (not finite)"));
  }
}

}  // namespace

ReceivingScores receiving_scores(const core::Cell& cell, const core::HumanBody* body,
                                 const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
                                 double load_kg) {
  if (arms.empty()) return {};
  // Both hands hold the board at once: one configuration.
  return receiving_scores(cell, body, posture_of(cell, body, arms), arm_names(arms), load_kg,
                          arms.size() > 1);
}

ReceivingScores receiving_scores(const core::Cell& cell, const core::HumanBody* body,
                                 const Eigen::VectorXd& q, const std::vector<std::string>& arms,
                                 double load_kg, bool two_hands) {
  ReceivingScores r;
  if (arms.empty()) return r;
  const core::RobotModel& human = body != nullptr ? body->model() : cell.human();
  check_configuration(human, q);
  r.two_hands = two_hands || arms.size() > 1;
  r.load_kg = load_kg;
  for (const auto& arm : arms) {
    HandScores h;
    h.arm = arm;
    h.rula_inputs = core::rula_inputs_from_posture(human, q, arm, load_kg, r.two_hands);
    h.rula = core::rula(h.rula_inputs);
    h.reba_inputs = core::reba_inputs_from_posture(human, q, arm, load_kg);
    h.reba = core::reba(h.reba_inputs);
    r.hands.push_back(std::move(h));
  }
  r.worst_rula = 0;
  r.worst_reba = 0;
  for (int i = 1; i < static_cast<int>(r.hands.size()); ++i) {
    const auto& h = r.hands[static_cast<std::size_t>(i)];
    if (h.rula.grand > r.rula().grand) r.worst_rula = i;
    if (h.reba.reba > r.reba().reba) r.worst_reba = i;
  }
  r.scored = true;
  return r;
}

ReceivingScores receiving_scores(const core::Cell& cell, const BoardPlan& plan, double load_kg) {
  if (plan.human_arm.empty() || plan.human_joints.size() == 0) return {};
  std::vector<std::pair<std::string, Eigen::VectorXd>> arms{{plan.human_arm, plan.human_joints}};
  if (!plan.second_human_arm.empty()) {
    if (plan.second_human_joints.size() == 0) return {};
    arms.emplace_back(plan.second_human_arm, plan.second_human_joints);
  }
  return receiving_scores(cell, plan.worker.get(), arms, load_kg);
}

PostureCheck check_receiving_posture(
    const core::Cell& cell, const core::HumanBody* body, const core::Pose& stance,
    const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
    const Eigen::Vector3d& part_centre, double load_kg) {
  if (arms.empty()) {
    PostureCheck c;
    c.part_centre_z = part_centre.z();
    return c;
  }
  return check_receiving_posture(cell, body, stance, posture_of(cell, body, arms), arm_names(arms),
                                 part_centre, load_kg, arms.size() > 1);
}

PostureCheck check_receiving_posture(const core::Cell& cell, const core::HumanBody* body,
                                     const core::Pose& stance, const Eigen::VectorXd& q,
                                     const std::vector<std::string>& arms,
                                     const Eigen::Vector3d& part_centre, double load_kg,
                                     bool two_hands) {
  PostureCheck c;
  c.part_centre_z = part_centre.z();
  if (arms.empty()) return c;
  const core::RobotModel& human = body != nullptr ? body->model() : cell.human();
  const std::vector<core::HumanArm>& human_arms =
      body != nullptr ? body->arms() : cell.human_arms();
  check_configuration(human, q);
  std::vector<core::Pose> links;
  human.link_poses(q, links);
  c.shoulder_z = std::numeric_limits<double>::infinity();
  c.elbow_below_shoulder = true;
  for (const auto& name : arms) {
    const auto arm = std::find_if(human_arms.begin(), human_arms.end(),
                                  [&](const auto& h) { return h.spec.name == name; });
    if (arm == human_arms.end()) {
      std::string names;
      for (const auto& h : human_arms) names += (names.empty() ? "" : ", ") + h.spec.name;
      throw core::InputError("receiving posture", "human arms", "one of: " + names,
                             "'" + name + "'");
    }
    const core::Pose base =
        stance * links[static_cast<std::size_t>(human.link_index(arm->spec.base_link))];
    // The torso's joint is the hip: the arm base link's own joint, at the link's origin.
    const int torso_joint =
        human.links()[static_cast<std::size_t>(human.link_index(arm->spec.base_link))].parent_joint;
    if (torso_joint >= 0) {
      const int v = human.joints()[static_cast<std::size_t>(torso_joint)].variable;
      if (v >= 0) c.trunk_flexion_deg = core::rad_to_deg(q[v]);
    }
    c.hip_z = base.translation().z();
    const double shoulder = (base * arm->chain.first_joint_position()).z();
    c.shoulder_z = std::min(c.shoulder_z, shoulder);
    // The elbow: the chain's joint named so (else its fourth), at its child link's origin.
    const auto& names = arm->chain.joint_names();
    std::string elbow_name = names.size() > 3 ? names[3] : names.back();
    for (const auto& n : names) {
      if (n.find("elbow") != std::string::npos) elbow_name = n;
    }
    const auto& joint = human.joints()[static_cast<std::size_t>(human.joint_index(elbow_name))];
    const double elbow =
        (stance * links[static_cast<std::size_t>(joint.child_link)]).translation().z();
    c.elbow_below_shoulder = c.elbow_below_shoulder && elbow < shoulder;
  }
  const ReceivingScores scores = receiving_scores(cell, body, q, arms, load_kg, two_hands);
  c.rula_grand = scores.scored ? scores.rula().grand : 0;
  return c;
}

}  // namespace hila::online
