#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/pose.hpp"

namespace hila::db {

// Plain records as stored in a product database. Poses are in the part frame unless noted.
// Stored as columns (x, y, z, qw, qx, qy, qz) so they read well in the sqlite3 shell.

struct MassProperties {
  double volume = 0.0;                                // m^3
  Eigen::Vector3d com = Eigen::Vector3d::Zero();      // part frame
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about the CoM, part frame, kg m^2
};

struct PartRecord {
  std::int64_t id = 0;  // assigned by the database
  std::string name;
  int assembly_order = 0;
  std::string mesh_file;  // as given in the product file
  std::string mesh_hash;  // SHA-256 of the mesh as loaded (vertices and triangles, metres)
  double mass = 0.0;
  MassProperties mass_properties;
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();  // bounding box size, part frame
  int triangle_count = 0;
  core::Pose target = core::Pose::Identity();   // world (assembly frame applied)
  core::Pose initial = core::Pose::Identity();  // world
};

// A stable placement of the part resting on a horizontal plane (kept for later use).
struct PlacementRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  core::Pose part_in_plane =
      core::Pose::Identity();  // part frame in a plane frame (z up, plane z=0)
  double stability = 0.0;      // distance of the CoM projection to the support polygon's edge, m
};

struct RobotGraspRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  core::Pose tcp = core::Pose::Identity();  // gripper TCP in the part frame
  double jaw_width = 0.0;                   // part width between the contacts, m
  Eigen::Vector3d contact_1 = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_1 = Eigen::Vector3d::Zero();  // outward surface normal
  Eigen::Vector3d contact_2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_2 = Eigen::Vector3d::Zero();
  double quality = 0.0;                   // in [0, 1], higher is better
  double friction_torque_capacity = 0.0;  // N m, both fingers
  double lever = 0.0;                     // distance of the CoM from the grasp axis, m
  double theta_c_deg = 90.0;              // relaxation limit (90 = no constraint)
};

struct SuctionGraspRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  core::Pose cup = core::Pose::Identity();  // cup frame in the part frame (z into the part)
  double rotation_deg = 0.0;                // tool rotation about the face normal
  double force_margin = 0.0;                // max_force - required pull force, N
  double moment_margin = 0.0;               // max_moment - required moment, N m
};

struct HumanGraspRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  core::Pose hand = core::Pose::Identity();  // hand grasp frame in the part frame
  double aperture = 0.0;                     // m
  Eigen::Vector3d contact_1 = Eigen::Vector3d::Zero();
  Eigen::Vector3d contact_2 = Eigen::Vector3d::Zero();
  double quality = 0.0;
  bool one_hand_stable = false;  // false: the part needs two hands (soft-finger check)
};

// Best human comfort Q (paper Eq. 4) over a grid of hand positions x a set of hand orientations,
// for one human arm, in the arm's base frame. Bins the arm never reached hold 0.
struct ComfortMapRecord {
  std::string arm;                                   // human arm name, unique per database
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // grid node (0,0,0), arm base frame, m
  double spacing = 0.0;                              // m between nodes
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();    // nodes per axis
  std::vector<Eigen::Quaterniond> orientations;      // hand orientations (w, x, y, z)
  // dims.prod() * orientations.size() bytes, Q * 255 (0: never reached); node (x, y, z) and
  // orientation o at index ((x * dims.y + y) * dims.z + z) * n_orient + o.
  std::vector<std::uint8_t> values;
  std::int64_t samples = 0;  // forward-kinematics samples used
  std::uint64_t seed = 0;
  double coverage = 0.0;  // share of in-reach bins holding a value
};

