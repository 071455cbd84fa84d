#include "cmd_inspect_graph.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>
#include <vector>

#include "hila/core/error.hpp"
#include "hila/core/pose.hpp"

namespace hila::tools {

namespace {

using Id = std::int64_t;
using RrGrasp = std::pair<Id, Id>;           // (robot handover, robot grasp)
using RrGraspGoal = std::tuple<Id, Id, Id>;  // (robot handover, robot grasp, candidate)
// (suction arm, "" for direct, "table" for a regrasp on the table; delivering arm)
using WayKey = std::pair<std::string, std::string>;

double round_to(double v, double unit) {
  return std::round(v / unit) * unit;
}

// A pose as {"xyz": [m], "quaternion_wxyz": [...]}, rounded to 1e-6.
nlohmann::json pose_values(const core::Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d& t = pose.translation();
  return {{"xyz", {round_to(t.x(), 1e-6), round_to(t.y(), 1e-6), round_to(t.z(), 1e-6)}},
          {"quaternion_wxyz",
           {round_to(q.w(), 1e-6), round_to(q.x(), 1e-6), round_to(q.y(), 1e-6),
            round_to(q.z(), 1e-6)}}};
}

// The regrasp-graph edges standing for one edge of the manipulation graph (one per IK branch,
// plus parallel alternative bridges): how many, and the first connected one in id order (the
// stored path the online planner follows first; alternatives come after it).
struct Stored {
  int edges = 0;
  bool connected = false;
  double cost = 0.0;      // rad, joint-space length of that edge's path
  double duration = 0.0;  // s, the robot's estimated time along it (0: not estimated)
  std::string via;        // how that edge was connected: "roadmap" or "bridge"

  void add(const db::RegraspEdgeRecord& e) {
    ++edges;
    if (e.connected && !connected) {
      connected = true;
      cost = e.cost;
      duration = e.duration;
      via = e.via;
    }
  }
};

template <class Map, class Key>
const Stored* find(const Map& map, const Key& key) {
  const auto it = map.find(key);
  return it == map.end() ? nullptr : &it->second;
}

bool connected(const Stored* s) {
  return s != nullptr && s->connected;
}

nlohmann::json stored_json(const Stored* s) {
  if (s == nullptr) return nullptr;
  return {{"edges", s->edges},
          {"connected", s->connected},
          {"cost_rad", s->connected ? nlohmann::json(round_to(s->cost, 1e-4)) : nullptr},
          {"duration_s", s->connected ? nlohmann::json(round_to(s->duration, 1e-4)) : nullptr},
          {"via", s->via}};
}

// "not stored", "not connected" or e.g. "5.21 rad 2.4 s roadmap" (the time left out where it was
// not estimated: a path of some length with duration 0, in a file migrated from schema 8).
std::string status(const Stored* s) {
  if (s == nullptr) return "not stored";
  if (!s->connected) return "not connected";
  std::ostringstream out;
  out << std::fixed << std::setprecision(2) << s->cost << " rad ";
  if (s->duration > 0.0 || s->cost == 0.0) {
    out << std::setprecision(1) << s->duration << " s ";
  }
  out << s->via;
  return out.str();
}

// The part's regrasp graph indexed by what the manipulation graph's edges stand for.
struct RegraspIndex {
  std::map<Id, Stored> pick_transit;      // suction grasp -> the suction arm from home to the pick
  std::map<Id, Stored> cup_transfer;      // robot handover -> the suction arm's transfer to it
  std::map<RrGrasp, Stored> way_in;       // the receiving arm from home into the exchange grasp
  std::map<RrGrasp, Stored> exchange;     // suction cup -> receiving gripper
  std::map<RrGraspGoal, Stored> to_goal;  // the receiving arm's transfer to the goal
  std::map<std::pair<Id, Id>, Stored> cup_to_goal;  // (cup, goal) -> the suction arm's transfer

