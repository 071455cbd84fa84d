// One full-arm collision check against the cell: FK of every robot link, pose update of the
// moving bodies, box tests (world, then oriented) + FCL's narrow phase. Configurations are seeded
// random left-arm poses that are collision-free (the common case while planning), and ones that
// collide. Run: build/release/bench/bench_collision --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "hila/core/arm_poser.hpp"
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

// Poses the robot at each configuration in turn (FK of every link, body poses) and runs `query`.
template <typename Query>
void check_loop(benchmark::State& state, const std::vector<Eigen::VectorXd>& configs, Query query) {
  const auto& p = problem();
  core::CollisionData data(p.scene.model);
  core::set_cell_state(*p.cell, p.scene, data, p.cell->home_configuration(),
                       p.cell->human_neutral());
  std::vector<core::Pose> links;
  std::size_t i = 0;
  for (auto _ : state) {
    p.cell->robot().link_poses(configs[i++ % configs.size()], links);
    core::set_robot_pose(data, p.scene.robot, links);
    benchmark::DoNotOptimize(query(data));
  }
}

// The planner's query: the moving arm (links + gripper) against the cell, the other arm, the
// human and itself.
bool arm_query(core::CollisionData& data) {
  return core::in_collision(problem().scene.model, data, problem().scene.arm_bodies[0]);
}

void BM_FullArmCheckFree(benchmark::State& state) {
  check_loop(state, problem().free_configs, arm_query);
}
BENCHMARK(BM_FullArmCheckFree);

void BM_FullArmCheckColliding(benchmark::State& state) {
  check_loop(state, problem().colliding_configs, arm_query);
}
BENCHMARK(BM_FullArmCheckColliding);

// The same query with only the moving arm re-posed (core::ArmPoser), as the online planner and
// validator check each sample: the other arm, the torso and the human stay where they are.
// Poses the left arm alone at each of `configs` in turn (core::ArmPoser), the rest of the cell
// at home, and runs the planner's query.
void arm_poser_loop(benchmark::State& state, const std::vector<Eigen::VectorXd>& configs) {
  const auto& p = problem();
  core::CollisionData data(p.scene.model);
  core::set_cell_state(*p.cell, p.scene, data, p.cell->home_configuration(),
                       p.cell->human_neutral());
  core::ArmPoser poser(*p.cell, p.scene, p.cell->arm("left"));
  poser.pose_robot(data, p.cell->home_configuration());
  std::size_t i = 0;
  for (auto _ : state) {
    poser.pose_arm(data, configs[i++ % configs.size()]);
    benchmark::DoNotOptimize(arm_query(data));
  }
}

void BM_ArmPoserCheckFree(benchmark::State& state) {
  arm_poser_loop(state, problem().free_configs);
}
BENCHMARK(BM_ArmPoserCheckFree);

// The same along straight joint-space segments between those configurations at 0.01 rad, the
// way the validator and a segment check walk a motion: consecutive samples close together.
void BM_ArmPoserCheckAlongPath(benchmark::State& state) {
  const auto& p = problem();
  std::vector<Eigen::VectorXd> samples;
  for (std::size_t k = 1; k < 64; ++k) {
    const Eigen::VectorXd& a = p.free_configs[k - 1];
    const Eigen::VectorXd& b = p.free_configs[k];
    const int steps = static_cast<int>(std::ceil((b - a).norm() / 0.01));
    for (int s = 0; s < steps; ++s) samples.push_back(a + (b - a) * (double(s) / steps));
  }
  arm_poser_loop(state, samples);
}
BENCHMARK(BM_ArmPoserCheckAlongPath);

// Every pair in the scene (both arms, human static) through the broad-phase trees.
void BM_WholeSceneCheckFree(benchmark::State& state) {
  check_loop(state, problem().free_configs, [](core::CollisionData& data) {
    return core::in_collision(problem().scene.model, data);
  });
}
BENCHMARK(BM_WholeSceneCheckFree);

// The arm's pairs one by one with FCL's narrow phase, no broad phase: the baseline.
void BM_BruteForceArmCheckFree(benchmark::State& state) {
  check_loop(state, problem().free_configs, [](core::CollisionData& data) {
    return core::in_collision_brute_force(problem().scene.model, data,
                                          problem().scene.arm_bodies[0]);
  });
}
BENCHMARK(BM_BruteForceArmCheckFree);

}  // namespace

BENCHMARK_MAIN();
