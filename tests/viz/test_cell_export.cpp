#include <gtest/gtest.h>

#include <random>
#include <set>

#include "gltf_reading.hpp"
#include "hila/core/error.hpp"
#include "hila/viz/cell_export.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

// A seeded configuration of every robot variable within its limits.
Eigen::VectorXd random_configuration(const core::RobotModel& model, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  Eigen::VectorXd q(model.num_variables());
  const Eigen::VectorXd lo = model.lower_limits(), hi = model.upper_limits();
  for (int i = 0; i < q.size(); ++i) {
    q[i] = std::uniform_real_distribution<double>(std::max(lo[i], -3.0), std::min(hi[i], 3.0))(rng);
  }
  return q;
}

// Every link of `model` is a node "prefix + LINK" at `root * FK(q)` (1e-9), and carries a mesh
// of one primitive per collision geometry in `material`'s group.
void expect_model(const tinygltf::Model& gltf, const NodeState& state,
                  const core::RobotModel& model, const Eigen::VectorXd& q, const core::Pose& root,
                  const std::string& prefix) {
  const auto nodes = nodes_by_name(gltf);
  std::vector<core::Pose> links;
  model.link_poses(q, links);
  for (std::size_t l = 0; l < model.links().size(); ++l) {
    const core::Link& link = model.links()[l];
    const auto it = nodes.find(prefix + link.name);
    ASSERT_NE(it, nodes.end()) << prefix + link.name;
    const auto n = static_cast<std::size_t>(it->second);
    EXPECT_LT(pose_error(state.world[n], root * links[l]), 1e-9) << link.name;
    const int mesh = gltf.nodes[n].mesh;
    if (link.collisions.empty()) {
      EXPECT_EQ(mesh, -1) << link.name;
    } else {
      ASSERT_GE(mesh, 0) << link.name;
      EXPECT_EQ(gltf.meshes[static_cast<std::size_t>(mesh)].primitives.size(),
                link.collisions.size())
          << link.name;
    }
  }
}

std::string material_of(const tinygltf::Model& gltf, const std::string& node_name) {
  const int node = nodes_by_name(gltf).at(node_name);
  const int mesh = gltf.nodes[static_cast<std::size_t>(node)].mesh;
  const int material = gltf.meshes.at(static_cast<std::size_t>(mesh)).primitives.at(0).material;
  return gltf.materials.at(static_cast<std::size_t>(material)).name;
}

TEST(CellExport, EveryLinkAtItsForwardKinematics) {
  const auto cell = reference_cell();
  viz::CellView view;
  view.robot_q = random_configuration(cell->robot(), 7);
  view.human_q = random_configuration(cell->human(), 8);
  std::mt19937_64 rng(9);
  view.human_stance = random_pose(rng);
  view.tool = random_pose(rng);
  const tinygltf::Model gltf = load_glb(viz::cell_glb(*cell, view));
  const NodeState state = node_states(gltf);
  expect_model(gltf, state, cell->robot(), view.robot_q, core::Pose::Identity(), "robot/");
  expect_model(gltf, state, cell->human(), view.human_q, *view.human_stance, "human/");
  // The tool's handle link where the view puts it.
  const auto nodes = nodes_by_name(gltf);
  const int handle = nodes.at("tool/" + cell->spec().suction.handle_link);
  EXPECT_LT(pose_error(state.world[static_cast<std::size_t>(handle)], *view.tool), 1e-9);
  for (const core::BoxObstacle& box : cell->spec().obstacles) {
    const int n = nodes.at("obstacle/" + box.name);
    EXPECT_LT(pose_error(state.world[static_cast<std::size_t>(n)], box.pose), 1e-9);
    EXPECT_EQ(material_of(gltf, "obstacle/" + box.name), "table");
  }
}

TEST(CellExport, HomeByDefaultAndTheToolInHand) {
  const auto cell = reference_cell();
  viz::CellView view;
  view.tool_arm = cell->arms().back().spec.name;
  const tinygltf::Model gltf = load_glb(viz::cell_glb(*cell, view));
  const NodeState state = node_states(gltf);
  const Eigen::VectorXd home = cell->home_configuration(cell->spec().gripper.jaw_max);
  expect_model(gltf, state, cell->robot(), home, core::Pose::Identity(), "robot/");
  expect_model(gltf, state, cell->human(), cell->human_neutral(), cell->spec().human_stance,
               "human/");
  std::vector<core::Pose> links;
  cell->robot().link_poses(home, links);
  const core::Pose tcp =
      links[static_cast<std::size_t>(cell->robot().link_index(cell->arms().back().spec.tip_link))];
  const int handle = nodes_by_name(gltf).at("tool/" + cell->spec().suction.handle_link);
  EXPECT_LT(pose_error(state.world[static_cast<std::size_t>(handle)],
                       tcp * cell->spec().suction.handle_in_tcp),
            1e-9);
}

TEST(CellExport, ProductPartsAtTargetsAndInitialPoses) {
  const auto cell = reference_cell();
  const core::ProductSpec product = core::load_product(product_path());
  const tinygltf::Model gltf = load_glb(viz::cell_glb(*cell, viz::product_view(product)));
  const NodeState state = node_states(gltf);
  const auto nodes = nodes_by_name(gltf);
  for (const core::PartSpec& part : product.parts) {
    const auto finished = static_cast<std::size_t>(nodes.at("finished/" + part.name));
    const auto stacked = static_cast<std::size_t>(nodes.at("stack/" + part.name));
    EXPECT_LT(pose_error(state.world[finished], product.target_in_world(part)), 1e-9);
    EXPECT_LT(pose_error(state.world[stacked], part.initial), 1e-9);
    // The mesh's triangles, all of them.
    const auto& primitive =
        gltf.meshes[static_cast<std::size_t>(gltf.nodes[finished].mesh)].primitives.at(0);
    EXPECT_EQ(gltf.accessors[static_cast<std::size_t>(primitive.indices)].count,
              3 * part.mesh.triangles.size());
    EXPECT_EQ(material_of(gltf, "finished/" + part.name), "finished");
    EXPECT_EQ(material_of(gltf, "stack/" + part.name), "stacked");
  }
  const int handle = nodes.at("tool/" + cell->spec().suction.handle_link);
  EXPECT_LT(pose_error(state.world[static_cast<std::size_t>(handle)], product.suction_tool_pose),
            1e-9);
  // Distinct colours per group.
  std::set<std::vector<double>> colours;
  for (const auto& m : gltf.materials) colours.insert(m.pbrMetallicRoughness.baseColorFactor);
  EXPECT_EQ(colours.size(), gltf.materials.size());
  std::map<std::string, std::set<std::string>> groups;  // node name prefix -> materials
  for (const auto& node : gltf.nodes) {
    if (node.mesh >= 0)
      groups[node.name.substr(0, node.name.find('/'))].insert(material_of(gltf, node.name));
  }
  EXPECT_EQ(groups["robot"], (std::set<std::string>{"robot", "gripper"}));
  EXPECT_EQ(groups["human"], std::set<std::string>{"human"});
  EXPECT_EQ(groups["tool"], std::set<std::string>{"tool"});
}

TEST(CellExport, ConfigurationOfTheWrongSizeIsBadInput) {
  const auto cell = reference_cell();
  viz::CellView view;
  view.robot_q = Eigen::VectorXd::Zero(3);
  expect_input_error([&] { viz::cell_glb(*cell, view); }, {"robot configuration", "got 3"});
}

}  // namespace
}  // namespace hila::test
