#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "hila/core/error.hpp"
#include "hila/core/robot_model.hpp"
#include "util/test_util.hpp"

using namespace hila::core;
using namespace hila::test;

namespace {

std::string urdf_path() {
  return data_path("cell/dual_ur3.urdf");
}

const RobotModel& dual_ur3() {
  static const RobotModel model = RobotModel::load_urdf_file(urdf_path());
  return model;
}

// A two-link robot whose link and joint elements are spliced in by the tests.
std::string small_urdf(const std::string& base_geometry, const std::string& joint_child) {
  return "<?xml version=\"1.0\"?>\n"
         "<robot name=\"small\">\n"
         "  <link name=\"base\"><collision><geometry>" +
         base_geometry +
         "</geometry></collision></link>\n"
         "  <link name=\"arm\"/>\n"
         "  <joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"" +
         joint_child +
         "\"/><origin xyz=\"0 0 0.1\" rpy=\"0 0 0\"/><axis xyz=\"0 0 1\"/>"
         "<limit lower=\"-1\" upper=\"1\" velocity=\"1\" effort=\"1\"/></joint>\n"
         "</robot>\n";
}

}  // namespace

TEST(RobotModel, DualUr3VariablesAndJoints) {
  const RobotModel& model = dual_ur3();
  EXPECT_EQ(model.name(), "dual_ur3");
  EXPECT_EQ(model.source(), urdf_path());
  EXPECT_EQ(model.num_variables(), 14);
  int revolute = 0;
  int independent_prismatic = 0;
  int mimic = 0;
  for (const Joint& j : model.joints()) {
    if (j.type == JointType::Revolute) {
      ++revolute;
      EXPECT_GE(j.variable, 0) << j.name;
    }
    if (j.type == JointType::Prismatic && j.mimic_joint < 0) ++independent_prismatic;
    if (j.mimic_joint >= 0) {
      ++mimic;
      EXPECT_EQ(j.variable, -1) << j.name;
    }
    if (j.type == JointType::Fixed) {
      EXPECT_EQ(j.variable, -1) << j.name;
    }
  }
  EXPECT_EQ(revolute, 12);
  EXPECT_EQ(independent_prismatic, 2);
  EXPECT_EQ(mimic, 2);
  ASSERT_EQ(model.variable_joints().size(), 14u);
  for (int v = 0; v < model.num_variables(); ++v) {
    EXPECT_EQ(model.joints()[model.variable_joints()[v]].variable, v);
  }

  // Mimic joints point at their masters.
  const Joint& left_r = model.joints()[model.joint_index("left_finger_r_joint")];
  EXPECT_EQ(left_r.mimic_joint, model.joint_index("left_finger_joint"));
  EXPECT_DOUBLE_EQ(left_r.mimic_multiplier, 1.0);
  const Joint& right_r = model.joints()[model.joint_index("right_finger_r_joint")];
  EXPECT_EQ(right_r.mimic_joint, model.joint_index("right_finger_joint"));

  // Limits from the URDF.
  const Joint& finger = model.joints()[model.joint_index("left_finger_joint")];
  EXPECT_DOUBLE_EQ(finger.lower, 0.0);
  EXPECT_DOUBLE_EQ(finger.upper, 0.0425);
  EXPECT_EQ(model.lower_limits().size(), 14);
  EXPECT_TRUE((model.lower_limits().array() <= model.upper_limits().array()).all());
  const Eigen::VectorXd neutral = model.neutral_configuration();
  EXPECT_TRUE((neutral.array() >= model.lower_limits().array()).all());
  EXPECT_TRUE((neutral.array() <= model.upper_limits().array()).all());

  // Topological order: every joint's parent link is the root or the child of an earlier joint.
  std::vector<bool> placed(model.links().size(), false);
  placed[model.root_link()] = true;
  for (const Joint& j : model.joints()) {
    EXPECT_TRUE(placed[j.parent_link]) << j.name;
    placed[j.child_link] = true;
  }
  EXPECT_EQ(model.links()[model.root_link()].name, "world");
}

