#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "hila/core/mesh.hpp"
#include "hila/core/mesh_symmetry.hpp"
#include "hila/core/pose.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

Eigen::Matrix3d turn(double deg, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(core::deg_to_rad(deg), axis.normalized()).toRotationMatrix();
}

// Every rotation found maps every vertex onto a vertex (checked by brute force, no grid).
void expect_maps_onto_itself(const core::TriangleMesh& mesh,
                             const std::vector<Eigen::Matrix3d>& rotations) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& v : mesh.vertices) c += v;
  c /= static_cast<double>(mesh.vertices.size());
  for (const auto& r : rotations) {
    EXPECT_NEAR(r.determinant(), 1.0, 1e-9);
    for (const auto& v : mesh.vertices) {
      const Eigen::Vector3d w = c + r * (v - c);
      double nearest = 1e9;
      for (const auto& u : mesh.vertices) nearest = std::min(nearest, (u - w).norm());
      EXPECT_LT(nearest, core::kSymmetryTolerance);
    }
  }
}

}  // namespace

// A cabinet board (a box with three different sides, off the origin and turned in its frame):
// the identity and the three half turns about its axes. Handed over turned by a half turn about
// any of them, it needs no re-orientation; a turn of 170 degrees about its normal needs 10.
TEST(MeshSymmetry, ABoxIsTheSameAfterAHalfTurnAboutEachAxis) {
  core::TriangleMesh box = core::make_box_mesh(Eigen::Vector3d(0.39, 0.288, 0.01));
  const Eigen::Matrix3d frame = turn(30.0, Eigen::Vector3d(1, 2, 3));
  for (auto& v : box.vertices) v = frame * v + Eigen::Vector3d(0.1, -0.2, 0.05);
  const auto symmetries = core::mesh_symmetries(box);
  ASSERT_EQ(symmetries.size(), 4u);
  EXPECT_TRUE(symmetries.front().isIdentity());
  expect_maps_onto_itself(box, symmetries);
  const Eigen::Matrix3d target = turn(20.0, Eigen::Vector3d(0, 0, 1));
  for (int axis = 0; axis < 3; ++axis) {
    // A half turn about the board's own axis (the frame's column): world orientation target R.
    const Eigen::Matrix3d half = turn(180.0, frame.col(axis));
    EXPECT_NEAR(core::least_rotation_angle_deg(target * half, target, {}), 180.0, 1e-6);
    EXPECT_NEAR(core::least_rotation_angle_deg(target * half, target, symmetries), 0.0, 1e-6);
  }
  const Eigen::Matrix3d almost = turn(170.0, frame.col(2));
  EXPECT_NEAR(core::least_rotation_angle_deg(target * almost, target, symmetries), 10.0, 1e-6);
  // A quarter turn about the normal is not a symmetry of a board longer than wide.
  const Eigen::Matrix3d quarter = turn(90.0, frame.col(2));
  EXPECT_NEAR(core::least_rotation_angle_deg(target * quarter, target, symmetries), 90.0, 1e-6);
}

// A square plate: the quarter turns about its normal as well.
TEST(MeshSymmetry, ASquarePlateIsTheSameAfterAQuarterTurn) {
  const core::TriangleMesh plate = core::make_box_mesh(Eigen::Vector3d(0.3, 0.3, 0.01));
  const auto symmetries = core::mesh_symmetries(plate);
  expect_maps_onto_itself(plate, symmetries);
  EXPECT_GE(symmetries.size(), 4u);
  EXPECT_NEAR(core::least_rotation_angle_deg(turn(90.0, Eigen::Vector3d::UnitZ()),
                                             Eigen::Matrix3d::Identity(), symmetries),
              0.0, 1e-6);
}

// A part without symmetry (a box with a notch cut off one corner: an extra vertex, its corner
// moved in): only the identity, and every re-orientation keeps its full angle.
TEST(MeshSymmetry, AnAsymmetricPartKeepsItsFullReorientation) {
  core::TriangleMesh part = core::make_box_mesh(Eigen::Vector3d(0.39, 0.288, 0.01));
  ASSERT_EQ(part.vertices.size(), 8u);
  part.vertices[0] += Eigen::Vector3d(0.03, 0.02, 0.0);  // one corner moved in
  const auto symmetries = core::mesh_symmetries(part);
  ASSERT_EQ(symmetries.size(), 1u);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Matrix3d a = test::random_pose(rng).linear();
    const Eigen::Matrix3d b = test::random_pose(rng).linear();
    EXPECT_NEAR(core::least_rotation_angle_deg(a, b, symmetries),
                core::rad_to_deg(Eigen::AngleAxisd(a.transpose() * b).angle()), 1e-9);
  }
  EXPECT_NEAR(core::least_rotation_angle_deg(turn(180.0, Eigen::Vector3d::UnitZ()),
                                             Eigen::Matrix3d::Identity(), symmetries),
              180.0, 1e-6);
}

// The cabinet's board meshes: boxes, each with its four rotations.
TEST(MeshSymmetry, TheCabinetsBoardsAreBoxes) {
  for (const char* name : {"cabinet/shelf.stl", "cabinet/lateral.stl", "cabinet/back_panel.stl"}) {
    const auto mesh = core::load_mesh(test::data_path(name), 0.001);
    EXPECT_EQ(core::mesh_symmetries(mesh).size(), 4u) << name;
  }
}
