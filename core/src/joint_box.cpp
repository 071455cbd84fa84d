#include "hila/core/joint_box.hpp"

#include <algorithm>

namespace hila::core {

JointBox joint_box(const Arm& arm, double joint_range) {
  JointBox box{arm.chain.lower_limits(), arm.chain.upper_limits()};
  for (Eigen::Index i = 0; i < box.lower.size(); ++i) {
    if (box.upper[i] - box.lower[i] <= 2.0 * joint_range + 1e-9) continue;
    const double home = arm.spec.home[i];
    box.lower[i] = std::max(box.lower[i], home - joint_range);
    box.upper[i] = std::min(box.upper[i], home + joint_range);
  }
  return box;
}

}  // namespace hila::core
