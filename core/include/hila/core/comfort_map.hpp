#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

// `count` rotations spread evenly over SO(3) (super-Fibonacci spirals, Alexa 2022): deterministic,
// no clustering at the poles as with Euler-angle grids.
std::vector<Eigen::Quaterniond> spread_orientations(int count);

// Index of the rotation of `set` closest to `rotation` (largest |<q, q_i>|).
int nearest_orientation(const std::vector<Eigen::Quaterniond>& set,
                        const Eigen::Quaterniond& rotation);

struct ComfortMapSettings {
  double spacing = 0.03;     // m between grid nodes (issue: at most 3 cm)
  int orientations = 128;    // hand orientations per node (issue: at least 100)
  long samples = 3'000'000;  // forward-kinematics samples of the arm's joint space
  std::uint64_t seed = 1;
};

// Best comfort Q (paper Eq. 4) per hand position x orientation, for one human arm, in the arm's
// base frame: built offline, stored in the database, looked up by the build's handover search and
// by the online planner for the human standing where the scene says. Built by forward sampling: random joint configurations inside the limits, their
// hand pose binned to the nearest grid node and nearest orientation, each bin keeping the best Q
// seen. Q is stored in 1/255 steps (one byte per bin). Lookups interpolate trilinearly between
// the eight nodes around the position at the nearest orientation; bins never reached hold 0.
// Exact nearest-orientation queries over a fixed set in a few dot products: the unit
// quaternions (sign-folded) are split into the cells of a cube-face grid, each cell listing the
// members that can be nearest to some rotation inside it (by the triangle inequality of the
// rotation metric acos|<p, q>|). Same answers as nearest_orientation, ties included.
class OrientationIndex {
 public:
  OrientationIndex() = default;
  explicit OrientationIndex(const std::vector<Eigen::Quaterniond>& set, int cells_per_axis = 16);
  int nearest(const Eigen::Quaterniond& rotation) const;
  double mean_candidates() const;

 private:
  std::vector<Eigen::Vector4d> set_;  // (w, x, y, z)
  int n_ = 0;
  std::vector<int> offsets_;     // per cell, into candidates_ (one extra at the end)
  std::vector<int> candidates_;  // ascending per cell
  std::vector<int> unique_;      // per cell: the only candidate, or -1
};

class ComfortMap {
 public:
  static ComfortMap build(const core::KinematicChain& arm, const ComfortMapSettings& settings);
  // A map from its grid and its bins in node-major order, the database's
  // (((x * dims.y + y) * dims.z + z) * orientations + o), as values() returns them.
  static ComfortMap from_grid(const Eigen::Vector3d& origin, double spacing,
                              const Eigen::Vector3i& dims,
                              std::vector<Eigen::Quaterniond> orientations,
                              const std::vector<std::uint8_t>& node_major_values,
                              double coverage);

  double lookup(const core::Pose& hand_in_base) const;
  // Index of the map's orientation nearest to `rotation`.
  int nearest_orientation(const Eigen::Quaterniond& rotation) const {
    return orientation_index_.nearest(rotation);
  }
  // The stored value of one bin (no interpolation).
  double bin(const Eigen::Vector3i& node, int orientation) const;
  // The grid node nearest to a position (clamped to the grid).
  Eigen::Vector3i nearest_node(const Eigen::Vector3d& position) const;
  Eigen::Vector3d node_position(const Eigen::Vector3i& node) const;

  // Share of bins within the arm's reach sphere that hold a value.
  double coverage() const { return coverage_; }
  const Eigen::Vector3i& dims() const { return dims_; }
  const std::vector<Eigen::Quaterniond>& orientations() const { return orientations_; }
  // The bins in the database's order (a copy; see db::ComfortMapRecord::values).
  std::vector<std::uint8_t> values() const;
  long filled_bins() const;
  double spacing() const { return spacing_; }
  const Eigen::Vector3d& origin() const { return origin_; }

 private:
  std::size_t index(const Eigen::Vector3i& node, int orientation) const;

  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // position of node (0, 0, 0)
  double spacing_ = 0.03;
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<Eigen::Quaterniond> orientations_;
  OrientationIndex orientation_index_;
  // Orientation-major in memory ((o * X + x) * Y + y) * Z + z, so the eight nodes a lookup
  // interpolates share two to four cache lines; the database keeps node-major order.
  std::vector<std::uint8_t> values_;
  double coverage_ = 0.0;
};

// Q from the Jacobian through the eigenvalues of J J^T (6 x 6), cheaper than an SVD of J; equals
// comfort_index(J, length).
double comfort_index_fast(const core::Jacobian& jacobian, double characteristic_length);

}  // namespace hila::core
