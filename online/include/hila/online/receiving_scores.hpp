#pragma once

#include "hila/core/receiving_posture.hpp"
#include "hila/online/board_planner.hpp"

namespace hila::online {

using core::check_receiving_posture;
using core::HandScores;
using core::PostureCheck;
using core::receiving_scores;
using core::ReceivingScores;

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
