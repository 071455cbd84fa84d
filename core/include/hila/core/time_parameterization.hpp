#pragma once

#include <Eigen/Core>
#include <vector>

namespace hila::core {

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

// The duration (s) of time_parameterize's timing of `path` (rest to rest at every waypoint)
// without sampling it: an upper bound of the time the robot takes along the path, cheap enough
// to estimate a motion before it is planned (the straight move between two configurations).
double rest_to_rest_duration(const std::vector<Eigen::VectorXd>& path,
                             const Eigen::VectorXd& max_velocity,
                             const Eigen::VectorXd& max_acceleration, double scale = 1.0);

// The path's points with every segment split evenly into pieces no longer than `max_step`
// (rad), repeated waypoints dropped: what the smoother and time_parameterize_through work on.
std::vector<Eigen::VectorXd> resample_path(const std::vector<Eigen::VectorXd>& path,
                                           double max_step);

// Times a path without stopping at its waypoints (a smoothed path's dense waypoints): the path is
// split into pieces no longer than `max_step` (rad), each traversed at a constant speed, and
// the speeds are the largest that keep, as the validator measures them, every joint's velocity
// on each piece and its acceleration between consecutive pieces (their velocity difference over
// the mean of their durations) within the scaled limits, starting from rest and coming to
// rest (a virtual piece at zero speed before the first and after the last). A forward and a
// backward pass bound the speeds; where the two bounds meet, speeds are lowered until every
// limit holds. Repeated waypoints are dropped.
TimedPath time_parameterize_through(const std::vector<Eigen::VectorXd>& path,
                                    const Eigen::VectorXd& max_velocity,
                                    const Eigen::VectorXd& max_acceleration, double scale = 1.0,
                                    double max_step = 0.05);

}  // namespace hila::core
