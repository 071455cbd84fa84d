#include "hila/online/world.hpp"

namespace hila::online {

namespace {

std::vector<core::PlacedPart> placed(const core::ProductSpec& product, const Scene& scene) {
  std::vector<core::PlacedPart> out;
  for (const auto& f : scene.finished) {
    out.push_back({f.name, &product.part(f.name).mesh, f.pose});
  }
  return out;
}

// The boards neither finished nor being handled: still in the stack, where the scene has them.
std::vector<core::PlacedPart> still_stacked(const core::ProductSpec& product, const Scene& scene,
                                            const std::string& board) {
  std::vector<core::PlacedPart> out;
  for (const auto& part : product.parts) {
    if (part.name == board || scene.is_finished(part.name)) continue;
    out.push_back({part.name, &part.mesh, scene.initial_pose(part)});
  }
  return out;
}

}  // namespace

World::World(const core::Cell& cell, const core::ProductSpec& product, const Scene& scene,
             const std::string& board, const std::string& suction_arm)
    : cell_(cell),
      board_(product.part(board)),
      scene_(scene),
      finished_(placed(product, scene)),
      stage_(core::build_stage_scene(cell, board_.mesh, finished_, suction_arm,
                                     still_stacked(product, scene, board))) {
  for (const auto& o : scene_.obstacles) {
    if (o.is_box()) {
      core::GeometrySpec box;
      box.box_size = o.box_size;
      obstacles_.push_back(stage_.cell.model.add_body("obstacle/" + o.name, {box}, true, o.pose));
    } else {
      obstacles_.push_back(
          stage_.cell.model.add_mesh_body("obstacle/" + o.name, o.mesh, true, o.pose));
    }
  }
}

core::CollisionData World::make_data() const {
  core::CollisionData data(stage_.cell.model);
  Eigen::VectorXd robot_q = cell_.home_configuration();
  for (const auto& arm : cell_.arms()) {
    const auto it = scene_.robot.find(arm.spec.name);
    if (it != scene_.robot.end()) cell_.set_arm(robot_q, arm, it->second);
  }
  core::set_robot_state(cell_, stage_.cell, data, robot_q);
  std::vector<core::Pose> poses;
  cell_.human().link_poses(cell_.human_neutral(), poses);
  core::set_robot_pose(data, stage_.cell.human, poses, scene_.human_stance);
  place_tool(data, robot_q, scene_.tool_in_hand, scene_.tool);
  data.set_body_pose(stage_.board, scene_.initial_pose(board_));
  return data;
}

void World::place_tool(core::CollisionData& data, const Eigen::VectorXd& robot_q, bool in_hand,
                       const core::Pose& on_table) const {
  if (!in_hand) {
    core::set_robot_pose(data, stage_.tool, stage_.tool_links_in_handle, on_table);
    return;
  }
  const core::Arm& arm = cell_.arms()[static_cast<std::size_t>(stage_.suction_arm)];
  std::vector<core::Pose> links;
  cell_.robot().link_poses(robot_q, links);
  core::set_tool_held(cell_, stage_, data,
                      links[static_cast<std::size_t>(cell_.robot().link_index(arm.spec.tip_link))]);
}

}  // namespace hila::online
