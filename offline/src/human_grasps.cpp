#include "hila/offline/human_grasps.hpp"

#include <algorithm>
#include <cmath>

#include "hila/core/soft_finger.hpp"

namespace hila::offline {

namespace {
core::GeometrySpec box(double x, double y, double z, const Eigen::Vector3d& centre) {
  core::GeometrySpec g;
  g.type = core::GeometrySpec::Type::Box;
  g.box_size = {x, y, z};
  g.origin = core::make_pose(centre);
  return g;
}

core::SoftFingerPad skin(const core::HumanHandSpec& hand) {
  return {hand.pad.friction, hand.pad.elastic_modulus, hand.pad.thickness, hand.pad.radius_1,
          hand.pad.radius_2};
}
}  // namespace

HandGeometry human_hand_geometry(const core::HumanHandSpec& hand) {
  HandGeometry g;
  // Fingers: slabs whose inner faces are at +-opening/2, centred on the grasp point.
  const double half = 0.5 * hand.finger_thickness;
  g.finger_pos.push_back(box(hand.finger_width, hand.finger_thickness, hand.finger_length, {0, half, 0}));
  g.finger_neg.push_back(box(hand.finger_width, hand.finger_thickness, hand.finger_length, {0, -half, 0}));
  // Palm behind the fingertips (toward the wrist, -z), spanning the closed hand.
  g.fixed.push_back(box(hand.palm_width, hand.palm_thickness, hand.palm_length,
                        {0, 0, -0.5 * hand.finger_length - 0.5 * hand.palm_length}));
  return g;
}

bool one_hand_holds(const core::HumanHandSpec& hand, double mass, double gravity, double lever) {
  const double weight = mass * gravity;
  return core::soft_finger_holds(skin(hand), hand.grip_force, 0.5 * weight, 0.5 * weight * lever);
}

std::vector<db::HumanGraspRecord> plan_human_grasps(const core::TriangleMesh& mesh,
                                                    const PartAnalysis& analysis, double mass,
                                                    const core::Cell& cell,
                                                    const HumanGraspSettings& settings) {
  const auto& hand = cell.spec().human_hand;
  const SurfaceQuery surface(mesh);
  AntipodalSettings antipodal;
  antipodal.samples = settings.samples;
  antipodal.friction = hand.pad.friction;
  antipodal.min_width = hand.aperture_min;
  antipodal.max_width = hand.aperture_max - settings.opening_margin;
  antipodal.seed = settings.seed;
  const std::vector<ContactPair> pairs = sample_antipodal_pairs(surface, antipodal);

  HandPartChecker checker(human_hand_geometry(hand), mesh);
  const Eigen::Vector3d com = analysis.mass_properties.com;
  const double half_extent = 0.5 * (mesh.max_corner() - mesh.min_corner()).maxCoeff();
  std::vector<db::HumanGraspRecord> candidates;
  for (const ContactPair& pair : pairs) {
    const double opening = std::min(pair.width + settings.opening_margin, hand.aperture_max);
    for (const core::Pose& frame : grasp_frames_about_axis(pair, settings.approach_rotations)) {
      if (checker.collides(frame, opening)) continue;
      db::HumanGraspRecord g;
      g.hand = frame;
      g.aperture = pair.width;
      g.contact_1 = pair.first.point;
      g.contact_2 = pair.second.point;
      const double lever = axis_lever(com, pair.centre, pair.axis);
      g.quality = 0.5 * pair.alignment + 0.5 * (1.0 - std::min(1.0, lever / half_extent));
      g.one_hand_stable = one_hand_holds(hand, mass, cell.spec().gravity, lever);
      candidates.push_back(g);
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const db::HumanGraspRecord& a, const db::HumanGraspRecord& b) {
                     return a.quality > b.quality;
                   });
  std::vector<core::Pose> poses;
  for (const auto& g : candidates) poses.push_back(g.hand);
  std::vector<db::HumanGraspRecord> grasps;
  for (const int i : distinct_poses(poses, settings.merge_distance,
                                    core::deg_to_rad(settings.merge_angle_deg))) {
    grasps.push_back(candidates[static_cast<std::size_t>(i)]);
  }
  return grasps;
}

}  // namespace hila::offline
