#include <gtest/gtest.h>

#include <random>

#include "hila/core/collision.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/offline/roadmap.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

offline::RoadmapSettings small_settings() {
  offline::RoadmapSettings s;
  s.nodes = 250;
  s.seed = 5;
  return s;
}

const offline::Roadmap& small_roadmap() {
  static const offline::Roadmap map =
      offline::build_roadmap(*test::reference_cell(), "left", small_settings());
  return map;
}

// Independent references: the whole robot's link poses (not the chain), a whole-scene
// brute-force collision check (every pair through FCL's narrow phase).
struct Reference {
  std::shared_ptr<const core::Cell> cell = test::reference_cell();
  core::CellScene scene = core::build_cell_scene(*cell);
  core::CollisionData data{scene.model};
  const core::Arm& arm = cell->arm("left");

  bool colliding(const Eigen::VectorXd& q) {
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, arm, q);
    core::set_cell_state(*cell, scene, data, robot_q, cell->human_neutral());
    return core::in_collision_brute_force(scene.model, data);
  }
  double inclination_deg(const Eigen::VectorXd& q) {
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, arm, q);
    std::vector<core::Pose> poses;
    cell->robot().link_poses(robot_q, poses);
    const core::Pose tcp =
        poses[static_cast<std::size_t>(cell->robot().link_index(arm.spec.tip_link))];
    const Eigen::Vector3d axis = tcp.linear() * cell->spec().gripper.opening_axis.normalized();
    const double c = std::min(1.0, std::abs(axis.z()));
    return core::rad_to_deg(std::acos(c));
  }
};

}  // namespace

TEST(Roadmap, NodesAreFreeAndTheirInclinationMatchesBruteForceFk) {
  const auto& map = small_roadmap();
  // PRM's milestones that got no edge are not part of the roadmap.
  ASSERT_LE(static_cast<int>(map.nodes.size()), small_settings().nodes);
  ASSERT_GE(static_cast<int>(map.nodes.size()), small_settings().nodes / 2);
  Reference ref;
  int near_vertical = 0;
  for (std::size_t i = 0; i < map.nodes.size(); ++i) {
    const auto& q = map.nodes[i];
    EXPECT_TRUE(ref.arm.chain.within_limits(q, 1e-12));
    EXPECT_FALSE(ref.colliding(q)) << "node " << i;
    EXPECT_NEAR(map.node_inclination_deg[i], ref.inclination_deg(q), 1e-6) << i;
    near_vertical += map.node_inclination_deg[i] <= 11.0 ? 1 : 0;
  }
  // The slip-biased sampler puts a large share of nodes where even an 11 degree limit holds
  // (uniform sampling puts about 2 % there).
  EXPECT_GT(near_vertical, static_cast<int>(map.nodes.size() / 4));
}

TEST(Roadmap, SampledEdgesRecheckedDenselyAndIndependently) {
  const auto& map = small_roadmap();
  ASSERT_GT(map.edges.size(), map.nodes.size() * 2);
  Reference ref;
  std::mt19937_64 rng(3);
  for (int k = 0; k < 40; ++k) {
    const std::size_t e = rng() % map.edges.size();
    const auto& a = map.nodes[static_cast<std::size_t>(map.edges[e].first)];
    const auto& b = map.nodes[static_cast<std::size_t>(map.edges[e].second)];
    EXPECT_NEAR(map.edge_length[e], (b - a).norm(), 1e-12);
    // Four times denser than the build's samples (which are among them).
    const int steps = static_cast<int>(map.edge_gravity[e].size()) + 1;
    std::vector<Eigen::VectorXd> dense;
    for (int i = 1; i < 4 * steps; ++i) dense.push_back(a + (b - a) * (i / (4.0 * steps)));
    double worst = std::max(ref.inclination_deg(a), ref.inclination_deg(b));
    for (const auto& q : dense) {
      EXPECT_FALSE(ref.colliding(q)) << "edge " << e;
      worst = std::max(worst, ref.inclination_deg(q));
    }
    // Between two stored samples (<= 0.05 rad of joint motion) the axis turns by little.
    EXPECT_NEAR(map.edge_max_inclination_deg[e], worst, 2.0) << "edge " << e;
    EXPECT_LE(map.edge_max_inclination_deg[e], worst + 1e-6);
    ASSERT_EQ(map.edge_gravity[e].size(), offline::edge_samples(a, b, map.resolution).size());
  }
}

TEST(Roadmap, SameSeedSameRoadmap) {
  const auto again = offline::build_roadmap(*test::reference_cell(), "left", small_settings());
  const auto& map = small_roadmap();
  ASSERT_EQ(again.nodes.size(), map.nodes.size());
  ASSERT_EQ(again.edges, map.edges);
  for (std::size_t i = 0; i < map.nodes.size(); ++i) {
    EXPECT_TRUE(again.nodes[i].isApprox(map.nodes[i], 0.0));
  }
}

TEST(Roadmap, EdgeSamplesAreEvenAndInterior) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6), b = Eigen::VectorXd::Zero(6);
  b[0] = 0.2;
  const auto s = offline::edge_samples(a, b, 0.05);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s[0][0], 0.05, 1e-12);
  EXPECT_NEAR(s[2][0], 0.15, 1e-12);
  EXPECT_TRUE(offline::edge_samples(a, a, 0.05).empty());
}
