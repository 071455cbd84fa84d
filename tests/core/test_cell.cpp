#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/error.hpp"
#include "util/test_util.hpp"

using namespace hila::core;
using namespace hila::test;

namespace {

// Replaces the first occurrence of `from` (which must exist) with `to`.
std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "cell.yaml no longer contains '" << from << "'";
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

// The reference cell text with its URDF paths made absolute, so that it can live in a temp dir.
std::string cell_text() {
  std::string text = read_file(cell_path());
  text = replace_once(text, "urdf: dual_ur3.urdf", "urdf: " + data_path("cell/dual_ur3.urdf"));
  text = replace_once(text, "tool_urdf: suction_tool.urdf",
                      "tool_urdf: " + data_path("cell/suction_tool.urdf"));
  text = replace_once(text, "urdf: human.urdf", "urdf: " + data_path("cell/human.urdf"));
  return text;
}

// Writes a (modified) cell file into a fresh temp dir and returns its path.
std::string write_cell(const std::string& test_name, const std::string& text) {
  return write_file(temp_dir("cell_" + test_name), "cell.yaml", text);
}

Pose link_pose(const Cell& cell, const Eigen::VectorXd& q, const std::string& link) {
  std::vector<Pose> poses;
  cell.robot().link_poses(q, poses);
  return poses[cell.robot().link_index(link)];
}

}  // namespace

TEST(Cell, ReferenceCellLoads) {
  const auto cell = reference_cell();
  ASSERT_NE(cell, nullptr);
  EXPECT_EQ(cell->spec().file, cell_path());
  ASSERT_EQ(cell->arms().size(), 2u);
  EXPECT_EQ(cell->arms()[0].spec.name, "left");
  EXPECT_EQ(cell->arms()[1].spec.name, "right");
  for (const Arm& arm : cell->arms()) {
    EXPECT_EQ(arm.chain.dof(), 6) << arm.spec.name;
    EXPECT_TRUE(arm.ur_ik.has_value()) << arm.spec.name;
    EXPECT_TRUE(arm.spec.ur_dh.has_value()) << arm.spec.name;
    EXPECT_EQ(arm.spec.home.size(), 6);
    EXPECT_EQ(arm.spec.max_velocity.size(), 6);
    EXPECT_EQ(arm.spec.max_acceleration.size(), 6);
    EXPECT_TRUE(arm.chain.within_limits(arm.spec.home));
    EXPECT_GE(arm.finger_variable, 0);
    EXPECT_EQ(cell->robot().joints()[cell->robot().variable_joints()[arm.finger_variable]].name,
              arm.spec.name + "_finger_joint");
  }
  EXPECT_NE(cell->arms()[0].finger_variable, cell->arms()[1].finger_variable);
  EXPECT_EQ(&cell->arm("right"), &cell->arms()[1]);
  expect_input_error([&] { cell->arm("middle"); }, {cell_path(), "arm", "left, right", "'middle'"});

  ASSERT_EQ(cell->human_arms().size(), 2u);
  for (const HumanArm& arm : cell->human_arms()) {
    EXPECT_EQ(arm.chain.dof(), 7) << arm.spec.name;
    EXPECT_EQ(arm.spec.base_link, "torso");
  }
  EXPECT_EQ(cell->human_arms()[0].spec.tip_link, "left_hand_grasp");
  EXPECT_EQ(cell->human_arms()[1].spec.tip_link, "right_hand_grasp");

  // Values read from the file.
  EXPECT_DOUBLE_EQ(cell->arms()[0].spec.home[0], deg_to_rad(15));
  EXPECT_DOUBLE_EQ(cell->arms()[0].spec.max_velocity[3], deg_to_rad(360));
  EXPECT_DOUBLE_EQ(cell->spec().gripper.jaw_max, 0.085);
  EXPECT_DOUBLE_EQ(cell->spec().gripper.pad.friction, 0.8);
  ASSERT_EQ(cell->spec().obstacles.size(), 1u);
  EXPECT_EQ(cell->spec().obstacles[0].name, "table");
  EXPECT_EQ(cell->spec().allowed_collisions.size(), 8u);
  EXPECT_LT((cell->spec().human_stance.translation() - Eigen::Vector3d(1.15, 0, 0.1)).norm(),
            1e-12);
  EXPECT_TRUE(is_valid_pose(cell->spec().human_stance));
}

