#include "hila/offline/grasp_common.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hila/core/mesh.hpp"

namespace hila::offline {

std::vector<ContactPair> sample_antipodal_pairs(const SurfaceQuery& surface,
                                                const AntipodalSettings& settings) {
  const double cos_cone = std::cos(std::atan(settings.friction));
  std::vector<ContactPair> pairs;
  for (const SurfacePoint& p : surface.sample_uniform(settings.samples, settings.seed)) {
    const Eigen::Vector3d inward = -p.normal;
    // Start a hair inside the surface so the ray does not hit the starting face again.
    const auto hit = surface.first_hit(p.point, inward, 1e-7);
    if (!hit) continue;
    ContactPair pair;
    pair.first = p;
    pair.second = *hit;
    const Eigen::Vector3d d = hit->point - p.point;
    pair.width = d.norm();
    if (pair.width < settings.min_width || pair.width > settings.max_width || pair.width < 1e-9) {
      continue;
    }
    pair.axis = d / pair.width;
    // The first normal is along the line by construction; the second must be inside the cone.
    pair.alignment = hit->normal.dot(pair.axis);
    if (pair.alignment < cos_cone) continue;
    pair.centre = 0.5 * (p.point + hit->point);
    pairs.push_back(pair);
  }
  return pairs;
}

std::vector<core::Pose> grasp_frames_about_axis(const ContactPair& pair, int count) {
  const Eigen::Vector3d y = pair.axis;
  Eigen::Index least = 0;
  y.cwiseAbs().minCoeff(&least);
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(least);
  const Eigen::Vector3d z0 = (e - e.dot(y) * y).normalized();
  std::vector<core::Pose> frames;
  frames.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const double angle = 2.0 * core::kPi * k / count;
    const Eigen::Vector3d z = Eigen::AngleAxisd(angle, y) * z0;
    core::Pose frame = core::Pose::Identity();
    frame.linear().col(0) = y.cross(z);
    frame.linear().col(1) = y;
    frame.linear().col(2) = z;
    frame.translation() = pair.centre;
    frames.push_back(frame);
  }
  return frames;
}

HandPartChecker::HandPartChecker(const HandGeometry& hand, const core::TriangleMesh& part) {
  model_.add_mesh_body("part", part, true);
  fixed_ = model_.add_body("hand", hand.fixed, false);
  finger_pos_ = model_.add_body("finger+", hand.finger_pos, false);
  finger_neg_ = model_.add_body("finger-", hand.finger_neg, false);
  // The hand's own parts may touch each other (pads closed, fingers on the palm).
  model_.allow(fixed_, finger_pos_);
  model_.allow(fixed_, finger_neg_);
  model_.allow(finger_pos_, finger_neg_);
  data_ = std::make_unique<core::CollisionData>(model_);
}

bool HandPartChecker::collides(const core::Pose& grasp_in_part, double opening) {
  data_->set_body_pose(fixed_, grasp_in_part);
  data_->set_body_pose(finger_pos_,
                       grasp_in_part * core::make_pose(Eigen::Vector3d(0, 0.5 * opening, 0)));
  data_->set_body_pose(finger_neg_,
                       grasp_in_part * core::make_pose(Eigen::Vector3d(0, -0.5 * opening, 0)));
  return core::in_collision(model_, *data_);
}

