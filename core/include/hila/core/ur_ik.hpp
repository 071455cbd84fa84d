#pragma once

#include <Eigen/Core>
#include <array>

#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Denavit–Hartenberg lengths of a Universal Robots arm (alpha = pi/2, 0, 0, pi/2, -pi/2, 0).
struct UrDhParameters {
  double d1 = 0.1519;
  double a2 = -0.24365;
  double a3 = -0.21325;
  double d4 = 0.11235;
  double d5 = 0.08535;
  double d6 = 0.0819;
};

// DH forward kinematics: flange (DH frame 6) in DH frame 0.
Pose ur_dh_fk(const UrDhParameters& dh, const Vector6d& q);

struct UrIkSolutions {
  std::array<Vector6d, 8> q;
  int count = 0;
};

// Closed-form inverse kinematics of a UR arm for the TCP of a KinematicChain. The constructor
// derives the TCP offset from the chain and verifies that the chain's FK equals the DH model
// (throws InputError otherwise), so a wrong URDF or DH table cannot go unnoticed.
class UrIk {
 public:
  UrIk(const KinematicChain& chain, const UrDhParameters& dh);

  // All solutions (up to 8) for the TCP pose in the chain's base frame. Each joint is wrapped by
  // multiples of 2*pi to the value nearest `seed` inside the chain's limits; solutions outside
  // the limits are dropped. Sorted by Euclidean joint distance to `seed`. No allocation.
  int solve(const Pose& tcp, const Vector6d& seed, UrIkSolutions& out) const;

  const UrDhParameters& dh() const { return dh_; }
  const Pose& tool() const { return tool_; }

 private:
  UrDhParameters dh_;
  Pose tool_;  // TCP in the DH flange frame
  Pose tool_inv_;
  Vector6d lower_;
  Vector6d upper_;
};

}  // namespace hila::core
