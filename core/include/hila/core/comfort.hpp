#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

// Human comfort of paper Eq. 4: Q = sigma_min / sigma_max of the arm's 6 x n Jacobian. The
// translational rows are divided by a characteristic length L (the arm's reach) so that Q is
// dimensionless and the same for a scaled copy of the arm, as the paper intends. Q in [0, 1].
double comfort_index(const core::Jacobian& jacobian, double characteristic_length);

// The reach used as L: distance from the shoulder to the grasp frame with the arm stretched
// (all joints zero).
double characteristic_length(const core::KinematicChain& arm);

struct ComfortSettings {
  int ik_attempts = 24;  // seeded restarts over the arm's self-motion (7 joints, 6 constraints)
  // Restarts made after the first solution is found; negative: all ik_attempts (the most
  // comfortable posture). A reach check with a good seed needs few.
  int attempts_after_found = -1;
  double tolerance = 1e-10;  // m and rad: the hand pose error a solution may leave
  // GenericIkSettings::hold_joints_at_limits: steps solved over the joints not held at a limit.
  bool hold_joints_at_limits = false;
  std::uint64_t seed = 1;
};

struct ComfortResult {
  bool reachable = false;
  double quality = 0.0;  // best Q over the IK solutions found, 0 when unreachable
  Eigen::VectorXd joints;
};

// The most comfortable way the arm reaches the hand pose (in the arm's base frame): IK from
// `seed_joints` and from seeded random restarts inside the joint limits, keeping the solution with
// the highest Q. The redundancy is searched by the restarts, not analytically.
ComfortResult best_comfort(const core::KinematicChain& arm, const core::Pose& hand_in_base,
                           const Eigen::VectorXd& seed_joints,
                           const ComfortSettings& settings = {});

}  // namespace hila::core
