#pragma once

#include <string>
#include <vector>

#include "hila/core/mesh.hpp"
#include "hila/core/pose.hpp"

namespace hila::core {

struct PartSpec {
  std::string name;
  std::string mesh_file;            // resolved path
  double unit_scale = 1.0;          // metres per mesh unit
  double mass = 0.0;                // kg
  Pose target = Pose::Identity();   // in the assembly frame
  Pose initial = Pose::Identity();  // nominal pose on the table, world frame
  int order = 0;                    // 1-based assembly order
  TriangleMesh mesh;                // loaded, in metres, part frame
};

struct ProductSpec {
  std::string file;
  std::string name;
  Pose assembly_frame = Pose::Identity();     // world
  Pose suction_tool_pose = Pose::Identity();  // world, the tool's handle frame
  std::vector<PartSpec> parts;                // sorted by assembly order

  const PartSpec& part(const std::string& name) const;  // throws InputError
  Pose target_in_world(const PartSpec& part) const { return assembly_frame * part.target; }
};

// Reads the product file and every part mesh. Rejects missing/unreadable/empty meshes,
// non-finite values, non-positive masses, implausible sizes (a part larger than 3 m or smaller
// than 5 mm: wrong unit), duplicate names and orders that are not 1..N.
ProductSpec load_product(const std::string& path);

// Metres per unit for "m", "cm", "mm", "in".
double unit_scale_from_name(const std::string& unit, const std::string& file,
                            const std::string& field);

}  // namespace hila::core
