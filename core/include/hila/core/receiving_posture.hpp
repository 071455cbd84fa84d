#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/comfort.hpp"
#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/pose.hpp"

// The worker's receiving posture scored (RULA, REBA) and checked (forward bend, elbow against
// shoulder, the part's centre against hip and shoulder): what the online planner orders goals by
// and the offline build widens a worker's band candidates by.
namespace hila::core {

// How the online planner reaches a receiving hand, and the offline build judges a goal by it:
// 8 attempts, stopping at the first solution, to 1e-7 m and rad (far below what a human hand
// notices), with the joints at a limit held out of the step (receiving postures often have a
// wrist or elbow at its end stop: clipped steps crawl along it).
ComfortSettings reach_settings();

// The arm `arm` (a human arm name) of `body` (nullptr: the cell's human), the worker standing at
// `stance` at its neutral posture, reaching the hand pose `hand` (world) by core::best_comfort
// from `seed` (the arm's chain joints; another size: all joints zero, within the limits).
// Unreachable without solving where the hand lies beyond the stretched arm from the shoulder, or
// for an arm the body has not.
ComfortResult reach_hand(const Cell& cell, const HumanBody* body, const Pose& stance,
                         const std::string& arm, const Pose& hand, const Eigen::VectorXd& seed,
                         const ComfortSettings& ik = reach_settings());

// RULA and REBA of one hand of the human's receiving posture (docs/ergonomic_scores.md).
struct HandScores {
  std::string arm;  // the human arm ("left", "right"): the side scored
  RulaInputs rula_inputs;
  RulaScore rula;
  RebaInputs reba_inputs;
  RebaScore reba;
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
  const RulaScore& rula() const { return hands[static_cast<std::size_t>(worst_rula)].rula; }
  const RebaScore& reba() const { return hands[static_cast<std::size_t>(worst_reba)].reba; }
};

// RULA and REBA of a receiving posture: the arms' chain joints (`arms`: the goal's hand first),
// the rest of the human at its neutral posture, on `body` (nullptr: the cell's human), holding
// `load_kg` (two hands where `arms` has two). Throws InputError as below.
ReceivingScores receiving_scores(const Cell& cell, const HumanBody* body,
                                 const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
                                 double load_kg);
// The same at a whole configuration `q` of the human model (the body's, else the cell's human),
// e.g. with the torso bent forward: the hands `arms` (human arm names) scored there. `two_hands`:
// the load is shared by two hands even where `arms` names one (a part held with both hands whose
// one hand's posture stands for both); with two arms it is shared anyway.
ReceivingScores receiving_scores(const Cell& cell, const HumanBody* body, const Eigen::VectorXd& q,
                                 const std::vector<std::string>& arms, double load_kg,
                                 bool two_hands);

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
  // No forward bend (within kNeutralBandDeg), the elbows below the shoulders, the centre
  // between hip and shoulder height.
  bool upright() const {
    return trunk_flexion_deg <= kNeutralBandDeg && elbow_below_shoulder && part_centre_z >= hip_z &&
           part_centre_z <= shoulder_z;
  }
  // Upright, and RULA grand at most `max_rula`.
  bool natural(int max_rula) const { return upright() && rula_grand <= max_rula; }
};
PostureCheck check_receiving_posture(
    const Cell& cell, const HumanBody* body, const Pose& stance,
    const std::vector<std::pair<std::string, Eigen::VectorXd>>& arms,
    const Eigen::Vector3d& part_centre, double load_kg);
// The same at a whole configuration `q` (receiving_scores above: `arms` by name, `two_hands`).
PostureCheck check_receiving_posture(const Cell& cell, const HumanBody* body, const Pose& stance,
                                     const Eigen::VectorXd& q, const std::vector<std::string>& arms,
                                     const Eigen::Vector3d& part_centre, double load_kg,
                                     bool two_hands);

}  // namespace hila::core
