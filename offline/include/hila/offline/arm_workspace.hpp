#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/stage_scene.hpp"

namespace hila::offline {

// One arm moving through the static cell (table, robot body, the other arm at home, the human at
// the stance, the suction tool in the suction arm's hand) and the parts finished at the board's
// stage, optionally holding a board. The roadmaps are built against the empty cell; the board's
// filters and regrasp graph against its stage. Mutable: one per thread.
class ArmWorkspace {
 public:
  // `board`: the mesh a held board has (nullptr: the arm never holds one).
  // `finished`: parts standing in the cell (static), e.g. core::parts_before(product, index);
  // `stacked`: those still in the stack, e.g. core::parts_after(product, index).
  // `tool_on_table`: the suction tool's handle pose (world) where it stands on the table, not in
  // any hand (nullptr: in the suction arm's hand); the suction arm is then a gripper arm.
  ArmWorkspace(const core::Cell& cell, const std::string& arm, const std::string& suction_arm,
               const core::TriangleMesh* board = nullptr,
               const std::vector<core::PlacedPart>& finished = {},
               const std::vector<core::PlacedPart>& stacked = {},
               const core::Pose* tool_on_table = nullptr);

  const core::Cell& cell() const { return cell_; }
  const core::Arm& arm() const { return arm_; }
  int arm_index() const { return arm_index_; }
  bool is_suction_arm() const { return arm_index_ == scene_.suction_arm; }
  // This arm holds the tool (the suction arm, the tool not standing on the table).
  bool holds_tool() const { return is_suction_arm() && !tool_on_table_; }
  const core::Pose& base() const { return base_; }
  const core::StageScene& scene() const { return scene_; }

  // Within the joint limits and the arm (with the tool when it is the suction arm) clear of the
  // cell. Poses the arm: board_clear(q) may follow.
  bool arm_valid(const Eigen::VectorXd& q);

  // Holds the board at `board_in_tcp` with the gripper open to `jaw` (the suction arm: the jaw
  // is ignored, the board sits on the cup). Until release() the board follows the TCP.
  void hold(const core::Pose& board_in_tcp, double jaw);
  // Leaves the board standing at `world` (not held): an obstacle the arm checks against, except
  // the suction cup, which may touch it. release() parks it again.
  void place_board(const core::Pose& world);
  void release();
  bool holding() const { return holding_; }
  // The rest of the robot (the other arm, the jaws) at robot_q, the tool in the suction arm's
  // hand wherever that arm is; this arm's own joints stay each check's. The receiving arm's way
  // in to the exchange is checked with the suction arm there, not at home.
  void pose_rest(const Eigen::VectorXd& robot_q);

  // The held board clear of everything but what it touches (the arm as posed by q).
  bool board_clear(const Eigen::VectorXd& q);
  // arm_valid and, when holding, board_clear.
  bool valid(const Eigen::VectorXd& q) { return arm_valid(q) && (!holding_ || board_clear(q)); }

  // What makes q invalid, for diagnostics: "outside the joint limits", "BODY vs BODY" (the first
  // contact found) or "" when valid.
  std::string why_invalid(const Eigen::VectorXd& q);

  // The TCP in the world for arm joints q.
  core::Pose tcp(const Eigen::VectorXd& q) const { return base_ * arm_.chain.fk(q); }

 private:
  void pose_arm(const Eigen::VectorXd& q);

  const core::Cell& cell_;
  const core::Arm& arm_;
  int arm_index_ = 0;
  core::StageScene scene_;
  core::CollisionData data_;
  std::vector<int> arm_bodies_;
  std::vector<int> board_bodies_;
  std::vector<std::pair<int, int>> moving_links_;  // (link, body) of this arm
  std::vector<core::Pose> link_poses_;
  core::Pose base_;
  core::Pose board_in_tcp_ = core::Pose::Identity();
  bool holding_ = false;
  Eigen::VectorXd robot_q_;
  Eigen::VectorXd posed_;  // arm joints the scene is posed for
  bool tool_on_table_ = false;
};

}  // namespace hila::offline
