#include "hila/offline/regrasp.hpp"

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <tuple>

#include "hila/core/bridge.hpp"
#include "hila/core/error.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/pre_grasp.hpp"
#include "hila/core/roadmap_graph.hpp"
#include "hila/core/slip_projection.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/core/time_parameterization.hpp"
#include "hila/offline/arm_workspace.hpp"
#include "hila/offline/suction_pick.hpp"

namespace hila::offline {

namespace {

// The gripper opens a little wider than the board while it closes or lets go.
constexpr double kJawMargin = 0.005;

// One arm's roadmap with its search structure and workspace.
struct ArmPlanning {
  const Roadmap& roadmap;
  const core::RoadmapGraph& graph;  // of the roadmap, shared by every workspace of the arm
  ArmWorkspace workspace;
  std::vector<bool> all_edges;
  double held_resolution = 0.01;  // rad, motions with the board in hand (the online planner's)
};

// A long held board sweeps centimetres between the roadmap's samples: motions holding it are
// checked as finely as the online planner and validator check them.
double check_resolution(const ArmPlanning& arm) {
  return arm.workspace.holding() ? std::min(arm.held_resolution, arm.roadmap.resolution)
                                 : arm.roadmap.resolution;
}

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

// A configuration and the roadmap nodes it attaches to (straight edges keeping the slip limit
// and the workspace's validity as it currently holds), computed once however many queries use it.
struct Endpoint {
  Eigen::VectorXd q;
  std::vector<Attachment> attached;
};

Endpoint endpoint(ArmPlanning& arm, const GraspSlip& slip, const Eigen::VectorXd& q, int k) {
  return {q, attach_configuration(arm.workspace, arm.roadmap, slip, q, k, check_resolution(arm))};
}

// A roadmap edge valid in the workspace as it holds (the arm and the held board against the
// board's stage): the roadmap itself was checked in the empty cell, the filters for the held
// board only.
bool edge_valid_here(ArmPlanning& arm, int a, int b) {
  const auto& nodes = arm.roadmap.nodes;
  for (const auto& q : edge_samples(nodes[static_cast<std::size_t>(a)],
                                    nodes[static_cast<std::size_t>(b)], check_resolution(arm))) {
    if (!arm.workspace.valid(q)) return false;
  }
  return true;
}

// A configuration's validity for a motion of the arm: the slip limit and the workspace as it
// currently holds (what a bridge and a shortcut check; a filtered roadmap edge keeps the slip
// limit by construction).
std::function<bool(const Eigen::VectorXd&)> valid_under(ArmPlanning& arm, const GraspSlip& slip) {
  return [&arm, holds = SlipTest(slip),
          base_rotation =
              Eigen::Matrix3d(arm.workspace.base().linear())](const Eigen::VectorXd& q) {
    return holds(gravity_in_tcp(arm.workspace.arm(), base_rotation, q)) && arm.workspace.valid(q);
  };
}

// Shortest path between two attached configurations over the allowed edges, its edges
// validated lazily at the board's stage (a blocked edge is dropped and the search repeated),
// then shortened by straight shortcuts under `slip` and the workspace: the online planner
// follows the stored path and shortens it within a small check budget, which a long roadmap
// path can exhaust; here it is done once, without a budget.
Connection roadmap_path(ArmPlanning& arm, const GraspSlip& slip, std::vector<bool> allowed,
                        const Endpoint& from, const Endpoint& to,
                        core::GraphSearchWorkspace& search) {
  constexpr int kMaxSearches = 100;
  Connection c;
  if (from.attached.empty() || to.attached.empty()) return c;
  std::vector<core::GraphEndpoint> in, out;
  for (const auto& a : from.attached) in.push_back({a.node, a.cost});
  for (const auto& a : to.attached) out.push_back({a.node, a.cost});
  core::GraphPath path;
  for (int searches = 0; searches < kMaxSearches; ++searches) {
    path = core::shortest_path(arm.graph, allowed, in, out, search);
    if (!path.found) return c;
    bool clear = true;
    for (std::size_t i = 1; i < path.nodes.size() && clear; ++i) {
      const int a = path.nodes[i - 1];
      const int b = path.nodes[i];
      for (auto it = arm.graph.neighbours_begin(a); it != arm.graph.neighbours_end(a); ++it) {
        if (it->node != b || !allowed[static_cast<std::size_t>(it->edge)]) continue;
        if (!edge_valid_here(arm, a, b)) {
          allowed[static_cast<std::size_t>(it->edge)] = false;
          clear = false;
        }
        break;
      }
    }
    if (clear) break;
    path.found = false;
  }
  if (!path.found) return c;
  c.connected = true;
  c.via = "roadmap";
  c.path_nodes = static_cast<int>(path.nodes.size());
  c.path.push_back(from.q);
  for (const int n : path.nodes) c.path.push_back(arm.roadmap.nodes[static_cast<std::size_t>(n)]);
  c.path.push_back(to.q);
  c.path = core::shortcut_path(c.path, valid_under(arm, slip), check_resolution(arm));
  c.cost = path_length(c.path);
  return c;
}

// Where the filtered roadmap is cut (or an end does not attach): a bridge planned under the
// same checks (the slip limit and the workspace as it currently holds).
// With `project`, samples are projected onto the slip limit (as the online planner's bridges).
Connection bridge_path(ArmPlanning& arm, const GraspSlip& slip, const Eigen::VectorXd& from,
                       const Eigen::VectorXd& to, const core::BridgeSettings& bridge,
                       bool project = false) {
  Connection c;
  const auto valid = valid_under(arm, slip);
  core::BridgeSettings checked = bridge;
  checked.resolution = check_resolution(arm);
  if (project) {
    const core::SlipProjection projection(arm.workspace.arm(), arm.workspace.base(), slip.axis,
                                          slip.lever, slip.theta_c_deg);
    if (projection.active()) checked.project = projection;
  }
  c.path = core::plan_bridge(arm.workspace.arm(), valid, from, to, checked);
  if (c.path.empty()) return c;
  c.connected = true;
  c.via = "bridge";
  c.cost = path_length(c.path);
  return c;
}

// The roadmap first, then a bridge.
Connection connect(ArmPlanning& arm, const std::vector<bool>& allowed, const GraspSlip& slip,
                   const Eigen::VectorXd& from, const Eigen::VectorXd& to, int k,
                   core::GraphSearchWorkspace& search, const core::BridgeSettings& bridge) {
  const Endpoint start = endpoint(arm, slip, from, k);
  if (!start.attached.empty()) {
    Connection c = roadmap_path(arm, slip, allowed, start, endpoint(arm, slip, to, k), search);
    if (c.connected) return c;
  }
  return bridge_path(arm, slip, from, to, bridge);
}

// Every IK branch of the arm with its TCP at `tcp` (world) that is valid in the workspace as it
// currently holds, `preferred` (a branch chosen earlier) first. An arm holding a long board
// under a tight slip limit rarely changes branch, so the branch is part of a regrasp node.
std::vector<Eigen::VectorXd> valid_branches(ArmPlanning& arm, const core::Pose& tcp,
                                            const Eigen::VectorXd& preferred) {
  std::vector<Eigen::VectorXd> out{preferred};
  core::UrIkSolutions ik;
  const core::Arm& a = arm.workspace.arm();
  const int n = a.ur_ik->solve(arm.workspace.base().inverse() * tcp, a.spec.home, ik);
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd q = ik.q[static_cast<std::size_t>(i)];
    if ((q - preferred).norm() > 1e-6 && arm.workspace.valid(q)) out.push_back(q);
  }
  return out;
}

// Both arms at the exchange: the suction arm holding the board at the robot-robot pose and the
// receiving arm closing on it. Each arm's workspace has the other at home, so a suction-arm IK
// branch other than the one the handover search checked must be re-checked with the receiving
// arm in place.
class ExchangeCheck {
 public:
  ExchangeCheck(const core::Cell& cell, const core::TriangleMesh& board,
                const std::vector<core::PlacedPart>& finished,
                const std::vector<core::PlacedPart>& stacked, const std::string& suction_arm,
                const std::string& receiving_arm)
      : cell_(cell),
        scene_(core::build_stage_scene(cell, board, finished, suction_arm, stacked)),
        data_(scene_.cell.model),
        suction_(cell.arm(suction_arm)),
        receiving_(cell.arm(receiving_arm)),
        robot_q_(cell.home_configuration()) {
    for (std::size_t i = 0; i < cell.arms().size(); ++i) {
      if (&cell.arms()[i] == &receiving_) receiving_bodies_ = scene_.cell.arm_bodies[i];
    }
    core::set_cell_state(cell, scene_.cell, data_, robot_q_, cell.human_neutral());
  }

