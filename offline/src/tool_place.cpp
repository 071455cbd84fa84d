#include "hila/offline/tool_place.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "hila/core/collision.hpp"
#include "hila/core/ur_ik.hpp"
#include "hila/offline/arm_workspace.hpp"

namespace hila::offline {

namespace {

// Every part at its initial pose, or at its target (world).
std::vector<core::PlacedPart> all_parts(const core::ProductSpec& product, bool at_targets) {
  std::vector<core::PlacedPart> parts;
  for (const auto& p : product.parts) {
    parts.push_back({p.name, &p.mesh, at_targets ? product.target_in_world(p) : p.initial});
  }
  return parts;
}

// The cell obstacle whose top is the highest one under `point` (its box, in its own frame, spans
// the point's x and y); nullptr for none.
const core::BoxObstacle* surface_under(const core::Cell& cell, const Eigen::Vector3d& point) {
  const core::BoxObstacle* best = nullptr;
  double best_top = -std::numeric_limits<double>::infinity();
  for (const auto& o : cell.spec().obstacles) {
    const Eigen::Vector3d local = o.pose.inverse() * point;
    const Eigen::Vector3d half = 0.5 * o.size;
    if (std::abs(local.x()) > half.x() || std::abs(local.y()) > half.y()) continue;
    const double top = (o.pose * Eigen::Vector3d(local.x(), local.y(), half.z())).z();
    if (top <= point.z() && top > best_top) {
      best = &o;
      best_top = top;
    }
  }
  return best;
}

}  // namespace

bool reaches_tool_at(const core::Cell& cell, const std::string& arm, const core::Pose& handle,
                     const std::vector<core::PlacedPart>& finished,
                     const std::vector<core::PlacedPart>& stacked, double approach, double lift) {
  const core::Arm& a = cell.arm(arm);
  if (!a.ur_ik) return false;  // an arm without closed-form IK takes no tool
  const core::Pose base_inv = core::arm_base_in_world(cell, a).inverse();
  const core::Pose tcp = handle * cell.spec().suction.handle_in_tcp.inverse();
  core::UrIkSolutions ik;
  const int n = a.ur_ik->solve(base_inv * tcp, a.spec.home, ik);
  if (n == 0) return false;  // out of reach: no collision scene needed
  ArmWorkspace open_hand(cell, arm, arm, nullptr, finished, stacked, &handle);
  ArmWorkspace holding(cell, arm, arm, nullptr, finished, stacked);
  const Eigen::Vector3d approach_axis =
      tcp.linear() * cell.spec().gripper.approach_axis.normalized();
  core::Pose before = tcp;
  before.translation() -= approach * approach_axis;
  core::Pose raised = tcp;
  raised.translation().z() += lift;
  // The IK solution nearest `seed` at `pose`, if valid in `workspace`.
  core::UrIkSolutions near;
  auto valid_near = [&](const core::Pose& pose, const Eigen::VectorXd& seed,
                        ArmWorkspace& workspace) {
    const int m = a.ur_ik->solve(base_inv * pose, seed, near);
    return m > 0 && workspace.arm_valid(near.q.front());
  };
  for (int k = 0; k < n; ++k) {
    const Eigen::VectorXd q = ik.q[static_cast<std::size_t>(k)];
    if (open_hand.arm_valid(q) && valid_near(before, q, open_hand) &&
        valid_near(raised, q, holding)) {
      return true;
    }
  }
  return false;
}

bool reaches_tool_stand(const core::Cell& cell, const core::ProductSpec& product, std::size_t index,
                        const std::string& arm, double approach, double lift) {
  return reaches_tool_at(cell, arm, product.suction_tool_pose, core::parts_before(product, index),
                         core::parts_after(product, index), approach, lift);
}

ToolRelay find_tool_relay(const core::Cell& cell, const core::ProductSpec& product,
                          const ToolRelaySettings& settings) {
  ToolRelay relay;
  const core::Pose& stand = product.suction_tool_pose;
  const core::BoxObstacle* table = surface_under(cell, stand.translation());
  if (table == nullptr || !(settings.spacing > 0.0) || settings.yaw_steps < 1) return relay;

  // The standing tool against the parts (both poses) and the robot at home; the tool's own links
  // are one rigid body, and its foot on the table is the stand's contact, so the table is left out.
  core::CollisionModel model;
  for (const auto& p : product.parts) {
    model.add_mesh_body("initial/" + p.name, p.mesh, true, p.initial);
    model.add_mesh_body("target/" + p.name, p.mesh, true, product.target_in_world(p));
  }
  const core::RobotBodies robot = core::add_robot(model, cell.robot(), "robot/", true);
  const core::RobotModel& tool_model = cell.suction_tool();
  const core::RobotBodies tool = core::add_robot(model, tool_model, "tool/");
  std::vector<int> tool_bodies;
  for (const int b : tool.link_to_body) {
    if (b >= 0) tool_bodies.push_back(b);
  }
  for (const int a : tool_bodies) {
    for (const int b : tool_bodies) {
      if (a < b) model.allow(a, b);
    }
  }
  core::CollisionData data(model);
  std::vector<core::Pose> poses;
  cell.robot().link_poses(cell.home_configuration(), poses);
  core::set_robot_pose(data, robot, poses);
  tool_model.link_poses(tool_model.neutral_configuration(), poses);
  const core::Pose handle_in_tool =
      poses[static_cast<std::size_t>(tool_model.link_index(cell.spec().suction.handle_link))];

  // Candidates in grid order, scored by the farthest arm base's distance (x, y).
  struct Candidate {
    core::Pose handle;
    bool roomy = false;  // clear of the parts and the robot by the clearance, not only apart
    double score = 0.0;
  };
  std::vector<Candidate> candidates;
  const Eigen::Vector3d half = 0.5 * table->size;
  const int nx = static_cast<int>(std::floor(table->size.x() / settings.spacing));
  const int ny = static_cast<int>(std::floor(table->size.y() / settings.spacing));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      const Eigen::Vector3d local(-half.x() + i * settings.spacing,
                                  -half.y() + j * settings.spacing, half.z());
      Eigen::Vector3d at = table->pose * local;
      at.z() = stand.translation().z();
      for (int k = 0; k < settings.yaw_steps; ++k) {
        core::Pose place = core::Pose::Identity();
        place.linear() =
            Eigen::AngleAxisd(2.0 * M_PI * k / settings.yaw_steps, Eigen::Vector3d::UnitZ()) *
            stand.linear();
        place.translation() = at;
        ++relay.places;
        core::set_robot_pose(data, tool, poses, place * handle_in_tool.inverse());
        // Contact first: FCL's distance query between touching shapes runs its penetration
        // (EPA) code, which asserts on some mesh pairs.
        if (core::in_collision(model, data, tool_bodies)) continue;
        const double distance = core::min_distance(model, data);
        if (!(distance > 0.0)) continue;
        const bool roomy = distance >= settings.clearance;
        relay.clear += roomy ? 1 : 0;
        double score = 0.0;
        for (const auto& arm : cell.arms()) {
          const Eigen::Vector3d base = core::arm_base_in_world(cell, arm).translation();
          score = std::max(score, (at - base).head<2>().norm());
        }
        candidates.push_back({place, roomy, score});
      }
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) {
                     return a.roomy != b.roomy ? a.roomy : a.score < b.score;
                   });
  const auto initial = all_parts(product, false);
  const auto targets = all_parts(product, true);
  for (const auto& c : candidates) {
    bool every_arm = true;
    for (const auto& arm : cell.arms()) {
      every_arm = every_arm && reaches_tool_at(cell, arm.spec.name, c.handle, targets, initial,
                                               settings.approach, settings.lift);
    }
    if (every_arm) {
      relay.handle = c.handle;
      break;
    }
  }
  return relay;
}

}  // namespace hila::offline
