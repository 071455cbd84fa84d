#pragma once

// Reading a .glb back for the viz tests: tinygltf's loader, node world transforms (static or at
// an animation time, with glTF's own interpolation: LINEAR lerp / slerp, STEP).

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "hila/core/pose.hpp"

namespace hila::test {

inline tinygltf::Model load_glb(const std::string& bytes) {
  tinygltf::TinyGLTF loader;
  tinygltf::Model model;
  std::string error, warning;
  const bool ok = loader.LoadBinaryFromMemory(&model, &error, &warning,
                                              reinterpret_cast<const unsigned char*>(bytes.data()),
                                              static_cast<unsigned int>(bytes.size()));
  EXPECT_TRUE(ok) << error;
  EXPECT_TRUE(error.empty()) << error;
  EXPECT_TRUE(warning.empty()) << warning;
  return model;
}

inline std::map<std::string, int> nodes_by_name(const tinygltf::Model& model) {
  std::map<std::string, int> out;
  for (std::size_t i = 0; i < model.nodes.size(); ++i) {
    EXPECT_TRUE(out.emplace(model.nodes[i].name, static_cast<int>(i)).second)
        << "two nodes named " << model.nodes[i].name;
  }
  return out;
}

// Each node's parent (-1 for a root).
inline std::vector<int> node_parents(const tinygltf::Model& model) {
  std::vector<int> parent(model.nodes.size(), -1);
  for (std::size_t i = 0; i < model.nodes.size(); ++i) {
    for (int c : model.nodes[i].children) parent[static_cast<std::size_t>(c)] = static_cast<int>(i);
  }
  return parent;
}

inline core::Pose node_local(const tinygltf::Node& node) {
  core::Pose p = core::Pose::Identity();
  if (node.translation.size() == 3) {
    p.translation() =
        Eigen::Vector3d(node.translation[0], node.translation[1], node.translation[2]);
  }
  if (node.rotation.size() == 4) {
    p.linear() =
        Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2])
            .toRotationMatrix();
  }
  return p;
}

inline std::vector<float> read_floats(const tinygltf::Model& model, int accessor_index) {
  const tinygltf::Accessor& a = model.accessors.at(static_cast<std::size_t>(accessor_index));
  EXPECT_EQ(a.componentType, TINYGLTF_COMPONENT_TYPE_FLOAT);
  const tinygltf::BufferView& v = model.bufferViews.at(static_cast<std::size_t>(a.bufferView));
  const int components = tinygltf::GetNumComponentsInType(static_cast<std::uint32_t>(a.type));
  std::vector<float> out(a.count * static_cast<std::size_t>(components));
  const unsigned char* data = model.buffers.at(static_cast<std::size_t>(v.buffer)).data.data() +
                              v.byteOffset + a.byteOffset;
  std::memcpy(out.data(), data, out.size() * sizeof(float));
  return out;
}

// One channel: times and values (3 or 4 per key).
struct Track {
  std::string interpolation;
  std::vector<float> times;
  std::vector<float> values;
  int components = 3;
};

// The tracks of the animation by (node, path).
inline std::map<std::pair<int, std::string>, Track> animation_tracks(const tinygltf::Model& model,
                                                                     int animation = 0) {
  std::map<std::pair<int, std::string>, Track> out;
  const tinygltf::Animation& a = model.animations.at(static_cast<std::size_t>(animation));
  for (const tinygltf::AnimationChannel& c : a.channels) {
    const tinygltf::AnimationSampler& s = a.samplers.at(static_cast<std::size_t>(c.sampler));
    Track t{s.interpolation, read_floats(model, s.input), read_floats(model, s.output),
            c.target_path == "rotation" ? 4 : 3};
    out[{c.target_node, c.target_path}] = std::move(t);
  }
  return out;
}

// The track's value at `time` (glTF: clamped to the first and last keys).
inline Eigen::VectorXd sample(const Track& track, double time) {
  const auto n = track.times.size();
  auto value = [&](std::size_t i) {
    Eigen::VectorXd v(track.components);
    for (int c = 0; c < track.components; ++c) {
      v[c] =
          track
              .values[i * static_cast<std::size_t>(track.components) + static_cast<std::size_t>(c)];
    }
    return v;
  };
  if (time <= track.times.front()) return value(0);
  if (time >= track.times.back()) return value(n - 1);
  const auto upper = std::upper_bound(track.times.begin(), track.times.end(), time);
  const std::size_t i = static_cast<std::size_t>(upper - track.times.begin()) - 1;
  if (track.interpolation == "STEP") return value(i);
  const double s = (time - track.times[i]) / (track.times[i + 1] - track.times[i]);
  if (track.components == 4) {
    const Eigen::VectorXd a = value(i), b = value(i + 1);
    const Eigen::Quaterniond qa(a[3], a[0], a[1], a[2]), qb(b[3], b[0], b[1], b[2]);
    const Eigen::Quaterniond q = qa.slerp(s, qb);
    Eigen::VectorXd out(4);
    out << q.x(), q.y(), q.z(), q.w();
    return out;
  }
  return (1.0 - s) * value(i) + s * value(i + 1);
}

// Every node's world transform and visibility (no zero scale on its way to the root), static
// (`tracks` null) or at `time`.
struct NodeState {
  std::vector<core::Pose> world;
  std::vector<bool> visible;
};

inline NodeState node_states(const tinygltf::Model& model,
                             const std::map<std::pair<int, std::string>, Track>* tracks = nullptr,
                             double time = 0.0) {
  const std::vector<int> parent = node_parents(model);
  NodeState out;
  out.world.assign(model.nodes.size(), core::Pose::Identity());
  out.visible.assign(model.nodes.size(), true);
  std::vector<bool> done(model.nodes.size(), false);
  std::function<void(std::size_t)> visit = [&](std::size_t i) {
    if (done[i]) return;
    const tinygltf::Node& node = model.nodes[i];
    core::Pose local = node_local(node);
    bool visible = node.scale.size() != 3 || node.scale[0] != 0.0;
    if (tracks) {
      const int n = static_cast<int>(i);
      if (auto t = tracks->find({n, "rotation"}); t != tracks->end()) {
        const Eigen::VectorXd q = sample(t->second, time);
        local.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
      }
      if (auto t = tracks->find({n, "translation"}); t != tracks->end()) {
        local.translation() = sample(t->second, time);
      }
      if (auto t = tracks->find({n, "scale"}); t != tracks->end()) {
        visible = sample(t->second, time)[0] != 0.0;
      }
    }
    if (parent[i] >= 0) {
      visit(static_cast<std::size_t>(parent[i]));
      local = out.world[static_cast<std::size_t>(parent[i])] * local;
      visible = visible && out.visible[static_cast<std::size_t>(parent[i])];
    }
    out.world[i] = local;
    out.visible[i] = visible;
    done[i] = true;
  };
  for (std::size_t i = 0; i < model.nodes.size(); ++i) visit(i);
  return out;
}

inline double pose_error(const core::Pose& a, const core::Pose& b) {
  return std::max((a.translation() - b.translation()).norm(),
                  (a.linear() - b.linear()).cwiseAbs().maxCoeff());
}

}  // namespace hila::test
