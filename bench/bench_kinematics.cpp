// FK, Jacobian, analytic UR IK and KDL's numerical IK (orocos-kdl, Levenberg–Marquardt) on the
// same seeded random targets. Run: build/release/bench/bench_kinematics
//   --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainiksolverpos_lma.hpp>
#include <kdl/frames.hpp>
#include <memory>
#include <random>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/generic_ik.hpp"
#include "hila/core/ur_ik.hpp"

using namespace hila;

namespace {

constexpr int kTargets = 4096;

struct Problem {
  std::shared_ptr<const core::Cell> cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  const core::Arm* arm = &cell->arm("left");
  std::vector<Eigen::VectorXd> configurations;
  std::vector<core::Pose> targets;
  std::vector<Eigen::VectorXd> seeds;

  Problem() {
    std::mt19937_64 rng(2024);
    for (int i = 0; i < kTargets; ++i) {
      configurations.push_back(core::random_configuration(arm->chain, rng));
      targets.push_back(arm->chain.fk(configurations.back()));
      seeds.push_back(core::random_configuration(arm->chain, rng));
    }
  }
};

const Problem& problem() {
  static const Problem p;
  return p;
}

// The UR3 as a KDL chain from the same DH table, plus the 0.20 m TCP.
KDL::Chain kdl_chain(const core::UrDhParameters& dh) {
  const double a[6] = {0, dh.a2, dh.a3, 0, 0, 0};
  const double d[6] = {dh.d1, 0, 0, dh.d4, dh.d5, dh.d6};
  const double alpha[6] = {core::kPi / 2, 0, 0, core::kPi / 2, -core::kPi / 2, 0};
  KDL::Chain chain;
  for (int i = 0; i < 6; ++i) {
    chain.addSegment(
        KDL::Segment(KDL::Joint(KDL::Joint::RotZ), KDL::Frame::DH(a[i], alpha[i], d[i], 0)));
  }
  chain.addSegment(KDL::Segment(KDL::Joint(KDL::Joint::None), KDL::Frame(KDL::Vector(0, 0, 0.20))));
  return chain;
}

KDL::Frame to_kdl(const core::Pose& p) {
  const Eigen::Matrix3d& r = p.linear();
  return KDL::Frame(KDL::Rotation(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0),
                                  r(2, 1), r(2, 2)),
                    KDL::Vector(p.translation().x(), p.translation().y(), p.translation().z()));
}

void BM_ForwardKinematics(benchmark::State& state) {
  const auto& p = problem();
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(p.arm->chain.fk(p.configurations[i++ % kTargets]));
  }
}
BENCHMARK(BM_ForwardKinematics);

void BM_Jacobian(benchmark::State& state) {
  const auto& p = problem();
  core::Pose tip;
  core::Jacobian jac(6, 6);
  std::size_t i = 0;
  for (auto _ : state) {
    p.arm->chain.fk_and_jacobian(p.configurations[i++ % kTargets], tip, jac);
    benchmark::DoNotOptimize(jac.data());
  }
}
BENCHMARK(BM_Jacobian);

void BM_AnalyticIkAllSolutions(benchmark::State& state) {
  const auto& p = problem();
  core::UrIkSolutions sols;
  std::size_t i = 0;
  std::size_t solved = 0, calls = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % kTargets;
    const int n = p.arm->ur_ik->solve(p.targets[k], p.seeds[k], sols);
    benchmark::DoNotOptimize(sols.q.data());
    ++calls;
    solved += n > 0 ? 1 : 0;
  }
  state.counters["success_rate"] = static_cast<double>(solved) / static_cast<double>(calls);
}
BENCHMARK(BM_AnalyticIkAllSolutions);

void BM_KdlIkLma(benchmark::State& state) {
  const auto& p = problem();
  const KDL::Chain chain = kdl_chain(*p.cell->spec().arms[0].ur_dh);
  // Weights of position and orientation as KDL's defaults; eps 1e-9, 500 iterations.
  KDL::ChainIkSolverPos_LMA solver(chain, 1e-9, 500);
  KDL::JntArray seed(6), out(6);
  KDL::ChainFkSolverPos_recursive fk(chain);
  std::size_t i = 0;
  std::size_t solved = 0, calls = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % kTargets;
    for (int j = 0; j < 6; ++j) seed(j) = p.seeds[k][j];
    const KDL::Frame target = to_kdl(p.targets[k]);
    const int rc = solver.CartToJnt(seed, target, out);
    benchmark::DoNotOptimize(out.data.data());
    state.PauseTiming();
    KDL::Frame reached;
    fk.JntToCart(out, reached);
    const bool ok = rc >= 0 && (reached.p - target.p).Norm() < 1e-6 &&
                    KDL::diff(reached.M, target.M).Norm() < 1e-6;
    solved += ok ? 1 : 0;
    ++calls;
    state.ResumeTiming();
  }
  state.counters["success_rate"] = static_cast<double>(solved) / static_cast<double>(calls);
}
BENCHMARK(BM_KdlIkLma);

void BM_HilaGenericIk(benchmark::State& state) {
  const auto& p = problem();
  std::mt19937_64 rng(1);
  core::GenericIkSettings settings;
  settings.max_attempts = 1;  // one seed, like KDL
  std::size_t i = 0, solved = 0, calls = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % kTargets;
    const auto r = core::solve_ik(p.arm->chain, p.targets[k], p.seeds[k], rng, settings);
    benchmark::DoNotOptimize(r.q.data());
    solved += r.success ? 1 : 0;
    ++calls;
  }
  state.counters["success_rate"] = static_cast<double>(solved) / static_cast<double>(calls);
}
BENCHMARK(BM_HilaGenericIk);

}  // namespace

BENCHMARK_MAIN();
