#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hila/core/mesh.hpp"
#include "hila/db/records.hpp"

namespace hila::offline {

// A planar region of the part surface (coplanar, edge-connected faces).
struct PlanarFacet {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();    // outward, unit
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // area-weighted
  double offset = 0.0;                                 // plane: normal . x = offset
  double area = 0.0;
  std::vector<int> triangles;  // indices into the mesh
  // The facet's boundary polygon(s) are implied by its triangles; inside() tests use them.
};

struct PartAnalysis {
  db::MassProperties mass_properties;  // uniform density from the given mass
  std::vector<PlanarFacet> facets;     // sorted by decreasing area (ties: by normal, then offset)
  core::TriangleMesh convex_hull;
  std::vector<db::PlacementRecord> placements;  // stable resting poses on a plane (part_id unset)
  // The checked mesh, outward oriented: the input with the winding of re-oriented triangles
  // flipped (same vertices, same triangle indices). Facet triangle indices refer to it; build a
  // SurfaceQuery from it (not from the input) so its normals point outward.
  core::TriangleMesh mesh;
  bool reoriented = false;  // true when the input's orientation was repaired (see analyze_part)
};

// Checks the mesh with CGAL's Polygon Mesh Processing and computes the analysis. Throws
// core::InputError("<part_name>: mesh: expected ..., got ...") naming the defect and its count,
// e.g. "expected a closed mesh, got 3 border edges". Checked, in this order: at least one
// triangle, finite coordinates and valid indices; no degenerate (collinear) faces; manifold and
// consistently oriented edges, no non-manifold vertices; closed; no self-intersections; a
// positive enclosed volume. `mass` in kg must be > 0 and finite (else field "mass").
//
// Orientation is repaired, not rejected: a closed, consistently oriented mesh whose faces point
// inward (or a component oriented against the others, e.g. a void) is re-oriented with
// PMP::orient_to_bound_a_volume; PartAnalysis::mesh carries the result and `reoriented` is set.
//
// Mass properties: volume and CoM by PMP::volume / PMP::centroid, inertia about the CoM from the
// signed tetrahedra of the surface (uniform density mass / volume). Facets: coplanar edge-connected
// triangles (normals within 1e-3 rad and vertices within 1e-6 m of the largest triangle's plane).
// Placements: one per convex hull facet whose CoM projection lies inside it by more than 1e-6 m;
// stability is that distance to the facet edge; part_in_plane puts the facet on z = 0 (outward
// normal along -z, part above) with the CoM above the plane origin; sorted by decreasing
// stability (ties: facet order).
PartAnalysis analyze_part(const std::string& part_name, const core::TriangleMesh& mesh,
                          double mass);

// Is `point` (on the facet's plane, part frame) inside the facet with at least `margin` to its
// boundary? (For placing a suction cup of radius `margin`.) The point is projected onto the
// facet's plane first; the boundary is every edge used by only one of the facet's triangles, so
// holes count. `mesh` is the mesh the facet was computed from (PartAnalysis::mesh).
bool point_inside_facet(const core::TriangleMesh& mesh, const PlanarFacet& facet,
                        const Eigen::Vector3d& point, double margin);

}  // namespace hila::offline
