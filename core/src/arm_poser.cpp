#include "hila/core/arm_poser.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace hila::core {

ArmPoser::ArmPoser(const Cell& cell, const CellScene& scene, const Arm& arm)
    : robot_(cell.robot()), bodies_(scene.robot) {
  std::vector<int> stack{robot_.link_index(arm.spec.base_link)};
  while (!stack.empty()) {
    const int link = stack.back();
    stack.pop_back();
    for (const int j : robot_.links()[static_cast<std::size_t>(link)].child_joints) {
      joints_.push_back(j);
      const int child = robot_.joints()[static_cast<std::size_t>(j)].child_link;
      if (bodies_.link_to_body[static_cast<std::size_t>(child)] >= 0) {
        link_bodies_.emplace_back(child, bodies_.link_to_body[static_cast<std::size_t>(child)]);
      }
      stack.push_back(child);
    }
  }
  // The model's joint order has every parent before its children (RobotModel::link_poses).
  std::sort(joints_.begin(), joints_.end());
  for (const int j : joints_) {
    const Pose& origin = robot_.joints()[static_cast<std::size_t>(j)].origin;
    const bool unrotated = origin.linear() == Eigen::Matrix3d::Identity();
    origin_unrotated_.push_back(unrotated);
    origin_identity_.push_back(unrotated && origin.translation().isZero(0.0));
  }
}

void ArmPoser::pose_robot(CollisionData& data, const Eigen::VectorXd& robot_q) {
  robot_.link_poses(robot_q, poses_);
  set_robot_pose(data, bodies_, poses_);
}

void ArmPoser::pose_arm(CollisionData& data, const Eigen::VectorXd& robot_q) {
  assert(poses_.size() == robot_.links().size());  // pose_robot() first
  for (std::size_t k = 0; k < joints_.size(); ++k) {
    const int j = joints_[k];
    const Joint& joint = robot_.joints()[static_cast<std::size_t>(j)];
    Pose& child = poses_[static_cast<std::size_t>(joint.child_link)];
    const Pose& parent = poses_[static_cast<std::size_t>(joint.parent_link)];
    // The same values as parent * origin: a product with an identity rotation is exact.
    if (origin_identity_[k]) {
      child = parent;
    } else if (origin_unrotated_[k]) {
      child.linear() = parent.linear();
      child.translation().noalias() = parent.linear() * joint.origin.translation();
      child.translation() += parent.translation();
    } else {
      child = parent * joint.origin;
    }
    if (joint.type == JointType::Fixed) continue;
    const double value = robot_.joint_value(robot_q, j);
    if (joint.type == JointType::Prismatic) {
      child.translation() += child.linear() * (value * joint.axis);
    } else if (joint.axis == Eigen::Vector3d::UnitZ()) {
      // A rotation about the joint's own z (every UR joint): two columns turn, nothing else.
      const double c = std::cos(value);
      const double s = std::sin(value);
      auto r = child.linear();
      const Eigen::Vector3d x = r.col(0);
      r.col(0) = c * x + s * r.col(1);
      r.col(1) = c * r.col(1) - s * x;
    } else {
      child = child * joint_motion(joint, value);
    }
  }
  for (const auto& [link, body] : link_bodies_) {
    data.set_body_pose(body, poses_[static_cast<std::size_t>(link)]);
  }
}

}  // namespace hila::core
