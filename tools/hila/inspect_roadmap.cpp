#include "inspect_roadmap.hpp"

#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <tuple>

#include "hila/core/error.hpp"
#include "hila/core/roadmap_graph.hpp"

namespace hila::tools {

namespace {

nlohmann::json roadmap_json(const db::RoadmapRecord& r) {
  const auto components = core::connected_components(static_cast<int>(r.nodes.size()), r.edges,
                                                     std::vector<bool>(r.edges.size(), true));
  std::map<int, int> sizes;
  for (const int c : components) ++sizes[c];
  int largest = 0;
  for (const auto& [c, n] : sizes) largest = std::max(largest, n);
  int within_11 = 0, within_22 = 0;
  for (const double d : r.node_inclination_deg) {
    within_11 += d <= 11.0 ? 1 : 0;
    within_22 += d <= 22.0 ? 1 : 0;
  }
  double length = 0.0;
  for (const double l : r.edge_length) length += l;
  return {{"id", r.id},
          {"arm", r.arm},
          {"dof", r.dof},
          {"resolution_rad", r.resolution},
          {"nodes", r.nodes.size()},
          {"edges", r.edges.size()},
          {"mean_edge_length_rad", r.edges.empty() ? 0.0 : length / r.edges.size()},
          {"components", sizes.size()},
          {"largest_component", largest},
          {"nodes_inclination_within_11_deg", within_11},
          {"nodes_inclination_within_22_deg", within_22}};
}

nlohmann::json board_json(const db::Database& database, const db::PartRecord& part,
                          const std::map<std::int64_t, std::string>& roadmap_arm,
                          const std::string& arm) {
  nlohmann::json filters = nlohmann::json::array();
  for (const auto& f : database.roadmap_filters(part.id)) {
    const std::string& a = roadmap_arm.at(f.roadmap_id);
    if (!arm.empty() && a != arm) continue;
    filters.push_back({{"id", f.id},
                       {"arm", a},
                       {"grasp_kind", f.grasp_kind},
                       {"grasp_id", f.grasp_id},
                       {"theta_c_deg", f.theta_c_deg},
                       {"valid_edges", f.valid_edges},
                       {"components", f.components},
                       {"largest_component", f.largest_component}});
  }
  const auto nodes = database.regrasp_nodes(part.id);
  const auto edges = database.regrasp_edges(part.id);
  std::map<std::int64_t, const db::RegraspNodeRecord*> node_by_id;
  for (const auto& n : nodes) node_by_id[n.id] = &n;
  std::map<std::string, std::pair<int, int>> by_kind;  // "kind arm" -> (connected, total)
  int bridges = 0;
  // A goal (robot-human pose) connects when some transfer into it is connected and the chain
  // before it is: the transit to its robot-robot node and the suction arm's pick, transit and
  // transfer to the robot-robot pose.
  std::map<std::int64_t, bool> reached;  // node id -> reached from home along connected edges
  for (const auto& n : nodes) reached[n.id] = n.kind == "home";
  for (int pass = 0; pass < 4; ++pass) {  // the chain is 4 edges deep at most
    for (const auto& e : edges) {
      if (e.connected && reached[e.from_node]) reached[e.to_node] = true;
    }
  }
  // A transfer's other bridges are parallel edges after the first (bridge_alternatives): counted
  // apart, so that an edge count is a count of the connections tried.
  std::map<std::int64_t, bool> alternative;  // edge id -> repeats an earlier edge's ends
  {
    std::map<std::tuple<std::string, std::int64_t, std::int64_t>, bool> seen;
    for (const auto& e : edges) {
      auto& s = seen[std::make_tuple(e.kind, e.from_node, e.to_node)];
      alternative[e.id] = s;
      s = true;
    }
  }
  int alternatives = 0;
  for (const auto& e : edges) {
    if (!arm.empty() && e.arm != arm) continue;
    if (alternative[e.id]) {
      ++alternatives;
      continue;
    }
    auto& k = by_kind[e.kind + " " + e.arm];
    k.first += e.connected ? 1 : 0;
    ++k.second;
    bridges += e.via == "bridge" ? 1 : 0;
  }
  // Handover edges only say the exchange is possible; the receiving arm's robot-robot node is
  // reached when both arms get there.
  std::map<std::int64_t, bool> rr_ready;
  for (const auto& e : edges) {
    if (e.kind != "handover") continue;
    bool left = false;
    for (const auto& t : edges) {
      if (t.kind == "transit" && t.to_node == e.to_node && t.connected) left = true;
    }
    rr_ready[e.to_node] = left && reached[e.from_node];
  }
  nlohmann::json goals = nlohmann::json::array();
  bool any = false;
  std::map<std::int64_t, nlohmann::json> goal_by_candidate;
  for (const auto& e : edges) {
    if (e.kind != "transfer" || alternative[e.id]) continue;
    const auto* to = node_by_id[e.to_node];
    if (to->kind != "human_handover") continue;
    auto& g = goal_by_candidate[to->candidate_id];
    if (g.is_null()) {
      g = {{"candidate_id", to->candidate_id}, {"transfers", 0}, {"connected", false}};
    }
    g["transfers"] = g["transfers"].get<int>() + 1;
    const bool chain = e.connected && rr_ready[e.from_node];
    if (chain && (!g["connected"].get<bool>() || e.cost < g["cost_rad"].get<double>())) {
      g["connected"] = true;
      g["grasp_id"] = to->grasp_id;
      g["cost_rad"] = e.cost;
      g["via"] = e.via;
    }
  }
  std::map<std::int64_t, int> rank;
  for (const auto& c : database.handover_goals(part.id)) rank[c.id] = c.rank;
  std::vector<std::pair<int, nlohmann::json>> ordered;
  for (auto& [c, g] : goal_by_candidate) {
    g["rank"] = rank.count(c) ? rank[c] : -1;
    any = any || g["connected"].get<bool>();
    ordered.emplace_back(g["rank"].get<int>(), g);
  }
  std::sort(ordered.begin(), ordered.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (auto& [r, g] : ordered) goals.push_back(g);
  nlohmann::json kinds = nlohmann::json::object();
  for (const auto& [k, v] : by_kind) kinds[k] = {{"connected", v.first}, {"total", v.second}};
  return {{"part", part.name},
          {"order", part.assembly_order},
          {"filters", filters},
          {"regrasp_nodes", nodes.size()},
          {"regrasp_edges", kinds},
          {"bridges", bridges},
          {"alternative_bridges", alternatives},
          {"goals", goals},
          {"goal_connected", any}};
}

}  // namespace

int inspect_roadmap(const db::Database& database, const std::string& arm, const std::string& part,
                    bool json) {
  if (database.roadmaps().empty()) {
    throw core::InputError(database.path(), "roadmaps", "robot roadmaps",
                           "none (a database from before schema 4: rebuild it with hila build)");
  }
  nlohmann::json roadmaps = nlohmann::json::array();
  std::map<std::int64_t, std::string> roadmap_arm;
  for (const auto& r : database.roadmaps()) {
    roadmap_arm[r.id] = r.arm;
    if (arm.empty() || r.arm == arm) roadmaps.push_back(roadmap_json(r));
  }
  if (roadmaps.empty()) {
    std::string arms;
    for (const auto& [id, a] : roadmap_arm) arms += (arms.empty() ? "'" : ", '") + a + "'";
    throw core::InputError("command line", "--arm", "an arm with a roadmap (" + arms + ")",
                           "'" + arm + "'");
  }
  nlohmann::json boards = nlohmann::json::array();
  bool all = true;
  for (const auto& p : database.parts()) {
    if (!part.empty() && p.name != part) continue;
    boards.push_back(board_json(database, p, roadmap_arm, arm));
    all = all && boards.back()["goal_connected"].get<bool>();
  }
  if (!part.empty() && boards.empty()) database.part(part);  // throws naming the part
  const nlohmann::json out = {
      {"roadmaps", roadmaps}, {"boards", boards}, {"every_board_has_a_connected_goal", all}};
  if (json) {
    std::cout << out.dump(2) << "\n";
    return 0;
  }
  for (const auto& r : roadmaps) {
    std::cout << "roadmap, " << r["arm"].get<std::string>() << " arm: " << r["nodes"] << " nodes, "
              << r["edges"] << " edges (mean " << std::fixed << std::setprecision(2)
              << r["mean_edge_length_rad"].get<double>() << " rad, checked every "
              << r["resolution_rad"].get<double>() << " rad), " << r["components"]
              << " components (largest " << r["largest_component"]
              << "); opening axis within 11/22 deg "
              << "of vertical at " << r["nodes_inclination_within_11_deg"] << "/"
              << r["nodes_inclination_within_22_deg"] << " nodes\n";
  }
  for (const auto& b : boards) {
    std::cout << b["order"] << "  " << b["part"].get<std::string>() << ": " << b["filters"].size()
              << " filters, " << b["regrasp_nodes"] << " regrasp nodes, " << b["bridges"]
              << " bridged edges (" << b["alternative_bridges"]
              << " more as alternatives); goal connected: "
              << (b["goal_connected"].get<bool>() ? "yes" : "NO") << "\n";
    for (const auto& f : b["filters"]) {
      std::cout << "     filter " << std::setw(4) << f["id"] << "  " << std::setw(5)
                << f["arm"].get<std::string>() << " " << std::setw(7)
                << f["grasp_kind"].get<std::string>() << " " << std::setw(5) << f["grasp_id"]
                << "  theta_c " << std::setw(3) << std::setprecision(0)
                << f["theta_c_deg"].get<double>() << "  " << std::setw(6) << f["valid_edges"]
                << " edges, " << std::setw(5) << f["components"] << " components (largest "
                << f["largest_component"] << ")\n";
    }
    for (const auto& [k, v] : b["regrasp_edges"].items()) {
      std::cout << "     " << std::left << std::setw(16) << k << std::right << v["connected"] << "/"
                << v["total"] << " connected\n";
    }
    for (const auto& g : b["goals"]) {
      std::cout << "     goal rank " << std::setw(2) << g["rank"] << ": "
                << (g["connected"].get<bool>()
                        ? "connected via " + g["via"].get<std::string>() + ", " +
                              std::to_string(g["cost_rad"].get<double>()).substr(0, 5) +
                              " rad, grasp " + std::to_string(g["grasp_id"].get<std::int64_t>())
                        : std::string("not connected"))
                << " (" << g["transfers"] << " transfers tried)\n";
    }
  }
  std::cout << "every board has a connected goal: " << (all ? "yes" : "NO") << "\n";
  return 0;
}

}  // namespace hila::tools
