#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/pose.hpp"

namespace hila::viz {

// A robot-robot exchange of the part (robot_handovers with a shared grasp): the suction arm
// holds the part on the tool's cup, the receiving arm's gripper closes on it.
struct ExchangeView {
  core::Pose board = core::Pose::Identity();  // world
  std::string suction_arm;
  Eigen::VectorXd suction_joints;  // rad
  std::string receiving_arm;
  Eigen::VectorXd receiving_joints;  // rad
  double jaw_opening = 0.0;          // m, the receiving grasp's jaw width
};

// A ranked handover goal (handover_candidates with a rank).
struct GoalView {
  int rank = 0;                               // 0-based, by Eq. 8
  core::Pose board = core::Pose::Identity();  // world
  double quality = 0.0;                       // Q, 0 to 1
  // RULA grand score (1-7) of the receiving posture, the worse hand's; 0: not scored.
  int rula_grand = 0;
  // Human arm name -> its joints (rad) in the receiving posture; the other arms neutral.
  std::map<std::string, Eigen::VectorXd> human_arms;
  std::optional<ExchangeView> exchange;  // empty: the robot at home, no exchange shown
};

enum class GoalColour {
  kQuality,  // by Q, from the lowest shown (red) to the highest (green)
  kRula,     // by RULA grand score: 1 green to 7 red (a goal not scored: grey)
};

struct GoalsSettings {
  GoalColour colour = GoalColour::kQuality;
  // Goal k's scene is moved by k * offset (world) so that the scenes stand side by side.
  Eigen::Vector3d offset{0.0, 2.0, 0.0};
};

struct GoalsView {
  std::string part;
  const core::TriangleMesh* mesh = nullptr;
  std::optional<core::Pose> human_stance;  // world; empty: the cell's
  std::vector<GoalView> goals;
};

// The goals as a glTF 2.0 binary (.glb): per goal a node "goal:RANK" at k * offset (k: its
// index in `goals`) holding, in world coordinates: the part "goal:RANK/part" at the goal's pose
// (material "Q V", scale_colour of Q from the lowest Q of `goals`, red, to the highest, green;
// with GoalColour::kRula material "RULA G", scale_colour((7 - G) / 6), "RULA -" grey unscored),
// the human "goal:RANK/human/LINK" at the stance in the receiving posture, the table
// "goal:RANK/obstacle/NAME", the robot "goal:RANK/robot/LINK" at the exchange's joints (the
// receiving jaws at its opening; home without an exchange), the suction tool in the suction
// arm's gripper "goal:RANK/tool/LINK" and the part at the exchange pose "goal:RANK/exchange".
// Throws core::InputError for an unknown arm, joints of the wrong size or a missing mesh.
std::string goals_glb(const core::Cell& cell, const GoalsView& view,
                      const GoalsSettings& settings = {});

}  // namespace hila::viz
