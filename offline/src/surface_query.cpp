#include "hila/offline/surface_query.hpp"

#include <CGAL/AABB_face_graph_triangle_primitive.h>
#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/Side_of_triangle_mesh.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "cgal_types.hpp"

namespace hila::offline {
namespace {

using detail::Kernel;
using detail::Point3;
using detail::SurfaceMesh;
using detail::to_eigen;
using detail::to_point;
using Primitive = CGAL::AABB_face_graph_triangle_primitive<SurfaceMesh>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;
using SideOfMesh = CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel>;

// A triangle soup: every triangle gets its own three vertices, so face i is triangle i whatever
// the input's connectivity. Ray shooting and the inside test need triangles, not adjacency.
SurfaceMesh triangle_soup(const core::TriangleMesh& mesh) {
  SurfaceMesh soup;
  soup.reserve(static_cast<SurfaceMesh::size_type>(3 * mesh.triangles.size()),
               static_cast<SurfaceMesh::size_type>(3 * mesh.triangles.size()),
               static_cast<SurfaceMesh::size_type>(mesh.triangles.size()));
  for (const auto& t : mesh.triangles) {
    const auto a = soup.add_vertex(to_point(mesh.vertices[t[0]]));
    const auto b = soup.add_vertex(to_point(mesh.vertices[t[1]]));
    const auto c = soup.add_vertex(to_point(mesh.vertices[t[2]]));
    soup.add_face(a, b, c);  // three distinct fresh vertices: never refused
  }
  return soup;
}

// Uniform double in [0, 1) from the top 53 bits: the same numbers with every standard library
// (std::uniform_real_distribution is implementation-defined).
double unit_random(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

}  // namespace

struct SurfaceQuery::Impl {
  core::TriangleMesh mesh;
  std::vector<Eigen::Vector3d> normals;  // from the winding; outward for an outward mesh
  std::vector<double> cumulative_area;   // prefix sums, for area-weighted sampling
  SurfaceMesh soup;
  Tree tree;
  std::optional<SideOfMesh> side;  // unset for an empty mesh

  explicit Impl(const core::TriangleMesh& input) : mesh(input) {
    const int vertex_count = static_cast<int>(mesh.vertices.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      if (!mesh.vertices[i].allFinite()) {
        throw std::invalid_argument("SurfaceQuery: vertex " + std::to_string(i) + " is not finite");
      }
    }
    double total = 0.0;
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      for (const int v : t) {
        if (v < 0 || v >= vertex_count) {
          throw std::invalid_argument("SurfaceQuery: triangle " + std::to_string(i) +
                                      " has vertex index " + std::to_string(v) + " out of range");
        }
      }
      const Eigen::Vector3d cross = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                        .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]]);
      const double norm = cross.norm();
      normals.push_back(norm > 0.0 ? Eigen::Vector3d(cross / norm) : Eigen::Vector3d::Zero());
      total += 0.5 * norm;
      cumulative_area.push_back(total);
    }
    soup = triangle_soup(mesh);
    if (!mesh.triangles.empty()) {
      // Built eagerly so that every later query only reads the tree (thread safety).
      tree.insert(faces(soup).first, faces(soup).second, soup);
      tree.build();
      side.emplace(tree);
    }
  }
};

SurfaceQuery::SurfaceQuery(const core::TriangleMesh& mesh) : impl_(std::make_unique<Impl>(mesh)) {}
SurfaceQuery::~SurfaceQuery() = default;
SurfaceQuery::SurfaceQuery(SurfaceQuery&&) noexcept = default;
SurfaceQuery& SurfaceQuery::operator=(SurfaceQuery&&) noexcept = default;

