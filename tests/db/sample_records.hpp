#pragma once

// Shared fixtures for the hila::db tests: records with awkward values and a helper that writes
// them, so every test file builds databases the same way.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "util/test_util.hpp"

namespace hila::db::test_data {

struct SamplePart {
  PartRecord part;
  std::vector<PlacementRecord> placements;
  std::vector<RobotGraspRecord> robot_grasps;
  std::vector<SuctionGraspRecord> suction_grasps;
  std::vector<HumanGraspRecord> human_grasps;
  // Schema version 3. The ids in these records (id, part_id, suction_grasp_id, candidate_id,
  // robot_grasp_id, robot_handover_id) are the ones write_sample's writer assigns.
  std::optional<HandoverStageRecord> handover_stage;
  std::vector<RobotHandoverRecord> robot_handovers;
  std::vector<HandoverCandidateRecord> handover_candidates;
  std::vector<SharedGraspRecord> shared_grasps;  // of this part's candidates
  std::vector<ErgonomicsRecord> ergonomics;
  // Schema version 4. The ids in these records (id, roadmap_id, grasp_id, robot_handover_id,
  // candidate_id, from_node, to_node, filter_id) are likewise the ones write_sample's writer
  // assigns; part_id is the part's.
  std::vector<RoadmapFilterRecord> roadmap_filters;
  std::vector<RegraspNodeRecord> regrasp_nodes;
  std::vector<RegraspEdgeRecord> regrasp_edges;
  // Schema version 5. id, candidate_id and robot_grasp_id are the ones write_sample's writer
  // assigns.
  std::vector<DirectGraspRecord> direct_grasps;  // of this part's candidates
  // Schema version 6. id, candidate_id, pick_grasp_id and robot_grasp_id are the ones
  // write_sample's writer assigns.
  std::vector<TableRegraspRecord> table_regrasps;  // of this part's candidates
  // Schema version 8. id, candidate_id and suction_grasp_id are the ones write_sample's writer
  // assigns.
  std::vector<SuctionDeliveryRecord> suction_deliveries;  // of this part's candidates
};

struct Sample {
  Meta meta;
  std::vector<SamplePart> parts;
  std::vector<ComfortMapRecord> comfort_maps;
  std::vector<RoadmapRecord> roadmaps;  // ids 1, 2, ... in order
};

inline Eigen::Vector3d random_vector(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

inline Eigen::Quaterniond random_orientation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

// A comfort map with random values, `zero_share` of them 0 (as the bins the arm never reaches),
// the others anywhere in 1..255.
inline ComfortMapRecord make_comfort_map(const std::string& arm, std::uint64_t seed,
                                         const Eigen::Vector3i& dims, int orientation_count,
                                         double zero_share = 0.9) {
  std::mt19937_64 rng(seed);
  ComfortMapRecord map;
  map.arm = arm;
  map.origin = random_vector(rng, 1.0);
  map.spacing = 0.03;
  map.dims = dims;
  for (int o = 0; o < orientation_count; ++o) map.orientations.push_back(random_orientation(rng));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> value(1, 255);
  map.values.resize(static_cast<std::size_t>(dims.prod()) * map.orientations.size());
  for (auto& v : map.values) v = u(rng) < zero_share ? 0 : static_cast<std::uint8_t>(value(rng));
  map.samples = 2000000;
  map.seed = seed | (std::uint64_t{1} << 63);  // beyond SQLite's signed integers
  map.coverage = 0.25 + 1e-17;
  return map;
}

inline Eigen::VectorXd random_joints(std::mt19937_64& rng, int count) {
  std::uniform_real_distribution<double> u(-3.14, 3.14);
  Eigen::VectorXd joints(count);
  for (int i = 0; i < count; ++i) joints[i] = u(rng);
  return joints;
}

// Handover records for the sample's two parts (written after their grasps, so their references are
// the ids the writer assigns in order). Part 1 is assembled first: no finished parts, three robot
// handovers (one with no joints), six candidates of every status whose goals are written out of
// rank order, shared grasps, and all three ergonomics methods. Part 2 (two hands, no suction
// grasps, so no robot handovers) failed: candidates but no goal, two ergonomics methods. Every
// value is finite (the writer refuses anything else in these tables) but awkward: subnormal, huge,
// -0.0 in a joint blob, non-ASCII text.
inline void add_handover_records(Sample& s, std::mt19937_64& rng) {
  std::int64_t robot_grasp_base = 0;  // robot grasp ids before this part
  std::int64_t suction_base = 0;
  std::int64_t robot_handover_id = 0;
  std::int64_t candidate_id = 0;
  std::int64_t shared_id = 0;
  for (std::size_t k = 0; k < s.parts.size(); ++k) {
    SamplePart& p = s.parts[k];
    const auto part_id = static_cast<std::int64_t>(k + 1);

    HandoverStageRecord stage;
    stage.part_id = part_id;
    if (k == 1) stage.finished_parts = {s.parts[0].part.name, "shelf 'top' / ü"};
    stage.draws = k == 0 ? 812 : 2147483647;
    stage.candidates = k == 0 ? 6 : 3;
    stage.comfortable = k == 0 ? 5 : 0;
    stage.comfortable_default_body = k == 0 ? 6 : 1;
    stage.goals = k == 0 ? 3 : 0;
    stage.robot_handovers = k == 0 ? 3 : 0;
    stage.two_hands = k == 1;
    stage.failure = k == 0 ? "" : "no comfortable pose: the board needs two hands — 手";
    p.handover_stage = stage;

    for (std::size_t i = 0; i < p.suction_grasps.size() + (p.suction_grasps.empty() ? 0 : 1); ++i) {
      RobotHandoverRecord h;
      h.id = ++robot_handover_id;
      h.part_id = part_id;
      h.board = test::random_pose(rng, 0.8);
      h.suction_grasp_id =
          suction_base + 1 + static_cast<std::int64_t>(i % p.suction_grasps.size());
      h.arm = "right";
      if (i != 1) {
        h.joints = random_joints(rng, 6);
        h.joints[2] = -0.0;
        h.joints[4] = std::numeric_limits<double>::denorm_min();
      }
      p.robot_handovers.push_back(h);
    }

    const std::vector<std::string> statuses =
        k == 0 ? std::vector<std::string>{"uncomfortable", "goal", "no_shared_grasp",
                                          "goal",          "goal", "uncomfortable"}
               : std::vector<std::string>{"uncomfortable", "uncomfortable", "uncomfortable"};
    const int goal_ranks[] = {2, 0, 1};  // the goals in id order have these ranks
    int goal = 0;
    for (std::size_t i = 0; i < statuses.size(); ++i) {
      HandoverCandidateRecord c;
      c.id = ++candidate_id;
      c.part_id = part_id;
      c.sample = static_cast<int>(3 * i + k);
      c.board = test::random_pose(rng, 0.5);
      c.distance = 0.05 * static_cast<double>(i + 1) + 1e-17;
      c.quality = i == 0 ? 1e-310 : 0.5 + 0.01 * static_cast<double>(i);
      c.status = statuses[i];
      c.rank = c.status == "goal" ? goal_ranks[goal++] : -1;
      // The bodies of meta.human_bodies (two) that take it (schema version 10): every mask of two
      // bits, on goals and on the others.
      static constexpr std::uint32_t kBodies[2][6] = {{0, 3, 1, 2, 3, 0}, {2, 0, 1}};
      c.bodies = kBodies[k][i];
      if (c.status != "uncomfortable" || i == 5) {
        c.human_arm = "right";
        c.human_grasp_id = 2 - static_cast<std::int64_t>(i % 2);
        c.human_quality = c.quality + 0.125;
      }
      if (k == 1) {
        c.second_arm = "left ✋";
        c.second_grasp_id = 3;
        c.second_quality = -1e300;
      }
      if (c.status == "goal") {
        c.human_joints = random_joints(rng, 7);
        if (goal == 2) c.second_joints = random_joints(rng, 7);
      }
      p.handover_candidates.push_back(c);

      for (std::size_t j = 0; c.status == "goal" && j < p.robot_handovers.size(); ++j) {
        SharedGraspRecord g;
        g.id = ++shared_id;
        g.candidate_id = c.id;
        g.robot_grasp_id = robot_grasp_base + 1 + static_cast<std::int64_t>((i + j) % 4);
        g.robot_handover_id = p.robot_handovers[j].id;
        g.arm = "left";
        g.joints_rr = random_joints(rng, 6);
        if (j != 2) g.joints_rh = random_joints(rng, 6);
        g.inclination_rr_deg = 12.5 * static_cast<double>(j);
        g.inclination_rh_deg = 89.999999999999986;
        p.shared_grasps.push_back(g);
      }
    }

    const std::vector<std::string> methods =
        k == 0 ? std::vector<std::string>{"hila", "table", "alone"}
               : std::vector<std::string>{"table", "alone"};
    for (std::size_t i = 0; i < methods.size(); ++i) {
      ErgonomicsRecord e;
      e.part_id = part_id;
      e.method = methods[i];
      e.reachable = i != 2;
      e.torso_flexion_deg = 17.25 * static_cast<double>(i) + 1e-13;
      e.shoulder_elevated = i == 1;
      e.reach = 0.62 + 1e-16;
      e.reorientation_deg = i == 0 ? 0.0 : 179.75;
      e.quality = 0.9 - 0.3 * static_cast<double>(i);
      e.arm = i == 2 ? "left" : "right";
      p.ergonomics.push_back(e);
    }

    robot_grasp_base += static_cast<std::int64_t>(p.robot_grasps.size());
    suction_base += static_cast<std::int64_t>(p.suction_grasps.size());
  }
}

// Component ids per node over the set edges: 0, 1, ... in order of each component's lowest node
// (as hila::offline::connected_components numbers them).
inline std::vector<int> components_of(std::size_t node_count,
                                      const std::vector<std::pair<int, int>>& edges,
                                      const std::vector<bool>& bits) {
  std::vector<int> parent(node_count);
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int n) {
    while (parent[n] != n) n = parent[n] = parent[parent[n]];
    return n;
  };
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (bits[e]) parent[root(edges[e].second)] = root(edges[e].first);
  }
  std::vector<int> component(node_count, -1);
  std::map<int, int> ids;  // root -> id
  for (std::size_t n = 0; n < node_count; ++n) {
    const int r = root(static_cast<int>(n));
    const auto it = ids.try_emplace(r, static_cast<int>(ids.size())).first;
    component[n] = it->second;
  }
  return component;
}

