#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

namespace hila::core {

// An undirected joint-space roadmap as a compressed adjacency list: what the offline tools store
// and the online planner searches. Edge lengths are joint-space Euclidean distances, so the
// search's straight-line heuristic is admissible and consistent. Immutable once built, so one
// graph serves every thread.
class RoadmapGraph {
 public:
  struct Neighbour {
    int node;
    int edge;
  };

  RoadmapGraph() = default;
  // Edges join node indices in range; self-loops are invalid. Throws std::invalid_argument.
  RoadmapGraph(std::vector<Eigen::VectorXd> nodes, std::vector<std::pair<int, int>> edges);

  int node_count() const { return static_cast<int>(nodes_.size()); }
  int edge_count() const { return static_cast<int>(edges_.size()); }
  const Eigen::VectorXd& node(int n) const { return nodes_[static_cast<std::size_t>(n)]; }
  const std::vector<Eigen::VectorXd>& nodes() const { return nodes_; }
  const std::pair<int, int>& edge(int e) const { return edges_[static_cast<std::size_t>(e)]; }
  double edge_length(int e) const { return lengths_[static_cast<std::size_t>(e)]; }
  const Neighbour* neighbours_begin(int n) const {
    return adjacency_.data() + offsets_[static_cast<std::size_t>(n)];
  }
  const Neighbour* neighbours_end(int n) const {
    return adjacency_.data() + offsets_[static_cast<std::size_t>(n) + 1];
  }

 private:
  std::vector<Eigen::VectorXd> nodes_;
  std::vector<std::pair<int, int>> edges_;
  std::vector<double> lengths_;
  std::vector<int> offsets_;  // node n's neighbours: adjacency_[offsets_[n], offsets_[n + 1])
  std::vector<Neighbour> adjacency_;
};

// Where a query enters and leaves the roadmap: a node and the cost of the connection to it
// (e.g. the straight edge from the start configuration).
struct GraphEndpoint {
  int node = -1;
  double cost = 0.0;
};

struct GraphPath {
  bool found = false;
  double cost = 0.0;       // entry cost + edge lengths + exit cost
  std::vector<int> nodes;  // from an entry node to an exit node
  int expanded = 0;        // nodes taken off the open list
};

// Per-thread scratch of the search, reused between queries (no allocation once warm).
class GraphSearchWorkspace {
 public:
  void reset(int node_count);

  std::vector<double> g;
  std::vector<int> parent;
  std::vector<double> exit_cost;  // cost of leaving through the node (infinity: not an exit)
  std::vector<std::uint32_t> stamp;
  std::vector<std::uint32_t> closed;
  std::vector<std::pair<double, int>> heap;
  std::uint32_t generation = 0;
  // The heuristic per node, kept while the exits stay the same: a lazy planner searches the
  // same query again after each invalidated edge, and the nearest-exit distance over dozens of
  // exits is most of a search's time otherwise.
  std::vector<double> heuristic;
  std::vector<std::uint32_t> heuristic_stamp;
  std::uint32_t heuristic_generation = 0;
  const RoadmapGraph* heuristic_graph = nullptr;  // graphs never change once built
  std::vector<GraphEndpoint> heuristic_exits;
};

// A* over the edges whose `allowed` bit is set (size edge_count), from any entry to any exit,
// minimising entry cost + path length + exit cost. The heuristic is the straight joint-space
// distance to the nearest exit plus that exit's cost (admissible, consistent), so the answer is
// the shortest path. Never throws on the query path.
GraphPath shortest_path(const RoadmapGraph& graph, const std::vector<bool>& allowed,
                        const std::vector<GraphEndpoint>& entries,
                        const std::vector<GraphEndpoint>& exits, GraphSearchWorkspace& workspace);

// Connected-component id per node over the allowed edges: ids 0, 1, ... in order of each
// component's lowest node.
std::vector<int> connected_components(int node_count, const std::vector<std::pair<int, int>>& edges,
                                      const std::vector<bool>& allowed);

}  // namespace hila::core
