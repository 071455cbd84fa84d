#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/roadmap_graph.hpp"

using namespace hila;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Problem {
  std::vector<Eigen::VectorXd> nodes;
  std::vector<std::pair<int, int>> edges;
  std::vector<bool> allowed;
};

struct Query {
  std::vector<core::GraphEndpoint> entries;
  std::vector<core::GraphEndpoint> exits;
};

Problem random_problem(std::mt19937_64& rng) {
  Problem p;
  const int n = std::uniform_int_distribution<int>(20, 60)(rng);
  const int dim = std::bernoulli_distribution(0.5)(rng) ? 3 : 6;
  std::uniform_real_distribution<double> coord(-1.0, 1.0);
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd q(dim);
    for (int d = 0; d < dim; ++d) q[d] = coord(rng);
    p.nodes.push_back(q);
  }
  // Sparse enough that some queries are cut off, dense enough that most are not.
  const int m = std::uniform_int_distribution<int>(n, 3 * n)(rng);
  std::uniform_int_distribution<int> pick(0, n - 1);
  while (static_cast<int>(p.edges.size()) < m) {
    const int a = pick(rng), b = pick(rng);
    if (a != b) p.edges.emplace_back(a, b);
  }
  const double keep = std::uniform_real_distribution<double>(0.4, 1.0)(rng);
  std::bernoulli_distribution allowed(keep);
  for (int e = 0; e < m; ++e) p.allowed.push_back(allowed(rng));
  return p;
}

Query random_query(std::mt19937_64& rng, int n) {
  Query q;
  std::uniform_int_distribution<int> pick(0, n - 1);
  std::uniform_int_distribution<int> count(1, 3);
  std::uniform_real_distribution<double> cost(0.0, 2.0);
  const int ne = count(rng), nx = count(rng);
  for (int i = 0; i < ne; ++i) q.entries.push_back({pick(rng), cost(rng)});
  for (int i = 0; i < nx; ++i) q.exits.push_back({pick(rng), cost(rng)});
  return q;
}

// Independent reference: Floyd-Warshall over the allowed edges, lengths recomputed from the
// nodes, then the best entry/exit combination.
double reference_cost(const Problem& p, const Query& q) {
  const std::size_t n = p.nodes.size();
  std::vector<std::vector<double>> d(n, std::vector<double>(n, kInf));
  for (std::size_t i = 0; i < n; ++i) d[i][i] = 0.0;
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    if (!p.allowed[e]) continue;
    const auto a = static_cast<std::size_t>(p.edges[e].first);
    const auto b = static_cast<std::size_t>(p.edges[e].second);
    double len = 0.0;
    for (Eigen::Index k = 0; k < p.nodes[a].size(); ++k) {
      const double diff = p.nodes[a][k] - p.nodes[b][k];
      len += diff * diff;
    }
    len = std::sqrt(len);
    d[a][b] = std::min(d[a][b], len);
    d[b][a] = std::min(d[b][a], len);
  }
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < n; ++i) {
      if (d[i][k] == kInf) continue;
      for (std::size_t j = 0; j < n; ++j) {
        if (d[i][k] + d[k][j] < d[i][j]) d[i][j] = d[i][k] + d[k][j];
      }
    }
  }
  double best = kInf;
  for (const auto& s : q.entries) {
    for (const auto& x : q.exits) {
      const double c =
          s.cost + d[static_cast<std::size_t>(s.node)][static_cast<std::size_t>(x.node)] + x.cost;
      best = std::min(best, c);
    }
  }
  return best;
}

