#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"

namespace hila::viz {

// What a cell scene shows besides the cell's robot, human and obstacles.
struct CellView {
  Eigen::VectorXd robot_q;  // the robot's whole configuration; empty: home, jaws open
  Eigen::VectorXd human_q;  // the human's configuration; empty: the neutral posture
  std::optional<core::Pose> human_stance;  // world; empty: the cell's stance
  // The suction tool: in the gripper of `tool_arm` when that is an arm's name, else standing on
  // the table with its handle at `tool` (world); neither: not shown.
  std::optional<core::Pose> tool;
  std::string tool_arm;
  std::vector<core::PlacedPart> finished;  // parts in the assembly, at their world poses
  std::vector<core::PlacedPart> stacked;   // parts on the table, at their world poses
};

// The view of a product in the cell: the tool on the table at the product's tool pose, every part
// finished at its target and on the table at its initial pose (the meshes stay owned by
// `product`).
CellView product_view(const core::ProductSpec& product);

// The cell as a glTF 2.0 binary (.glb): one node per link, named "robot/LINK", "human/LINK" and
// "tool/LINK" (each a child of its parent link's node, at the joint's transform for the
// configuration, so a node's world transform is the link's pose), "obstacle/NAME",
// "finished/PART" and "stack/PART" (at their world poses). A link's node carries one mesh of its
// collision geometry (boxes, cylinders, spheres, meshes; the URDF's visual geometry is not
// loaded). Materials by group: "robot", "gripper" (links from an arm's flange on), "tool",
// "table" (the obstacles), "human", "finished", "stacked". Throws core::InputError for a
// configuration of the wrong size or a mesh that cannot be read.
std::string cell_glb(const core::Cell& cell, const CellView& view);

}  // namespace hila::viz
