#include "hila/core/comfort.hpp"

#include <Eigen/SVD>
#include <random>

#include "hila/core/generic_ik.hpp"

namespace hila::core {

double comfort_index(const core::Jacobian& jacobian, double characteristic_length) {
  core::Jacobian scaled = jacobian;
  scaled.topRows<3>() /= characteristic_length;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled);
  const auto& s = svd.singularValues();
  if (s.size() == 0 || s[0] <= 0.0) return 0.0;
  // A 6 x n Jacobian with n >= 6 has six singular values; fewer columns leave it rank-deficient.
  if (jacobian.cols() < 6) return 0.0;
  return s[s.size() - 1] / s[0];
}

double characteristic_length(const core::KinematicChain& arm) {
  const core::Pose stretched = arm.fk(Eigen::VectorXd::Zero(arm.dof()));
  return (stretched.translation() - arm.first_joint_position()).norm();
}

ComfortResult best_comfort(const core::KinematicChain& arm, const core::Pose& hand_in_base,
                           const Eigen::VectorXd& seed_joints, const ComfortSettings& settings) {
  ComfortResult best;
  const double length = characteristic_length(arm);
  std::mt19937_64 rng(settings.seed);
  core::GenericIkSettings ik;
  ik.max_attempts = 1;  // restarts are ours, so that every solution is scored
  ik.position_tolerance = settings.tolerance;
  ik.orientation_tolerance = settings.tolerance;
  ik.hold_joints_at_limits = settings.hold_joints_at_limits;
  int found_at = -1;
  for (int attempt = 0; attempt < settings.ik_attempts; ++attempt) {
    if (found_at >= 0 && settings.attempts_after_found >= 0 &&
        attempt - found_at > settings.attempts_after_found) {
      break;
    }
    const Eigen::VectorXd start = attempt == 0 ? seed_joints : core::random_configuration(arm, rng);
    const core::GenericIkResult r = core::solve_ik(arm, hand_in_base, start, rng, ik);
    if (!r.success) continue;
    const double q = comfort_index(arm.jacobian(r.q), length);
    if (found_at < 0) found_at = attempt;
    if (!best.reachable || q > best.quality) {
      best.reachable = true;
      best.quality = q;
      best.joints = r.q;
    }
  }
  return best;
}

}  // namespace hila::core