  RegraspIndex(const std::vector<db::RegraspNodeRecord>& nodes,
               const std::vector<db::RegraspEdgeRecord>& edges) {
    std::map<Id, const db::RegraspNodeRecord*> node;
    for (const auto& n : nodes) node[n.id] = &n;
    for (const auto& e : edges) {
      const auto& from = *node.at(e.from_node);
      const auto& to = *node.at(e.to_node);
      if (e.kind == "transit" && to.kind == "pick") {
        pick_transit[to.grasp_id].add(e);
      } else if (e.kind == "transit" && to.kind == "robot_handover") {
        way_in[{to.robot_handover_id, to.grasp_id}].add(e);
      } else if (e.kind == "transfer" && to.kind == "robot_handover") {
        cup_transfer[to.robot_handover_id].add(e);
      } else if (e.kind == "handover") {
        exchange[{to.robot_handover_id, to.grasp_id}].add(e);
      } else if (e.kind == "transfer" && to.kind == "human_handover" &&
                 to.grasp_kind == "suction") {
        cup_to_goal[{to.grasp_id, to.candidate_id}].add(e);
      } else if (e.kind == "transfer" && to.kind == "human_handover") {
        to_goal[{from.robot_handover_id, to.grasp_id, to.candidate_id}].add(e);
      }
    }
  }

  // Every stored edge of the exchange from the table to the goal is connected: the chain the
  // online planner follows (as `inspect roadmap` counts a goal connected).
  bool chain(const db::RobotHandoverRecord& rr, Id grasp, Id candidate) const {
    return connected(find(pick_transit, rr.suction_grasp_id)) &&
           connected(find(cup_transfer, rr.id)) &&
           connected(find(exchange, RrGrasp{rr.id, grasp})) &&
           connected(find(way_in, RrGrasp{rr.id, grasp})) &&
           connected(find(to_goal, RrGraspGoal{rr.id, grasp, candidate}));
  }
};

struct Goal {
  db::HandoverCandidateRecord candidate;
  std::vector<db::SharedGraspRecord> shared;
  std::vector<db::DirectGraspRecord> direct;
  std::vector<db::TableRegraspRecord> regrasps;
  std::vector<db::SuctionDeliveryRecord> on_cup;
};

// One way to the human: a direct pick by `arm`, a regrasp on the table by `arm` (its gripper
// picks, sets the part down elsewhere, takes it again), on `arm`'s suction cup (it picks and
// presents the part with the tool), or an exchange from `suction_arm`'s cup to `arm`'s gripper.
// The online planner tries them in that order within a goal.
struct Way {
  enum class Kind { kDirect, kRegrasp, kSuction, kExchange };
  Kind kind = Kind::kDirect;
  std::string suction_arm;  // the exchange's
  std::string arm;          // the arm that delivers
  std::string picking_arm;  // the regrasp's: the arm that sets it down (another for a relay)
  std::set<int> ranks;      // goals served
  std::set<int> connected;  // goals whose chain the regrasp graph connects (exchange)
  std::set<Id> gripper_grasps, suction_grasps, robot_handovers;
  std::set<Id> set_downs;  // table regrasp records (regrasp)

