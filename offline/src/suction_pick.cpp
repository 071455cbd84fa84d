#include "hila/offline/suction_pick.hpp"

#include "hila/offline/roadmap.hpp"

namespace hila::offline {

SuctionPick plan_suction_pick(ArmWorkspace& workspace, const core::Pose& board_initial,
                              const db::SuctionGraspRecord& grasp, double lift, double resolution) {
  SuctionPick pick;
  const core::Arm& arm = workspace.arm();
  const core::Pose board_in_tcp = workspace.scene().cup_in_tcp * grasp.cup.inverse();
  const core::Pose tcp = board_initial * board_in_tcp.inverse();
  const core::Pose base_inv = workspace.base().inverse();
  core::UrIkSolutions ik;
  const int n = arm.ur_ik->solve(base_inv * tcp, arm.spec.home, ik);
  core::Pose lifted = tcp;
  lifted.translation().z() += lift;
  for (int i = 0; i < n; ++i) {
    const Eigen::VectorXd q = ik.q[static_cast<std::size_t>(i)];
    workspace.place_board(board_initial);
    if (!workspace.arm_valid(q)) continue;
    if (pick.lift.size() == 0) {
      core::UrIkSolutions lift_ik;
      if (arm.ur_ik->solve(base_inv * lifted, q, lift_ik) > 0) {
        const Eigen::VectorXd up = lift_ik.q[0];
        workspace.hold(board_in_tcp, 0.0);
        bool free = workspace.valid(up);
        for (const auto& x : edge_samples(q, up, resolution)) {
          if (!free) break;
          free = workspace.valid(x);
        }
        if (free) {
          pick.lift = up;
          pick.solutions.insert(pick.solutions.begin(), q);
          continue;
        }
      }
    }
    pick.solutions.push_back(q);
  }
  workspace.release();
  return pick;
}

}  // namespace hila::offline
