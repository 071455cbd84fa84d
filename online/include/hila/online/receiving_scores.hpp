#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/human_body.hpp"
#include "hila/online/board_planner.hpp"

namespace hila::online {

// RULA and REBA of one hand of the human's receiving posture (docs/ergonomic_scores.md).
struct HandScores {
  std::string arm;  // the human arm ("left", "right"): the side scored
  core::RulaInputs rula_inputs;
  core::RulaScore rula;
  core::RebaInputs reba_inputs;
  core::RebaScore reba;
};

// The receiving posture of a planned board scored: each hand that takes it, the goal's hand
// first, then the second hand of a two-hand goal.
struct ReceivingScores {
  bool scored = false;  // false: the plan has no human posture (not solved)
  bool two_hands = false;
  double load_kg = 0.0;  // the part's mass
  std::vector<HandScores> hands;
  // The hand with the higher RULA grand score and the one with the higher REBA score (the first
  // hand on a tie): the board's scores.
  int worst_rula = -1;
  int worst_reba = -1;
  const core::RulaScore& rula() const { return hands[static_cast<std::size_t>(worst_rula)].rula; }
  const core::RebaScore& reba() const { return hands[static_cast<std::size_t>(worst_reba)].reba; }
};

// RULA and REBA of a receiving posture: the arms' chain joints (`arms`: the goal's hand first),
// the rest of the human at its neutral posture, on `body` (nullptr: the cell's human), holding
// `load_kg` (two hands where `arms` has two). Throws core::InputError as below.
ReceivingScores receiving_scores(const core::Cell& cell, const core::HumanBody* body,
                                 const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
                                 double load_kg);
// The same at a whole configuration `q` of the human model (the body's, else the cell's human),
// e.g. with the torso bent forward: the hands `arms` (human arm names) scored there. `two_hands`:
// the load is shared by two hands even where `arms` names one (a part held with both hands whose
// one hand's posture stands for both); with two arms it is shared anyway.
ReceivingScores receiving_scores(const core::Cell& cell, const core::HumanBody* body,
                                 const Eigen::VectorXd& q, const std::vector<std::string>& arms,
                                 double load_kg, bool two_hands);

// Where a receiving posture puts the worker (docs/online.md, "Goals a person would choose"):
// the torso's forward bend, whether every receiving elbow is below its shoulder, and the part's
// centre of mass against the worker's hip and shoulder heights (world z, the human at `stance`),
// with the posture's RULA grand score (the worse hand's).
struct PostureCheck {
  double trunk_flexion_deg = 0.0;     // the torso joint, forward positive
  bool elbow_below_shoulder = false;  // every receiving hand's elbow joint below its shoulder
  double part_centre_z = 0.0;         // m, world
  double hip_z = 0.0;                 // m, world: the torso's hip joint
  double shoulder_z = 0.0;            // m, world: the lower receiving shoulder joint
  int rula_grand = 0;
  // No forward bend (within core::kNeutralBandDeg), the elbows below the shoulders, the centre
  // between hip and shoulder height.
  bool upright() const {
    return trunk_flexion_deg <= core::kNeutralBandDeg && elbow_below_shoulder &&
           part_centre_z >= hip_z && part_centre_z <= shoulder_z;
  }
  // Upright, and RULA grand at most `max_rula`.
  bool natural(int max_rula) const { return upright() && rula_grand <= max_rula; }
};
PostureCheck check_receiving_posture(
    const core::Cell& cell, const core::HumanBody* body, const core::Pose& stance,
    const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
    const Eigen::Vector3d& part_centre, double load_kg);
// The same at a whole configuration `q` (receiving_scores above: `arms` by name, `two_hands`).
PostureCheck check_receiving_posture(const core::Cell& cell, const core::HumanBody* body,
                                     const core::Pose& stance, const Eigen::VectorXd& q,
                                     const std::vector<std::string>& arms,
                                     const Eigen::Vector3d& part_centre, double load_kg,
                                     bool two_hands);

// Scores the posture the planner hands the board over at: plan.human_joints on plan.human_arm
// (and plan.second_human_joints on plan.second_human_arm), the rest of the human at
// cell.human_neutral() (core::human_posture), holding `load_kg`; on the plan's worker's body
// where it names one (BoardPlan::worker: its model, its neutral posture). RULA scores each hand
// with its share of the load (half with two hands), REBA with the whole load. Nothing scored
// (scored false) for a plan without a posture. Throws core::InputError where the cell's human model
// is not one of generate_human_urdf or its arms are not named "left" and "right"; meant for the
// output edge, after planning.
ReceivingScores receiving_scores(const core::Cell& cell, const BoardPlan& plan, double load_kg);

}  // namespace hila::online
