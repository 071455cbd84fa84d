#include "hila/offline/part_analysis.hpp"

#include <CGAL/Polygon_mesh_processing/manifoldness.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/convex_hull_3.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <numeric>
#include <set>
#include <tuple>
#include <utility>

#include "cgal_types.hpp"
#include "hila/core/error.hpp"

namespace hila::offline {
namespace {

namespace PMP = CGAL::Polygon_mesh_processing;
using detail::Point3;
using detail::SurfaceMesh;
using detail::to_eigen;
using detail::to_point;

// Coplanarity for facets: normals within 1e-3 rad of the seed triangle's and every vertex within
// 1 um of the seed's plane (STL files store floats; 1 um is far above their rounding at part
// scale and far below any real step in a part).
constexpr double kFacetAngleTolerance = 1e-3;  // rad
constexpr double kFacetPlaneTolerance = 1e-6;  // m
// A support facet whose CoM projection is closer than this to its edge is not a stable placement.
constexpr double kMinStability = 1e-6;  // m
// Slack for "is the point inside this triangle" so points on shared internal edges are inside.
constexpr double kInsideTolerance = 1e-12;  // m

[[noreturn]] void mesh_error(const std::string& part, const std::string& expected,
                             const std::string& got) {
  throw core::InputError(part, "mesh", expected, got);
}

std::string count_text(std::size_t count, const std::string& singular, const std::string& plural) {
  return std::to_string(count) + " " + (count == 1 ? singular : plural);
}

// --- Input checks ------------------------------------------------------------------------------

void check_indices_and_coordinates(const std::string& part, const core::TriangleMesh& mesh) {
  if (mesh.triangles.empty()) mesh_error(part, "at least one triangle", "an empty mesh");
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!mesh.vertices[i].allFinite()) {
      mesh_error(part, "finite vertex coordinates",
                 "NaN or infinite values at vertex " + std::to_string(i));
    }
  }
  const int vertex_count = static_cast<int>(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    for (const int v : mesh.triangles[i]) {
      if (v < 0 || v >= vertex_count) {
        mesh_error(part, "vertex indices in [0, " + std::to_string(vertex_count) + ")",
                   std::to_string(v) + " in triangle " + std::to_string(i));
      }
    }
  }
}

// Same exact predicate as PMP::is_degenerate_triangle_face, but on the raw triangles: it also
// catches triangles that repeat a vertex index, which a Surface_mesh cannot even hold.
void check_degenerate_faces(const std::string& part, const core::TriangleMesh& mesh) {
  std::size_t count = 0;
  int first = -1;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    if (CGAL::collinear(to_point(mesh.vertices[t[0]]), to_point(mesh.vertices[t[1]]),
                        to_point(mesh.vertices[t[2]]))) {
      if (first < 0) first = static_cast<int>(i);
      ++count;
    }
  }
  if (count > 0) {
    mesh_error(part, "no degenerate (zero-area) faces",
               count_text(count, "degenerate face", "degenerate faces") + " (first: triangle " +
                   std::to_string(first) + ")");
  }
}

