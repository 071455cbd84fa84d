#include "hila/core/kinematic_chain.hpp"

#include <algorithm>
#include <cmath>

#include "hila/core/error.hpp"

namespace hila::core {

namespace {

// A rotation taking `axis` onto +z.
Eigen::Matrix3d align_to_z(const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond::FromTwoVectors(axis, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// pose := pose * Rz(q), touching only the two affected columns.
inline void post_rotate_z(Pose& pose, double q) {
  const double c = std::cos(q);
  const double s = std::sin(q);
  auto r = pose.linear();
  const Eigen::Vector3d x = r.col(0);
  const Eigen::Vector3d y = r.col(1);
  pose.linear().col(0) = c * x + s * y;
  pose.linear().col(1) = c * y - s * x;
}

inline void post_translate_z(Pose& pose, double q) {
  pose.translation() += q * pose.linear().col(2);
}

}  // namespace

KinematicChain::KinematicChain(const RobotModel& model, const std::string& base_link,
                               const std::string& tip_link)
    : base_link_(base_link), tip_link_(tip_link) {
  const int base = model.link_index(base_link, "chain base link");
  const int tip = model.link_index(tip_link, "chain tip link");
  std::vector<int> path;  // joints from tip up to base
  for (int link = tip; link != base;) {
    const int j = model.links()[link].parent_joint;
    if (j < 0) {
      throw InputError(model.source(), "chain " + base_link + " -> " + tip_link,
                       "a base link that is an ancestor of the tip link",
                       "'" + base_link + "' is not above '" + tip_link + "'");
    }
    path.push_back(j);
    link = model.joints()[j].parent_link;
  }
  std::reverse(path.begin(), path.end());

  Pose accumulated = Pose::Identity();
  std::vector<double> lower;
  std::vector<double> upper;
  for (const int j : path) {
    const Joint& joint = model.joints()[j];
    if (joint.type == JointType::Fixed) {
      accumulated = accumulated * joint.origin;
      continue;
    }
    if (joint.variable < 0) {
      throw InputError(model.source(), "joint '" + joint.name + "'",
                       "an independent joint inside a kinematic chain", "a mimic joint");
    }
    // M_axis(q) = A^T M_z(q) A with A taking the axis to z: fold A^T before and A after.
    const Eigen::Matrix3d a = align_to_z(joint.axis);
    Pose pre = Pose::Identity();
    pre.linear() = a.transpose();
    fixed_.push_back(accumulated * joint.origin * pre);
    accumulated = Pose::Identity();
    accumulated.linear() = a;
    joint_types_.push_back(joint.type == JointType::Prismatic ? JointType::Prismatic
                                                              : JointType::Revolute);
    joint_names_.push_back(joint.name);
    model_variables_.push_back(joint.variable);
    lower.push_back(joint.lower);
    upper.push_back(joint.upper);
  }
  fixed_.push_back(accumulated);
  lower_ = Eigen::Map<Eigen::VectorXd>(lower.data(), static_cast<Eigen::Index>(lower.size()));
  upper_ = Eigen::Map<Eigen::VectorXd>(upper.data(), static_cast<Eigen::Index>(upper.size()));
}

bool KinematicChain::within_limits(const Eigen::VectorXd& q, double tolerance) const {
  return q.size() == dof() && (q.array() >= lower_.array() - tolerance).all() &&
         (q.array() <= upper_.array() + tolerance).all();
}

Pose KinematicChain::fk(const Eigen::VectorXd& q) const {
  assert(q.size() == dof());
  Pose t = fixed_[0];
  for (int i = 0; i < dof(); ++i) {
    if (joint_types_[i] == JointType::Revolute) {
      post_rotate_z(t, q[i]);
    } else {
      post_translate_z(t, q[i]);
    }
    t = t * fixed_[i + 1];
  }
  return t;
}

void KinematicChain::fk_and_jacobian(const Eigen::VectorXd& q, Pose& tip, Jacobian& jac) const {
  assert(q.size() == dof());
  const int n = dof();
  jac.resize(6, n);
  Eigen::Matrix<double, 3, Eigen::Dynamic> axes(3, n);
  Eigen::Matrix<double, 3, Eigen::Dynamic> origins(3, n);
  Pose t = fixed_[0];
  for (int i = 0; i < n; ++i) {
    axes.col(i) = t.linear().col(2);
    origins.col(i) = t.translation();
    if (joint_types_[i] == JointType::Revolute) {
      post_rotate_z(t, q[i]);
    } else {
      post_translate_z(t, q[i]);
    }
    t = t * fixed_[i + 1];
  }
  tip = t;
  for (int i = 0; i < n; ++i) {
    if (joint_types_[i] == JointType::Revolute) {
      jac.block<3, 1>(0, i) = axes.col(i).cross(t.translation() - origins.col(i));
      jac.block<3, 1>(3, i) = axes.col(i);
    } else {
      jac.block<3, 1>(0, i) = axes.col(i);
      jac.block<3, 1>(3, i).setZero();
    }
  }
}

Jacobian KinematicChain::jacobian(const Eigen::VectorXd& q) const {
  Pose tip;
  Jacobian jac;
  fk_and_jacobian(q, tip, jac);
  return jac;
}

}  // namespace hila::core
