#pragma once

#include <fcl/math/bv/OBB.h>

#include <cmath>

namespace hila::core {

// The separating-axis inequality of `axis` for boxes p and q: 0-2 p's axes, 3-5 q's, 6-14 their
// cross products, as in fcl::obbDisjoint (rotation magnitudes padded by 1e-6). `t` is q's centre
// in p's frame; `r(i, j)` gives the relative rotation's entry p.axis.col(i) . q.axis.col(j), and
// only the 3 or 4 entries this axis reads are asked for.
template <typename Rotation>
inline bool separates_along(const fcl::OBBd& p, const fcl::OBBd& q, const Eigen::Vector3d& t,
                            const Rotation& r, int axis) {
  const Eigen::Vector3d& a = p.extent;
  const Eigen::Vector3d& b = q.extent;
  const auto pad = [](double v) { return std::abs(v) + 1e-6; };
  if (axis < 3) {
    const double r0 = r(axis, 0);
    const double r1 = r(axis, 1);
    const double r2 = r(axis, 2);
    return std::abs(t[axis]) > a[axis] + pad(r0) * b[0] + pad(r1) * b[1] + pad(r2) * b[2];
  }
  if (axis < 6) {
    const int j = axis - 3;
    const double r0 = r(0, j);
    const double r1 = r(1, j);
    const double r2 = r(2, j);
    return std::abs(r0 * t[0] + r1 * t[1] + r2 * t[2]) >
           b[j] + pad(r0) * a[0] + pad(r1) * a[1] + pad(r2) * a[2];
  }
  // p's axis i crossed with q's axis j.
  const int i = (axis - 6) / 3;
  const int j = (axis - 6) % 3;
  const int i1 = (i + 1) % 3;
  const int i2 = (i + 2) % 3;
  const int j1 = (j + 1) % 3;
  const int j2 = (j + 2) % 3;
  const double r_i1j = r(i1, j);
  const double r_i2j = r(i2, j);
  const double s = t[i2] * r_i1j - t[i1] * r_i2j;
  return std::abs(s) >
         a[i1] * pad(r_i2j) + a[i2] * pad(r_i1j) + b[j1] * pad(r(i, j2)) + b[j2] * pad(r(i, j1));
}

// Whether `axis` separates p and q, computing only the relative rotation's entries that axis
// reads: the cached axis usually separates, and then the rest is never needed.
inline bool axis_separates(const fcl::OBBd& p, const fcl::OBBd& q, const Eigen::Vector3d& t,
                           int axis) {
  return separates_along(
      p, q, t, [&](int i, int j) { return p.axis.col(i).dot(q.axis.col(j)); }, axis);
}

// The separating-axis test of two oriented boxes, as fcl::OBB::overlap computes it (the same
// relative rotation and translation, each of the 15 axes' inequality as in fcl::obbDisjoint),
// but starting with the axis `first` and returning the axis that separated; -1 when none does
// (overlap). The boxes are disjoint exactly when one axis separates, whatever the order, so the
// verdict is FCL's. A motion moves boxes a little between samples: the axis that separated a
// pair last time mostly separates it again, and one inequality replaces up to fifteen.
inline int separating_axis(const fcl::OBBd& p, const fcl::OBBd& q, int first) {
  const Eigen::Vector3d d = q.To - p.To;
  const Eigen::Vector3d t(p.axis.col(0).dot(d), p.axis.col(1).dot(d), p.axis.col(2).dot(d));
  if (first >= 0 && first < 15 && axis_separates(p, q, t, first)) return first;
  const Eigen::Matrix3d r = p.axis.transpose() * q.axis;
  const auto entry = [&r](int i, int j) { return r(i, j); };
  for (int axis = 0; axis < 15; ++axis) {
    if (axis != first && separates_along(p, q, t, entry, axis)) return axis;
  }
  return -1;
}

}  // namespace hila::core
