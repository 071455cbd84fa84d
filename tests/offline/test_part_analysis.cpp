#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <thread>

#include "hila/core/error.hpp"
#include "hila/core/mesh.hpp"
#include "hila/offline/part_analysis.hpp"
#include "util/test_util.hpp"

namespace hila::offline {
namespace {

core::TriangleMesh transformed(core::TriangleMesh mesh, const core::Pose& pose) {
  for (auto& v : mesh.vertices) v = pose * v;
  return mesh;
}

// Concatenates two meshes into one (no welding).
core::TriangleMesh merged(const core::TriangleMesh& a, const core::TriangleMesh& b) {
  core::TriangleMesh out = a;
  const int base = static_cast<int>(a.vertices.size());
  out.vertices.insert(out.vertices.end(), b.vertices.begin(), b.vertices.end());
  for (const auto& t : b.triangles)
    out.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  return out;
}

Eigen::Matrix3d box_inertia(const Eigen::Vector3d& size, double mass) {
  const double a2 = size.x() * size.x();
  const double b2 = size.y() * size.y();
  const double c2 = size.z() * size.z();
  return Eigen::Vector3d(mass * (b2 + c2) / 12.0, mass * (a2 + c2) / 12.0, mass * (a2 + b2) / 12.0)
      .asDiagonal();
}

// Solid tetrahedron A=(0,0,0), B=(1,0,0), C=(0,1,0), D=(2,2,1), outward faces. Its CoM
// (0.75, 0.75, 0.25) projects outside the base ABC (x + y = 1.5 > 1), so ABC is no support.
core::TriangleMesh leaning_tetrahedron() {
  core::TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 2, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  return mesh;
}

// Checks a placement independently: the hull rests on z = 0 with nothing below it, the CoM is
// above the plane origin, and the stability is the distance from the origin to the edge of the
// support polygon (the hull vertices on z = 0, a convex polygon), measured here in 2D.
void expect_valid_placement(const PartAnalysis& analysis, const db::PlacementRecord& placement) {
  const core::Pose& pose = placement.part_in_plane;
  EXPECT_TRUE(core::is_valid_pose(pose, 1e-9));
  std::vector<Eigen::Vector2d> support;
  for (const auto& v : analysis.convex_hull.vertices) {
    const Eigen::Vector3d p = pose * v;
    EXPECT_GE(p.z(), -1e-12);
    if (std::abs(p.z()) < 1e-9) support.push_back(p.head<2>());
  }
  ASSERT_GE(support.size(), 3u);
  const Eigen::Vector3d com = pose * analysis.mass_properties.com;
  EXPECT_NEAR(com.x(), 0.0, 1e-12);
  EXPECT_NEAR(com.y(), 0.0, 1e-12);
  EXPECT_GT(com.z(), 0.0);
  // Convex polygon around its mean, sorted by angle; the origin's distance to each edge line.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : support) mean += p;
  mean /= static_cast<double>(support.size());
  std::sort(support.begin(), support.end(),
            [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
              return std::atan2(a.y() - mean.y(), a.x() - mean.x()) <
                     std::atan2(b.y() - mean.y(), b.x() - mean.x());
            });
  double distance = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < support.size(); ++i) {
    const Eigen::Vector2d a = support[i];
    const Eigen::Vector2d b = support[(i + 1) % support.size()];
    const Eigen::Vector2d edge = b - a;
    // Counter-clockwise polygon: the origin is inside when left of every edge.
    const double signed_distance = (edge.x() * (-a.y()) - edge.y() * (-a.x())) / edge.norm();
    distance = std::min(distance, signed_distance);
  }
  EXPECT_NEAR(placement.stability, distance, 1e-9);
}

TEST(PartAnalysis, BoxMassPropertiesMatchClosedForms) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> size_dist(0.01, 0.8);
  std::uniform_real_distribution<double> mass_dist(0.1, 20.0);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector3d size(size_dist(rng), size_dist(rng), size_dist(rng));
    const double mass = mass_dist(rng);
    const auto analysis = analyze_part("box", core::make_box_mesh(size), mass);
    const auto& props = analysis.mass_properties;
    EXPECT_NEAR(props.volume, size.prod(), 1e-12 * size.prod());
    EXPECT_LT(props.com.norm(), 1e-12);
    EXPECT_TRUE(props.inertia.isApprox(box_inertia(size, mass), 1e-10)) << props.inertia << "\nvs\n"
                                                                        << box_inertia(size, mass);
    EXPECT_FALSE(analysis.reoriented);
  }
}