// Sets the filter's components from its bits and the counts from both.
inline void complete_filter(RoadmapFilterRecord& f, const RoadmapRecord& roadmap) {
  f.component = components_of(roadmap.nodes.size(), roadmap.edges, f.edges);
  f.valid_edges = static_cast<int>(std::count(f.edges.begin(), f.edges.end(), true));
  std::map<int, int> sizes;
  for (int c : f.component) ++sizes[c];
  f.components = static_cast<int>(sizes.size());
  f.largest_component = 0;
  for (const auto& entry : sizes) f.largest_component = std::max(f.largest_component, entry.second);
}

// A roadmap of `node_count` random configurations and `edge_count` distinct random edges (at most
// node_count * (node_count - 1) / 2), with awkward values: -0.0 and a subnormal in node 0,
// inclinations of exactly 0 and 90 degrees.
inline RoadmapRecord make_roadmap(const std::string& arm, std::uint64_t seed, int dof,
                                  int node_count, int edge_count) {
  std::mt19937_64 rng(seed);
  RoadmapRecord r;
  r.arm = arm;
  r.dof = dof;
  r.resolution = 0.05 + 1e-17;
  std::uniform_real_distribution<double> angle(0.0, 90.0);
  for (int n = 0; n < node_count; ++n) {
    r.nodes.push_back(random_joints(rng, dof));
    r.node_gravity.push_back(random_vector(rng, 1.0).normalized());
    r.node_inclination_deg.push_back(n == 1 ? 90.0 : n == 2 ? 0.0 : angle(rng));
  }
  if (node_count > 0) {
    r.nodes[0][1] = -0.0;
    r.nodes[0][dof - 1] = std::numeric_limits<double>::denorm_min();
    r.node_gravity[0] = Eigen::Vector3d(-0.0, 0.0, -1.0);
  }
  // A random spanning tree first (so the roadmap is connected when edge_count >= node_count - 1),
  // then other pairs by a partial Fisher-Yates shuffle (the same on every platform).
  std::vector<std::pair<int, int>> pairs;
  for (int b = 1; b < node_count; ++b) {
    r.edges.emplace_back(static_cast<int>(rng() % static_cast<std::uint64_t>(b)), b);
  }
  if (static_cast<int>(r.edges.size()) > edge_count)
    r.edges.resize(static_cast<std::size_t>(edge_count));
  for (int a = 0; a < node_count; ++a) {
    for (int b = a + 1; b < node_count; ++b) {
      if (std::find(r.edges.begin(), r.edges.end(), std::make_pair(a, b)) == r.edges.end()) {
        pairs.emplace_back(a, b);
      }
    }
  }
  for (std::size_t e = 0; r.edges.size() < static_cast<std::size_t>(edge_count); ++e) {
    std::swap(pairs[e], pairs[e + rng() % (pairs.size() - e)]);
    r.edges.push_back(pairs[e]);
  }
  for (const auto& [a, b] : r.edges) {
    r.edge_length.push_back((r.nodes[b] - r.nodes[a]).norm());
    r.edge_max_inclination_deg.push_back(
        std::max(r.node_inclination_deg[a], r.node_inclination_deg[b]) + 1e-13);
  }
  return r;
}

