#pragma once

// Shared fixtures for the hila::db tests: records with awkward values and a helper that writes
// them, so every test file builds databases the same way.

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "hila/db/database.hpp"
#include "util/test_util.hpp"

namespace hila::db::test_data {

struct SamplePart {
  PartRecord part;
  std::vector<PlacementRecord> placements;
  std::vector<RobotGraspRecord> robot_grasps;
  std::vector<SuctionGraspRecord> suction_grasps;
  std::vector<HumanGraspRecord> human_grasps;
};

struct Sample {
  Meta meta;
  std::vector<SamplePart> parts;
  std::vector<ComfortMapRecord> comfort_maps;
};

inline Eigen::Vector3d random_vector(std::mt19937_64& rng, double scale) {
  std::uniform_real_distribution<double> u(-scale, scale);
  return {u(rng), u(rng), u(rng)};
}

inline Eigen::Quaterniond random_orientation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized();
}

// A comfort map with random values, `zero_share` of them 0 (as the bins the arm never reaches),
// the others anywhere in 1..255.
inline ComfortMapRecord make_comfort_map(const std::string& arm, std::uint64_t seed,
                                         const Eigen::Vector3i& dims, int orientation_count,
                                         double zero_share = 0.9) {
  std::mt19937_64 rng(seed);
  ComfortMapRecord map;
  map.arm = arm;
  map.origin = random_vector(rng, 1.0);
  map.spacing = 0.03;
  map.dims = dims;
  for (int o = 0; o < orientation_count; ++o) map.orientations.push_back(random_orientation(rng));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::uniform_int_distribution<int> value(1, 255);
  map.values.resize(static_cast<std::size_t>(dims.prod()) * map.orientations.size());
  for (auto& v : map.values) v = u(rng) < zero_share ? 0 : static_cast<std::uint8_t>(value(rng));
  map.samples = 2000000;
  map.seed = seed | (std::uint64_t{1} << 63);  // beyond SQLite's signed integers
  map.coverage = 0.25 + 1e-17;
  return map;
}