TEST(PartAnalysis, TranslatedAndRotatedBoxInertiaIsRotatedAboutTheCom) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Vector3d size(0.1 + 0.05 * trial, 0.3, 0.02 + 0.01 * trial);
    const double mass = 1.5 + trial;
    const core::Pose pose = test::random_pose(rng, 2.0);
    const auto analysis = analyze_part("box", transformed(core::make_box_mesh(size), pose), mass);
    const auto& props = analysis.mass_properties;
    EXPECT_NEAR(props.volume, size.prod(), 1e-10 * size.prod());
    EXPECT_LT((props.com - pose.translation()).norm(), 1e-12);
    const Eigen::Matrix3d expected =
        pose.linear() * box_inertia(size, mass) * pose.linear().transpose();
    EXPECT_LT((props.inertia - expected).norm(), 1e-10 * expected.norm())
        << props.inertia << "\nvs\n"
        << expected;
    EXPECT_TRUE(props.inertia.isApprox(props.inertia.transpose(), 0.0));
  }
}

TEST(PartAnalysis, TranslatedBoxKeepsItsInertia) {
  const Eigen::Vector3d size(0.4, 0.25, 0.1);
  core::Pose shift = core::Pose::Identity();
  shift.translation() = Eigen::Vector3d(3.0, -2.0, 0.5);
  const auto analysis = analyze_part("box", transformed(core::make_box_mesh(size), shift), 2.0);
  EXPECT_LT((analysis.mass_properties.com - shift.translation()).norm(), 1e-12);
  EXPECT_TRUE(analysis.mass_properties.inertia.isApprox(box_inertia(size, 2.0), 1e-9));
}

TEST(PartAnalysis, CabinetLateralBoardHasSixFacetsBigOnesFirst) {
  const auto mesh = core::load_mesh(test::data_path("cabinet/lateral.stl"), 0.001);
  const auto analysis = analyze_part("lateral", mesh, 1.8);
  EXPECT_NEAR(analysis.mass_properties.volume, 0.587 * 0.295 * 0.010, 1e-9);
  ASSERT_EQ(analysis.facets.size(), 6u);
  const double big = 0.587 * 0.295;
  EXPECT_NEAR(analysis.facets[0].area, big, 1e-9);
  EXPECT_NEAR(analysis.facets[1].area, big, 1e-9);
  EXPECT_NEAR(analysis.facets[2].area, 0.587 * 0.010, 1e-9);
  EXPECT_NEAR(analysis.facets[3].area, 0.587 * 0.010, 1e-9);
  EXPECT_NEAR(analysis.facets[4].area, 0.295 * 0.010, 1e-9);
  EXPECT_NEAR(analysis.facets[5].area, 0.295 * 0.010, 1e-9);
  // The big faces are the board's sides (z in the file), opposite, 5 mm from the centre.
  EXPECT_NEAR(std::abs(analysis.facets[0].normal.z()), 1.0, 1e-12);
  EXPECT_NEAR(analysis.facets[0].normal.dot(analysis.facets[1].normal), -1.0, 1e-12);
  EXPECT_NEAR(analysis.facets[0].offset, 0.005, 1e-9);
  std::set<int> covered;
  for (std::size_t i = 0; i < analysis.facets.size(); ++i) {
    const auto& facet = analysis.facets[i];
    EXPECT_NEAR(facet.normal.norm(), 1.0, 1e-12);
    EXPECT_NEAR(facet.normal.dot(facet.centroid), facet.offset, 1e-12);
    EXPECT_GT(facet.offset, 0.0);  // outward normals of a body around its centre
    EXPECT_TRUE(std::is_sorted(facet.triangles.begin(), facet.triangles.end()));
    if (i > 0) {
      EXPECT_GE(analysis.facets[i - 1].area, facet.area);
    }
    covered.insert(facet.triangles.begin(), facet.triangles.end());
  }
  EXPECT_EQ(covered.size(), mesh.triangles.size());

  // A suction cup on the big face: the centre has 147.5 mm to the nearest edge.
  const auto& side = analysis.facets[0];
  EXPECT_TRUE(point_inside_facet(analysis.mesh, side, side.centroid, 0.147));
  EXPECT_FALSE(point_inside_facet(analysis.mesh, side, side.centroid, 0.148));
  // 13.5 mm from the short edge at x = 293.5 mm.
  const Eigen::Vector3d near_edge = side.centroid + Eigen::Vector3d(0.28, 0.0, 0.0);
  EXPECT_TRUE(point_inside_facet(analysis.mesh, side, near_edge, 0.0134));
  EXPECT_FALSE(point_inside_facet(analysis.mesh, side, near_edge, 0.0136));
  EXPECT_FALSE(
      point_inside_facet(analysis.mesh, side, side.centroid + Eigen::Vector3d(0.3, 0, 0), 0.0));
  // A point of the opposite face's plane, projected, is still inside this facet.
  EXPECT_TRUE(point_inside_facet(analysis.mesh, side, analysis.facets[1].centroid, 0.1));
}

