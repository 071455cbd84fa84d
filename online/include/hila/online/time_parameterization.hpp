#pragma once

#include <Eigen/Core>
#include <vector>

namespace hila::online {

struct TimedPath {
  std::vector<double> time;        // s, from 0
  std::vector<Eigen::VectorXd> q;  // rad
};

// Times a path of straight joint-space segments that stops at every waypoint: along each segment
// a trapezoidal (or triangular) speed profile, synchronised over the joints, that keeps every
// joint within `max_velocity` and `max_acceleration` scaled by `scale` (0, 1]. Each segment is
// sampled `samples_per_segment` times along its profile, so that the trajectory can be played
// back by linear interpolation without exceeding the limits.
TimedPath time_parameterize(const std::vector<Eigen::VectorXd>& path,
                            const Eigen::VectorXd& max_velocity,
                            const Eigen::VectorXd& max_acceleration, double scale = 1.0,
                            int samples_per_segment = 8);

}  // namespace hila::online
