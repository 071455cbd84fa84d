#pragma once

#include <vector>

#include "hila/core/cell.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/grasp_common.hpp"
#include "hila/offline/part_analysis.hpp"

namespace hila::offline {

struct HumanGraspSettings {
  int samples = 800;
  int approach_rotations = 12;
  double opening_margin = 0.01;   // m
  double merge_distance = 0.015;  // m
  double merge_angle_deg = 20.0;
  std::uint64_t seed = 2;
};

// The human hand of the cell as HandGeometry: thumb and finger slabs at +-aperture/2, the palm
// behind the fingertips.
HandGeometry human_hand_geometry(const core::HumanHandSpec& hand);

// Whether one hand holds the part with this grasp (soft-finger predicate, paper Eq. 2): each
// fingertip carries half the weight as tangential force and half the worst-case gravity torque
// m g lever about its normal, at the hand's grip force.
bool one_hand_holds(const core::HumanHandSpec& hand, double mass, double gravity, double lever);

// Human grasps: the same antipodal planner with the hand's aperture, pads (mu = 0.8) and a simple
// hand collision model; quality as for robot grasps; one_hand_stable recorded per grasp.
std::vector<db::HumanGraspRecord> plan_human_grasps(const core::TriangleMesh& mesh,
                                                    const PartAnalysis& analysis, double mass,
                                                    const core::Cell& cell,
                                                    const HumanGraspSettings& settings);

}  // namespace hila::offline