// Face i of the result is triangle i (the input is all-or-nothing). Only vertices used by a
// triangle are added (an isolated vertex is harmless in the input but not a valid polygon mesh);
// `mesh_vertex` maps the Surface_mesh's vertex indices back to the input's.
SurfaceMesh build_surface_mesh(const std::string& part, const core::TriangleMesh& mesh,
                               std::vector<int>& mesh_vertex) {
  SurfaceMesh sm;
  sm.reserve(static_cast<SurfaceMesh::size_type>(mesh.vertices.size()),
             static_cast<SurfaceMesh::size_type>(3 * mesh.triangles.size() / 2),
             static_cast<SurfaceMesh::size_type>(mesh.triangles.size()));
  std::vector<SurfaceMesh::Vertex_index> vertices(mesh.vertices.size(), SurfaceMesh::null_vertex());
  mesh_vertex.clear();
  for (const auto& t : mesh.triangles) {
    for (const int v : t) {
      if (vertices[v] == SurfaceMesh::null_vertex()) {
        vertices[v] = sm.add_vertex(to_point(mesh.vertices[v]));
        mesh_vertex.push_back(v);
      }
    }
  }
  // add_face refuses a face that would put a third face on an edge, run an edge twice in the
  // same direction (inconsistent orientation) or close a fan around an already closed vertex.
  std::size_t rejected = 0;
  int first = -1;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    if (sm.add_face(vertices[t[0]], vertices[t[1]], vertices[t[2]]) == SurfaceMesh::null_face()) {
      if (first < 0) first = static_cast<int>(i);
      ++rejected;
    }
  }
  if (rejected > 0) {
    mesh_error(part, "a manifold, consistently oriented mesh",
               count_text(rejected, "face", "faces") +
                   " on non-manifold edges or vertices or against their neighbours' orientation "
                   "(first: triangle " +
                   std::to_string(first) + ")");
  }
  std::vector<SurfaceMesh::Halfedge_index> cones;
  PMP::non_manifold_vertices(sm, std::back_inserter(cones));
  if (!cones.empty()) {
    std::set<SurfaceMesh::Vertex_index> pinched;
    for (const auto h : cones) pinched.insert(sm.target(h));
    mesh_error(part, "a manifold mesh",
               count_text(pinched.size(), "non-manifold vertex", "non-manifold vertices") +
                   " (first: vertex " +
                   std::to_string(mesh_vertex[static_cast<std::size_t>(*pinched.begin())]) + ")");
  }
  if (!CGAL::is_valid_polygon_mesh(sm)) {
    mesh_error(part, "a valid polygon mesh", "an invalid halfedge structure");
  }
  return sm;
}

void check_closed(const std::string& part, const SurfaceMesh& sm) {
  std::size_t border = 0;
  for (const auto h : sm.halfedges()) {
    if (sm.is_border(h)) ++border;
  }
  if (border > 0) {
    mesh_error(part, "a closed mesh", count_text(border, "border edge", "border edges"));
  }
}

void check_self_intersections(const std::string& part, const SurfaceMesh& sm) {
  std::vector<std::pair<SurfaceMesh::Face_index, SurfaceMesh::Face_index>> pairs;
  PMP::self_intersections(sm, std::back_inserter(pairs));
  if (!pairs.empty()) {
    mesh_error(part, "no self-intersections",
               count_text(pairs.size(), "intersecting face pair", "intersecting face pairs"));
  }
}

// Repair, not error: a closed mesh whose faces all point inward (a common exporter mistake) is
// unambiguous, so its components are re-oriented to bound a volume. Updates the triangles to the
// repaired winding (same indices, same vertex set) and returns whether anything changed.
bool orient_outward(SurfaceMesh& sm, const std::vector<int>& mesh_vertex,
                    core::TriangleMesh& mesh) {
  // does_bound_a_volume alone accepts an all-inward mesh (it bounds the unbounded volume), hence
  // also the outward test, which looks at the outermost component.
  if (PMP::does_bound_a_volume(sm) && PMP::is_outward_oriented(sm)) return false;
  PMP::orient_to_bound_a_volume(sm);
  bool changed = false;
  for (const auto f : sm.faces()) {
    auto& t = mesh.triangles[static_cast<std::size_t>(f)];
    const auto h = sm.halfedge(f);
    const int a = mesh_vertex[static_cast<std::size_t>(sm.source(h))];
    const int b = mesh_vertex[static_cast<std::size_t>(sm.target(h))];
    // Same cyclic order as before? Otherwise flip, keeping the first index where it was.
    const bool same =
        (a == t[0] && b == t[1]) || (a == t[1] && b == t[2]) || (a == t[2] && b == t[0]);
    if (!same) {
      std::swap(t[1], t[2]);
      changed = true;
    }
  }
  return changed;
}

// --- Mass properties ---------------------------------------------------------------------------