// A filter of `roadmap` with each edge set with probability `share`, its components and counts.
inline RoadmapFilterRecord make_filter(const RoadmapRecord& roadmap, std::int64_t roadmap_id,
                                       std::mt19937_64& rng, const std::string& grasp_kind,
                                       std::int64_t grasp_id, double theta_c_deg, double share) {
  RoadmapFilterRecord f;
  f.roadmap_id = roadmap_id;
  f.grasp_kind = grasp_kind;
  f.grasp_id = grasp_id;
  f.theta_c_deg = theta_c_deg;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (std::size_t e = 0; e < roadmap.edges.size(); ++e) f.edges.push_back(u(rng) < share);
  complete_filter(f, roadmap);
  return f;
}

inline std::vector<Eigen::VectorXd> random_solutions(std::mt19937_64& rng, int count, int dof) {
  std::vector<Eigen::VectorXd> solutions;
  for (int i = 0; i < count; ++i) solutions.push_back(random_joints(rng, dof));
  return solutions;
}

// Roadmaps and the regrasp graph: the left (gripper) arm's roadmap has 11 nodes and 13 edges (bit
// lists that are not a whole number of bytes), the right (suction) arm's 5 nodes, 7 joints and 8
// edges (exactly one byte). Part 1 has four filters, seven regrasp nodes of every kind and six
// edges of every kind (one not connected; the connected transit and transfer edges with paths via
// the roadmap and via a bridge); part 2 two filters, three nodes and two edges. Written after the
// handover records (the nodes refer to robot handovers and candidates).
inline void add_roadmap_records(Sample& s, std::mt19937_64& rng) {
  s.roadmaps.push_back(make_roadmap("left", rng(), 6, 11, 13));
  s.roadmaps.push_back(make_roadmap("right", rng(), 7, 5, 8));
  for (std::size_t i = 0; i < s.roadmaps.size(); ++i) {
    s.roadmaps[i].id = static_cast<std::int64_t>(i + 1);
  }
  const RoadmapRecord& left = s.roadmaps[0];
  const RoadmapRecord& right = s.roadmaps[1];
  const int left_dof = left.dof;
  const int right_dof = right.dof;

  SamplePart& a = s.parts[0];
  a.roadmap_filters = {make_filter(left, 1, rng, "gripper", 1, 22.0, 0.6),
                       make_filter(left, 1, rng, "gripper", 3, 90.0, 1.0),
                       make_filter(right, 2, rng, "suction", 1, 90.0, 0.5),
                       make_filter(right, 2, rng, "suction", 2, 90.0, 0.0)};
  SamplePart& b = s.parts[1];
  b.roadmap_filters = {make_filter(left, 1, rng, "gripper", 6, 11.5, 0.7),
                       make_filter(left, 1, rng, "gripper", 9, 1e-300, 0.3)};
  std::int64_t filter_id = 0;
  for (std::size_t k = 0; k < s.parts.size(); ++k) {
    for (auto& f : s.parts[k].roadmap_filters) {
      f.id = ++filter_id;
      f.part_id = static_cast<std::int64_t>(k + 1);
    }
  }

  const auto node = [&](std::int64_t part_id, const std::string& kind, const std::string& arm,
                        const std::string& grasp_kind, std::int64_t grasp_id,
                        const core::Pose& board, int solutions, int dof) {
    RegraspNodeRecord n;
    n.part_id = part_id;
    n.kind = kind;
    n.arm = arm;
    n.grasp_kind = grasp_kind;
    n.grasp_id = grasp_id;
    n.board = board;
    n.solutions = random_solutions(rng, solutions, dof);
    return n;
  };
  const core::Pose home = core::Pose::Identity();
  a.regrasp_nodes = {
      node(1, "home", "left", "", 0, home, 1, left_dof),
      node(1, "home", "right", "", 0, home, 1, right_dof),
      node(1, "pick", "left", "gripper", 1, a.part.initial, 3, left_dof),
      node(1, "pick", "right", "suction", 1, a.part.initial, 2, right_dof),
      node(1, "robot_handover", "right", "suction", 1, a.robot_handovers[0].board, 1, right_dof),
      node(1, "robot_handover", "left", "gripper", 3, a.robot_handovers[0].board, 2, left_dof),
      node(1, "human_handover", "left", "gripper", 1, a.handover_candidates[1].board, 4, left_dof),
  };
  a.regrasp_nodes[4].robot_handover_id = a.robot_handovers[0].id;
  a.regrasp_nodes[5].robot_handover_id = a.robot_handovers[0].id;
  a.regrasp_nodes[6].candidate_id = a.handover_candidates[1].id;
  a.regrasp_nodes[2].solutions[1][0] = -0.0;
  a.regrasp_nodes[2].solutions[2][5] = std::numeric_limits<double>::denorm_min();
  b.regrasp_nodes = {
      node(2, "home", "left", "", 0, home, 1, left_dof),
      node(2, "pick", "left", "gripper", 6, b.part.initial, 2, left_dof),
      node(2, "human_handover", "left", "gripper", 6, b.handover_candidates[0].board, 1, left_dof),
  };
  b.regrasp_nodes[2].candidate_id = b.handover_candidates[0].id;
  std::int64_t node_id = 0;
  for (auto& p : s.parts) {
    for (auto& n : p.regrasp_nodes) n.id = ++node_id;
  }

  const auto edge = [](std::int64_t part_id, const std::string& kind, const std::string& arm,
                       std::int64_t from, std::int64_t to, std::int64_t filter, bool connected,
                       double cost, int path_nodes) {
    RegraspEdgeRecord e;
    e.part_id = part_id;
    e.kind = kind;
    e.arm = arm;
    e.from_node = from;
    e.to_node = to;
    e.filter_id = filter;
    e.connected = connected;
    e.cost = cost;
    e.path_nodes = path_nodes;
    return e;
  };
  a.regrasp_edges = {
      edge(1, "transit", "left", 1, 3, 0, true, 1.25, 4),
      edge(1, "transfer", "left", 3, 7, 1, true, 2.5 + 1e-15, 9),
      edge(1, "transit", "right", 2, 4, 0, true, 0.75, 2),
      edge(1, "transfer", "right", 4, 5, 3, false, 0.0, 0),
      edge(1, "handover", "right", 5, 6, 0, true, 0.0, 0),
      edge(1, "transfer", "left", 6, 7, 2, true, 1e300, 2147483647),
  };
  b.regrasp_edges = {
      edge(2, "transit", "left", 8, 9, 0, false, 0.0, 0),
      edge(2, "transfer", "left", 9, 10, 5, true, std::numeric_limits<double>::denorm_min(), 2),
  };
  // The connected transit and transfer edges' paths: from the from-node's first solution through
  // `between` random waypoints to the to-node's first solution.
  const auto connect = [&](SamplePart& p, std::size_t index, const std::string& via, int between) {
    RegraspEdgeRecord& e = p.regrasp_edges[index];
    const auto first_solution = [&](std::int64_t id) {
      for (const auto& q : s.parts) {
        for (const auto& n : q.regrasp_nodes) {
          if (n.id == id) return n.solutions[0];
        }
      }
      return Eigen::VectorXd();
    };
    const Eigen::VectorXd from = first_solution(e.from_node);
    e.via = via;
    e.path = {from};
    for (int i = 0; i < between; ++i) {
      e.path.push_back(random_joints(rng, static_cast<int>(from.size())));
    }
    e.path.push_back(first_solution(e.to_node));
  };
  connect(a, 0, "roadmap", 4);
  connect(a, 1, "bridge", 1);
  connect(a, 2, "roadmap", 2);
  connect(a, 5, "roadmap", 0);  // the least: two waypoints
  connect(b, 1, "bridge", 3);
  a.regrasp_edges[1].path[1][0] = -0.0;
  a.regrasp_edges[1].path[1][4] = std::numeric_limits<double>::denorm_min();
  b.regrasp_edges[1].path[2][1] = 1e300;
  // Estimated times along the paths (schema version 9), each different: one not exactly
  // representable, a path with none estimated (0, as a migrated row), a huge one and a subnormal.
  // The edges without a path keep 0.
  a.regrasp_edges[0].duration = 6.125;
  a.regrasp_edges[1].duration = 0.1;
  a.regrasp_edges[2].duration = 0.0;
  a.regrasp_edges[5].duration = 1e300;
  b.regrasp_edges[1].duration = std::numeric_limits<double>::denorm_min();
  std::int64_t edge_id = 0;
  for (auto& p : s.parts) {
    for (auto& e : p.regrasp_edges) e.id = ++edge_id;
  }
}

