#include "hila/offline/regrasp.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <tuple>

#include "hila/core/error.hpp"
#include "hila/core/roadmap_graph.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/offline/arm_workspace.hpp"
#include "hila/offline/bridge.hpp"
#include "hila/offline/suction_pick.hpp"

namespace hila::offline {

namespace {

// The gripper opens a little wider than the board while it closes or lets go.
constexpr double kJawMargin = 0.005;

// One arm's roadmap with its search structure and workspace.
struct ArmPlanning {
  const Roadmap& roadmap;
  core::RoadmapGraph graph;
  ArmWorkspace workspace;
  std::vector<bool> all_edges;
};

struct Connection {
  bool connected = false;
  double cost = 0.0;
  int path_nodes = 0;
  std::string via;  // "roadmap" or "bridge"
  std::vector<Eigen::VectorXd> path;
};

double path_length(const std::vector<Eigen::VectorXd>& path) {
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  return length;
}

// Shortest path from `from` to `to` over the allowed edges, both ends attached by straight edges
// that keep the slip limit and the workspace's validity (as the workspace currently holds);
// where the filtered roadmap is cut, a bridge planned under the same checks.
Connection connect(ArmPlanning& arm, const std::vector<bool>& allowed, const GraspSlip& slip,
                   const Eigen::VectorXd& from, const Eigen::VectorXd& to, int k,
                   core::GraphSearchWorkspace& search, const BridgeSettings& bridge) {
  Connection c;
  const auto entries = attach_configuration(arm.workspace, arm.roadmap, slip, from, k);
  const auto exits = entries.empty()
                         ? std::vector<Attachment>{}
                         : attach_configuration(arm.workspace, arm.roadmap, slip, to, k);
  if (!exits.empty()) {
    std::vector<core::GraphEndpoint> in, out;
    for (const auto& a : entries) in.push_back({a.node, a.cost});
    for (const auto& a : exits) out.push_back({a.node, a.cost});
    const core::GraphPath path = core::shortest_path(arm.graph, allowed, in, out, search);
    if (path.found) {
      c.connected = true;
      c.via = "roadmap";
      c.path_nodes = static_cast<int>(path.nodes.size());
      c.path.push_back(from);
      for (const int n : path.nodes)
        c.path.push_back(arm.roadmap.nodes[static_cast<std::size_t>(n)]);
      c.path.push_back(to);
      c.cost = path_length(c.path);
      return c;
    }
  }
  const SlipTest holds(slip);
  const Eigen::Matrix3d base_rotation = arm.workspace.base().linear();
  auto valid = [&](const Eigen::VectorXd& q) {
    return holds(gravity_in_tcp(arm.workspace.arm(), base_rotation, q)) && arm.workspace.valid(q);
  };
  c.path = plan_bridge(arm.workspace.arm(), valid, from, to, bridge);
  if (c.path.empty()) return c;
  c.connected = true;
  c.via = "bridge";
  c.cost = path_length(c.path);
  return c;
}

db::RoadmapFilterRecord make_filter(const Roadmap& roadmap, std::int64_t roadmap_index,
                                    const std::string& kind, std::int64_t grasp, double theta_c_deg,
                                    std::vector<bool> edges) {
  db::RoadmapFilterRecord f;
  f.roadmap_id = roadmap_index;
  f.grasp_kind = kind;
  f.grasp_id = grasp;
  f.theta_c_deg = theta_c_deg;
  f.component = connected_components(roadmap, edges);
  f.valid_edges = static_cast<int>(std::count(edges.begin(), edges.end(), true));
  std::vector<int> sizes;
  for (const int id : f.component) {
    if (id >= static_cast<int>(sizes.size())) sizes.resize(static_cast<std::size_t>(id) + 1, 0);
    ++sizes[static_cast<std::size_t>(id)];
  }
  f.components = static_cast<int>(sizes.size());
  f.largest_component = sizes.empty() ? 0 : *std::max_element(sizes.begin(), sizes.end());
  f.edges = std::move(edges);
  return f;
}

}  // namespace

GraspSlip grasp_slip(const core::Cell& cell, const db::RobotGraspRecord& grasp,
                     const Eigen::Vector3d& com) {
  const Eigen::Vector3d opening_tcp = cell.spec().gripper.opening_axis.normalized();
  const Eigen::Vector3d axis_part = grasp.tcp.linear() * opening_tcp;
  const Eigen::Vector3d lever_part =
      core::lever_direction(axis_part, 0.5 * (grasp.contact_1 + grasp.contact_2), com);
  GraspSlip s;
  s.axis = opening_tcp;
  s.lever = grasp.tcp.linear().transpose() * lever_part;
  s.theta_c_deg = grasp.theta_c_deg;
  return s;
}

RegraspResult plan_regrasp(const core::Cell& cell, const core::ProductSpec& product,
                           std::size_t index, const BoardGrasps& grasps,
                           const HandoverResult& handover, const Roadmap& suction_roadmap,
                           const Roadmap& receiving_roadmap, const RegraspSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const core::PartSpec& part = product.parts[index];
  RegraspResult result;
  auto finish = [&](const std::string& failure) {
    result.failure = failure;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };

  // Goals in Eq. 8 order and their shared grasps.
  std::vector<int> goals;
  for (std::size_t c = 0; c < handover.candidates.size(); ++c) {
    const int rank = handover.candidates[c].rank;
    if (rank >= 0 && rank < settings.goals) goals.push_back(static_cast<int>(c));
  }
  std::sort(goals.begin(), goals.end(), [&](int a, int b) {
    return handover.candidates[static_cast<std::size_t>(a)].rank <
           handover.candidates[static_cast<std::size_t>(b)].rank;
  });
  if (goals.empty()) {
    return finish(handover.stage.failure.empty() ? "the board has no handover goal"
                                                 : handover.stage.failure);
  }
  std::vector<std::size_t> shared;
  for (const int c : goals) {
    for (std::size_t s = 0; s < handover.shared.size(); ++s) {
      if (handover.shared[s].candidate_id == c) shared.push_back(s);
    }
  }

  ArmPlanning suction{suction_roadmap,
                      core::RoadmapGraph(suction_roadmap.nodes, suction_roadmap.edges),
                      ArmWorkspace(cell, settings.suction_arm, settings.suction_arm, &part.mesh),
                      std::vector<bool>(suction_roadmap.edges.size(), true)};
  ArmPlanning receiving{
      receiving_roadmap, core::RoadmapGraph(receiving_roadmap.nodes, receiving_roadmap.edges),
      ArmWorkspace(cell, settings.receiving_arm, settings.suction_arm, &part.mesh),
      std::vector<bool>(receiving_roadmap.edges.size(), true)};
  core::GraphSearchWorkspace search;
  std::uint64_t bridges = 0;
  auto bridge = [&] {
    BridgeSettings b = settings.bridge;
    b.resolution = receiving_roadmap.resolution;
    b.seed = settings.seed + 0x9E3779B97F4A7C15ULL * ++bridges;
    return b;
  };
  const GraspSlip no_slip_limit;  // theta_c 90: any tilt
  const int k = settings.attach_neighbours;
  const core::Pose cup_in_tcp = suction.workspace.scene().cup_in_tcp;

  auto add_node = [&](const std::string& kind, const std::string& arm,
                      const std::string& grasp_kind, std::int64_t grasp, std::int64_t rr,
                      std::int64_t candidate, const core::Pose& board,
                      std::vector<Eigen::VectorXd> solutions) {
    db::RegraspNodeRecord n;
    n.kind = kind;
    n.arm = arm;
    n.grasp_kind = grasp_kind;
    n.grasp_id = grasp;
    n.robot_handover_id = rr;
    n.candidate_id = candidate;
    n.board = board;
    n.solutions = std::move(solutions);
    result.nodes.push_back(std::move(n));
    return static_cast<int>(result.nodes.size()) - 1;
  };
  auto add_edge = [&](const std::string& kind, const std::string& arm, int from, int to, int filter,
                      const Connection& c) {
    db::RegraspEdgeRecord e;
    e.kind = kind;
    e.arm = arm;
    e.from_node = from;
    e.to_node = to;
    e.filter_id = filter;
    e.connected = c.connected;
    e.cost = c.connected ? c.cost : 0.0;
    e.path_nodes = c.connected ? c.path_nodes : 0;
    e.via = c.connected ? c.via : "";
    if (c.connected) e.path = c.path;
    result.edges.push_back(e);
    result.bridges += c.connected && c.via == "bridge" ? 1 : 0;
    return static_cast<int>(result.edges.size()) - 1;
  };

  const int home_suction = add_node("home", settings.suction_arm, "", -1, -1, -1,
                                    core::Pose::Identity(), {suction.workspace.arm().spec.home});
  const int home_receiving =
      add_node("home", settings.receiving_arm, "", -1, -1, -1, core::Pose::Identity(),
               {receiving.workspace.arm().spec.home});

  // --- Suction arm: pick from the stack, lift, transfer to each robot-robot pose -------------
  struct Pick {
    int node = -1;
    bool transit = false;  // home -> pick connected
    Eigen::VectorXd lift;  // joints after the lift (empty: no collision-free lift)
    int filter = -1;
  };
  std::map<std::int64_t, Pick> picks;        // by suction grasp index
  std::map<std::int64_t, int> rr_nodes;      // robot handover -> node
  std::map<std::int64_t, bool> rr_transfer;  // robot handover -> pick->rr connected
  const core::Arm& suction_arm = suction.workspace.arm();
  auto pick_for = [&](std::int64_t s) -> Pick& {
    auto it = picks.find(s);
    if (it != picks.end()) return it->second;
    Pick& p = picks[s];
    const auto& grasp = grasps.suction[static_cast<std::size_t>(s)];
    const core::Pose board_in_tcp = cup_in_tcp * grasp.cup.inverse();
    const SuctionPick plan = plan_suction_pick(suction.workspace, part.initial, grasp,
                                               settings.lift, suction_roadmap.resolution);
    const std::vector<Eigen::VectorXd>& solutions = plan.solutions;
    const Eigen::VectorXd& lift = plan.lift;
    if (solutions.empty()) return p;
    p.lift = lift;
    p.node = add_node("pick", settings.suction_arm, "suction", s, -1, -1, part.initial, solutions);
    // Transit: the tool-carrying arm from home to the pick (the board stands in the stack).
    suction.workspace.place_board(part.initial);
    const Connection transit =
        connect(suction, suction.all_edges, no_slip_limit, suction_arm.spec.home, solutions.front(),
                k, search, bridge());
    suction.workspace.release();
    add_edge("transit", settings.suction_arm, home_suction, p.node, -1, transit);
    p.transit = transit.connected;
    // The suction grasp's filter: the board on the cup clear of the static cell.
    suction.workspace.hold(board_in_tcp, 0.0);
    result.filters.push_back(
        make_filter(suction_roadmap, 0, "suction", s, 90.0,
                    held_board_filter(suction.workspace, suction_roadmap, suction.all_edges)));
    suction.workspace.release();
    p.filter = static_cast<int>(result.filters.size()) - 1;
    return p;
  };
  auto rr_node_for = [&](std::int64_t r) {
    auto it = rr_nodes.find(r);
    if (it != rr_nodes.end()) return it->second;
    const auto& rr = handover.robot_handovers[static_cast<std::size_t>(r)];
    const int node = add_node("robot_handover", settings.suction_arm, "suction",
                              rr.suction_grasp_id, r, -1, rr.board, {rr.joints});
    rr_nodes[r] = node;
    const Pick& pick = pick_for(rr.suction_grasp_id);
    Connection transfer;
    if (pick.node >= 0 && pick.lift.size() > 0) {
      const auto& grasp = grasps.suction[static_cast<std::size_t>(rr.suction_grasp_id)];
      suction.workspace.hold(cup_in_tcp * grasp.cup.inverse(), 0.0);
      transfer = connect(suction, result.filters[static_cast<std::size_t>(pick.filter)].edges,
                         no_slip_limit, pick.lift, rr.joints, k, search, bridge());
      suction.workspace.release();
      if (transfer.connected) {  // the path starts at the pick, below the lift
        transfer.path.insert(transfer.path.begin(),
                             result.nodes[static_cast<std::size_t>(pick.node)].solutions.front());
        transfer.cost = path_length(transfer.path);
      }
    }
    if (pick.node >= 0) {
      add_edge("transfer", settings.suction_arm, pick.node, node, pick.filter, transfer);
    }
    rr_transfer[r] = pick.node >= 0 && pick.transit && transfer.connected;
    return node;
  };

  // --- Receiving arm: transit to the robot-robot pose, handover, transfer to the human -------
  std::map<std::int64_t, int> gripper_filters;  // robot grasp -> filter
  auto gripper_filter_for = [&](std::int64_t g) {
    auto it = gripper_filters.find(g);
    if (it != gripper_filters.end()) return it->second;
    const auto& grasp = grasps.robot[static_cast<std::size_t>(g)];
    const GraspSlip slip = grasp_slip(cell, grasp, grasps.com);
    receiving.workspace.hold(grasp.tcp.inverse(),
                             std::min(cell.spec().gripper.jaw_max, grasp.jaw_width + kJawMargin));
    result.filters.push_back(make_filter(receiving_roadmap, 1, "gripper", g, grasp.theta_c_deg,
                                         held_board_filter(receiving.workspace, receiving_roadmap,
                                                           slip_filter(receiving_roadmap, slip))));
    receiving.workspace.release();
    const int f = static_cast<int>(result.filters.size()) - 1;
    gripper_filters[g] = f;
    return f;
  };
  std::map<std::pair<std::int64_t, std::int64_t>, std::pair<int, bool>> rr_left;  // (r, g)
  auto rr_left_for = [&](const db::SharedGraspRecord& s) {
    const auto key = std::make_pair(s.robot_handover_id, s.robot_grasp_id);
    auto it = rr_left.find(key);
    if (it != rr_left.end()) return it->second;
    const auto& rr = handover.robot_handovers[static_cast<std::size_t>(s.robot_handover_id)];
    const int node = add_node("robot_handover", settings.receiving_arm, "gripper", s.robot_grasp_id,
                              s.robot_handover_id, -1, rr.board, {s.joints_rr});
    const Connection transit =
        connect(receiving, receiving.all_edges, no_slip_limit, receiving.workspace.arm().spec.home,
                s.joints_rr, k, search, bridge());
    add_edge("transit", settings.receiving_arm, home_receiving, node, -1, transit);
    Connection exchange;
    exchange.connected = true;
    add_edge("handover", settings.receiving_arm, rr_node_for(s.robot_handover_id), node, -1,
             exchange);
    rr_left[key] = {node, transit.connected};
    return rr_left[key];
  };

  // Goals in Eq. 8 order; each goal's shared grasps until one connects the whole chain. Filters
  // are made when a grasp is first needed, and the search stops after `served_goals` goals:
  // the online planner tries the goals in the same order.
  std::size_t next_shared = 0;
  for (const int c : goals) {
    if (result.goals_served >= settings.served_goals) break;
    ++result.goals_considered;
    bool served = false;
    for (; next_shared < shared.size() && handover.shared[shared[next_shared]].candidate_id == c;
         ++next_shared) {
      if (served) continue;  // the goal's remaining grasps are not needed
      const auto& s = handover.shared[shared[next_shared]];
      ++result.shared_grasps;
      const auto [rr_node, transit_ok] = rr_left_for(s);
      // Only a grasp whose chain up to the exchange connects is worth its filter.
      if (!transit_ok || !rr_transfer[s.robot_handover_id]) {
        ++result.cut_before_exchange;
        continue;
      }
      const int filter = gripper_filter_for(s.robot_grasp_id);
      const auto& candidate = handover.candidates[static_cast<std::size_t>(s.candidate_id)];
      const int rh_node =
          add_node("human_handover", settings.receiving_arm, "gripper", s.robot_grasp_id, -1,
                   s.candidate_id, candidate.board, {s.joints_rh});
      const auto& grasp = grasps.robot[static_cast<std::size_t>(s.robot_grasp_id)];
      receiving.workspace.hold(grasp.tcp.inverse(),
                               std::min(cell.spec().gripper.jaw_max, grasp.jaw_width + kJawMargin));
      const Connection transfer = connect(
          receiving, result.filters[static_cast<std::size_t>(filter)].edges,
          grasp_slip(cell, grasp, grasps.com), s.joints_rr, s.joints_rh, k, search, bridge());
      receiving.workspace.release();
      add_edge("transfer", settings.receiving_arm, rr_node, rh_node, filter, transfer);
      ++result.transfers;
      result.transfers_connected += transfer.connected ? 1 : 0;
      served = transfer.connected;
    }
    if (!served) continue;
    ++result.goals_served;
    if (result.first_served_rank < 0) {
      result.first_served_rank = handover.candidates[static_cast<std::size_t>(c)].rank;
    }
  }
  if (result.goals_served == 0) {
    return finish("none of the first " + std::to_string(result.goals_considered) +
                  " goals connects home -> pick -> robot-robot -> robot-human in the roadmaps (" +
                  std::to_string(result.shared_grasps) +
                  " shared grasps tried: " + std::to_string(result.cut_before_exchange) +
                  " cut before the exchange, " + std::to_string(result.transfers_connected) +
                  " of " + std::to_string(result.transfers) +
                  " receiving-arm transfers connected within their filters)");
  }
  return finish("");
}

}  // namespace hila::offline
