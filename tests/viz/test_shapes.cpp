#include <gtest/gtest.h>

#include <map>

#include "shapes.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

// Every edge in exactly two triangles, once each way (closed, consistently oriented), and the
// enclosed volume (positive: faces point outwards).
double closed_volume(const core::TriangleMesh& mesh) {
  std::map<std::pair<int, int>, int> edges;
  double volume = 0.0;
  for (const auto& t : mesh.triangles) {
    for (int k = 0; k < 3; ++k) ++edges[{t[k], t[(k + 1) % 3]}];
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
  }
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1) << edge.first << "-" << edge.second;
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u) << edge.first << "-" << edge.second;
  }
  return volume;
}

TEST(Shapes, CylinderOnItsSurfaceClosedOutward) {
  const core::TriangleMesh c = viz::make_cylinder_mesh(0.05, 0.2, 32);
  for (const Eigen::Vector3d& v : c.vertices) {
    EXPECT_NEAR(std::abs(v.z()), 0.1, 1e-15);
    EXPECT_TRUE(std::abs(v.head<2>().norm() - 0.05) < 1e-15 || v.head<2>().norm() == 0.0);
  }
  const double volume = closed_volume(c);
  const double exact = core::kPi * 0.05 * 0.05 * 0.2;
  EXPECT_GT(volume, 0.98 * exact);
  EXPECT_LT(volume, exact);
}

TEST(Shapes, SphereOnItsSurfaceClosedOutward) {
  const core::TriangleMesh s = viz::make_sphere_mesh(0.1, 24);
  for (const Eigen::Vector3d& v : s.vertices) EXPECT_NEAR(v.norm(), 0.1, 1e-15);
  const double volume = closed_volume(s);
  const double exact = 4.0 / 3.0 * core::kPi * 1e-3;
  EXPECT_GT(volume, 0.95 * exact);
  EXPECT_LT(volume, exact);
}

TEST(Shapes, GeometryAtItsOrigin) {
  core::GeometrySpec g;
  g.type = core::GeometrySpec::Type::Box;
  g.box_size = Eigen::Vector3d(0.2, 0.4, 0.6);
  g.origin = core::make_pose(Eigen::Vector3d(1, 2, 3));
  const core::TriangleMesh m = viz::geometry_mesh(g);
  EXPECT_NEAR((m.min_corner() - Eigen::Vector3d(0.9, 1.8, 2.7)).norm(), 0.0, 1e-15);
  EXPECT_NEAR((m.max_corner() - Eigen::Vector3d(1.1, 2.2, 3.3)).norm(), 0.0, 1e-15);
  g.type = core::GeometrySpec::Type::Mesh;
  g.mesh_path = data_path("cabinet/shelf.stl");
  g.mesh_scale = Eigen::Vector3d(0.001, 0.002, 0.001);
  g.origin = core::Pose::Identity();
  const core::TriangleMesh shelf = viz::geometry_mesh(g);
  const core::TriangleMesh file = core::load_mesh(g.mesh_path, 1.0);
  ASSERT_EQ(shelf.vertices.size(), file.vertices.size());
  EXPECT_NEAR(shelf.vertices[3].y(), 0.002 * file.vertices[3].y(), 1e-15);
  g.mesh_path = data_path("cabinet/none.stl");
  expect_input_error([&] { viz::geometry_mesh(g); }, {"none.stl"});
}

}  // namespace
}  // namespace hila::test
