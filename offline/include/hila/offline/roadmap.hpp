#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/bridge.hpp"
#include "hila/core/cell.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/arm_workspace.hpp"

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
  // Each joint's range in the roadmap: within this much of home (and the limits). A UR's +-2 pi
  // joints would otherwise leave the milestones far apart (a roadmap in many components, its
  // edges long); IK solutions are wrapped nearest home, so goals fall inside. A
  // joint limited to less (the elbow, +-pi) keeps its limits (core::joint_box).
  double joint_range = 3.14159265358979323846;
  std::uint64_t seed = 1;
  // The arm that keeps the suction tool in its hand: the tool moves with it in every check.
  std::string suction_arm = "right";
};

// A joint-space roadmap of one arm over the static cell (table, robot body, the other arm at
// home, the human at the stance, the suction tool in the suction arm's hand; see ArmWorkspace),
// built with OMPL's PRM on OMPL's state space and nearest-neighbour structures. Every node and edge
// is collision-free at the resolution; milestones PRM could not connect to any other are left out.
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

// `progress` (optional) is called with the milestone count as PRM grows (every 250).
Roadmap build_roadmap(const core::Cell& cell, const std::string& arm,
                      const RoadmapSettings& settings,
                      const std::function<void(int milestones)>& progress = {});

// The joint box the roadmap samples (core::joint_box).
Eigen::VectorXd roadmap_lower(const core::Arm& arm, const RoadmapSettings& settings);
Eigen::VectorXd roadmap_upper(const core::Arm& arm, const RoadmapSettings& settings);

// The database form (edge gravity samples are not stored: filters are computed offline).
db::RoadmapRecord to_record(const Roadmap& roadmap);

// What a held part needs of the roadmap: the grasp's opening axis and the unit lever from the
// axis to the centre of mass, both in the TCP frame, and its relaxation limit.
struct GraspSlip {
  Eigen::Vector3d axis = Eigen::Vector3d::UnitY();
  Eigen::Vector3d lever = Eigen::Vector3d::Zero();
  double theta_c_deg = 90.0;
};

// The grasp's slip test for a gravity direction in the TCP frame: sin(slip) = |g . (axis x
// lever)| within sin(theta_c) (see core::slip_angle_deg). Built once, one dot product per call.
class SlipTest {
 public:
  explicit SlipTest(const GraspSlip& grasp);
  bool operator()(const Eigen::Vector3d& gravity_in_tcp) const {
    return std::abs(gravity_in_tcp.dot(normal_)) <= limit_;
  }

 private:
  Eigen::Vector3d normal_;
  double limit_;
};

// The roadmap's edges a grasp may use: every sample (both ends and the interior samples) has a
// slip angle (core::slip_angle_deg) within theta_c. One bit per edge.
std::vector<bool> slip_filter(const Roadmap& roadmap, const GraspSlip& grasp);

// Connected-component id per node over the edges whose bit is set (ids 0, 1, ... in order of
// the lowest node of each component).
std::vector<int> connected_components(const Roadmap& roadmap, const std::vector<bool>& edges);

// Of the edges set in `edges` (e.g. a slip_filter), those along which the board the workspace
// holds stays clear of the static cell, at every node and interior sample. Nodes are checked
// once each.
std::vector<bool> held_board_filter(ArmWorkspace& workspace, const Roadmap& roadmap,
                                    std::vector<bool> edges);

struct Attachment {
  int node = -1;
  double cost = 0.0;  // joint-space length of the straight connection, rad
};

// Roadmap nodes among the `k` nearest (joint space) that a straight edge from `q` reaches within
// the grasp's slip limit and valid in the workspace (the arm and, when it holds one, the board)
// at `resolution` (rad; 0: the roadmap's); `q` itself must satisfy both, else none. Nearest
// first.
std::vector<Attachment> attach_configuration(ArmWorkspace& workspace, const Roadmap& roadmap,
                                             const GraspSlip& grasp, const Eigen::VectorXd& q,
                                             int k, double resolution = 0.0);

using core::edge_samples;  // core/bridge.hpp

// Gravity's direction in the TCP frame for arm joints q (world gravity -z), the arm's base
// rotated by `base_rotation` in the world (core::arm_base_in_world, computed once by callers).
Eigen::Vector3d gravity_in_tcp(const core::Arm& arm, const Eigen::Matrix3d& base_rotation,
                               const Eigen::VectorXd& q);

}  // namespace hila::offline
