#include "hila/core/time_parameterization.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace hila::core {

namespace {

// Rest-to-rest profile over a unit path parameter s in [0, 1] with peak speed v and
// acceleration a (in s per second): its duration and s at time t.
struct Profile {
  double v = 0.0;
  double a = 0.0;
  double ramp = 0.0;  // time accelerating
  double duration = 0.0;

  Profile(double v_max, double a_max) : v(v_max), a(a_max) {
    if (v * v / a >= 1.0) {  // triangular: the peak speed is never reached
      ramp = std::sqrt(1.0 / a);
      v = a * ramp;
      duration = 2.0 * ramp;
    } else {
      ramp = v / a;
      duration = 1.0 / v + ramp;
    }
  }
  double at(double t) const {
    if (t <= ramp) return 0.5 * a * t * t;
    if (t >= duration - ramp) {
      const double r = duration - t;
      return 1.0 - 0.5 * a * r * r;
    }
    return 0.5 * a * ramp * ramp + v * (t - ramp);
  }
};

// The profile of a straight segment `delta` (rad): its speed and acceleration in the unit
// parameter, the tightest joint deciding; none for a repeated waypoint.
std::optional<Profile> segment_profile(const Eigen::VectorXd& delta,
                                       const Eigen::VectorXd& max_velocity,
                                       const Eigen::VectorXd& max_acceleration, double scale) {
  double v = std::numeric_limits<double>::infinity();
  double a = std::numeric_limits<double>::infinity();
  for (Eigen::Index j = 0; j < delta.size(); ++j) {
    const double d = std::abs(delta[j]);
    if (d < 1e-12) continue;
    v = std::min(v, scale * max_velocity[j] / d);
    a = std::min(a, scale * max_acceleration[j] / d);
  }
  if (!std::isfinite(v)) return std::nullopt;
  return Profile(v, a);
}

}  // namespace

double rest_to_rest_duration(const std::vector<Eigen::VectorXd>& path,
                             const Eigen::VectorXd& max_velocity,
                             const Eigen::VectorXd& max_acceleration, double scale) {
  double total = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const auto segment =
        segment_profile(path[i] - path[i - 1], max_velocity, max_acceleration, scale);
    if (segment) total += segment->duration;
  }
  return total;
}

TimedPath time_parameterize(const std::vector<Eigen::VectorXd>& path,
                            const Eigen::VectorXd& max_velocity,
                            const Eigen::VectorXd& max_acceleration, double scale,
                            int samples_per_segment) {
  TimedPath out;
  if (path.empty()) return out;
  out.time.push_back(0.0);
  out.q.push_back(path.front());
  double t0 = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    const Eigen::VectorXd delta = path[i] - path[i - 1];
    const auto segment = segment_profile(delta, max_velocity, max_acceleration, scale);
    if (!segment) continue;  // a repeated waypoint
    const Profile& profile = *segment;
    for (int k = 1; k <= samples_per_segment; ++k) {
      const double t = profile.duration * static_cast<double>(k) / samples_per_segment;
      out.time.push_back(t0 + t);
      out.q.push_back(k == samples_per_segment
                          ? path[i]
                          : Eigen::VectorXd(path[i - 1] + profile.at(t) * delta));
    }
    t0 += profile.duration;
  }
  return out;
}

namespace {

// The pieces of a path with their directions, lengths and speed limits.
struct Pieces {
  std::vector<Eigen::VectorXd> points;  // waypoints, consecutive ones distinct
  std::vector<Eigen::VectorXd> unit;    // direction of piece i (points[i] -> points[i + 1])
  std::vector<double> length;
  std::vector<double> top_speed;  // the velocity limit along the piece
};

Pieces split(const std::vector<Eigen::VectorXd>& path, const Eigen::VectorXd& vmax,
             double max_step) {
  Pieces p;
  p.points = resample_path(path, max_step);
  for (std::size_t i = 0; i + 1 < p.points.size(); ++i) {
    const Eigen::VectorXd delta = p.points[i + 1] - p.points[i];
    const double l = delta.norm();
    p.length.push_back(l);
    p.unit.push_back(delta / l);
    double top = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < delta.size(); ++j) {
      const double u = std::abs(p.unit.back()[j]);
      if (u > 1e-12) top = std::min(top, vmax[j] / u);
    }
    p.top_speed.push_back(top);
  }
  return p;
}

