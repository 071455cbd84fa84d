#include "shapes.hpp"

#include <algorithm>
#include <map>
#include <mutex>

#include "hila/core/pose.hpp"

namespace hila::viz {

core::TriangleMesh make_cylinder_mesh(double radius, double length, int segments) {
  segments = std::max(segments, 3);
  core::TriangleMesh mesh;
  const double h = 0.5 * length;
  for (int i = 0; i < segments; ++i) {
    const double a = 2.0 * core::kPi * i / segments;
    const double x = radius * std::cos(a);
    const double y = radius * std::sin(a);
    mesh.vertices.emplace_back(x, y, -h);
    mesh.vertices.emplace_back(x, y, h);
  }
  const int bottom = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, -h);
  mesh.vertices.emplace_back(0.0, 0.0, h);
  const int top = bottom + 1;
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    const int b0 = 2 * i, t0 = 2 * i + 1, b1 = 2 * j, t1 = 2 * j + 1;
    // Counter-clockwise seen from outside.
    mesh.triangles.push_back({b0, b1, t1});
    mesh.triangles.push_back({b0, t1, t0});
    mesh.triangles.push_back({bottom, b1, b0});
    mesh.triangles.push_back({top, t0, t1});
  }
  return mesh;
}

core::TriangleMesh make_sphere_mesh(double radius, int segments) {
  segments = std::max(segments, 3);
  const int rings = std::max(segments / 2, 2);
  core::TriangleMesh mesh;
  mesh.vertices.emplace_back(0.0, 0.0, -radius);  // south pole
  for (int r = 1; r < rings; ++r) {
    const double polar = core::kPi * r / rings;  // from the south pole
    for (int i = 0; i < segments; ++i) {
      const double a = 2.0 * core::kPi * i / segments;
      mesh.vertices.emplace_back(radius * std::sin(polar) * std::cos(a),
                                 radius * std::sin(polar) * std::sin(a), -radius * std::cos(polar));
    }
  }
  const int north = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, radius);
  auto ring_vertex = [segments](int r, int i) { return 1 + (r - 1) * segments + i % segments; };
  for (int i = 0; i < segments; ++i) {
    mesh.triangles.push_back({0, ring_vertex(1, i + 1), ring_vertex(1, i)});
    mesh.triangles.push_back({north, ring_vertex(rings - 1, i), ring_vertex(rings - 1, i + 1)});
    for (int r = 1; r + 1 < rings; ++r) {
      mesh.triangles.push_back(
          {ring_vertex(r, i), ring_vertex(r, i + 1), ring_vertex(r + 1, i + 1)});
      mesh.triangles.push_back(
          {ring_vertex(r, i), ring_vertex(r + 1, i + 1), ring_vertex(r + 1, i)});
    }
  }
  return mesh;
}

core::TriangleMesh transformed(core::TriangleMesh mesh, const core::Pose& pose) {
  for (Eigen::Vector3d& v : mesh.vertices) v = pose * v;
  return mesh;
}

core::TriangleMesh geometry_mesh(const core::GeometrySpec& geometry) {
  core::TriangleMesh mesh;
  switch (geometry.type) {
    case core::GeometrySpec::Type::Box:
      mesh = core::make_box_mesh(geometry.box_size);
      break;
    case core::GeometrySpec::Type::Cylinder:
      mesh = make_cylinder_mesh(geometry.radius, geometry.length);
      break;
    case core::GeometrySpec::Type::Sphere:
      mesh = make_sphere_mesh(geometry.radius);
      break;
    case core::GeometrySpec::Type::Mesh: {
      // A URDF names the same file for many links (and both arms): read each once.
      static std::mutex cache_mutex;
      static std::map<std::string, core::TriangleMesh> cache;
      std::lock_guard lock(cache_mutex);
      auto it = cache.find(geometry.mesh_path);
      if (it == cache.end()) {
        it = cache.emplace(geometry.mesh_path, core::load_mesh(geometry.mesh_path, 1.0)).first;
      }
      mesh = it->second;
      for (Eigen::Vector3d& v : mesh.vertices) v = v.cwiseProduct(geometry.mesh_scale);
      break;
    }
  }
  return transformed(std::move(mesh), geometry.origin);
}

}  // namespace hila::viz
