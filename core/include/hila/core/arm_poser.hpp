#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

// Poses one arm of the robot in collision data: what a motion check does at every sample.
// set_robot_state() runs the whole robot's FK and moves every robot body; an arm moving alone
// only changes the links below its base (its joints, the gripper, the jaw), so those are all
// that pose_arm() recomputes and moves. Per-thread, like the CollisionData it poses.
class ArmPoser {
 public:
  ArmPoser(const Cell& cell, const CellScene& scene, const Arm& arm);

  // The whole robot (as set_robot_state), remembering every link pose.
  void pose_robot(CollisionData& data, const Eigen::VectorXd& robot_q);
  // The arm's links only. robot_q may differ from the last pose_robot() on this data in the
  // arm's own joints and jaw only; everything else is as posed then.
  void pose_arm(CollisionData& data, const Eigen::VectorXd& robot_q);
  // A link's pose (root frame, which is the world's) as last posed.
  const Pose& link_pose(int link) const { return poses_[static_cast<std::size_t>(link)]; }

 private:
  const RobotModel& robot_;
  const RobotBodies& bodies_;
  std::vector<int> joints_;  // below the arm's base, parents first
  // Per joint of joints_: its origin has no rotation (most of an arm's: the product with it is
  // a translation, and exactly the product's result), and no translation either.
  std::vector<char> origin_unrotated_;
  std::vector<char> origin_identity_;
  std::vector<std::pair<int, int>> link_bodies_;  // (link, body) below the arm's base
  std::vector<Pose> poses_;                       // every link, root frame
};

}  // namespace hila::core
