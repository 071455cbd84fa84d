#include "hila/viz/grasp_export.hpp"

#include <algorithm>
#include <cstdio>

#include "cell_nodes.hpp"
#include "hila/core/error.hpp"

namespace hila::viz {

double holding_margin(const core::SuctionSpec& suction, const SuctionGraspView& grasp) {
  return std::min(grasp.force_margin / suction.max_force, grasp.moment_margin / suction.max_moment);
}

namespace {

// One material per distinct label (the colours repeat: θc in 1-degree steps).
class ScaleMaterials {
 public:
  explicit ScaleMaterials(GltfBuilder& builder) : builder_(builder) {}
  int get(const std::string& label, double fraction) {
    const auto it = materials_.find(label);
    if (it != materials_.end()) return it->second;
    return materials_[label] = builder_.add_material(label, scale_colour(fraction));
  }

 private:
  GltfBuilder& builder_;
  std::map<std::string, int> materials_;
};

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

}  // namespace

std::string grasps_glb(const core::Cell& cell, const GraspsView& view) {
  if (!view.mesh) {
    throw core::InputError("hila export grasps", "part " + view.part, "a mesh", "none");
  }
  const core::Arm& arm = view.arm.empty() ? cell.arms().at(0) : cell.arm(view.arm);
  const core::RobotModel& robot = cell.robot();
  const core::GripperSpec& gripper = cell.spec().gripper;
  GltfBuilder builder;
  const Materials m = add_materials(builder);
  ScaleMaterials scale(builder);
  MeshCache meshes;
  builder.add_node("part/" + view.part, -1, view.part_pose,
                   add_part_mesh(builder, "part/" + view.part, *view.mesh, m.stacked));

  const int flange = robot.link_index(arm.spec.flange_link);
  const int tip = robot.link_index(arm.spec.tip_link);
  std::vector<core::Pose> links;
  for (const GripperGraspView& g : view.gripper) {
    Eigen::VectorXd q = cell.home_configuration(gripper.jaw_max);
    cell.set_jaw(q, arm, std::clamp(g.jaw_width, gripper.jaw_min, gripper.jaw_max));
    robot.link_poses(q, links);
    const core::Pose flange_in_tcp =
        links[static_cast<std::size_t>(tip)].inverse() * links[static_cast<std::size_t>(flange)];
    const std::string name = "grasp:" + std::to_string(g.id);
    const int material =
        scale.get("theta_c " + fixed(g.theta_c_deg, 2) + " deg", g.theta_c_deg / 90.0);
    const int node = builder.add_node(name, -1, view.part_pose * g.tcp);
    add_model_nodes(builder, robot, q, name + "/", "", node, flange_in_tcp,
                    [&](int) { return material; }, {flange, &meshes});
  }

  const core::RobotModel& tool = cell.suction_tool();
  const Eigen::VectorXd tool_q = tool.neutral_configuration();
  tool.link_poses(tool_q, links);
  const core::Pose root_in_cup =
      links[static_cast<std::size_t>(tool.link_index(cell.spec().suction.cup_link))].inverse() *
      links[static_cast<std::size_t>(tool.root_link())];
  for (const SuctionGraspView& s : view.suction) {
    const std::string name = "suction:" + std::to_string(s.id);
    const double margin = holding_margin(cell.spec().suction, s);
    const int material = scale.get("margin " + fixed(margin, 2), margin);
    const int node = builder.add_node(name, -1, view.part_pose * s.cup);
    add_model_nodes(builder, tool, tool_q, name + "/", "", node, root_in_cup,
                    [&](int) { return material; }, {-1, &meshes});
  }
  return builder.glb();
}

}  // namespace hila::viz