// Checks the returned node sequence against the problem: starts at an entry, ends at an exit,
// consecutive nodes joined by an allowed edge, and its own cost equals the reported cost.
void check_path(const Problem& p, const Query& q, const core::GraphPath& path) {
  ASSERT_FALSE(path.nodes.empty());
  double entry = kInf, exit = kInf;
  for (const auto& s : q.entries) {
    if (s.node == path.nodes.front()) entry = std::min(entry, s.cost);
  }
  for (const auto& x : q.exits) {
    if (x.node == path.nodes.back()) exit = std::min(exit, x.cost);
  }
  ASSERT_LT(entry, kInf) << "path does not start at an entry node";
  ASSERT_LT(exit, kInf) << "path does not end at an exit node";
  std::set<std::pair<int, int>> allowed_pairs;
  for (std::size_t e = 0; e < p.edges.size(); ++e) {
    if (!p.allowed[e]) continue;
    allowed_pairs.insert(p.edges[e]);
    allowed_pairs.emplace(p.edges[e].second, p.edges[e].first);
  }
  double sum = entry + exit;
  for (std::size_t i = 0; i + 1 < path.nodes.size(); ++i) {
    const int a = path.nodes[i], b = path.nodes[i + 1];
    ASSERT_TRUE(allowed_pairs.count({a, b}))
        << "step " << i << " (" << a << " -> " << b << ") is not an allowed edge";
    sum += (p.nodes[static_cast<std::size_t>(a)] - p.nodes[static_cast<std::size_t>(b)]).norm();
  }
  EXPECT_NEAR(sum, path.cost, 1e-9);
}

// Independent reference: BFS over the allowed edges, ids in order of each component's lowest
// node (the first node the outer loop meets).
std::vector<int> reference_components(int n, const std::vector<std::pair<int, int>>& edges,
                                      const std::vector<bool>& allowed) {
  std::vector<std::vector<int>> adj(static_cast<std::size_t>(n));
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (!allowed[e]) continue;
    adj[static_cast<std::size_t>(edges[e].first)].push_back(edges[e].second);
    adj[static_cast<std::size_t>(edges[e].second)].push_back(edges[e].first);
  }
  std::vector<int> id(static_cast<std::size_t>(n), -1);
  int next = 0;
  for (int s = 0; s < n; ++s) {
    if (id[static_cast<std::size_t>(s)] >= 0) continue;
    std::queue<int> open;
    open.push(s);
    id[static_cast<std::size_t>(s)] = next;
    while (!open.empty()) {
      const int v = open.front();
      open.pop();
      for (int w : adj[static_cast<std::size_t>(v)]) {
        if (id[static_cast<std::size_t>(w)] < 0) {
          id[static_cast<std::size_t>(w)] = next;
          open.push(w);
        }
      }
    }
    ++next;
  }
  return id;
}

Eigen::VectorXd point(double x, double y) {
  Eigen::VectorXd q(2);
  q << x, y;
  return q;
}

}  // namespace

TEST(RoadmapGraph, AdjacencyMatchesEdgeList) {
  std::mt19937_64 rng(11);
  const Problem p = random_problem(rng);
  const core::RoadmapGraph graph(p.nodes, p.edges);
  ASSERT_EQ(graph.node_count(), static_cast<int>(p.nodes.size()));
  ASSERT_EQ(graph.edge_count(), static_cast<int>(p.edges.size()));
  std::multiset<std::pair<int, int>> expected, seen;
  for (int e = 0; e < graph.edge_count(); ++e) {
    const auto [a, b] = p.edges[static_cast<std::size_t>(e)];
    EXPECT_EQ(graph.edge(e), p.edges[static_cast<std::size_t>(e)]);
    EXPECT_NEAR(
        graph.edge_length(e),
        (p.nodes[static_cast<std::size_t>(a)] - p.nodes[static_cast<std::size_t>(b)]).norm(),
        1e-12);
    expected.emplace(a, e);
    expected.emplace(b, e);
  }
  for (int v = 0; v < graph.node_count(); ++v) {
    for (const auto* it = graph.neighbours_begin(v); it != graph.neighbours_end(v); ++it) {
      const auto [a, b] = graph.edge(it->edge);
      EXPECT_TRUE((a == v && b == it->node) || (b == v && a == it->node))
          << "node " << v << " lists neighbour " << it->node << " via edge " << it->edge;
      seen.emplace(v, it->edge);
    }
  }
  EXPECT_EQ(seen, expected);
}

