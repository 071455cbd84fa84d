#include "hila/online/time_parameterization.hpp"

#include <algorithm>
#include <cmath>

namespace hila::online {

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

}  // namespace

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
    // The segment's speed and acceleration in its unit parameter: the tightest joint decides.
    double v = std::numeric_limits<double>::infinity();
    double a = std::numeric_limits<double>::infinity();
    for (Eigen::Index j = 0; j < delta.size(); ++j) {
      const double d = std::abs(delta[j]);
      if (d < 1e-12) continue;
      v = std::min(v, scale * max_velocity[j] / d);
      a = std::min(a, scale * max_acceleration[j] / d);
    }
    if (!std::isfinite(v)) continue;  // a repeated waypoint
    const Profile profile(v, a);
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

}  // namespace hila::online
