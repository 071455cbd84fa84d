#include "hila/online/planner_model.hpp"

#include "hila/core/error.hpp"
#include "hila/db/provenance.hpp"
#include "hila/online/world.hpp"

namespace hila::online {

std::shared_ptr<const PlannerModel> PlannerModel::load(const std::string& database_path,
                                                       const std::string& cell_path,
                                                       const std::string& product_path) {
  auto cell = core::Cell::load(cell_path);
  core::ProductSpec product = core::load_product(product_path);
  db::OpenOptions options;
  options.expected_cell_hash = db::cell_hash(cell->spec());
  options.expected_product_hash = db::product_hash(product);
  options.comfort_maps = false;  // read when a scene's human first stands elsewhere
  db::Database database = db::Database::open(database_path, options);
  if (database.meta().product_name != product.name) {
    throw db::DatabaseError(database_path, "meta.product_name",
                            "the product '" + product.name + "' of " + product_path,
                            "'" + database.meta().product_name + "'");
  }
  return std::shared_ptr<const PlannerModel>(
      new PlannerModel(std::move(cell), std::move(product), std::move(database)));
}

PlannerModel::PlannerModel(std::shared_ptr<const core::Cell> cell, core::ProductSpec product,
                           db::Database database)
    : cell_(std::move(cell)), product_(std::move(product)), database_(std::move(database)) {
  for (const auto& arm : cell_->arms()) {
    const db::RoadmapRecord* record = database_.roadmap(arm.spec.name);
    if (record == nullptr) {
      throw db::DatabaseError(
          database_.path(), "roadmaps", "a roadmap for arm '" + arm.spec.name + "'", "none",
          "rebuild with: hila build " + product_.file + " -o " + database_.path());
    }
    roadmaps_[arm.spec.name] = std::make_unique<ArmRoadmap>(*record);
  }
  for (const auto& part : database_.parts()) {
    auto& b = *(boards_[part.name] = std::make_unique<BoardRecords>());
    b.part = part;
    b.goals = database_.handover_goals(part.id);
    for (const auto& goal : b.goals) {
      b.shared_grasps[goal.id] = database_.shared_grasps(goal.id);
      b.direct_grasps[goal.id] = database_.direct_grasps(goal.id);
      b.table_regrasps[goal.id] = database_.table_regrasps(goal.id);
      b.suction_deliveries[goal.id] = database_.suction_deliveries(goal.id);
    }
    for (auto& g : database_.robot_grasps(part.id)) b.robot_grasps[g.id] = std::move(g);
    for (auto& g : database_.suction_grasps(part.id)) b.suction_grasps[g.id] = std::move(g);
    for (auto& g : database_.human_grasps(part.id)) b.human_grasps[g.id] = std::move(g);
    for (auto& h : database_.robot_handovers(part.id)) {
      if (b.suction_arm.empty()) b.suction_arm = h.arm;
      b.robot_handovers[h.id] = std::move(h);
    }
    std::map<std::int64_t, std::string> arm_of_roadmap;
    for (const auto& m : database_.roadmaps()) arm_of_roadmap[m.id] = m.arm;
    for (auto& f : database_.roadmap_filters(part.id)) {
      b.filters[{arm_of_roadmap[f.roadmap_id], f.grasp_kind, f.grasp_id}] = std::move(f.edges);
    }
    b.regrasp_nodes = database_.regrasp_nodes(part.id);
    for (const auto& n : b.regrasp_nodes) b.node_by_id[n.id] = &n;
    b.regrasp_edges = database_.regrasp_edges(part.id);
  }
}

void PlannerModel::load_worker_comfort() const {
  std::call_once(worker_comfort_once_, [this] {
    try {
      worker_comfort_ = std::make_unique<const WorkerComfort>(*cell_, database_.read_comfort_maps(),
                                                              database_.path());
    } catch (const std::exception& e) {
      worker_comfort_error_ = e.what();
    }
  });
  if (worker_comfort_ == nullptr) {
    throw db::DatabaseError(database_.path(), "comfort_maps", "readable comfort maps",
                            worker_comfort_error_);
  }
}

const WorkerComfort* PlannerModel::worker_comfort(std::string* error) const noexcept {
  try {
    load_worker_comfort();
  } catch (const std::exception& e) {
    if (error != nullptr) *error = e.what();
    return nullptr;
  }
  return worker_comfort_.get();
}

const BoardRecords* PlannerModel::board_records(const std::string& board) const {
  const auto it = boards_.find(board);
  return it == boards_.end() ? nullptr : it->second.get();
}

std::string PlannerModel::suction_arm(const std::string& board) const {
  const BoardRecords* records = board_records(board);
  return records == nullptr || records->suction_arm.empty() ? kDefaultSuctionArm
                                                            : records->suction_arm;
}

const ArmRoadmap& PlannerModel::roadmap(const std::string& arm) const {
  const auto it = roadmaps_.find(arm);
  if (it == roadmaps_.end()) {
    throw core::InputError(database_.path(), "roadmaps", "an arm of the cell", "'" + arm + "'");
  }
  return *it->second;
}

}  // namespace hila::online
