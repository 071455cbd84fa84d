// Plans the robot's motions for one cabinet board in the scene as the cameras report it.
// Usage: plan_one_board cabinet.hila scene.yaml   (a `hila build` database, a scene file)
#include <chrono>
#include <iostream>

#include "hila/online/board_planner.hpp"

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  namespace online = hila::online;
  // The database with the cell and product files the scene names (it must have been built from
  // them), loaded once for every query.
  const online::SceneFiles files = online::read_scene_files(argv[2]);
  const auto model = online::PlannerModel::load(argv[1], files.cell, files.product);
  const online::Scene scene = online::load_scene(argv[2], model->cell(), model->product());
  online::BoardPlanner planner(*model);  // one per thread, for any number of boards and scenes
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  const online::BoardPlan plan = planner.plan(scene, "base", deadline);
  std::cout << "base: " << online::to_string(plan.status) << ", " << plan.steps.size() << " steps, "
            << plan.duration << " s of motion\n";
  return plan.solved() ? 0 : 1;
}
