#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "hila/core/error.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/yaml_reader.hpp"
#include "util/test_util.hpp"

using namespace hila::core;
using namespace hila::test;

namespace {

// Writes `text` as a YAML file in a fresh temp dir and loads it.
struct YamlFile {
  std::string path;
  YamlNode root;
};

YamlFile load_text(const std::string& test_name, const std::string& text) {
  const std::string dir = temp_dir("yaml_reader_" + test_name);
  const std::string path = write_file(dir, "input.yaml", text);
  return {path, YamlNode::load_file(path)};
}

}  // namespace

TEST(YamlReader, ReadsValuesAndTracksPaths) {
  const auto [path, root] = load_text("values",
                                      "name: cabinet\n"
                                      "count: 7\n"
                                      "flag: true\n"
                                      "mass: 0.8\n"
                                      "robot:\n"
                                      "  arms:\n"
                                      "    - {name: left, home: [1, 2, 3]}\n"
                                      "    - {name: right, home: [4, 5, 6]}\n");
  EXPECT_EQ(root.file(), path);
  EXPECT_EQ(root.at("name").as_string(), "cabinet");
  EXPECT_EQ(root.at("count").as_int(), 7);
  EXPECT_TRUE(root.at("flag").as_bool());
  EXPECT_DOUBLE_EQ(root.at("mass").as_positive(), 0.8);
  const YamlNode home = root.at("robot").at("arms").at(1).at("home");
  EXPECT_EQ(home.path(), "robot.arms[1].home");
  EXPECT_EQ(home.file(), path);
  EXPECT_EQ(home.as_vec3(), Eigen::Vector3d(4, 5, 6));
  EXPECT_TRUE(root.has("robot"));
  EXPECT_FALSE(root.has("human"));
  EXPECT_FALSE(root.find("human").has_value());
  ASSERT_TRUE(root.find("count").has_value());
  EXPECT_EQ(root.at("robot").at("arms").size(), 2u);
}

TEST(YamlReader, MissingFileNamesThePath) {
  const std::string dir = temp_dir("yaml_reader_missing");
  const std::string path = dir + "/does_not_exist.yaml";
  expect_input_error([&] { YamlNode::load_file(path); }, {path, "no such file"});
}

TEST(YamlReader, ADirectoryIsNotAYamlFile) {
  const std::string dir = temp_dir("yaml_reader_directory");
  expect_input_error([&] { YamlNode::load_file(dir); },
                     {dir, "expected a YAML file, got a directory"});
}

TEST(YamlReader, MalformedYamlNamesFileAndLine) {
  const std::string dir = temp_dir("yaml_reader_malformed");
  // Line 3 opens a flow sequence that is never closed before a new block key.
  const std::string path = write_file(dir, "broken.yaml",
                                      "name: cabinet\n"
                                      "mass: 0.8\n"
                                      "target: {xyz: [0, 0, 0]\n"
                                      "other: 1\n");
  try {
    YamlNode::load_file(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find("well-formed YAML"), std::string::npos) << message;
    EXPECT_EQ(e.field().rfind("line ", 0), 0u) << message;
    // The reported line must be inside the file, at or after the opening brace.
    const int line = std::stoi(e.field().substr(5));
    EXPECT_GE(line, 3) << message;
    EXPECT_LE(line, 5) << message;
  }

  // A tab-indented / bad-indentation mapping: error on line 3.
  const std::string path2 = write_file(dir, "indent.yaml",
                                       "a: 1\n"
                                       "b: 2\n"
                                       "  c: 3\n");
  expect_input_error([&] { YamlNode::load_file(path2); }, {path2, "line 3", "well-formed YAML"});

  // from_string names the given source.
  expect_input_error([] { YamlNode::from_string("a: [1, 2\n", "inline-source"); },
                     {"inline-source", "line ", "well-formed YAML"});
}

TEST(YamlReader, TopLevelMustBeAMap) {
  const std::string dir = temp_dir("yaml_reader_toplevel");
  const std::string path = write_file(dir, "list.yaml", "- 1\n- 2\n");
  expect_input_error([&] { YamlNode::load_file(path); }, {path, "a YAML map", "a list of 2 items"});
}

TEST(YamlReader, MissingRequiredFieldNamesDottedPath) {
  const auto [path, root] = load_text("required",
                                      "robot:\n"
                                      "  arms:\n"
                                      "    - {name: left}\n");
  expect_input_error([&] { root.at("gripper"); }, {path, "gripper", "required field"});
  expect_input_error([&] { root.at("robot").at("arms").at(0).at("home_deg"); },
                     {path, "robot.arms[0].home_deg", "required field", "got nothing"});
  expect_input_error([&] { root.at("robot").at("arms").at(3); },
                     {path, "robot.arms", "at least 4 items"});
}

