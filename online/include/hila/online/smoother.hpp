#pragma once

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace hila::online {

struct SmootherSettings {
  double spacing = 0.05;  // rad between the smoothed path's points
  // Over about this length (rad) of path a corner is rounded: the weight pulling each point
  // towards the unsmoothed path, against 1 on its second difference, is (spacing / length)^4.
  double length = 0.5;
  // Where a smoothed segment is invalid, the points around it are pulled back this many times
  // harder in the next round (the unsmoothed path is valid: enough rounds restore it there).
  double pin_growth = 20.0;
  int pin_reach = 3;  // points on each side of an invalid segment pinned with it
  int max_rounds = 6;
};

struct SmoothResult {
  std::vector<Eigen::VectorXd> path;  // the smoothed path, else the input unchanged
  bool smoothed = false;
  int rounds = 0;  // solves (one sparse Cholesky factorisation each)
  int segments_checked = 0;
};

// Smooths a valid joint-space path while keeping it valid: the path is resampled every
// `spacing` and its points minimise the sum of squared second differences (a discrete
// acceleration) plus the weighted squared distance to the resampled path, ends fixed;
// the banded normal equations are factorised with CHOLMOD (SuiteSparse) for all joints at once.
// Every segment of the result is checked with `segment_valid(a, b)` (the planner's collisions,
// slip, joint limits), which must judge b as well as the motion to it: the points are new
// configurations, and a is the start or the previous segment's b. Where one fails, the points
// around it are pinned harder to the original and the system is solved again. When no valid
// smoothing is found within the rounds, or the path has nothing to smooth, the input is returned.
SmoothResult smooth_path(
    const std::vector<Eigen::VectorXd>& path,
    const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& segment_valid,
    const SmootherSettings& settings = {});

}  // namespace hila::online
