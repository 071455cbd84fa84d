#include <gtest/gtest.h>

#include <cmath>

#include "hila/core/error.hpp"
#include "hila/core/product.hpp"
#include "hila/online/scene.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

const core::ProductSpec& cabinet() {
  static const core::ProductSpec product = core::load_product(test::product_path());
  return product;
}

std::string scene_path() {
  return test::data_path("cabinet/scene.yaml");
}

// A scene file in a fresh folder (beside a copy of nothing: meshes are given by absolute path).
std::string write_scene(const std::string& name, const std::string& text) {
  return test::write_file(test::temp_dir("scene_" + name), "scene.yaml", text);
}

online::Scene load(const std::string& path) {
  return online::load_scene(path, *test::reference_cell(), cabinet());
}

}  // namespace

TEST(Scene, NominalCabinetSceneMatchesTheProductAndTheCell) {
  const online::Scene s = load(scene_path());
  const auto& cell = *test::reference_cell();
  EXPECT_EQ(s.product, "cabinet");
  EXPECT_FALSE(s.tool_in_hand);
  EXPECT_TRUE(s.finished.empty());
  EXPECT_TRUE(s.obstacles.empty());
  EXPECT_TRUE(s.tool.isApprox(cabinet().suction_tool_pose, 1e-9));
  EXPECT_TRUE(s.assembly_frame.isApprox(cabinet().assembly_frame, 1e-9));
  EXPECT_TRUE(s.human_stance.isApprox(cell.spec().human_stance, 1e-9));
  for (const auto& arm : cell.arms()) {
    ASSERT_EQ(s.robot.count(arm.spec.name), 1u);
    EXPECT_LT((s.robot.at(arm.spec.name) - arm.spec.home).norm(), 1e-6) << arm.spec.name;
  }
  // Every board: the file lists base at its nominal pose; the others default to it.
  for (const auto& part : cabinet().parts) {
    EXPECT_TRUE(s.initial_pose(part).isApprox(part.initial, 1e-9)) << part.name;
  }
  EXPECT_EQ(s.detected.size(), 1u);
}

TEST(Scene, NominalSceneEqualsTheLoadedFile) {
  const online::Scene file = load(scene_path());
  const online::Scene nominal = online::nominal_scene(*test::reference_cell(), cabinet());
  EXPECT_TRUE(file.tool.isApprox(nominal.tool, 1e-9));
  EXPECT_TRUE(file.human_stance.isApprox(nominal.human_stance, 1e-9));
  for (const auto& [arm, q] : nominal.robot) EXPECT_LT((file.robot.at(arm) - q).norm(), 1e-6);
}

TEST(Scene, FinishingABoardPlacesItAtItsTargetInTheSceneAssemblyFrame) {
  const std::string path = write_scene("moved", R"(product: cabinet
assembly_frame: {xyz: [0.65, 0.05, 1.094], rpy_deg: [0, 0, 10]}
boards:
  lateral_right: {xyz: [0.31, -0.29, 1.141], rpy_deg: [0, 0, 95]}
)");
  online::Scene s = load(path);
  const auto& part = cabinet().part("lateral_right");
  EXPECT_FALSE(s.initial_pose(part).isApprox(part.initial, 1e-6));
  s = s.with_finished(cabinet(), "base").with_finished(cabinet(), "lateral_right");
  ASSERT_EQ(s.finished.size(), 2u);
  EXPECT_EQ(s.finished[1].name, "lateral_right");
  const core::Pose want = s.assembly_frame * part.target;
  EXPECT_TRUE(s.finished[1].pose.isApprox(want, 1e-12));
  // Independently: the frame is 10° about z at (0.65, 0.05), so the target's offset turns.
  const Eigen::Vector3d offset =
      Eigen::AngleAxisd(core::deg_to_rad(10.0), Eigen::Vector3d::UnitZ()) *
      part.target.translation();
  EXPECT_TRUE(
      s.finished[1].pose.translation().isApprox(Eigen::Vector3d(0.65, 0.05, 1.094) + offset, 1e-9));
  EXPECT_TRUE(s.is_finished("base"));
  EXPECT_EQ(s.detected.count("lateral_right"), 0u) << "a finished board is no longer detected";
  EXPECT_EQ(s.with_finished(cabinet(), "base").finished.size(), 2u) << "finishing twice is a no-op";
}

