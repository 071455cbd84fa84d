#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>

#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

struct GenericIkSettings {
  int max_iterations = 150;              // per attempt
  int max_attempts = 20;                 // the seed first, then random restarts inside the limits
  double position_tolerance = 1e-10;     // m
  double orientation_tolerance = 1e-10;  // rad
  double damping = 1e-6;       // added to the LM lambda (keeps steps bounded near singularities)
  bool position_only = false;  // ignore orientation (reaching tasks)
  // A joint at a limit whose step would push it past the limit is held there for that step, the
  // step solved again over the others (an active set), instead of the step being clipped: the
  // clipped step leaves the other joints' share unsolved, and the iterate crawls along the limit
  // for tens of iterations. false: clipped steps only.
  bool hold_joints_at_limits = false;
};

struct GenericIkResult {
  bool success = false;
  Eigen::VectorXd q;
  double position_error = 0.0;
  double orientation_error = 0.0;
  int attempts = 0;
  int iterations = 0;
};

// Pose error [p_target - p; log(R_target R^T)] in the base frame.
Eigen::Matrix<double, 6, 1> pose_error(const Pose& target, const Pose& current);

// Levenberg–Marquardt IK for any KinematicChain, respecting joint limits by projection, with
// random restarts drawn from `rng` (deterministic for a fixed seed).
GenericIkResult solve_ik(const KinematicChain& chain, const Pose& target,
                         const Eigen::VectorXd& seed, std::mt19937_64& rng,
                         const GenericIkSettings& settings = {});

// A uniformly random configuration inside the chain's limits (limits wider than +-pi are sampled
// in +-pi, which covers every pose).
Eigen::VectorXd random_configuration(const KinematicChain& chain, std::mt19937_64& rng);

}  // namespace hila::core
