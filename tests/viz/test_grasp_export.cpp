#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "gltf_reading.hpp"
#include "hila/core/error.hpp"
#include "hila/core/product.hpp"
#include "hila/viz/grasp_export.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

// The test's own grasps of the cabinet's first part: seeded random TCP and cup frames, jaw
// widths over the gripper's range and beyond, θc in whole degrees and between, margins from
// negative to the cup's full capacity.
viz::GraspsView random_grasps(const core::Cell& cell, const core::ProductSpec& product,
                              std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  viz::GraspsView view;
  view.part = product.parts.at(0).name;
  view.mesh = &product.parts.at(0).mesh;
  view.part_pose = random_pose(rng);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    viz::GripperGraspView g;
    g.id = 100 + 3 * i;  // ids as a database assigns them: not 0-based, not dense
    g.tcp = random_pose(rng, 0.2);
    g.jaw_width = -0.01 + 0.11 * unit(rng);
    g.theta_c_deg = i % 2 ? std::round(90.0 * unit(rng)) : 90.0 * unit(rng);
    view.gripper.push_back(g);
  }
  view.gripper[3].theta_c_deg = 0.0;
  view.gripper[4].theta_c_deg = 90.0;
  const core::SuctionSpec& suction = cell.spec().suction;
  for (int i = 0; i < 12; ++i) {
    viz::SuctionGraspView s;
    s.id = 7 + i;
    s.cup = random_pose(rng, 0.2);
    s.force_margin = suction.max_force * (1.2 * unit(rng) - 0.1);
    s.moment_margin = suction.max_moment * (1.2 * unit(rng) - 0.1);
    view.suction.push_back(s);
  }
  return view;
}

std::vector<double> colour_of(const tinygltf::Model& gltf, int node) {
  const int mesh = gltf.nodes.at(static_cast<std::size_t>(node)).mesh;
  EXPECT_GE(mesh, 0);
  const int material = gltf.meshes.at(static_cast<std::size_t>(mesh)).primitives.at(0).material;
  return gltf.materials.at(static_cast<std::size_t>(material)).pbrMetallicRoughness.baseColorFactor;
}

// Every mesh-carrying descendant of `node` in one colour; returns it.
std::vector<double> copy_colour(const tinygltf::Model& gltf, int node) {
  std::vector<double> colour;
  std::vector<int> open{node};
  while (!open.empty()) {
    const int n = open.back();
    open.pop_back();
    const auto& gn = gltf.nodes[static_cast<std::size_t>(n)];
    if (gn.mesh >= 0) {
      const std::vector<double> c = colour_of(gltf, n);
      if (colour.empty()) colour = c;
      EXPECT_EQ(c, colour) << gn.name;
    }
    open.insert(open.end(), gn.children.begin(), gn.children.end());
  }
  EXPECT_FALSE(colour.empty());
  return colour;
}