TEST(PartAnalysis, ConvexHullOfABoxIsTheBox) {
  const Eigen::Vector3d size(0.3, 0.2, 0.1);
  const auto analysis = analyze_part("box", core::make_box_mesh(size), 1.0);
  const auto& hull = analysis.convex_hull;
  EXPECT_EQ(hull.vertices.size(), 8u);
  EXPECT_EQ(hull.triangles.size(), 12u);
  for (const auto& v : hull.vertices) {
    EXPECT_NEAR(v.cwiseAbs().x(), 0.15, 1e-15);
    EXPECT_NEAR(v.cwiseAbs().y(), 0.10, 1e-15);
    EXPECT_NEAR(v.cwiseAbs().z(), 0.05, 1e-15);
  }
  // Outward hull triangles: the hull analysed as a part has the box's volume.
  const auto hull_analysis = analyze_part("hull", hull, 1.0);
  EXPECT_FALSE(hull_analysis.reoriented);
  EXPECT_NEAR(hull_analysis.mass_properties.volume, size.prod(), 1e-15);
}

TEST(PartAnalysis, UnusedVerticesAreIgnored) {
  auto mesh = core::make_box_mesh(Eigen::Vector3d(0.3, 0.2, 0.1));
  mesh.vertices.emplace_back(5.0, 5.0, 5.0);  // referenced by no triangle
  const auto analysis = analyze_part("box", mesh, 1.0);
  EXPECT_NEAR(analysis.mass_properties.volume, 0.006, 1e-15);
  EXPECT_EQ(analysis.convex_hull.vertices.size(), 8u);
  EXPECT_LT(analysis.convex_hull.max_corner().maxCoeff(), 0.2);
  EXPECT_EQ(analysis.mesh.vertices.size(), mesh.vertices.size());
}

TEST(PartAnalysis, BoxRestsStablyOnEachFaceLargestFirst) {
  const Eigen::Vector3d size(0.5, 0.3, 0.08);
  const auto analysis = analyze_part("box", core::make_box_mesh(size), 3.0);
  ASSERT_EQ(analysis.placements.size(), 6u);
  // Largest face (0.5 x 0.3, normal +-z): stability = half the shorter side; then 0.04 four times.
  EXPECT_NEAR(analysis.placements[0].stability, 0.15, 1e-12);
  EXPECT_NEAR(analysis.placements[1].stability, 0.15, 1e-12);
  for (int i = 2; i < 6; ++i) EXPECT_NEAR(analysis.placements[i].stability, 0.04, 1e-12);
  for (int i = 0; i < 2; ++i) {
    const auto& pose = analysis.placements[i].part_in_plane;
    // Lying flat: the part's z axis is vertical, the CoM half the thickness up.
    EXPECT_NEAR(std::abs(pose.linear()(2, 2)), 1.0, 1e-12);
    EXPECT_NEAR((pose * analysis.mass_properties.com).z(), 0.04, 1e-12);
  }
  for (const auto& placement : analysis.placements) {
    EXPECT_EQ(placement.part_id, 0);
    expect_valid_placement(analysis, placement);
  }
}

