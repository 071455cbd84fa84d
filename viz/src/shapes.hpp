#pragma once

#include "hila/core/mesh.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::viz {

// Triangle meshes of URDF primitives, centred at the origin, for drawing: a cylinder along z and
// a sphere with `segments` facets around (at least 3); their vertices lie on the true surface.
core::TriangleMesh make_cylinder_mesh(double radius, double length, int segments = 32);
core::TriangleMesh make_sphere_mesh(double radius, int segments = 24);

// The geometry as a mesh in its link's frame (its origin applied); a mesh file is read once and
// scaled per axis. Throws core::InputError for an unreadable mesh file.
core::TriangleMesh geometry_mesh(const core::GeometrySpec& geometry);

// `mesh` moved by `pose`.
core::TriangleMesh transformed(core::TriangleMesh mesh, const core::Pose& pose);

}  // namespace hila::viz