TEST(RobotModel, MimicFingersMoveSymmetricallyAlongPalmY) {
  const RobotModel& model = dual_ur3();
  Eigen::VectorXd q = model.neutral_configuration();
  const int left_var = model.joints()[model.joint_index("left_finger_joint")].variable;
  const int right_var = model.joints()[model.joint_index("right_finger_joint")].variable;
  ASSERT_GE(left_var, 0);
  ASSERT_GE(right_var, 0);
  // Some arbitrary arm pose so that the palm frame is not axis-aligned.
  for (int v = 0; v < model.num_variables(); ++v) {
    if (v != left_var && v != right_var) q[v] = 0.1 * (v + 1);
  }
  const double half_opening = 0.03;
  q[left_var] = half_opening;

  std::vector<Pose> poses;
  model.link_poses(q, poses);
  ASSERT_EQ(poses.size(), model.links().size());
  const Pose& palm = poses[model.link_index("left_gripper_palm")];
  const Eigen::Vector3d pad_l =
      palm.inverse() * poses[model.link_index("left_pad_l")].translation();
  const Eigen::Vector3d pad_r =
      palm.inverse() * poses[model.link_index("left_pad_r")].translation();
  EXPECT_NEAR(pad_l.y(), half_opening, 1e-12);
  EXPECT_NEAR(pad_r.y(), -half_opening, 1e-12);
  EXPECT_NEAR(pad_l.x(), pad_r.x(), 1e-12);
  EXPECT_NEAR(pad_l.z(), pad_r.z(), 1e-12);
  EXPECT_NEAR((pad_l - pad_r).norm(), 2 * half_opening, 1e-12);
  // Fingers keep the palm orientation (pure translation).
  const Pose finger_r_in_palm = palm.inverse() * poses[model.link_index("left_finger_r")];
  EXPECT_LT((finger_r_in_palm.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_NEAR(model.joint_value(q, model.joint_index("left_finger_r_joint")), half_opening, 0.0);

  // The other gripper stays closed.
  const Pose& right_palm = poses[model.link_index("right_gripper_palm")];
  const Eigen::Vector3d right_l =
      right_palm.inverse() * poses[model.link_index("right_pad_l")].translation();
  const Eigen::Vector3d right_r =
      right_palm.inverse() * poses[model.link_index("right_pad_r")].translation();
  EXPECT_NEAR((right_l - right_r).norm(), 0.0, 1e-12);
}

TEST(RobotModel, LinkIndexUnknownNameThrows) {
  const RobotModel& model = dual_ur3();
  EXPECT_EQ(model.links()[model.link_index("left_tcp")].name, "left_tcp");
  EXPECT_FALSE(model.find_link("left_tcpp").has_value());
  expect_input_error([&] { model.link_index("left_tcpp"); },
                     {urdf_path(), "link", "'left_tcpp'", "dual_ur3"});
  expect_input_error([&] { model.link_index("nope", "robot.arms[0].tip_link"); },
                     {urdf_path(), "robot.arms[0].tip_link", "'nope'"});
  expect_input_error([&] { model.joint_index("no_joint"); }, {urdf_path(), "joint", "'no_joint'"});
}

TEST(RobotModel, MissingFileThrows) {
  const std::string dir = temp_dir("robot_model_missing");
  const std::string path = dir + "/absent.urdf";
  expect_input_error([&] { RobotModel::load_urdf_file(path); }, {path, "no such file"});
}

TEST(RobotModel, TruncatedXmlThrows) {
  const std::string text = read_file(urdf_path());
  ASSERT_GT(text.size(), 1000u);
  const std::string truncated = text.substr(0, text.size() / 2);
  const std::string dir = temp_dir("robot_model_truncated");
  const std::string path = write_file(dir, "truncated.urdf", truncated);
  expect_input_error([&] { RobotModel::load_urdf_file(path); }, {path, "a valid URDF document"});
  expect_input_error([&] { RobotModel::load_urdf_string(truncated, "in-memory.urdf"); },
                     {"in-memory.urdf", "a valid URDF document"});
  expect_input_error([&] { RobotModel::load_urdf_string("not xml at all", "junk.urdf"); },
                     {"junk.urdf", "expected a URDF (XML), got text that is not XML"});
}

TEST(RobotModel, AnEmptyFileOrADirectoryIsNotAUrdf) {
  const std::string dir = temp_dir("robot_model_not_a_urdf");
  const std::string empty = write_file(dir, "empty.urdf", " \n");
  expect_input_error([&] { RobotModel::load_urdf_file(empty); },
                     {empty, "expected a URDF (XML), got an empty file"});
  expect_input_error([&] { RobotModel::load_urdf_file(dir); },
                     {dir, "expected a URDF file, got a directory"});
}

TEST(RobotModel, JointToUnknownLinkThrows) {
  const std::string good = small_urdf("<box size=\"0.1 0.1 0.1\"/>", "arm");
  const RobotModel model = RobotModel::load_urdf_string(good, "good.urdf");
  EXPECT_EQ(model.num_variables(), 1);
  EXPECT_EQ(model.links().size(), 2u);

  const std::string bad = small_urdf("<box size=\"0.1 0.1 0.1\"/>", "ghost");
  expect_input_error([&] { RobotModel::load_urdf_string(bad, "ghost.urdf"); },
                     {"ghost.urdf", "a valid URDF document", "ghost"});
}

TEST(RobotModel, ZeroRadiusCylinderRejected) {
  const std::string ok = small_urdf("<cylinder radius=\"0.05\" length=\"0.2\"/>", "arm");
  const RobotModel model = RobotModel::load_urdf_string(ok, "ok.urdf");
  const auto& shapes = model.links()[model.link_index("base")].collisions;
  ASSERT_EQ(shapes.size(), 1u);
  EXPECT_EQ(shapes[0].type, GeometrySpec::Type::Cylinder);
  EXPECT_DOUBLE_EQ(shapes[0].radius, 0.05);
  EXPECT_DOUBLE_EQ(shapes[0].length, 0.2);

  const std::string zero = small_urdf("<cylinder radius=\"0\" length=\"0.2\"/>", "arm");
  expect_input_error(
      [&] { RobotModel::load_urdf_string(zero, "zero_radius.urdf"); },
      {"zero_radius.urdf", "link 'base' collision geometry", "positive radius", "radius 0"});
  const std::string zero_box = small_urdf("<box size=\"0.1 0 0.1\"/>", "arm");
  expect_input_error([&] { RobotModel::load_urdf_string(zero_box, "flat_box.urdf"); },
                     {"flat_box.urdf", "link 'base'", "positive finite sides"});
}

TEST(RobotModel, AdjacentLinks) {
  const RobotModel& model = dual_ur3();
  const int shoulder = model.link_index("left_shoulder_link");
  const int upper = model.link_index("left_upper_arm_link");
  const int forearm = model.link_index("left_forearm_link");
  const int base = model.link_index("left_base_link");
  EXPECT_TRUE(model.adjacent(shoulder, upper));
  EXPECT_TRUE(model.adjacent(upper, shoulder));
  EXPECT_TRUE(model.adjacent(upper, forearm));
  EXPECT_TRUE(model.adjacent(base, shoulder));
  EXPECT_FALSE(model.adjacent(base, upper));
  EXPECT_FALSE(model.adjacent(shoulder, forearm));
  // Siblings under the palm are not adjacent to each other.
  EXPECT_FALSE(
      model.adjacent(model.link_index("left_finger_l"), model.link_index("left_finger_r")));
  EXPECT_TRUE(
      model.adjacent(model.link_index("left_gripper_palm"), model.link_index("left_finger_l")));
  // Left and right arms never touch through a joint.
  EXPECT_FALSE(model.adjacent(shoulder, model.link_index("right_shoulder_link")));
}