TEST(PartAnalysis, LeaningTetrahedronHasUnstableHullFacets) {
  const auto analysis = analyze_part("tetra", leaning_tetrahedron(), 1.0);
  EXPECT_NEAR(analysis.mass_properties.volume, 1.0 / 6.0, 1e-15);
  EXPECT_LT((analysis.mass_properties.com - Eigen::Vector3d(0.75, 0.75, 0.25)).norm(), 1e-15);
  EXPECT_EQ(analysis.convex_hull.triangles.size(), 4u);
  ASSERT_FALSE(analysis.placements.empty());
  EXPECT_LT(analysis.placements.size(), 4u);
  for (const auto& placement : analysis.placements) {
    // Never on the base ABC (outward normal -z would have to point down).
    const Eigen::Vector3d base_normal =
        placement.part_in_plane.linear() * -Eigen::Vector3d::UnitZ();
    EXPECT_GT(base_normal.z(), -1.0 + 1e-6);
    expect_valid_placement(analysis, placement);
  }
  for (std::size_t i = 1; i < analysis.placements.size(); ++i) {
    EXPECT_GE(analysis.placements[i - 1].stability, analysis.placements[i].stability);
  }
  // Face ABD: the CoM projects to (0.75, 0.70, 0.35), barycentric (0.6, 0.05, 0.35), inside.
  bool abd = false;
  const Eigen::Vector3d abd_normal = Eigen::Vector3d(0, -1, 2).normalized();
  for (const auto& placement : analysis.placements) {
    abd |= (placement.part_in_plane.linear() * abd_normal).z() < -1.0 + 1e-9;
  }
  EXPECT_TRUE(abd);
}

TEST(PartAnalysis, ResultIsDeterministic) {
  const auto mesh = core::load_mesh(test::data_path("cabinet/lateral.stl"), 0.001);
  const auto a = analyze_part("lateral", mesh, 1.8);
  const auto b = analyze_part("lateral", mesh, 1.8);
  ASSERT_EQ(a.facets.size(), b.facets.size());
  for (std::size_t i = 0; i < a.facets.size(); ++i) {
    EXPECT_EQ(a.facets[i].triangles, b.facets[i].triangles);
    EXPECT_EQ(a.facets[i].normal, b.facets[i].normal);
  }
  ASSERT_EQ(a.placements.size(), b.placements.size());
  for (std::size_t i = 0; i < a.placements.size(); ++i) {
    EXPECT_EQ(a.placements[i].stability, b.placements[i].stability);
    EXPECT_TRUE(a.placements[i].part_in_plane.isApprox(b.placements[i].part_in_plane, 0.0));
  }
}

// A closed prism with a regular `sides`-gon cross-section (a dowel-like part): its two caps are
// equal, so its two most stable placements tie exactly and only a canonical order separates them.
core::TriangleMesh regular_prism(int sides, double radius, double length) {
  core::TriangleMesh mesh;
  for (int end = 0; end < 2; ++end) {
    for (int k = 0; k < sides; ++k) {
      const double angle = 2.0 * M_PI * k / sides;
      mesh.vertices.emplace_back(radius * std::cos(angle), radius * std::sin(angle),
                                 (end == 0 ? -0.5 : 0.5) * length);
    }
  }
  const int bottom_centre = static_cast<int>(mesh.vertices.size());
  mesh.vertices.emplace_back(0.0, 0.0, -0.5 * length);
  mesh.vertices.emplace_back(0.0, 0.0, 0.5 * length);
  for (int k = 0; k < sides; ++k) {
    const int a = k;
    const int b = (k + 1) % sides;
    mesh.triangles.push_back({a, b, b + sides});
    mesh.triangles.push_back({a, b + sides, a + sides});
    mesh.triangles.push_back({bottom_centre, b, a});
    mesh.triangles.push_back({bottom_centre + 1, a + sides, b + sides});
  }
  return mesh;
}

