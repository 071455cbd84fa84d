#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace hila::core {

// An indexed triangle mesh in metres.
struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::array<int, 3>> triangles;

  Eigen::Vector3d min_corner() const;
  Eigen::Vector3d max_corner() const;
};

// Reads an STL, OBJ or PLY mesh (by its extension, any case) with assimp, merges all its meshes,
// applies `unit_scale` (metres per file unit, e.g. 0.001 for millimetres) and joins identical
// vertices. Throws InputError for a missing/unreadable file, another extension, a file assimp 5.2
// would mishandle (src/mesh_checks.hpp), an empty mesh or non-finite coordinates.
TriangleMesh load_mesh(const std::string& path, double unit_scale);

// An axis-aligned box centred at the origin (12 outward-facing triangles).
TriangleMesh make_box_mesh(const Eigen::Vector3d& size);

// Writes the mesh with assimp's exporter; format by id ("stl", "stlb", "obj", "ply").
void write_mesh(const TriangleMesh& mesh, const std::string& path, const std::string& format_id);

}  // namespace hila::core
