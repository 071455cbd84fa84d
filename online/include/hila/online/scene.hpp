#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/product.hpp"

namespace hila::online {

// An obstacle the cameras report that the cell file does not know: a box or a mesh.
struct SceneObstacle {
  std::string name;
  core::Pose pose = core::Pose::Identity();            // world
  Eigen::Vector3d box_size = Eigen::Vector3d::Zero();  // a box when no mesh is given
  std::string mesh_file;                               // resolved path; empty for a box
  core::TriangleMesh mesh;                             // loaded, metres
  bool is_box() const { return mesh_file.empty(); }
};

// A board already assembled, where it actually stands.
struct FinishedBoard {
  std::string name;
  core::Pose pose = core::Pose::Identity();  // world
};

// The cell as it is when the planner is asked (docs/scene.md). Everything not given takes its
// nominal value from the product and the cell files.
struct Scene {
  std::string file;
  std::string product;  // the product's name: must match the database
  // Detected initial poses (world) of the boards still to be handled; others stay nominal.
  std::map<std::string, core::Pose> detected;
  core::Pose tool = core::Pose::Identity();  // the suction tool's handle (world) when on the table
  bool tool_in_hand = false;                 // an arm already holds it: tool_arm
  std::string tool_arm = "right";            // the arm holding it when tool_in_hand
  core::Pose assembly_frame = core::Pose::Identity();  // where the assembly stands (world)
  std::vector<FinishedBoard> finished;                 // in assembly order
  core::Pose human_stance = core::Pose::Identity();
  // The worker who is there (`worker:`): a body of `hila human` standing at human_stance, for
  // which the goals' comfort, reach and posture are evaluated; nullptr: the cell's own human.
  // Built with core::HumanBody(cell, spec), once per scene file; shared by the scenes that
  // follow from it (with_finished).
  std::shared_ptr<const core::HumanBody> worker;
  std::vector<SceneObstacle> obstacles;
  std::map<std::string, Eigen::VectorXd> robot;  // arm name -> current joints (every arm)

  bool is_finished(const std::string& board) const;
  // The board's pose on the table: detected, else the product's nominal initial pose.
  core::Pose initial_pose(const core::PartSpec& part) const;
  // The scene after `board` is assembled at its target in the scene's assembly frame.
  Scene with_finished(const core::ProductSpec& spec, const std::string& board) const;
};

// The cell and product files a scene names (`files: {cell: ..., product: ...}`, relative to the
// scene file), read before the scene itself can be checked against them. Throws core::InputError.
struct SceneFiles {
  std::string cell;
  std::string product;
};
SceneFiles read_scene_files(const std::string& path);

// Reads and checks a scene file against the cell and the product: unknown boards, arms or
// fields, non-finite numbers, a board detected below the table top, a board both finished and
// detected, joints outside their limits, a human stance over the table, a worker's stature or
// sex out of their domain or a body the cell's human arms do not fit. Throws core::InputError
// "FILE: FIELD: expected X, got Y".
Scene load_scene(const std::string& path, const core::Cell& cell, const core::ProductSpec& product);

// The nominal scene: every board at its initial pose, the tool on the table, nothing finished,
// the human at the cell's stance, the robot at home.
Scene nominal_scene(const core::Cell& cell, const core::ProductSpec& product);

}  // namespace hila::online