TEST(Scene, ObstaclesAndFinishedBoardsWithMeasuredPoses) {
  const std::string mesh = test::data_path("cabinet/shelf.stl");
  const std::string path = write_scene(
      "obstacles", R"(product: cabinet
finished:
  - base
  - {name: lateral_right, pose: {xyz: [0.62, 0.2, 1.39], rotation: [[0, 1, 0], [0, 0, 1], [1, 0, 0]]}}
obstacles:
  - {name: crate, box: [0.2, 0.3, 0.1], pose: {xyz: [0.5, 0.3, 1.144], rpy_deg: [0, 0, 0]}}
  - {name: jig, mesh: )" +
                       mesh + R"(, scale: 0.001, pose: {xyz: [0.5, -0.5, 1.2], rpy_deg: [0, 0, 0]}}
)");
  const online::Scene s = load(path);
  ASSERT_EQ(s.finished.size(), 2u);
  EXPECT_TRUE(
      s.finished[0].pose.isApprox(cabinet().target_in_world(cabinet().part("base")), 1e-12));
  EXPECT_NEAR(s.finished[1].pose.translation().y(), 0.2, 1e-12);
  ASSERT_EQ(s.obstacles.size(), 2u);
  EXPECT_TRUE(s.obstacles[0].is_box());
  EXPECT_TRUE(s.obstacles[0].box_size.isApprox(Eigen::Vector3d(0.2, 0.3, 0.1)));
  EXPECT_FALSE(s.obstacles[1].is_box());
  // The shelf mesh in mm, scaled to metres: 390 mm long.
  const Eigen::Vector3d extent =
      s.obstacles[1].mesh.max_corner() - s.obstacles[1].mesh.min_corner();
  EXPECT_NEAR(extent.maxCoeff(), 0.390, 1e-6);
}

TEST(Scene, BadInputsNameTheFileTheFieldAndWhatWasExpected) {
  auto expect = [](const std::string& name, const std::string& text,
                   std::initializer_list<std::string> fragments) {
    const std::string path = write_scene(name, text);
    std::vector<std::string> all{path};
    all.insert(all.end(), fragments.begin(), fragments.end());
    SCOPED_TRACE(name);
    try {
      load(path);
      ADD_FAILURE() << "accepted";
    } catch (const core::InputError& e) {
      for (const auto& f : all)
        EXPECT_NE(std::string(e.what()).find(f), std::string::npos)
            << "missing '" << f << "' in: " << e.what();
    }
  };
  expect("unknown_board", "product: cabinet\nboards:\n  basee: {xyz: [0.3, -0.3, 1.152]}\n",
         {"boards.basee", "base, lateral_right", "'basee'"});
  expect("nan_pose", "product: cabinet\nboards:\n  base: {xyz: [.nan, -0.3, 1.152]}\n",
         {"boards.base", "finite"});
  expect("under_table", "product: cabinet\nboards:\n  base: {xyz: [0.3, -0.3, 1.05]}\n",
         {"boards.base", "table top", "inside the table"});
  expect("other_product", "product: shelf\n", {"product", "'cabinet'", "'shelf'"});
  expect("missing_product", "boards: {}\n", {"product"});
  expect("typo", "product: cabinet\nobstacle: []\n", {"obstacle"});
  expect("joints_out_of_limits", "product: cabinet\nrobot:\n  left: [0, 0, 0, 0, 0, 7.5]\n",
         {"robot.left", "limits"});
  expect("joints_count", "product: cabinet\nrobot:\n  left: [0, 0, 0]\n", {"robot.left", "6"});
  expect("unknown_arm", "product: cabinet\nrobot:\n  middle: [0, 0, 0, 0, 0, 0]\n",
         {"robot.middle", "left", "right"});
  expect("finished_twice", "product: cabinet\nfinished: [base, base]\n", {"finished", "again"});
  expect("finished_and_detected",
         "product: cabinet\nfinished: [base]\nboards:\n  base: {xyz: [0.3, -0.3, 1.152]}\n",
         {"boards.base", "finished"});
  expect("box_and_mesh",
         "product: cabinet\nobstacles:\n  - {name: a, box: [0.1, 0.1, 0.1], mesh: x.stl, pose: "
         "{xyz: [0, 0, 0]}}\n",
         {"obstacles[0]", "exactly one of box"});
  expect("negative_box",
         "product: cabinet\nobstacles:\n  - {name: a, box: [0.1, -0.1, 0.1], pose: {xyz: [0, 0, "
         "0]}}\n",
         {"obstacles[0].box", "(0, 5]"});
  expect("missing_mesh",
         "product: cabinet\nobstacles:\n  - {name: a, mesh: nowhere.stl, pose: {xyz: [0, 0, 0]}}\n",
         {"obstacles[0].mesh", "nowhere.stl"});
  expect("stance_on_table", "product: cabinet\nhuman:\n  stance: {xyz: [0.5, 0.0, 0.1]}\n",
         {"human.stance", "clear of the table"});
}

