#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/product.hpp"
#include "util/test_util.hpp"

using namespace hila::core;
using namespace hila::test;

namespace {

const ProductSpec& cabinet() {
  static const ProductSpec product = load_product(product_path());
  return product;
}

std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  EXPECT_NE(pos, std::string::npos) << "product.yaml no longer contains '" << from << "'";
  if (pos != std::string::npos) text.replace(pos, from.size(), to);
  return text;
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  std::size_t pos = 0;
  int count = 0;
  while ((pos = text.find(from, pos)) != std::string::npos) {
    text.replace(pos, from.size(), to);
    pos += to.size();
    ++count;
  }
  EXPECT_GT(count, 0) << "product.yaml no longer contains '" << from << "'";
  return text;
}

// The cabinet's product file with absolute mesh paths, so that it can live in a temp dir.
std::string product_text() {
  std::string text = read_file(product_path());
  for (const char* mesh : {"shelf.stl", "lateral.stl", "back_panel.stl"}) {
    text = replace_all(text, std::string("mesh: ") + mesh,
                       "mesh: " + data_path(std::string("cabinet/") + mesh));
  }
  return text;
}

std::string write_product(const std::string& dir, const std::string& text) {
  return write_file(dir, "product.yaml", text);
}

const std::vector<std::string> kNames = {
    "base", "lateral_right", "back_lower", "shelf_middle", "lateral_left", "top", "back_upper"};

// All boards at their targets as moving mesh bodies, plus the cell's table as a static box.
struct AssemblyScene {
  CollisionModel model;
  std::vector<int> boards;
  int table = -1;
};

AssemblyScene build_assembly(const ProductSpec& product) {
  AssemblyScene scene;
  for (const PartSpec& part : product.parts) {
    scene.boards.push_back(
        scene.model.add_mesh_body(part.name, part.mesh, false, product.target_in_world(part)));
  }
  const auto cell = reference_cell();
  for (const BoxObstacle& o : cell->spec().obstacles) {
    if (o.name != "table") continue;
    GeometrySpec box;
    box.type = GeometrySpec::Type::Box;
    box.box_size = o.size;
    scene.table = scene.model.add_body("table", {box}, true, o.pose);
  }
  return scene;
}

}  // namespace

TEST(Product, CabinetLoads) {
  const ProductSpec& p = cabinet();
  EXPECT_EQ(p.name, "cabinet");
  EXPECT_EQ(p.file, product_path());
  ASSERT_EQ(p.parts.size(), 7u);
  for (std::size_t i = 0; i < p.parts.size(); ++i) {
    EXPECT_EQ(p.parts[i].order, static_cast<int>(i) + 1);
    EXPECT_EQ(p.parts[i].name, kNames[i]);
    EXPECT_DOUBLE_EQ(p.parts[i].unit_scale, 0.001);
    EXPECT_TRUE(is_valid_pose(p.parts[i].target)) << p.parts[i].name;
    EXPECT_TRUE(is_valid_pose(p.parts[i].initial)) << p.parts[i].name;
    EXPECT_FALSE(p.parts[i].mesh.triangles.empty());
  }
  EXPECT_DOUBLE_EQ(p.part("base").mass, 0.8);
  EXPECT_DOUBLE_EQ(p.part("shelf_middle").mass, 0.8);
  EXPECT_DOUBLE_EQ(p.part("top").mass, 0.8);
  EXPECT_DOUBLE_EQ(p.part("lateral_right").mass, 1.8);
  EXPECT_DOUBLE_EQ(p.part("lateral_left").mass, 1.8);
  EXPECT_DOUBLE_EQ(p.part("back_lower").mass, 0.22);
  EXPECT_DOUBLE_EQ(p.part("back_upper").mass, 0.22);
  expect_input_error([&] { p.part("door"); }, {product_path(), "part", "'door'"});

  EXPECT_LT((p.assembly_frame.translation() - Eigen::Vector3d(0.62, 0.0, 1.094)).norm(), 1e-12);
  EXPECT_EQ(p.part("lateral_right").mesh_file, data_path("cabinet/lateral.stl"));
  // target_in_world composes the assembly frame.
  const PartSpec& top = p.part("top");
  EXPECT_LT(
      (p.target_in_world(top).translation() - (p.assembly_frame * top.target.translation())).norm(),
      1e-12);
}

