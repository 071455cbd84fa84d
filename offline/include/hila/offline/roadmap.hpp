#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"

namespace hila::offline {

struct RoadmapSettings {
  int nodes = 3000;     // milestones
  int neighbours = 15;  // PRM's k nearest neighbours tried per milestone
  // Share of samples drawn in the slip-constrained region: gripper poses whose opening axis lies
  // within `vertical_cone_deg` of vertical (by analytic IK), the rest uniform in joint space.
  double slip_bias = 0.8;
  double vertical_cone_deg = 10.0;
  // Edges are checked (collision) and annotated (inclination) at most this far apart in joint
  // space (rad, Euclidean over the six joints).
  double resolution = 0.05;
  std::uint64_t seed = 1;
};

// A joint-space roadmap of one arm over the static cell (table, robot body, the other arm at
// home, the human at the stance), built with OMPL's PRM on OMPL's state space and
// nearest-neighbour structures. Every node and edge is collision-free at the resolution;
// milestones PRM could not connect to any other are left out.
struct Roadmap {
  std::string arm;
  int dof = 0;
  double resolution = 0.0;
  std::vector<Eigen::VectorXd> nodes;
  // Gravity's direction in the TCP frame at each node; the axis inclination follows from it for
  // any opening axis, and the slip angle of any grasp (see core::slip_angle_deg).
  std::vector<Eigen::Vector3d> node_gravity;
  std::vector<double> node_inclination_deg;  // the gripper's opening axis vs gravity, [0, 90]
  std::vector<std::pair<int, int>> edges;
  std::vector<double> edge_length;               // joint-space Euclidean length, rad
  std::vector<double> edge_max_inclination_deg;  // largest over the edge's samples
  // Gravity in the TCP frame at the edge's interior samples (ends excluded: they are nodes).
  std::vector<std::vector<Eigen::Vector3d>> edge_gravity;
  double seconds = 0.0;
};

Roadmap build_roadmap(const core::Cell& cell, const std::string& arm,
                      const RoadmapSettings& settings);

// What a held part needs of the roadmap: the grasp's opening axis and the unit lever from the
// axis to the centre of mass, both in the TCP frame, and its relaxation limit.
struct GraspSlip {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d lever = Eigen::Vector3d::Zero();
  double theta_c_deg = 90.0;
};

// The roadmap's edges a grasp may use: every sample (both ends and the interior samples) has a
// slip angle (core::slip_angle_deg) within theta_c. One bit per edge.
std::vector<bool> slip_filter(const Roadmap& roadmap, const GraspSlip& grasp);

// Connected-component id per node over the edges whose bit is set (ids 0, 1, ... in order of
// the lowest node of each component).
std::vector<int> connected_components(const Roadmap& roadmap, const std::vector<bool>& edges);

// Roadmap nodes among the `k` nearest (joint space) that a straight edge from `q` reaches
// collision-free against the static cell and within the grasp's slip limit at the roadmap's
// resolution; `q` itself must satisfy both, else none. (The held part is not checked yet.)
std::vector<int> attach_configuration(const core::Cell& cell, const Roadmap& roadmap,
                                      const GraspSlip& grasp, const Eigen::VectorXd& q, int k);

// The interior samples of the straight joint-space segment a -> b at `resolution` (what the
// roadmap checks and annotates): ceil(|b - a| / resolution) - 1 points, evenly spaced.
std::vector<Eigen::VectorXd> edge_samples(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                          double resolution);

// Gravity's direction in the TCP frame for arm joints q (world gravity -z), the arm's base
// rotated by `base_rotation` in the world (core::arm_base_in_world, computed once by callers).
Eigen::Vector3d gravity_in_tcp(const core::Arm& arm, const Eigen::Matrix3d& base_rotation,
                               const Eigen::VectorXd& q);

}  // namespace hila::offline
