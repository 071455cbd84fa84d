#pragma once

#include <Eigen/Core>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/mesh.hpp"
#include "hila/db/records.hpp"

namespace hila::offline {

// A regrasp on the table: the arm whose gripper picked a part sets it down where it lay, on
// another resting pose, lets go and takes it again with a grasp that serves a goal its first grasp
// does not (the human's hand where the gripper was, or the arm's reach at the goal).
struct TableRegraspSettings {
  bool enabled = true;
  // The resting poses tried where the part lay: the `placements` most stable of
  // PartAnalysis::placements, each turned about the vertical in `yaws` even steps.
  int placements = 4;
  int yaws = 8;
  // m: the part lies on a box obstacle of the cell (the table) when its lowest point is this close
  // to the box's top over the part's centre of mass; a part on another part (a pile) is not set
  // down elsewhere.
  double support_tolerance = 0.002;
  // Relays: where one arm's gripper picks the part but only the other arm's holds it at a
  // comfortable goal, the first sets it down where both arms reach and the other takes it
  // (relay_set_down_poses). `relay_spots` places on the part's table, on a grid `relay_spacing`
  // m apart, nearest the farther arm base first.
  bool relay = true;
  int relay_spots = 4;
  double relay_spacing = 0.05;
};

// Where a part lying on the table at `initial` can be set down for a regrasp: its centre of mass
// (`com`, part frame) over the same point of the table, resting on one of `placements` (most
// stable first) turned about the vertical; the initial pose itself is left out (a regrasp there
// would be a direct pick). Empty when the part does not lie on a box obstacle of the cell.
std::vector<core::Pose> table_set_down_poses(const core::Cell& cell, const core::TriangleMesh& mesh,
                                             const Eigen::Vector3d& com, const core::Pose& initial,
                                             const std::vector<db::PlacementRecord>& placements,
                                             const TableRegraspSettings& settings);

// Where a part lying on the table at `initial` can be set down for a relay between the arms: at
// each of settings.relay_spots places of the same table (its centre of mass over a grid point,
// those nearest the farther arm base first, at least relay_spacing from where it lay), resting as
// table_set_down_poses has it there. Empty when the part does not lie on a box obstacle.
std::vector<core::Pose> relay_set_down_poses(const core::Cell& cell, const core::TriangleMesh& mesh,
                                             const Eigen::Vector3d& com, const core::Pose& initial,
                                             const std::vector<db::PlacementRecord>& placements,
                                             const TableRegraspSettings& settings);

}  // namespace hila::offline