TEST(Product, MeshExtentsInMetres) {
  const ProductSpec& p = cabinet();
  for (const char* name : {"lateral_right", "lateral_left"}) {
    const TriangleMesh& mesh = p.part(name).mesh;
    const Eigen::Vector3d extent = mesh.max_corner() - mesh.min_corner();
    EXPECT_NEAR(extent.x(), 0.587, 1e-9) << name;
    EXPECT_NEAR(extent.y(), 0.295, 1e-9) << name;
    EXPECT_NEAR(extent.z(), 0.010, 1e-9) << name;
    // Centred at the mass centre.
    EXPECT_LT((mesh.max_corner() + mesh.min_corner()).norm(), 1e-9) << name;
  }
  for (const PartSpec& part : p.parts) {
    const Eigen::Vector3d extent = part.mesh.max_corner() - part.mesh.min_corner();
    EXPECT_GT(extent.minCoeff(), 0.002) << part.name;  // back panels are 3 mm, boards 10 mm
    EXPECT_LT(extent.maxCoeff(), 0.7) << part.name;    // and well below a metre long
  }
  // Same mesh file, same geometry.
  EXPECT_EQ(p.part("base").mesh.vertices, p.part("top").mesh.vertices);
}

TEST(Product, AssembledBoardsAreCollisionFree) {
  const ProductSpec& p = cabinet();
  AssemblyScene scene = build_assembly(p);
  ASSERT_GE(scene.table, 0) << "the reference cell has no table";
  CollisionData data(scene.model);
  CollisionPair pair;
  EXPECT_FALSE(in_collision(scene.model, data, &pair)) << describe_pair(scene.model, pair);
  EXPECT_FALSE(in_collision_brute_force(scene.model, data, &pair))
      << describe_pair(scene.model, pair);
  // The boards keep (about) 1 mm gaps: nothing touches.
  const double gap = min_distance(scene.model, data, &pair);
  EXPECT_GT(gap, 0.0005) << describe_pair(scene.model, pair);
  EXPECT_LT(gap, 0.01) << "boards are supposed to be assembled, not scattered";

  // Every board is above the table top and not floating far above it.
  const Pose& table_pose = scene.model.initial_pose(scene.table);
  const double table_top = table_pose.translation().z() + 0.5 * 0.024;
  EXPECT_NEAR(table_top, 1.094, 1e-9);
  for (const PartSpec& part : p.parts) {
    double lowest = 1e9;
    const Pose world = p.target_in_world(part);
    for (const auto& v : part.mesh.vertices) lowest = std::min(lowest, (world * v).z());
    EXPECT_GT(lowest, table_top) << part.name;
    EXPECT_LT(lowest, table_top + 0.6) << part.name;
  }
}

TEST(Product, BoardMovedIntoNeighbourCollides) {
  const ProductSpec& p = cabinet();
  AssemblyScene scene = build_assembly(p);
  CollisionData data(scene.model);
  ASSERT_FALSE(in_collision(scene.model, data));

  // Move the right lateral 5 mm toward the cabinet's centre (-y): into the shelves' ends.
  const int lateral = *scene.model.find_body("lateral_right");
  Pose moved = p.target_in_world(p.part("lateral_right"));
  moved.translation() += p.assembly_frame.linear() * Eigen::Vector3d(0, -0.005, 0);
  data.set_body_pose(lateral, moved);
  CollisionPair pair;
  EXPECT_TRUE(in_collision(scene.model, data, &pair));
  EXPECT_TRUE(pair.body_a == lateral || pair.body_b == lateral) << describe_pair(scene.model, pair);
  EXPECT_TRUE(in_collision_brute_force(scene.model, data));

  // Back to the target: free again.
  data.set_body_pose(lateral, p.target_in_world(p.part("lateral_right")));
  EXPECT_FALSE(in_collision(scene.model, data));

  // The base lowered by 5 mm penetrates the table.
  const int base = *scene.model.find_body("base");
  Pose lowered = p.target_in_world(p.part("base"));
  lowered.translation().z() -= 0.005;
  data.set_body_pose(base, lowered);
  EXPECT_TRUE(in_collision(scene.model, data, &pair));
  EXPECT_EQ(std::min(pair.body_a, pair.body_b), std::min(base, scene.table))
      << describe_pair(scene.model, pair);
  EXPECT_EQ(std::max(pair.body_a, pair.body_b), std::max(base, scene.table))
      << describe_pair(scene.model, pair);
}