// Red never rises and green never falls as the value rises; the ends differ.
void expect_monotone(std::vector<std::pair<double, std::vector<double>>> by_value) {
  std::sort(by_value.begin(), by_value.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (std::size_t i = 1; i < by_value.size(); ++i) {
    EXPECT_LE(by_value[i].second[0], by_value[i - 1].second[0]) << by_value[i].first;
    EXPECT_GE(by_value[i].second[1], by_value[i - 1].second[1]) << by_value[i].first;
  }
  EXPECT_GT(by_value.front().second[0], by_value.back().second[0] + 0.5);
  EXPECT_LT(by_value.front().second[1] + 0.5, by_value.back().second[1]);
}

class GraspExport : public ::testing::Test {
 protected:
  void SetUp() override {
    cell_ = reference_cell();
    product_ = core::load_product(product_path());
    view_ = random_grasps(*cell_, product_, 34);
    gltf_ = load_glb(viz::grasps_glb(*cell_, view_));
    state_ = node_states(gltf_);
    nodes_ = nodes_by_name(gltf_);
  }
  const core::Pose& world(const std::string& name) const {
    return state_.world.at(static_cast<std::size_t>(nodes_.at(name)));
  }

  std::shared_ptr<const core::Cell> cell_;
  core::ProductSpec product_;
  viz::GraspsView view_;
  tinygltf::Model gltf_;
  NodeState state_;
  std::map<std::string, int> nodes_;
};

TEST_F(GraspExport, OneNodePerGraspAtThePartPoseTimesTheGrasp) {
  int grasp_nodes = 0, suction_nodes = 0;
  for (const auto& [name, n] : nodes_) {
    if (name.find('/') != std::string::npos) continue;
    grasp_nodes += name.rfind("grasp:", 0) == 0 ? 1 : 0;
    suction_nodes += name.rfind("suction:", 0) == 0 ? 1 : 0;
  }
  EXPECT_EQ(grasp_nodes, static_cast<int>(view_.gripper.size()));
  EXPECT_EQ(suction_nodes, static_cast<int>(view_.suction.size()));
  EXPECT_LT(pose_error(world("part/" + view_.part), view_.part_pose), 1e-9);

  const core::Arm& arm = cell_->arms().front();
  const std::string tcp_link = arm.spec.tip_link;
  for (const auto& g : view_.gripper) {
    const std::string name = "grasp:" + std::to_string(g.id);
    const core::Pose expected = view_.part_pose * g.tcp;
    EXPECT_LT(pose_error(world(name), expected), 1e-9) << name;
    EXPECT_LT(pose_error(world(name + "/" + tcp_link), expected), 1e-9) << name;
  }
  const std::string cup_link = cell_->spec().suction.cup_link;
  for (const auto& s : view_.suction) {
    const std::string name = "suction:" + std::to_string(s.id);
    const core::Pose expected = view_.part_pose * s.cup;
    EXPECT_LT(pose_error(world(name), expected), 1e-9) << name;
    EXPECT_LT(pose_error(world(name + "/" + cup_link), expected), 1e-9) << name;
  }
}

TEST_F(GraspExport, TheGrippersLinksAtTheGraspsJawOpening) {
  const core::Arm& arm = cell_->arms().front();
  const core::RobotModel& robot = cell_->robot();
  const core::GripperSpec& gripper = cell_->spec().gripper;
  std::vector<core::Pose> links;
  for (const auto& g : view_.gripper) {
    // The robot with the jaws at the grasp's width (clamped to the range), its TCP moved onto
    // the grasp: every link from the flange on where the export put it.
    Eigen::VectorXd q = cell_->home_configuration(gripper.jaw_max);
    cell_->set_jaw(q, arm, std::clamp(g.jaw_width, gripper.jaw_min, gripper.jaw_max));
    robot.link_poses(q, links);
    const core::Pose tcp_to_world =
        view_.part_pose * g.tcp *
        links[static_cast<std::size_t>(robot.link_index(arm.spec.tip_link))].inverse();
    const std::string name = "grasp:" + std::to_string(g.id) + "/";
    int found = 0;
    for (std::size_t l = 0; l < links.size(); ++l) {
      const auto it = nodes_.find(name + robot.links()[l].name);
      if (it == nodes_.end()) continue;
      ++found;
      EXPECT_LT(
          pose_error(state_.world[static_cast<std::size_t>(it->second)], tcp_to_world * links[l]),
          1e-9)
          << name << robot.links()[l].name;
    }
    EXPECT_GE(found, 6) << name;  // flange, sensor, palm, two fingers, two pads, TCP
    EXPECT_EQ(nodes_.count(name + arm.spec.flange_link), 1u);
    EXPECT_EQ(nodes_.count(name + arm.spec.base_link), 0u) << "the gripper only";
  }
}

TEST_F(GraspExport, ColoursRiseWithThetaCAndTheHoldingMargin) {
  std::vector<std::pair<double, std::vector<double>>> by_theta, by_margin;
  for (const auto& g : view_.gripper) {
    by_theta.emplace_back(g.theta_c_deg,
                          copy_colour(gltf_, nodes_.at("grasp:" + std::to_string(g.id))));
  }
  expect_monotone(by_theta);
  const core::SuctionSpec& suction = cell_->spec().suction;
  for (const auto& s : view_.suction) {
    // The margin as docs/cli.md states it: the smaller share of the cup's capacity left.
    const double margin =
        std::min(s.force_margin / suction.max_force, s.moment_margin / suction.max_moment);
    EXPECT_DOUBLE_EQ(viz::holding_margin(suction, s), margin);
    by_margin.emplace_back(margin,
                           copy_colour(gltf_, nodes_.at("suction:" + std::to_string(s.id))));
  }
  expect_monotone(by_margin);
}

TEST(GraspExportInput, AnUnknownArmOrNoMeshIsBadInput) {
  const auto cell = reference_cell();
  const core::ProductSpec product = core::load_product(product_path());
  viz::GraspsView view = random_grasps(*cell, product, 1);
  view.arm = "third";
  expect_input_error([&] { viz::grasps_glb(*cell, view); }, {"third"});
  view.arm.clear();
  view.mesh = nullptr;
  expect_input_error([&] { viz::grasps_glb(*cell, view); }, {"mesh"});
}

}  // namespace
}  // namespace hila::test