TEST(RoadmapGraph, ShortestPathMatchesFloydWarshall) {
  std::mt19937_64 rng(20240611);
  int found = 0, not_found = 0, multi_node = 0;
  for (int trial = 0; trial < 50; ++trial) {
    SCOPED_TRACE("graph " + std::to_string(trial));
    const Problem p = random_problem(rng);
    const core::RoadmapGraph graph(p.nodes, p.edges);
    for (int k = 0; k < 4; ++k) {
      SCOPED_TRACE("query " + std::to_string(k));
      const Query q = random_query(rng, graph.node_count());
      core::GraphSearchWorkspace ws;
      const core::GraphPath path = core::shortest_path(graph, p.allowed, q.entries, q.exits, ws);
      const double ref = reference_cost(p, q);
      ASSERT_EQ(path.found, ref < kInf);
      if (!path.found) {
        ++not_found;
        EXPECT_TRUE(path.nodes.empty());
        continue;
      }
      ++found;
      if (path.nodes.size() > 2) ++multi_node;
      EXPECT_NEAR(path.cost, ref, 1e-9);
      EXPECT_GE(path.expanded, 1);
      check_path(p, q, path);
    }
  }
  // The random problems exercise both outcomes and non-trivial paths.
  EXPECT_GT(found, 50);
  EXPECT_GT(not_found, 5);
  EXPECT_GT(multi_node, 20);
}