// Second moments by the divergence theorem: the solid is the signed sum of tetrahedra (com, a, b,
// c) over the outward triangles, and for a tetrahedron with one vertex at the origin
// integral(x x^T) dV = V / 20 * (a a^T + b b^T + c c^T + s s^T), s = a + b + c (Tonon 2004).
// Taking the CoM as the apex gives the tensor about the CoM directly, with small coordinates.
Eigen::Matrix3d inertia_about(const core::TriangleMesh& mesh, const Eigen::Vector3d& com,
                              double density) {
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d a = mesh.vertices[t[0]] - com;
    const Eigen::Vector3d b = mesh.vertices[t[1]] - com;
    const Eigen::Vector3d c = mesh.vertices[t[2]] - com;
    const double volume = a.dot(b.cross(c)) / 6.0;
    const Eigen::Vector3d s = a + b + c;
    second += volume / 20.0 *
              (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  Eigen::Matrix3d inertia = density * (second.trace() * Eigen::Matrix3d::Identity() - second);
  return 0.5 * (inertia + inertia.transpose());
}

// --- Planar facets -----------------------------------------------------------------------------

struct TriangleGeometry {
  Eigen::Vector3d normal;  // unit (zero for a zero-area triangle)
  Eigen::Vector3d centroid;
  double area = 0.0;
};

std::vector<TriangleGeometry> triangle_geometry(const core::TriangleMesh& mesh) {
  std::vector<TriangleGeometry> out(mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d& b = mesh.vertices[t[1]];
    const Eigen::Vector3d& c = mesh.vertices[t[2]];
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double norm = cross.norm();
    out[i].area = 0.5 * norm;
    out[i].normal = norm > 0.0 ? Eigen::Vector3d(cross / norm) : Eigen::Vector3d::Zero();
    out[i].centroid = (a + b + c) / 3.0;
  }
  return out;
}

// Edge-adjacent triangles (sharing both vertex indices of an edge), sorted, no duplicates.
std::vector<std::vector<int>> edge_neighbours(const core::TriangleMesh& mesh) {
  std::vector<std::pair<std::uint64_t, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    for (int k = 0; k < 3; ++k) {
      const auto lo = static_cast<std::uint64_t>(std::min(t[k], t[(k + 1) % 3]));
      const auto hi = static_cast<std::uint64_t>(std::max(t[k], t[(k + 1) % 3]));
      edges.emplace_back((lo << 32) | hi, static_cast<int>(i));
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::vector<int>> neighbours(mesh.triangles.size());
  for (std::size_t begin = 0; begin < edges.size();) {
    std::size_t end = begin;
    while (end < edges.size() && edges[end].first == edges[begin].first) ++end;
    for (std::size_t i = begin; i < end; ++i) {
      for (std::size_t j = begin; j < end; ++j) {
        if (edges[i].second != edges[j].second) {
          neighbours[edges[i].second].push_back(edges[j].second);
        }
      }
    }
    begin = end;
  }
  for (auto& n : neighbours) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return neighbours;
}

bool facet_less(const PlanarFacet& a, const PlanarFacet& b) {
  if (a.area != b.area) return a.area > b.area;
  for (int k = 0; k < 3; ++k) {
    if (a.normal[k] != b.normal[k]) return a.normal[k] < b.normal[k];
  }
  return a.offset < b.offset;
}

// Region growing from the largest unassigned triangle; a neighbour joins when it lies in the
// seed's plane (angle and distance tolerances above). Comparing against the seed, not the
// neighbour, keeps a finely tessellated curved surface from chaining into one "facet".
std::vector<PlanarFacet> planar_facets(const core::TriangleMesh& mesh) {
  const auto geometry = triangle_geometry(mesh);
  const auto neighbours = edge_neighbours(mesh);
  std::vector<int> seeds(mesh.triangles.size());
  std::iota(seeds.begin(), seeds.end(), 0);
  std::stable_sort(seeds.begin(), seeds.end(),
                   [&](int a, int b) { return geometry[a].area > geometry[b].area; });
  const double min_cos = std::cos(kFacetAngleTolerance);
  std::vector<char> assigned(mesh.triangles.size(), 0);
  std::vector<PlanarFacet> facets;
  for (const int seed : seeds) {
    if (assigned[seed] || geometry[seed].area <= 0.0) continue;
    const Eigen::Vector3d n0 = geometry[seed].normal;
    const double d0 = n0.dot(geometry[seed].centroid);
    const auto in_seed_plane = [&](int t) {
      if (n0.dot(geometry[t].normal) < min_cos) return false;
      for (const int v : mesh.triangles[t]) {
        if (std::abs(n0.dot(mesh.vertices[v]) - d0) > kFacetPlaneTolerance) return false;
      }
      return true;
    };
    PlanarFacet facet;
    std::deque<int> queue{seed};
    assigned[seed] = 1;
    while (!queue.empty()) {
      const int t = queue.front();
      queue.pop_front();
      facet.triangles.push_back(t);
      for (const int n : neighbours[t]) {
        if (!assigned[n] && in_seed_plane(n)) {
          assigned[n] = 1;
          queue.push_back(n);
        }
      }
    }
    std::sort(facet.triangles.begin(), facet.triangles.end());
    Eigen::Vector3d weighted_normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d weighted_centroid = Eigen::Vector3d::Zero();
    for (const int t : facet.triangles) {
      facet.area += geometry[t].area;
      weighted_normal += geometry[t].area * geometry[t].normal;
      weighted_centroid += geometry[t].area * geometry[t].centroid;
    }
    facet.normal = weighted_normal.normalized();
    facet.centroid = weighted_centroid / facet.area;
    facet.offset = facet.normal.dot(facet.centroid);
    facets.push_back(std::move(facet));
  }
  std::sort(facets.begin(), facets.end(), facet_less);
  return facets;
}

// Distance from `point` (projected onto the facet plane) to the facet boundary when the point is
// inside the facet, -1 when it is outside. The boundary is every edge used by exactly one of the
// facet's triangles (outer rim and holes alike).
double facet_margin(const core::TriangleMesh& mesh, const PlanarFacet& facet,
                    const Eigen::Vector3d& point) {
  const Eigen::Vector3d n = facet.normal.normalized();
  const Eigen::Vector3d u = n.unitOrthogonal();
  const Eigen::Vector3d v = n.cross(u);
  // 2D coordinates relative to the facet centroid: small numbers, and (u, v, n) is right-handed,
  // so outward-oriented triangles are counter-clockwise.
  const auto to_2d = [&](const Eigen::Vector3d& x) {
    const Eigen::Vector3d r = x - facet.centroid;
    return Eigen::Vector2d(u.dot(r), v.dot(r));
  };
  const auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() * b.y() - a.y() * b.x();
  };
  const Eigen::Vector2d p = to_2d(point);
  bool inside = false;
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * facet.triangles.size());
  for (const int index : facet.triangles) {
    const auto& t = mesh.triangles.at(static_cast<std::size_t>(index));
    if (!inside) {
      const Eigen::Vector2d a = to_2d(mesh.vertices.at(t[0]));
      const Eigen::Vector2d b = to_2d(mesh.vertices.at(t[1]));
      const Eigen::Vector2d c = to_2d(mesh.vertices.at(t[2]));
      const double sign = cross2(b - a, c - a) >= 0.0 ? 1.0 : -1.0;
      const auto left_of = [&](const Eigen::Vector2d& from, const Eigen::Vector2d& to) {
        const double length = (to - from).norm();
        return length == 0.0 || sign * cross2(to - from, p - from) >= -kInsideTolerance * length;
      };
      inside = left_of(a, b) && left_of(b, c) && left_of(c, a);
    }
    for (int k = 0; k < 3; ++k) {
      edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
    }
  }
  if (!inside) return -1.0;
  std::sort(edges.begin(), edges.end());
  double margin = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i == 1) {
      const Eigen::Vector2d a = to_2d(mesh.vertices[edges[i].first]);
      const Eigen::Vector2d b = to_2d(mesh.vertices[edges[i].second]);
      const Eigen::Vector2d ab = b - a;
      const double length2 = ab.squaredNorm();
      const double s = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
      margin = std::min(margin, (p - (a + s * ab)).norm());
    }
    i = j;
  }
  return margin;
}

