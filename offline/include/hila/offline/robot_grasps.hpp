#pragma once

#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/grasp_common.hpp"
#include "hila/offline/part_analysis.hpp"

namespace hila::offline {

struct RobotGraspSettings {
  int samples = 1500;             // surface samples tried as first contacts
  int approach_rotations = 12;    // approach directions about each grasp axis (30 degrees)
  double opening_margin = 0.005;  // m, the jaw opens to width + margin before closing
  double merge_distance = 0.01;   // m, near-duplicate TCP positions
  double merge_angle_deg = 20.0;  // and orientations
  // Fingertip grasps (TwoFingerSettings::max_tip_shift): a grasp whose fingers would reach past
  // the part is set back so they end `tip_clearance` short of it, while the contact stays at least
  // `tip_margin` inside the pad's end (the TCP is the pads' centre, the pad `gripper.pad.length`
  // long along the approach). A small part lying on the table is taken at the fingertips.
  double tip_clearance = 0.002;  // m
  double tip_margin = 0.003;     // m
  std::uint64_t seed = 1;
};

// The 2F-85 of the cell as HandGeometry in its TCP frame: every link below the arm's flange,
// with the finger links (those that move with the jaw joint) separated by side.
HandGeometry gripper_geometry(const core::Cell& cell, const std::string& arm);

// The friction-torque capacity of a grasp (both fingers), N m: the cell's calibration when set,
// else 2 mu P e_n of the soft-finger model at the cell's grip force.
double gripper_torque_capacity(const core::Cell& cell);

// Per-grasp relaxation limit theta_c (paper §V-C) for a part of `mass` with its centre of mass at
// `com`, grasped along the axis through `contact_centre` with unit direction `axis`.
double grasp_theta_c(const core::Cell& cell, double mass, const Eigen::Vector3d& com,
                     const Eigen::Vector3d& contact_centre, const Eigen::Vector3d& axis);

// Antipodal parallel-jaw grasps of the cell's gripper on a part, collision-free against the part,
// near-duplicates merged, sorted by decreasing quality. quality = 0.5 * (antipodal alignment) +
// 0.5 * (1 - lever / half the part's largest extent): grasps near the CoM axis are better.
std::vector<db::RobotGraspRecord> plan_robot_grasps(const core::TriangleMesh& mesh,
                                                    const PartAnalysis& analysis, double mass,
                                                    const core::Cell& cell,
                                                    const RobotGraspSettings& settings);

}  // namespace hila::offline