TEST(YamlReader, WrongTypeNamesFieldAndValue) {
  const auto [path, root] = load_text("types",
                                      "part:\n"
                                      "  mass: heavy\n"
                                      "  order: 1.5\n"
                                      "  flag: maybe\n"
                                      "  xyz: [1, 2]\n"
                                      "  name: [a, b]\n"
                                      "  sub: {a: 1}\n");
  const YamlNode part = root.at("part");
  expect_input_error([&] { part.at("mass").as_double(); },
                     {path, "part.mass", "expected a number", "got 'heavy'"});
  expect_input_error([&] { part.at("order").as_int(); },
                     {path, "part.order", "an integer", "'1.5'"});
  expect_input_error([&] { part.at("flag").as_bool(); }, {path, "part.flag", "true or false"});
  expect_input_error([&] { part.at("xyz").as_vec3(); },
                     {path, "part.xyz", "a list of 3 numbers", "a list of 2 items"});
  expect_input_error([&] { part.at("name").as_string(); }, {path, "part.name", "a string"});
  expect_input_error([&] { part.at("sub").as_double(); }, {path, "part.sub", "a number", "a map"});
  expect_input_error([&] { part.at("mass").at("x"); }, {path, "part.mass", "a map"});
}

TEST(YamlReader, NanIsRejected) {
  const auto [path, root] = load_text("nan",
                                      "a: .nan\n"
                                      "b: nan\n"
                                      "c: NaN\n"
                                      "d: .inf\n"
                                      "e: [1, .nan, 3]\n");
  expect_input_error([&] { root.at("a").as_double(); }, {path, "a: ", "a finite number", "NaN"});
  expect_input_error([&] { root.at("b").as_double(); }, {path, "b: ", "a finite number", "NaN"});
  expect_input_error([&] { root.at("c").as_double(); }, {path, "c: ", "a finite number"});
  expect_input_error([&] { root.at("d").as_double(); }, {path, "d: ", "a finite number", "inf"});
  expect_input_error([&] { root.at("e").as_vec3(); }, {path, "e[1]", "a finite number"});
  // Every numeric conversion goes through the same check.
  expect_input_error([&] { root.at("a").as_positive(); }, {path, "a: ", "finite"});
  expect_input_error([&] { root.at("b").as_non_negative(); }, {path, "b: ", "finite"});
  expect_input_error([&] { root.at("a").as_double_in(-1, 1); }, {path, "a: ", "finite"});
}

TEST(YamlReader, RangeChecks) {
  const auto [path, root] = load_text("ranges",
                                      "neg: -1\n"
                                      "zero: 0\n"
                                      "pos: 2.5\n");
  expect_input_error([&] { root.at("neg").as_positive(); },
                     {path, "neg", "a positive number", "got -1"});
  expect_input_error([&] { root.at("zero").as_positive(); }, {path, "zero", "a positive number"});
  EXPECT_DOUBLE_EQ(root.at("zero").as_non_negative(), 0.0);
  expect_input_error([&] { root.at("neg").as_non_negative(); },
                     {path, "neg", "a non-negative number", "-1"});
  EXPECT_DOUBLE_EQ(root.at("pos").as_double_in(0, 3), 2.5);
  expect_input_error([&] { root.at("pos").as_double_in(0, 2); }, {path, "pos", "[0, 2]", "2.5"});
}

TEST(YamlReader, ExpectOnlyRejectsUnknownField) {
  const auto [path, root] = load_text("unknown",
                                      "parts:\n"
                                      "  - {name: base, masss: 0.8}\n");
  const YamlNode part = root.at("parts").at(0);
  EXPECT_NO_THROW(part.expect_only({"name", "masss"}));
  expect_input_error(
      [&] {
        part.expect_only({"name", "mass", "order"});
      },
      {path, "parts[0].masss", "unknown field 'masss'", "name, mass, order"});
  expect_input_error([&] { root.expect_only({"name"}); }, {path, "parts", "unknown field 'parts'"});
}

TEST(YamlReader, PoseWithRpyDegrees) {
  const auto [path, root] = load_text("pose_rpy",
                                      "p: {xyz: [0.1, 0.2, 0.3], rpy_deg: [10, -20, 30]}\n"
                                      "r: {xyz: [0, 0, 0], rpy: [0.1, 0.2, 0.3]}\n"
                                      "t: {xyz: [1, 2, 3]}\n");
  const Pose p = root.at("p").as_pose();
  EXPECT_LT((p.translation() - Eigen::Vector3d(0.1, 0.2, 0.3)).norm(), 1e-15);
  const Eigen::Matrix3d expected =
      rpy_to_matrix(Eigen::Vector3d(deg_to_rad(10), deg_to_rad(-20), deg_to_rad(30)));
  EXPECT_LT((p.linear() - expected).cwiseAbs().maxCoeff(), 1e-12);
  const Pose r = root.at("r").as_pose();
  EXPECT_LT((r.linear() - rpy_to_matrix(Eigen::Vector3d(0.1, 0.2, 0.3))).cwiseAbs().maxCoeff(),
            1e-15);
  const Pose t = root.at("t").as_pose();
  EXPECT_TRUE(t.linear().isIdentity(0.0));
  EXPECT_EQ(t.translation(), Eigen::Vector3d(1, 2, 3));
}

