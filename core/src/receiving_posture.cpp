#include "hila/core/receiving_posture.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "hila/core/error.hpp"

namespace hila::core {

namespace {

// The whole configuration and the model it belongs to: the body's where there is one.
Eigen::VectorXd posture_of(const Cell& cell, const HumanBody* body,
                           const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms) {
  return body != nullptr ? body->posture(arms) : human_posture(cell, arms);
}

std::vector<std::string> arm_names(
    const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms) {
  std::vector<std::string> names;
  for (const auto& entry : arms) names.push_back(entry.first);
  return names;
}

// Refuses a configuration of another model (another length) or with a NaN or an infinity.
void check_configuration(const RobotModel& human, const Eigen::VectorXd& q) {
  if (q.size() != human.num_variables() || !q.allFinite()) {
    throw InputError("receiving posture", "human configuration",
                     std::to_string(human.num_variables()) + " finite values",
                     std::to_string(q.size()) + (q.allFinite() ? "" : " (not finite)"));
  }
}

}  // namespace

ComfortSettings reach_settings() {
  ComfortSettings s;
  s.ik_attempts = 8;
  s.attempts_after_found = 0;
  s.tolerance = 1e-7;
  s.hold_joints_at_limits = true;
  return s;
}

ComfortResult reach_hand(const Cell& cell, const HumanBody* body, const Pose& stance,
                         const std::string& arm, const Pose& hand, const Eigen::VectorXd& seed,
                         const ComfortSettings& ik) {
  const std::vector<HumanArm>& arms = body != nullptr ? body->arms() : cell.human_arms();
  const auto a =
      std::find_if(arms.begin(), arms.end(), [&](const HumanArm& h) { return h.spec.name == arm; });
  if (a == arms.end()) return {};
  Pose base_in_stance;
  if (body != nullptr) {
    base_in_stance = body->base_in_stance(static_cast<int>(a - arms.begin()));
  } else {
    std::vector<Pose> links;
    cell.human().link_poses(cell.human_neutral(), links);
    base_in_stance = links[static_cast<std::size_t>(cell.human().link_index(a->spec.base_link))];
  }
  const Pose in_base = (stance * base_in_stance).inverse() * hand;
  if ((in_base.translation() - a->chain.first_joint_position()).norm() >
      characteristic_length(a->chain)) {
    return {};
  }
  const Eigen::VectorXd start = seed.size() == a->chain.dof()
                                    ? seed
                                    : Eigen::VectorXd::Zero(a->chain.dof())
                                          .cwiseMax(a->chain.lower_limits())
                                          .cwiseMin(a->chain.upper_limits());
  return best_comfort(a->chain, in_base, start, ik);
}

ReceivingScores receiving_scores(const Cell& cell, const HumanBody* body,
                                 const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
                                 double load_kg) {
  if (arms.empty()) return {};
  // Both hands hold the board at once: one configuration.
  return receiving_scores(cell, body, posture_of(cell, body, arms), arm_names(arms), load_kg,
                          arms.size() > 1);
}

ReceivingScores receiving_scores(const Cell& cell, const HumanBody* body, const Eigen::VectorXd& q,
                                 const std::vector<std::string>& arms, double load_kg,
                                 bool two_hands) {
  ReceivingScores r;
  if (arms.empty()) return r;
  const RobotModel& human = body != nullptr ? body->model() : cell.human();
  check_configuration(human, q);
  r.two_hands = two_hands || arms.size() > 1;
  r.load_kg = load_kg;
  for (const auto& arm : arms) {
    HandScores h;
    h.arm = arm;
    h.rula_inputs = rula_inputs_from_posture(human, q, arm, load_kg, r.two_hands);
    h.rula = rula(h.rula_inputs);
    h.reba_inputs = reba_inputs_from_posture(human, q, arm, load_kg);
    h.reba = reba(h.reba_inputs);
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

PostureCheck check_receiving_posture(
    const Cell& cell, const HumanBody* body, const Pose& stance,
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

PostureCheck check_receiving_posture(const Cell& cell, const HumanBody* body, const Pose& stance,
                                     const Eigen::VectorXd& q, const std::vector<std::string>& arms,
                                     const Eigen::Vector3d& part_centre, double load_kg,
                                     bool two_hands) {
  PostureCheck c;
  c.part_centre_z = part_centre.z();
  if (arms.empty()) return c;
  const RobotModel& human = body != nullptr ? body->model() : cell.human();
  const std::vector<HumanArm>& human_arms = body != nullptr ? body->arms() : cell.human_arms();
  check_configuration(human, q);
  std::vector<Pose> links;
  human.link_poses(q, links);
  c.shoulder_z = std::numeric_limits<double>::infinity();
  c.elbow_below_shoulder = true;
  for (const auto& name : arms) {
    const auto arm = std::find_if(human_arms.begin(), human_arms.end(),
                                  [&](const auto& h) { return h.spec.name == name; });
    if (arm == human_arms.end()) {
      std::string names;
      for (const auto& h : human_arms) names += (names.empty() ? "" : ", ") + h.spec.name;
      throw InputError("receiving posture", "human arms", "one of: " + names, "'" + name + "'");
    }
    const Pose base =
        stance * links[static_cast<std::size_t>(human.link_index(arm->spec.base_link))];
    // The torso's joint is the hip: the arm base link's own joint, at the link's origin.
    const int torso_joint =
        human.links()[static_cast<std::size_t>(human.link_index(arm->spec.base_link))].parent_joint;
    if (torso_joint >= 0) {
      const int v = human.joints()[static_cast<std::size_t>(torso_joint)].variable;
      if (v >= 0) c.trunk_flexion_deg = rad_to_deg(q[v]);
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

}  // namespace hila::core
