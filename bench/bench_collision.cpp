// One full-arm collision check against the cell: FK of every robot link, pose update of the
// moving bodies, FCL broad phase + narrow phase. Configurations are seeded random left-arm poses
// that are collision-free (the common case while planning), and ones that collide.
// Run: build/release/bench/bench_collision --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <random>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/generic_ik.hpp"

using namespace hila;

namespace {

struct Problem {
  std::shared_ptr<const core::Cell> cell = core::Cell::load(HILA_DATA_DIR "/cell/cell.yaml");
  core::CellScene scene = core::build_cell_scene(*cell);
  std::vector<Eigen::VectorXd> free_configs;
  std::vector<Eigen::VectorXd> colliding_configs;

  Problem() {
    core::CollisionData data(scene.model);
    std::mt19937_64 rng(5);
    const core::Arm& arm = cell->arm("left");
    while (free_configs.size() < 512 || colliding_configs.size() < 512) {
      Eigen::VectorXd q = cell->home_configuration();
      cell->set_arm(q, arm, core::random_configuration(arm.chain, rng));
      core::set_cell_state(*cell, scene, data, q, cell->human_neutral());
      auto& bucket = core::in_collision(scene.model, data) ? colliding_configs : free_configs;
      if (bucket.size() < 512) bucket.push_back(q);
    }
  }
};

const Problem& problem() {
  static const Problem p;
  return p;
}

// The planner's query: the moving arm (links + gripper) against the cell, the other arm, the
// human and itself.
void full_arm_check(benchmark::State& state, const std::vector<Eigen::VectorXd>& configs) {
  const auto& p = problem();
  core::CollisionData data(p.scene.model);
  core::set_cell_state(*p.cell, p.scene, data, p.cell->home_configuration(), p.cell->human_neutral());
  const std::vector<int>& arm_bodies = p.scene.arm_bodies[0];
  std::vector<core::Pose> links;
  std::size_t i = 0;
  for (auto _ : state) {
    p.cell->robot().link_poses(configs[i++ % configs.size()], links);
    core::set_robot_pose(data, p.scene.robot, links);
    benchmark::DoNotOptimize(core::in_collision(p.scene.model, data, arm_bodies));
  }
}

void BM_FullArmCheckFree(benchmark::State& state) { full_arm_check(state, problem().free_configs); }
BENCHMARK(BM_FullArmCheckFree);

void BM_FullArmCheckColliding(benchmark::State& state) {
  full_arm_check(state, problem().colliding_configs);
}
BENCHMARK(BM_FullArmCheckColliding);

// Every pair in the scene (both arms, human static) through the broad-phase trees.
void BM_WholeSceneCheckFree(benchmark::State& state) {
  const auto& p = problem();
  core::CollisionData data(p.scene.model);
  core::set_cell_state(*p.cell, p.scene, data, p.cell->home_configuration(), p.cell->human_neutral());
  std::vector<core::Pose> links;
  std::size_t i = 0;
  for (auto _ : state) {
    p.cell->robot().link_poses(p.free_configs[i++ % p.free_configs.size()], links);
    core::set_robot_pose(data, p.scene.robot, links);
    benchmark::DoNotOptimize(core::in_collision(p.scene.model, data));
  }
}
BENCHMARK(BM_WholeSceneCheckFree);

void BM_BruteForceCheckFree(benchmark::State& state) {
  const auto& p = problem();
  core::CollisionData data(p.scene.model);
  core::set_cell_state(*p.cell, p.scene, data, p.cell->home_configuration(), p.cell->human_neutral());
  std::vector<core::Pose> links;
  std::size_t i = 0;
  for (auto _ : state) {
    p.cell->robot().link_poses(p.free_configs[i++ % p.free_configs.size()], links);
    core::set_robot_pose(data, p.scene.robot, links);
    benchmark::DoNotOptimize(core::in_collision_brute_force(p.scene.model, data, p.scene.arm_bodies[0]));
  }
}
BENCHMARK(BM_BruteForceCheckFree);

}  // namespace

BENCHMARK_MAIN();
