#include "hila/core/ur_ik.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "hila/core/error.hpp"

namespace hila::core {

namespace {

constexpr double kAlpha[6] = {kPi / 2, 0.0, 0.0, kPi / 2, -kPi / 2, 0.0};
// Tolerance for clamping acos/asin arguments that numerically exceed 1.
constexpr double kClampTolerance = 1e-9;

inline Pose dh_transform(double theta, double d, double a, double alpha) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(alpha), sa = std::sin(alpha);
  Pose t = Pose::Identity();
  t.matrix() << ct, -st * ca, st * sa, a * ct,  //
      st, ct * ca, -ct * sa, a * st,            //
      0, sa, ca, d,                             //
      0, 0, 0, 1;
  return t;
}

std::array<double, 6> d_of(const UrDhParameters& dh) {
  return {dh.d1, 0.0, 0.0, dh.d4, dh.d5, dh.d6};
}
std::array<double, 6> a_of(const UrDhParameters& dh) {
  return {0.0, dh.a2, dh.a3, 0.0, 0.0, 0.0};
}

// Returns false when |x| exceeds 1 by more than the tolerance.
inline bool safe_acos(double x, double& out) {
  if (x > 1.0 + kClampTolerance || x < -1.0 - kClampTolerance) return false;
  out = std::acos(std::clamp(x, -1.0, 1.0));
  return true;
}

inline double wrap_near(double value, double seed, double lo, double hi, bool& ok) {
  // Nearest representative of value + 2*pi*k to seed, then the nearest one inside the limits.
  const double two_pi = 2.0 * kPi;
  double v = value + two_pi * std::round((seed - value) / two_pi);
  if (v >= lo && v <= hi) {
    ok = true;
    return v;
  }
  double best = 0.0;
  double best_dist = std::numeric_limits<double>::infinity();
  for (int k = -2; k <= 2; ++k) {
    const double c = v + two_pi * k;
    if (c >= lo && c <= hi && std::abs(c - seed) < best_dist) {
      best = c;
      best_dist = std::abs(c - seed);
    }
  }
  ok = std::isfinite(best_dist);
  return best;
}

}  // namespace

Pose ur_dh_fk(const UrDhParameters& dh, const Vector6d& q) {
  const auto d = d_of(dh);
  const auto a = a_of(dh);
  Pose t = Pose::Identity();
  for (int i = 0; i < 6; ++i) t = t * dh_transform(q[i], d[i], a[i], kAlpha[i]);
  return t;
}

UrIk::UrIk(const KinematicChain& chain, const UrDhParameters& dh) : dh_(dh) {
  if (chain.dof() != 6) {
    throw InputError(chain.base_link() + " -> " + chain.tip_link(), "dof",
                     "a 6-joint UR chain", std::to_string(chain.dof()) + " joints");
  }
  const Vector6d zero = Vector6d::Zero();
  tool_ = ur_dh_fk(dh_, zero).inverse() * chain.fk(zero);
  tool_inv_ = tool_.inverse();
  lower_ = chain.lower_limits();
  upper_ = chain.upper_limits();
  // The chain must match the DH model everywhere, not just at zero.
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  for (int trial = 0; trial < 16; ++trial) {
    Vector6d q;
    for (int i = 0; i < 6; ++i) q[i] = angle(rng);
    const Pose expected = chain.fk(q);
    const Pose got = ur_dh_fk(dh_, q) * tool_;
    const double err = (expected.matrix() - got.matrix()).cwiseAbs().maxCoeff();
    if (err > 1e-9) {
      throw InputError(chain.base_link() + " -> " + chain.tip_link(), "kinematics",
                       "a URDF chain matching the UR DH parameters (base link = DH frame 0)",
                       "a mismatch of " + format_number(err) + " at a random configuration");
    }
  }
}

