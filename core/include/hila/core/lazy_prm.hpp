#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "hila/core/cell.hpp"

namespace hila::core {

struct LazyPrmSettings {
  double resolution = 0.05;  // rad, segment checks (as the roadmaps')
  // rad, longest roadmap edge: as long as the stored roadmaps' k-nearest edges (a short one
  // leaves a sparse 6-joint roadmap without edges).
  double range = 3.0;
  double joint_range = 3.14159265358979323846;  // core::joint_box
  std::uint64_t seed = 1;
  // The roadmap grows without validity checks (lazily), so a check budget alone does not bound
  // a query: it also stops when the roadmap has grown by this many vertices.
  unsigned long max_vertices = 20000;
};

// OMPL's LazyPRM over one arm's joint box with its roadmap kept between queries: the
// persistent-roadmap baseline the stored, filtered roadmaps are measured against. Each query
// brings its own validity (the scene and the held board change), so every vertex's and edge's
// validity is forgotten between queries while the graph itself grows as queries need. Not
// thread-safe (one per thread).
class LazyPrmPlanner {
 public:
  explicit LazyPrmPlanner(const Arm& arm, const LazyPrmSettings& settings = {});
  ~LazyPrmPlanner();
  LazyPrmPlanner(const LazyPrmPlanner&) = delete;
  LazyPrmPlanner& operator=(const LazyPrmPlanner&) = delete;

  // A path from `from` to `to` (waypoints, straight segments valid at the resolution), or
  // nothing within `max_checks` validity checks or the deadline. Ends outside the joint box
  // give nothing. A query stopped inside LazyPRM's own search loop (out of checks or time)
  // clears the roadmap: OMPL may have left it half-updated.
  std::vector<Eigen::VectorXd> plan(const std::function<bool(const Eigen::VectorXd&)>& valid,
                                    const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                    long max_checks,
                                    std::chrono::steady_clock::time_point deadline);

  std::size_t roadmap_vertices() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hila::core
