#pragma once

#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/online/scene.hpp"

namespace hila::online {

// The scene as one collision world for handling one board: the cell with the human at the
// scene's stance, the finished boards where the scene says, the boards still in the stack where
// the scene has them (detected, else nominal), the board and the suction tool (both moving) and
// the scene's extra obstacles (static). Const after construction: one
// CollisionData per thread (make_data()).
// The arm that holds the suction tool when the database gives a board no other (the build's
// default roles: offline::HandoverSettings::suction_arm).
inline constexpr const char* kDefaultSuctionArm = "right";

class World {
 public:
  World(const core::Cell& cell, const core::ProductSpec& product, const Scene& scene,
        const std::string& board, const std::string& suction_arm = kDefaultSuctionArm);

  const core::Cell& cell() const { return cell_; }
  const core::StageScene& stage() const { return stage_; }
  const core::PartSpec& board() const { return board_; }
  const std::vector<int>& obstacles() const { return obstacles_; }  // the scene's extra bodies
  // A CollisionData with the human at the scene's stance, the board at its initial pose, the
  // tool where the scene has it (on the table, or in the suction arm's hand at its current
  // joints) and the robot at the scene's joints.
  core::CollisionData make_data() const;
  // Poses the suction tool: in the suction arm's hand at its joints in `robot_q` (whole-robot FK),
  // or standing on the table at `on_table` (its handle, world).
  void place_tool(core::CollisionData& data, const Eigen::VectorXd& robot_q, bool in_hand,
                  const core::Pose& on_table) const;

 private:
  const core::Cell& cell_;
  const core::PartSpec& board_;
  Scene scene_;
  std::vector<core::PlacedPart> finished_;
  core::StageScene stage_;
  std::vector<int> obstacles_;
};

}  // namespace hila::online
