#include "hila/core/generic_ik.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <vector>

namespace hila::core {

Eigen::Matrix<double, 6, 1> pose_error(const Pose& target, const Pose& current) {
  Eigen::Matrix<double, 6, 1> e;
  e.head<3>() = target.translation() - current.translation();
  const Eigen::AngleAxisd aa(target.linear() * current.linear().transpose());
  e.tail<3>() = aa.angle() * aa.axis();
  return e;
}

Eigen::VectorXd random_configuration(const KinematicChain& chain, std::mt19937_64& rng) {
  Eigen::VectorXd q(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    const double lo = std::max(chain.lower_limits()[i], -kPi);
    const double hi = std::min(chain.upper_limits()[i], kPi);
    q[i] = std::uniform_real_distribution<double>(lo, hi)(rng);
  }
  return q;
}

namespace {

// One Levenberg-Marquardt step dq = J^T (J J^T + lambda I)^-1 e over the task's Rows rows, in
// fixed-size matrices (no allocation in the IK loop); the columns of held joints are left out
// (zeroed in a copy, `free_jac`, only when a joint is held).
template <int Rows>
void lm_step(const Jacobian& jac, const Eigen::Matrix<double, 6, 1>& e, double lambda,
             const std::vector<bool>& held, Jacobian& free_jac, Eigen::VectorXd& dq) {
  const bool any_held = std::find(held.begin(), held.end(), true) != held.end();
  if (any_held) {
    free_jac = jac;
    for (std::size_t i = 0; i < held.size(); ++i) {
      if (held[i]) free_jac.col(static_cast<Eigen::Index>(i)).setZero();
    }
  }
  const auto j = (any_held ? free_jac : jac).topRows<Rows>();
  Eigen::Matrix<double, Rows, Rows> jjt = j * j.transpose();
  jjt.diagonal().array() += lambda;
  const Eigen::Matrix<double, Rows, 1> y = jjt.ldlt().solve(e.head<Rows>());
  dq.noalias() = j.transpose() * y;
}

}  // namespace

GenericIkResult solve_ik(const KinematicChain& chain, const Pose& target,
                         const Eigen::VectorXd& seed, std::mt19937_64& rng,
                         const GenericIkSettings& settings) {
  GenericIkResult result;
  const int rows = settings.position_only ? 3 : 6;
  const int n = chain.dof();
  Pose tip, tip_new;
  Jacobian jac(6, n), jac_new(6, n);
  Jacobian free_jac(6, n);
  Eigen::VectorXd q(n), q_new(n), dq(n);
  std::vector<bool> held(static_cast<std::size_t>(n), false);
  double best_cost = std::numeric_limits<double>::infinity();
  for (int attempt = 0; attempt < settings.max_attempts; ++attempt) {
    ++result.attempts;
    q = (attempt == 0 ? seed : random_configuration(chain, rng))
            .cwiseMax(chain.lower_limits())
            .cwiseMin(chain.upper_limits());
    double lambda = 1e-2;
    chain.fk_and_jacobian(q, tip, jac);
    Eigen::Matrix<double, 6, 1> e = pose_error(target, tip);
    double cost = e.head(rows).squaredNorm();
    for (int it = 0; it < settings.max_iterations; ++it) {
      ++result.iterations;
      if (e.head<3>().norm() < settings.position_tolerance &&
          (settings.position_only || e.tail<3>().norm() < settings.orientation_tolerance)) {
        break;
      }
      const double added = lambda + settings.damping * settings.damping;
      std::fill(held.begin(), held.end(), false);
      // Without holding: one step. Holding: again while the step pushes a joint at a limit out.
      for (int pass = 0; pass <= (settings.hold_joints_at_limits ? n : 0); ++pass) {
        if (settings.position_only) {
          lm_step<3>(jac, e, added, held, free_jac, dq);
        } else {
          lm_step<6>(jac, e, added, held, free_jac, dq);
        }
        bool more = false;
        for (int i = 0; settings.hold_joints_at_limits && i < n; ++i) {
          const auto k = static_cast<std::size_t>(i);
          if (held[k]) continue;
          if ((q[i] <= chain.lower_limits()[i] && dq[i] < 0.0) ||
              (q[i] >= chain.upper_limits()[i] && dq[i] > 0.0)) {
            held[k] = true;
            more = true;
          }
        }
        if (!more) break;
      }
      q_new = (q + dq).cwiseMax(chain.lower_limits()).cwiseMin(chain.upper_limits());
      chain.fk_and_jacobian(q_new, tip_new, jac_new);
      const Eigen::Matrix<double, 6, 1> e_new = pose_error(target, tip_new);
      const double cost_new = e_new.head(rows).squaredNorm();
      if (cost_new < cost) {
        q.swap(q_new);
        tip = tip_new;
        jac.swap(jac_new);
        e = e_new;
        cost = cost_new;
        lambda = std::max(lambda * 0.3, 1e-12);
      } else {
        lambda = std::min(lambda * 10.0, 1e6);
        if (lambda >= 1e6) break;  // stuck in a local minimum or at a limit: restart
      }
    }
    if (cost < best_cost) {
      best_cost = cost;
      result.q = q;
      result.position_error = e.head<3>().norm();
      result.orientation_error = settings.position_only ? 0.0 : e.tail<3>().norm();
    }
    // Converged when within tolerance after the loop's own test.
    if (result.position_error < settings.position_tolerance * 10 &&
        result.orientation_error < settings.orientation_tolerance * 10) {
      result.success = true;
      return result;
    }
  }
  return result;
}

}  // namespace hila::core
