#include "hila/core/roadmap_graph.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

namespace hila::core {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

}  // namespace

RoadmapGraph::RoadmapGraph(std::vector<Eigen::VectorXd> nodes,
                           std::vector<std::pair<int, int>> edges)
    : nodes_(std::move(nodes)), edges_(std::move(edges)) {
  const int n = node_count();
  offsets_.assign(static_cast<std::size_t>(n) + 1, 0);
  lengths_.reserve(edges_.size());
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const auto [a, b] = edges_[e];
    if (a < 0 || b < 0 || a >= n || b >= n || a == b) {
      throw std::invalid_argument("roadmap edge " + std::to_string(e) +
                                  ": expected two distinct nodes in [0, " + std::to_string(n) +
                                  "), got (" + std::to_string(a) + ", " + std::to_string(b) + ")");
    }
    lengths_.push_back(
        (nodes_[static_cast<std::size_t>(a)] - nodes_[static_cast<std::size_t>(b)]).norm());
    ++offsets_[static_cast<std::size_t>(a) + 1];
    ++offsets_[static_cast<std::size_t>(b) + 1];
  }
  for (int i = 0; i < n; ++i) {
    offsets_[static_cast<std::size_t>(i) + 1] += offsets_[static_cast<std::size_t>(i)];
  }
  adjacency_.resize(2 * edges_.size());
  std::vector<int> fill(offsets_.begin(), offsets_.end() - 1);
  for (std::size_t e = 0; e < edges_.size(); ++e) {
    const auto [a, b] = edges_[e];
    adjacency_[static_cast<std::size_t>(fill[static_cast<std::size_t>(a)]++)] = {
        b, static_cast<int>(e)};
    adjacency_[static_cast<std::size_t>(fill[static_cast<std::size_t>(b)]++)] = {
        a, static_cast<int>(e)};
  }
}

void GraphSearchWorkspace::reset(int node_count) {
  const auto n = static_cast<std::size_t>(node_count);
  if (g.size() != n) {
    g.assign(n, kInfinity);
    parent.assign(n, -1);
    exit_cost.assign(n, kInfinity);
    stamp.assign(n, 0);
    closed.assign(n, 0);
    generation = 0;
  }
  ++generation;
  if (generation == 0) {  // wrapped: clear the stamps once every 2^32 queries
    std::fill(stamp.begin(), stamp.end(), 0);
    std::fill(closed.begin(), closed.end(), 0);
    generation = 1;
  }
  heap.clear();
}

