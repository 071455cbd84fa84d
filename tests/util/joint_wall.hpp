#pragma once

// A joint-space wall with one gap, shared by the bridge and LazyPRM tests: the straight motion
// is blocked, a detour exists, and a path can be re-checked independently.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "hila/core/cell.hpp"
#include "util/test_util.hpp"

namespace hila::test {

using Validity = std::function<bool(const Eigen::VectorXd&)>;

inline const core::Arm& left_arm() {
  static const auto cell = reference_cell();
  return cell->arm("left");
}

// A wall across joint 0 (|q0 - wall_q0| < half_thickness) for every other joint value, with one
// gap where |q1 - gap_q1| < half_gap: the only way from one side to the other.
struct Wall {
  double wall_q0 = 0.0;
  double half_thickness = 0.15;
  double gap_q1 = 0.0;
  double half_gap = 0.3;

  bool blocked(const Eigen::VectorXd& q) const {
    return std::abs(q[0] - wall_q0) < half_thickness && std::abs(q[1] - gap_q1) >= half_gap;
  }
};

struct Scenario {
  Eigen::VectorXd from, to;
  Wall wall;
};

// From home to home + 1 rad in joint 0, the wall half-way with its gap 1.2 rad off in joint 1,
// so the straight line hits the wall but a detour exists.
inline Scenario wall_scenario() {
  const core::Arm& arm = left_arm();
  Scenario s;
  s.from = arm.spec.home;
  s.to = arm.spec.home;
  s.to[0] += 1.0;
  s.wall.wall_q0 = arm.spec.home[0] + 0.5;
  s.wall.gap_q1 = arm.spec.home[1] + 1.2;
  return s;
}

inline Validity validity_of(const Wall& wall) {
  return [wall](const Eigen::VectorXd& q) { return !wall.blocked(q); };
}

inline bool within_limits(const core::Arm& arm, const Eigen::VectorXd& q) {
  return ((q - arm.chain.lower_limits()).array() >= 0.0).all() &&
         ((arm.chain.upper_limits() - q).array() >= 0.0).all();
}

// Independent re-check: every state on every segment, ends included, at `resolution` / 5.
inline void expect_path_valid(const std::vector<Eigen::VectorXd>& path, const Validity& valid,
                              double resolution) {
  const double step = resolution / 5.0;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::VectorXd& a = path[i];
    const Eigen::VectorXd& b = path[i + 1];
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int k = 0; k <= steps; ++k) {
      const Eigen::VectorXd q = a + (b - a) * (static_cast<double>(k) / steps);
      ASSERT_TRUE(valid(q)) << "segment " << i
                            << " is invalid at t = " << static_cast<double>(k) / steps << ": "
                            << q.transpose();
    }
  }
}

}  // namespace hila::test
