#include "hila/core/stage_scene.hpp"

#include "hila/core/error.hpp"

namespace hila::core {

namespace {

// The body of `link` or, when it has no geometry, of its nearest ancestor with geometry.
int body_of_link_or_ancestor(const RobotModel& robot, const RobotBodies& bodies, int link) {
  while (link >= 0) {
    const int body = bodies.link_to_body[static_cast<std::size_t>(link)];
    if (body >= 0) return body;
    const int joint = robot.links()[static_cast<std::size_t>(link)].parent_joint;
    link = joint < 0 ? -1 : robot.joints()[static_cast<std::size_t>(joint)].parent_link;
  }
  return -1;
}

}  // namespace

Pose arm_base_in_world(const Cell& cell, const Arm& arm) {
  std::vector<Pose> poses;
  cell.robot().link_poses(cell.home_configuration(), poses);
  return poses[static_cast<std::size_t>(cell.robot().link_index(arm.spec.base_link))];
}

std::vector<PlacedPart> parts_before(const ProductSpec& product, std::size_t index) {
  std::vector<PlacedPart> out;
  for (std::size_t i = 0; i < index && i < product.parts.size(); ++i) {
    const PartSpec& p = product.parts[i];
    out.push_back({p.name, &p.mesh, product.target_in_world(p)});
  }
  return out;
}

std::vector<PlacedPart> parts_after(const ProductSpec& product, std::size_t index) {
  std::vector<PlacedPart> out;
  for (std::size_t i = index + 1; i < product.parts.size(); ++i) {
    const PartSpec& p = product.parts[i];
    out.push_back({p.name, &p.mesh, p.initial});
  }
  return out;
}

StageScene build_stage_scene(const Cell& cell, const TriangleMesh& board,
                             const std::vector<PlacedPart>& finished,
                             const std::string& suction_arm,
                             const std::vector<PlacedPart>& stacked) {
  StageScene scene;
  scene.cell = build_cell_scene(cell);
  CollisionModel& model = scene.cell.model;
  for (const PlacedPart& p : finished) {
    scene.finished.push_back(model.add_mesh_body("finished/" + p.name, *p.mesh, true, p.pose));
  }
  for (const PlacedPart& p : stacked) {
    scene.stacked.push_back(model.add_mesh_body("stack/" + p.name, *p.mesh, true, p.pose));
  }
  scene.board = model.add_mesh_body("board", board, false);

  const RobotModel& tool = cell.suction_tool();
  scene.tool = add_robot(model, tool, "tool/");
  for (const int b : scene.tool.link_to_body) {
    if (b >= 0) scene.tool_bodies.push_back(b);
  }
  const auto& arms = cell.arms();
  for (std::size_t a = 0; a < arms.size(); ++a) {
    if (arms[a].spec.name == suction_arm) scene.suction_arm = static_cast<int>(a);
  }
  if (scene.suction_arm < 0) {
    throw InputError(cell.spec().file, "suction arm", "the name of an arm of the cell",
                     "'" + suction_arm + "'");
  }
  const Arm& arm = arms[static_cast<std::size_t>(scene.suction_arm)];
  const int handle =
      body_of_link_or_ancestor(tool, scene.tool, tool.link_index(cell.spec().suction.handle_link));
  const int cup =
      body_of_link_or_ancestor(tool, scene.tool, tool.link_index(cell.spec().suction.cup_link));
  // The handle sits in the hand: it may touch every body from the flange on.
  const auto hand =
      subtree_bodies(cell.robot(), scene.cell.robot, cell.robot().link_index(arm.spec.flange_link));
  for (const int h : hand) {
    if (handle >= 0) model.allow(handle, h);
  }
  if (cup >= 0) model.allow(cup, scene.board);

  std::vector<Pose> poses;
  tool.link_poses(tool.neutral_configuration(), poses);
  const Pose handle_inv =
      poses[static_cast<std::size_t>(tool.link_index(cell.spec().suction.handle_link))].inverse();
  for (const Pose& p : poses) scene.tool_links_in_handle.push_back(handle_inv * p);
  scene.cup_in_tcp =
      cell.spec().suction.handle_in_tcp * scene.tool_links_in_handle[static_cast<std::size_t>(
                                              tool.link_index(cell.spec().suction.cup_link))];
  return scene;
}

void set_tool_held(const Cell& cell, const StageScene& scene, CollisionData& data,
                   const Pose& tcp) {
  set_robot_pose(data, scene.tool, scene.tool_links_in_handle,
                 tcp * cell.spec().suction.handle_in_tcp);
}

}  // namespace hila::core