// Direct grasps of part 1's three goals (part 2 has none), written with the candidates
// interleaved (2, 4, 2, 5, 4, 2, 5), so that one candidate's grasps are not consecutive ids: both
// arms, a non-ASCII arm name, a grasp without a stored pick solution (empty joints_pick), -0.0 and
// a subnormal in a joint blob, inclinations of exactly 0 and just below 90 degrees. From an RNG of
// its own, so that every other record of the sample keeps the values it had before the table.
inline void add_direct_grasps(Sample& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  SamplePart& p = s.parts[0];
  std::vector<std::int64_t> goals;  // candidate ids in id order
  for (const auto& c : p.handover_candidates) {
    if (c.status == "goal") goals.push_back(c.id);
  }
  const std::size_t goal_of[] = {0, 1, 0, 2, 1, 0, 2};
  std::int64_t id = 0;
  for (std::size_t i = 0; i < std::size(goal_of); ++i) {
    DirectGraspRecord g;
    g.id = ++id;
    g.candidate_id = goals.at(goal_of[i]);
    g.robot_grasp_id = 1 + static_cast<std::int64_t>((3 * i) % p.robot_grasps.size());
    g.arm = i == 4 ? "right ✋" : i % 3 == 1 ? "right" : "left";
    if (i != 3) g.joints_pick = random_joints(rng, 6);
    g.joints_rh = random_joints(rng, 6);
    g.inclination_pick_deg = i == 0 ? 0.0 : 11.25 * static_cast<double>(i) + 1e-13;
    g.inclination_rh_deg = i == 2 ? 89.999999999999986 : 45.5 - static_cast<double>(i);
    p.direct_grasps.push_back(g);
  }
  p.direct_grasps[0].joints_pick[1] = -0.0;
  p.direct_grasps[0].joints_pick[5] = std::numeric_limits<double>::denorm_min();
  p.direct_grasps[5].joints_rh[2] = -0.0;
}