// How far piece `b` at speed sb after piece `a` at speed sa exceeds the acceleration limit: the
// largest ratio over the joints of |v_b - v_a| to amax * (t_a + t_b) / 2 (<= 1 holds). A piece
// index of -1 is the robot at rest (no duration).
double accel_ratio(const Pieces& p, const Eigen::VectorXd& amax, int a, double sa, int b,
                   double sb) {
  const double ta = a < 0 ? 0.0 : p.length[static_cast<std::size_t>(a)] / sa;
  const double tb = b < 0 ? 0.0 : p.length[static_cast<std::size_t>(b)] / sb;
  const double mean = 0.5 * (ta + tb);
  double worst = 0.0;
  for (Eigen::Index j = 0; j < amax.size(); ++j) {
    const double va = a < 0 ? 0.0 : sa * p.unit[static_cast<std::size_t>(a)][j];
    const double vb = b < 0 ? 0.0 : sb * p.unit[static_cast<std::size_t>(b)][j];
    worst = std::max(worst, std::abs(vb - va) / (amax[j] * mean));
  }
  return worst;
}

// accel_ratio(p, amax, a, sa, b, sb) <= 1, without the divisions and stopping at the first joint
// over its limit: the passes below ask this hundreds of times per piece.
bool accel_within(const Pieces& p, const Eigen::VectorXd& amax, int a, double sa, int b,
                  double sb) {
  const double ta = a < 0 ? 0.0 : p.length[static_cast<std::size_t>(a)] / sa;
  const double tb = b < 0 ? 0.0 : p.length[static_cast<std::size_t>(b)] / sb;
  const double mean = 0.5 * (ta + tb);
  const double* ua = a < 0 ? nullptr : p.unit[static_cast<std::size_t>(a)].data();
  const double* ub = b < 0 ? nullptr : p.unit[static_cast<std::size_t>(b)].data();
  for (Eigen::Index j = 0; j < amax.size(); ++j) {
    const double va = ua == nullptr ? 0.0 : sa * ua[j];
    const double vb = ub == nullptr ? 0.0 : sb * ub[j];
    if (std::abs(vb - va) > amax[j] * mean) return false;
  }
  return true;
}

// The largest speed of piece `next` (up to its cap) reachable from piece `prev` at `speed`.
double reachable(const Pieces& p, const Eigen::VectorXd& amax, int prev, double speed, int next,
                 double cap) {
  auto ok = [&](double s) { return accel_within(p, amax, prev, speed, next, s); };
  if (ok(cap)) return cap;
  // The feasible speeds are those near `speed` and, apart from them, tiny ones (a piece that
  // lasts long enough averages any jump away): step down from the cap to the first feasible
  // speed, then refine between it and the step above, so the upper interval is found.
  // Holding the previous speed is feasible unless the direction turns: then the bracket is
  // between it and the cap.
  double hi = cap;
  double lo = speed > 0.0 && speed < cap ? speed : 0.8 * cap;
  while (lo > 1e-9 * cap && !ok(lo)) {
    hi = lo;
    lo *= 0.95;
  }
  if (!ok(lo)) return lo;  // not reached: a tiny speed is always feasible
  for (int it = 0; it < 30; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (ok(mid)) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  return lo;
}

}  // namespace

std::vector<Eigen::VectorXd> resample_path(const std::vector<Eigen::VectorXd>& path,
                                           double max_step) {
  std::vector<Eigen::VectorXd> out;
  for (const auto& q : path) {
    if (!out.empty() && (q - out.back()).norm() <= 1e-12) continue;
    if (!out.empty()) {
      const Eigen::VectorXd from = out.back();
      const int n = std::max(1, static_cast<int>(std::ceil((q - from).norm() / max_step)));
      for (int k = 1; k < n; ++k) out.push_back(from + (static_cast<double>(k) / n) * (q - from));
    }
    out.push_back(q);
  }
  return out;
}

