#include "scene_exports.hpp"

#include "hila/core/error.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/viz/plan_export.hpp"

namespace hila::tools {

PlanScene read_plan_scene(const std::string& database, const std::string& plan_file,
                          const std::string& scene) {
  PlanScene p;
  p.database = database;
  p.inputs = {{database, "the database"}, {plan_file, "the plan file"}};
  p.plan = viz::read_plan_file(plan_file);
  p.scene_file = scene.empty() ? p.plan.scene : scene;
  p.inputs.push_back({p.scene_file, "the scene file"});
  p.files = online::read_scene_files(p.scene_file);
  for (auto&& more : {cell_input_files(p.files.cell), product_input_files(p.files.product)}) {
    p.inputs.insert(p.inputs.end(), more.begin(), more.end());
  }
  return p;
}

std::string plan_scene_glb(const PlanScene& p) {
  // The database checks that it was built from the scene's cell and product.
  const auto model = online::PlannerModel::load(p.database, p.files.cell, p.files.product);
  const online::Scene scene = online::load_scene(p.scene_file, model->cell(), model->product());
  if (p.plan.product != model->product().name) {
    throw core::InputError(p.plan.file, "product", "'" + model->product().name + "'",
                           "'" + p.plan.product + "'");
  }
  viz::PlanStart start;
  for (const viz::PlanFileBoard& b : p.plan.boards) {
    start.initial[b.board] = scene.initial_pose(model->product().part(b.board));
  }
  for (const online::FinishedBoard& f : scene.finished) {
    start.finished.push_back({f.name, &model->product().part(f.name).mesh, f.pose});
  }
  start.assembly_frame = scene.assembly_frame;
  start.tool = scene.tool;
  start.tool_in_hand = scene.tool_in_hand;
  start.human_stance = scene.human_stance;
  start.robot = scene.robot;
  return viz::plan_glb(model->cell(), model->product(), start, p.plan);
}

}  // namespace hila::tools