// --- Convex hull and placements ----------------------------------------------------------------

core::TriangleMesh convex_hull(const core::TriangleMesh& mesh) {
  std::vector<char> used(mesh.vertices.size(), 0);
  for (const auto& t : mesh.triangles) {
    for (const int v : t) used[v] = 1;
  }
  std::vector<Point3> points;
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (used[i]) points.push_back(to_point(mesh.vertices[i]));
  }
  SurfaceMesh hull;
  CGAL::convex_hull_3(points.begin(), points.end(), hull);
  // convex_hull_3 returns the same triangles from call to call, but in an order that varies
  // between calls (and threads). Areas and normals summed over a facet's triangles depend on
  // that order in their last bits, and equal-stability placements were sorted by them, so the
  // hull is put in a canonical order: vertices lexicographically, each triangle starting at its
  // smallest index (orientation kept), triangles sorted.
  std::vector<SurfaceMesh::Vertex_index> vertices(hull.vertices().begin(), hull.vertices().end());
  const auto coordinates_less = [&](SurfaceMesh::Vertex_index a, SurfaceMesh::Vertex_index b) {
    const Point3& p = hull.point(a);
    const Point3& q = hull.point(b);
    return std::make_tuple(p.x(), p.y(), p.z()) < std::make_tuple(q.x(), q.y(), q.z());
  };
  std::sort(vertices.begin(), vertices.end(), coordinates_less);
  core::TriangleMesh out;
  std::vector<int> index(hull.num_vertices(), -1);
  for (const auto v : vertices) {
    index[static_cast<std::size_t>(v)] = static_cast<int>(out.vertices.size());
    out.vertices.push_back(to_eigen(hull.point(v)));
  }
  for (const auto f : hull.faces()) {
    std::vector<int> polygon;
    for (const auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      polygon.push_back(index[static_cast<std::size_t>(v)]);
    }
    // convex_hull_3 triangulates its output; fan-triangulate defensively all the same.
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k) {
      std::array<int, 3> triangle{polygon[0], polygon[k], polygon[k + 1]};
      std::rotate(triangle.begin(), std::min_element(triangle.begin(), triangle.end()),
                  triangle.end());
      out.triangles.push_back(triangle);
    }
  }
  std::sort(out.triangles.begin(), out.triangles.end());
  return out;
}

