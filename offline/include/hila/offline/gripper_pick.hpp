#pragma once

#include <Eigen/Core>

#include "hila/core/pose.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/arm_workspace.hpp"

namespace hila::offline {

struct GripperPickSettings {
  // m: the open gripper waits this far back from the grasp (core::find_pre_grasp) and comes in
  // straight, checked at approach_resolution (rad).
  double approach = 0.05;
  double approach_resolution = 0.01;
  double lift = 0.15;        // m straight up with the part held
  double resolution = 0.01;  // rad: the lift's samples
  double jaw_margin = 0.005;  // m: the jaws close to the part's width plus this while holding
};

// One arm's gripper taking the part where it lies (no tool, no exchange): an IK solution at the
// grasp, clear of the cell with the open gripper around the part standing at its initial pose,
// with a way in from a pre-grasp, and the lift straight up with the part held, clear from the
// first sample after the grasp (at the grasp the part still rests on what carries it).
// How far the best IK branch got, for the reason a part cannot be picked: no IK solution at
// the grasp (out of reach), none clear of the cell there, none with a way in, no IK for the
// lift, the lift blocked.
enum class GripperPickCheck { kReach, kGraspClear, kWayIn, kLiftReach, kLiftClear, kPicked };
const char* to_string(GripperPickCheck check);

struct GripperPick {
  Eigen::VectorXd grasp;  // joints at the grasp (empty: none)
  Eigen::VectorXd lift;   // joints after the lift
  GripperPickCheck failed = GripperPickCheck::kReach;  // kPicked when ok()
  bool ok() const { return grasp.size() > 0 && lift.size() > 0; }
};

// `workspace`: the picking arm's, built with the part's mesh and, for the suction arm, the tool
// standing on the table (an arm holding the tool has no free gripper). The slip limit is the
// caller's check (the part's pose fixes it before any IK). Leaves the workspace released.
GripperPick plan_gripper_pick(ArmWorkspace& workspace, const core::Pose& board_initial,
                              const db::RobotGraspRecord& grasp,
                              const GripperPickSettings& settings);

}  // namespace hila::offline