std::vector<TwoFingerGrasp> plan_two_finger_grasps(const core::TriangleMesh& mesh,
                                                   const Eigen::Vector3d& com,
                                                   const HandGeometry& hand,
                                                   const TwoFingerSettings& settings) {
  const SurfaceQuery surface(mesh);
  const std::vector<ContactPair> pairs = sample_antipodal_pairs(surface, settings.antipodal);
  HandPartChecker checker(hand, mesh);
  const double half_extent = 0.5 * (mesh.max_corner() - mesh.min_corner()).maxCoeff();
  const double reach = settings.max_tip_shift > 0.0 ? finger_reach(hand) : 0.0;
  std::vector<TwoFingerGrasp> candidates;
  for (const ContactPair& pair : pairs) {
    const double opening = std::min(pair.width + settings.opening_margin, settings.max_opening);
    for (core::Pose frame : grasp_frames_about_axis(pair, settings.approach_rotations)) {
      double shift = 0.0;
      if (settings.max_tip_shift > 0.0) {
        // The part's extent beyond the pair's centre along the approach.
        const Eigen::Vector3d z = frame.linear().col(2);
        double beyond = -std::numeric_limits<double>::infinity();
        for (const Eigen::Vector3d& v : mesh.vertices)
          beyond = std::max(beyond, (v - pair.centre).dot(z));
        const double past = reach - beyond;  // > 0: the fingertips stand out past the part
        if (past > 0.0) {
          shift = std::min(past + settings.tip_clearance, settings.max_tip_shift);
          frame.translation() -= shift * z;
        }
      }
      if (checker.collides(frame, opening)) continue;
      TwoFingerGrasp g;
      g.pair = pair;
      g.frame = frame;
      g.tip_shift = shift;
      g.lever = axis_lever(com, pair.centre, pair.axis);
      g.quality = 0.5 * pair.alignment + 0.5 * (1.0 - std::min(1.0, g.lever / half_extent));
      candidates.push_back(g);
    }
  }
  std::stable_sort(
      candidates.begin(), candidates.end(),
      [](const TwoFingerGrasp& a, const TwoFingerGrasp& b) { return a.quality > b.quality; });
  std::vector<core::Pose> poses;
  poses.reserve(candidates.size());
  for (const auto& g : candidates) poses.push_back(g.frame);
  std::vector<TwoFingerGrasp> kept;
  for (const int i :
       distinct_poses(poses, settings.merge_distance, core::deg_to_rad(settings.merge_angle_deg))) {
    kept.push_back(candidates[static_cast<std::size_t>(i)]);
  }
  return kept;
}

namespace {

// The largest z of a shape posed by its origin.
double top_z(const core::GeometrySpec& spec) {
  const Eigen::Matrix3d& r = spec.origin.linear();
  const double centre = spec.origin.translation().z();
  switch (spec.type) {
    case core::GeometrySpec::Type::Box:
      return centre + 0.5 * r.row(2).cwiseAbs().dot(spec.box_size);
    case core::GeometrySpec::Type::Cylinder:
      // The axis's half-length plus the rim's radius across it.
      return centre + 0.5 * spec.length * std::abs(r(2, 2)) +
             spec.radius * std::sqrt(std::max(0.0, 1.0 - r(2, 2) * r(2, 2)));
    case core::GeometrySpec::Type::Sphere:
      return centre + spec.radius;
    case core::GeometrySpec::Type::Mesh: {
      const core::TriangleMesh mesh = core::load_mesh(spec.mesh_path, 1.0);
      double top = -std::numeric_limits<double>::infinity();
      for (const Eigen::Vector3d& v : mesh.vertices) {
        top = std::max(top, (spec.origin * v.cwiseProduct(spec.mesh_scale)).z());
      }
      return top;
    }
  }
  return centre;
}

}  // namespace

double finger_reach(const HandGeometry& hand) {
  double reach = -std::numeric_limits<double>::infinity();
  for (const auto* group : {&hand.finger_pos, &hand.finger_neg}) {
    for (const core::GeometrySpec& spec : *group) reach = std::max(reach, top_z(spec));
  }
  return reach;
}

double axis_lever(const Eigen::Vector3d& com, const Eigen::Vector3d& point_on_axis,
                  const Eigen::Vector3d& axis) {
  const Eigen::Vector3d r = com - point_on_axis;
  return (r - r.dot(axis) * axis).norm();
}

std::vector<int> distinct_poses(const std::vector<core::Pose>& poses, double distance,
                                double angle) {
  std::vector<int> kept;
  Eigen::Matrix3d flip = Eigen::Matrix3d::Identity();
  flip(0, 0) = -1;
  flip(1, 1) = -1;  // rotation by pi about z
  for (int i = 0; i < static_cast<int>(poses.size()); ++i) {
    bool duplicate = false;
    for (const int k : kept) {
      if ((poses[i].translation() - poses[k].translation()).norm() > distance) continue;
      const Eigen::Matrix3d& a = poses[i].linear();
      const Eigen::Matrix3d& b = poses[k].linear();
      if (core::rotation_distance(a, b) <= angle || core::rotation_distance(a, b * flip) <= angle) {
        duplicate = true;
        break;
      }
    }
    if (!duplicate) kept.push_back(i);
  }
  return kept;
}

}  // namespace hila::offline
