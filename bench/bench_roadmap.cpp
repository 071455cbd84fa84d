// Roadmaps (issue 5, in progress). Run:
//   build/release/bench/bench_roadmap --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
// - BM_BuildRoadmap: one arm's roadmap at the default size (3000 milestones, k = 10).
// - BM_SlipFilter: one grasp's edge filter over that roadmap, and its components.
#include <benchmark/benchmark.h>

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

}  // namespace

BENCHMARK_MAIN();
