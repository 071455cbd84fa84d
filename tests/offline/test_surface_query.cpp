#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <thread>
#include <vector>

#include "hila/core/mesh.hpp"
#include "hila/offline/part_analysis.hpp"
#include "hila/offline/surface_query.hpp"
#include "util/test_util.hpp"

namespace hila::offline {
namespace {

const Eigen::Vector3d kSize(0.3, 0.2, 0.1);  // box centred at the origin
const Eigen::Vector3d kHalf = kSize / 2.0;

// Which box face (0..5 = -x, +x, -y, +y, -z, +z) a surface point lies on, -1 if none: exactly
// one coordinate on its plane (1e-12) and the others within the face.
int box_face(const Eigen::Vector3d& p) {
  int face = -1;
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(p[axis]) > kHalf[axis] + 1e-12) return -1;
    if (std::abs(std::abs(p[axis]) - kHalf[axis]) < 1e-12) face = 2 * axis + (p[axis] > 0 ? 1 : 0);
  }
  return face;
}

Eigen::Vector3d face_normal(int face) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  n[face / 2] = (face % 2 == 1) ? 1.0 : -1.0;
  return n;
}

TEST(SurfaceQuery, RayFromAboveHitsTheTopFace) {
  const SurfaceQuery query(core::make_box_mesh(kSize));
  const auto hit = query.first_hit(Eigen::Vector3d(0.05, -0.03, 1.0), Eigen::Vector3d(0, 0, -1));
  ASSERT_TRUE(hit.has_value());
  EXPECT_LT((hit->point - Eigen::Vector3d(0.05, -0.03, 0.05)).norm(), 1e-15);
  EXPECT_LT((hit->normal - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  ASSERT_GE(hit->triangle, 0);
  ASSERT_LT(hit->triangle, 12);
  // The reported triangle is on the top face.
  const auto box = core::make_box_mesh(kSize);
  for (const int v : box.triangles[hit->triangle]) EXPECT_NEAR(box.vertices[v].z(), 0.05, 1e-15);
  // Direction length does not matter; an oblique ray hits where the line meets the plane.
  const auto scaled = query.first_hit(Eigen::Vector3d(0.05, -0.03, 1.0), Eigen::Vector3d(0, 0, -7));
  ASSERT_TRUE(scaled.has_value());
  EXPECT_LT((scaled->point - hit->point).norm(), 1e-15);
  const auto oblique =
      query.first_hit(Eigen::Vector3d(-0.5, 0.0, 0.05 + 0.5), Eigen::Vector3d(1.0, 0.0, -1.0));
  ASSERT_TRUE(oblique.has_value());
  EXPECT_LT((oblique->point - Eigen::Vector3d(0.0, 0.0, 0.05)).norm(), 1e-14);
}

TEST(SurfaceQuery, RayFromInsideHitsTheFarFace) {
  const SurfaceQuery query(core::make_box_mesh(kSize));
  const auto hit = query.first_hit(Eigen::Vector3d(0.01, 0.02, -0.01), Eigen::Vector3d(1, 0, 0));
  ASSERT_TRUE(hit.has_value());
  EXPECT_LT((hit->point - Eigen::Vector3d(0.15, 0.02, -0.01)).norm(), 1e-15);
  EXPECT_LT((hit->normal - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  const auto down = query.first_hit(Eigen::Vector3d(0.01, 0.02, -0.01), Eigen::Vector3d(0, -1, 0));
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(down->point.y(), -0.1, 1e-15);
  EXPECT_LT((down->normal + Eigen::Vector3d::UnitY()).norm(), 1e-15);
}

TEST(SurfaceQuery, MissingRayReturnsNothing) {
  const SurfaceQuery query(core::make_box_mesh(kSize));
  EXPECT_FALSE(query.first_hit(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1)).has_value());
  EXPECT_FALSE(query.first_hit(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(1, 0, 0)).has_value());
  EXPECT_FALSE(query.first_hit(Eigen::Vector3d(0.2, 0, 1), Eigen::Vector3d(0, 0, -1)).has_value());
  EXPECT_FALSE(query.first_hit(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d::Zero()).has_value());
  // Pointing at the box but with the box entirely closer than min_distance.
  EXPECT_FALSE(query.first_hit(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1), 1.2));
}

TEST(SurfaceQuery, MinDistanceSkipsTheStartingFace) {
  const SurfaceQuery query(core::make_box_mesh(kSize));
  const Eigen::Vector3d on_top(0.05, 0.02, 0.05);
  const Eigen::Vector3d down(0, 0, -1);
  // Starting on the top face: t = 0 is not > min_distance = 0, so the bottom face is next.
  auto hit = query.first_hit(on_top, down);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), -0.05, 1e-15);
  EXPECT_LT((hit->normal + Eigen::Vector3d::UnitZ()).norm(), 1e-15);
  hit = query.first_hit(on_top, down, 1e-3);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), -0.05, 1e-15);
  // From above: min_distance past the top face skips it, short of it does not.
  const Eigen::Vector3d above(0.05, 0.02, 0.06);
  hit = query.first_hit(above, down, 0.02);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), -0.05, 1e-15);
  hit = query.first_hit(above, down, 0.005);
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), 0.05, 1e-15);
  // Starting exactly on an edge of the top face (two triangles contain the start).
  hit = query.first_hit(Eigen::Vector3d(0.0, 0.1, 0.05), Eigen::Vector3d(0, -1, -1));
  ASSERT_TRUE(hit.has_value());
  EXPECT_NEAR(hit->point.z(), -0.05, 1e-15);
  EXPECT_NEAR(hit->point.y(), 0.0, 1e-15);
}

