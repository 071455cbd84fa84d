#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
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
};

}  // namespace hila::db
