// Grasp planning per board (robot grasps with theta_c, suction, human grasps) and the whole
// cabinet database build. Run: build/release/bench/bench_grasps --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <filesystem>

#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"
#include "hila/offline/build.hpp"
#include "hila/offline/part_analysis.hpp"

using namespace hila;

namespace {

struct Problem {
  std::shared_ptr<const core::Cell> cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  core::ProductSpec product = core::load_product(HILA_DATA_DIR "/cabinet/product.yaml");
};

const Problem& problem() {
  static const Problem p;
  return p;
}

// One board of each kind: 0 = base (390x288x10), 1 = lateral (587x295x10), 2 = back panel (3 mm).
void BM_BoardGrasps(benchmark::State& state) {
  const auto& p = problem();
  const auto& part = p.product.parts[static_cast<std::size_t>(state.range(0))];
  state.SetLabel(part.name);
  std::size_t robot = 0, suction = 0, human = 0;
  for (auto _ : state) {
    const auto analysis = offline::analyze_part(part.name, part.mesh, part.mass);
    robot = offline::plan_robot_grasps(part.mesh, analysis, part.mass, *p.cell, {}).size();
    suction = offline::plan_suction_grasps(part.mesh, analysis, part.mass, *p.cell, {}).size();
    human = offline::plan_human_grasps(part.mesh, analysis, part.mass, *p.cell, {}).size();
  }
  state.counters["robot"] = static_cast<double>(robot);
  state.counters["suction"] = static_cast<double>(suction);
  state.counters["human"] = static_cast<double>(human);
}
BENCHMARK(BM_BoardGrasps)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

// The whole cabinet database with the default settings, on 1 and 2 threads.
void BM_CabinetBuild(benchmark::State& state) {
  const std::string out =
      (std::filesystem::temp_directory_path() / "hila_bench_cabinet.hila").string();
  offline::BuildSettings settings;
  settings.jobs = static_cast<int>(state.range(0));
  for (auto _ : state) {
    offline::build_database(HILA_DATA_DIR "/cabinet/product.yaml", HILA_DATA_DIR "/cell/cell.yaml",
                            out, settings);
  }
  std::filesystem::remove(out);
}
BENCHMARK(BM_CabinetBuild)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
