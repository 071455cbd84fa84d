#include <gtest/gtest.h>

#include <random>

#include "gltf_builder.hpp"
#include "gltf_reading.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

// A scene without nodes (a part without goals) or without anything still reads back.
TEST(GltfBuilder, AnEmptySceneReadsBack) {
  viz::GltfBuilder with_a_mesh;
  with_a_mesh.add_mesh("box", {{core::make_box_mesh(Eigen::Vector3d(0.1, 0.2, 0.3)),
                                with_a_mesh.add_material("red", {1.0, 0.0, 0.0, 1.0})}});
  const viz::GltfBuilder empty;
  for (const viz::GltfBuilder* builder :
       std::vector<const viz::GltfBuilder*>{&with_a_mesh, &empty}) {
    const tinygltf::Model model = load_glb(builder->glb());
    ASSERT_EQ(model.scenes.size(), 1u);
    EXPECT_TRUE(model.scenes[0].nodes.empty());
    EXPECT_TRUE(model.nodes.empty());
  }
}

TEST(GltfBuilder, NodesMeshesAndChannelsReadBack) {
  viz::GltfBuilder builder;
  const int red = builder.add_material("red", {1.0, 0.0, 0.0, 1.0});
  const core::TriangleMesh box = core::make_box_mesh(Eigen::Vector3d(0.1, 0.2, 0.3));
  const int mesh = builder.add_mesh("box", {{box, red}, {core::TriangleMesh{}, red}});
  EXPECT_EQ(builder.add_mesh("empty", {{core::TriangleMesh{}, red}}), -1);
  std::mt19937_64 rng(5);
  const core::Pose a = random_pose(rng), b = random_pose(rng);
  const int root = builder.add_node("a", -1, a);
  const int child = builder.add_node("b", root, b, mesh);
  builder.set_node_scale(child, 0.0);
  const int animation = builder.add_animation("anim");
  builder.add_channel(animation, child, "rotation", {0.0f, 1.0f}, {0, 0, 0, 1, 0, 0, 1, 0},
                      "LINEAR");
  builder.add_channel(animation, child, "scale", {0.0f, 2.0f}, {0, 0, 0, 1, 1, 1}, "STEP");

  const tinygltf::Model model = load_glb(builder.glb());
  ASSERT_EQ(model.nodes.size(), 2u);
  const NodeState state = node_states(model);
  EXPECT_LT(pose_error(state.world[0], a), 1e-12);
  EXPECT_LT(pose_error(state.world[1], a * b), 1e-12);
  EXPECT_FALSE(state.visible[1]);
  ASSERT_EQ(model.meshes.size(), 1u);
  ASSERT_EQ(model.meshes[0].primitives.size(), 1u);  // the empty primitive skipped
  const auto& p = model.meshes[0].primitives[0];
  const std::vector<float> positions = read_floats(model, p.attributes.at("POSITION"));
  ASSERT_EQ(positions.size(), 3 * box.vertices.size());
  for (std::size_t i = 0; i < box.vertices.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_EQ(positions[3 * i + static_cast<std::size_t>(k)],
                static_cast<float>(box.vertices[i][k]));
    }
  }
  EXPECT_EQ(model.accessors[static_cast<std::size_t>(p.indices)].count, 3 * box.triangles.size());
  EXPECT_EQ(model.materials.at(static_cast<std::size_t>(p.material)).name, "red");
  const auto tracks = animation_tracks(model);
  ASSERT_EQ(tracks.size(), 2u);
  const NodeState later = node_states(model, &tracks, 2.0);
  EXPECT_TRUE(later.visible[1]);
  EXPECT_LT((later.world[1].translation() - (a * b).translation()).norm(), 1e-12);
  const Eigen::VectorXd r = sample(tracks.at({1, "rotation"}), 0.5);
  EXPECT_NEAR(r[2], std::sqrt(0.5), 1e-7);  // halfway to half a turn about z: slerp
}

TEST(GltfBuilder, KeyTimesMustIncrease) {
  viz::GltfBuilder builder;
  const int node = builder.add_node("n", -1, core::Pose::Identity());
  const int animation = builder.add_animation("anim");
  EXPECT_THROW(
      builder.add_channel(animation, node, "scale", {0.0f, 0.0f}, {1, 1, 1, 1, 1, 1}, "STEP"),
      std::logic_error);
  EXPECT_THROW(builder.add_channel(animation, node, "scale", {0.0f}, {1, 1}, "STEP"),
               std::logic_error);
}

}  // namespace
}  // namespace hila::test
