#pragma once

#include <vector>

#include "hila/core/cell.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/part_analysis.hpp"

namespace hila::offline {

struct SuctionSettings {
  int rotations = 12;              // tool rotations about the face normal (30 degrees)
  double min_area_fraction = 0.2;  // a "large" flat face has at least this share of the largest
};

// Suction grasps (paper §VI-A): the cup at the centre of mass projected onto each large flat
// face (the cup's disc must fit inside the face), the tool rotated about the normal in steps.
// Kept when the cup holds the part's weight (pull force) and the moment of the weight about the
// cup at the worst tilt (m g |CoM - cup|) within the cell's limits; margins are stored.
std::vector<db::SuctionGraspRecord> plan_suction_grasps(const core::TriangleMesh& mesh,
                                                        const PartAnalysis& analysis, double mass,
                                                        const core::Cell& cell,
                                                        const SuctionSettings& settings);

}  // namespace hila::offline
