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
  g.finger_pos.push_back(
      box(hand.finger_width, hand.finger_thickness, hand.finger_length, {0, half, 0}));
  g.finger_neg.push_back(
      box(hand.finger_width, hand.finger_thickness, hand.finger_length, {0, -half, 0}));
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
  TwoFingerSettings two;
  two.antipodal.samples = settings.samples;
  two.antipodal.friction = hand.pad.friction;
  two.antipodal.min_width = hand.aperture_min;
  two.antipodal.max_width = hand.aperture_max - settings.opening_margin;
  two.antipodal.seed = settings.seed;
  two.approach_rotations = settings.approach_rotations;
  two.opening_margin = settings.opening_margin;
  two.max_opening = hand.aperture_max;
  two.merge_distance = settings.merge_distance;
  two.merge_angle_deg = settings.merge_angle_deg;
  std::vector<db::HumanGraspRecord> grasps;
  for (const TwoFingerGrasp& t :
       plan_two_finger_grasps(mesh, analysis.mass_properties.com, human_hand_geometry(hand), two)) {
    db::HumanGraspRecord g;
    g.hand = t.frame;
    g.aperture = t.pair.width;
    g.contact_1 = t.pair.first.point;
    g.contact_2 = t.pair.second.point;
    g.quality = t.quality;
    g.one_hand_stable = one_hand_holds(hand, mass, cell.spec().gravity, t.lever);
    grasps.push_back(g);
  }
  return grasps;
}

}  // namespace hila::offline