// Robot-human handover goals of one board at its assembly stage (paper §IV, §VI-B): the boards
// assembled before it stand at their targets. One row per board.
struct HandoverStageRecord {
  std::int64_t part_id = 0;
  std::vector<std::string> finished_parts;  // in assembly order
  int draws = 0;                            // poses drawn to obtain the candidates
  int candidates = 0;  // poses satisfying Eq. 1 (rotation < 45 deg, offset < 0.5 m, no collision)
  // |S|: above the comfort threshold for the worker each was drawn for (a goal's copy at the
  // grasps a worker takes it naturally at: above comfort_floor; docs/handover.md)
  int comfortable = 0;
  // Candidates the cell's own human takes above the threshold (at the grasps chosen for the
  // worker each was drawn for): without a body set, |S| before the human's IK confirmed any.
  int comfortable_default_body = 0;
  int goals = 0;            // |𝕊|: members of S with a shared or direct grasp
  int robot_handovers = 0;  // feasible robot-robot handover poses
  bool two_hands = false;   // no one-hand human grasp holds the board
  std::string failure;      // empty when goals > 0, else why there is none
};

// A robot-robot handover pose: the right arm holds the board by suction at its centre of mass.
struct RobotHandoverRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  core::Pose board = core::Pose::Identity();  // world
  std::int64_t suction_grasp_id = 0;
  std::string arm;         // the arm holding the suction tool
  Eigen::VectorXd joints;  // its IK solution, rad
};

// A sampled robot-human handover pose (Eq. 1) with its evaluation. Status: "uncomfortable" (not
// in S), "no_shared_grasp" (in S, not in 𝕊: no shared nor direct grasp), "goal" (in 𝕊; rank is
// its Eq. 8 position).
struct HandoverCandidateRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  int sample = 0;                             // index among the Eq. 1 candidates
  core::Pose board = core::Pose::Identity();  // world
  double distance = 0.0;  // Eq. 8: position offset + rotation weight * rotation angle, m
  double quality = 0.0;   // the cell human's best Q (weaker hand for two-hand boards)
  std::string status;
  int rank = -1;                    // 0-based among the goals, -1 for the others
  std::string human_arm;            // arm of the best human grasp ("" when none)
  std::int64_t human_grasp_id = 0;  // 0 when none
  double human_quality = 0.0;       // that hand's Q
  std::string second_arm;           // the other hand for two-hand boards ("" otherwise)
  std::int64_t second_grasp_id = 0;
  double second_quality = 0.0;
  Eigen::VectorXd human_joints;   // goals: best-Q IK of human_arm (empty otherwise), rad
  Eigen::VectorXd second_joints;  // goals of two-hand boards: IK of second_arm
  // Bit i: body i of meta.human_bodies (the build's worker set) takes it above the comfort
  // threshold at these grasps; 0 without a body set.
  std::uint32_t bodies = 0;
};

// A robot grasp valid at both handover poses of a goal (the receiving arm's IK at each): the
// part reaches the human through a robot-robot exchange.
struct SharedGraspRecord {
  std::int64_t id = 0;
  std::int64_t candidate_id = 0;  // a "goal" candidate
  std::int64_t robot_grasp_id = 0;
  std::int64_t robot_handover_id = 0;  // the robot-robot pose it is received at
  std::string arm;                     // the receiving arm
  Eigen::VectorXd joints_rr;           // at the robot-robot pose, rad
  Eigen::VectorXd joints_rh;           // at the robot-human pose, rad
  double inclination_rr_deg = 0.0;     // opening axis vs gravity at each pose (<= theta_c)
  double inclination_rh_deg = 0.0;
};

// A robot grasp with which one arm's gripper takes the part where it lies and holds it at a
// goal's robot-human pose: the part goes to the human without an exchange (schema version 5).
struct DirectGraspRecord {
  std::int64_t id = 0;
  std::int64_t candidate_id = 0;  // a "goal" candidate
  std::int64_t robot_grasp_id = 0;
  std::string arm;                    // the arm that picks and delivers
  Eigen::VectorXd joints_pick;        // at the part's initial pose, rad
  Eigen::VectorXd joints_rh;          // at the robot-human pose, rad
  double inclination_pick_deg = 0.0;  // opening axis vs gravity at each pose (<= theta_c)
  double inclination_rh_deg = 0.0;
};