// Table regrasps of part 1's three goals (part 2 has none), written with the candidates
// interleaved (5, 2, 4, 2, 5), so that one candidate's regrasps are not consecutive ids: both arms,
// a non-ASCII arm name, two relays (taken again by the other arm: records 1 and 4, one each way;
// the others by the arm that set it down), a regrasp that sets down and takes again with the same
// grasp, one without stored place and repick solutions (empty joints_place and joints_repick), -0.0
// and a subnormal in joint blobs, a subnormal placement coordinate, a placement turned exactly half
// about the vertical, inclinations of exactly 0 and just below 90 degrees, and four inclinations
// that differ in every record (so that no column can stand in for another). From an RNG of its
// own, so that every other record of the sample keeps the values it had before the table.
inline void add_table_regrasps(Sample& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  SamplePart& p = s.parts[0];
  std::vector<std::int64_t> goals;  // candidate ids in id order
  for (const auto& c : p.handover_candidates) {
    if (c.status == "goal") goals.push_back(c.id);
  }
  const std::size_t goal_of[] = {2, 0, 1, 0, 2};
  const auto grasps = static_cast<std::int64_t>(p.robot_grasps.size());
  std::int64_t id = 0;
  for (std::size_t i = 0; i < std::size(goal_of); ++i) {
    const auto k = static_cast<std::int64_t>(i);
    TableRegraspRecord r;
    r.id = ++id;
    r.candidate_id = goals.at(goal_of[i]);
    r.pick_grasp_id = 1 + (2 * k + 1) % grasps;
    r.robot_grasp_id = 1 + (3 * k) % grasps;
    r.arm = i == 3 ? "left ✋" : i % 2 == 0 ? "left" : "right";
    r.repick_arm = r.arm;
    r.placement = test::random_pose(rng, 0.6);
    r.joints_pick = random_joints(rng, 6);
    if (i != 2) {
      r.joints_place = random_joints(rng, 6);
      r.joints_repick = random_joints(rng, 6);
    }
    r.joints_rh = random_joints(rng, 6);
    const double base = 17.5 * static_cast<double>(i) + 1e-13;
    r.inclination_pick_deg = i == 0 ? 0.0 : base + 0.25;
    r.inclination_place_deg = base + 1.5;
    r.inclination_repick_deg = i == 4 ? 89.999999999999986 : base + 2.75;
    r.inclination_rh_deg = base + 4.0;
    p.table_regrasps.push_back(r);
  }
  p.table_regrasps[1].robot_grasp_id = p.table_regrasps[1].pick_grasp_id;  // the same grasp
  p.table_regrasps[1].repick_arm = "left";  // relays: the other arm takes it again
  p.table_regrasps[4].repick_arm = "right";
  p.table_regrasps[0].joints_place[3] = -0.0;
  p.table_regrasps[0].joints_repick[0] = std::numeric_limits<double>::denorm_min();
  p.table_regrasps[4].joints_rh[5] = -0.0;
  p.table_regrasps[4].joints_pick[2] = -std::numeric_limits<double>::denorm_min();
  p.table_regrasps[2].placement.translation().y() = std::numeric_limits<double>::denorm_min();
  core::Pose half_turn = core::Pose::Identity();
  half_turn.linear() = Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal();
  half_turn.translation() = Eigen::Vector3d(0.5, -0.25, 0.0625);
  p.table_regrasps[1].placement = half_turn;
}

