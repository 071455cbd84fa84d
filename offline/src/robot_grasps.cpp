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
    for (const int j : robot.links()[link].child_joints)
      stack.push_back(robot.joints()[j].child_link);
    const auto& shapes = robot.links()[link].collisions;
    if (shapes.empty()) continue;
    const double moved =
        (tcp_inv * open[link]).translation().y() - (tcp_inv * closed[link]).translation().y();
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
  return core::relaxation_limit_deg(mass, cell.spec().gravity,
                                    axis_lever(com, contact_centre, axis),
                                    gripper_torque_capacity(cell), relax);
}

std::vector<db::RobotGraspRecord> plan_robot_grasps(const core::TriangleMesh& mesh,
                                                    const PartAnalysis& analysis, double mass,
                                                    const core::Cell& cell,
                                                    const RobotGraspSettings& settings) {
  const auto& gripper = cell.spec().gripper;
  TwoFingerSettings two;
  two.antipodal.samples = settings.samples;
  two.antipodal.friction = gripper.pad.friction;
  two.antipodal.min_width = gripper.jaw_min;
  two.antipodal.max_width = gripper.jaw_max - settings.opening_margin;
  two.antipodal.seed = settings.seed;
  two.approach_rotations = settings.approach_rotations;
  two.opening_margin = settings.opening_margin;
  two.max_opening = gripper.jaw_max;
  two.merge_distance = settings.merge_distance;
  two.merge_angle_deg = settings.merge_angle_deg;
  two.max_tip_shift = std::max(0.0, 0.5 * gripper.pad.length - settings.tip_margin);
  two.tip_clearance = settings.tip_clearance;
  const Eigen::Vector3d com = analysis.mass_properties.com;
  const double capacity = gripper_torque_capacity(cell);
  std::vector<db::RobotGraspRecord> grasps;
  for (const TwoFingerGrasp& t : plan_two_finger_grasps(
           mesh, com, gripper_geometry(cell, cell.arms().front().spec.name), two)) {
    db::RobotGraspRecord g;
    g.tcp = t.frame;
    g.jaw_width = t.pair.width;
    g.contact_1 = t.pair.first.point;
    g.normal_1 = t.pair.first.normal;
    g.contact_2 = t.pair.second.point;
    g.normal_2 = t.pair.second.normal;
    g.lever = t.lever;
    g.quality = t.quality;
    g.friction_torque_capacity = capacity;
    g.theta_c_deg = grasp_theta_c(cell, mass, com, t.pair.centre, t.pair.axis);
    grasps.push_back(g);
  }
  return grasps;
}

}  // namespace hila::offline
