// Human comfort maps and handover goals (issue 4). Run:
//   build/release/bench/bench_handover --benchmark_repetitions=3
//   --benchmark_report_aggregates_only=true
// - BM_ComfortMapsBothArms: both human arms' maps at the default resolution (3 cm x 128
//   orientations, 3 M samples each), one thread per arm (2 cores), real time.
// - BM_ComfortLookup: one lookup of a random reachable hand pose (world frame, cell human;
//   random over 13 MB of bins: cache misses included).
// - BM_ComfortLookupGraspsOfABoard: lookups in the handover search's pattern (every grasp of a
//   board at one pose).
// - BM_ComfortLookupBodySet: the same for the worst Q over a 3-body set.
// - BM_HandoverGoals/i: handover goals of board i at its assembly stage (default settings).
#include <benchmark/benchmark.h>

#include <random>
#include <thread>

#include "hila/core/generic_ik.hpp"
#include "hila/core/product.hpp"
#include "hila/offline/handover.hpp"
#include "hila/offline/human_grasps.hpp"
#include "hila/offline/part_analysis.hpp"
#include "hila/offline/robot_grasps.hpp"
#include "hila/offline/suction_grasps.hpp"

using namespace hila;

namespace {

struct Problem {
  std::shared_ptr<const core::Cell> cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  core::ProductSpec product = core::load_product(HILA_DATA_DIR "/cabinet/product.yaml");
  std::vector<core::ComfortMap> maps;
  Problem() {
    for (const auto& arm : cell->human_arms()) {
      maps.push_back(core::ComfortMap::build(arm.chain, {}));
    }
  }
};

const Problem& problem() {
  static const Problem p;
  return p;
}

void BM_ComfortMapsBothArms(benchmark::State& state) {
  const auto cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  long filled = 0;
  for (auto _ : state) {
    std::vector<core::ComfortMap> maps(cell->human_arms().size());
    std::vector<std::thread> threads;
    for (std::size_t a = 0; a < maps.size(); ++a) {
      threads.emplace_back(
          [&, a] { maps[a] = core::ComfortMap::build(cell->human_arms()[a].chain, {}); });
    }
    for (auto& t : threads) t.join();
    filled = 0;
    for (const auto& m : maps) filled += m.filled_bins();
  }
  state.counters["filled_bins"] = static_cast<double>(filled);
}
BENCHMARK(BM_ComfortMapsBothArms)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

std::vector<core::Pose> random_hands(const offline::HumanComfort& comfort, int arm) {
  const auto& chain = problem().cell->human_arms()[static_cast<std::size_t>(arm)].chain;
  std::mt19937_64 rng(1);
  std::vector<core::Pose> hands;
  for (int i = 0; i < 1024; ++i) {
    hands.push_back(comfort.arm_base(arm) * chain.fk(core::random_configuration(chain, rng)));
  }
  return hands;
}

void BM_ComfortLookup(benchmark::State& state) {
  const offline::HumanComfort comfort(*problem().cell, problem().maps);
  const auto hands = random_hands(comfort, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(comfort.quality(1, hands[i++ & 1023]));
  }
}
BENCHMARK(BM_ComfortLookup)->Unit(benchmark::kNanosecond);

void BM_ComfortLookupBodySet(benchmark::State& state) {
  const offline::HumanComfort comfort(
      *problem().cell, problem().maps,
      {{1.50, core::Sex::Female}, {1.722, core::Sex::Male}, {1.88, core::Sex::Male}});
  const auto hands = random_hands(comfort, 1);
  std::size_t i = 0;
  for (auto _ : state) {
    // Every body of the set: the lookups a worker set's build makes per hand pose.
    const core::Pose& hand = hands[i++ & 1023];
    for (int b = 0; b < comfort.body_count(); ++b) {
      benchmark::DoNotOptimize(comfort.body_quality(b, 1, hand));
    }
  }
}
BENCHMARK(BM_ComfortLookupBodySet)->Unit(benchmark::kNanosecond);

// The access pattern of handover evaluation: every human grasp of one board at one candidate
// pose, in turn (nearby positions and orientations, warm caches).
void BM_ComfortLookupGraspsOfABoard(benchmark::State& state) {
  const auto& p = problem();
  const offline::HumanComfort comfort(*p.cell, p.maps);
  const auto& part = p.product.parts[2];
  const auto analysis = offline::analyze_part(part.name, part.mesh, part.mass);
  const auto grasps = offline::plan_human_grasps(analysis.mesh, analysis, part.mass, *p.cell, {});
  core::Pose board = p.product.target_in_world(part);
  board.translation() += Eigen::Vector3d(0.15, 0.0, 0.1);
  std::vector<core::Pose> hands;
  for (const auto& g : grasps) hands.push_back(board * g.hand);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(comfort.quality(1, hands[i]));
    i = i + 1 == hands.size() ? 0 : i + 1;
  }
  state.counters["grasps"] = static_cast<double>(hands.size());
}
BENCHMARK(BM_ComfortLookupGraspsOfABoard)->Unit(benchmark::kNanosecond);

void BM_HandoverGoals(benchmark::State& state) {
  const auto& p = problem();
  const auto index = static_cast<std::size_t>(state.range(0));
  const auto& part = p.product.parts[index];
  state.SetLabel(part.name);
  const auto analysis = offline::analyze_part(part.name, part.mesh, part.mass);
  offline::BoardGrasps grasps;
  grasps.robot = offline::plan_robot_grasps(analysis.mesh, analysis, part.mass, *p.cell, {});
  grasps.suction = offline::plan_suction_grasps(analysis.mesh, analysis, part.mass, *p.cell, {});
  grasps.human = offline::plan_human_grasps(analysis.mesh, analysis, part.mass, *p.cell, {});
  grasps.com = analysis.mass_properties.com;
  const offline::HumanComfort comfort(*p.cell, p.maps);
  offline::HandoverResult r;
  for (auto _ : state) {
    r = offline::plan_handover_goals(*p.cell, p.product, index, grasps, comfort, {});
  }
  state.counters["S"] = r.stage.comfortable;
  state.counters["goals"] = r.stage.goals;
}
BENCHMARK(BM_HandoverGoals)->DenseRange(0, 6)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