// A regrasp on the table: the arm's gripper picks the part where it lies with one grasp, sets it
// down at `placement` (another of its resting poses, or the same turned about the vertical), lets
// go, and `repick_arm`'s gripper takes it again with the delivering grasp and holds that at a
// goal's robot-human pose. A relay (repick_arm the other arm, schema version 8): the part is set
// down where both arms reach and the other arm delivers it.
struct TableRegraspRecord {
  std::int64_t id = 0;
  std::int64_t candidate_id = 0;                  // a "goal" candidate
  std::int64_t pick_grasp_id = 0;                 // the grasp the part is picked and set down with
  std::int64_t robot_grasp_id = 0;                // the grasp it is taken again and delivered with
  std::string arm;                                // the arm that picks it and sets it down
  std::string repick_arm;                         // the arm that takes it again and delivers it
  core::Pose placement = core::Pose::Identity();  // the part where it is set down (world)
  Eigen::VectorXd joints_pick;                    // pick_grasp at the part's initial pose, rad
  Eigen::VectorXd joints_place;                   // pick_grasp at the placement
  Eigen::VectorXd joints_repick;                  // robot_grasp at the placement (repick_arm)
  Eigen::VectorXd joints_rh;          // robot_grasp at the robot-human pose (repick_arm)
  double inclination_pick_deg = 0.0;  // opening axis vs gravity at each pose (<= theta_c)
  double inclination_place_deg = 0.0;
  double inclination_repick_deg = 0.0;
  double inclination_rh_deg = 0.0;
};

// A suction delivery (schema version 8): the arm holding the suction tool picks the part by
// suction where it lies (any of its suction grasps the stack allows, chosen online) and presents
// it on its cup at a goal's robot-human pose; the human takes it from the cup. For a part whose
// comfortable goals no gripper serves after an exchange: no exchange, no gripper.
struct SuctionDeliveryRecord {
  std::int64_t id = 0;
  std::int64_t candidate_id = 0;      // a "goal" candidate
  std::int64_t suction_grasp_id = 0;  // the cup on the part
  std::string arm;                    // the arm holding the tool
  Eigen::VectorXd joints_rh;          // at the robot-human pose, rad
};

// One way of getting a board to the human, as the human's body experiences it (the paper's
// Table 2 in numbers). Method: "hila" (the first goal), "table" (laid flat on the table in front
// of the human), "alone" (the human takes it from the stack).
struct ErgonomicsRecord {
  std::int64_t part_id = 0;
  std::string method;
  bool reachable = false;          // some grasp reachable with the torso bent up to its limit
  double torso_flexion_deg = 0.0;  // least forward bend needed
  bool shoulder_elevated = false;  // elbow at or above shoulder height
  double reach = 0.0;              // shoulder to hand, m
  double reorientation_deg = 0.0;  // rotation left to bring the board to its target
  double quality = 0.0;            // comfort Q of the posture
  std::string arm;                 // the human arm used
};

// One arm's joint-space roadmap over the static cell (schema v4). Node i's configuration is
// nodes[i]; edge e joins edges[e].first < edges[e].second.
struct RoadmapRecord {
  std::int64_t id = 0;
  std::string arm;  // unique per database
  int dof = 0;
  double resolution = 0.0;             // joint-space spacing (rad) at which edges were checked
  std::vector<Eigen::VectorXd> nodes;  // each of size dof, rad
  std::vector<Eigen::Vector3d> node_gravity;  // gravity's unit direction in the TCP frame
  std::vector<double> node_inclination_deg;   // gripper opening axis vs gravity, [0, 90]
  std::vector<std::pair<int, int>> edges;
  std::vector<double> edge_length;  // rad
  std::vector<double> edge_max_inclination_deg;
};