TEST(PartAnalysis, HullAndPlacementsOfADowelAreTheSameOnEveryCallAndThread) {
  // CGAL's convex_hull_3 returns its triangles in an order that varies between calls; the tied
  // caps of a dowel were then sorted differently by a build with --jobs 2.
  const auto mesh = regular_prism(24, 0.01, 0.3);
  const auto reference = analyze_part("dowel", mesh, 0.1);
  ASSERT_GE(reference.placements.size(), 2u);
  EXPECT_EQ(reference.placements[0].stability, reference.placements[1].stability);
  for (int run = 0; run < 6; ++run) {
    PartAnalysis other;
    if (run % 2 == 0) {
      other = analyze_part("dowel", mesh, 0.1);
    } else {
      std::thread worker([&] { other = analyze_part("dowel", mesh, 0.1); });
      worker.join();
    }
    ASSERT_EQ(other.convex_hull.vertices, reference.convex_hull.vertices) << "run " << run;
    ASSERT_EQ(other.convex_hull.triangles, reference.convex_hull.triangles) << "run " << run;
    ASSERT_EQ(other.placements.size(), reference.placements.size());
    for (std::size_t i = 0; i < other.placements.size(); ++i) {
      EXPECT_EQ(other.placements[i].stability, reference.placements[i].stability);
      EXPECT_TRUE(other.placements[i].part_in_plane.isApprox(reference.placements[i].part_in_plane,
                                                             0.0))
          << "run " << run << " placement " << i;
    }
  }
}

TEST(PartAnalysis, OpenMeshIsRejected) {
  auto mesh = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  mesh.triangles.pop_back();
  test::expect_input_error([&] { analyze_part("open_box", mesh, 1.0); },
                           {"open_box", "mesh", "closed", "3 border edges"});
}

TEST(PartAnalysis, InwardOrientedBoxIsRepaired) {
  const Eigen::Vector3d size(0.3, 0.2, 0.1);
  auto mesh = core::make_box_mesh(size);
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  const auto analysis = analyze_part("inward_box", mesh, 2.0);
  EXPECT_TRUE(analysis.reoriented);
  EXPECT_NEAR(analysis.mass_properties.volume, size.prod(), 1e-15);
  EXPECT_TRUE(analysis.mass_properties.inertia.isApprox(box_inertia(size, 2.0), 1e-10));
  // The repaired mesh is the original box winding again; facet normals point outward.
  EXPECT_EQ(analysis.mesh.triangles, core::make_box_mesh(size).triangles);
  EXPECT_EQ(analysis.mesh.vertices, mesh.vertices);
  ASSERT_EQ(analysis.facets.size(), 6u);
  for (const auto& facet : analysis.facets) EXPECT_GT(facet.offset, 0.0);
  EXPECT_EQ(analysis.placements.size(), 6u);
}

TEST(PartAnalysis, HollowBoxKeepsItsInwardVoidAndMixedOrientationIsRepaired) {
  const Eigen::Vector3d outer(0.4, 0.4, 0.4);
  const Eigen::Vector3d inner(0.2, 0.2, 0.2);
  auto cavity = core::make_box_mesh(inner);
  for (auto& t : cavity.triangles) std::swap(t[1], t[2]);  // a void faces into the solid
  const auto hollow = analyze_part("hollow", merged(core::make_box_mesh(outer), cavity), 5.0);
  EXPECT_FALSE(hollow.reoriented);
  const double volume = outer.prod() - inner.prod();
  EXPECT_NEAR(hollow.mass_properties.volume, volume, 1e-15);
  const double density = 5.0 / volume;
  const Eigen::Matrix3d expected =
      box_inertia(outer, density * outer.prod()) - box_inertia(inner, density * inner.prod());
  EXPECT_TRUE(hollow.mass_properties.inertia.isApprox(expected, 1e-10));
  // The same with the void wrongly facing outward: re-oriented to the same solid.
  const auto repaired =
      analyze_part("hollow", merged(core::make_box_mesh(outer), core::make_box_mesh(inner)), 5.0);
  EXPECT_TRUE(repaired.reoriented);
  EXPECT_NEAR(repaired.mass_properties.volume, volume, 1e-15);
  EXPECT_EQ(repaired.mesh.triangles, hollow.mesh.triangles);
  // Two separate boxes, one inward: only that one is flipped.
  core::Pose shift = core::Pose::Identity();
  shift.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  const auto pair =
      analyze_part("pair", merged(core::make_box_mesh(inner), transformed(cavity, shift)), 1.0);
  EXPECT_TRUE(pair.reoriented);
  EXPECT_NEAR(pair.mass_properties.volume, 2.0 * inner.prod(), 1e-15);
  const auto box_triangles = core::make_box_mesh(inner).triangles;
  for (std::size_t i = 0; i < pair.mesh.triangles.size(); ++i) {
    const auto& t = pair.mesh.triangles[i];
    const auto& expected_t = box_triangles[i % 12];
    const int base = i < 12 ? 0 : 8;
    EXPECT_EQ(
        t, (std::array<int, 3>{expected_t[0] + base, expected_t[1] + base, expected_t[2] + base}));
  }
}

