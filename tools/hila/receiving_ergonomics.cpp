#include "receiving_ergonomics.hpp"

#include <utility>
#include <vector>

#include "hila/core/error.hpp"

namespace hila::tools {

ReceivingErgonomics plan_receiving_ergonomics(const core::Cell& cell, const online::BoardPlan& plan,
                                              double load_kg, const core::Pose& stance,
                                              const Eigen::Vector3d& centre_of_mass) {
  ReceivingErgonomics e;
  try {
    e.scores = online::receiving_scores(cell, plan, load_kg);
    if (!e.scores.scored) {
      e.error = "no receiving posture";
      return e;
    }
    // Where the posture puts the worker (BoardPlanSettings::natural_posture_first).
    std::vector<std::pair<std::string, Eigen::VectorXd>> arms{{plan.human_arm, plan.human_joints}};
    if (!plan.second_human_arm.empty()) {
      arms.emplace_back(plan.second_human_arm, plan.second_human_joints);
    }
    e.check = online::check_receiving_posture(cell, plan.worker.get(), stance, arms,
                                              plan.human_handover * centre_of_mass, load_kg);
  } catch (const core::InputError& error) {
    e.scores = {};
    e.error = error.what();
  }
  return e;
}

nlohmann::json hand_scores_json(const online::HandScores& h) {
  const core::RulaScore& r = h.rula;
  const core::RebaScore& b = h.reba;
  return {{"side", h.arm},
          {"angles_deg",
           {{"trunk_flexion", h.rula_inputs.trunk_flexion_deg},
            {"upper_arm", h.rula_inputs.upper_arm_flexion_deg},
            {"upper_arm_abducted", h.rula_inputs.upper_arm_abducted},
            {"lower_arm", h.rula_inputs.lower_arm_flexion_deg},
            {"arm_across_midline_or_out_to_side", h.rula_inputs.arm_across_midline_or_out_to_side},
            {"wrist", h.rula_inputs.wrist_flexion_deg},
            {"wrist_deviated", h.rula_inputs.wrist_deviated},
            {"wrist_twist_near_end", h.rula_inputs.wrist_twist_near_end}}},
          {"rula",
           {{"grand", r.grand},
            {"action_level", core::rula_action_level(r.grand)},
            {"action", core::rula_action(r.grand)},
            {"load_kg", h.rula_inputs.load_kg},
            {"upper_arm", r.upper_arm},
            {"lower_arm", r.lower_arm},
            {"wrist", r.wrist},
            {"wrist_twist", r.wrist_twist},
            {"posture_a", r.posture_a},
            {"muscle_use", r.muscle_use},
            {"force_load", r.force_load},
            {"score_c", r.score_c},
            {"neck", r.neck},
            {"trunk", r.trunk},
            {"legs", r.legs},
            {"posture_b", r.posture_b},
            {"score_d", r.score_d}}},
          {"reba",
           {{"score", b.reba},
            {"risk", core::reba_risk_level(b.reba)},
            {"load_kg", h.reba_inputs.load_kg},
            {"neck", b.neck},
            {"trunk", b.trunk},
            {"legs", b.legs},
            {"posture_a", b.posture_a},
            {"load_force", b.load_force},
            {"score_a", b.score_a},
            {"upper_arm", b.upper_arm},
            {"lower_arm", b.lower_arm},
            {"wrist", b.wrist},
            {"posture_b", b.posture_b},
            {"coupling", b.coupling},
            {"score_b", b.score_b},
            {"score_c", b.score_c},
            {"activity", b.activity}}}};
}

nlohmann::json receiving_ergonomics_json(const ReceivingErgonomics& e) {
  if (!e.scores.scored) return {{"error", e.error}};
  const online::ReceivingScores& s = e.scores;
  const online::PostureCheck& c = e.check;
  nlohmann::json hands = nlohmann::json::array();
  for (const auto& h : s.hands) hands.push_back(hand_scores_json(h));
  return {{"load_kg", s.load_kg},
          {"posture",
           {{"trunk_flexion_deg", c.trunk_flexion_deg},
            {"elbow_below_shoulder", c.elbow_below_shoulder},
            {"part_centre_z", c.part_centre_z},
            {"hip_z", c.hip_z},
            {"shoulder_z", c.shoulder_z},
            {"natural", c.natural(online::BoardPlanSettings{}.natural_max_rula)}}},
          {"two_hands", s.two_hands},
          {"rula",
           {{"grand", s.rula().grand},
            {"action_level", core::rula_action_level(s.rula().grand)},
            {"action", core::rula_action(s.rula().grand)},
            {"side", s.hands[static_cast<std::size_t>(s.worst_rula)].arm}}},
          {"reba",
           {{"score", s.reba().reba},
            {"risk", core::reba_risk_level(s.reba().reba)},
            {"side", s.hands[static_cast<std::size_t>(s.worst_reba)].arm}}},
          {"hands", hands}};
}

}  // namespace hila::tools