TEST(YamlReader, PoseWithQuaternion) {
  const double a = 0.8;
  const std::string w = std::to_string(std::cos(a / 2));
  const std::string z = std::to_string(std::sin(a / 2));
  const auto [path, root] =
      load_text("pose_quat", "good: {xyz: [0, 0, 1], quat_wxyz: [" + w + ", 0, 0, " + z +
                                 "]}\n"
                                 "bad: {xyz: [0, 0, 1], quat_wxyz: [1, 1, 0, 0]}\n"
                                 "short: {xyz: [0, 0, 1], quat_wxyz: [1, 0, 0]}\n");
  const Pose good = root.at("good").as_pose();
  const Eigen::Matrix3d expected =
      Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_LT((good.linear() - expected).cwiseAbs().maxCoeff(), 1e-6);  // 6 printed digits
  EXPECT_EQ(good.translation(), Eigen::Vector3d(0, 0, 1));
  expect_input_error([&] { root.at("bad").as_pose(); },
                     {path, "bad.quat_wxyz", "a unit quaternion", "norm 1.414"});
  expect_input_error([&] { root.at("short").as_pose(); },
                     {path, "short.quat_wxyz", "a list of 4 numbers"});
}

TEST(YamlReader, PoseWithRotationMatrix) {
  const auto [path, root] =
      load_text("pose_matrix",
                "good: {xyz: [1, 0, 0], rotation: [[0, 1, 0], [0, 0, 1], [1, 0, 0]]}\n"
                "scaled: {xyz: [1, 0, 0], rotation: [[2, 0, 0], [0, 1, 0], [0, 0, 1]]}\n"
                "mirror: {xyz: [1, 0, 0], rotation: [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]}\n"
                "rows: {xyz: [1, 0, 0], rotation: [[1, 0, 0], [0, 1, 0]]}\n");
  const Pose good = root.at("good").as_pose();
  Eigen::Matrix3d expected;
  expected << 0, 1, 0, 0, 0, 1, 1, 0, 0;
  EXPECT_EQ(good.linear(), expected);
  expect_input_error([&] { root.at("scaled").as_pose(); },
                     {path, "scaled.rotation", "orthonormal"});
  expect_input_error([&] { root.at("mirror").as_pose(); },
                     {path, "mirror.rotation", "determinant +1"});
  expect_input_error([&] { root.at("rows").as_pose(); }, {path, "rows.rotation", "3 rows"});
}

TEST(YamlReader, PoseRejectsTwoRotationsAndBadKeys) {
  const auto [path, root] =
      load_text("pose_two",
                "two: {xyz: [0, 0, 0], rpy_deg: [0, 0, 90], quat_wxyz: [1, 0, 0, 0]}\n"
                "typo: {xyz: [0, 0, 0], rpy_degs: [0, 0, 90]}\n"
                "noxyz: {rpy_deg: [0, 0, 90]}\n");
  expect_input_error([&] { root.at("two").as_pose(); },
                     {path, "two", "at most one of rpy_deg, rpy, quat_wxyz, rotation"});
  expect_input_error([&] { root.at("typo").as_pose(); }, {path, "typo.rpy_degs", "unknown field"});
  expect_input_error([&] { root.at("noxyz").as_pose(); }, {path, "noxyz.xyz", "required field"});
}

TEST(YamlReader, ResolvePathRelativeToFileFolder) {
  const std::string dir = temp_dir("yaml_reader_resolve");
  std::filesystem::create_directories(dir + "/sub");
  const std::string path = write_file(dir + "/sub", "cell.yaml", "urdf: robot.urdf\n");
  const YamlNode root = YamlNode::load_file(path);
  const std::filesystem::path sub = std::filesystem::path(dir) / "sub";
  EXPECT_EQ(root.resolve_path(root.at("urdf").as_string()), (sub / "robot.urdf").string());
  EXPECT_EQ(root.at("urdf").resolve_path("meshes/a.stl"), (sub / "meshes" / "a.stl").string());
  EXPECT_EQ(root.resolve_path("../shared/b.stl"),
            (std::filesystem::path(dir) / "shared" / "b.stl").lexically_normal().string());
  EXPECT_EQ(root.resolve_path("/abs/c.stl"), "/abs/c.stl");
  // The resolved file really is the one next to the YAML file.
  write_file(sub.string(), "robot.urdf", "<robot/>");
  EXPECT_TRUE(std::filesystem::exists(root.resolve_path("robot.urdf")));
}

