#include "hila/core/pre_grasp.hpp"

#include "hila/core/bridge.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/core/ur_ik.hpp"

namespace hila::core {

std::vector<Eigen::Vector3d> pre_grasp_offsets(const Pose& grasp_tcp,
                                               const Eigen::Vector3d& approach_tcp,
                                               const Eigen::Vector3d& opening_tcp,
                                               double distance) {
  const Eigen::Vector3d back = -(grasp_tcp.linear() * approach_tcp.normalized());
  const Eigen::Vector3d along =
      grasp_tcp.linear() * approach_tcp.normalized().cross(opening_tcp.normalized());
  const double d = distance;
  return {d * back,   0.5 * d * back,  0.2 * d * back,  d * along,
          -d * along, 0.5 * d * along, -0.5 * d * along};
}

std::optional<Eigen::VectorXd> find_pre_grasp(
    const Cell& cell, const Arm& arm, const Eigen::VectorXd& grasp_q, double distance,
    double resolution, const std::function<bool(const Eigen::VectorXd&)>& valid) {
  const Pose base = arm_base_in_world(cell, arm);
  const Pose grasp_tcp = base * arm.chain.fk(grasp_q);
  const auto& gripper = cell.spec().gripper;
  UrIkSolutions ik;
  for (const Eigen::Vector3d& offset :
       pre_grasp_offsets(grasp_tcp, gripper.approach_axis, gripper.opening_axis, distance)) {
    Pose pre = grasp_tcp;
    pre.translation() += offset;
    // Sorted nearest the seed, within the limits: the first stays in the grasp's branch.
    if (arm.ur_ik->solve(base.inverse() * pre, grasp_q, ik) == 0) continue;
    const Eigen::VectorXd pre_q = ik.q.front();
    if (valid(pre_q) && segment_valid(valid, pre_q, grasp_q, resolution)) return pre_q;
  }
  return std::nullopt;
}

}  // namespace hila::core