TEST(PartAnalysis, GentlyCurvedSurfaceDoesNotChainIntoOneFacet) {
  // A block with a barrel-vault top: 64 segments of an arc (radius 1 m), neighbouring segments
  // 0.78 mrad apart (< 1 mrad). Pairwise merging would chain the whole vault (50 mrad) into one
  // "planar" facet; growing against the seed's plane takes at most three segments per facet.
  constexpr int kSegments = 64;
  const double radius = 1.0;
  const double half_angle = 0.025;
  const double height = 0.02;
  const double width = 0.1;
  const double half_span = radius * std::sin(half_angle);
  // Profile in (x, z), counter-clockwise: bottom corners, then the arc from +x back to -x.
  std::vector<Eigen::Vector2d> profile = {{-half_span, 0.0}, {half_span, 0.0}};
  for (int i = kSegments; i >= 0; --i) {
    const double phi = -half_angle + 2.0 * half_angle * i / kSegments;
    profile.emplace_back(radius * std::sin(phi),
                         height + radius * (std::cos(phi) - std::cos(half_angle)));
  }
  const int m = static_cast<int>(profile.size());
  core::TriangleMesh mesh;
  for (const double y : {-width / 2, width / 2}) {
    for (const auto& p : profile) mesh.vertices.emplace_back(p.x(), y, p.y());
  }
  for (int j = 1; j + 1 < m; ++j) {
    mesh.triangles.push_back({0, j, j + 1});          // y = -w/2, outward -y
    mesh.triangles.push_back({m, m + j + 1, m + j});  // y = +w/2, outward +y
  }
  for (int j = 0; j < m; ++j) {
    const int k = (j + 1) % m;
    mesh.triangles.push_back({j, m + k, k});
    mesh.triangles.push_back({j, m + j, m + k});
  }
  const auto analysis = analyze_part("vault", mesh, 1.0);
  EXPECT_FALSE(analysis.reoriented);
  int top_facets = 0;
  for (const auto& facet : analysis.facets) {
    if (facet.normal.z() > 0.99) ++top_facets;
    for (const int t : facet.triangles) {
      const auto& tri = analysis.mesh.triangles[t];
      const Eigen::Vector3d n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                                    .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]])
                                    .normalized();
      EXPECT_LT(std::acos(std::min(1.0, n.dot(facet.normal))), 1e-3);
    }
  }
  EXPECT_GE(top_facets, kSegments / 3);
  EXPECT_LE(top_facets, kSegments);
  // Bottom, two ends and two sides are single facets: 5 + the vault's pieces.
  EXPECT_EQ(analysis.facets.size(), static_cast<std::size_t>(5 + top_facets));
  // By area: bottom (50 x 100 mm), the ends (20 x 100 mm), the profile sides (~50 x 20 mm).
  EXPECT_NEAR(analysis.facets[0].normal.z(), -1.0, 1e-12);
  EXPECT_NEAR(std::abs(analysis.facets[1].normal.x()), 1.0, 1e-3);
  EXPECT_NEAR(std::abs(analysis.facets[2].normal.x()), 1.0, 1e-3);
  EXPECT_NEAR(std::abs(analysis.facets[3].normal.y()), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(analysis.facets[4].normal.y()), 1.0, 1e-12);
}

