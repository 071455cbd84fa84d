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
    const Pose before = accumulated * joint.origin * pre;
    fixed_rotation_.push_back(before.linear());
    fixed_translation_.push_back(before.translation());
    accumulated = Pose::Identity();
    accumulated.linear() = a;
    joint_types_.push_back(joint.type == JointType::Prismatic ? JointType::Prismatic
                                                              : JointType::Revolute);
    joint_names_.push_back(joint.name);
    model_variables_.push_back(joint.variable);
    lower.push_back(joint.lower);
    upper.push_back(joint.upper);
  }
  fixed_rotation_.push_back(accumulated.linear());
  fixed_translation_.push_back(accumulated.translation());
  for (Eigen::Matrix3d& r : fixed_rotation_) {
    SignedPermutation sp;
    sp.valid = true;
    for (int j = 0; j < 3 && sp.valid; ++j) {
      int nonzero = 0;
      for (int k = 0; k < 3; ++k) {
        const double v = r(k, j);
        if (std::abs(v) < 1e-12) continue;
        if (std::abs(std::abs(v) - 1.0) > 1e-12) sp.valid = false;
        sp.perm[j] = k;
        sp.sign[j] = v > 0 ? 1.0 : -1.0;
        ++nonzero;
      }
      if (nonzero != 1) sp.valid = false;
    }
    if (sp.valid) {
      // Snap to the exact permutation (URDF rpy round-trips leave 1e-17 residues).
      r.setZero();
      for (int j = 0; j < 3; ++j) r(sp.perm[j], j) = sp.sign[j];
      sp.identity = r == Eigen::Matrix3d::Identity();
    }
    fixed_permutation_.push_back(sp);
  }
  lower_ = Eigen::Map<Eigen::VectorXd>(lower.data(), static_cast<Eigen::Index>(lower.size()));
  upper_ = Eigen::Map<Eigen::VectorXd>(upper.data(), static_cast<Eigen::Index>(upper.size()));
}

bool KinematicChain::within_limits(const Eigen::VectorXd& q, double tolerance) const {
  return q.size() == dof() && (q.array() >= lower_.array() - tolerance).all() &&
         (q.array() <= upper_.array() + tolerance).all();
}

namespace {

// Walks the chain: for each joint i, `visit(i, r, p)` sees the frame of joint i (z = axis)
// before its motion; returns the tip frame in (r, p).
template <typename Perm, typename Visit>
inline void walk_chain(const std::vector<Eigen::Matrix3d>& fixed_r,
                       const std::vector<Eigen::Vector3d>& fixed_p,
                       const std::vector<Perm>& fixed_perm, const std::vector<JointType>& types,
                       const Eigen::VectorXd& q, Eigen::Matrix3d& r, Eigen::Vector3d& p,
                       Visit&& visit) {
  r = fixed_r[0];
  p = fixed_p[0];
  const int n = static_cast<int>(types.size());
  // All sines and cosines first: they are independent, so the CPU overlaps them instead of
  // waiting for each inside the dependent chain of products.
  constexpr int kStack = 16;
  double sin_stack[kStack];
  double cos_stack[kStack];
  std::vector<double> sin_heap;
  std::vector<double> cos_heap;
  double* sines = sin_stack;
  double* cosines = cos_stack;
  if (n > kStack) {
    sin_heap.resize(n);
    cos_heap.resize(n);
    sines = sin_heap.data();
    cosines = cos_heap.data();
  }
  for (int i = 0; i < n; ++i) ::sincos(q[i], &sines[i], &cosines[i]);
  for (int i = 0; i < n; ++i) {
    visit(i, r, p);
    // T <- T * M(q_i) * F_{i+1}; a revolute M = Rz(q) mixes only columns 0 and 1 of R.
    if (types[i] == JointType::Revolute) {
      const double s = sines[i];
      const double c = cosines[i];
      const Eigen::Vector3d x = r.col(0);
      const Eigen::Vector3d y = r.col(1);
      r.col(0) = c * x + s * y;
      r.col(1) = c * y - s * x;
    } else {
      p.noalias() += q[i] * r.col(2);
    }
    p.noalias() += r * fixed_p[i + 1];
    const Perm& sp = fixed_perm[i + 1];
    if (sp.identity) {
      // Parallel consecutive axes (DH alpha = 0): nothing to do.
    } else if (sp.valid) {
      const Eigen::Matrix3d old = r;
      for (int j = 0; j < 3; ++j) r.col(j) = sp.sign[j] * old.col(sp.perm[j]);
    } else {
      const Eigen::Matrix3d next = r * fixed_r[i + 1];
      r = next;
    }
  }
}

}  // namespace

Pose KinematicChain::fk(const Eigen::VectorXd& q) const {
  assert(q.size() == dof());
  Pose tip = Pose::Identity();
  Eigen::Matrix3d r;
  Eigen::Vector3d p;
  walk_chain(fixed_rotation_, fixed_translation_, fixed_permutation_, joint_types_, q, r, p,
             [](int, const Eigen::Matrix3d&, const Eigen::Vector3d&) {});
  tip.linear() = r;
  tip.translation() = p;
  return tip;
}

void KinematicChain::fk_and_jacobian(const Eigen::VectorXd& q, Pose& tip, Jacobian& jac) const {
  assert(q.size() == dof());
  const int n = dof();
  jac.resize(6, n);  // no allocation when it already has n columns (an IK loop's)
  // Each joint's axis goes to the angular rows and its origin, for now, to the linear rows: the
  // linear column needs the tip, known only at the end of the walk.
  Eigen::Matrix3d r;
  Eigen::Vector3d p;
  walk_chain(fixed_rotation_, fixed_translation_, fixed_permutation_, joint_types_, q, r, p,
             [&](int i, const Eigen::Matrix3d& ri, const Eigen::Vector3d& pi) {
               jac.block<3, 1>(3, i) = ri.col(2);
               jac.block<3, 1>(0, i) = pi;
             });
  tip = Pose::Identity();
  tip.linear() = r;
  tip.translation() = p;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d axis = jac.block<3, 1>(3, i);
    if (joint_types_[i] == JointType::Revolute) {
      const Eigen::Vector3d origin = jac.block<3, 1>(0, i);
      jac.block<3, 1>(0, i) = axis.cross(p - origin);
    } else {
      jac.block<3, 1>(0, i) = axis;
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
