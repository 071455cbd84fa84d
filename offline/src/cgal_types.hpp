#pragma once

// Private to hila_offline: the CGAL types shared by its CGAL translation units. Never include
// this from a public header (CGAL headers are slow to compile and must not leak to users).

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <Eigen/Core>

namespace hila::offline::detail {

// Exact predicates keep the topological tests (orientation, self-intersection, inside) robust;
// inexact constructions are enough for the doubles we hand back.
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point3 = Kernel::Point_3;
using Vector3 = Kernel::Vector_3;
using SurfaceMesh = CGAL::Surface_mesh<Point3>;

inline Point3 to_point(const Eigen::Vector3d& v) {
  return Point3(v.x(), v.y(), v.z());
}
inline Eigen::Vector3d to_eigen(const Point3& p) {
  return Eigen::Vector3d(p.x(), p.y(), p.z());
}

}  // namespace hila::offline::detail