  bool direct() const { return kind == Kind::kDirect; }
  bool exchange() const { return kind == Kind::kExchange; }
  const char* kind_name() const {
    return kind == Kind::kDirect    ? "direct"
           : kind == Kind::kRegrasp ? "regrasp"
           : kind == Kind::kSuction ? "suction"
                                    : "exchange";
  }
  std::string name() const {
    switch (kind) {
      case Kind::kDirect:
        return "direct by " + arm;
      case Kind::kRegrasp:
        return picking_arm == arm ? "regrasp on table by " + arm
                                  : "relay on table " + picking_arm + " -> " + arm;
      case Kind::kSuction:
        return "on the cup by " + arm;
      case Kind::kExchange:
        break;
    }
    return "exchange " + suction_arm + " -> " + arm;
  }
};

std::string goal_node(int rank, const std::string& arm) {
  return "goal:" + std::to_string(rank) + ":" + arm;
}
std::string cup_node(const std::string& arm, Id suction_grasp) {
  return "cup:" + arm + ":" + std::to_string(suction_grasp);
}
std::string received_node(const std::string& arm, Id rr, Id grasp) {
  return "received:" + arm + ":" + std::to_string(rr) + ":" + std::to_string(grasp);
}
std::string set_down_node(const std::string& arm, Id regrasp) {
  return "set_down:" + arm + ":" + std::to_string(regrasp);
}
std::string taken_again_node(const std::string& arm, Id regrasp) {
  return "taken_again:" + arm + ":" + std::to_string(regrasp);
}

// "1 goal", "2 goals".
std::string count(std::size_t n, const std::string& noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

// "a, b, c" of the first `most` ids, then "... (+n)".
template <class Ids>
std::string id_list(const Ids& ids, std::size_t most = 8) {
  std::string out;
  std::size_t n = 0;
  for (const auto id : ids) {
    if (n++ == most) {
      out += ", ... (+" + std::to_string(ids.size() - most) + ")";
      break;
    }
    out += (out.empty() ? "" : ", ") + std::to_string(id);
  }
  return out;
}

nlohmann::json edge_json(const std::string& from, const std::string& to, const std::string& kind,
                         const nlohmann::json& way, const std::string& arm,
                         const nlohmann::json& grasp_kind, const nlohmann::json& grasps,
                         const std::string& offline, const Stored* regrasp, const Stored* transit) {
  return {{"from", from},
          {"to", to},
          {"kind", kind},
          {"way", way},
          {"arm", arm},
          {"grasp_kind", grasp_kind},
          {"grasps", grasps},
          {"offline", offline},
          {"regrasp", stored_json(regrasp)},
          {"transit", stored_json(transit)}};
}

struct Graph {
  nlohmann::json json;
  std::vector<Goal> goals;
  std::vector<Way> ways;
  std::map<Id, db::RobotHandoverRecord> robot_handovers;
  RegraspIndex regrasp;
};

Graph build_graph(const db::Database& database, const db::PartRecord& part,
                  const db::HandoverStageRecord& stage) {
  const auto regrasp_nodes = database.regrasp_nodes(part.id);
  const bool regrasp_stored = !regrasp_nodes.empty();
  Graph g{{}, {}, {}, {}, {regrasp_nodes, database.regrasp_edges(part.id)}};
  for (const auto& r : database.robot_handovers(part.id)) g.robot_handovers[r.id] = r;
  for (const auto& c : database.handover_goals(part.id)) {
    g.goals.push_back({c, database.shared_grasps(c.id), database.direct_grasps(c.id),
                       database.table_regrasps(c.id), database.suction_deliveries(c.id)});
  }

  std::map<WayKey, Way> ways;
  std::map<std::string, std::set<Id>> picked;          // arm -> its direct grasps over every goal
  std::set<std::tuple<std::string, Id, Id>> received;  // (receiving arm, rr, grasp)
  int goals_direct = 0, goals_regrasp = 0, goals_exchange = 0, goals_suction = 0;
  std::set<int> goals_connected;
  for (const auto& goal : g.goals) {
    const int rank = goal.candidate.rank;
    goals_direct += goal.direct.empty() ? 0 : 1;
    goals_regrasp += goal.regrasps.empty() ? 0 : 1;
    goals_exchange += goal.shared.empty() ? 0 : 1;
    goals_suction += goal.on_cup.empty() ? 0 : 1;
    for (const auto& d : goal.on_cup) {
      Way& w = ways[{"cup", d.arm}];
      w.kind = Way::Kind::kSuction;
      w.arm = d.arm;
      w.ranks.insert(rank);
      w.suction_grasps.insert(d.suction_grasp_id);
      if (connected(find(g.regrasp.pick_transit, d.suction_grasp_id)) &&
          connected(find(g.regrasp.cup_to_goal, std::make_pair(d.suction_grasp_id,
                                                                goal.candidate.id)))) {
        w.connected.insert(rank);
      }
    }
    for (const auto& d : goal.direct) {
      Way& w = ways[{"", d.arm}];
      w.arm = d.arm;
      w.ranks.insert(rank);
      w.gripper_grasps.insert(d.robot_grasp_id);
      picked[d.arm].insert(d.robot_grasp_id);
    }
    for (const auto& r : goal.regrasps) {
      Way& w = ways[{"table:" + r.arm, r.repick_arm}];
      w.kind = Way::Kind::kRegrasp;
      w.picking_arm = r.arm;
      w.arm = r.repick_arm;
      w.ranks.insert(rank);
      w.gripper_grasps.insert(r.pick_grasp_id);
      w.gripper_grasps.insert(r.robot_grasp_id);
      w.set_downs.insert(r.id);
      picked[r.arm].insert(r.pick_grasp_id);
    }
    for (const auto& s : goal.shared) {
      const auto& rr = g.robot_handovers.at(s.robot_handover_id);
      Way& w = ways[{rr.arm, s.arm}];
      w.kind = Way::Kind::kExchange;
      w.suction_arm = rr.arm;
      w.arm = s.arm;
      w.ranks.insert(rank);
      w.gripper_grasps.insert(s.robot_grasp_id);
      w.suction_grasps.insert(rr.suction_grasp_id);
      w.robot_handovers.insert(rr.id);
      received.insert({s.arm, rr.id, s.robot_grasp_id});
      if (g.regrasp.chain(rr, s.robot_grasp_id, goal.candidate.id)) {
        w.connected.insert(rank);
        goals_connected.insert(rank);
      }
    }
  }
  // In the order the online planner tries them within a goal.
  for (const auto kind :
       {Way::Kind::kDirect, Way::Kind::kRegrasp, Way::Kind::kSuction, Way::Kind::kExchange}) {
    for (auto& [key, w] : ways) {
      if (w.kind == kind) g.ways.push_back(w);
    }
  }

  nlohmann::json nodes = nlohmann::json::array();
  nlohmann::json edges = nlohmann::json::array();
  nodes.push_back({{"id", "table"},
                   {"kind", "table"},
                   {"arm", nullptr},
                   {"label", part.name + " on the table at its initial pose"}});
  for (const auto& [arm, grasps] : picked) {
    nodes.push_back({{"id", "picked:" + arm},
                     {"kind", "picked"},
                     {"arm", arm},
                     {"label", "in the " + arm + " gripper at the pick"},
                     {"grasps", grasps}});
    edges.push_back(edge_json("table", "picked:" + arm, "gripper_pick", "direct", arm, "gripper",
                              grasps, "online", nullptr, nullptr));
  }
  // Regrasps on the table: from the pick, set down at the record's pose and taken again.
  std::set<Id> regrasp_listed;
  for (const auto& goal : g.goals) {
    for (const auto& r : goal.regrasps) {
      if (!regrasp_listed.insert(r.id).second) continue;
      const std::string down = set_down_node(r.arm, r.id);
      const std::string again = taken_again_node(r.arm, r.id);
      const Eigen::Vector3d at = r.placement.translation();
      nodes.push_back(
          {{"id", down},
           {"kind", "set_down"},
           {"arm", nullptr},
           {"label", "set down on the table by the " + r.arm + " arm (regrasp " +
                         std::to_string(r.id) + ")"},
           {"regrasp", r.id},
           {"position", {round_to(at.x(), 1e-5), round_to(at.y(), 1e-5), round_to(at.z(), 1e-5)}}});
      nodes.push_back({{"id", again},
                       {"kind", "taken_again"},
                       {"arm", r.repick_arm},
                       {"label", "in the " + r.repick_arm + " gripper again, grasp " +
                                     std::to_string(r.robot_grasp_id)},
                       {"regrasp", r.id},
                       {"grasp", r.robot_grasp_id}});
      edges.push_back(edge_json("picked:" + r.arm, down, "set_down", "regrasp", r.arm, "gripper",
                                {r.pick_grasp_id}, "online", nullptr, nullptr));
      edges.push_back(edge_json(down, again, "gripper_pick", "regrasp", r.repick_arm, "gripper",
                                {r.robot_grasp_id}, "online", nullptr, nullptr));
    }
  }
  std::set<std::pair<std::string, Id>> cups;
  auto add_cup = [&](const std::string& arm, Id suction_grasp, const char* way) {
    if (!cups.insert({arm, suction_grasp}).second) return;
    const std::string cup = cup_node(arm, suction_grasp);
    const Stored* transit = find(g.regrasp.pick_transit, suction_grasp);
    nodes.push_back({{"id", cup},
                     {"kind", "cup"},
                     {"arm", arm},
                     {"label", "on the " + arm + " suction cup, suction grasp " +
                                   std::to_string(suction_grasp)},
                     {"suction_grasp", suction_grasp}});
    edges.push_back(edge_json("table", cup, "suction_pick", way, arm, "suction", {suction_grasp},
                              transit ? "stored" : "not_stored", nullptr, transit));
  };
  for (const auto& [id, rr] : g.robot_handovers) add_cup(rr.arm, rr.suction_grasp_id, "exchange");
  for (const auto& goal : g.goals) {
    for (const auto& d : goal.on_cup) add_cup(d.arm, d.suction_grasp_id, "suction");
  }
  for (const auto& [id, rr] : g.robot_handovers) {
    const std::string node = "rr:" + std::to_string(id);
    const Stored* transfer = find(g.regrasp.cup_transfer, id);
    nodes.push_back({{"id", node},
                     {"kind", "robot_handover"},
                     {"arm", rr.arm},
                     {"label", "at robot-robot pose " + std::to_string(id) + " on the " + rr.arm +
                                   " suction cup"},
                     {"robot_handover", id},
                     {"suction_grasp", rr.suction_grasp_id}});
    edges.push_back(edge_json(cup_node(rr.arm, rr.suction_grasp_id), node, "transfer", "exchange",
                              rr.arm, "suction", {rr.suction_grasp_id},
                              transfer ? "stored" : "not_stored", transfer, nullptr));
  }
  for (const auto& [arm, rr, grasp] : received) {
    const std::string node = received_node(arm, rr, grasp);
    const Stored* exchange = find(g.regrasp.exchange, RrGrasp{rr, grasp});
    nodes.push_back({{"id", node},
                     {"kind", "received"},
                     {"arm", arm},
                     {"label", "in the " + arm + " gripper at robot-robot pose " +
                                   std::to_string(rr) + ", grasp " + std::to_string(grasp)},
                     {"robot_handover", rr},
                     {"grasp", grasp}});
    edges.push_back(edge_json("rr:" + std::to_string(rr), node, "handover", "exchange", arm,
                              "gripper", {grasp}, exchange ? "stored" : "not_stored", exchange,
                              find(g.regrasp.way_in, RrGrasp{rr, grasp})));
  }
  for (const auto& goal : g.goals) {
    const auto& c = goal.candidate;
    std::map<std::string, std::set<Id>> direct;  // arm -> grasps
    for (const auto& d : goal.direct) direct[d.arm].insert(d.robot_grasp_id);
    std::set<std::string> arms;
    for (const auto& [arm, grasps] : direct) arms.insert(arm);
    for (const auto& r : goal.regrasps) arms.insert(r.repick_arm);
    for (const auto& s : goal.shared) arms.insert(s.arm);
    std::set<std::string> cup_arms;
    for (const auto& d : goal.on_cup) cup_arms.insert(d.arm);
    for (const auto& arm : cup_arms) {
      nodes.push_back(
          {{"id", goal_node(c.rank, arm) + ":cup"},
           {"kind", "goal"},
           {"arm", arm},
           {"label", "at goal rank " + std::to_string(c.rank) + " on the " + arm + " suction cup"},
           {"rank", c.rank},
           {"candidate", c.id},
           {"distance", round_to(c.distance, 1e-5)},
           {"quality", round_to(c.quality, 1e-4)}});
      edges.push_back(edge_json(goal_node(c.rank, arm) + ":cup", "human", "present", nullptr, arm,
                                nullptr, nlohmann::json::array(), "none", nullptr, nullptr));
    }
    for (const auto& d : goal.on_cup) {
      const Stored* transfer =
          find(g.regrasp.cup_to_goal, std::make_pair(d.suction_grasp_id, c.id));
      edges.push_back(edge_json(cup_node(d.arm, d.suction_grasp_id),
                                goal_node(c.rank, d.arm) + ":cup", "transfer", "suction", d.arm,
                                "suction", {d.suction_grasp_id}, transfer ? "stored" : "not_stored",
                                transfer, nullptr));
    }
    for (const auto& arm : arms) {
      nodes.push_back(
          {{"id", goal_node(c.rank, arm)},
           {"kind", "goal"},
           {"arm", arm},
           {"label", "at goal rank " + std::to_string(c.rank) + " in the " + arm + " gripper"},
           {"rank", c.rank},
           {"candidate", c.id},
           {"distance", round_to(c.distance, 1e-5)},
           {"quality", round_to(c.quality, 1e-4)}});
    }
    for (const auto& [arm, grasps] : direct) {
      edges.push_back(edge_json("picked:" + arm, goal_node(c.rank, arm), "transfer", "direct", arm,
                                "gripper", grasps, "online", nullptr, nullptr));
    }
    for (const auto& r : goal.regrasps) {
      edges.push_back(edge_json(taken_again_node(r.arm, r.id), goal_node(c.rank, r.repick_arm),
                                "transfer", "regrasp", r.repick_arm, "gripper", {r.robot_grasp_id},
                                "online", nullptr, nullptr));
    }
    for (const auto& s : goal.shared) {
      const Stored* transfer =
          find(g.regrasp.to_goal, RrGraspGoal{s.robot_handover_id, s.robot_grasp_id, c.id});
      edges.push_back(edge_json(received_node(s.arm, s.robot_handover_id, s.robot_grasp_id),
                                goal_node(c.rank, s.arm), "transfer", "exchange", s.arm, "gripper",
                                {s.robot_grasp_id}, transfer ? "stored" : "not_stored", transfer,
                                nullptr));
    }
    for (const auto& arm : arms) {
      edges.push_back(edge_json(goal_node(c.rank, arm), "human", "present", nullptr, arm, nullptr,
                                nlohmann::json::array(), "none", nullptr, nullptr));
    }
  }
  nodes.push_back(
      {{"id", "human"}, {"kind", "human"}, {"arm", nullptr}, {"label", "taken by the human"}});

  nlohmann::json ways_json = nlohmann::json::array();
  for (const auto& w : g.ways) {
    ways_json.push_back(
        {{"way", w.kind_name()},
         {"name", w.name()},
         {"arm", w.arm},
         {"suction_arm", w.exchange() ? nlohmann::json(w.suction_arm) : nlohmann::json(nullptr)},
         {"goals", w.ranks.size()},
         {"best_rank", *w.ranks.begin()},
         {"gripper_grasps", w.gripper_grasps},
         {"suction_grasps", w.suction_grasps},
         {"robot_handovers", w.robot_handovers},
         {"set_downs", w.set_downs},
         {"goals_connected_offline", w.exchange() || w.kind == Way::Kind::kSuction
                                         ? nlohmann::json(w.connected.size())
                                         : nlohmann::json(nullptr)}});
  }
  g.json = {{"part", part.name},
            {"order", part.assembly_order},
            {"failure", stage.failure},
            {"regrasp_stored", regrasp_stored},
            {"suction_tool_relay", database.meta().tool_relay
                                       ? nlohmann::json(pose_values(*database.meta().tool_relay))
                                       : nlohmann::json(nullptr)},
            {"summary",
             {{"goals", g.goals.size()},
              {"goals_direct", goals_direct},
              {"goals_regrasp", goals_regrasp},
              {"goals_exchange", goals_exchange},
              {"goals_suction", goals_suction},
              {"goals_connected_offline", goals_connected.size()},
              {"robot_handovers", g.robot_handovers.size()},
              {"ways", ways_json}}},
            {"nodes", nodes},
            {"edges", edges}};
  return g;
}

void print_text(const Graph& g, int shown_goals) {
  const auto& j = g.json;
  const auto& summary = j["summary"];
  std::cout << "graph of " << j["part"].get<std::string>() << " (order " << j["order"]
            << "): " << count(g.goals.size(), "goal") << ", " << summary["goals_exchange"]
            << " by exchange, " << summary["goals_direct"] << " direct, "
            << summary["goals_regrasp"] << " by a regrasp on the table, "
            << summary["goals_suction"] << " on the suction cup; "
            << count(g.robot_handovers.size(), "robot-robot pose") << "\n";
  if (!j["suction_tool_relay"].is_null()) {
    const auto& xyz = j["suction_tool_relay"]["xyz"];
    std::cout << "  suction tool relay (where the arm that reaches the stand sets the tool down "
                 "for the other): ("
              << xyz[0].get<double>() << ", " << xyz[1].get<double>() << ", "
              << xyz[2].get<double>() << ") m\n";
  }
  if (!g.ways.empty()) {
    std::cout << "  way                       goals  best rank  grasps\n";
  }
  for (const auto& w : g.ways) {
    std::string grasps = std::to_string(w.gripper_grasps.size()) + " gripper";
    if (w.kind == Way::Kind::kRegrasp) {
      grasps += " at " + count(w.set_downs.size(), "set-down");
    } else if (w.kind == Way::Kind::kSuction) {
      grasps = std::to_string(w.suction_grasps.size()) + " suction";
    } else if (w.exchange()) {
      grasps += ", " + std::to_string(w.suction_grasps.size()) + " suction at " +
                count(w.robot_handovers.size(), "robot-robot pose");
    }
    std::cout << "  " << std::left << std::setw(24) << w.name() << std::right << std::setw(7)
              << w.ranks.size() << std::setw(11) << *w.ranks.begin() << "  " << grasps << "\n";
  }
  for (const auto& w : g.ways) {
    if (w.kind == Way::Kind::kSuction) {
      std::cout << "  " << w.name() << ": " << count(w.connected.size(), "goal")
                << " with a stored pick and transfer to the goal\n";
    } else if (!w.exchange()) {
      std::cout << "  " << w.name()
                << ": no stored path (the online planner plans it through the arm's roadmap)\n";
    } else if (!j["regrasp_stored"].get<bool>()) {
      std::cout << "  " << w.name() << ": the database holds no regrasp graph for this part\n";
    } else {
      std::cout << "  " << w.name() << ": " << count(w.connected.size(), "goal")
                << " connected end to end in the regrasp graph"
                << (w.connected.empty()
                        ? ""
                        : " (" + std::string(w.connected.size() == 1 ? "rank " : "ranks ") +
                              id_list(w.connected, 5) + ")")
                << "\n";
    }
  }
  if (!g.goals.empty()) {
    std::cout << "goals in rank order (" << std::min<std::size_t>(g.goals.size(), shown_goals)
              << " of " << g.goals.size() << ")\n";
  }
  if (!g.goals.empty() && shown_goals > 0 && summary["goals_exchange"].get<int>() > 0) {
    std::cout << "  (not stored: the regrasp graph has no such edge; the build examines the goals\n"
                 "  in rank order and stops after a few are served)\n";
  }
  int shown = 0;
  for (const auto& goal : g.goals) {
    if (shown++ == shown_goals) {
      std::cout << "  ... " << g.goals.size() - static_cast<std::size_t>(shown_goals)
                << " more (--goals N, --json)\n";
      break;
    }
    const auto& c = goal.candidate;
    std::string hand = c.human_arm + " (" + std::to_string(c.human_grasp_id) + ")";
    if (!c.second_arm.empty()) {
      hand += " + " + c.second_arm + " (" + std::to_string(c.second_grasp_id) + ")";
    }
    std::cout << "  rank " << c.rank << "  distance " << std::fixed << std::setprecision(3)
              << c.distance << " m  Q " << c.quality << "  human " << hand << "\n";
    std::map<std::string, std::set<Id>> direct;  // arm -> grasps
    for (const auto& d : goal.direct) direct[d.arm].insert(d.robot_grasp_id);
    for (const auto& [arm, grasps] : direct) {
      std::cout << "    direct by " << arm << ": " << count(grasps.size(), "gripper grasp") << " "
                << id_list(grasps) << " (planned online)\n";
    }
    // By arm, "A -> B" for a relay.
    std::map<std::string, std::vector<const db::TableRegraspRecord*>> regrasps;
    for (const auto& r : goal.regrasps) {
      regrasps[r.repick_arm == r.arm ? r.arm : r.arm + " -> " + r.repick_arm].push_back(&r);
    }
    for (const auto& [arm, list] : regrasps) {
      std::string pairs;
      for (std::size_t i = 0; i < list.size() && i < 4; ++i) {
        pairs += (i == 0 ? "" : ", ") + std::to_string(list[i]->pick_grasp_id) + " -> " +
                 std::to_string(list[i]->robot_grasp_id);
      }
      if (list.size() > 4) pairs += ", ...";
      std::cout << "    "
                << (arm.find(" -> ") == std::string::npos ? "regrasp on table by " : "relay on table ")
                << arm << ": " << count(list.size(), "set-down")
                << " (grasps picked -> taken again: " << pairs << "; planned online)\n";
    }
    std::map<std::string, std::set<Id>> on_cup;  // arm -> suction grasps
    for (const auto& d : goal.on_cup) on_cup[d.arm].insert(d.suction_grasp_id);
    for (const auto& [arm, cups] : on_cup) {
      int stored = 0;
      for (const Id cup : cups) {
        stored += connected(find(g.regrasp.cup_to_goal, std::make_pair(cup, c.id))) ? 1 : 0;
      }
      std::cout << "    on the cup by " << arm << ": " << count(cups.size(), "suction grasp") << " "
                << id_list(cups) << " (" << stored << " with a stored transfer)\n";
    }
    // Exchange ways, each by robot-robot pose: the suction arm's pick and transfer to it, the
    // receiving arm's way in, and its best stored transfer to the goal over the grasps there.
    std::map<WayKey, std::map<Id, std::vector<const db::SharedGraspRecord*>>> exchanges;
    for (const auto& s : goal.shared) {
      const auto& rr = g.robot_handovers.at(s.robot_handover_id);
      exchanges[{rr.arm, s.arm}][rr.id].push_back(&s);
    }
    for (const auto& [key, by_rr] : exchanges) {
      std::set<Id> grasps;
      for (const auto& [rr, shared] : by_rr) {
        for (const auto* s : shared) grasps.insert(s->robot_grasp_id);
      }
      std::cout << "    exchange " << key.first << " -> " << key.second << ": "
                << count(grasps.size(), "gripper grasp") << " at "
                << count(by_rr.size(), "robot-robot pose") << "\n"
                << "        rr   cup  grasps  " << std::left << std::setw(28)
                << key.first + " pick+transfer" << std::setw(20) << key.second + " way in"
                << key.second + " transfer to goal" << std::right << "\n";
      for (const auto& [id, shared] : by_rr) {
        const auto& rr = g.robot_handovers.at(id);
        const Stored* transit = find(g.regrasp.pick_transit, rr.suction_grasp_id);
        const std::string to_rr = transit != nullptr && !transit->connected
                                      ? "pick not reached"
                                      : status(find(g.regrasp.cup_transfer, id));
        // The receiving arm's way in, counted over the goal's grasps here, and its best stored
        // transfer to the goal.
        int ways_in = 0, ways_in_connected = 0;
        const Stored* to_goal = nullptr;
        Id to_goal_grasp = 0;
        int tried = 0;
        for (const auto* s : shared) {
          const Stored* in = find(g.regrasp.way_in, RrGrasp{id, s->robot_grasp_id});
          ways_in += in != nullptr ? 1 : 0;
          ways_in_connected += connected(in) ? 1 : 0;
          const Stored* t = find(g.regrasp.to_goal, RrGraspGoal{id, s->robot_grasp_id, c.id});
          if (t == nullptr) continue;
          ++tried;
          if (to_goal == nullptr || (t->connected && !to_goal->connected) ||
              (t->connected && t->cost < to_goal->cost)) {
            to_goal = t;
            to_goal_grasp = s->robot_grasp_id;
          }
        }
        const std::string way_in = ways_in == 0 ? "not stored"
                                                : std::to_string(ways_in_connected) + "/" +
                                                      std::to_string(ways_in) + " connected";
        std::string delivered = status(to_goal);
        if (connected(to_goal)) {
          delivered = std::to_string(to_goal_grasp) + ": " + delivered;
        } else if (to_goal != nullptr) {
          delivered += " (" + count(static_cast<std::size_t>(tried), "grasp") + ")";
        }
        std::cout << "      " << std::setw(4) << id << std::setw(6) << rr.suction_grasp_id
                  << std::setw(8) << shared.size() << "  " << std::left << std::setw(28) << to_rr
                  << std::setw(20) << way_in << delivered << std::right << "\n";
      }
    }
  }
  if (g.goals.empty()) {
    std::cout << "no goal: " << j["failure"].get<std::string>() << "\n";
  }
}

}  // namespace

int inspect_graph(const db::Database& database, const std::string& part_name, int goals,
                  bool json) {
  if (part_name.empty()) {
    throw core::InputError("command line", "--part", "the name of a part", "nothing");
  }
  if (goals < 0) {
    throw core::InputError("command line", "--goals", "a number of goals >= 0",
                           std::to_string(goals));
  }
  const auto& part = database.part(part_name);
  const db::HandoverStageRecord* stage = database.handover_stage(part.id);
  if (stage == nullptr) {
    throw core::InputError(database.path(), "handover_stages",
                           "handover goals for '" + part_name + "'",
                           "none (a database from before schema 3: rebuild it with hila build)");
  }
  const Graph g = build_graph(database, part, *stage);
  if (json) {
    std::cout << g.json.dump(2) << "\n";
    return 0;
  }
  print_text(g, goals);
  return 0;
}

}  // namespace hila::tools
