#include "scene_variation.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "hila/core/collision.hpp"
#include "hila/online/world.hpp"

namespace hila::bench {

namespace {

// An axis-aligned rectangle in the world's x/y plane.
struct Footprint {
  Eigen::Vector2d min = Eigen::Vector2d::Constant(1e9);
  Eigen::Vector2d max = Eigen::Vector2d::Constant(-1e9);

  void add(const Eigen::Vector3d& p) {
    min = min.cwiseMin(p.head<2>());
    max = max.cwiseMax(p.head<2>());
  }
  bool overlaps(const Footprint& o, double margin) const {
    return (min.array() - margin < o.max.array()).all() &&
           (o.min.array() < max.array() + margin).all();
  }
};

Footprint footprint(const core::TriangleMesh& mesh, const core::Pose& pose) {
  Footprint f;
  for (const auto& v : mesh.vertices) f.add(pose * v);
  return f;
}

const core::BoxObstacle& table_of(const core::Cell& cell) {
  for (const auto& o : cell.spec().obstacles) {
    if (o.name == "table") {
      // The box is placed inside the table's x/y extent: only an axis-aligned table has one.
      if (!o.pose.linear().isIdentity(1e-9)) {
        throw std::runtime_error(cell.spec().file +
                                 ": obstacles: table: expected an axis-aligned table for the "
                                 "benchmark's extra box, got a rotated one");
      }
      return o;
    }
  }
  throw std::runtime_error(cell.spec().file +
                           ": obstacles: expected a box named 'table' for the benchmark's extra "
                           "box to stand on, found none");
}

core::Pose box_pose(const Eigen::Vector3d& centre, double yaw) {
  core::Pose p = core::Pose::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = centre;
  return p;
}

// Whether the board at its detected pose touches anything: a finished board (a board shifted
// toward the assembly and yawed can reach into its back panel), the robot at the scene's joints,
// the tool, the table. A camera cannot see a board there, so such a draw is not a problem to
// plan but a variation to redraw.
bool board_touches(const online::Scene& scene, const core::Cell& cell,
                   const core::ProductSpec& product, const std::string& board) {
  const online::World world(cell, product, scene, board);
  core::CollisionData data = world.make_data();
  return core::in_collision(world.stage().cell.model, data, {world.stage().board});
}

// Whether the box, grown by `margin` on every side, touches what can move at the scene's start:
// the robot at its joints, the tool (on the table or in hand) and the board at its detected pose.
bool touches_movers(const online::Scene& scene, const core::Cell& cell,
                    const core::ProductSpec& product, const std::string& board,
                    const online::SceneObstacle& box, double margin) {
  online::Scene probe = scene;
  online::SceneObstacle grown = box;
  grown.box_size += Eigen::Vector3d::Constant(2.0 * margin);
  probe.obstacles.push_back(grown);
  // The tool's cup stands on the table, a contact by design: 3 mm up it touches nothing, and
  // the box's margin dwarfs that.
  probe.tool.translation().z() += 0.003;
  const online::World world(cell, product, probe, board);
  core::CollisionData data = world.make_data();
  const core::CollisionModel& model = world.stage().cell.model;
  // The query starts from the moving bodies: given a static body (the box) alone, it would pair
  // it with the static scene only, where every pair is skipped.
  std::vector<int> moving;
  for (int b = 0; b < model.num_bodies(); ++b) {
    if (model.is_enabled(b) && !model.is_static(b)) moving.push_back(b);
  }
  core::CollisionPair pair;
  if (!core::in_collision(model, data, moving, &pair)) return false;
  const int box_body = world.obstacles().back();
  if (pair.body_a != box_body && pair.body_b != box_body) {
    throw std::runtime_error(
        "vary_scene: the scene for '" + board +
        "' is in collision before any box is added: " + core::describe_pair(model, pair));
  }
  return true;
}

}  // namespace

VariedScene vary_scene(const online::Scene& base, const core::Cell& cell,
                       const core::ProductSpec& product, const std::string& board,
                       std::uint64_t seed, const VariationSettings& settings) {
  std::mt19937_64 rng(seed);
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  VariedScene out;
  out.seed = seed;
  out.scene = base;
  online::Scene& scene = out.scene;
  const core::PartSpec& part = product.part(board);

  // The board: shifted and yawed about world z through its centre, at its detected height,
  // redrawn while it would touch something. One draw per statement: the order of draws is part
  // of what the seed means.
  const core::Pose detected = base.initial_pose(part);
  const Eigen::Vector3d centre =
      detected * (0.5 * (part.mesh.min_corner() + part.mesh.max_corner()));
  for (int attempt = 0;; ++attempt) {
    if (attempt == settings.board_tries) {
      throw std::runtime_error("vary_scene: every pose drawn for '" + board + "' (seed " +
                               std::to_string(seed) + ", " + std::to_string(attempt) +
                               " tries) touches something in its base scene");
    }
    out.board_shift.x() = uniform(-settings.board_shift, settings.board_shift);
    out.board_shift.y() = uniform(-settings.board_shift, settings.board_shift);
    out.board_yaw_deg = uniform(-settings.board_yaw_deg, settings.board_yaw_deg);
    core::Pose about = core::Pose::Identity();
    about.linear() =
        Eigen::AngleAxisd(core::deg_to_rad(out.board_yaw_deg), Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    about.translation() = centre + Eigen::Vector3d(out.board_shift.x(), out.board_shift.y(), 0.0) -
                          about.linear() * centre;
    scene.detected[board] = about * detected;
    out.board_redraws = attempt;
    if (!board_touches(scene, cell, product, board)) break;
  }

  // The human: a few centimetres off the cell's stance, facing the same way.
  out.stance_shift.x() = uniform(-settings.stance_shift, settings.stance_shift);
  out.stance_shift.y() = uniform(-settings.stance_shift, settings.stance_shift);
  scene.human_stance.translation().head<2>() += out.stance_shift;

  // The box: anywhere on the table clear of the board, the stack and the assembly by footprint,
  // and of the robot and the tool by collision.
  std::vector<Footprint> keep_out;
  keep_out.push_back(footprint(part.mesh, scene.initial_pose(part)));
  for (const auto& p : product.parts) {
    if (p.name != board && !scene.is_finished(p.name)) {
      keep_out.push_back(footprint(p.mesh, scene.initial_pose(p)));
    }
  }
  Footprint assembly;
  for (const auto& p : product.parts) {
    const Footprint f = footprint(p.mesh, scene.assembly_frame * p.target);
    assembly.add({f.min.x(), f.min.y(), 0.0});
    assembly.add({f.max.x(), f.max.y(), 0.0});
  }
  keep_out.push_back(assembly);
  const core::BoxObstacle& table = table_of(cell);
  const Eigen::Vector3d table_min = table.pose.translation() - 0.5 * table.size;
  const Eigen::Vector3d table_max = table.pose.translation() + 0.5 * table.size;
  for (int attempt = 0; attempt < settings.box_tries; ++attempt) {
    const double side = uniform(settings.box_min, settings.box_max);
    const double yaw = uniform(0.0, 0.5 * core::kPi);  // a cube repeats every 90 degrees
    const double half = 0.5 * side * (std::abs(std::cos(yaw)) + std::abs(std::sin(yaw)));
    if (table_max.x() - table_min.x() < 2.0 * half || table_max.y() - table_min.y() < 2.0 * half) {
      continue;
    }
    // 2 mm above the top, like the product's gaps, so that standing never reads as touching.
    const double x = uniform(table_min.x() + half, table_max.x() - half);
    const double y = uniform(table_min.y() + half, table_max.y() - half);
    const Eigen::Vector3d at(x, y, table_max.z() + 0.5 * side + 0.002);
    Footprint f;
    f.add(at - Eigen::Vector3d(half, half, 0.0));
    f.add(at + Eigen::Vector3d(half, half, 0.0));
    if (std::any_of(keep_out.begin(), keep_out.end(),
                    [&](const Footprint& k) { return k.overlaps(f, settings.box_margin); })) {
      continue;
    }
    online::SceneObstacle box;
    box.name = "bench_box";
    box.box_size = Eigen::Vector3d::Constant(side);
    box.pose = box_pose(at, yaw);
    if (touches_movers(scene, cell, product, board, box, settings.box_margin)) continue;
    out.box_side = side;
    out.box_centre = at;
    out.box_yaw_deg = core::rad_to_deg(yaw);
    scene.obstacles.push_back(std::move(box));
    return out;
  }
  throw std::runtime_error("vary_scene: no place on the table for the extra box for '" + board +
                           "' (seed " + std::to_string(seed) + ") after " +
                           std::to_string(settings.box_tries) + " tries");
}

}  // namespace hila::bench
