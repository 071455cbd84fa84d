#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hila/core/pose.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::core {

using Jacobian = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// The serial chain of a RobotModel between a base link and a tip link (the base must be an
// ancestor of the tip). Fixed joints are folded away and every movable joint is normalised to
// rotate about (or slide along) local z, so forward kinematics is one sin/cos and one rigid
// product per joint. Immutable after construction, so it is safe to share between threads.
class KinematicChain {
 public:
  KinematicChain(const RobotModel& model, const std::string& base_link,
                 const std::string& tip_link);

  int dof() const { return static_cast<int>(joint_types_.size()); }
  const std::string& base_link() const { return base_link_; }
  const std::string& tip_link() const { return tip_link_; }
  const std::vector<std::string>& joint_names() const { return joint_names_; }
  // Index into RobotModel's configuration vector for each chain joint.
  const std::vector<int>& model_variables() const { return model_variables_; }
  const Eigen::VectorXd& lower_limits() const { return lower_; }
  const Eigen::VectorXd& upper_limits() const { return upper_; }
  bool within_limits(const Eigen::VectorXd& q, double tolerance = 0.0) const;
  // Where the first joint's axis passes through, in the base frame (the shoulder of an arm).
  Eigen::Vector3d first_joint_position() const { return fixed_translation_.front(); }

  // Tip pose in the base frame.
  Pose fk(const Eigen::VectorXd& q) const;
  // Geometric Jacobian at the tip origin, rows [linear velocity; angular velocity], base frame.
  Jacobian jacobian(const Eigen::VectorXd& q) const;
  // Both at once (the Jacobian needs the frames anyway).
  void fk_and_jacobian(const Eigen::VectorXd& q, Pose& tip, Jacobian& jac) const;

 private:
  std::string base_link_;
  std::string tip_link_;
  std::vector<std::string> joint_names_;
  std::vector<int> model_variables_;
  std::vector<JointType> joint_types_;
  // fixed_[0] * M(q0) * fixed_[1] * M(q1) * ... * fixed_[n], with M a motion about/along z.
  // Kept as separate rotation/translation so the products inline (Eigen's Transform product
  // does not), which halves the cost of FK.
  std::vector<Eigen::Matrix3d> fixed_rotation_;
  std::vector<Eigen::Vector3d> fixed_translation_;
  // When a fixed rotation is a signed axis permutation (DH alphas of 0 and +-90 degrees), the
  // product with it is a column shuffle: column j of R*F is sign[j] * R.col(perm[j]).
  struct SignedPermutation {
    bool valid = false;
    bool identity = false;
    int perm[3] = {0, 1, 2};
    double sign[3] = {1, 1, 1};
  };
  std::vector<SignedPermutation> fixed_permutation_;
  Eigen::VectorXd lower_;
  Eigen::VectorXd upper_;
};

}  // namespace hila::core