// The edges of one arm's roadmap that a held board may use (slip within the grasp's limit and
// the held board clear of the static cell), with connected components over them.
struct RoadmapFilterRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  std::int64_t roadmap_id = 0;
  std::string grasp_kind;  // "gripper" (robot_grasps.id) or "suction" (suction_grasps.id)
  std::int64_t grasp_id = 0;
  double theta_c_deg = 90.0;
  std::vector<bool> edges;     // one per roadmap edge
  std::vector<int> component;  // one per roadmap node: component id >= 0 over the set edges
  int valid_edges = 0;         // number of set bits
  int components = 0;          // number of distinct ids
  int largest_component = 0;   // nodes in the largest
};

// A regrasp-graph node: the board at one pose held (or about to be held) by one arm with one
// grasp, with the arm's collision-free IK solutions. kind: "home" (arm at home, grasp_kind "",
// grasp_id 0), "pick" (board at its initial pose), "robot_handover" (robot_handover_id set),
// "human_handover" (candidate_id set).
struct RegraspNodeRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  std::string kind;
  std::string arm;
  std::string grasp_kind;  // "", "gripper" or "suction"
  std::int64_t grasp_id = 0;
  std::int64_t robot_handover_id = 0;         // 0 unless kind == "robot_handover"
  std::int64_t candidate_id = 0;              // 0 unless kind == "human_handover"
  core::Pose board = core::Pose::Identity();  // world; identity for "home"
  std::vector<Eigen::VectorXd> solutions;     // at least one, each of the arm's dof, rad
};

// A regrasp-graph edge. kind: "transit" (arm moves empty), "transfer" (arm moves holding the
// board; filter_id names the roadmap filter used), "handover" (suction arm -> gripper arm at a
// robot-robot pose; cost 0). cost: joint-space length (rad) of the path found, when connected; 0
// and connected=false otherwise.
struct RegraspEdgeRecord {
  std::int64_t id = 0;
  std::int64_t part_id = 0;
  std::string kind;
  std::string arm;
  std::int64_t from_node = 0;  // regrasp_nodes.id
  std::int64_t to_node = 0;
  std::int64_t filter_id = 0;  // 0 for transit and handover
  bool connected = false;
  double cost = 0.0;
  int path_nodes = 0;  // roadmap nodes on the path (0 when not connected)
  // How the edge was connected: "roadmap" (a shortest path through the filtered roadmap, both
  // ends attached by straight edges), "bridge" (a path planned around a cut in the roadmap by
  // RRT-Connect under the same checks), "" when not connected or for a handover.
  std::string via;
  // The joint-space path from the from-node's first solution to the to-node's first solution,
  // waypoints joined by straight segments (empty when not connected and for a handover; at
  // least 2 waypoints of equal size otherwise).
  std::vector<Eigen::VectorXd> path;
  // Estimated robot time along `path`, s (schema version 9): the path timed as the online
  // planner times a motion (core::time_parameterize_through, not stopping at its waypoints) at
  // the moving arm's velocity and acceleration limits times RegraspSettings::timing_speed_scale.
  // 0 without a path, and in a file migrated from version 8 or earlier (not estimated: the
  // online planner then times `path` itself).
  double duration = 0.0;
};

// Self-description of a database (the `meta` table, one key per field).
struct Meta {
  int schema_version = 0;
  std::string hila_version;
  std::string product_name;
  std::string cell_hash;      // SHA-256 hex of the cell file and the files it references
  std::string product_hash;   // SHA-256 hex of the product file and its meshes
  std::string settings_hash;  // SHA-256 hex of the build settings
  std::uint64_t seed = 0;
  std::string created_at;  // ISO 8601 UTC; excluded from the content digest
  std::string cell_file;
  std::string product_file;
  // The human bodies every handover goal was checked for, "STATURE SEX" joined by "; " (empty:
  // the cell's human only).
  std::string human_bodies;
  // Where the suction tool may stand besides its stand, taken and set down there by every arm
  // (offline::find_tool_relay): the handle's pose (world). None: no place serves, or the build did
  // not look (a file written before hila 0.12, or roles never swapped).
  std::optional<core::Pose> tool_relay;
};

}  // namespace hila::db