TEST(SurfaceQuery, UniformSamplesLieOnTheSurfaceInProportionToArea) {
  const auto box = core::make_box_mesh(kSize);
  const SurfaceQuery query(box);
  constexpr int kCount = 60000;
  const auto samples = query.sample_uniform(kCount, 42);
  ASSERT_EQ(samples.size(), static_cast<std::size_t>(kCount));
  std::array<int, 6> counts{};
  for (const auto& s : samples) {
    const int face = box_face(s.point);
    ASSERT_GE(face, 0) << s.point.transpose();
    ++counts[face];
    EXPECT_LT((s.normal - face_normal(face)).norm(), 1e-15);
    ASSERT_GE(s.triangle, 0);
    ASSERT_LT(s.triangle, 12);
    // The point lies in its triangle's plane.
    const auto& t = box.triangles[s.triangle];
    EXPECT_LT(std::abs(face_normal(face).dot(box.vertices[t[0]] - s.point)), 1e-15);
  }
  // Pearson chi-square over the six faces (5 degrees of freedom; 25 is p ~ 1e-4).
  const std::array<double, 6> areas = {kSize.y() * kSize.z(), kSize.y() * kSize.z(),
                                       kSize.x() * kSize.z(), kSize.x() * kSize.z(),
                                       kSize.x() * kSize.y(), kSize.x() * kSize.y()};
  double total_area = 0.0;
  for (const double a : areas) total_area += a;
  double chi2 = 0.0;
  for (int f = 0; f < 6; ++f) {
    const double expected = kCount * areas[f] / total_area;
    chi2 += (counts[f] - expected) * (counts[f] - expected) / expected;
  }
  EXPECT_LT(chi2, 25.0);
  // Top and bottom carry 0.12 / 0.22 of the area; a sampler by triangle count would give 1/3.
  EXPECT_NEAR((counts[4] + counts[5]) / double(kCount), 0.12 / 0.22, 0.01);
}