  bool clear(const core::Pose& board, const Eigen::VectorXd& suction_q,
             const Eigen::VectorXd& receiving_q, double jaw) {
    cell_.set_arm(robot_q_, suction_, suction_q);
    cell_.set_arm(robot_q_, receiving_, receiving_q);
    cell_.set_jaw(robot_q_, receiving_, jaw);
    core::set_robot_state(cell_, scene_.cell, data_, robot_q_);
    core::set_tool_held(cell_, scene_, data_,
                        core::arm_base_in_world(cell_, suction_) * suction_.chain.fk(suction_q));
    data_.set_body_pose(scene_.board, board);
    return !core::in_collision(scene_.cell.model, data_, receiving_bodies_);
  }

  // The receiving arm's way in to `receiving_q` (core::find_pre_grasp, as the handover search
  // and the online approach ask), the suction arm holding the board as in clear(); none for an
  // exchange pressed against the robot's body, which may be valid and yet unreachable.
  std::optional<Eigen::VectorXd> pre_grasp(const core::Pose& board,
                                           const Eigen::VectorXd& suction_q,
                                           const Eigen::VectorXd& receiving_q, double jaw,
                                           double distance, double resolution) {
    return core::find_pre_grasp(
        cell_, receiving_, receiving_q, distance, resolution, [&](const Eigen::VectorXd& q) {
          return receiving_.chain.within_limits(q, 1e-9) && clear(board, suction_q, q, jaw);
        });
  }