TEST(PartAnalysis, DegenerateFaceIsRejected) {
  // Split triangle (0, 2, 1) at the midpoint m of edge 0-2 and close the T-junction with the
  // zero-area triangle (2, m, 0): closed, manifold, oriented, one degenerate face.
  auto mesh = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  const int m = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(0.5 * (mesh.vertices[0] + mesh.vertices[2]));
  ASSERT_EQ(mesh.triangles[0], (std::array<int, 3>{0, 2, 1}));
  mesh.triangles[0] = {0, m, 1};
  mesh.triangles.push_back({m, 2, 1});
  mesh.triangles.push_back({2, m, 0});
  test::expect_input_error([&] { analyze_part("sliver", mesh, 1.0); },
                           {"sliver", "mesh", "degenerate", "1 degenerate face", "triangle 13"});
  // Without the sliver the T-junction leaves the mesh open: the sliver was what closed it.
  mesh.triangles.pop_back();
  test::expect_input_error([&] { analyze_part("sliver", mesh, 1.0); }, {"closed"});
  // A triangle repeating a vertex index is degenerate too.
  auto repeated = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  repeated.triangles[4] = {0, 1, 1};
  test::expect_input_error([&] { analyze_part("repeated", repeated, 1.0); },
                           {"repeated", "degenerate", "triangle 4"});
}

TEST(PartAnalysis, SelfIntersectingMeshIsRejected) {
  const auto box = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  core::Pose shift = core::Pose::Identity();
  shift.translation() = Eigen::Vector3d(0.1, 0.05, 0.03);
  const auto mesh = merged(box, transformed(box, shift));
  test::expect_input_error([&] { analyze_part("overlap", mesh, 1.0); },
                           {"overlap", "mesh", "no self-intersections", "intersecting face pair"});
  // Two disjoint boxes are a valid (two-component) part.
  shift.translation() = Eigen::Vector3d(0.5, 0.0, 0.0);
  const auto apart = analyze_part("apart", merged(box, transformed(box, shift)), 2.0);
  EXPECT_NEAR(apart.mass_properties.volume, 2 * 0.008, 1e-15);
  EXPECT_LT((apart.mass_properties.com - Eigen::Vector3d(0.25, 0, 0)).norm(), 1e-15);
}

TEST(PartAnalysis, NonManifoldMeshIsRejected) {
  // A duplicated triangle runs its edges a second time in the same direction.
  auto mesh = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  mesh.triangles.push_back(mesh.triangles[3]);
  test::expect_input_error([&] { analyze_part("fin", mesh, 1.0); },
                           {"fin", "mesh", "manifold", "1 face", "triangle 12"});
  // Two boxes sharing one corner vertex: closed, but pinched at that vertex.
  const auto box = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  auto pinched = merged(box, transformed(box, core::make_pose(Eigen::Vector3d(0.2, 0.2, 0.2))));
  for (auto& t : pinched.triangles) {
    for (auto& v : t) {
      if (v == 8) v = 7;  // the second box's corner 0 is the first box's corner 7
    }
  }
  // The second box's three faces at the shared corner cannot join the closed first corner.
  test::expect_input_error([&] { analyze_part("pinched", pinched, 1.0); },
                           {"pinched", "mesh", "manifold", "3 faces", "vertices", "triangle 12"});
}

TEST(PartAnalysis, BadMassOrEmptyMeshIsRejected) {
  const auto box = core::make_box_mesh(Eigen::Vector3d(0.2, 0.2, 0.2));
  test::expect_input_error([&] { analyze_part("board", box, 0.0); },
                           {"board", "mass", "positive", "got 0"});
  test::expect_input_error([&] { analyze_part("board", box, -1.0); }, {"board", "mass", "got -1"});
  test::expect_input_error(
      [&] { analyze_part("board", box, std::numeric_limits<double>::quiet_NaN()); },
      {"board", "mass", "got nan"});
  test::expect_input_error(
      [&] { analyze_part("board", box, std::numeric_limits<double>::infinity()); },
      {"board", "mass", "got inf"});
  test::expect_input_error([&] { analyze_part("empty", core::TriangleMesh{}, 1.0); },
                           {"empty", "mesh", "at least one triangle"});
  auto bad_index = box;
  bad_index.triangles[2][1] = 8;
  test::expect_input_error([&] { analyze_part("indices", bad_index, 1.0); },
                           {"indices", "mesh", "vertex indices", "triangle 2"});
  auto nan_vertex = box;
  nan_vertex.vertices[5].y() = std::numeric_limits<double>::quiet_NaN();
  test::expect_input_error([&] { analyze_part("nan", nan_vertex, 1.0); },
                           {"nan", "mesh", "finite", "vertex 5"});
}

}  // namespace
}  // namespace hila::offline
