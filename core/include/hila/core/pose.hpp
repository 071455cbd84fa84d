#pragma once

#include <Eigen/Geometry>
#include <string>

namespace hila::core {

using Pose = Eigen::Isometry3d;

// Roll-pitch-yaw (fixed X, then Y, then Z; URDF convention) in radians.
Eigen::Matrix3d rpy_to_matrix(const Eigen::Vector3d& rpy);
Eigen::Vector3d matrix_to_rpy(const Eigen::Matrix3d& rotation);

Pose make_pose(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy = Eigen::Vector3d::Zero());

// True if every entry is finite and the rotation is orthonormal with det +1 (to tolerance).
bool is_valid_pose(const Pose& pose, double tolerance = 1e-6);

// Throws InputError naming `file` and `field` when the pose is not finite or not a rotation.
void check_pose(const Pose& pose, const std::string& file, const std::string& field,
                double tolerance = 1e-6);

// Angle of the relative rotation between two poses, in radians, in [0, pi].
double rotation_distance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

constexpr double kPi = 3.14159265358979323846;
constexpr double deg_to_rad(double deg) {
  return deg * kPi / 180.0;
}
constexpr double rad_to_deg(double rad) {
  return rad * 180.0 / kPi;
}

}  // namespace hila::core