TimedPath time_parameterize_through(const std::vector<Eigen::VectorXd>& path,
                                    const Eigen::VectorXd& max_velocity,
                                    const Eigen::VectorXd& max_acceleration, double scale,
                                    double max_step) {
  TimedPath out;
  if (path.empty()) return out;
  const Eigen::VectorXd vmax = scale * max_velocity;
  const Eigen::VectorXd amax = scale * max_acceleration;
  const Pieces p = split(path, vmax, max_step);
  const int n = static_cast<int>(p.length.size());
  out.time.push_back(0.0);
  out.q.push_back(p.points.front());
  if (n == 0) return out;
  // Each piece's cap: its velocity limit, and the speed at which it can be held through the
  // turns at its two ends (equal speeds on both sides of a turn by |du| need
  // s^2 <= amax (L_a + L_b) / (2 |du|) in every joint). Without it a greedy pass could reach a
  // speed from which only a near stop is feasible at the next turn.
  std::vector<double> cap = p.top_speed;
  for (int i = 1; i < n; ++i) {
    const auto a = static_cast<std::size_t>(i - 1);
    const auto b = static_cast<std::size_t>(i);
    const Eigen::VectorXd turn = p.unit[b] - p.unit[a];
    double hold = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < turn.size(); ++j) {
      const double du = std::abs(turn[j]);
      if (du > 1e-12) {
        hold = std::min(hold, std::sqrt(amax[j] * (p.length[a] + p.length[b]) / (2.0 * du)));
      }
    }
    cap[a] = std::min(cap[a], hold);
    cap[b] = std::min(cap[b], hold);
  }
  // Backward from rest at the end (the fastest speeds from which every later cap can still be
  // kept), then forward from rest under those bounds.
  std::vector<double> backward(static_cast<std::size_t>(n));
  for (int i = n - 1; i >= 0; --i) {
    const double next = i == n - 1 ? 0.0 : backward[static_cast<std::size_t>(i + 1)];
    const double own = cap[static_cast<std::size_t>(i)];
    // Only braking is this pass's job (reversed in time, an acceleration out of the next
    // piece); speeding up to a faster next piece is left to the forward pass.
    backward[static_cast<std::size_t>(i)] =
        own <= next ? own : reachable(p, amax, i + 1 < n ? i + 1 : -1, next, i, own);
  }
  std::vector<double> speed(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double previous = i == 0 ? 0.0 : speed[static_cast<std::size_t>(i - 1)];
    const double bound = backward[static_cast<std::size_t>(i)];
    // Braking to the bound was planned backward (the previous piece is at most its own
    // bound, which brakes into this one within limits).
    speed[static_cast<std::size_t>(i)] =
        bound <= previous ? bound : reachable(p, amax, i - 1, previous, i, bound);
  }
  // The forward pass keeps each pair with its predecessor; a piece held below its backward
  // bound may still brake too hard into the next. Bring the faster of any violating pair
  // towards the slower (equal speeds under the caps are always feasible).
  // A pair found within limits stays so until one of its speeds changes: only pairs next to a
  // changed speed are checked again (the same sweeps, the same changes, in the same order).
  std::vector<char> unchecked(static_cast<std::size_t>(n) + 1, 1);  // pair i: pieces i - 1, i
  for (int sweep = 0; sweep < 200; ++sweep) {
    bool changed = false;
    for (int i = 0; i <= n; ++i) {
      if (!unchecked[static_cast<std::size_t>(i)]) continue;
      const int a = i - 1;
      const int b = i < n ? i : -1;
      const double sa = a < 0 ? 0.0 : speed[static_cast<std::size_t>(a)];
      const double sb = b < 0 ? 0.0 : speed[static_cast<std::size_t>(b)];
      if (accel_within(p, amax, a, sa, b, sb)) {
        unchecked[static_cast<std::size_t>(i)] = 0;
        continue;
      }
      const bool a_faster = b < 0 || (a >= 0 && sa > sb);
      const int piece = a_faster ? a : b;
      double& faster = speed[static_cast<std::size_t>(piece)];
      faster = std::max(a_faster ? sb : sa, 0.9 * faster);
      if (faster <= 0.0) faster = 1e-6;
      unchecked[static_cast<std::size_t>(piece)] = 1;
      unchecked[static_cast<std::size_t>(piece) + 1] = 1;
      changed = true;
    }
    if (!changed) break;
  }
  // Whatever is left (never seen in practice): slowing everything by c scales every
  // acceleration ratio by c^2.
  double worst = 0.0;
  for (int i = 0; i <= n; ++i) {
    const int a = i - 1;
    const int b = i < n ? i : -1;
    worst =
        std::max(worst, accel_ratio(p, amax, a, a < 0 ? 0.0 : speed[static_cast<std::size_t>(a)], b,
                                    b < 0 ? 0.0 : speed[static_cast<std::size_t>(b)]));
  }
  if (worst > 1.0) {
    for (double& s : speed) s /= std::sqrt(worst) * 1.0001;
  }
  for (int i = 0; i < n; ++i) {
    out.time.push_back(out.time.back() +
                       p.length[static_cast<std::size_t>(i)] / speed[static_cast<std::size_t>(i)]);
    out.q.push_back(p.points[static_cast<std::size_t>(i + 1)]);
  }
  return out;
}

}  // namespace hila::core