TEST(Product, CopiedProductLoadsFromTempDir) {
  // The control for the bad-input tests below: the unmodified copy loads.
  const std::string path = write_product(temp_dir("product_copy"), product_text());
  const ProductSpec p = load_product(path);
  EXPECT_EQ(p.file, path);
  EXPECT_EQ(p.parts.size(), 7u);
}

TEST(Product, MillimetreMeshDeclaredAsMetres) {
  const std::string text = replace_once(product_text(), "mesh_unit: mm", "mesh_unit: m");
  const std::string path = write_product(temp_dir("product_mm_as_m"), text);
  expect_input_error([&] { load_product(path); }, {path, "parts[0].mesh_unit", "mm"});
}

TEST(Product, MetreMeshDeclaredAsMillimetres) {
  // A 0.4 x 0.3 x 0.01 box written in metres but declared mm: 0.4 mm across.
  const std::string dir = temp_dir("product_m_as_mm");
  write_mesh(make_box_mesh(Eigen::Vector3d(0.4, 0.3, 0.01)), dir + "/board_m.stl", "stlb");
  const std::string text =
      replace_once(product_text(), "mesh: " + data_path("cabinet/shelf.stl"), "mesh: board_m.stl");
  const std::string path = write_product(dir, text);
  expect_input_error([&] { load_product(path); }, {path, "parts[0].mesh_unit", "5 mm"});
}

TEST(Product, BadMass) {
  struct Case {
    std::string value, fragment;
  };
  // A part's mass is in [1 g, 25 kg]: the 1e-300 and 100 are refused.
  const std::string range = "a mass in kilograms in [0.001, 25]";
  const std::vector<Case> cases = {{"0", range},         {"-1", range},     {".nan", "finite"},
                                   {"nan", "finite"},    {"800", range},    {"100", range},
                                   {"25.01", range},     {"1e-300", range}, {"0.0009", range},
                                   {"heavy", "a number"}};
  for (std::size_t i = 0; i < cases.size(); ++i) {
    SCOPED_TRACE("mass: " + cases[i].value);
    const std::string text = replace_once(product_text(), "mass: 1.8", "mass: " + cases[i].value);
    const std::string path = write_product(temp_dir("product_mass_" + std::to_string(i)), text);
    // lateral_right is the second part in the file.
    expect_input_error([&] { load_product(path); }, {path, "parts[1].mass", cases[i].fragment});
  }
  for (const char* bound : {"0.001", "25"}) {
    const std::string text =
        replace_once(product_text(), "mass: 1.8", std::string("mass: ") + bound);
    EXPECT_NO_THROW(load_product(write_product(temp_dir("product_mass_bound"), text))) << bound;
  }
}

TEST(Product, UnknownMeshUnit) {
  const std::string text = replace_once(product_text(), "mesh_unit: mm", "mesh_unit: furlong");
  const std::string path = write_product(temp_dir("product_furlong"), text);
  expect_input_error([&] { load_product(path); },
                     {path, "parts[0].mesh_unit", "'furlong'", "m, cm, mm, in"});
}

TEST(Product, OtherMeshUnitsScale) {
  EXPECT_DOUBLE_EQ(unit_scale_from_name("m", "f", "x"), 1.0);
  EXPECT_DOUBLE_EQ(unit_scale_from_name("cm", "f", "x"), 0.01);
  EXPECT_DOUBLE_EQ(unit_scale_from_name("mm", "f", "x"), 0.001);
  EXPECT_DOUBLE_EQ(unit_scale_from_name("in", "f", "x"), 0.0254);
  expect_input_error([] { unit_scale_from_name("MM", "p.yaml", "parts[2].mesh_unit"); },
                     {"p.yaml", "parts[2].mesh_unit", "'MM'"});
}

