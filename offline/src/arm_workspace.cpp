#include "hila/offline/arm_workspace.hpp"

#include <algorithm>

#include "hila/core/error.hpp"

namespace hila::offline {

namespace {

const core::Pose kParked(Eigen::Translation3d(100.0, 100.0, 100.0));

// A stand-in when no board is ever held: the scene needs a board body; it stays disabled.
const core::TriangleMesh& placeholder_board() {
  static const core::TriangleMesh mesh = [] {
    core::TriangleMesh m;
    for (int i = 0; i < 8; ++i) {
      m.vertices.emplace_back((i & 1) ? 0.01 : 0.0, (i & 2) ? 0.01 : 0.0, (i & 4) ? 0.01 : 0.0);
    }
    m.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                   {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    return m;
  }();
  return mesh;
}

int arm_index_of(const core::Cell& cell, const core::Arm& arm) {
  int i = 0;
  while (&cell.arms()[static_cast<std::size_t>(i)] != &arm) ++i;
  return i;
}

}  // namespace

ArmWorkspace::ArmWorkspace(const core::Cell& cell, const std::string& arm,
                           const std::string& suction_arm, const core::TriangleMesh* board,
                           const std::vector<core::PlacedPart>& finished,
                           const std::vector<core::PlacedPart>& stacked,
                           const core::Pose* tool_on_table)
    : cell_(cell),
      arm_(cell.arm(arm)),
      arm_index_(arm_index_of(cell, arm_)),
      scene_(core::build_stage_scene(cell, board ? *board : placeholder_board(), finished,
                                     suction_arm, stacked)),
      data_(scene_.cell.model),
      arm_bodies_(scene_.cell.arm_bodies[static_cast<std::size_t>(arm_index_)]),
      board_bodies_{scene_.board},
      base_(core::arm_base_in_world(cell, arm_)),
      robot_q_(cell.home_configuration()),
      tool_on_table_(tool_on_table != nullptr) {
  if (!board) scene_.cell.model.set_enabled(scene_.board, false);
  // While held, the board is rigid with the last arm link and everything below it (the hand, and
  // the tool on the suction arm): the grasp planners checked those pairs at the grasp, and they
  // cannot change, so checking them at every sample would only cost time.
  if (board) {
    const core::RobotModel& robot = cell.robot();
    int root = robot.link_index(arm_.spec.flange_link);
    for (;;) {
      const int joint = robot.links()[static_cast<std::size_t>(root)].parent_joint;
      if (joint < 0) break;
      const auto& j = robot.joints()[static_cast<std::size_t>(joint)];
      if (j.type != core::JointType::Fixed) break;
      root = j.parent_link;
    }
    std::vector<int> rigid = core::subtree_bodies(robot, scene_.cell.robot, root);
    if (holds_tool())
      rigid.insert(rigid.end(), scene_.tool_bodies.begin(), scene_.tool_bodies.end());
    for (const int b : rigid) scene_.cell.model.allow(scene_.board, b);
  }
  // Only this arm's links move: the rest of the robot stays as posed here.
  const auto& link_to_body = scene_.cell.robot.link_to_body;
  for (std::size_t link = 0; link < link_to_body.size(); ++link) {
    const int b = link_to_body[link];
    if (b >= 0 && std::find(arm_bodies_.begin(), arm_bodies_.end(), b) != arm_bodies_.end()) {
      moving_links_.emplace_back(static_cast<int>(link), b);
    }
  }
  if (holds_tool()) {
    arm_bodies_.insert(arm_bodies_.end(), scene_.tool_bodies.begin(), scene_.tool_bodies.end());
  }
  core::set_cell_state(cell_, scene_.cell, data_, robot_q_, cell_.human_neutral());
  if (tool_on_table != nullptr) {
    core::set_robot_pose(data_, scene_.tool, scene_.tool_links_in_handle, *tool_on_table);
  } else {
    const core::Arm& tool_arm = cell_.arms()[static_cast<std::size_t>(scene_.suction_arm)];
    core::set_tool_held(
        cell_, scene_, data_,
        core::arm_base_in_world(cell_, tool_arm) * tool_arm.chain.fk(tool_arm.spec.home));
  }
  data_.set_body_pose(scene_.board, kParked);
}

void ArmWorkspace::pose_arm(const Eigen::VectorXd& q) {
  cell_.set_arm(robot_q_, arm_, q);
  cell_.robot().link_poses(robot_q_, link_poses_);
  for (const auto& [link, body] : moving_links_) {
    data_.set_body_pose(body, link_poses_[static_cast<std::size_t>(link)]);
  }
  const core::Pose tcp_world = tcp(q);
  if (holds_tool()) core::set_tool_held(cell_, scene_, data_, tcp_world);
  if (holding_) data_.set_body_pose(scene_.board, tcp_world * board_in_tcp_);
  posed_ = q;
}

bool ArmWorkspace::arm_valid(const Eigen::VectorXd& q) {
  if (!arm_.chain.within_limits(q, 1e-12)) return false;
  pose_arm(q);
  return !core::in_collision(scene_.cell.model, data_, arm_bodies_);
}

void ArmWorkspace::hold(const core::Pose& board_in_tcp, double jaw) {
  if (!scene_.cell.model.is_enabled(scene_.board)) {
    throw std::logic_error("ArmWorkspace::hold: built without a board mesh");
  }
  board_in_tcp_ = board_in_tcp;
  holding_ = true;
  if (!holds_tool()) cell_.set_jaw(robot_q_, arm_, jaw);
  posed_.resize(0);
}

void ArmWorkspace::place_board(const core::Pose& world) {
  if (!scene_.cell.model.is_enabled(scene_.board)) {
    throw std::logic_error("ArmWorkspace::place_board: built without a board mesh");
  }
  release();
  data_.set_body_pose(scene_.board, world);
}

void ArmWorkspace::release() {
  holding_ = false;
  if (!holds_tool()) cell_.set_jaw(robot_q_, arm_, cell_.spec().gripper.jaw_max);
  data_.set_body_pose(scene_.board, kParked);
  posed_.resize(0);
}

void ArmWorkspace::pose_rest(const Eigen::VectorXd& robot_q) {
  robot_q_ = robot_q;
  core::set_robot_state(cell_, scene_.cell, data_, robot_q_);
  if (tool_on_table_) {
    posed_.resize(0);
    return;
  }
  const core::Arm& tool_arm = cell_.arms()[static_cast<std::size_t>(scene_.suction_arm)];
  core::set_tool_held(cell_, scene_, data_,
                      core::arm_base_in_world(cell_, tool_arm) *
                          tool_arm.chain.fk(cell_.arm_joints(robot_q_, tool_arm)));
  posed_.resize(0);
}

std::string ArmWorkspace::why_invalid(const Eigen::VectorXd& q) {
  if (!arm_.chain.within_limits(q, 1e-12)) return "outside the joint limits";
  pose_arm(q);
  core::CollisionPair pair;
  const auto& model = scene_.cell.model;
  if (core::in_collision(model, data_, arm_bodies_, &pair) ||
      (holding_ && core::in_collision(model, data_, board_bodies_, &pair))) {
    return model.body_name(pair.body_a) + " vs " + model.body_name(pair.body_b);
  }
  return "";
}

bool ArmWorkspace::board_clear(const Eigen::VectorXd& q) {
  if (!holding_) return true;
  if (posed_.size() != q.size() || posed_ != q) pose_arm(q);
  return !core::in_collision(scene_.cell.model, data_, board_bodies_);
}

}  // namespace hila::offline