TEST(Cell, HomeTcpsAreMirrorImagesAcrossXzPlane) {
  const auto cell = reference_cell();
  const Eigen::VectorXd q = cell->home_configuration();
  const Pose left = link_pose(*cell, q, cell->arm("left").spec.tip_link);
  const Pose right = link_pose(*cell, q, cell->arm("right").spec.tip_link);
  EXPECT_NEAR(left.translation().x(), right.translation().x(), 1e-9);
  EXPECT_NEAR(left.translation().y(), -right.translation().y(), 1e-9);
  EXPECT_NEAR(left.translation().z(), right.translation().z(), 1e-9);
  // Not trivially on the plane.
  EXPECT_GT(std::abs(left.translation().y()), 0.01);

  // The chain FK (TCP in the arm base) agrees with the whole-robot FK.
  for (const Arm& arm : cell->arms()) {
    const Pose base = link_pose(*cell, q, arm.spec.base_link);
    const Pose tip = link_pose(*cell, q, arm.spec.tip_link);
    const Pose chain_tip = arm.chain.fk(arm.spec.home);
    EXPECT_LT(((base * chain_tip).matrix() - tip.matrix()).cwiseAbs().maxCoeff(), 1e-12)
        << arm.spec.name;
  }
}

TEST(Cell, HomeConfigurationSetsTheJaw) {
  const auto cell = reference_cell();
  const Eigen::VectorXd q = cell->home_configuration(0.06);
  ASSERT_EQ(q.size(), cell->robot().num_variables());
  for (const Arm& arm : cell->arms()) {
    EXPECT_DOUBLE_EQ(q[arm.finger_variable], 0.03) << arm.spec.name;
    const auto& vars = arm.chain.model_variables();
    ASSERT_EQ(vars.size(), 6u);
    for (std::size_t i = 0; i < vars.size(); ++i) {
      EXPECT_DOUBLE_EQ(q[vars[i]], arm.spec.home[static_cast<Eigen::Index>(i)]);
    }
  }
  const Eigen::VectorXd open = cell->home_configuration();
  for (const Arm& arm : cell->arms()) EXPECT_DOUBLE_EQ(open[arm.finger_variable], 0.0425);
  // The pads really are 6 cm apart.
  const Pose pad_l = link_pose(*cell, q, "left_pad_l");
  const Pose pad_r = link_pose(*cell, q, "left_pad_r");
  EXPECT_NEAR((pad_l.translation() - pad_r.translation()).norm(), 0.06, 1e-12);
}

TEST(Cell, ReferenceSceneIsCollisionFreeAtHome) {
  const auto cell = reference_cell();
  const CellScene scene = build_cell_scene(*cell);
  ASSERT_EQ(scene.obstacles.size(), 1u);
  CollisionData data(scene.model);
  set_cell_state(*cell, scene, data, cell->home_configuration(), cell->human_neutral());
  CollisionPair pair;
  EXPECT_FALSE(in_collision(scene.model, data, &pair)) << describe_pair(scene.model, pair);
}

TEST(Cell, CopiedCellLoadsFromTempDir) {
  // The control for the bad-input tests below: the unmodified copy loads.
  const std::string path = write_cell("copy", cell_text());
  const auto cell = Cell::load(path);
  EXPECT_EQ(cell->spec().file, path);
  EXPECT_EQ(cell->arms().size(), 2u);
  EXPECT_NO_THROW(build_cell_scene(*cell));
}