std::optional<SurfacePoint> SurfaceQuery::first_hit(const Eigen::Vector3d& origin,
                                                    const Eigen::Vector3d& direction,
                                                    double min_distance) const {
  if (!impl_ || !impl_->side || !origin.allFinite() || !direction.allFinite() ||
      direction.squaredNorm() == 0.0 || !std::isfinite(min_distance)) {
    return std::nullopt;
  }
  const Eigen::Vector3d start = origin + min_distance * direction;
  const Point3 source = to_point(start);
  const Kernel::Ray_3 ray(source, Kernel::Vector_3(direction.x(), direction.y(), direction.z()));
  // Hits at t == min_distance exactly (the start lies on the triangle, decided by an exact
  // predicate) do not count: skip those triangles and shoot again.
  std::vector<SurfaceMesh::Face_index> skipped;
  const auto skip = [&](SurfaceMesh::Face_index f) {
    return std::find(skipped.begin(), skipped.end(), f) != skipped.end();
  };
  for (int attempt = 0; attempt < 64; ++attempt) {
    const auto hit = impl_->tree.first_intersection(ray, skip);
    if (!hit) return std::nullopt;
    const SurfaceMesh::Face_index face = hit->second;
    const auto& soup = impl_->soup;
    const auto h = soup.halfedge(face);
    const Kernel::Triangle_3 triangle(soup.point(soup.source(h)), soup.point(soup.target(h)),
                                      soup.point(soup.target(soup.next(h))));
    if (triangle.has_on(source)) {
      skipped.push_back(face);
      continue;
    }
    Eigen::Vector3d point;
    if (const Point3* p = boost::get<Point3>(&hit->first)) {
      point = to_eigen(*p);
    } else if (const Kernel::Segment_3* s = boost::get<Kernel::Segment_3>(&hit->first)) {
      // The ray runs inside the triangle's plane: the entry point is the nearer end.
      const Eigen::Vector3d a = to_eigen(s->source());
      const Eigen::Vector3d b = to_eigen(s->target());
      point = (a - start).squaredNorm() <= (b - start).squaredNorm() ? a : b;
    } else {
      return std::nullopt;
    }
    SurfacePoint out;
    out.point = point;
    out.triangle = static_cast<int>(static_cast<std::size_t>(face));
    out.normal = impl_->normals[static_cast<std::size_t>(out.triangle)];
    return out;
  }
  return std::nullopt;
}

std::vector<SurfacePoint> SurfaceQuery::sample_uniform(int count, std::uint64_t seed) const {
  std::vector<SurfacePoint> out;
  if (!impl_ || count <= 0 || impl_->cumulative_area.empty() ||
      !(impl_->cumulative_area.back() > 0.0)) {
    return out;
  }
  const auto& cumulative = impl_->cumulative_area;
  const double total = cumulative.back();
  std::mt19937_64 rng(seed);
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    // First triangle whose prefix sum exceeds the draw; zero-area triangles are never picked.
    const double draw = unit_random(rng) * total;
    auto it = std::upper_bound(cumulative.begin(), cumulative.end(), draw);
    if (it == cumulative.end()) --it;
    const auto triangle = static_cast<std::size_t>(it - cumulative.begin());
    double r1 = unit_random(rng);
    double r2 = unit_random(rng);
    if (r1 + r2 > 1.0) {  // fold the square's upper half onto the triangle
      r1 = 1.0 - r1;
      r2 = 1.0 - r2;
    }
    const auto& t = impl_->mesh.triangles[triangle];
    const Eigen::Vector3d& a = impl_->mesh.vertices[t[0]];
    const Eigen::Vector3d& b = impl_->mesh.vertices[t[1]];
    const Eigen::Vector3d& c = impl_->mesh.vertices[t[2]];
    SurfacePoint sample;
    sample.point = a + r1 * (b - a) + r2 * (c - a);
    sample.normal = impl_->normals[triangle];
    sample.triangle = static_cast<int>(triangle);
    out.push_back(sample);
  }
  return out;
}

bool SurfaceQuery::inside(const Eigen::Vector3d& point) const {
  if (!impl_ || !impl_->side || !point.allFinite()) return false;
  return (*impl_->side)(to_point(point)) == CGAL::ON_BOUNDED_SIDE;
}

}  // namespace hila::offline
