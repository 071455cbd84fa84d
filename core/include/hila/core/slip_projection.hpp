#pragma once

#include <Eigen/Core>

#include "hila/core/cell.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

// Moves an arm configuration onto a held part's slip limit: the slip angle (slip_angle_deg) of
// a grasp depends only on the TCP's orientation, through sin(theta_s) = |g . (R n)| with n the
// opening axis crossed with the lever in the TCP frame. A few minimum-norm Newton steps on that
// one scalar, over all the arm's joints (the geometric Jacobian's angular rows), bring
// |g . (R n)| within `fill` of sin(theta_c). What a constrained bridge samples with
// (BridgeSettings::project): under a tight theta_c most uniform samples slip. Immutable; the
// call is thread-safe.
class SlipProjection {
 public:
  // `base`: the arm's base in the world (gravity is world -z); axis and lever in the TCP frame.
  SlipProjection(const Arm& arm, const Pose& base, const Eigen::Vector3d& axis_tcp,
                 const Eigen::Vector3d& lever_tcp, double theta_c_deg, double fill = 0.8);

  // Whether the constraint binds at all (a lever along the axis, or theta_c >= 90: never slips).
  bool active() const { return active_; }
  // The slip-limited scalar g . (R n) at q, whose magnitude is sin(theta_s).
  double constraint(const Eigen::VectorXd& q) const;
  // Its gradient over the arm's joints (analytic, from the geometric Jacobian).
  Eigen::VectorXd gradient(const Eigen::VectorXd& q) const;
  // Projects q in place; false when the steps do not reach the limit (q is then unchanged).
  bool operator()(Eigen::VectorXd& q) const;

 private:
  // The constraint at q, and its gradient into `gradient`.
  double evaluate(const Eigen::VectorXd& q, Eigen::VectorXd& gradient) const;

  const Arm* arm_;
  Pose base_;
  Eigen::Vector3d normal_tcp_;  // opening axis x lever, TCP frame
  double limit_ = 1.0;          // sin(theta_c)
  double fill_ = 0.8;
  bool active_ = false;
};

}  // namespace hila::core
