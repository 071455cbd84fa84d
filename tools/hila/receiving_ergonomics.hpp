#pragma once

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>

#include "hila/core/cell.hpp"
#include "hila/core/pose.hpp"
#include "hila/online/board_planner.hpp"
#include "hila/online/receiving_scores.hpp"

namespace hila::tools {

// A receiving posture scored (RULA, REBA: online::receiving_scores) and placed against the
// worker (online::check_receiving_posture): what the plan file's `ergonomics` block holds and
// `hila report ergonomics` reports for every way of taking a board.
struct ReceivingErgonomics {
  online::ReceivingScores scores;  // scored false: see `error`
  online::PostureCheck check;
  std::string error;  // why nothing is scored ("" when scored)
};

// The posture a plan hands the board over at (plan.human_joints and, for two hands,
// plan.second_human_joints) on the plan's worker (BoardPlan::worker, else the cell's human)
// standing at `stance`, holding `load_kg` (kg) with the part's centre of mass at
// `centre_of_mass` (part frame, m) carried to plan.human_handover. A human model the scores
// cannot read, or a plan without a posture, gives the reason in `error`.
ReceivingErgonomics plan_receiving_ergonomics(const core::Cell& cell, const online::BoardPlan& plan,
                                              double load_kg, const core::Pose& stance,
                                              const Eigen::Vector3d& centre_of_mass);

// The plan file's `ergonomics` block (docs/online.md): load, posture check, the board's RULA
// and REBA (the worse hand's) and each hand's with every sub-score; {"error": why} when not
// scored.
nlohmann::json receiving_ergonomics_json(const ReceivingErgonomics& e);

// One hand's RULA and REBA with every sub-score, and the arm angles they were scored from.
nlohmann::json hand_scores_json(const online::HandScores& h);

}  // namespace hila::tools
