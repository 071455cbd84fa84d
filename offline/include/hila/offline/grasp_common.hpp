#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "hila/core/collision.hpp"
#include "hila/core/pose.hpp"
#include "hila/offline/surface_query.hpp"

namespace hila::offline {

// An antipodal contact pair on a part: p1 and p2 with outward normals, p2 the first surface point
// behind p1 along -n1.
struct ContactPair {
  SurfacePoint first;
  SurfacePoint second;
  double width = 0.0;      // |p2 - p1|
  double alignment = 0.0;  // cos of the angle between -n2 and the p2 -> p1 direction
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();  // unit, p1 -> p2
};

struct AntipodalSettings {
  int samples = 1500;       // surface points tried as first contacts
  double friction = 0.5;    // mu of the contact: the friction cone half-angle is atan(mu)
  double min_width = 0.0;   // m
  double max_width = 0.08;  // m (jaw maximum minus the opening margin)
  std::uint64_t seed = 1;
};

// Antipodal pairs by ray shooting (paper §IV, Wan et al. 2016): each sampled point shoots a ray
// into the part along its inward normal; the exit point is kept when both normals lie inside the
// friction cone of the line joining them and the width fits. Deterministic for a seed.
std::vector<ContactPair> sample_antipodal_pairs(const SurfaceQuery& surface,
                                                const AntipodalSettings& settings);

// Grasp frames around a contact pair: y = the pair's axis (the opening/closing direction),
// z = approach, rotated in `count` even steps about y; origin at the pair's centre. The reference
// approach (step 0) is the part-frame axis least aligned with y, projected: deterministic.
std::vector<core::Pose> grasp_frames_about_axis(const ContactPair& pair, int count);

// A hand (gripper or human) as three collision bodies in its grasp frame: the fixed part (palm,
// sensor), and two fingers that move to +-opening/2 along y.
struct HandGeometry {
  std::vector<core::GeometrySpec> fixed;       // origins in the grasp frame
  std::vector<core::GeometrySpec> finger_pos;  // at opening 0, moving along +y
  std::vector<core::GeometrySpec> finger_neg;  // at opening 0, moving along -y
};

// Checks hand placements against one part (a static mesh body at the part frame origin).
// Construct one per thread.
class HandPartChecker {
 public:
  HandPartChecker(const HandGeometry& hand, const core::TriangleMesh& part);
  // True if the hand at `grasp_in_part`, opened to `opening`, touches the part.
  bool collides(const core::Pose& grasp_in_part, double opening);

 private:
  core::CollisionModel model_;
  int fixed_ = -1;
  int finger_pos_ = -1;
  int finger_neg_ = -1;
  std::unique_ptr<core::CollisionData> data_;
};

// A two-finger grasp found by plan_two_finger_grasps.
struct TwoFingerGrasp {
  ContactPair pair;
  core::Pose frame = core::Pose::Identity();  // grasp frame in the part frame
  double tip_shift = 0.0;  // m the frame is set back from the pair's centre along its approach
  double lever = 0.0;                         // CoM distance from the grasp axis
  double quality = 0.0;
};

struct TwoFingerSettings {
  AntipodalSettings antipodal;
  int approach_rotations = 12;
  double opening_margin = 0.005;  // the hand opens to width + margin (at most max_opening)
  double max_opening = 0.085;
  double merge_distance = 0.01;
  double merge_angle_deg = 20.0;
  // Fingertip grasps. Where the fingers, with the contact at the TCP, would reach past the part's
  // far side along the approach, they would strike whatever the part rests on there (a 20 mm
  // block on the table). Such a grasp is set back along its approach so the fingers end
  // `tip_clearance` short of the part, by at most `max_tip_shift` (m; 0: never). The contact
  // then lies that far from the TCP toward the fingertips.
  double max_tip_shift = 0.0;
  double tip_clearance = 0.002;  // m
};

// The grasp planner shared by the robot gripper and the human hand: antipodal pairs, frames about
// each axis, hand-part collision check, quality = 0.5 * alignment + 0.5 * (1 - lever / half the
// part's largest extent), best first (stable order), near-duplicates merged.
std::vector<TwoFingerGrasp> plan_two_finger_grasps(const core::TriangleMesh& mesh,
                                                   const Eigen::Vector3d& com,
                                                   const HandGeometry& hand,
                                                   const TwoFingerSettings& settings);

// How far the fingers (at opening 0) reach along the grasp frame's approach axis (z), m.
double finger_reach(const HandGeometry& hand);

// Distance of the centre of mass from the grasp axis line (the lever of the gravity torque).
double axis_lever(const Eigen::Vector3d& com, const Eigen::Vector3d& point_on_axis,
                  const Eigen::Vector3d& axis);

// Near-duplicate removal: keeps, in the given order, each pose farther than `distance` (m) or
// `angle` (rad) from every kept pose; a rotation by pi about z (a symmetric hand) counts as the
// same pose. Returns the kept indices.
std::vector<int> distinct_poses(const std::vector<core::Pose>& poses, double distance,
                                double angle);

}  // namespace hila::offline
