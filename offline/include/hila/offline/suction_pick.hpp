#pragma once

#include <Eigen/Core>
#include <vector>

#include "hila/core/pose.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/arm_workspace.hpp"

namespace hila::offline {

// The suction arm taking the board from the stack: its IK solutions with the cup on the board's
// face (collision-free, the board standing at its initial pose), and the lift straight up with
// the board held, on the IK branch of the first solution.
struct SuctionPick {
  std::vector<Eigen::VectorXd> solutions;  // nearest home first; the one with the lift first
  Eigen::VectorXd lift;                    // joints after the lift (empty: no free lift)
  bool ok() const { return !solutions.empty() && lift.size() > 0; }
};

// `workspace` must be the suction arm's, built with the board's mesh. The lift is checked at
// `resolution` (rad) from the first sample after the pick (at the pick the board rests on the
// table). Leaves the workspace released.
SuctionPick plan_suction_pick(ArmWorkspace& workspace, const core::Pose& board_initial,
                              const db::SuctionGraspRecord& grasp, double lift, double resolution);

}  // namespace hila::offline