int UrIk::solve(const Pose& tcp, const Vector6d& seed, UrIkSolutions& out) const {
  out.count = 0;
  const Pose t06 = tcp * tool_inv_;
  const auto d = d_of(dh_);
  const auto a = a_of(dh_);
  const Eigen::Matrix3d r = t06.linear();
  const Eigen::Vector3d p = t06.translation();

  // theta1: the wrist centre p05 must lie at distance d4 from the base z axis line.
  const Eigen::Vector3d p05 = p - dh_.d6 * r.col(2);
  const double rho = std::hypot(p05.x(), p05.y());
  if (rho < 1e-12) return 0;  // shoulder singularity: theta1 undefined
  double phi = 0.0;
  if (!safe_acos(dh_.d4 / rho, phi)) return 0;
  const double psi = std::atan2(p05.y(), p05.x());
  Vector6d raw[8];
  int raw_count = 0;
  for (int s1 = 0; s1 < 2; ++s1) {
    const double q1 = psi + (s1 == 0 ? phi : -phi) + kPi / 2;
    const double c1 = std::cos(q1), sn1 = std::sin(q1);
    // The joint-2 axis direction v = (s1, -c1, 0) seen from the flange gives the wrist angle in
    // atan2 form (acos near +-1 would lose half the digits at the wrist singularity):
    // cos q5 = a.v, sin q5 = +-|(n.v, o.v)|, and q6 from the direction of (n.v, -o.v).
    const double nv = r(0, 0) * sn1 - r(1, 0) * c1;
    const double ov = r(0, 1) * sn1 - r(1, 1) * c1;
    const double av = r(0, 2) * sn1 - r(1, 2) * c1;
    const double s5abs = std::hypot(nv, ov);
    for (int s5 = 0; s5 < 2; ++s5) {
      const double sign5 = s5 == 0 ? 1.0 : -1.0;
      const double q5 = std::atan2(sign5 * s5abs, av);
      double q6 = 0.0;
      if (s5abs > 1e-12) {
        q6 = std::atan2(-sign5 * ov, sign5 * nv);
      } else {
        q6 = seed[5];  // wrist singularity: q4 and q6 share one rotation; keep the seed's q6
      }
      const Pose t01 = dh_transform(q1, d[0], a[0], kAlpha[0]);
      const Pose t45 = dh_transform(q5, d[4], a[4], kAlpha[4]);
      const Pose t56 = dh_transform(q6, d[5], a[5], kAlpha[5]);
      const Pose t14 = t01.inverse() * t06 * (t45 * t56).inverse();
      const double px = t14.translation().x();
      const double pz = t14.translation().y();  // frame 1's x-y plane holds the planar 2R arm
      const double dist2 = px * px + pz * pz;
      double q3abs = 0.0;
      if (!safe_acos((dist2 - dh_.a2 * dh_.a2 - dh_.a3 * dh_.a3) / (2.0 * dh_.a2 * dh_.a3), q3abs)) {
        continue;
      }
      for (int s3 = 0; s3 < 2; ++s3) {
        const double q3 = s3 == 0 ? q3abs : -q3abs;
        const double q2 = std::atan2(pz, px) -
                          std::atan2(dh_.a3 * std::sin(q3), dh_.a2 + dh_.a3 * std::cos(q3));
        const Pose t12 = dh_transform(q2, d[1], a[1], kAlpha[1]);
        const Pose t23 = dh_transform(q3, d[2], a[2], kAlpha[2]);
        const Pose t34 = (t12 * t23).inverse() * t14;
        const double q4 = std::atan2(t34.linear()(1, 0), t34.linear()(0, 0));
        raw[raw_count++] << q1, q2, q3, q4, q5, q6;
      }
    }
  }

  for (int k = 0; k < raw_count; ++k) {
    Vector6d q;
    bool all_ok = true;
    for (int i = 0; i < 6 && all_ok; ++i) q[i] = wrap_near(raw[k][i], seed[i], lower_[i], upper_[i], all_ok);
    if (!all_ok) continue;
    bool duplicate = false;
    for (int m = 0; m < out.count && !duplicate; ++m) {
      duplicate = (out.q[m] - q).cwiseAbs().maxCoeff() < 1e-9;
    }
    if (!duplicate) out.q[out.count++] = q;
  }
  std::sort(out.q.begin(), out.q.begin() + out.count, [&](const Vector6d& x, const Vector6d& y) {
    return (x - seed).squaredNorm() < (y - seed).squaredNorm();
  });
  return out.count;
}

}  // namespace hila::core
