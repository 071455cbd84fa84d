#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "hila/core/cell.hpp"

namespace hila::core {

struct BridgeSettings {
  // Budget in validity checks, not seconds: the same inputs give the same bridge on any machine.
  long max_checks = 40000;
  double resolution = 0.05;  // rad, as the roadmap's edges
  std::uint64_t seed = 1;
  // RRT-Connect's step (rad). OMPL's default, a fifth of the space's extent, is several radians
  // for a UR: in a slip- and clearance-constrained space nearly every such step fails.
  double range = 0.4;
  // Each joint within this much of home (and the limits), as the roadmaps: core::joint_box.
  double joint_range = 3.14159265358979323846;
  // Online queries also stop at a deadline (the check budget keeps offline builds deterministic).
  std::optional<std::chrono::steady_clock::time_point> deadline;
  // Moves a uniform sample onto a constraint the valid states keep (a held board's slip limit,
  // SlipProjection), or rejects it: in a thin constrained set nearly every uniform sample is
  // invalid, and RRT-Connect by rejection alone spends its budget there. Optional.
  std::function<bool(Eigen::VectorXd&)> project;
  // Configurations a share of the samples is drawn around (`focus_fraction`, a Gaussian of
  // `focus_sigma` rad per joint). For an end wedged in by the scene: straight steps from it
  // toward uniform samples mostly fail, though the space right around it is largely free, so
  // its tree stays at its root while the other one spends the budget.
  std::vector<Eigen::VectorXd> focus;
  double focus_fraction = 0.0;
  double focus_sigma = 0.5;
};

// A path from `from` to `to` where every state satisfies `valid`, for where a filtered roadmap
// is cut: OMPL's RRT-Connect (sampling with a seeded generator of its own, so deterministic),
// then greedy straight-line shortcuts. Every segment is re-checked at the resolution. Returns
// the waypoints (from first, to last), or nothing within the budget.
std::vector<Eigen::VectorXd> plan_bridge(const Arm& arm,
                                         const std::function<bool(const Eigen::VectorXd&)>& valid,
                                         const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                         const BridgeSettings& settings);

// The same towards whichever of several ends it reaches first: RRT-Connect with every valid one
// of `targets` a root of its goal tree (invalid ones are skipped), for repairing a blocked
// stored path, where any later waypoint past the blockage will do. The path ends exactly at
// the target it reached; nothing when none is reached within the budget.
std::vector<Eigen::VectorXd> plan_bridge_to_any(
    const Arm& arm, const std::function<bool(const Eigen::VectorXd&)>& valid,
    const Eigen::VectorXd& from, const std::vector<Eigen::VectorXd>& targets,
    const BridgeSettings& settings);

// Greedy straight shortcuts of a path: from each kept waypoint, the farthest later one a straight
// segment reaches, valid at every sample at `resolution` (visited coarse to fine), while `budget`
// lasts (validity checks, spent as they are made; nullptr: no limit). A segment between
// consecutive waypoints is taken as valid, unless `check_kept`: it is then checked too, and
// nothing is returned when it fails.
std::vector<Eigen::VectorXd> shortcut_path(const std::vector<Eigen::VectorXd>& path,
                                           const std::function<bool(const Eigen::VectorXd&)>& valid,
                                           double resolution, long* budget = nullptr,
                                           bool check_kept = false);

// The interior samples of the straight joint-space segment a -> b at `resolution`:
// ceil(|b - a| / resolution) - 1 points, evenly spaced (what roadmaps check and annotate).
std::vector<Eigen::VectorXd> edge_samples(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                          double resolution);

// The interior samples of edge_samples(a, b, resolution) visited coarse to fine (the middle,
// then the quarters, ...) until `visit` returns false: a blocked segment is usually found
// after a few checks rather than at the blocked sample's place in line. Whether every visit
// returned true; `visited` (optional) counts the visits.
bool all_samples_coarse_to_fine(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                double resolution,
                                const std::function<bool(const Eigen::VectorXd&)>& visit,
                                long* visited = nullptr);

// Whether the straight segment a -> b is valid at every interior sample (the ends are assumed
// checked), at the resolution (visited coarse to fine).
bool segment_valid(const std::function<bool(const Eigen::VectorXd&)>& valid,
                   const Eigen::VectorXd& a, const Eigen::VectorXd& b, double resolution);

}  // namespace hila::core