TEST(RoadmapGraph, ReusedWorkspaceMatchesFreshWorkspace) {
  std::mt19937_64 rng(77);
  core::GraphSearchWorkspace shared;
  int compared = 0;
  for (int trial = 0; trial < 50; ++trial) {
    // Graphs of varying size (the workspace resizes) and several queries per graph (it does not).
    const Problem p = random_problem(rng);
    const core::RoadmapGraph graph(p.nodes, p.edges);
    for (int k = 0; k < 4; ++k) {
      const Query q = random_query(rng, graph.node_count());
      core::GraphSearchWorkspace fresh;
      const auto a = core::shortest_path(graph, p.allowed, q.entries, q.exits, shared);
      const auto b = core::shortest_path(graph, p.allowed, q.entries, q.exits, fresh);
      ASSERT_EQ(a.found, b.found) << "graph " << trial << " query " << k;
      EXPECT_EQ(a.cost, b.cost) << "graph " << trial << " query " << k;
      EXPECT_EQ(a.nodes, b.nodes) << "graph " << trial << " query " << k;
      EXPECT_EQ(a.expanded, b.expanded) << "graph " << trial << " query " << k;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 200);
}

// A lazy planner's loop: the same query searched again after each edge of the found path is
// dropped, on one workspace (which keeps the heuristic while the exits stay the same), against
// a fresh workspace and Floyd-Warshall every time; then a second graph of the same size with
// the same exits on that workspace (its heuristic must not be reused).
TEST(RoadmapGraph, RepeatedSearchesWithDroppedEdgesMatchFreshSearches) {
  std::mt19937_64 rng(91);
  core::GraphSearchWorkspace shared;
  int searches = 0, dropped = 0;
  for (int trial = 0; trial < 30; ++trial) {
    SCOPED_TRACE("graph " + std::to_string(trial));
    Problem p = random_problem(rng);
    const core::RoadmapGraph graph(p.nodes, p.edges);
    const Query q = random_query(rng, graph.node_count());
    for (int round = 0; round < 20; ++round) {
      core::GraphSearchWorkspace fresh;
      const auto a = core::shortest_path(graph, p.allowed, q.entries, q.exits, shared);
      const auto b = core::shortest_path(graph, p.allowed, q.entries, q.exits, fresh);
      ++searches;
      ASSERT_EQ(a.found, b.found);
      ASSERT_EQ(a.found, reference_cost(p, q) < kInf);
      if (!a.found) break;
      EXPECT_EQ(a.nodes, b.nodes);
      EXPECT_EQ(a.expanded, b.expanded);
      EXPECT_NEAR(a.cost, reference_cost(p, q), 1e-9);
      if (a.nodes.size() < 2) break;
      // Drop every allowed edge joining the path's middle pair, as an invalidated edge.
      const std::size_t i = a.nodes.size() / 2;
      const std::pair<int, int> hop{a.nodes[i - 1], a.nodes[i]};
      for (std::size_t e = 0; e < p.edges.size(); ++e) {
        if (p.edges[e] == hop || p.edges[e] == std::make_pair(hop.second, hop.first)) {
          dropped += p.allowed[e] ? 1 : 0;
          p.allowed[e] = false;
        }
      }
    }
    // Same node count, same exits, other coordinates.
    Problem moved = p;
    for (auto& q_node : moved.nodes) q_node *= -2.0;
    const core::RoadmapGraph other(moved.nodes, moved.edges);
    core::GraphSearchWorkspace fresh;
    const auto a = core::shortest_path(other, moved.allowed, q.entries, q.exits, shared);
    const auto b = core::shortest_path(other, moved.allowed, q.entries, q.exits, fresh);
    ASSERT_EQ(a.found, b.found);
    EXPECT_EQ(a.nodes, b.nodes);
    EXPECT_EQ(a.expanded, b.expanded);
  }
  EXPECT_GT(searches, 100);
  EXPECT_GT(dropped, 50);
}

TEST(RoadmapGraph, NeverUsesDisallowedEdge) {
  // A square 0-1-2-3 with the diagonal 0-2 short-cutting it; the diagonal is disallowed, so the
  // path must go around (length 2) instead of across (sqrt 2).
  const std::vector<Eigen::VectorXd> nodes{point(0, 0), point(1, 0), point(1, 1), point(0, 1)};
  const std::vector<std::pair<int, int>> edges{{0, 2}, {0, 1}, {1, 2}, {2, 3}, {3, 0}};
  const core::RoadmapGraph graph(nodes, edges);
  core::GraphSearchWorkspace ws;
  const std::vector<core::GraphEndpoint> entries{{0, 0.0}}, exits{{2, 0.0}};

  auto path = core::shortest_path(graph, {true, true, true, true, true}, entries, exits, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, std::sqrt(2.0), 1e-12);
  EXPECT_EQ(path.nodes, (std::vector<int>{0, 2}));

  path = core::shortest_path(graph, {false, true, true, true, true}, entries, exits, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, 2.0, 1e-12);
  ASSERT_EQ(path.nodes.size(), 3u);
  EXPECT_EQ(path.nodes.front(), 0);
  EXPECT_EQ(path.nodes.back(), 2);

  // With one side of the square also cut, only the other side remains.
  path = core::shortest_path(graph, {false, false, true, true, true}, entries, exits, ws);
  ASSERT_TRUE(path.found);
  EXPECT_EQ(path.nodes, (std::vector<int>{0, 3, 2}));

  // Nothing out of node 0 is allowed: no path, although node 2 is reachable in the full graph.
  path = core::shortest_path(graph, {false, false, true, true, false}, entries, exits, ws);
  EXPECT_FALSE(path.found);
  EXPECT_TRUE(path.nodes.empty());
}

TEST(RoadmapGraph, ParallelEdgesAreJudgedByEdgeNotByNodePair) {
  // Two edges join 0 and 1; only the second is allowed, which is enough.
  const std::vector<Eigen::VectorXd> nodes{point(0, 0), point(3, 4)};
  const core::RoadmapGraph graph(nodes, {{0, 1}, {1, 0}});
  core::GraphSearchWorkspace ws;
  auto path = core::shortest_path(graph, {false, true}, {{0, 0.5}}, {{1, 0.25}}, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, 5.75, 1e-12);
  EXPECT_EQ(path.nodes, (std::vector<int>{0, 1}));
  path = core::shortest_path(graph, {false, false}, {{0, 0.5}}, {{1, 0.25}}, ws);
  EXPECT_FALSE(path.found);
}

TEST(RoadmapGraph, EntryAndExitCostsChooseTheEndpoints) {
  // A line 0-1-2-3 (unit steps). Entering at 0 is cheap but far; entering at 2 is dear but
  // close. Exit at 3 only.
  const std::vector<Eigen::VectorXd> nodes{point(0, 0), point(1, 0), point(2, 0), point(3, 0)};
  const core::RoadmapGraph graph(nodes, {{0, 1}, {1, 2}, {2, 3}});
  const std::vector<bool> all{true, true, true};
  core::GraphSearchWorkspace ws;
  auto path = core::shortest_path(graph, all, {{0, 0.0}, {2, 2.5}}, {{3, 0.0}}, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, 3.0, 1e-12);
  EXPECT_EQ(path.nodes, (std::vector<int>{0, 1, 2, 3}));
  path = core::shortest_path(graph, all, {{0, 0.0}, {2, 1.5}}, {{3, 0.0}}, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, 2.5, 1e-12);
  EXPECT_EQ(path.nodes, (std::vector<int>{2, 3}));
  // The same node as entry and exit: a one-node path costing entry + exit.
  path = core::shortest_path(graph, all, {{1, 0.25}}, {{3, 0.0}, {1, 0.5}}, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, 0.75, 1e-12);
  EXPECT_EQ(path.nodes, (std::vector<int>{1}));
}

TEST(RoadmapGraph, ConnectedComponentsMatchBfs) {
  std::mt19937_64 rng(314159);
  int multi_component = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Problem p = random_problem(rng);
    const int n = static_cast<int>(p.nodes.size());
    const auto ids = core::connected_components(n, p.edges, p.allowed);
    const auto ref = reference_components(n, p.edges, p.allowed);
    ASSERT_EQ(ids, ref) << "graph " << trial;
    if (*std::max_element(ref.begin(), ref.end()) > 0) ++multi_component;
  }
  EXPECT_GT(multi_component, 10);
}

