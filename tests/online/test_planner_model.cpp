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
