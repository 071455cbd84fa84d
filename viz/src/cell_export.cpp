#include "hila/viz/cell_export.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>

#include "cell_nodes.hpp"
#include "hila/core/error.hpp"
#include "shapes.hpp"

namespace hila::viz {

Materials add_materials(GltfBuilder& builder) {
  // Colours (linear RGBA) that tell the groups apart at a glance.
  Materials m;
  m.robot = builder.add_material("robot", {0.55, 0.6, 0.68, 1.0});
  m.gripper = builder.add_material("gripper", {0.12, 0.12, 0.14, 1.0});
  m.tool = builder.add_material("tool", {0.9, 0.45, 0.05, 1.0});
  m.table = builder.add_material("table", {0.45, 0.3, 0.18, 1.0});
  m.human = builder.add_material("human", {0.85, 0.65, 0.5, 1.0});
  m.finished = builder.add_material("finished", {0.2, 0.55, 0.25, 1.0});
  m.stacked = builder.add_material("stacked", {0.75, 0.7, 0.45, 1.0});
  m.held = builder.add_material("held", {0.1, 0.45, 0.85, 1.0});
  return m;
}

core::Pose link_local_pose(const core::RobotModel& model, int link, const Eigen::VectorXd& q) {
  const int j = model.links()[static_cast<std::size_t>(link)].parent_joint;
  if (j < 0) return core::Pose::Identity();
  const core::Joint& joint = model.joints()[static_cast<std::size_t>(j)];
  return joint.origin * core::joint_motion(joint, model.joint_value(q, j));
}

std::vector<int> add_model_nodes(GltfBuilder& builder, const core::RobotModel& model,
                                 const Eigen::VectorXd& q, const std::string& prefix,
                                 const std::string& suffix, int parent, const core::Pose& root_pose,
                                 const std::function<int(int link)>& material_of,
                                 const ModelNodeOptions& options) {
  std::vector<int> nodes(model.links().size(), -1);
  // Joints are in topological order: a parent link's node exists before its children's.
  auto add = [&](int link, int parent_node, const core::Pose& local) {
    const core::Link& l = model.links()[static_cast<std::size_t>(link)];
    const std::string name = prefix + l.name + suffix;
    const int material = material_of(link);
    const auto key = std::make_tuple(&model, link, material);
    int mesh = -1;
    if (options.meshes && options.meshes->count(key)) {
      mesh = options.meshes->at(key);
    } else {
      std::vector<Primitive> primitives;
      for (const core::GeometrySpec& g : l.collisions)
        primitives.push_back({geometry_mesh(g), material});
      mesh = builder.add_mesh(name, primitives);
      if (options.meshes) (*options.meshes)[key] = mesh;
    }
    nodes[static_cast<std::size_t>(link)] = builder.add_node(name, parent_node, local, mesh);
  };
  add(options.root_link >= 0 ? options.root_link : model.root_link(), parent, root_pose);
  for (const core::Joint& joint : model.joints()) {
    const int parent_node = nodes[static_cast<std::size_t>(joint.parent_link)];
    if (parent_node < 0) continue;  // outside the subtree
    add(joint.child_link, parent_node, link_local_pose(model, joint.child_link, q));
  }
  return nodes;
}

std::array<double, 4> scale_colour(double fraction) {
  const double f = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  return {0.9 * (1.0 - f) + 0.05, 0.75 * f + 0.05, 0.08, 1.0};
}

Eigen::VectorXd robot_configuration(const core::Cell& cell, const Eigen::VectorXd& robot_q) {
  if (robot_q.size() == 0) return cell.home_configuration(cell.spec().gripper.jaw_max);
  if (robot_q.size() != cell.robot().num_variables()) {
    throw core::InputError(cell.spec().robot_urdf, "robot configuration",
                           std::to_string(cell.robot().num_variables()) + " joint values",
                           std::to_string(robot_q.size()));
  }
  return robot_q;
}

std::set<int> gripper_links(const core::Cell& cell) {
  const core::RobotModel& robot = cell.robot();
  std::set<int> links;
  for (const core::Arm& arm : cell.arms()) {
    std::vector<int> open{robot.link_index(arm.spec.flange_link)};
    while (!open.empty()) {
      const int link = open.back();
      open.pop_back();
      links.insert(link);
      for (int j : robot.links()[static_cast<std::size_t>(link)].child_joints) {
        open.push_back(robot.joints()[static_cast<std::size_t>(j)].child_link);
      }
    }
  }
  return links;
}

CellNodes add_cell_nodes(GltfBuilder& builder, const core::Cell& cell, const CellView& view) {
  CellNodes out;
  out.materials = add_materials(builder);
  const Materials& m = out.materials;
  const Eigen::VectorXd robot_q = robot_configuration(cell, view.robot_q);
  const std::set<int> gripper = gripper_links(cell);
  out.robot_links =
      add_model_nodes(builder, cell.robot(), robot_q, "robot/", "", -1, core::Pose::Identity(),
                      [&](int link) { return gripper.count(link) ? m.gripper : m.robot; });
  const Eigen::VectorXd human_q = view.human_q.size() ? view.human_q : cell.human_neutral();
  if (human_q.size() != cell.human().num_variables()) {
    throw core::InputError(cell.spec().human_urdf, "human configuration",
                           std::to_string(cell.human().num_variables()) + " joint values",
                           std::to_string(human_q.size()));
  }
  out.human_links = add_model_nodes(builder, cell.human(), human_q, "human/", "", -1,
                                    view.human_stance.value_or(cell.spec().human_stance),
                                    [&](int) { return m.human; });
  for (const core::BoxObstacle& box : cell.spec().obstacles) {
    const int mesh =
        builder.add_mesh("obstacle/" + box.name, {{core::make_box_mesh(box.size), m.table}});
    builder.add_node("obstacle/" + box.name, -1, box.pose, mesh);
  }
  return out;
}

int add_tool_nodes(GltfBuilder& builder, const core::Cell& cell, int parent,
                   const core::Pose& handle, const std::string& suffix, int material) {
  const core::RobotModel& tool = cell.suction_tool();
  const Eigen::VectorXd q = tool.neutral_configuration();
  std::vector<core::Pose> links;
  tool.link_poses(q, links);
  const core::Pose handle_in_root =
      links[static_cast<std::size_t>(tool.link_index(cell.spec().suction.handle_link))];
  // Node names "tool/LINK" + suffix: the suffix tells copies apart.
  const std::vector<int> nodes =
      add_model_nodes(builder, tool, q, "tool/", suffix, parent, handle * handle_in_root.inverse(),
                      [&](int) { return material; });
  return nodes[static_cast<std::size_t>(tool.root_link())];
}

int add_part_mesh(GltfBuilder& builder, const std::string& name, const core::TriangleMesh& mesh,
                  int material) {
  return builder.add_mesh(name, {{mesh, material}});
}

CellView product_view(const core::ProductSpec& product) {
  CellView view;
  view.tool = product.suction_tool_pose;
  for (const core::PartSpec& part : product.parts) {
    view.finished.push_back({part.name, &part.mesh, product.target_in_world(part)});
    view.stacked.push_back({part.name, &part.mesh, part.initial});
  }
  return view;
}

std::string cell_glb(const core::Cell& cell, const CellView& view) {
  GltfBuilder builder;
  const CellNodes nodes = add_cell_nodes(builder, cell, view);
  const Materials& m = nodes.materials;
  if (!view.tool_arm.empty()) {
    const core::Arm& arm = cell.arm(view.tool_arm);
    add_tool_nodes(
        builder, cell,
        nodes.robot_links[static_cast<std::size_t>(cell.robot().link_index(arm.spec.tip_link))],
        cell.spec().suction.handle_in_tcp, "", m.tool);
  } else if (view.tool) {
    add_tool_nodes(builder, cell, -1, *view.tool, "", m.tool);
  }
  for (const auto& [parts, prefix, material] : {std::tuple{&view.finished, "finished/", m.finished},
                                                std::tuple{&view.stacked, "stack/", m.stacked}}) {
    for (const core::PlacedPart& part : *parts) {
      const int mesh = add_part_mesh(builder, prefix + part.name, *part.mesh, material);
      builder.add_node(prefix + part.name, -1, part.pose, mesh);
    }
  }
  return builder.glb();
}

}  // namespace hila::viz