TEST(RoadmapGraph, ConnectedComponentsNumberByLowestNode) {
  // Components {0, 4}, {1, 2}, {3}: numbered in the order of their lowest nodes 0, 1, 3; the
  // disallowed edge 3-4 does not join.
  const std::vector<std::pair<int, int>> edges{{4, 0}, {2, 1}, {3, 4}};
  EXPECT_EQ(core::connected_components(5, edges, {true, true, false}),
            (std::vector<int>{0, 1, 1, 2, 0}));
  EXPECT_EQ(core::connected_components(5, edges, {true, true, true}),
            (std::vector<int>{0, 1, 1, 0, 0}));
  EXPECT_EQ(core::connected_components(3, {}, {}), (std::vector<int>{0, 1, 2}));
}

TEST(RoadmapGraph, BadEdgesThrow) {
  const std::vector<Eigen::VectorXd> nodes{point(0, 0), point(1, 0), point(2, 0)};
  EXPECT_THROW(core::RoadmapGraph(nodes, {{0, 3}}), std::invalid_argument);
  EXPECT_THROW(core::RoadmapGraph(nodes, {{-1, 1}}), std::invalid_argument);
  EXPECT_THROW(core::RoadmapGraph(nodes, {{0, 1}, {5, 2}}), std::invalid_argument);
  EXPECT_THROW(core::RoadmapGraph(nodes, {{0, 1}, {1, 1}}), std::invalid_argument);
  EXPECT_THROW(core::RoadmapGraph({}, {{0, 1}}), std::invalid_argument);
  EXPECT_NO_THROW(core::RoadmapGraph(nodes, {{0, 1}, {1, 2}, {2, 0}}));
}

TEST(RoadmapGraph, MalformedQueriesFindNothingWithoutThrowing) {
  const std::vector<Eigen::VectorXd> nodes{point(0, 0), point(1, 0), point(2, 0)};
  const core::RoadmapGraph graph(nodes, {{0, 1}, {1, 2}});
  core::GraphSearchWorkspace ws;
  const std::vector<core::GraphEndpoint> entries{{0, 0.0}}, exits{{2, 0.0}};
  // The well-formed query succeeds, so each failure below is down to the malformation.
  ASSERT_TRUE(core::shortest_path(graph, {true, true}, entries, exits, ws).found);
  core::GraphPath path;
  EXPECT_NO_THROW(path = core::shortest_path(graph, {true}, entries, exits, ws));
  EXPECT_FALSE(path.found);
  EXPECT_NO_THROW(path = core::shortest_path(graph, {true, true, true}, entries, exits, ws));
  EXPECT_FALSE(path.found);
  EXPECT_NO_THROW(path = core::shortest_path(graph, {}, entries, exits, ws));
  EXPECT_FALSE(path.found);
  EXPECT_NO_THROW(path = core::shortest_path(graph, {true, true}, {}, exits, ws));
  EXPECT_FALSE(path.found);
  EXPECT_NO_THROW(path = core::shortest_path(graph, {true, true}, entries, {}, ws));
  EXPECT_FALSE(path.found);
  // Endpoints naming nodes out of range are ignored rather than read.
  EXPECT_NO_THROW(path = core::shortest_path(graph, {true, true}, {{7, 0.0}}, exits, ws));
  EXPECT_FALSE(path.found);
  EXPECT_NO_THROW(path = core::shortest_path(graph, {true, true}, entries, {{-1, 0.0}}, ws));
  EXPECT_FALSE(path.found);
  EXPECT_TRUE(path.nodes.empty());
  // And the workspace still answers correctly afterwards.
  path = core::shortest_path(graph, {true, true}, entries, exits, ws);
  ASSERT_TRUE(path.found);
  EXPECT_NEAR(path.cost, 2.0, 1e-12);
}
