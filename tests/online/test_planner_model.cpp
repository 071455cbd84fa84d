#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hila/offline/build.hpp"
#include "hila/online/planner_model.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;
namespace fs = std::filesystem;

namespace {

// A small but complete cabinet database.
std::string quick_database(const std::string& dir) {
  const offline::BuildSettings s = test::quick_build_settings(7, 2);
  const std::string out = dir + "/cabinet.hila";
  offline::build_database(test::product_path(), test::cell_path(), out, s);
  return out;
}

// A copy of a data folder, so that one file can be changed.
std::string copy_folder(const std::string& from, const std::string& to) {
  fs::create_directories(to);
  for (const auto& e : fs::directory_iterator(from)) {
    fs::copy_file(e.path(), to + "/" + e.path().filename().string(),
                  fs::copy_options::overwrite_existing);
  }
  return to;
}

}  // namespace

TEST(PlannerModel, LoadsItsDatabaseAndRefusesOnesBuiltFromOtherInputs) {
  const std::string dir = test::temp_dir("planner_model");
  const std::string database = quick_database(dir);

  const auto model = online::PlannerModel::load(database, test::cell_path(), test::product_path());
  EXPECT_EQ(model->product().name, "cabinet");
  EXPECT_EQ(model->product().parts.size(), 7u);
  for (const auto& arm : model->cell().arms()) {
    const auto& roadmap = model->roadmap(arm.spec.name);
    EXPECT_EQ(roadmap.graph.node_count(), static_cast<int>(roadmap.record.nodes.size()));
    EXPECT_EQ(roadmap.graph.edge_count(), static_cast<int>(roadmap.record.edges.size()));
    EXPECT_GT(roadmap.graph.edge_count(), 0) << arm.spec.name;
  }
  test::expect_input_error([&] { model->roadmap("middle"); }, {database, "'middle'"});
  // Each board's records, indexed at load, are the database's for that board.
  const db::Database& db = model->database();
  EXPECT_EQ(model->board_records("drawer"), nullptr);
  for (const auto& part : db.parts()) {
    SCOPED_TRACE(part.name);
    const online::BoardRecords* b = model->board_records(part.name);
    ASSERT_NE(b, nullptr);
    EXPECT_EQ(b->part.id, part.id);
    const auto goals = db.handover_goals(part.id);
    ASSERT_EQ(b->goals.size(), goals.size());
    for (std::size_t i = 0; i < goals.size(); ++i) {
      EXPECT_EQ(b->goals[i].id, goals[i].id);
      EXPECT_EQ(b->shared_grasps.at(goals[i].id).size(), db.shared_grasps(goals[i].id).size());
    }
    for (std::size_t i = 1; i < b->goals.size(); ++i) {
      EXPECT_LE(b->goals[i - 1].rank, b->goals[i].rank);
    }
    EXPECT_EQ(b->robot_grasps.size(), db.robot_grasps(part.id).size());
    for (const auto& g : db.robot_grasps(part.id)) {
      EXPECT_EQ(b->robot_grasps.at(g.id).theta_c_deg, g.theta_c_deg);
    }
    EXPECT_EQ(b->suction_grasps.size(), db.suction_grasps(part.id).size());
    EXPECT_EQ(b->robot_handovers.size(), db.robot_handovers(part.id).size());
    const auto filters = db.roadmap_filters(part.id);
    EXPECT_EQ(b->filters.size(), filters.size());
    for (const auto& f : filters) {
      const db::RoadmapFilterRecord* stored = db.roadmap_filter(f.id);
      ASSERT_NE(stored, nullptr);
      std::string arm;
      for (const auto& m : db.roadmaps()) {
        if (m.id == f.roadmap_id) arm = m.arm;
      }
      EXPECT_EQ(b->filters.at({arm, f.grasp_kind, f.grasp_id}), f.edges);
    }
    for (const auto& goal : b->goals) {
      EXPECT_EQ(b->direct_grasps.at(goal.id).size(), db.direct_grasps(goal.id).size());
    }
    const auto nodes = db.regrasp_nodes(part.id);
    ASSERT_EQ(b->regrasp_nodes.size(), nodes.size());
    for (const auto& n : nodes) EXPECT_EQ(b->node_by_id.at(n.id)->id, n.id);
    EXPECT_EQ(b->regrasp_edges.size(), db.regrasp_edges(part.id).size());
  }

  // The product file changed since the build (one comment added): refused, with the fix.
  const std::string cabinet =
      copy_folder(fs::path(test::product_path()).parent_path().string(), dir + "/cabinet_changed");
  {
    std::ofstream append(cabinet + "/product.yaml", std::ios::app);
    append << "# moved the stack\n";
  }
  test::expect_input_error(
      [&] { online::PlannerModel::load(database, test::cell_path(), cabinet + "/product.yaml"); },
      {database, "product_hash", "hila build"});

  // The cell file changed.
  const std::string cell =
      copy_folder(fs::path(test::cell_path()).parent_path().string(), dir + "/cell_changed");
  {
    std::ofstream append(cell + "/cell.yaml", std::ios::app);
    append << "# recalibrated\n";
  }
  test::expect_input_error(
      [&] { online::PlannerModel::load(database, cell + "/cell.yaml", test::product_path()); },
      {database, "cell_hash"});

  // Missing and corrupt databases.
  test::expect_input_error(
      [&] {
        online::PlannerModel::load(dir + "/none.hila", test::cell_path(), test::product_path());
      },
      {dir + "/none.hila"});
  const std::string corrupt = test::write_file(dir, "corrupt.hila", std::string(4096, 'x'));
  test::expect_input_error(
      [&] { online::PlannerModel::load(corrupt, test::cell_path(), test::product_path()); },
      {corrupt});
}