// Suction deliveries of part 1's goals (part 2 has no suction grasps, so none), written with the
// candidates interleaved (4, 5, 4, 2, 5), so that one candidate's deliveries are not consecutive
// ids: both suction grasps, both arms, a non-ASCII arm name, a delivery without a stored
// robot-human solution (empty joints_rh), a 7-joint arm, -0.0 and a subnormal in a joint blob.
// From an RNG of its own, so that every other record of the sample keeps the values it had before
// the table.
inline void add_suction_deliveries(Sample& s, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  SamplePart& p = s.parts[0];
  std::vector<std::int64_t> goals;  // candidate ids in id order
  for (const auto& c : p.handover_candidates) {
    if (c.status == "goal") goals.push_back(c.id);
  }
  const std::size_t goal_of[] = {1, 2, 1, 0, 2};
  const auto grasps = static_cast<std::int64_t>(p.suction_grasps.size());
  std::int64_t id = 0;
  for (std::size_t i = 0; i < std::size(goal_of); ++i) {
    SuctionDeliveryRecord d;
    d.id = ++id;
    d.candidate_id = goals.at(goal_of[i]);
    d.suction_grasp_id = 1 + static_cast<std::int64_t>(i) % grasps;
    d.arm = i == 4 ? "right ✋" : i % 3 == 0 ? "right" : "left";
    if (i != 2) d.joints_rh = random_joints(rng, i == 3 ? 7 : 6);
    p.suction_deliveries.push_back(d);
  }
  p.suction_deliveries[0].joints_rh[1] = -0.0;
  p.suction_deliveries[4].joints_rh[5] = std::numeric_limits<double>::denorm_min();
}

