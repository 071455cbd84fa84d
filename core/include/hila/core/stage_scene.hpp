#pragma once

#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/product.hpp"

namespace hila::core {

// A part already assembled, standing at its pose.
struct PlacedPart {
  std::string name;
  const TriangleMesh* mesh = nullptr;
  Pose pose = Pose::Identity();  // world
};

// The cell at one assembly stage, as a collision scene: the static cell (robot, human at its
// stance, table), the finished parts and the parts still in the stack (static), the board being
// handled and the suction tool (both moving). The tool's handle touches the suction arm's gripper
// and the board touches the tool's cup: those pairs are allowed. Built once per stage; one
// CollisionData per thread.
struct StageScene {
  CellScene cell;
  std::vector<int> finished;           // bodies of the finished parts
  std::vector<int> stacked;            // bodies of the parts still in the stack
  int board = -1;                      // the board being handled
  RobotBodies tool;                    // suction tool links
  std::vector<int> tool_bodies;        // their bodies
  int suction_arm = -1;                // index into Cell::arms()
  Pose cup_in_tcp = Pose::Identity();  // the cup face in the suction arm's TCP while held
  // The tool is rigid: its link poses relative to the handle, computed once.
  std::vector<Pose> tool_links_in_handle;
};

// The parts assembled before `index` (product order), at their targets in the product's
// assembly frame: the nominal stage of the part at `index`.
std::vector<PlacedPart> parts_before(const ProductSpec& product, std::size_t index);

// The parts after `index` (product order) at their initial poses: the stack under the part at
// `index`, in the nominal stage.
std::vector<PlacedPart> parts_after(const ProductSpec& product, std::size_t index);

// `finished` become bodies "finished/NAME", `stacked` "stack/NAME".
StageScene build_stage_scene(const Cell& cell, const TriangleMesh& board,
                             const std::vector<PlacedPart>& finished,
                             const std::string& suction_arm,
                             const std::vector<PlacedPart>& stacked = {});

// Poses the tool held by the suction arm whose TCP is at `tcp` (world).
void set_tool_held(const Cell& cell, const StageScene& scene, CollisionData& data, const Pose& tcp);

// An arm's base link pose in the world (fixed for a fixed-base robot).
Pose arm_base_in_world(const Cell& cell, const Arm& arm);

}  // namespace hila::core
