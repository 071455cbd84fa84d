#include "hila/viz/goal_export.hpp"

#include <algorithm>
#include <cstdio>
#include <set>

#include "cell_nodes.hpp"
#include "hila/core/error.hpp"

namespace hila::viz {

namespace {

void check_size(const std::string& what, const Eigen::VectorXd& q, int dof) {
  if (q.size() != dof) {
    throw core::InputError("hila export goals", what, std::to_string(dof) + " joint values",
                           std::to_string(q.size()));
  }
}

const core::HumanArm& human_arm(const core::Cell& cell, const std::string& name) {
  for (const core::HumanArm& arm : cell.human_arms()) {
    if (arm.spec.name == name) return arm;
  }
  throw core::InputError(cell.spec().file, "human.arms", "an arm named '" + name + "'",
                         "no such arm");
}

}  // namespace

std::string goals_glb(const core::Cell& cell, const GoalsView& view,
                      const GoalsSettings& settings) {
  if (!view.mesh) {
    throw core::InputError("hila export goals", "part " + view.part, "a mesh", "none");
  }
  GltfBuilder builder;
  const Materials m = add_materials(builder);
  MeshCache meshes;
  const std::set<int> gripper = gripper_links(cell);
  const int part_mesh = add_part_mesh(builder, "part/" + view.part, *view.mesh, m.held);
  std::map<std::string, int> obstacle_meshes;
  for (const core::BoxObstacle& box : cell.spec().obstacles) {
    obstacle_meshes[box.name] =
        builder.add_mesh("obstacle/" + box.name, {{core::make_box_mesh(box.size), m.table}});
  }
  const core::RobotModel& tool = cell.suction_tool();
  std::vector<core::Pose> tool_links;
  tool.link_poses(tool.neutral_configuration(), tool_links);
  const core::Pose root_in_handle =
      tool_links[static_cast<std::size_t>(tool.link_index(cell.spec().suction.handle_link))]
          .inverse() *
      tool_links[static_cast<std::size_t>(tool.root_link())];

  // Q spans a narrow band (the comfort threshold to a few tenths): the colour scale runs from the
  // lowest Q shown (red) to the highest (green).
  double q_low = 1.0, q_high = 0.0;
  for (const GoalView& goal : view.goals) {
    q_low = std::min(q_low, goal.quality);
    q_high = std::max(q_high, goal.quality);
  }
  for (std::size_t k = 0; k < view.goals.size(); ++k) {
    const GoalView& goal = view.goals[k];
    const std::string name = "goal:" + std::to_string(goal.rank);
    core::Pose offset = core::Pose::Identity();
    offset.translation() = static_cast<double>(k) * settings.offset;
    const int root = builder.add_node(name, -1, offset);

    char label[32];
    int q_material = -1;
    if (settings.colour == GoalColour::kRula) {
      if (goal.rula_grand >= 1 && goal.rula_grand <= 7) {
        std::snprintf(label, sizeof label, "RULA %d", goal.rula_grand);
        q_material = builder.add_material(label, scale_colour((7.0 - goal.rula_grand) / 6.0));
      } else {
        q_material = builder.add_material("RULA -", {0.6, 0.6, 0.6, 1.0});
      }
    } else {
      std::snprintf(label, sizeof label, "Q %.3f", goal.quality);
      q_material = builder.add_material(
          label, scale_colour(q_high > q_low ? (goal.quality - q_low) / (q_high - q_low) : 1.0));
    }
    builder.add_node(name + "/part", root, goal.board,
                     add_part_mesh(builder, name + "/part", *view.mesh, q_material));

    Eigen::VectorXd human_q = cell.human_neutral();
    for (const auto& [arm_name, q] : goal.human_arms) {
      const core::HumanArm& arm = human_arm(cell, arm_name);
      check_size(name + ": human arm " + arm_name, q, arm.chain.dof());
      for (int i = 0; i < q.size(); ++i) {
        human_q[arm.chain.model_variables()[static_cast<std::size_t>(i)]] = q[i];
      }
    }
    add_model_nodes(builder, cell.human(), human_q, name + "/human/", "", root,
                    view.human_stance.value_or(cell.spec().human_stance),
                    [&](int) { return m.human; }, {-1, &meshes});
    for (const core::BoxObstacle& box : cell.spec().obstacles) {
      builder.add_node(name + "/obstacle/" + box.name, root, box.pose,
                       obstacle_meshes.at(box.name));
    }

    Eigen::VectorXd robot_q = cell.home_configuration(cell.spec().gripper.jaw_max);
    if (goal.exchange) {
      const ExchangeView& e = *goal.exchange;
      const core::Arm& suction = cell.arm(e.suction_arm);
      const core::Arm& receiving = cell.arm(e.receiving_arm);
      check_size(name + ": exchange arm " + e.suction_arm, e.suction_joints, suction.chain.dof());
      check_size(name + ": exchange arm " + e.receiving_arm, e.receiving_joints,
                 receiving.chain.dof());
      cell.set_arm(robot_q, suction, e.suction_joints);
      cell.set_jaw(robot_q, suction, cell.spec().suction.handle_width);
      cell.set_arm(robot_q, receiving, e.receiving_joints);
      cell.set_jaw(
          robot_q, receiving,
          std::clamp(e.jaw_opening, cell.spec().gripper.jaw_min, cell.spec().gripper.jaw_max));
    }
    const std::vector<int> robot_nodes = add_model_nodes(
        builder, cell.robot(), robot_q, name + "/robot/", "", root, core::Pose::Identity(),
        [&](int link) { return gripper.count(link) ? m.gripper : m.robot; }, {-1, &meshes});
    if (goal.exchange) {
      const core::Arm& suction = cell.arm(goal.exchange->suction_arm);
      const int tip =
          robot_nodes[static_cast<std::size_t>(cell.robot().link_index(suction.spec.tip_link))];
      add_model_nodes(builder, tool, tool.neutral_configuration(), name + "/tool/", "", tip,
                      cell.spec().suction.handle_in_tcp * root_in_handle,
                      [&](int) { return m.tool; }, {-1, &meshes});
      builder.add_node(name + "/exchange", root, goal.exchange->board, part_mesh);
    }
  }
  return builder.glb();
}

}  // namespace hila::viz