// Two parts with different record counts (part 2 has no suction grasps), values that are
// negative, tiny, huge, subnormal and infinite, a non-ASCII part name, handover records (see
// add_handover_records), two comfort maps, roadmaps with the regrasp graph (see
// add_roadmap_records), direct grasps (see add_direct_grasps), table regrasps (see
// add_table_regrasps) and suction deliveries (see add_suction_deliveries).
inline Sample make_sample(std::uint64_t seed = 7) {
  std::mt19937_64 rng(seed);
  Sample s;
  s.meta.hila_version = hila_version();  // what Database::open expects by default
  s.meta.product_name = "cabinet";
  s.meta.cell_hash = std::string(64, 'c');
  s.meta.product_hash = std::string(64, 'a');
  s.meta.settings_hash = std::string(64, '5');
  s.meta.seed = std::numeric_limits<std::uint64_t>::max();  // beyond SQLite's signed integers
  s.meta.created_at = "2024-06-11T10:00:00Z";
  s.meta.cell_file = "meshes/cell/cell.yaml";
  s.meta.product_file = "meshes/cabinet/product.yaml";
  s.meta.human_bodies = "1.75 male; 1.55 female";

  for (int k = 0; k < 2; ++k) {
    SamplePart p;
    p.part.name = k == 0 ? "Gehäuse-ß-部品-🔩" : "door panel 'left'";
    p.part.assembly_order = k == 0 ? -3 : 7;
    p.part.mesh_file = k == 0 ? "meshes/cabinet/ü.stl" : "door.obj";
    p.part.mesh_hash = std::string(64, k == 0 ? 'e' : 'f');
    p.part.mass = k == 0 ? 1e-300 : 12.5;
    p.part.mass_properties.volume = k == 0 ? std::numeric_limits<double>::denorm_min() : 3.2e-3;
    p.part.mass_properties.com = random_vector(rng, 1e-9);
    Eigen::Matrix3d a;
    a << random_vector(rng, 1.0), random_vector(rng, 1.0), random_vector(rng, 1.0);
    p.part.mass_properties.inertia = (a * a.transpose()) * (k == 0 ? 1e-12 : 1e6);
    p.part.mass_properties.inertia(0, 1) = p.part.mass_properties.inertia(1, 0) = -2.5e-7;
    // Exactly symmetric (the database stores one triangle): a + b == b + a bit for bit.
    const Eigen::Matrix3d raw = p.part.mass_properties.inertia;
    p.part.mass_properties.inertia = 0.5 * (raw + raw.transpose());
    p.part.extent = Eigen::Vector3d(0.1, -1e300, 1e300);
    p.part.triangle_count = k == 0 ? 2147483647 : 0;
    p.part.target = test::random_pose(rng, 1e3);
    p.part.initial = test::random_pose(rng, 1e-6);

    for (int i = 0; i < 3 + k; ++i) {
      PlacementRecord r;
      r.part_in_plane = test::random_pose(rng);
      r.stability = -0.001 * (i + 1);
      p.placements.push_back(r);
    }
    for (int i = 0; i < 5 - k; ++i) {
      RobotGraspRecord g;
      g.tcp = test::random_pose(rng, 0.2);
      g.jaw_width = 0.001 * (i + 1) + 1e-17;
      g.contact_1 = random_vector(rng, 0.1);
      g.normal_1 = random_vector(rng, 1.0).normalized();
      g.contact_2 = random_vector(rng, 0.1);
      g.normal_2 = -g.normal_1;
      g.quality = 0.1 * i + 0.05;
      g.friction_torque_capacity = i == 0 ? std::numeric_limits<double>::infinity() : 1.0 / 3.0;
      g.lever = -1e-200;
      g.theta_c_deg = i == 1 ? 90.0 : 22.0 + i;
      p.robot_grasps.push_back(g);
    }
    for (int i = 0; k == 0 && i < 2; ++i) {
      SuctionGraspRecord g;
      g.cup = test::random_pose(rng, 0.3);
      g.rotation_deg = -179.999 + i * 90;
      g.force_margin = -std::numeric_limits<double>::infinity();
      g.moment_margin = 1e-310;  // subnormal
      p.suction_grasps.push_back(g);
    }
    for (int i = 0; i < 2; ++i) {
      HumanGraspRecord g;
      g.hand = test::random_pose(rng, 0.5);
      g.aperture = 0.07 + i * 1e-15;
      g.contact_1 = random_vector(rng, 0.05);
      g.contact_2 = random_vector(rng, 0.05);
      g.quality = 1.0 - i * std::numeric_limits<double>::epsilon();
      g.one_hand_stable = (i + k) % 2 == 0;
      p.human_grasps.push_back(g);
    }
    s.parts.push_back(p);
  }
  add_handover_records(s, rng);
  // Two small comfort maps of different shapes (the values' size is what the writer checks).
  s.comfort_maps.push_back(make_comfort_map("right", seed + 1, {4, 3, 2}, 10));
  s.comfort_maps.push_back(make_comfort_map("left", seed + 2, {2, 5, 3}, 7, 0.5));
  add_roadmap_records(s, rng);
  add_direct_grasps(s, seed + 3);
  add_table_regrasps(s, seed + 4);
  add_suction_deliveries(s, seed + 5);
  return s;
}

