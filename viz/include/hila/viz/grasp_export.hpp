#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/pose.hpp"

namespace hila::viz {

// A gripper grasp of the part, as the database stores it (robot_grasps).
struct GripperGraspView {
  std::int64_t id = 0;
  core::Pose tcp = core::Pose::Identity();  // the gripper's TCP in the part frame
  double jaw_width = 0.0;                   // m, the jaws' opening at the grasp
  double theta_c_deg = 90.0;                // relaxation limit θc, deg (90: no constraint)
};

// A suction grasp of the part, as the database stores it (suction_grasps).
struct SuctionGraspView {
  std::int64_t id = 0;
  core::Pose cup = core::Pose::Identity();  // the cup frame in the part frame (z into the part)
  double force_margin = 0.0;                // N, the cup's pull-off force left
  double moment_margin = 0.0;               // N m, the cup's moment left
};

struct GraspsView {
  std::string part;  // names the part's node
  const core::TriangleMesh* mesh = nullptr;
  core::Pose part_pose = core::Pose::Identity();  // where the part is shown (world)
  std::string arm;  // whose gripper is drawn; empty: the cell's first arm
  std::vector<GripperGraspView> gripper;
  std::vector<SuctionGraspView> suction;
};

// The suction grasp's holding margin: the smaller share of the cup's capacity left,
// min(force_margin / max_force, moment_margin / max_moment) (0 to 1 for a grasp that holds).
double holding_margin(const core::SuctionSpec& suction, const SuctionGraspView& grasp);

// The part's grasps as a glTF 2.0 binary (.glb): the part "part/NAME" at `part_pose`; per
// gripper grasp a node "grasp:ID" at part_pose * tcp (the TCP frame) holding the gripper's links
// (the arm's flange on, "grasp:ID/LINK", the jaws at the grasp's jaw width, clamped to the
// gripper's range) with the TCP link at the node's origin; per suction grasp a node "suction:ID"
// at part_pose * cup holding the suction tool's links ("suction:ID/LINK") with the cup link at
// the node's origin. Colours (materials "theta_c D deg", "margin M"): scale_colour of θc / 90
// for a gripper, of holding_margin for a suction tool, red (0) to green (1). Throws
// core::InputError for an unknown arm or a missing mesh.
std::string grasps_glb(const core::Cell& cell, const GraspsView& view);

}  // namespace hila::viz
