#include "gltf_builder.hpp"

#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace hila::viz {

GltfBuilder::GltfBuilder() {
  model_.asset.version = "2.0";
  model_.asset.generator = "hila export";
  model_.buffers.emplace_back();
  model_.scenes.emplace_back();
  // Named: tinygltf writes a scene without nodes or name as null, which no loader accepts (a
  // part without goals has an empty scene).
  model_.scenes[0].name = "hila";
  model_.defaultScene = 0;
}

int GltfBuilder::add_material(const std::string& name, const std::array<double, 4>& rgba) {
  tinygltf::Material material;
  material.name = name;
  material.pbrMetallicRoughness.baseColorFactor = {rgba[0], rgba[1], rgba[2], rgba[3]};
  material.pbrMetallicRoughness.metallicFactor = 0.0;
  material.pbrMetallicRoughness.roughnessFactor = 0.7;
  material.doubleSided = true;
  if (rgba[3] < 1.0) material.alphaMode = "BLEND";
  model_.materials.push_back(std::move(material));
  return static_cast<int>(model_.materials.size()) - 1;
}

int GltfBuilder::add_buffer_view(const void* bytes, std::size_t size, int target) {
  std::vector<unsigned char>& data = model_.buffers[0].data;
  data.resize((data.size() + 3) / 4 * 4, 0);  // accessors of 4-byte components stay aligned
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = size;
  view.target = target;
  const auto* begin = static_cast<const unsigned char*>(bytes);
  data.insert(data.end(), begin, begin + size);
  model_.bufferViews.push_back(view);
  return static_cast<int>(model_.bufferViews.size()) - 1;
}

int GltfBuilder::add_float_accessor(const std::vector<float>& values, int type, int components,
                                    int target, bool with_bounds) {
  tinygltf::Accessor accessor;
  accessor.bufferView = add_buffer_view(values.data(), values.size() * sizeof(float), target);
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.type = type;
  accessor.count = values.size() / static_cast<std::size_t>(components);
  if (with_bounds && !values.empty()) {
    // glTF requires the bounds of positions and of animation inputs.
    accessor.minValues.assign(values.begin(), values.begin() + components);
    accessor.maxValues = accessor.minValues;
    for (std::size_t i = 0; i < values.size(); ++i) {
      const auto c = i % static_cast<std::size_t>(components);
      accessor.minValues[c] = std::min<double>(accessor.minValues[c], values[i]);
      accessor.maxValues[c] = std::max<double>(accessor.maxValues[c], values[i]);
    }
  }
  model_.accessors.push_back(accessor);
  return static_cast<int>(model_.accessors.size()) - 1;
}

int GltfBuilder::add_mesh(const std::string& name, const std::vector<Primitive>& primitives) {
  tinygltf::Mesh mesh;
  mesh.name = name;
  for (const Primitive& p : primitives) {
    if (p.mesh.triangles.empty()) continue;
    std::vector<float> positions;
    positions.reserve(3 * p.mesh.vertices.size());
    for (const Eigen::Vector3d& v : p.mesh.vertices) {
      for (int k = 0; k < 3; ++k) positions.push_back(static_cast<float>(v[k]));
    }
    std::vector<std::uint32_t> indices;
    indices.reserve(3 * p.mesh.triangles.size());
    for (const auto& t : p.mesh.triangles) {
      for (int k = 0; k < 3; ++k) indices.push_back(static_cast<std::uint32_t>(t[k]));
    }
    tinygltf::Primitive primitive;
    primitive.attributes["POSITION"] =
        add_float_accessor(positions, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER, true);
    tinygltf::Accessor index_accessor;
    index_accessor.bufferView =
        add_buffer_view(indices.data(), indices.size() * sizeof(std::uint32_t),
                        TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    index_accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    index_accessor.type = TINYGLTF_TYPE_SCALAR;
    index_accessor.count = indices.size();
    model_.accessors.push_back(index_accessor);
    primitive.indices = static_cast<int>(model_.accessors.size()) - 1;
    primitive.material = p.material;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    mesh.primitives.push_back(std::move(primitive));
  }
  if (mesh.primitives.empty()) return -1;
  model_.meshes.push_back(std::move(mesh));
  return static_cast<int>(model_.meshes.size()) - 1;
}

void set_node_pose(tinygltf::Node& node, const core::Pose& pose) {
  const Eigen::Vector3d t = pose.translation();
  const Eigen::Quaterniond q(pose.linear());
  node.translation = {t.x(), t.y(), t.z()};
  node.rotation = {q.x(), q.y(), q.z(), q.w()};
}

int GltfBuilder::add_node(const std::string& name, int parent, const core::Pose& local, int mesh) {
  tinygltf::Node node;
  node.name = name;
  node.mesh = mesh;
  set_node_pose(node, local);
  model_.nodes.push_back(std::move(node));
  const int index = static_cast<int>(model_.nodes.size()) - 1;
  if (parent < 0) {
    model_.scenes[0].nodes.push_back(index);
  } else {
    model_.nodes.at(static_cast<std::size_t>(parent)).children.push_back(index);
  }
  return index;
}

void GltfBuilder::set_node_scale(int node, double scale) {
  model_.nodes.at(static_cast<std::size_t>(node)).scale = {scale, scale, scale};
}

int GltfBuilder::add_animation(const std::string& name) {
  tinygltf::Animation animation;
  animation.name = name;
  model_.animations.push_back(std::move(animation));
  return static_cast<int>(model_.animations.size()) - 1;
}

void GltfBuilder::add_channel(int animation, int node, const std::string& path,
                              const std::vector<float>& times, const std::vector<float>& values,
                              const std::string& interpolation) {
  const int components = path == "rotation" ? 4 : 3;
  if (times.empty() || values.size() != times.size() * static_cast<std::size_t>(components)) {
    throw std::logic_error("glTF channel of node " + std::to_string(node) + " (" + path +
                           "): " + std::to_string(times.size()) + " keys, " +
                           std::to_string(values.size()) + " values");
  }
  for (std::size_t i = 1; i < times.size(); ++i) {
    if (!(times[i] > times[i - 1])) {
      throw std::logic_error("glTF channel of node " + std::to_string(node) +
                             ": key times not strictly increasing at key " + std::to_string(i));
    }
  }
  tinygltf::Animation& a = model_.animations.at(static_cast<std::size_t>(animation));
  tinygltf::AnimationSampler sampler;
  sampler.input = add_float_accessor(times, TINYGLTF_TYPE_SCALAR, 1, 0, true);
  sampler.output = add_float_accessor(
      values, components == 4 ? TINYGLTF_TYPE_VEC4 : TINYGLTF_TYPE_VEC3, components, 0, false);
  sampler.interpolation = interpolation;
  a.samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = static_cast<int>(a.samplers.size()) - 1;
  channel.target_node = node;
  channel.target_path = path;
  a.channels.push_back(channel);
}

std::string GltfBuilder::glb() const {
  tinygltf::Model model = model_;
  model.buffers[0].data.resize((model.buffers[0].data.size() + 3) / 4 * 4, 0);
  if (model.buffers[0].data.empty()) model.buffers.clear();  // a GLB's BIN chunk may not be empty
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, out, false, true)) {
    throw std::runtime_error("tinygltf could not serialise the glTF model");
  }
  return out.str();
}

}  // namespace hila::viz
