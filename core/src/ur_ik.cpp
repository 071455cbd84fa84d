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
  constexpr double kInvTwoPi = 1.0 / (2.0 * kPi);
  double v = value + two_pi * std::floor((seed - value) * kInvTwoPi + 0.5);
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
    throw InputError(chain.base_link() + " -> " + chain.tip_link(), "dof", "a 6-joint UR chain",
                     std::to_string(chain.dof()) + " joints");
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
    double sn1 = 0.0, c1 = 1.0;
    ::sincos(q1, &sn1, &c1);
    // The joint-2 axis direction v = (s1, -c1, 0) seen from the flange gives the wrist angle in
    // atan2 form (acos near +-1 would lose half the digits at the wrist singularity):
    // cos q5 = a.v, sin q5 = +-|(n.v, o.v)|, and q6 from the direction of (n.v, -o.v).
    const double nv = r(0, 0) * sn1 - r(1, 0) * c1;
    const double ov = r(0, 1) * sn1 - r(1, 1) * c1;
    const double av = r(0, 2) * sn1 - r(1, 2) * c1;
    const double s5abs = std::hypot(nv, ov);
    // Frame 1 in the base: R01 = Rz(q1) Rx(pi/2), origin (0, 0, d1).
    Eigen::Matrix3d r01;
    r01 << c1, 0, sn1, sn1, 0, -c1, 0, 1, 0;
    const Eigen::Matrix3d r10 = r01.transpose();
    const Eigen::Vector3d p1 = r10 * (p - Eigen::Vector3d(0, 0, dh_.d1));
    const Eigen::Matrix3d r16 = r10 * r;
    // Wrist branch s5 = +: q5, q6; branch -: -q5, q6 + pi (the same wrist orientation).
    const double q5_plus = std::atan2(s5abs, av);
    const double q6_plus = s5abs > 1e-12 ? std::atan2(-ov, nv) : seed[5];
    double sn5 = 0.0, c5 = 1.0, sn6 = 0.0, c6 = 1.0;
    ::sincos(q5_plus, &sn5, &c5);
    ::sincos(q6_plus, &sn6, &c6);
    // T46 = Rz(q5) Tz(d5) Rx(-pi/2) Rz(q6) Tz(d6); T14 = T16 * T46^-1.
    Eigen::Matrix3d r46;
    r46 << c5 * c6, -c5 * sn6, -sn5,  //
        sn5 * c6, -sn5 * sn6, c5,     //
        -sn6, -c6, 0;
    const Eigen::Matrix3d r14_plus = r16 * r46.transpose();
    // Joints 2-4 are parallel: R14 = Rz(q2+q3+q4) Rx(pi/2). The flipped wrist negates
    // columns 0 and 2 of R14, i.e. adds pi to q2+q3+q4.
    const double q234_plus = std::atan2(r14_plus(1, 0), r14_plus(0, 0));
    for (int s5 = 0; s5 < 2; ++s5) {
      const bool flipped = s5 == 1;
      const double q5 = flipped ? -q5_plus : q5_plus;
      const double q6 = flipped ? q6_plus + kPi : q6_plus;
      const double q234 = flipped ? q234_plus + kPi : q234_plus;
      // Wrist-1 origin in frame 1: p14 = p16 - R14 * p46, p46 = (-d6 s5, d6 c5, d5). For the
      // flipped wrist R14 = R14+ diag(-1, 1, -1) and s5 changes sign, so only d5 flips.
      const Eigen::Vector3d p46(-dh_.d6 * sn5, dh_.d6 * c5, flipped ? -dh_.d5 : dh_.d5);
      const Eigen::Vector3d p14 = p1 - r14_plus * p46;
      // The planar 2R arm (a2, a3) in frame 1's x-y plane.
      const double px = p14.x();
      const double py = p14.y();
      const double c3 =
          (px * px + py * py - dh_.a2 * dh_.a2 - dh_.a3 * dh_.a3) / (2.0 * dh_.a2 * dh_.a3);
      double q3abs = 0.0;
      if (!safe_acos(c3, q3abs)) continue;
      const double sn3abs = std::sqrt(std::max(0.0, 1.0 - c3 * c3));
      const double k1 = dh_.a2 + dh_.a3 * std::clamp(c3, -1.0, 1.0);
      for (int s3 = 0; s3 < 2; ++s3) {
        const double q3 = s3 == 0 ? q3abs : -q3abs;
        const double k2 = dh_.a3 * (s3 == 0 ? sn3abs : -sn3abs);
        // q2 = atan2(py, px) - atan2(k2, k1) as a single atan2.
        const double q2 = std::atan2(py * k1 - px * k2, px * k1 + py * k2);
        const double q4 = q234 - q2 - q3;
        raw[raw_count++] << q1, q2, q3, q4, q5, q6;
      }
    }
  }

  for (int k = 0; k < raw_count; ++k) {
    Vector6d q;
    bool all_ok = true;
    for (int i = 0; i < 6 && all_ok; ++i)
      q[i] = wrap_near(raw[k][i], seed[i], lower_[i], upper_[i], all_ok);
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