TEST(Scene, TheNominalSceneNamesTheCabinetsCellAndProductFiles) {
  const online::SceneFiles files = online::read_scene_files(scene_path());
  EXPECT_EQ(core::load_product(files.product).name, "cabinet");
  EXPECT_EQ(core::load_cell_spec(files.cell).arms.size(), 2u);
  test::expect_input_error(
      [] { online::read_scene_files(write_scene("no_files", "product: cabinet\n")); }, {"files"});
}

TEST(Scene, MissingFileIsAnInputError) {
  test::expect_input_error([] { load("/nonexistent/scene.yaml"); }, {"/nonexistent/scene.yaml"});
}

// `worker:` names the body at the stance: a model of `hila human` for that stature and sex
// (its shoulder where the anthropometric ratio puts it), the cell's own human when absent.
TEST(Scene, TheWorkerWhoIsThereIsABodyOfThatStatureAndSex) {
  EXPECT_EQ(load(scene_path()).worker, nullptr);
  const online::Scene s =
      load(write_scene("worker", "product: cabinet\nworker: {stature: 1.50, sex: female}\n"));
  ASSERT_NE(s.worker, nullptr);
  EXPECT_DOUBLE_EQ(s.worker->spec().stature, 1.50);
  EXPECT_EQ(s.worker->spec().sex, core::Sex::Female);
  EXPECT_FALSE(s.worker->same_as_cell());
  // Shoulder 0.818 H above the floor, 0.115 H (biacromial 0.230 H / 2) from the midline.
  for (int a = 0; a < static_cast<int>(s.worker->arms().size()); ++a) {
    const Eigen::Vector3d shoulder =
        s.worker->base_in_stance(a) *
        s.worker->arms()[static_cast<std::size_t>(a)].chain.first_joint_position();
    EXPECT_NEAR(shoulder.z(), 0.818 * 1.50, 1e-6);
    EXPECT_NEAR(std::abs(shoulder.y()), 0.115 * 1.50, 1e-6);
  }
  // The scenes that follow keep the worker.
  EXPECT_EQ(s.with_finished(cabinet(), "base").worker, s.worker);
  // The cell's own body named is the cell's human.
  const online::Scene same = load(
      write_scene("worker_default", "product: cabinet\nworker: {stature: 1.722, sex: male}\n"));
  ASSERT_NE(same.worker, nullptr);
  EXPECT_TRUE(same.worker->same_as_cell());
}

TEST(Scene, ABadWorkerNamesTheFileTheFieldAndWhatWasExpected) {
  auto expect = [](const std::string& name, const std::string& text,
                   std::initializer_list<std::string> fragments) {
    const std::string path = write_scene(name, "product: cabinet\n" + text);
    std::vector<std::string> all{path};
    all.insert(all.end(), fragments.begin(), fragments.end());
    SCOPED_TRACE(name);
    try {
      load(path);
      ADD_FAILURE() << "accepted";
    } catch (const core::InputError& e) {
      for (const auto& f : all)
        EXPECT_NE(std::string(e.what()).find(f), std::string::npos)
            << "missing '" << f << "' in: " << e.what();
    }
  };
  expect("millimetres", "worker: {stature: 1500, sex: female}\n",
         {"worker.stature", "[1.3, 2.2]", "millimetres"});
  expect("child", "worker: {stature: 1.0, sex: male}\n", {"worker.stature", "adult stature"});
  expect("sex", "worker: {stature: 1.6, sex: woman}\n",
         {"worker.sex", "male or female", "'woman'"});
  expect("no_sex", "worker: {stature: 1.6}\n", {"worker", "sex"});
  expect("typo", "worker: {stature: 1.6, sex: male, height: 1.6}\n", {"worker", "height"});
  expect("not_a_map", "worker: 1.6\n", {"worker", "stature"});
  expect("nan", "worker: {stature: .nan, sex: male}\n", {"worker.stature"});
}
