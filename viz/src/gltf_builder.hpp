#pragma once

// Private to hila::viz: the only header that includes tinygltf, so users of hila::viz never need
// it. Tests of these helpers see viz/src.

#include <tiny_gltf.h>

#include <string>
#include <vector>

#include "hila/core/mesh.hpp"
#include "hila/core/pose.hpp"

namespace hila::viz {

// One triangle mesh of a glTF mesh, drawn with one material.
struct Primitive {
  core::TriangleMesh mesh;  // metres, in the node's frame
  int material = -1;
};

// Builds a glTF 2.0 model with one binary buffer (the .glb's BIN chunk): materials, meshes,
// nodes in one scene, and node animations. Indices returned are glTF indices.
class GltfBuilder {
 public:
  GltfBuilder();

  // A PBR material of colour `rgba` (linear, 0..1), not metallic, double-sided (a robot link's
  // inner faces show through cut primitives).
  int add_material(const std::string& name, const std::array<double, 4>& rgba);
  // A mesh of one primitive per entry (float positions, uint32 indices, triangles). Primitives
  // without triangles are skipped; returns -1 if none remains.
  int add_mesh(const std::string& name, const std::vector<Primitive>& primitives);
  // A node under `parent` (-1: a root of the scene) at `local` in the parent's frame.
  int add_node(const std::string& name, int parent, const core::Pose& local, int mesh = -1);
  void set_node_scale(int node, double scale);

  // A new empty animation; channels are added by the functions below.
  int add_animation(const std::string& name);
  // `path` "rotation" (values x, y, z, w per key), "translation" or "scale" (x, y, z per key);
  // `times` in seconds, strictly increasing; `interpolation` "LINEAR" or "STEP".
  void add_channel(int animation, int node, const std::string& path,
                   const std::vector<float>& times, const std::vector<float>& values,
                   const std::string& interpolation);

  const tinygltf::Model& model() const { return model_; }
  // The model as a .glb file's bytes.
  std::string glb() const;

 private:
  // Appends `bytes` to the buffer (4-byte aligned) as a new buffer view; returns its index.
  int add_buffer_view(const void* bytes, std::size_t size, int target);
  int add_float_accessor(const std::vector<float>& values, int type, int components, int target,
                         bool with_bounds);

  tinygltf::Model model_;
};

// A node's local pose as glTF stores it (translation, rotation quaternion x y z w, no scale).
void set_node_pose(tinygltf::Node& node, const core::Pose& pose);

}  // namespace hila::viz