 private:
  const core::Cell& cell_;
  core::StageScene scene_;
  core::CollisionData data_;
  const core::Arm& suction_;
  const core::Arm& receiving_;
  std::vector<int> receiving_bodies_;
  Eigen::VectorXd robot_q_;
};

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
  // The board's stage: its chains must not carry it (or the arm) through the parts already
  // assembled or those still in the stack, or the online planner would find every stored
  // transfer blocked in the nominal sequence and fall back to bridges.
  const std::vector<core::PlacedPart> finished = core::parts_before(product, index);
  const std::vector<core::PlacedPart> stacked = core::parts_after(product, index);
  const core::RoadmapGraph suction_graph(suction_roadmap.nodes, suction_roadmap.edges);
  const core::RoadmapGraph receiving_graph(receiving_roadmap.nodes, receiving_roadmap.edges);
  ArmPlanning suction{
      suction_roadmap, suction_graph,
      ArmWorkspace(cell, settings.suction_arm, settings.suction_arm, &part.mesh, finished, stacked),
      std::vector<bool>(suction_roadmap.edges.size(), true), settings.held_resolution};
  ArmPlanning receiving{receiving_roadmap, receiving_graph,
                        ArmWorkspace(cell, settings.receiving_arm, settings.suction_arm, &part.mesh,
                                     finished, stacked),
                        std::vector<bool>(receiving_roadmap.edges.size(), true),
                        settings.held_resolution};
  core::GraphSearchWorkspace search;
  ExchangeCheck exchange(cell, part.mesh, finished, stacked, settings.suction_arm,
                         settings.receiving_arm);
  // Each kind of bridge draws its seeds from a sequence of its own (a counter times its
  // stride): the coarse searches of suction transfers and the alternatives leave the bridges
  // stored for the chains as they would be without them.
  auto seeded = [&](std::uint64_t& drawn, std::uint64_t stride) {
    core::BridgeSettings b = settings.bridge;
    b.resolution = receiving_roadmap.resolution;
    b.seed = settings.seed + stride * ++drawn;
    return b;
  };
  std::uint64_t bridges = 0, coarse_seeds = 0, alternative_seeds = 0;
  auto bridge = [&] { return seeded(bridges, 0x9E3779B97F4A7C15ULL); };
  // The suction transfer's search at the online planner's resolution.
  auto coarse_bridge = [&] { return seeded(coarse_seeds, 0x94D049BB133111EBULL); };
  auto alternative_bridge = [&] {
    core::BridgeSettings b = seeded(alternative_seeds, 0xD1B54A32D192ED03ULL);
    b.max_checks = settings.alternative_checks;
    return b;
  };
  const GraspSlip no_slip_limit;  // theta_c 90: any tilt
  const int k = settings.attach_neighbours;
  const int k_way_in = std::max(k, settings.way_in_neighbours);
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
    if (e.path.size() >= 2) {
      const core::ArmSpec& spec = arm == settings.suction_arm ? suction.workspace.arm().spec
                                                              : receiving.workspace.arm().spec;
      e.duration =
          core::time_parameterize_through(e.path, spec.max_velocity, spec.max_acceleration,
                                          settings.timing_speed_scale, settings.timing_step)
              .time.back();
    }
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
    bool open_online = false;  // connected only at the online planner's resolution
    if (pick.node >= 0 && pick.lift.size() > 0) {
      const auto& grasp = grasps.suction[static_cast<std::size_t>(rr.suction_grasp_id)];
      const core::Pose board_in_tcp = cup_in_tcp * grasp.cup.inverse();
      suction.workspace.hold(board_in_tcp, 0.0);
      // The handover search kept one IK solution; another branch at the same pose may be the
      // one the held board can reach from the stack. The stored one is tried first.
      std::vector<Eigen::VectorXd> ends =
          valid_branches(suction, rr.board * board_in_tcp.inverse(), rr.joints);
      // Through the roadmap to each branch, then bridges to the first few.
      const auto& edges = result.filters[static_cast<std::size_t>(pick.filter)].edges;
      const Endpoint lifted = endpoint(suction, no_slip_limit, pick.lift, k);
      std::size_t chosen = 0;
      for (int pass = 0; pass < 2 && !transfer.connected; ++pass) {
        for (chosen = 0; chosen < ends.size(); ++chosen) {
          if (pass == 1 && static_cast<int>(chosen) >= settings.transfer_bridges) break;
          transfer = pass == 0
                         ? roadmap_path(suction, no_slip_limit, edges, lifted,
                                        endpoint(suction, no_slip_limit, ends[chosen], k), search)
                         : bridge_path(suction, no_slip_limit, pick.lift, ends[chosen], bridge());
          if (transfer.connected) break;
        }
      }
      if (transfer.connected) {  // the node's solution the transfer reaches comes first
        std::swap(ends.front(), ends[chosen]);
        result.nodes[static_cast<std::size_t>(node)].solutions = ends;
      }
      // Not connected at the validator's resolution: the online planner searches at its own,
      // coarser one and its validator mends what it finds, so the same search may connect
      // there. Only a transfer blocked at both is stored (as blocked).
      if (!transfer.connected && settings.online_held_resolution > suction.held_resolution) {
        const double fine = suction.held_resolution;
        suction.held_resolution = settings.online_held_resolution;
        const Endpoint coarse_lift = endpoint(suction, no_slip_limit, pick.lift, k);
        for (std::size_t b = 0; b < ends.size() && !open_online; ++b) {
          open_online = roadmap_path(suction, no_slip_limit, edges, coarse_lift,
                                     endpoint(suction, no_slip_limit, ends[b], k), search)
                            .connected;
        }
        // Bridges to every branch, a share of the samples drawn around the robot-robot end
        // (where a transfer that does not attach is wedged), as the online planner's.
        for (std::size_t b = 0; b < ends.size() && !open_online; ++b) {
          core::BridgeSettings focused = coarse_bridge();
          focused.focus = {ends[b]};
          focused.focus_fraction = settings.coarse_focus;
          focused.max_checks = settings.coarse_bridge_checks;
          open_online = bridge_path(suction, no_slip_limit, pick.lift, ends[b], focused).connected;
        }
        suction.held_resolution = fine;
      }
      suction.workspace.release();
      if (transfer.connected) {  // the path starts at the pick, below the lift
        transfer.path.insert(transfer.path.begin(),
                             result.nodes[static_cast<std::size_t>(pick.node)].solutions.front());
        transfer.cost = path_length(transfer.path);
      }
    }
    if (pick.node >= 0 && !open_online) {
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
  const core::Arm& receiving_arm = receiving.workspace.arm();
  const double jaw_max = cell.spec().gripper.jaw_max;
  struct LeftEnd {
    int node = -1;
    bool transit = false;  // home -> node connected and the exchange clear
  };
  // Per robot-robot pose: the receiving arm's workspace with the board standing there (a static
  // part, which the gripper must not touch on its way in) and the rest of the robot as at the
  // exchange (the suction arm holding the board), with home attached in it once.
  struct WayIn {
    ArmPlanning planning;
    Endpoint home;
  };
  std::map<std::int64_t, std::unique_ptr<WayIn>> ways_in;
  auto way_in_for = [&](std::int64_t robot_handover, const core::Pose& board,
                        const Eigen::VectorXd& robot_q) -> WayIn& {
    auto& slot = ways_in[robot_handover];
    if (slot) return *slot;
    std::vector<core::PlacedPart> parts = finished;
    parts.push_back({part.name + "_at_exchange", &part.mesh, board});
    slot = std::make_unique<WayIn>(
        WayIn{ArmPlanning{receiving_roadmap, receiving_graph,
                          ArmWorkspace(cell, settings.receiving_arm, settings.suction_arm, nullptr,
                                       parts, stacked),
                          receiving.all_edges, settings.held_resolution},
              {}});
    slot->planning.workspace.pose_rest(robot_q);
    slot->home = endpoint(slot->planning, no_slip_limit, receiving_arm.spec.home, k);
    return *slot;
  };
  // Per (robot handover, grasp): one node per receiving-arm branch at the exchange.
  std::map<std::pair<std::int64_t, std::int64_t>, std::vector<LeftEnd>> rr_left;
  auto rr_left_for = [&](const db::SharedGraspRecord& s) -> const std::vector<LeftEnd>& {
    const auto key = std::make_pair(s.robot_handover_id, s.robot_grasp_id);
    auto it = rr_left.find(key);
    if (it != rr_left.end()) return it->second;
    std::vector<LeftEnd>& ends = rr_left[key];
    const auto& rr = handover.robot_handovers[static_cast<std::size_t>(s.robot_handover_id)];
    const int suction_node = rr_node_for(s.robot_handover_id);
    if (!rr_transfer[s.robot_handover_id]) return ends;  // no use reaching an unreachable pose
    const auto& grasp = grasps.robot[static_cast<std::size_t>(s.robot_grasp_id)];
    const double jaw = std::min(jaw_max, grasp.jaw_width + kJawMargin);
    // The suction arm may hold the board in another IK branch than the handover search checked.
    const auto& suction_q = result.nodes[static_cast<std::size_t>(suction_node)].solutions.front();
    // The transit ends with the way in (home -> pre-grasp -> grasp), checked as the arm makes
    // it: the suction arm at the exchange, holding the board there. Checked with the suction
    // arm at home and no board, every stored transit ran into the board near its end, and the
    // online planner searched the roadmap for every receiving approach instead.
    Eigen::VectorXd at_exchange = cell.home_configuration();
    cell.set_arm(at_exchange, suction_arm, suction_q);
    WayIn& entry = way_in_for(s.robot_handover_id, rr.board, at_exchange);
    ArmPlanning& way_in = entry.planning;
    const Endpoint& way_in_home = entry.home;
    // Transits through the roadmap to every branch; bridges (costly when they fail) only when
    // none connects, to the first few branches.
    std::vector<Connection> transits;
    std::vector<Eigen::VectorXd> pre_grasps;
    for (const auto& q : valid_branches(receiving, rr.board * grasp.tcp, s.joints_rr)) {
      if (!exchange.clear(rr.board, suction_q, q, jaw)) continue;
      const std::optional<Eigen::VectorXd> pre_q = exchange.pre_grasp(
          rr.board, suction_q, q, jaw, settings.approach, settings.approach_resolution);
      if (!pre_q) continue;  // valid, but pressed where no open gripper gets in
      LeftEnd end;
      end.node = add_node("robot_handover", settings.receiving_arm, "gripper", s.robot_grasp_id,
                          s.robot_handover_id, -1, rr.board, {q});
      ends.push_back(end);
      pre_grasps.push_back(*pre_q);
      transits.push_back(roadmap_path(way_in, no_slip_limit, way_in.all_edges, way_in_home,
                                      endpoint(way_in, no_slip_limit, *pre_q, k_way_in), search));
    }
    const bool any = std::any_of(transits.begin(), transits.end(),
                                 [](const Connection& c) { return c.connected; });
    for (std::size_t i = 0; i < ends.size(); ++i) {
      if (!any && static_cast<int>(i) < settings.transfer_bridges) {
        transits[i] =
            bridge_path(way_in, no_slip_limit, receiving_arm.spec.home, pre_grasps[i], bridge());
      }
      if (transits[i].connected) {  // the straight approach, checked by pre_grasp()
        transits[i].path.push_back(
            result.nodes[static_cast<std::size_t>(ends[i].node)].solutions.front());
        transits[i].cost = path_length(transits[i].path);
      }
      add_edge("transit", settings.receiving_arm, home_receiving, ends[i].node, -1, transits[i]);
      Connection exchange_edge;
      exchange_edge.connected = true;
      add_edge("handover", settings.receiving_arm, suction_node, ends[i].node, -1, exchange_edge);
      ends[i].transit = transits[i].connected;
    }
    return ends;
  };

  // Goals in Eq. 8 order; each goal's shared grasps until one connects the whole chain. Filters
  // are made when a grasp is first needed, and the search stops after `served_goals` goals:
  // the online planner tries the goals in the same order.
  std::map<int, std::vector<std::size_t>> shared_of;  // candidate -> its shared grasps
  for (std::size_t i = 0; i < handover.shared.size(); ++i) {
    shared_of[handover.shared[i].candidate_id].push_back(i);
  }
  std::set<int> considered;
  // One goal's shared grasps until one connects the whole chain; true when one does.
  auto serve = [&](int c) {
    considered.insert(c);
    ++result.goals_considered;
    bool served = false;
    const auto grasps_of = shared_of.find(c);
    if (grasps_of == shared_of.end()) return false;
    for (const std::size_t g : grasps_of->second) {
      if (served) break;  // the goal's remaining grasps are not needed
      const auto& s = handover.shared[g];
      ++result.shared_grasps;
      std::vector<int> starts;  // receiving-arm nodes at the exchange reached from home
      for (const auto& end : rr_left_for(s)) {
        if (end.transit) starts.push_back(end.node);
      }
      // Only a grasp whose chain up to the exchange connects is worth its filter.
      if (starts.empty()) {
        ++result.cut_before_exchange;
        continue;
      }
      const int filter = gripper_filter_for(s.robot_grasp_id);
      const auto& edges = result.filters[static_cast<std::size_t>(filter)].edges;
      const auto& candidate = handover.candidates[static_cast<std::size_t>(s.candidate_id)];
      const auto& grasp = grasps.robot[static_cast<std::size_t>(s.robot_grasp_id)];
      const GraspSlip slip = grasp_slip(cell, grasp, grasps.com);
      receiving.workspace.hold(grasp.tcp.inverse(),
                               std::min(jaw_max, grasp.jaw_width + kJawMargin));
      const auto goals_rh = valid_branches(receiving, candidate.board * grasp.tcp, s.joints_rh);
      // Branch pairs, the handover search's first, then nearest first: through the roadmap,
      // then bridges for the nearest few.
      std::vector<std::tuple<double, int, std::size_t>> pairs;
      for (std::size_t a = 0; a < starts.size(); ++a) {
        const auto& qa = result.nodes[static_cast<std::size_t>(starts[a])].solutions.front();
        for (std::size_t b = 0; b < goals_rh.size(); ++b) {
          pairs.emplace_back(a == 0 && b == 0 ? -1.0 : (goals_rh[b] - qa).norm(), starts[a], b);
        }
      }
      std::sort(pairs.begin(), pairs.end());
      std::map<int, Endpoint> from_ends;  // by node
      std::vector<std::optional<Endpoint>> to_ends(goals_rh.size());
      Connection transfer;
      int from_node = starts.front();
      std::size_t to_branch = 0;
      for (const auto& [distance, node, b] : pairs) {
        auto it = from_ends.find(node);
        if (it == from_ends.end()) {
          it = from_ends
                   .emplace(
                       node,
                       endpoint(receiving, slip,
                                result.nodes[static_cast<std::size_t>(node)].solutions.front(), k))
                   .first;
        }
        if (it->second.attached.empty()) continue;
        if (!to_ends[b]) to_ends[b] = endpoint(receiving, slip, goals_rh[b], k);
        transfer = roadmap_path(receiving, slip, edges, it->second, *to_ends[b], search);
        if (transfer.connected) {
          from_node = node;
          to_branch = b;
          break;
        }
      }
      for (std::size_t i = 0; i < pairs.size() && !transfer.connected &&
                              static_cast<int>(i) < settings.transfer_bridges;
           ++i) {
        const auto& [distance, node, b] = pairs[i];
        transfer = bridge_path(receiving, slip,
                               result.nodes[static_cast<std::size_t>(node)].solutions.front(),
                               goals_rh[b], bridge());
        if (transfer.connected) {
          from_node = node;
          to_branch = b;
        }
      }
      // Where the filtered roadmap is cut, the online planner has no roadmap way round what a
      // scene puts on the bridge: other bridges between the same ends, stored as parallel
      // edges, give it other ways to follow.
      std::vector<Connection> alternatives;
      for (int a = 0;
           transfer.connected && transfer.via == "bridge" && a < settings.bridge_alternatives;
           ++a) {
        Connection other = bridge_path(receiving, slip, transfer.path.front(), transfer.path.back(),
                                       alternative_bridge(), true);
        if (other.connected && other.path != transfer.path) alternatives.push_back(other);
      }
      receiving.workspace.release();
      const int rh_node =
          add_node("human_handover", settings.receiving_arm, "gripper", s.robot_grasp_id, -1,
                   s.candidate_id, candidate.board, {goals_rh[to_branch]});
      add_edge("transfer", settings.receiving_arm, from_node, rh_node, filter, transfer);
      for (const auto& other : alternatives) {
        add_edge("transfer", settings.receiving_arm, from_node, rh_node, filter, other);
        ++result.alternatives;
      }
      ++result.transfers;
      result.transfers_connected += transfer.connected ? 1 : 0;
      served = transfer.connected;
    }
    if (!served) return false;
    ++result.goals_served;
    if (result.first_served_rank < 0) {
      result.first_served_rank = handover.candidates[static_cast<std::size_t>(c)].rank;
    }
    return true;
  };
  for (const int c : goals) {
    if (result.goals_served >= settings.served_goals) break;
    serve(c);
  }
  // Suction deliveries of the first goals: the suction arm's pick (its node, transit and the
  // cup's filter) and its transfer, the board on the cup, to the goal's robot-human pose, as for
  // a robot-robot pose: the online planner follows the stored path and its end's branch.
  for (const auto& d : handover.suction_deliveries) {
    const auto& candidate = handover.candidates[static_cast<std::size_t>(d.candidate_id)];
    if (candidate.rank < 0 || candidate.rank >= settings.goals) continue;
    const Pick& pick = pick_for(d.suction_grasp_id);
    if (pick.node < 0 || pick.lift.size() == 0) continue;
    const auto& grasp = grasps.suction[static_cast<std::size_t>(d.suction_grasp_id)];
    const core::Pose board_in_tcp = cup_in_tcp * grasp.cup.inverse();
    suction.workspace.hold(board_in_tcp, 0.0);
    std::vector<Eigen::VectorXd> ends =
        valid_branches(suction, candidate.board * board_in_tcp.inverse(), d.joints_rh);
    const auto& edges = result.filters[static_cast<std::size_t>(pick.filter)].edges;
    const Endpoint lifted = endpoint(suction, no_slip_limit, pick.lift, k);
    Connection transfer;
    std::size_t chosen = 0;
    for (int pass = 0; pass < 2 && !transfer.connected; ++pass) {
      for (chosen = 0; chosen < ends.size(); ++chosen) {
        if (pass == 1 && static_cast<int>(chosen) >= settings.transfer_bridges) break;
        transfer = pass == 0
                       ? roadmap_path(suction, no_slip_limit, edges, lifted,
                                      endpoint(suction, no_slip_limit, ends[chosen], k), search)
                       : bridge_path(suction, no_slip_limit, pick.lift, ends[chosen], bridge());
        if (transfer.connected) break;
      }
    }
    suction.workspace.release();
    if (ends.empty()) ends.push_back(d.joints_rh);
    if (transfer.connected) {
      std::swap(ends.front(), ends[chosen]);
      // The path starts at the pick, below the lift (as the exchanges' transfers).
      transfer.path.insert(transfer.path.begin(),
                           result.nodes[static_cast<std::size_t>(pick.node)].solutions.front());
      transfer.cost = path_length(transfer.path);
    }
    const int node = add_node("human_handover", settings.suction_arm, "suction", d.suction_grasp_id,
                              -1, d.candidate_id, candidate.board, ends);
    add_edge("transfer", settings.suction_arm, pick.node, node, pick.filter, transfer);
    ++result.suction_transfers;
    result.suction_transfers_connected += transfer.connected ? 1 : 0;
  }
  // The goals the cell's human takes with the part's centre between hip and shoulder height
  // (core::natural_height_band), in Eq. 8 order, until `served_natural` more are served: the
  // online planner tries natural receiving postures first (docs/online.md), and without a
  // stored chain it plans theirs from scratch. After the deliveries, so the bridges' seeds above
  // stay as they were.
  if (settings.served_natural > 0) {
    const core::HeightBand band =
        core::natural_height_band(cell, nullptr, cell.spec().human_stance);
    std::vector<int> in_band;
    for (std::size_t c = 0; c < handover.candidates.size(); ++c) {
      const auto& candidate = handover.candidates[c];
      if (candidate.rank >= 0 && considered.count(static_cast<int>(c)) == 0 &&
          band.contains((candidate.board * grasps.com).z())) {
        in_band.push_back(static_cast<int>(c));
      }
    }
    std::sort(in_band.begin(), in_band.end(), [&](int a, int b) {
      return handover.candidates[static_cast<std::size_t>(a)].rank <
             handover.candidates[static_cast<std::size_t>(b)].rank;
    });
    int natural_served = 0, natural_considered = 0;
    for (const int c : in_band) {
      if (natural_served >= settings.served_natural ||
          natural_considered >= settings.considered_natural) {
        break;
      }
      ++natural_considered;
      natural_served += serve(c) ? 1 : 0;
    }
  }
  // The robot-robot poses whose suction-arm transfer was examined on the way.
  for (const auto& [r, connected] : rr_transfer) {
    ++result.exchanges_examined;
    result.exchanges_connected += connected ? 1 : 0;
  }
  // Goals reached by a direct pick, a regrasp on the table or on the suction cup have no
  // exchange chain here: the online planner plans them through the picking arm's roadmap (the
  // stored transfers above where they connected).
  if (result.goals_served == 0 && handover.direct.empty() && handover.regrasps.empty() &&
      handover.suction_deliveries.empty()) {
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