TEST(Cell, MissingCellFile) {
  const std::string path = temp_dir("cell_missing") + "/cell.yaml";
  expect_input_error([&] { Cell::load(path); }, {path, "no such file"});
}

TEST(Cell, MalformedYaml) {
  const std::string text =
      replace_once(cell_text(), "jaw_range: [0.0, 0.085]", "jaw_range: [0.0, 0.085");
  const std::string path = write_cell("malformed", text);
  expect_input_error([&] { Cell::load(path); }, {path, "line ", "well-formed YAML"});
}

TEST(Cell, UnknownTopLevelField) {
  const std::string path = write_cell("unknown_field", cell_text() + "\ngravty: 9.81\n");
  expect_input_error([&] { Cell::load(path); }, {path, "gravty", "unknown field"});
}

TEST(Cell, UnknownTipLink) {
  const std::string text = replace_once(cell_text(), "tip_link: left_tcp", "tip_link: left_tcq");
  const std::string path = write_cell("tip_link", text);
  expect_input_error([&] { Cell::load(path); },
                     {path, "robot.arms[0].tip_link", "'left_tcq'", "dual_ur3.urdf"});
}

TEST(Cell, HomeWithFiveValuesAllListsShortened) {
  // All three per-joint lists have 5 entries: the cell parses, but the chain has 6 joints.
  std::string text = cell_text();
  text = replace_once(text, "home_deg: [15, -60, -120, -180, -120, 0]",
                      "home_deg: [15, -60, -120, -180, -120]");
  text = replace_once(text, "max_velocity_deg_s: [180, 180, 180, 360, 360, 360]",
                      "max_velocity_deg_s: [180, 180, 180, 360, 360]");
  text = replace_once(text, "max_acceleration_deg_s2: [170, 170, 170, 340, 340, 340]",
                      "max_acceleration_deg_s2: [170, 170, 170, 340, 340]");
  const std::string path = write_cell("home5_all", text);
  expect_input_error([&] { Cell::load(path); },
                     {path, "robot.arms[0].home_deg", "6 values", "got 5"});
}

TEST(Cell, HomeWithFiveValues) {
  // Only home_deg is wrong; the error must point at home_deg (not at the correct 6-value lists).
  const std::string text = replace_once(cell_text(), "home_deg: [15, -60, -120, -180, -120, 0]",
                                        "home_deg: [15, -60, -120, -180, -120]");
  const std::string path = write_cell("home5", text);
  expect_input_error([&] { Cell::load(path); }, {path, "robot.arms[0].home_deg"});
}

TEST(Cell, HomeOutsideLimits) {
  const std::string text = replace_once(cell_text(), "home_deg: [15, -60, -120, -180, -120, 0]",
                                        "home_deg: [15, -60, -120, -180, -120, 400]");
  const std::string path = write_cell("home_limits", text);
  expect_input_error([&] { Cell::load(path); }, {path, "robot.arms[0].home_deg", "limits"});
}

TEST(Cell, NanInHumanStance) {
  const std::string text = replace_once(cell_text(), "stance: {xyz: [1.15, 0.0, 0.1]",
                                        "stance: {xyz: [1.15, .nan, 0.1]");
  const std::string path = write_cell("stance_nan", text);
  expect_input_error([&] { Cell::load(path); }, {path, "human.stance.xyz[1]", "finite"});
}

TEST(Cell, StanceInsideTheTableIsRejected) {
  EXPECT_NO_THROW(check_human_stance(*Cell::load(write_cell("stance_ok", cell_text()))));
  // The human moved 0.5 m toward the robot: the pelvis is inside the table.
  const std::string text =
      replace_once(cell_text(), "stance: {xyz: [1.15, 0.0, 0.1]", "stance: {xyz: [0.65, 0.0, 0.1]");
  const auto cell = Cell::load(write_cell("stance_table", text));
  expect_input_error([&] { check_human_stance(*cell); }, {"human.stance", "table"});
}