// Two parts with different record counts (part 2 has no suction grasps), values that are
// negative, tiny, huge, subnormal and infinite, a non-ASCII part name, and two comfort maps.
inline Sample make_sample(std::uint64_t seed = 7) {
  std::mt19937_64 rng(seed);
  Sample s;
  s.meta.hila_version = "0.1.0";
  s.meta.product_name = "cabinet";
  s.meta.cell_hash = std::string(64, 'c');
  s.meta.product_hash = std::string(64, 'a');
  s.meta.settings_hash = std::string(64, '5');
  s.meta.seed = std::numeric_limits<std::uint64_t>::max();  // beyond SQLite's signed integers
  s.meta.created_at = "2024-06-11T10:00:00Z";
  s.meta.cell_file = "meshes/cell/cell.yaml";
  s.meta.product_file = "meshes/cabinet/product.yaml";

  for (int k = 0; k < 2; ++k) {
    SamplePart p;
    p.part.name = k == 0 ? "Gehäuse-ß-部品-🔩" : "door panel 'left'";
    p.part.assembly_order = k == 0 ? -3 : 7;
    p.part.mesh_file = k == 0 ? "meshes/cabinet/ü.stl" : "door.obj";
    p.part.mesh_hash = std::string(64, k == 0 ? 'e' : 'f');
    p.part.mass = k == 0 ? 1e-300 : 12.5;
    p.part.mass_properties.volume = k == 0 ? std::numeric_limits<double>::denorm_min() : 3.2e-3;
    p.part.mass_properties.com = random_vector(rng, 1e-9);
    Eigen::Matrix3d a;
    a << random_vector(rng, 1.0), random_vector(rng, 1.0), random_vector(rng, 1.0);
    p.part.mass_properties.inertia = (a * a.transpose()) * (k == 0 ? 1e-12 : 1e6);
    p.part.mass_properties.inertia(0, 1) = p.part.mass_properties.inertia(1, 0) = -2.5e-7;
    // Exactly symmetric (the database stores one triangle): a + b == b + a bit for bit.
    const Eigen::Matrix3d raw = p.part.mass_properties.inertia;
    p.part.mass_properties.inertia = 0.5 * (raw + raw.transpose());
    p.part.extent = Eigen::Vector3d(0.1, -1e300, 1e300);
    p.part.triangle_count = k == 0 ? 2147483647 : 0;
    p.part.target = test::random_pose(rng, 1e3);
    p.part.initial = test::random_pose(rng, 1e-6);

    for (int i = 0; i < 3 + k; ++i) {
      PlacementRecord r;
      r.part_in_plane = test::random_pose(rng);
      r.stability = -0.001 * (i + 1);
      p.placements.push_back(r);
    }
    for (int i = 0; i < 5 - k; ++i) {
      RobotGraspRecord g;
      g.tcp = test::random_pose(rng, 0.2);
      g.jaw_width = 0.001 * (i + 1) + 1e-17;
      g.contact_1 = random_vector(rng, 0.1);
      g.normal_1 = random_vector(rng, 1.0).normalized();
      g.contact_2 = random_vector(rng, 0.1);
      g.normal_2 = -g.normal_1;
      g.quality = 0.1 * i + 0.05;
      g.friction_torque_capacity = i == 0 ? std::numeric_limits<double>::infinity() : 1.0 / 3.0;
      g.lever = -1e-200;
      g.theta_c_deg = i == 1 ? 90.0 : 22.0 + i;
      p.robot_grasps.push_back(g);
    }
    for (int i = 0; k == 0 && i < 2; ++i) {
      SuctionGraspRecord g;
      g.cup = test::random_pose(rng, 0.3);
      g.rotation_deg = -179.999 + i * 90;
      g.force_margin = -std::numeric_limits<double>::infinity();
      g.moment_margin = 1e-310;  // subnormal
      p.suction_grasps.push_back(g);
    }
    for (int i = 0; i < 2; ++i) {
      HumanGraspRecord g;
      g.hand = test::random_pose(rng, 0.5);
      g.aperture = 0.07 + i * 1e-15;
      g.contact_1 = random_vector(rng, 0.05);
      g.contact_2 = random_vector(rng, 0.05);
      g.quality = 1.0 - i * std::numeric_limits<double>::epsilon();
      g.one_hand_stable = (i + k) % 2 == 0;
      p.human_grasps.push_back(g);
    }
    s.parts.push_back(p);
  }
  // Two small comfort maps of different shapes (the values' size is what the writer checks).
  s.comfort_maps.push_back(make_comfort_map("right", seed + 1, {4, 3, 2}, 10));
  s.comfort_maps.push_back(make_comfort_map("left", seed + 2, {2, 5, 3}, 7, 0.5));
  return s;
}

// Writes `sample` to `path` through DatabaseWriter (parts, then comfort maps) and returns the part
// ids in order.
inline std::vector<std::int64_t> write_sample(const std::string& path, const Sample& sample) {
  DatabaseWriter writer(path);
  writer.write_meta(sample.meta);
  std::vector<std::int64_t> ids;
  for (const auto& p : sample.parts) {
    const std::int64_t id = writer.add_part(p.part);
    writer.add_placements(id, p.placements);
    writer.add_robot_grasps(id, p.robot_grasps);
    writer.add_suction_grasps(id, p.suction_grasps);
    writer.add_human_grasps(id, p.human_grasps);
    ids.push_back(id);
  }
  for (const auto& map : sample.comfort_maps) writer.add_comfort_map(map);
  writer.commit();
  return ids;
}

// Largest absolute difference between two poses' 4x4 matrices.
inline double pose_error(const core::Pose& a, const core::Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

}  // namespace hila::db::test_data
