#include "hila/offline/table_regrasp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hila/core/pose.hpp"
#include "hila/core/stage_scene.hpp"

namespace hila::offline {

std::vector<core::Pose> table_set_down_poses(const core::Cell& cell, const core::TriangleMesh& mesh,
                                             const Eigen::Vector3d& com, const core::Pose& initial,
                                             const std::vector<db::PlacementRecord>& placements,
                                             const TableRegraspSettings& settings) {
  std::vector<core::Pose> poses;
  if (!settings.enabled || settings.placements < 1 || settings.yaws < 1) return poses;
  double bottom = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : mesh.vertices) bottom = std::min(bottom, (initial * v).z());
  const Eigen::Vector3d over = initial * com;
  // The box the part lies on: its top at the part's lowest point, under the centre of mass.
  const bool on_a_box = std::any_of(
      cell.spec().obstacles.begin(), cell.spec().obstacles.end(), [&](const core::BoxObstacle& o) {
        const Eigen::Vector3d local =
            o.pose.inverse() * Eigen::Vector3d(over.x(), over.y(), bottom);
        const Eigen::Vector3d half = 0.5 * o.size;
        return std::abs(local.z() - half.z()) <= settings.support_tolerance &&
               std::abs(local.x()) <= half.x() && std::abs(local.y()) <= half.y();
      });
  if (!on_a_box) return poses;
  const int count = std::min(settings.placements, static_cast<int>(placements.size()));
  for (int p = 0; p < count; ++p) {
    // part_in_plane rests the part on z = 0 with its centre of mass over the plane's origin.
    const core::Pose& in_plane = placements[static_cast<std::size_t>(p)].part_in_plane;
    for (int k = 0; k < settings.yaws; ++k) {
      core::Pose plane = core::Pose::Identity();
      plane.linear() =
          Eigen::AngleAxisd(2.0 * core::kPi * k / settings.yaws, Eigen::Vector3d::UnitZ())
              .toRotationMatrix();
      plane.translation() = Eigen::Vector3d(over.x(), over.y(), bottom);
      const core::Pose pose = plane * in_plane;
      const bool initial_again =
          (pose.translation() - initial.translation()).norm() < 1e-3 &&
          core::rotation_distance(pose.linear(), initial.linear()) < core::deg_to_rad(1.0);
      if (!initial_again) poses.push_back(pose);
    }
  }
  return poses;
}

std::vector<core::Pose> relay_set_down_poses(const core::Cell& cell, const core::TriangleMesh& mesh,
                                             const Eigen::Vector3d& com, const core::Pose& initial,
                                             const std::vector<db::PlacementRecord>& placements,
                                             const TableRegraspSettings& settings) {
  std::vector<core::Pose> poses;
  if (!settings.enabled || !settings.relay || settings.relay_spots < 1 ||
      !(settings.relay_spacing > 0.0)) {
    return poses;
  }
  const Eigen::Vector3d over = initial * com;
  double bottom = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& v : mesh.vertices) bottom = std::min(bottom, (initial * v).z());
  const core::BoxObstacle* table = nullptr;
  for (const auto& o : cell.spec().obstacles) {
    const Eigen::Vector3d local = o.pose.inverse() * Eigen::Vector3d(over.x(), over.y(), bottom);
    const Eigen::Vector3d half = 0.5 * o.size;
    if (std::abs(local.z() - half.z()) <= settings.support_tolerance &&
        std::abs(local.x()) <= half.x() && std::abs(local.y()) <= half.y()) {
      table = &o;
    }
  }
  if (table == nullptr) return poses;
  // Grid points of the table's top, the part's reach from its edges left to the checks.
  std::vector<std::pair<double, Eigen::Vector3d>> spots;
  const Eigen::Vector3d half = 0.5 * table->size;
  const int nx = static_cast<int>(std::floor(table->size.x() / settings.relay_spacing));
  const int ny = static_cast<int>(std::floor(table->size.y() / settings.relay_spacing));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      Eigen::Vector3d at = table->pose * Eigen::Vector3d(-half.x() + i * settings.relay_spacing,
                                                         -half.y() + j * settings.relay_spacing,
                                                         half.z());
      if ((at - over).head<2>().norm() < settings.relay_spacing) continue;  // where it lay
      double farther = 0.0;
      for (const auto& arm : cell.arms()) {
        const Eigen::Vector3d base = core::arm_base_in_world(cell, arm).translation();
        farther = std::max(farther, (at - base).head<2>().norm());
      }
      spots.emplace_back(farther, at);
    }
  }
  std::stable_sort(spots.begin(), spots.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  spots.resize(std::min(spots.size(), static_cast<std::size_t>(settings.relay_spots)));
  for (const auto& [farther, at] : spots) {
    core::Pose moved = initial;
    moved.translation() += Eigen::Vector3d(at.x() - over.x(), at.y() - over.y(), 0.0);
    for (const core::Pose& p : table_set_down_poses(cell, mesh, com, moved, placements, settings)) {
      poses.push_back(p);
    }
  }
  return poses;
}

}  // namespace hila::offline
