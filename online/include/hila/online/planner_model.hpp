#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"
#include "hila/db/database.hpp"
#include "hila/online/arm_motion.hpp"
#include "hila/online/worker_comfort.hpp"

namespace hila::online {

// One board's database records as the planner reads them, indexed once when the model is loaded
// (a query copies none of them).
struct BoardRecords {
  db::PartRecord part;
  std::vector<db::HandoverCandidateRecord> goals;  // Eq. 8 order: by rank (then id)
  std::map<std::int64_t, std::vector<db::SharedGraspRecord>> shared_grasps;    // by goal, id order
  std::map<std::int64_t, std::vector<db::DirectGraspRecord>> direct_grasps;    // by goal, id order
  std::map<std::int64_t, std::vector<db::TableRegraspRecord>> table_regrasps;  // by goal, id order
  std::map<std::int64_t, std::vector<db::SuctionDeliveryRecord>> suction_deliveries;  // likewise
  std::map<std::int64_t, db::RobotGraspRecord> robot_grasps;
  std::map<std::int64_t, db::SuctionGraspRecord> suction_grasps;
  std::map<std::int64_t, db::HumanGraspRecord> human_grasps;
  std::map<std::int64_t, db::RobotHandoverRecord> robot_handovers;
  // The arm the build gave the suction tool for this board (its robot handovers' arm), or ""
  // when it has none: the default roles (World's kDefaultSuctionArm).
  std::string suction_arm;
  // By (arm, grasp kind, grasp id): the filter of that arm's roadmap.
  std::map<std::tuple<std::string, std::string, std::int64_t>, std::vector<bool>> filters;
  std::vector<db::RegraspNodeRecord> regrasp_nodes;
  std::map<std::int64_t, const db::RegraspNodeRecord*> node_by_id;  // into regrasp_nodes
  std::vector<db::RegraspEdgeRecord> regrasp_edges;
};

// Everything the online planner reads, loaded once: the cell, the product and the database
// built from exactly these files (refused otherwise), with each arm's roadmap ready to search.
// Immutable after load: one model serves every query and thread (Pinocchio's Model; the
// per-thread state lives in the planners).
class PlannerModel {
 public:
  // Throws core::InputError / db::DatabaseError naming the file and field: a missing, corrupt
  // or outdated database, one built from another cell or product (the hashes differ: "rebuild
  // with hila build ..."), or one without roadmaps.
  static std::shared_ptr<const PlannerModel> load(const std::string& database_path,
                                                  const std::string& cell_path,
                                                  const std::string& product_path);

  const core::Cell& cell() const { return *cell_; }
  const core::ProductSpec& product() const { return product_; }
  const db::Database& database() const { return database_; }
  // Throws core::InputError naming the database for an arm without a roadmap.
  const ArmRoadmap& roadmap(const std::string& arm) const;
  // The comfort of the human the scene has at the stored goals, from the database's comfort maps
  // (about 13 MB per human arm: read from the file on first use, once, by whichever thread asks
  // first; load_worker_comfort() pays that at start-up). nullptr when the maps cannot be read,
  // with the reason in `error`. Never throws.
  const WorkerComfort* worker_comfort(std::string* error = nullptr) const noexcept;
  // Reads the comfort maps now. Throws db::DatabaseError when they cannot be read.
  void load_worker_comfort() const;
  // The board's records; nullptr when the database has no such board.
  const BoardRecords* board_records(const std::string& board) const;
  // The arm that picks `board` by suction (BoardRecords::suction_arm, else kDefaultSuctionArm).
  std::string suction_arm(const std::string& board) const;
  // Where both arms take and set down the suction tool besides its stand (db::Meta::tool_relay).
  const std::optional<core::Pose>& tool_relay() const { return database_.meta().tool_relay; }

 private:
  PlannerModel(std::shared_ptr<const core::Cell> cell, core::ProductSpec product,
               db::Database database);

  std::shared_ptr<const core::Cell> cell_;
  core::ProductSpec product_;
  db::Database database_;
  mutable std::once_flag worker_comfort_once_;
  mutable std::unique_ptr<const WorkerComfort> worker_comfort_;
  mutable std::string worker_comfort_error_;
  std::map<std::string, std::unique_ptr<ArmRoadmap>> roadmaps_;
  std::map<std::string, std::unique_ptr<BoardRecords>> boards_;  // in place: node_by_id points in
};

}  // namespace hila::online
