// Roadmaps (issue 5). Run:
//   build/release/bench/bench_roadmap --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true
// - BM_BuildRoadmap: one arm's roadmap at the default size (3000 milestones, k = 15), with the
//   memory it takes in the database form.
// - BM_SlipFilter: one grasp's edge filter over that roadmap, and its components.
// - BM_HeldBoardFilter: the held board's part of a filter (a lateral held at its edge).
// - BM_FilteredQuery: a shortest-path query on the stored roadmap under a 22 degree filter
//   (A* over core::RoadmapGraph, workspace reused), between random nodes of its largest
//   component; the online planner's roadmap query.
#include <benchmark/benchmark.h>

#include <random>

#include "hila/core/product.hpp"
#include "hila/core/roadmap_graph.hpp"
#include "hila/offline/roadmap.hpp"

using namespace hila;

namespace {

const offline::Roadmap& roadmap() {
  static const auto cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  static const offline::Roadmap map = offline::build_roadmap(*cell, "left", {});
  return map;
}

void BM_BuildRoadmap(benchmark::State& state) {
  const auto cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  offline::Roadmap map;
  for (auto _ : state) map = offline::build_roadmap(*cell, "left", {});
  state.counters["nodes"] = static_cast<double>(map.nodes.size());
  state.counters["edges"] = static_cast<double>(map.edges.size());
  // Stored: joints, gravity and inclination per node; node pair, length, inclination per edge.
  const double bytes = static_cast<double>(map.nodes.size()) * (map.dof + 3 + 1) * 8.0 +
                       static_cast<double>(map.edges.size()) * (2 * 4 + 2 * 8);
  state.counters["stored_MB"] = bytes / 1e6;
  // One filter: a bit per edge and a component id per node.
  state.counters["filter_KB"] =
      (static_cast<double>(map.edges.size()) / 8.0 + 4.0 * map.nodes.size()) / 1e3;
}
BENCHMARK(BM_BuildRoadmap)->Unit(benchmark::kSecond)->Iterations(1);

void BM_SlipFilter(benchmark::State& state) {
  const auto& map = roadmap();
  const offline::GraspSlip grasp{Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 22.0};
  std::size_t components = 0;
  for (auto _ : state) {
    const auto filter = offline::slip_filter(map, grasp);
    const auto ids = offline::connected_components(map, filter);
    components = static_cast<std::size_t>(*std::max_element(ids.begin(), ids.end()) + 1);
  }
  state.counters["components"] = static_cast<double>(components);
}
BENCHMARK(BM_SlipFilter)->Unit(benchmark::kMillisecond);

void BM_HeldBoardFilter(benchmark::State& state) {
  const auto& map = roadmap();
  static const auto cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  static const core::ProductSpec product =
      core::load_product(HILA_DATA_DIR "/cabinet/product.yaml");
  const core::PartSpec* lateral = nullptr;
  for (const auto& p : product.parts) {
    if (p.name == "lateral_right") lateral = &p;
  }
  offline::ArmWorkspace workspace(*cell, "left", "right", &lateral->mesh);
  // Held 5 cm in from the middle of a long edge, the board hanging ahead of the gripper.
  core::Pose board_in_tcp = core::Pose::Identity();
  board_in_tcp.translation() = Eigen::Vector3d(0.0, 0.0, 0.05);
  workspace.hold(board_in_tcp, cell->spec().gripper.jaw_max);
  const auto slip =
      offline::slip_filter(map, {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 22.0});
  std::size_t kept = 0;
  for (auto _ : state) {
    const auto filter = offline::held_board_filter(workspace, map, slip);
    kept = static_cast<std::size_t>(std::count(filter.begin(), filter.end(), true));
  }
  state.counters["slip_edges"] = static_cast<double>(std::count(slip.begin(), slip.end(), true));
  state.counters["kept_edges"] = static_cast<double>(kept);
}
BENCHMARK(BM_HeldBoardFilter)->Unit(benchmark::kSecond)->Iterations(1);

void BM_FilteredQuery(benchmark::State& state) {
  const auto& map = roadmap();
  const core::RoadmapGraph graph(map.nodes, map.edges);
  const auto filter =
      offline::slip_filter(map, {Eigen::Vector3d::UnitY(), Eigen::Vector3d::UnitZ(), 22.0});
  const auto ids = offline::connected_components(map, filter);
  std::vector<int> count(static_cast<std::size_t>(*std::max_element(ids.begin(), ids.end()) + 1));
  for (const int id : ids) ++count[static_cast<std::size_t>(id)];
  const int largest =
      static_cast<int>(std::max_element(count.begin(), count.end()) - count.begin());
  std::vector<int> members;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] == largest) members.push_back(static_cast<int>(i));
  }
  std::mt19937_64 rng(1);
  core::GraphSearchWorkspace workspace;
  double expanded = 0.0, queries = 0.0;
  for (auto _ : state) {
    const int a = members[rng() % members.size()];
    const int b = members[rng() % members.size()];
    const auto path = core::shortest_path(graph, filter, {{a, 0.0}}, {{b, 0.0}}, workspace);
    benchmark::DoNotOptimize(path.cost);
    expanded += path.expanded;
    queries += 1.0;
  }
  state.counters["expanded"] = expanded / queries;
  state.counters["component_nodes"] = static_cast<double>(members.size());
}
BENCHMARK(BM_FilteredQuery)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
