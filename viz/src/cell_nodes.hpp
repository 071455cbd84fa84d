#pragma once

// Private to hila::viz: the cell's nodes, shared by the cell and the plan exports.

#include <array>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "gltf_builder.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/mesh.hpp"
#include "hila/viz/cell_export.hpp"

namespace hila::viz {

// Material indices of the scene's groups.
struct Materials {
  int robot = -1;
  int gripper = -1;
  int tool = -1;
  int table = -1;
  int human = -1;
  int finished = -1;
  int stacked = -1;
  int held = -1;  // the board an arm handles (the plan)
};

Materials add_materials(GltfBuilder& builder);

// glTF meshes of links already added, by (model, link, material): copies of a model share them.
using MeshCache = std::map<std::tuple<const core::RobotModel*, int, int>, int>;

// Which links add_model_nodes adds and whether copies share their meshes.
struct ModelNodeOptions {
  int root_link = -1;           // the subtree from this link on; -1: the model's root link
  MeshCache* meshes = nullptr;  // reuse and record the links' meshes; nullptr: a mesh per link
};

// The nodes of a model's links, named prefix + LINK + suffix: node per link (RobotModel::links
// order; -1 for links outside the subtree), the subtree root's under `parent` at `root_pose`,
// each other link's under its parent link's at the joint's transform for `q`.
// `material_of(link)` picks each link's material.
std::vector<int> add_model_nodes(GltfBuilder& builder, const core::RobotModel& model,
                                 const Eigen::VectorXd& q, const std::string& prefix,
                                 const std::string& suffix, int parent, const core::Pose& root_pose,
                                 const std::function<int(int link)>& material_of,
                                 const ModelNodeOptions& options = {});

// A colour scale for a value mapped to [0, 1] (clamped): red (0) to green (1), linear in each
// channel (linear RGB, opaque): red falls and green rises with the value.
std::array<double, 4> scale_colour(double fraction);

// A link's local transform in its parent link's frame for the configuration `q`.
core::Pose link_local_pose(const core::RobotModel& model, int link, const Eigen::VectorXd& q);

// Links from each arm's flange on (the gripper and its fingers: material "gripper").
std::set<int> gripper_links(const core::Cell& cell);

// The robot's, human's and obstacles' nodes; `robot_links` and `human_links` per link.
struct CellNodes {
  Materials materials;
  std::vector<int> robot_links;
  std::vector<int> human_links;
};

CellNodes add_cell_nodes(GltfBuilder& builder, const core::Cell& cell, const CellView& view);

// The suction tool's links (names "tool/LINK" + suffix) with its handle at `handle` in the frame
// of `parent` (-1: the world); returns the tool's root node.
int add_tool_nodes(GltfBuilder& builder, const core::Cell& cell, int parent,
                   const core::Pose& handle, const std::string& suffix, int material);

// The mesh of a part (cached by the part's name per builder by the caller).
int add_part_mesh(GltfBuilder& builder, const std::string& name, const core::TriangleMesh& mesh,
                  int material);

// The robot's configuration `view.robot_q`, or home with the jaws open; InputError if its size is
// not the robot's.
Eigen::VectorXd robot_configuration(const core::Cell& cell, const Eigen::VectorXd& robot_q);

}  // namespace hila::viz