// yaml-cpp keeps the first of two equal keys; a repeated key is refused, naming its path and
// both lines, wherever the map is (top level, nested, in a list, flow style).
TEST(YamlReader, DuplicateKeysAreRefused) {
  const std::string dir = temp_dir("yaml_reader_duplicates");
  const std::string top = write_file(dir, "top.yaml", "a: 1\nb: 2\na: 3\n");
  expect_input_error([&] { YamlNode::load_file(top); },
                     {top, ": a: ", "a key that appears once in its map",
                      "'a' again on line 3 (first on line 1)"});
  const std::string nested =
      write_file(dir, "nested.yaml", "parts:\n  - name: x\n    mass: 1\n    mass: 100\n");
  expect_input_error([&] { YamlNode::load_file(nested); },
                     {nested, ": parts[0].mass: ", "'mass' again on line 4 (first on line 3)"});
  const std::string flow = write_file(dir, "flow.yaml", "p: {xyz: [0, 0, 0], xyz: [1, 1, 1]}\n");
  expect_input_error([&] { YamlNode::load_file(flow); }, {flow, ": p.xyz: ", "'xyz' again"});
  expect_input_error([] { YamlNode::from_string("k: 1\nk: 2\n", "text.yaml"); },
                     {"text.yaml", ": k: ", "'k' again on line 2"});
  // Equal keys in different maps, and a map reused through an alias, are fine.
  const std::string fine = write_file(dir, "fine.yaml",
                                      "a: {x: 1, y: 2}\nb: {x: 1, y: 2}\n"
                                      "c: &shared {x: 1}\nd: *shared\nl: [{x: 1}, {x: 2}]\n");
  const YamlNode root = YamlNode::load_file(fine);
  EXPECT_DOUBLE_EQ(root.at("d").at("x").as_double(), 1.0);
}

// Rotation angles are finite and within one turn either way: 1e300 degrees is a typo, not a
// rotation (and loses every digit of the angle that matters).
TEST(YamlReader, RotationAnglesBeyondOneTurnAreRefused) {
  const auto [path, root] = load_text("pose_angles",
                                      "huge: {xyz: [0, 0, 0], rpy_deg: [0, 0, 1e300]}\n"
                                      "turn: {xyz: [0, 0, 0], rpy_deg: [-360, 0, 360]}\n"
                                      "over: {xyz: [0, 0, 0], rpy_deg: [361, 0, 0]}\n"
                                      "rad: {xyz: [0, 0, 0], rpy: [0, 7, 0]}\n"
                                      "overflow: {xyz: [0, 0, 0], rpy_deg: [0, 1e400, 0]}\n");
  expect_input_error([&] { root.at("huge").as_pose(); },
                     {path, ": huge.rpy_deg[2]: ", "an angle in degrees in [-360, 360]", "1e+300"});
  EXPECT_NO_THROW(root.at("turn").as_pose());
  expect_input_error([&] { root.at("over").as_pose(); },
                     {path, ": over.rpy_deg[0]: ", "[-360, 360]", "got 361"});
  expect_input_error(
      [&] { root.at("rad").as_pose(); },
      {path, ": rad.rpy[1]: ", "an angle in radians in [-6.283185307, 6.283185307]", "got 7"});
  expect_input_error([&] { root.at("overflow").as_pose(); },
                     {path, ": overflow.rpy_deg[1]: ", "a number", "'1e400'"});
}

TEST(YamlReader, AListOrMapAsAKeyIsAnInputError) {
  // A stray bracket in a flow map makes a list a key (found by fuzz/fuzz_product): an input
  // error at the map, not yaml-cpp's bad conversion escaping as an internal error.
  const auto [path, root] = load_text("list_key",
                                      "assembly_frame: {xyz: [0, 0, 0], rpy_deg: 0, [0, 90]}\n"
                                      "robot: {[left, right]: 1}\n"
                                      "boards: {{a: 1}: 2}\n");
  expect_input_error(
      [&] { root.at("assembly_frame").as_pose(); },
      {path, "assembly_frame", "field names as keys", "a list or map used as a key"});
  expect_input_error([&] { root.at("robot").keys(); },
                     {path, "robot", "a list or map used as a key"});
  expect_input_error([&] { root.at("boards").expect_only({"a"}); },
                     {path, "boards", "a list or map used as a key"});
}