TEST(Cell, NonOrthonormalStanceRotation) {
  const std::string text = replace_once(
      cell_text(), "stance: {xyz: [1.15, 0.0, 0.1], rpy_deg: [0, 0, 180]}",
      "stance: {xyz: [1.15, 0.0, 0.1], rotation: [[-1, 0, 0], [0, -1.1, 0], [0, 0, 1]]}");
  const std::string path = write_cell("stance_rotation", text);
  expect_input_error([&] { Cell::load(path); }, {path, "human.stance.rotation", "orthonormal"});
}

TEST(Cell, JawRangeInMillimetres) {
  const std::string text =
      replace_once(cell_text(), "jaw_range: [0.0, 0.085]", "jaw_range: [0, 85]");
  const std::string path = write_cell("jaw_mm", text);
  expect_input_error([&] { Cell::load(path); }, {path, "gripper.jaw_range", "millimetres"});
}

TEST(Cell, WrongUrDhValue) {
  const std::string text = replace_once(cell_text(), "d4: 0.11235", "d4: 0.2");
  const std::string path = write_cell("dh", text);
  expect_input_error([&] { Cell::load(path); }, {"mismatch", "kinematics", "left_base_link"});
}

TEST(Cell, AllowedCollisionWithUnknownLink) {
  const std::string text =
      replace_once(cell_text(), "- [left_pad_l, left_pad_r]", "- [left_pad_l, left_pad_rr]");
  const std::string path = write_cell("allowed", text);
  const auto cell = Cell::load(path);  // names are checked when the scene is built
  expect_input_error([&] { build_cell_scene(*cell); },
                     {path, "robot.allowed_collisions", "'left_pad_rr'"});
}

TEST(Cell, OtherBadValues) {
  // A handful of further single-field mistakes, each must name the file and the field.
  struct Case {
    std::string from, to, field, fragment;
  };
  const std::vector<Case> cases = {
      {"grip_force: 100", "grip_force: 300", "gripper.grip_force", "[20, 235]"},
      {"opening_axis: [0, 1, 0]", "opening_axis: [0, 2, 0]", "gripper.opening_axis", "unit vector"},
      {"approach_axis: [0, 0, 1]", "approach_axis: [0, 1, 0]", "gripper.approach_axis",
       "perpendicular"},
      {"max_force: 40.0", "max_force: -40.0", "suction.max_force", "positive"},
      {"box: [0.8, 1.83, 0.024]", "box: [0.8, 0, 0.024]", "obstacles[0].box", "positive"},
      {"finger_joint: left_finger_joint", "finger_joint: left_finger_r_joint",
       "robot.arms[0].finger_joint", "independent"},
      {"kinematics: {type: ur,", "kinematics: {type: ux,", "robot.arms[0].kinematics.type", "'ux'"},
      {"- name: right", "- name: left", "robot.arms[1].name", "unique"},
      {"handle_link: tool_handle", "handle_link: tool_grip", "suction.handle_link", "'tool_grip'"},
      {"allowed_kg: 3.5", "allowed_kg: 2.5", "robot.arms[0].payload.allowed_kg", "[3, 1000]"},
      {"rated_kg: 3.0", "rated_kg: -3", "robot.arms[0].payload.rated_kg", "[0.001, 1000]"},
      {"mass_kg: 0.925", "mass_kg: 4", "robot.arms[0].payload.tooling[2].mass_kg", "3.5"},
      {"mass_kg: 0.25", "mass_kg: -1", "suction.mass_kg", "[0, 100]"},
      {"rated_kg: 3.0", "rated_kg: 3.0\n        payload_kg: 3", "robot.arms[0].payload",
       "payload_kg"},
  };
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE(cases[i].field);
    const std::string text = replace_once(cell_text(), cases[i].from, cases[i].to);
    const std::string path = write_cell("other_" + std::to_string(i), text);
    expect_input_error([&] { Cell::load(path); }, {path, cases[i].field, cases[i].fragment});
  }
}
