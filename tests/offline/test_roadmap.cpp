#include <gtest/gtest.h>

#include <random>

#include "hila/core/collision.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
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
    // Inside the roadmap's joint box around home.
    EXPECT_TRUE((q.array() >= offline::roadmap_lower(ref.arm, small_settings()).array()).all());
    EXPECT_TRUE((q.array() <= offline::roadmap_upper(ref.arm, small_settings()).array()).all());
    // Joints that turn more than once each way stay within one turn around home; the elbow
    // (+-pi) spans its limits.
    const double range = small_settings().joint_range;
    for (int j = 0; j < q.size(); ++j) {
      const double span = ref.arm.chain.upper_limits()[j] - ref.arm.chain.lower_limits()[j];
      if (span > 2.0 * range + 1e-9) {
        EXPECT_LE(std::abs(q[j] - ref.arm.spec.home[j]), range + 1e-12);
      }
    }
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

// The filter against a recomputation from scratch: FK of every sample (not the stored gravity),
// the gravity torque about the grasp axis against m g r sin(theta_c).
TEST(Roadmap, SlipFilterEqualsRecomputationFromFk) {
  const auto& map = small_roadmap();
  const auto cell = test::reference_cell();
  const core::Arm& arm = cell->arm("left");
  const core::Pose base = core::arm_base_in_world(*cell, arm);
  // Grasps of a board held at its edge: axis = TCP y, CoM straight ahead along the approach,
  // and one with the CoM off to the side; a 1.8 kg lateral's 11 and 22 degrees.
  const std::vector<offline::GraspSlip> grasps = {
      {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 11.0},
      {Eigen::Vector3d::UnitY(), Eigen::Vector3d(1, 0, 1).normalized(), 22.0},
      {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitX(), 90.0}};
  const double lever = 0.25, weight = 1.8 * 9.81;
  for (const auto& g : grasps) {
    const auto filter = offline::slip_filter(map, g);
    auto holds = [&](const Eigen::VectorXd& q) {
      const core::Pose tcp = base * arm.chain.fk(q);
      const Eigen::Vector3d axis = tcp.linear() * g.axis;
      const Eigen::Vector3d r = tcp.linear() * g.lever * lever;  // contact centre -> CoM
      const double torque = std::abs(axis.dot(r.cross(Eigen::Vector3d(0, 0, -weight))));
      return torque <= weight * lever * std::sin(core::deg_to_rad(g.theta_c_deg)) + 1e-9;
    };
    int kept = 0;
    for (std::size_t e = 0; e < map.edges.size(); ++e) {
      const auto& a = map.nodes[static_cast<std::size_t>(map.edges[e].first)];
      const auto& b = map.nodes[static_cast<std::size_t>(map.edges[e].second)];
      bool ok = holds(a) && holds(b);
      for (const auto& q : offline::edge_samples(a, b, map.resolution)) ok = ok && holds(q);
      ASSERT_EQ(filter[e], ok) << "edge " << e << " theta_c " << g.theta_c_deg;
      kept += ok ? 1 : 0;
    }
    if (g.theta_c_deg >= 90.0) {
      EXPECT_EQ(kept, static_cast<int>(map.edges.size()));
    } else {
      EXPECT_GT(kept, 0);
      EXPECT_LT(kept, static_cast<int>(map.edges.size()));
    }
  }
}

TEST(Roadmap, ComponentsAgreeWithBreadthFirstSearch) {
  const auto& map = small_roadmap();
  const auto filter =
      offline::slip_filter(map, {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 15.0});
  const auto ids = offline::connected_components(map, filter);
  std::vector<std::vector<int>> adjacent(map.nodes.size());
  for (std::size_t e = 0; e < map.edges.size(); ++e) {
    if (!filter[e]) continue;
    adjacent[static_cast<std::size_t>(map.edges[e].first)].push_back(map.edges[e].second);
    adjacent[static_cast<std::size_t>(map.edges[e].second)].push_back(map.edges[e].first);
  }
  std::vector<int> bfs(map.nodes.size(), -1);
  int next = 0;
  for (std::size_t s = 0; s < map.nodes.size(); ++s) {
    if (bfs[s] >= 0) continue;
    std::vector<int> queue{static_cast<int>(s)};
    bfs[s] = next;
    for (std::size_t k = 0; k < queue.size(); ++k) {
      for (const int n : adjacent[static_cast<std::size_t>(queue[k])]) {
        if (bfs[static_cast<std::size_t>(n)] < 0) {
          bfs[static_cast<std::size_t>(n)] = next;
          queue.push_back(n);
        }
      }
    }
    ++next;
  }
  EXPECT_EQ(ids, bfs);
  EXPECT_GT(next, 1);  // a tight limit cuts the roadmap
}

TEST(Roadmap, AttachingAConfigurationRespectsTheSlipLimit) {
  const auto& map = small_roadmap();
  const auto cell = test::reference_cell();
  const offline::GraspSlip loose{Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 90.0};
  // A node attaches to itself (a zero-length edge) and to some neighbours.
  offline::ArmWorkspace workspace(*cell, "left", "right");
  const auto self = offline::attach_configuration(workspace, map, loose, map.nodes[0], 10);
  ASSERT_FALSE(self.empty());
  EXPECT_EQ(self.front().node, 0);
  EXPECT_EQ(self.front().cost, 0.0);
  for (const auto& a : self) {
    EXPECT_NEAR(a.cost, (map.nodes[static_cast<std::size_t>(a.node)] - map.nodes[0]).norm(), 1e-12);
  }
  // Under a 1-degree limit, a node that violates it attaches to nothing; every attachment of a
  // node within it is a node within it.
  const offline::GraspSlip tight{Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 1.0};
  const Eigen::Vector3d normal = tight.axis.cross(tight.lever);
  int checked = 0;
  for (std::size_t i = 0; i < map.nodes.size() && checked < 8; ++i, ++checked) {
    const bool within =
        std::abs(map.node_gravity[i].dot(normal)) <= std::sin(core::deg_to_rad(1.0));
    const auto attached = offline::attach_configuration(workspace, map, tight, map.nodes[i], 10);
    if (!within) {
      EXPECT_TRUE(attached.empty()) << i;
    }
    for (const auto& a : attached) {
      EXPECT_LE(std::abs(map.node_gravity[static_cast<std::size_t>(a.node)].dot(normal)),
                std::sin(core::deg_to_rad(1.0)) + 1e-12);
    }
  }
}
