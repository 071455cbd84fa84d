#pragma once

#include <Eigen/Core>
#include <vector>

#include "hila/core/mesh.hpp"

namespace hila::core {

// How far a symmetry may move a vertex from the nearest vertex of the mesh (m): half a millimetre,
// below any feature a worker tells apart and above the rounding of exported meshes.
inline constexpr double kSymmetryTolerance = 0.0005;

// The rotations of a part that map its mesh onto itself (rotations R of the part frame about the
// vertices' centroid c, x -> c + R (x - c)): of the 24 rotations that permute the principal axes
// of the vertices' covariance with signs, those that take every vertex to within `tolerance` of
// a vertex. The identity is always first. Where the principal moments differ (a box with three
// different sides) this finds every symmetry of the part: the half turns about the axes where
// they map it onto itself; where two are equal (a square plate) the quarter turns about the
// third as well, while symmetries about axes between the principal ones may be missed (the
// covariance does not fix the axes in that plane).
std::vector<Eigen::Matrix3d> mesh_symmetries(const TriangleMesh& mesh,
                                             double tolerance = kSymmetryTolerance);

// The least rotation (degrees) that brings a part from orientation `from` to `to` (world), any of
// its `symmetries` (part frame, mesh_symmetries) counting as the same part: the least angle of
// (from R)^T to over R. The plain angle between the two for an empty list.
double least_rotation_angle_deg(const Eigen::Matrix3d& from, const Eigen::Matrix3d& to,
                                const std::vector<Eigen::Matrix3d>& symmetries);

}  // namespace hila::core
