#include "hila/offline/ergonomics.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "hila/core/collision.hpp"
#include "hila/core/comfort.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/mesh_symmetry.hpp"
#include "hila/core/robot_model.hpp"
#include "hila/offline/handover.hpp"

namespace hila::offline {

namespace {

// The configuration variable that bends the torso forward: the joint above the arms' base link.
int torso_variable(const core::RobotModel& human, const std::vector<core::HumanArm>& arms) {
  if (arms.empty()) return -1;
  const int link = human.link_index(arms.front().spec.base_link);
  const int joint = human.links()[static_cast<std::size_t>(link)].parent_joint;
  return joint < 0 ? -1 : human.joints()[static_cast<std::size_t>(joint)].variable;
}

struct Scored {
  double map_quality;
  double shoulder_distance;
  int arm;
  int grasp;
};

}  // namespace

core::Pose table_drop_pose(const core::Cell& cell, const core::Pose& placement,
                           const ErgonomicsSettings& settings) {
  double top = 0.0;
  for (const auto& o : cell.spec().obstacles) {
    top = std::max(top, o.pose.translation().z() + 0.5 * o.size.z());
  }
  // Longest side across the human: turn the part's x axis (its length) onto world y.
  const Eigen::Vector3d x = placement.linear().col(0);
  const double yaw = std::atan2(1.0, 0.0) - std::atan2(x.y(), x.x());
  core::Pose pose = core::Pose::Identity();
  pose.translation() = Eigen::Vector3d(settings.table_spot_x, settings.table_spot_y, top);
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  core::Pose on_plane = placement;
  on_plane.translation().head<2>().setZero();  // the part's origin over the spot
  return pose * on_plane;
}

Posture receiving_posture(const core::Cell& cell, const HumanComfort& comfort,
                          const core::Pose& stance, const core::Pose& board,
                          const std::vector<db::HumanGraspRecord>& human_grasps,
                          const std::vector<int>& grasps, int only_arm,
                          const ErgonomicsSettings& settings, const core::HumanBody* body) {
  // A body that is the cell's human is searched as the cell's human: the same postures.
  if (body != nullptr && body->same_as_cell()) body = nullptr;
  Posture posture;
  posture.stance = stance;
  posture.board = board;
  const core::RobotModel& human = body != nullptr ? body->model() : cell.human();
  const std::vector<core::HumanArm>& human_arms =
      body != nullptr ? body->arms() : cell.human_arms();
  const int torso = torso_variable(human, human_arms);
  const double max_flexion = torso < 0 ? 0.0 : core::rad_to_deg(human.upper_limits()[torso]);
  Eigen::VectorXd q = body != nullptr ? body->neutral() : cell.human_neutral();
  std::vector<core::Pose> links;
  core::ComfortSettings ik;
  ik.ik_attempts = settings.ik_attempts;
  ik.seed = settings.seed;
  for (double flexion = 0.0; flexion <= max_flexion + 1e-9; flexion += settings.flexion_step_deg) {
    if (torso >= 0) q[torso] = core::deg_to_rad(flexion);
    human.link_poses(q, links);
    std::vector<Scored> scored;
    for (int a = 0; a < static_cast<int>(human_arms.size()); ++a) {
      if (only_arm >= 0 && a != only_arm) continue;
      const auto& arm = human_arms[static_cast<std::size_t>(a)];
      const core::Pose base =
          stance * links[static_cast<std::size_t>(human.link_index(arm.spec.base_link))];
      const core::Pose base_inv = base.inverse();
      for (const int g : grasps) {
        const core::Pose hand = base_inv * board * human_grasps[static_cast<std::size_t>(g)].hand;
        // The cell human's map serves a body at the hand's place scaled about its shoulder.
        const double map_quality =
            comfort.map(a).lookup(body != nullptr ? body->to_cell_arm(a, hand) : hand);
        scored.push_back(
            {map_quality, (hand.translation() - arm.chain.first_joint_position()).norm(), a, g});
      }
    }
    // Best by the map first; map misses (unsampled bins) by nearness to the shoulder.
    std::stable_sort(scored.begin(), scored.end(), [](const Scored& x, const Scored& y) {
      if (x.map_quality != y.map_quality) return x.map_quality > y.map_quality;
      return x.shoulder_distance < y.shoulder_distance;
    });
    const auto take = std::min<std::size_t>(scored.size(),
                                            static_cast<std::size_t>(settings.candidates_per_step));
    for (std::size_t i = 0; i < take; ++i) {
      const Scored& s = scored[i];
      const auto& arm = human_arms[static_cast<std::size_t>(s.arm)];
      const core::Pose base =
          stance * links[static_cast<std::size_t>(human.link_index(arm.spec.base_link))];
      const core::Pose hand =
          base.inverse() * board * human_grasps[static_cast<std::size_t>(s.grasp)].hand;
      const Eigen::VectorXd seed = Eigen::VectorXd::Zero(arm.chain.dof())
                                       .cwiseMax(arm.chain.lower_limits())
                                       .cwiseMin(arm.chain.upper_limits());
      const core::ComfortResult r = core::best_comfort(arm.chain, hand, seed, ik);
      if (r.reachable && (!posture.reachable || r.quality > posture.quality)) {
        posture.reachable = true;
        posture.quality = r.quality;
        posture.arm = s.arm;
        posture.grasp = s.grasp;
        posture.arm_joints = r.joints;
        posture.torso_flexion_deg = flexion;
      }
    }
    if (posture.reachable) break;
  }
  if (!posture.reachable) return posture;
  // Shoulder and elbow heights at the posture.
  const auto& arm = human_arms[static_cast<std::size_t>(posture.arm)];
  const auto& vars = arm.chain.model_variables();
  if (torso >= 0) q[torso] = core::deg_to_rad(posture.torso_flexion_deg);
  for (std::size_t i = 0; i < vars.size(); ++i) {
    q[vars[i]] = posture.arm_joints[static_cast<Eigen::Index>(i)];
  }
  posture.q = q;
  human.link_poses(q, links);
  auto joint_position = [&](const std::string& name) -> Eigen::Vector3d {
    const auto& joint = human.joints()[static_cast<std::size_t>(human.joint_index(name))];
    return (stance * links[static_cast<std::size_t>(joint.child_link)]).translation();
  };
  const auto& names = arm.chain.joint_names();
  const Eigen::Vector3d shoulder = joint_position(names.front());
  std::string elbow_name = names.size() > 3 ? names[3] : names.back();
  for (const auto& n : names) {
    if (n.find("elbow") != std::string::npos) elbow_name = n;
  }
  const Eigen::Vector3d elbow = joint_position(elbow_name);
  posture.shoulder_elevated = elbow.z() >= shoulder.z();
  const core::Pose hand_world = board * human_grasps[static_cast<std::size_t>(posture.grasp)].hand;
  posture.reach = (hand_world.translation() - shoulder).norm();
  return posture;
}

Turn turn_in_hands(const core::Cell& cell, const HumanComfort& comfort, const core::Pose& stance,
                   const core::Pose& from, const Eigen::Matrix3d& target,
                   const std::vector<Eigen::Matrix3d>& symmetries, const Eigen::Vector3d& com,
                   const core::TriangleMesh* mesh,
                   const std::vector<db::HumanGraspRecord>& human_grasps,
                   const std::vector<int>& grasps, const ErgonomicsSettings& settings,
                   const TurnSettings& turn, const core::HumanBody* body) {
  // The fitted orientation nearest the taken one: the part turned by a symmetry R is the same
  // part, so target R^T serves as well as target.
  Eigen::Matrix3d goal = target;
  double least = Eigen::AngleAxisd(from.linear().transpose() * target).angle();
  for (const Eigen::Matrix3d& r : symmetries) {
    const Eigen::Matrix3d candidate = target * r.transpose();
    const double angle = Eigen::AngleAxisd(from.linear().transpose() * candidate).angle();
    if (angle < least - 1e-12) {
      least = angle;
      goal = candidate;
    }
  }
  Turn best;
  best.turned_deg = core::rad_to_deg(least);
  if (best.turned_deg < 1e-6) return best;
  const int steps =
      std::max(1, static_cast<int>(std::ceil(best.turned_deg / turn.step_deg - 1e-9)));
  const Eigen::Quaterniond q0(from.linear()), q1(goal);
  const core::HeightBand band = core::natural_height_band(cell, body, stance);
  const Eigen::Vector3d forward = stance.linear().col(0);
  // The worker's body and the board, for the clearance check: the arms that hold the board may
  // touch it, the torso, head and legs may not. The model the postures are searched on (a body
  // that is the cell's human is the cell's human, as receiving_posture does).
  const core::HumanBody* searched = body != nullptr && !body->same_as_cell() ? body : nullptr;
  const core::RobotModel& human = searched != nullptr ? searched->model() : cell.human();
  core::CollisionModel clearance;
  core::RobotBodies human_bodies;
  int board_body = -1;
  if (mesh != nullptr) {
    human_bodies = core::add_robot(clearance, human, "human/");
    board_body = clearance.add_mesh_body("board", *mesh, false);
    for (const auto& arm : searched != nullptr ? searched->arms() : cell.human_arms()) {
      const auto& first = human.joints()[static_cast<std::size_t>(
          human.joint_index(arm.chain.joint_names().front()))];
      for (const int b : core::subtree_bodies(human, human_bodies, first.child_link)) {
        clearance.allow(board_body, b);
      }
    }
  }
  core::CollisionData clearance_data(clearance);
  std::vector<core::Pose> links;
  auto blocked = [&](const Posture& p, const core::Pose& board) {
    if (board_body < 0) return false;
    human.link_poses(p.q, links);
    core::set_robot_pose(clearance_data, human_bodies, links, p.stance);
    clearance_data.set_body_pose(board_body, board);
    return core::in_collision(clearance, clearance_data, std::vector<int>{board_body});
  };
  bool chosen = false;
  int best_unreachable = 0;
  for (const double fraction : turn.band_fractions) {
    for (const double distance : turn.distances) {
      Turn t;
      t.turned_deg = best.turned_deg;
      t.point = stance.translation() + distance * forward;
      t.point.z() = band.hip_z + fraction * (band.shoulder_z - band.hip_z);
      int unreachable = 0;
      for (int k = 0; k <= steps; ++k) {
        core::Pose board = core::Pose::Identity();
        board.linear() = q0.slerp(static_cast<double>(k) / steps, q1).toRotationMatrix();
        board.translation() = t.point - board.linear() * com;
        const Posture p = receiving_posture(cell, comfort, stance, board, human_grasps, grasps, -1,
                                            settings, body);
        const bool in_body = p.reachable && blocked(p, board);
        t.blocked.push_back(in_body);
        if (!p.reachable) {
          ++unreachable;
        } else if (in_body) {
          ++unreachable;
          ++t.blocked_steps;
        } else {
          t.elevated_steps += p.shoulder_elevated ? 1 : 0;
          t.max_flexion_deg = std::max(t.max_flexion_deg, p.torso_flexion_deg);
        }
        t.boards.push_back(board);
        t.postures.push_back(p);
      }
      t.reachable = unreachable == t.blocked_steps;
      const bool better =
          !chosen || unreachable < best_unreachable ||
          (unreachable == best_unreachable && (t.elevated_steps < best.elevated_steps ||
                                               (t.elevated_steps == best.elevated_steps &&
                                                t.max_flexion_deg < best.max_flexion_deg - 1e-9)));
      if (better) {
        best = std::move(t);
        best_unreachable = unreachable;
        chosen = true;
      }
    }
  }
  return best;
}

std::vector<db::ErgonomicsRecord> evaluate_ergonomics(const core::Cell& cell,
                                                      const HumanComfort& comfort,
                                                      const ErgonomicsInputs& in,
                                                      const ErgonomicsSettings& settings,
                                                      std::vector<Posture>* postures) {
  const auto& grasps = *in.human_grasps;
  std::vector<int> one_hand, all;
  for (std::size_t g = 0; g < grasps.size(); ++g) {
    all.push_back(static_cast<int>(g));
    if (grasps[g].one_hand_stable) one_hand.push_back(static_cast<int>(g));
  }
  // Two-hand boards: the posture of one hand (the better one) stands for both.
  const std::vector<int>& usable = one_hand.empty() ? all : one_hand;
  if (postures != nullptr) postures->clear();
  auto record = [&](const std::string& method, const core::Pose& board, const Posture& p) {
    if (postures != nullptr) postures->push_back(p);
    db::ErgonomicsRecord r;
    r.method = method;
    r.reachable = p.reachable;
    r.torso_flexion_deg = p.torso_flexion_deg;
    r.shoulder_elevated = p.shoulder_elevated;
    r.reach = p.reach;
    r.reorientation_deg =
        core::least_rotation_angle_deg(board.linear(), in.target.linear(), in.symmetries);
    r.quality = p.quality;
    r.arm = p.arm >= 0 ? comfort.arm_name(p.arm) : "";
    return r;
  };
  std::vector<db::ErgonomicsRecord> out;
  const core::Pose stance = in.stance.value_or(cell.spec().human_stance);
  if (in.has_goal) {
    const Posture p = receiving_posture(cell, comfort, stance, in.goal, grasps, {in.goal_grasp},
                                        in.goal_arm, settings, in.body);
    out.push_back(record("hila", in.goal, p));
  }
  if (in.has_placement) {
    const core::Pose table = table_drop_pose(cell, in.table_placement, settings);
    out.push_back(record(
        "table", table,
        receiving_posture(cell, comfort, stance, table, grasps, usable, -1, settings, in.body)));
  }
  // Alone, the human steps sideways to face the stack.
  core::Pose at_stack = stance;
  at_stack.translation().y() = in.initial.translation().y();
  out.push_back(record("alone", in.initial,
                       receiving_posture(cell, comfort, at_stack, in.initial, grasps, usable, -1,
                                         settings, in.body)));
  return out;
}

}  // namespace hila::offline
