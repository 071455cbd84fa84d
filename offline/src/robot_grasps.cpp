#include "hila/offline/robot_grasps.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "hila/core/error.hpp"
#include "hila/core/soft_finger.hpp"

namespace hila::offline {

HandGeometry gripper_geometry(const core::Cell& cell, const std::string& arm_name) {
  const core::Arm& arm = cell.arm(arm_name);
  const core::RobotModel& robot = cell.robot();
  const int flange = robot.link_index(arm.spec.flange_link);
  const int tcp_link = robot.link_index(arm.spec.tip_link);
  constexpr double kProbe = 0.02;  // jaw opening used to tell which links move with the fingers
  Eigen::VectorXd q_closed = cell.home_configuration(0.0);
  Eigen::VectorXd q_open = cell.home_configuration(kProbe);
  std::vector<core::Pose> closed, open;
  robot.link_poses(q_closed, closed);
  robot.link_poses(q_open, open);
  const core::Pose tcp_inv = closed[tcp_link].inverse();

  HandGeometry hand;
  std::vector<int> stack{flange};
  while (!stack.empty()) {
    const int link = stack.back();
    stack.pop_back();
    for (const int j : robot.links()[link].child_joints) stack.push_back(robot.joints()[j].child_link);
    const auto& shapes = robot.links()[link].collisions;
    if (shapes.empty()) continue;
    const double moved = (tcp_inv * open[link]).translation().y() -
                         (tcp_inv * closed[link]).translation().y();
    auto& group = moved > 0.25 * kProbe    ? hand.finger_pos
                  : moved < -0.25 * kProbe ? hand.finger_neg
                                           : hand.fixed;
    for (core::GeometrySpec spec : shapes) {
      spec.origin = tcp_inv * closed[link] * spec.origin;
      group.push_back(spec);
    }
  }
  return hand;
}

double gripper_torque_capacity(const core::Cell& cell) {
  const auto& g = cell.spec().gripper;
  if (g.friction_torque_capacity > 0.0) return g.friction_torque_capacity;
  core::SoftFingerPad pad{g.pad.friction, g.pad.elastic_modulus, g.pad.thickness, g.pad.radius_1,
                          g.pad.radius_2};
  return 2.0 * core::finger_friction_torque(pad, g.grip_force);
}

double grasp_theta_c(const core::Cell& cell, double mass, const Eigen::Vector3d& com,
                     const Eigen::Vector3d& contact_centre, const Eigen::Vector3d& axis) {
  core::RelaxationSettings relax;
  relax.step_deg = cell.spec().gripper.slip_step_deg;
  return core::relaxation_limit_deg(mass, cell.spec().gravity, axis_lever(com, contact_centre, axis),
                                    gripper_torque_capacity(cell), relax);
}

std::vector<db::RobotGraspRecord> plan_robot_grasps(const core::TriangleMesh& mesh,
                                                    const PartAnalysis& analysis, double mass,
                                                    const core::Cell& cell,
                                                    const RobotGraspSettings& settings) {
  const auto& gripper = cell.spec().gripper;
  const SurfaceQuery surface(mesh);
  AntipodalSettings antipodal;
  antipodal.samples = settings.samples;
  antipodal.friction = gripper.pad.friction;
  antipodal.min_width = gripper.jaw_min;
  antipodal.max_width = gripper.jaw_max - settings.opening_margin;
  antipodal.seed = settings.seed;
  const std::vector<ContactPair> pairs = sample_antipodal_pairs(surface, antipodal);

  HandPartChecker checker(gripper_geometry(cell, cell.arms().front().spec.name), mesh);
  const Eigen::Vector3d com = analysis.mass_properties.com;
  const double half_extent = 0.5 * (mesh.max_corner() - mesh.min_corner()).maxCoeff();
  const double capacity = gripper_torque_capacity(cell);

  std::vector<db::RobotGraspRecord> candidates;
  for (const ContactPair& pair : pairs) {
    const double opening = std::min(pair.width + settings.opening_margin, gripper.jaw_max);
    for (const core::Pose& frame : grasp_frames_about_axis(pair, settings.approach_rotations)) {
      if (checker.collides(frame, opening)) continue;
      db::RobotGraspRecord g;
      g.tcp = frame;
      g.jaw_width = pair.width;
      g.contact_1 = pair.first.point;
      g.normal_1 = pair.first.normal;
      g.contact_2 = pair.second.point;
      g.normal_2 = pair.second.normal;
      g.lever = axis_lever(com, pair.centre, pair.axis);
      g.friction_torque_capacity = capacity;
      g.theta_c_deg = grasp_theta_c(cell, mass, com, pair.centre, pair.axis);
      g.quality = 0.5 * pair.alignment + 0.5 * (1.0 - std::min(1.0, g.lever / half_extent));
      candidates.push_back(g);
    }
  }
  // Best first; ties broken by position so the order never depends on hash or thread order.
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const db::RobotGraspRecord& a, const db::RobotGraspRecord& b) {
                     return a.quality > b.quality;
                   });
  std::vector<core::Pose> poses;
  poses.reserve(candidates.size());
  for (const auto& g : candidates) poses.push_back(g.tcp);
  std::vector<db::RobotGraspRecord> grasps;
  for (const int i : distinct_poses(poses, settings.merge_distance,
                                    core::deg_to_rad(settings.merge_angle_deg))) {
    grasps.push_back(candidates[static_cast<std::size_t>(i)]);
  }
  return grasps;
}

}  // namespace hila::offline