std::vector<db::PlacementRecord> stable_placements(const core::TriangleMesh& hull,
                                                   const Eigen::Vector3d& com) {
  struct Candidate {
    db::PlacementRecord record;
    PlanarFacet facet;
  };
  std::vector<Candidate> candidates;
  for (auto& facet : planar_facets(hull)) {
    const Eigen::Vector3d projection = com - (facet.normal.dot(com) - facet.offset) * facet.normal;
    const double stability = facet_margin(hull, facet, projection);
    if (!(stability > kMinStability)) continue;
    // Support facet down (outward normal to -z), facet plane at z = 0, CoM above the origin.
    const Eigen::Matrix3d rotation =
        Eigen::Quaterniond::FromTwoVectors(facet.normal, -Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    core::Pose pose = core::Pose::Identity();
    pose.linear() = rotation;
    const Eigen::Vector3d rotated_com = rotation * com;
    pose.translation() = Eigen::Vector3d(-rotated_com.x(), -rotated_com.y(), facet.offset);
    Candidate candidate;
    candidate.record.part_in_plane = pose;
    candidate.record.stability = stability;
    candidate.facet = std::move(facet);
    candidates.push_back(std::move(candidate));
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    if (a.record.stability != b.record.stability) return a.record.stability > b.record.stability;
    return facet_less(a.facet, b.facet);
  });
  std::vector<db::PlacementRecord> out;
  out.reserve(candidates.size());
  for (auto& c : candidates) out.push_back(c.record);
  return out;
}

}  // namespace

PartAnalysis analyze_part(const std::string& part_name, const core::TriangleMesh& mesh,
                          double mass) {
  if (!(mass > 0.0) || !std::isfinite(mass)) {
    throw core::InputError(part_name, "mass", "a positive, finite mass in kg",
                           core::format_number(mass));
  }
  check_indices_and_coordinates(part_name, mesh);
  check_degenerate_faces(part_name, mesh);
  std::vector<int> mesh_vertex;
  SurfaceMesh sm = build_surface_mesh(part_name, mesh, mesh_vertex);
  check_closed(part_name, sm);
  check_self_intersections(part_name, sm);

  PartAnalysis analysis;
  analysis.mesh = mesh;
  analysis.reoriented = orient_outward(sm, mesh_vertex, analysis.mesh);

  const double volume = PMP::volume(sm);
  if (!(volume > 0.0) || !std::isfinite(volume)) {
    mesh_error(part_name, "a positive enclosed volume", core::format_number(volume) + " m^3");
  }
  auto& props = analysis.mass_properties;
  props.volume = volume;
  props.com = to_eigen(PMP::centroid(sm));
  props.inertia = inertia_about(analysis.mesh, props.com, mass / volume);

  analysis.facets = planar_facets(analysis.mesh);
  analysis.convex_hull = convex_hull(analysis.mesh);
  analysis.placements = stable_placements(analysis.convex_hull, props.com);
  return analysis;
}

bool point_inside_facet(const core::TriangleMesh& mesh, const PlanarFacet& facet,
                        const Eigen::Vector3d& point, double margin) {
  if (facet.triangles.empty() || !point.allFinite()) return false;
  const double distance = facet_margin(mesh, facet, point);
  return distance >= 0.0 && distance >= margin;
}

}  // namespace hila::offline
