#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

// Where an open gripper may wait before closing on a board, as world offsets of the TCP from
// the grasp, in order of preference: back along the approach axis by `distance`, half and a
// fifth of it (the exchange may be close to the robot's body), then slid along the board's edge
// (approach x opening: the open fingers straddle the board) by +-distance and +-distance / 2.
std::vector<Eigen::Vector3d> pre_grasp_offsets(const Pose& grasp_tcp,
                                               const Eigen::Vector3d& approach_tcp,
                                               const Eigen::Vector3d& opening_tcp, double distance);

// The first pre-grasp (the offsets above, each by the IK solution nearest `grasp_q`) that is
// `valid` with every sample of the straight joint motion into `grasp_q` at `resolution`
// valid too; nothing when the grasp has no way in. The handover search, the regrasp graph and
// the online receiving approach all ask this one question.
std::optional<Eigen::VectorXd> find_pre_grasp(
    const Cell& cell, const Arm& arm, const Eigen::VectorXd& grasp_q, double distance,
    double resolution, const std::function<bool(const Eigen::VectorXd&)>& valid);

}  // namespace hila::core
