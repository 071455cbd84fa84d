#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"
#include "hila/db/database.hpp"
#include "hila/viz/goal_export.hpp"
#include "hila/viz/grasp_export.hpp"
#include "io_checks.hpp"

namespace hila::tools {

// A database opened with the cell and product it was built from (db::DatabaseError when the
// hashes or the product's name differ); the comfort maps are not read.
struct CheckedDatabase {
  std::shared_ptr<const core::Cell> cell;
  core::ProductSpec product;
  db::Database database;
};

CheckedDatabase open_checked_database(const std::string& database, const std::string& cell_file,
                                      const std::string& product_file);

// The files a database export reads (for check_output_path).
std::vector<InputFile> database_input_files(const std::string& database,
                                            const std::string& cell_file,
                                            const std::string& product_file);

// The part's gripper and suction grasps as the database stores them, the part in its own frame
// (the mesh stays owned by `d.product`). Throws core::InputError for an unknown part.
viz::GraspsView grasps_view(const CheckedDatabase& d, const std::string& part,
                            const std::string& arm);

// The part's first `count` ranked goals: the stored human postures (human_joints of the best
// hand, second_joints of the other for a two-hand part) and the robot-robot exchange of the
// goal's first shared grasp (its robot_handovers pose and suction arm's joints, the receiving
// arm's joints_rr and the grasp's jaw width), if it has one.
// (and the RULA grand score of each stored posture: receiving_rula).
viz::GoalsView goals_view(const CheckedDatabase& d, const std::string& part, int count);

// RULA grand score (1-7) of the human holding a part of `load_kg` with `arms` (human arm name ->
// its joints, the rest of the body neutral; each hand its share of the load), the worse hand's;
// 0 where the cell's human model is not one the scores read (core::human_posture).
int receiving_rula(const core::Cell& cell, const std::map<std::string, Eigen::VectorXd>& arms,
                   double load_kg);

}  // namespace hila::tools
