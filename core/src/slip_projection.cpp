#include "hila/core/slip_projection.hpp"

#include <cmath>

namespace hila::core {

SlipProjection::SlipProjection(const Arm& arm, const Pose& base, const Eigen::Vector3d& axis_tcp,
                               const Eigen::Vector3d& lever_tcp, double theta_c_deg, double fill)
    : arm_(&arm), base_(base), normal_tcp_(axis_tcp.cross(lever_tcp)), fill_(fill) {
  limit_ = std::sin(std::min(theta_c_deg, 90.0) * M_PI / 180.0);
  active_ = theta_c_deg < 90.0 && normal_tcp_.norm() > 1e-9;
  if (active_) normal_tcp_.normalize();
}

double SlipProjection::constraint(const Eigen::VectorXd& q) const {
  // Gravity is world -z: g . v is -v.z, whose sign does not matter to |.|.
  return -(base_.linear() * (arm_->chain.fk(q).linear() * normal_tcp_)).z();
}

double SlipProjection::evaluate(const Eigen::VectorXd& q, Eigen::VectorXd& gradient) const {
  Pose tip;
  Jacobian jac;
  arm_->chain.fk_and_jacobian(q, tip, jac);
  const Eigen::Vector3d v = base_.linear() * (tip.linear() * normal_tcp_);
  // d(R n)/dq_j = w_j x (R n), w_j the joint's world axis; the constraint is -(R n).z.
  gradient.resize(q.size());
  for (Eigen::Index j = 0; j < q.size(); ++j) {
    const Eigen::Vector3d w = base_.linear() * jac.block<3, 1>(3, j);
    gradient[j] = -(w.x() * v.y() - w.y() * v.x());
  }
  return -v.z();
}

Eigen::VectorXd SlipProjection::gradient(const Eigen::VectorXd& q) const {
  Eigen::VectorXd g;
  evaluate(q, g);
  return g;
}

bool SlipProjection::operator()(Eigen::VectorXd& q) const {
  if (!active_) return true;
  const double band = fill_ * limit_;
  Eigen::VectorXd x = q;
  Eigen::VectorXd gradient;
  constexpr int kSteps = 6;
  for (int step = 0; step <= kSteps; ++step) {
    const double f = evaluate(x, gradient);
    if (std::abs(f) <= limit_ && (step > 0 || std::abs(f) <= band)) {
      q = x;
      return true;
    }
    if (step == kSteps) break;
    const double g2 = gradient.squaredNorm();
    if (g2 < 1e-12) break;
    // A minimum-norm Newton step onto the band's near edge.
    const double target = f > 0.0 ? band : -band;
    x -= ((f - target) / g2) * gradient;
  }
  return false;
}

}  // namespace hila::core