GraphPath shortest_path(const RoadmapGraph& graph, const std::vector<bool>& allowed,
                        const std::vector<GraphEndpoint>& entries,
                        const std::vector<GraphEndpoint>& exits, GraphSearchWorkspace& ws) {
  GraphPath path;
  const int n = graph.node_count();
  if (static_cast<int>(allowed.size()) != graph.edge_count() || entries.empty() || exits.empty()) {
    return path;
  }
  ws.reset(n);
  const std::uint32_t gen = ws.generation;
  auto valid_node = [n](int v) { return v >= 0 && v < n; };
  // Exit costs live in the workspace, stamped with the generation like g.
  std::vector<GraphEndpoint> targets;
  targets.reserve(exits.size());
  for (const auto& x : exits) {
    if (!valid_node(x.node)) continue;
    targets.push_back(x);
  }
  if (targets.empty()) return path;
  auto touch = [&](int v) {
    const auto i = static_cast<std::size_t>(v);
    if (ws.stamp[i] != gen) {
      ws.stamp[i] = gen;
      ws.g[i] = kInfinity;
      ws.parent[i] = -1;
      ws.exit_cost[i] = kInfinity;
    }
  };
  for (const auto& x : targets) {
    touch(x.node);
    auto& c = ws.exit_cost[static_cast<std::size_t>(x.node)];
    c = std::min(c, x.cost);
  }
  const bool same_exits =
      ws.heuristic_graph == &graph && ws.heuristic.size() == static_cast<std::size_t>(n) &&
      ws.heuristic_generation != 0 &&
      std::equal(targets.begin(), targets.end(), ws.heuristic_exits.begin(),
                 ws.heuristic_exits.end(), [](const GraphEndpoint& a, const GraphEndpoint& b) {
                   return a.node == b.node && a.cost == b.cost;
                 });
  if (!same_exits) {
    if (ws.heuristic.size() != static_cast<std::size_t>(n)) {
      ws.heuristic.assign(static_cast<std::size_t>(n), kInfinity);
      ws.heuristic_stamp.assign(static_cast<std::size_t>(n), 0);
      ws.heuristic_generation = 0;
    }
    if (++ws.heuristic_generation == 0) {  // wrapped
      std::fill(ws.heuristic_stamp.begin(), ws.heuristic_stamp.end(), 0);
      ws.heuristic_generation = 1;
    }
    ws.heuristic_graph = &graph;
    ws.heuristic_exits = targets;
  }
  auto heuristic = [&](int v) {
    const auto i = static_cast<std::size_t>(v);
    if (ws.heuristic_stamp[i] == ws.heuristic_generation) return ws.heuristic[i];
    double h = kInfinity;
    const Eigen::VectorXd& q = graph.node(v);
    for (const auto& x : targets) h = std::min(h, (q - graph.node(x.node)).norm() + x.cost);
    ws.heuristic_stamp[i] = ws.heuristic_generation;
    ws.heuristic[i] = h;
    return h;
  };
  auto greater = [](const std::pair<double, int>& a, const std::pair<double, int>& b) {
    return a.first > b.first || (a.first == b.first && a.second > b.second);
  };
  auto push = [&](int v, double f) {
    ws.heap.emplace_back(f, v);
    std::push_heap(ws.heap.begin(), ws.heap.end(), greater);
  };
  for (const auto& s : entries) {
    if (!valid_node(s.node)) continue;
    touch(s.node);
    auto& g = ws.g[static_cast<std::size_t>(s.node)];
    if (s.cost < g) {
      g = s.cost;
      ws.parent[static_cast<std::size_t>(s.node)] = -1;
      push(s.node, s.cost + heuristic(s.node));
    }
  }
  // Leaving through an exit is a final step of cost exit_cost: the search ends when the best
  // completed path is no worse than the lowest f left on the open list.
  double best = kInfinity;
  int best_exit = -1;
  while (!ws.heap.empty()) {
    std::pop_heap(ws.heap.begin(), ws.heap.end(), greater);
    const auto [f, v] = ws.heap.back();
    ws.heap.pop_back();
    if (f >= best) break;
    const auto vi = static_cast<std::size_t>(v);
    if (ws.closed[vi] == gen) continue;
    ws.closed[vi] = gen;
    ++path.expanded;
    const double gv = ws.g[vi];
    if (gv + ws.exit_cost[vi] < best) {
      best = gv + ws.exit_cost[vi];
      best_exit = v;
    }
    for (const auto* it = graph.neighbours_begin(v); it != graph.neighbours_end(v); ++it) {
      if (!allowed[static_cast<std::size_t>(it->edge)]) continue;
      touch(it->node);
      const auto wi = static_cast<std::size_t>(it->node);
      if (ws.closed[wi] == gen) continue;
      const double gw = gv + graph.edge_length(it->edge);
      if (gw < ws.g[wi]) {
        ws.g[wi] = gw;
        ws.parent[wi] = v;
        push(it->node, gw + heuristic(it->node));
      }
    }
  }
  if (best_exit < 0) return path;
  path.found = true;
  path.cost = best;
  for (int v = best_exit; v >= 0; v = ws.parent[static_cast<std::size_t>(v)]) {
    path.nodes.push_back(v);
  }
  std::reverse(path.nodes.begin(), path.nodes.end());
  return path;
}

std::vector<int> connected_components(int node_count, const std::vector<std::pair<int, int>>& edges,
                                      const std::vector<bool>& allowed) {
  std::vector<int> parent(static_cast<std::size_t>(node_count));
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto find = [&](int x) {
    while (parent[static_cast<std::size_t>(x)] != x) {
      parent[static_cast<std::size_t>(x)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
      x = parent[static_cast<std::size_t>(x)];
    }
    return x;
  };
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (!allowed[e]) continue;
    const int ra = find(edges[e].first), rb = find(edges[e].second);
    if (ra != rb) parent[static_cast<std::size_t>(std::max(ra, rb))] = std::min(ra, rb);
  }
  std::vector<int> id(parent.size(), -1);
  std::vector<int> root_id(parent.size(), -1);
  int next = 0;
  for (std::size_t i = 0; i < parent.size(); ++i) {
    const auto r = static_cast<std::size_t>(find(static_cast<int>(i)));
    if (root_id[r] < 0) root_id[r] = next++;
    id[i] = root_id[r];
  }
  return id;
}

}  // namespace hila::core
