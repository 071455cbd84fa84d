#include "db_scenes.hpp"

#include <algorithm>
#include <map>

#include "hila/core/ergonomic_scores.hpp"
#include "hila/db/provenance.hpp"

namespace hila::tools {

CheckedDatabase open_checked_database(const std::string& database, const std::string& cell_file,
                                      const std::string& product_file) {
  auto cell = core::Cell::load(cell_file);
  core::ProductSpec product = core::load_product(product_file);
  db::OpenOptions options;
  options.expected_cell_hash = db::cell_hash(cell->spec());
  options.expected_product_hash = db::product_hash(product);
  options.comfort_maps = false;
  db::Database opened = db::Database::open(database, options);
  if (opened.meta().product_name != product.name) {
    throw db::DatabaseError(database, "meta.product_name",
                            "the product '" + product.name + "' of " + product_file,
                            "'" + opened.meta().product_name + "'");
  }
  return {std::move(cell), std::move(product), std::move(opened)};
}

std::vector<InputFile> database_input_files(const std::string& database,
                                            const std::string& cell_file,
                                            const std::string& product_file) {
  std::vector<InputFile> inputs{{database, "the database"}};
  for (auto&& more : {cell_input_files(cell_file), product_input_files(product_file)}) {
    inputs.insert(inputs.end(), more.begin(), more.end());
  }
  return inputs;
}

viz::GraspsView grasps_view(const CheckedDatabase& d, const std::string& part,
                            const std::string& arm) {
  const db::PartRecord& record = d.database.part(part);
  viz::GraspsView view;
  view.part = part;
  view.mesh = &d.product.part(part).mesh;
  view.arm = arm;
  for (const db::RobotGraspRecord& g : d.database.robot_grasps(record.id)) {
    view.gripper.push_back({g.id, g.tcp, g.jaw_width, g.theta_c_deg});
  }
  for (const db::SuctionGraspRecord& s : d.database.suction_grasps(record.id)) {
    view.suction.push_back({s.id, s.cup, s.force_margin, s.moment_margin});
  }
  return view;
}

int receiving_rula(const core::Cell& cell, const std::map<std::string, Eigen::VectorXd>& arms,
                   double load_kg) {
  if (arms.empty()) return 0;
  const std::vector<std::pair<std::string, Eigen::VectorXd>> hands(arms.begin(), arms.end());
  try {
    const Eigen::VectorXd q = core::human_posture(cell, hands);
    int worst = 0;
    for (const auto& [arm, joints] : hands) {
      const core::RulaInputs in =
          core::rula_inputs_from_posture(cell.human(), q, arm, load_kg, hands.size() > 1);
      worst = std::max(worst, core::rula(in).grand);
    }
    return worst;
  } catch (const core::InputError&) {
    return 0;  // a human model the scores do not read: shown unscored
  }
}

viz::GoalsView goals_view(const CheckedDatabase& d, const std::string& part, int count) {
  const db::PartRecord& record = d.database.part(part);
  viz::GoalsView view;
  view.part = part;
  view.mesh = &d.product.part(part).mesh;
  view.human_stance = d.cell->spec().human_stance;
  std::vector<db::HandoverCandidateRecord> goals = d.database.handover_goals(record.id);
  std::stable_sort(goals.begin(), goals.end(),
                   [](const auto& a, const auto& b) { return a.rank < b.rank; });
  if (goals.size() > static_cast<std::size_t>(std::max(count, 0))) {
    goals.resize(static_cast<std::size_t>(std::max(count, 0)));
  }
  std::map<std::int64_t, db::RobotHandoverRecord> handovers;
  for (auto& h : d.database.robot_handovers(record.id)) handovers[h.id] = std::move(h);
  std::map<std::int64_t, double> jaw_width;
  for (const auto& g : d.database.robot_grasps(record.id)) jaw_width[g.id] = g.jaw_width;
  for (const db::HandoverCandidateRecord& goal : goals) {
    viz::GoalView v;
    v.rank = goal.rank;
    v.board = goal.board;
    v.quality = goal.quality;
    if (!goal.human_arm.empty() && goal.human_joints.size() > 0) {
      v.human_arms[goal.human_arm] = goal.human_joints;
    }
    if (!goal.second_arm.empty() && goal.second_joints.size() > 0) {
      v.human_arms[goal.second_arm] = goal.second_joints;
    }
    v.rula_grand = receiving_rula(*d.cell, v.human_arms, d.product.part(part).mass);
    for (const db::SharedGraspRecord& shared : d.database.shared_grasps(goal.id)) {
      const auto h = handovers.find(shared.robot_handover_id);
      if (h == handovers.end()) continue;
      v.exchange =
          viz::ExchangeView{h->second.board, h->second.arm,    h->second.joints,
                            shared.arm,      shared.joints_rr, jaw_width[shared.robot_grasp_id]};
      break;
    }
    view.goals.push_back(std::move(v));
  }
  return view;
}

}  // namespace hila::tools