TEST(Product, MissingMeshFile) {
  const std::string dir = temp_dir("product_missing_mesh");
  const std::string text = replace_once(product_text(), "mesh: " + data_path("cabinet/lateral.stl"),
                                        "mesh: no_such_board.stl");
  const std::string path = write_product(dir, text);
  expect_input_error([&] { load_product(path); },
                     {dir + "/no_such_board.stl", "no such file", path, "parts[1].mesh"});
}

TEST(Product, EmptyMesh) {
  const std::string dir = temp_dir("product_empty_mesh");
  write_file(dir, "points.obj", "v 0 0 0\nv 100 0 0\nv 0 100 0\n");
  const std::string text =
      replace_once(product_text(), "mesh: " + data_path("cabinet/lateral.stl"), "mesh: points.obj");
  const std::string path = write_product(dir, text);
  expect_input_error([&] { load_product(path); }, {dir + "/points.obj", path, "parts[1].mesh"});
}

TEST(Product, DuplicateOrder) {
  const std::string text = replace_once(product_text(), "order: 2", "order: 1");
  const std::string path = write_product(temp_dir("product_dup_order"), text);
  expect_input_error([&] { load_product(path); }, {path, "parts[1].order", "unique"});
}

TEST(Product, OrdersNotOneToN) {
  const std::string text = replace_once(product_text(), "order: 7", "order: 8");
  const std::string path = write_product(temp_dir("product_gap"), text);
  expect_input_error([&] { load_product(path); }, {path, "parts", "orders 1..7", "order 8"});

  const std::string text0 = replace_once(product_text(), "order: 1", "order: 0");
  const std::string path0 = write_product(temp_dir("product_zero"), text0);
  expect_input_error([&] { load_product(path0); }, {path0, "parts", "orders 1..7", "order 0"});
}

TEST(Product, NanInTargetPose) {
  const std::string text = replace_once(product_text(), "target: {xyz: [0.0035, 0.0, 0.006]",
                                        "target: {xyz: [0.0035, .nan, 0.006]");
  const std::string path = write_product(temp_dir("product_nan_target"), text);
  expect_input_error([&] { load_product(path); }, {path, "parts[0].target.xyz[1]", "finite"});
}

TEST(Product, NonOrthonormalTargetRotation) {
  const std::string text =
      replace_once(product_text(), "rotation: [[0, 1, 0], [0, 0, 1], [1, 0, 0]]",
                   "rotation: [[0, 1, 0], [0, 0, 1], [1, 0, 0.2]]");
  const std::string path = write_product(temp_dir("product_bad_rotation"), text);
  expect_input_error([&] { load_product(path); },
                     {path, "parts[1].target.rotation", "orthonormal"});
}

TEST(Product, DuplicatePartName) {
  const std::string text = replace_once(product_text(), "name: top", "name: base");
  const std::string path = write_product(temp_dir("product_dup_name"), text);
  expect_input_error([&] { load_product(path); }, {path, "parts[5].name", "unique"});
}

// A part name labels tables, messages and database rows: empty or multi-line names are refused
// when the product is read, not by the build after minutes of work.
TEST(Product, EmptyOrMultiLinePartName) {
  const std::string empty = write_product(temp_dir("product_empty_name"),
                                          replace_once(product_text(), "name: top", "name: ''"));
  expect_input_error([&] { load_product(empty); },
                     {empty, "parts[5].name", "expected a non-empty part name, got ''"});
  const std::string newline =
      write_product(temp_dir("product_newline_name"),
                    replace_once(product_text(), "name: top", "name: \"to\\np\\t\""));
  expect_input_error([&] { load_product(newline); },
                     {newline, "parts[5].name", "without control characters, got 'to\\np\\t'"});
}

TEST(Product, ADirectoryIsNotAProductFile) {
  const std::string dir = temp_dir("product_directory");
  expect_input_error([&] { load_product(dir); }, {dir, "expected a YAML file, got a directory"});
}

TEST(Product, UnknownPartField) {
  const std::string text = replace_once(product_text(), "mass: 0.22", "masss: 0.22");
  const std::string path = write_product(temp_dir("product_typo"), text);
  expect_input_error([&] { load_product(path); }, {path, "parts[2].masss", "unknown field"});
}