TEST(SurfaceQuery, SamplingIsDeterministicPerSeed) {
  const SurfaceQuery query(core::make_box_mesh(kSize));
  const auto a = query.sample_uniform(500, 1234);
  const auto b = query.sample_uniform(500, 1234);
  const auto c = query.sample_uniform(500, 1235);
  ASSERT_EQ(a.size(), 500u);
  ASSERT_EQ(c.size(), 500u);
  int differing = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].point, b[i].point);
    EXPECT_EQ(a[i].triangle, b[i].triangle);
    differing += (a[i].point != c[i].point) ? 1 : 0;
  }
  EXPECT_GT(differing, 490);
  EXPECT_TRUE(query.sample_uniform(0, 1).empty());
  EXPECT_TRUE(query.sample_uniform(-3, 1).empty());
}

TEST(SurfaceQuery, InsideTellsInteriorFromExterior) {
  std::mt19937_64 rng(5);
  const core::Pose pose = test::random_pose(rng, 0.5);
  auto box = core::make_box_mesh(kSize);
  for (auto& v : box.vertices) v = pose * v;
  const SurfaceQuery query(box);
  EXPECT_TRUE(query.inside(pose * Eigen::Vector3d(0, 0, 0)));
  EXPECT_TRUE(query.inside(pose * Eigen::Vector3d(0.14, -0.09, 0.04)));
  EXPECT_FALSE(query.inside(pose * Eigen::Vector3d(0.16, 0, 0)));
  EXPECT_FALSE(query.inside(pose * Eigen::Vector3d(0, 0.11, 0)));
  EXPECT_FALSE(query.inside(pose * Eigen::Vector3d(0, 0, -0.051)));
  EXPECT_FALSE(query.inside(Eigen::Vector3d(10, 10, 10)));
  // Random points against the box's own inequalities.
  std::uniform_real_distribution<double> u(-0.2, 0.2);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d local(u(rng), u(rng), u(rng));
    const bool expected = (local.cwiseAbs() - kHalf).maxCoeff() < 0.0;
    if (std::abs((local.cwiseAbs() - kHalf).maxCoeff()) < 1e-9) continue;
    EXPECT_EQ(query.inside(pose * local), expected) << local.transpose();
  }
}

TEST(SurfaceQuery, RepairedMeshGivesOutwardNormals) {
  auto inward = core::make_box_mesh(kSize);
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  const auto analysis = analyze_part("inward", inward, 1.0);
  const SurfaceQuery query(analysis.mesh);
  const auto hit = query.first_hit(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1));
  ASSERT_TRUE(hit.has_value());
  EXPECT_LT((hit->normal - Eigen::Vector3d::UnitZ()).norm(), 1e-15);
}

TEST(SurfaceQuery, ConcurrentQueriesMatchSerialOnesAndMoveKeepsState) {
  const auto board = core::load_mesh(test::data_path("cabinet/lateral.stl"), 0.001);
  SurfaceQuery original(board);
  const SurfaceQuery query(std::move(original));
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  std::vector<Eigen::Vector3d> origins;
  for (int i = 0; i < 400; ++i) origins.emplace_back(u(rng), u(rng), 0.5);
  std::vector<int> serial;
  for (const auto& o : origins) {
    const auto hit = query.first_hit(o, Eigen::Vector3d(0, 0, -1));
    serial.push_back(hit ? hit->triangle : -1);
  }
  std::vector<int> first(origins.size()), second(origins.size());
  const auto run = [&](std::vector<int>& out) {
    for (std::size_t i = 0; i < origins.size(); ++i) {
      const auto hit = query.first_hit(origins[i], Eigen::Vector3d(0, 0, -1));
      out[i] = hit ? hit->triangle : -1;
      (void)query.inside(origins[i] - Eigen::Vector3d(0, 0, 0.5));
    }
  };
  std::thread a(run, std::ref(first));
  std::thread b(run, std::ref(second));
  a.join();
  b.join();
  EXPECT_EQ(first, serial);
  EXPECT_EQ(second, serial);
  int hits = 0;
  for (const int t : serial) hits += t >= 0 ? 1 : 0;
  EXPECT_GT(hits, 100);
  EXPECT_LT(hits, 400);
}

}  // namespace
}  // namespace hila::offline
