#include "hila/offline/gripper_pick.hpp"

#include <algorithm>

#include "hila/core/pre_grasp.hpp"
#include "hila/offline/roadmap.hpp"

namespace hila::offline {

const char* to_string(GripperPickCheck check) {
  switch (check) {
    case GripperPickCheck::kReach:
      return "out of the arm's reach";
    case GripperPickCheck::kGraspClear:
      return "in collision at the grasp";
    case GripperPickCheck::kWayIn:
      return "no way in to the grasp";
    case GripperPickCheck::kLiftReach:
      return "no IK for the lift";
    case GripperPickCheck::kLiftClear:
      return "the lift blocked";
    case GripperPickCheck::kPicked:
      return "picked";
  }
  return "?";
}

GripperPick plan_gripper_pick(ArmWorkspace& workspace, const core::Pose& board_initial,
                              const db::RobotGraspRecord& grasp,
                              const GripperPickSettings& settings) {
  GripperPick pick;
  const core::Arm& arm = workspace.arm();
  if (!arm.ur_ik || workspace.holds_tool()) return pick;
  const core::Pose tcp = board_initial * grasp.tcp;
  const core::Pose base_inv = workspace.base().inverse();
  core::Pose lifted = tcp;
  lifted.translation().z() += settings.lift;
  const double jaw =
      std::min(workspace.cell().spec().gripper.jaw_max, grasp.jaw_width + settings.jaw_margin);
  core::UrIkSolutions ik;
  const int n = arm.ur_ik->solve(base_inv * tcp, arm.spec.home, ik);
  // The furthest check any branch passed.
  const auto reached = [&](GripperPickCheck c) {
    if (static_cast<int>(c) > static_cast<int>(pick.failed)) pick.failed = c;
  };
  if (n > 0) reached(GripperPickCheck::kGraspClear);
  for (int i = 0; i < n && !pick.ok(); ++i) {
    const Eigen::VectorXd q = ik.q[static_cast<std::size_t>(i)];
    workspace.place_board(board_initial);
    if (!workspace.arm_valid(q)) continue;
    reached(GripperPickCheck::kWayIn);
    const auto pre = core::find_pre_grasp(
        workspace.cell(), arm, q, settings.approach, settings.approach_resolution,
        [&](const Eigen::VectorXd& x) { return workspace.arm_valid(x); });
    if (!pre) continue;
    reached(GripperPickCheck::kLiftReach);
    core::UrIkSolutions lift_ik;
    if (arm.ur_ik->solve(base_inv * lifted, q, lift_ik) == 0) continue;
    reached(GripperPickCheck::kLiftClear);
    const Eigen::VectorXd up = lift_ik.q[0];
    workspace.hold(grasp.tcp.inverse(), jaw);
    bool free = workspace.valid(up);
    for (const auto& x : edge_samples(q, up, settings.resolution)) {
      if (!free) break;
      free = workspace.valid(x);
    }
    if (free) {
      pick.grasp = q;
      pick.lift = up;
      reached(GripperPickCheck::kPicked);
    }
  }
  workspace.release();
  return pick;
}

}  // namespace hila::offline
