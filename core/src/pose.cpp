#include "hila/core/pose.hpp"

#include <cmath>

#include "hila/core/error.hpp"

namespace hila::core {

Eigen::Matrix3d rpy_to_matrix(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d matrix_to_rpy(const Eigen::Matrix3d& r) {
  const double pitch = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  const double roll = std::atan2(r(2, 1), r(2, 2));
  const double yaw = std::atan2(r(1, 0), r(0, 0));
  return {roll, pitch, yaw};
}

Pose make_pose(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy) {
  Pose pose = Pose::Identity();
  pose.linear() = rpy_to_matrix(rpy);
  pose.translation() = xyz;
  return pose;
}

bool is_valid_pose(const Pose& pose, double tolerance) {
  if (!pose.matrix().allFinite()) return false;
  const Eigen::Matrix3d r = pose.linear();
  if (!(r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), tolerance)) return false;
  return std::abs(r.determinant() - 1.0) < tolerance;
}

void check_pose(const Pose& pose, const std::string& file, const std::string& field,
                double tolerance) {
  if (!pose.matrix().allFinite()) {
    throw InputError(file, field, "a finite pose", "NaN or infinite values");
  }
  const Eigen::Matrix3d r = pose.linear();
  const double err = ((r.transpose() * r) - Eigen::Matrix3d::Identity()).norm();
  if (err > tolerance || std::abs(r.determinant() - 1.0) > tolerance) {
    throw InputError(file, field, "an orthonormal rotation with determinant +1",
                     "a matrix with |R^T R - I| = " + format_number(err) +
                         " and det = " + format_number(r.determinant()));
  }
}

double rotation_distance(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle();
}

}  // namespace hila::core