// Writes `sample` to `path` through DatabaseWriter and returns the part ids in order: first each
// part with its placements and grasps, then each part's handover, direct grasp, table regrasp,
// suction delivery and ergonomics records (so they may refer to grasps of any part), then the
// comfort maps, the roadmaps and each part's roadmap filters, regrasp nodes and regrasp edges. The
// candidate, robot handover, roadmap, filter and node ids the records refer to are translated from
// the sample's ids to the ones the writer returns (the same unless a test reorders the sample's
// parts); grasp ids are written as given.
inline std::vector<std::int64_t> write_sample(const std::string& path, const Sample& sample) {
  DatabaseWriter writer(path);
  writer.write_meta(sample.meta);
  std::vector<std::int64_t> ids;
  for (const auto& p : sample.parts) {
    const std::int64_t id = writer.add_part(p.part);
    writer.add_placements(id, p.placements);
    writer.add_robot_grasps(id, p.robot_grasps);
    writer.add_suction_grasps(id, p.suction_grasps);
    writer.add_human_grasps(id, p.human_grasps);
    ids.push_back(id);
  }
  std::map<std::int64_t, std::int64_t> handover_ids;
  std::map<std::int64_t, std::int64_t> candidate_ids;
  const auto remember = [](std::map<std::int64_t, std::int64_t>& map, const auto& records,
                           const std::vector<std::int64_t>& written) {
    for (std::size_t i = 0; i < records.size(); ++i) map[records[i].id] = written.at(i);
  };
  const auto translate = [](const std::map<std::int64_t, std::int64_t>& map, std::int64_t id) {
    const auto it = map.find(id);
    return it == map.end() ? id : it->second;
  };
  for (std::size_t k = 0; k < sample.parts.size(); ++k) {
    const SamplePart& p = sample.parts[k];
    if (p.handover_stage) {
      HandoverStageRecord stage = *p.handover_stage;
      stage.part_id = ids[k];
      writer.add_handover_stage(stage);
    }
    remember(handover_ids, p.robot_handovers,
             writer.add_robot_handovers(ids[k], p.robot_handovers));
    remember(candidate_ids, p.handover_candidates,
             writer.add_handover_candidates(ids[k], p.handover_candidates));
    std::vector<SharedGraspRecord> shared = p.shared_grasps;
    for (auto& g : shared) {
      g.candidate_id = translate(candidate_ids, g.candidate_id);
      g.robot_handover_id = translate(handover_ids, g.robot_handover_id);
    }
    writer.add_shared_grasps(shared);
    std::vector<DirectGraspRecord> direct = p.direct_grasps;
    for (auto& g : direct) g.candidate_id = translate(candidate_ids, g.candidate_id);
    writer.add_direct_grasps(direct);
    std::vector<TableRegraspRecord> regrasps = p.table_regrasps;
    for (auto& r : regrasps) r.candidate_id = translate(candidate_ids, r.candidate_id);
    writer.add_table_regrasps(regrasps);
    std::vector<SuctionDeliveryRecord> deliveries = p.suction_deliveries;
    for (auto& d : deliveries) d.candidate_id = translate(candidate_ids, d.candidate_id);
    writer.add_suction_deliveries(deliveries);
    writer.add_ergonomics(ids[k], p.ergonomics);
  }
  for (const auto& map : sample.comfort_maps) writer.add_comfort_map(map);
  std::map<std::int64_t, std::int64_t> roadmap_ids;
  for (const auto& roadmap : sample.roadmaps) roadmap_ids[roadmap.id] = writer.add_roadmap(roadmap);
  std::map<std::int64_t, std::int64_t> filter_ids;
  std::map<std::int64_t, std::int64_t> node_ids;
  for (std::size_t k = 0; k < sample.parts.size(); ++k) {
    const SamplePart& p = sample.parts[k];
    std::vector<RoadmapFilterRecord> filters = p.roadmap_filters;
    for (auto& f : filters) {
      f.part_id = ids[k];
      f.roadmap_id = translate(roadmap_ids, f.roadmap_id);
    }
    remember(filter_ids, p.roadmap_filters, writer.add_roadmap_filters(filters));
    std::vector<RegraspNodeRecord> nodes = p.regrasp_nodes;
    for (auto& n : nodes) {
      n.part_id = ids[k];
      n.robot_handover_id = translate(handover_ids, n.robot_handover_id);
      n.candidate_id = translate(candidate_ids, n.candidate_id);
    }
    remember(node_ids, p.regrasp_nodes, writer.add_regrasp_nodes(nodes));
    std::vector<RegraspEdgeRecord> edges = p.regrasp_edges;
    for (auto& e : edges) {
      e.part_id = ids[k];
      e.from_node = translate(node_ids, e.from_node);
      e.to_node = translate(node_ids, e.to_node);
      e.filter_id = translate(filter_ids, e.filter_id);
    }
    writer.add_regrasp_edges(edges);
  }
  writer.commit();
  return ids;
}

// SQL that turns a current file's regrasp_edges back into the table of schema versions 4 to 8
// (without duration), every other value kept: for a version 8 (or older) file made from the
// sample. The table's CREATE text (and its index's) is the 3 -> 4 step's, which is never edited,
// so the file declares the table as the hila of those versions wrote it.
inline std::string regrasp_edges_before_v9_sql() {
  const std::string& step_v4 = detail::migration_steps().at(2).sql;
  return "DROP INDEX regrasp_edges_part_id;\n"
         "ALTER TABLE regrasp_edges RENAME TO regrasp_edges_v9;\n" +
         step_v4.substr(step_v4.find("CREATE TABLE regrasp_edges (")) +
         "INSERT INTO regrasp_edges SELECT id, part_id, kind, arm, from_node, to_node, filter_id, "
         "connected, cost, path_nodes, via, path_dof, path_waypoints, path FROM regrasp_edges_v9 "
         "ORDER BY id;\n"
         "DROP TABLE regrasp_edges_v9;\n";
}

// The sample as a file migrated from version 8 or earlier holds it: no edge's duration estimated.
inline void clear_durations(Sample& sample) {
  for (auto& p : sample.parts) {
    for (auto& e : p.regrasp_edges) e.duration = 0.0;
  }
}

// SQL that turns a current file's handover_candidates back into the table of schema versions 3 to
// 9 (without bodies), every other value kept: for a version 9 (or older) file made from the
// sample. SQLite's DROP COLUMN cuts the column's text out of the CREATE statement, which leaves it
// exactly as the 2 -> 3 step declares the table (test_migration checks it), and rewrites no
// table referring to it.
inline std::string handover_candidates_before_v10_sql() {
  return "ALTER TABLE handover_candidates DROP COLUMN bodies;\n";
}

// The sample as a file migrated from version 9 or earlier holds it: no candidate's bodies.
inline void clear_bodies(Sample& sample) {
  for (auto& p : sample.parts) {
    for (auto& c : p.handover_candidates) c.bodies = 0;
  }
}

// Largest absolute difference between two poses' 4x4 matrices.
inline double pose_error(const core::Pose& a, const core::Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

}  // namespace hila::db::test_data
