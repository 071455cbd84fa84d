#pragma once

#include <Eigen/Core>

#include "hila/core/cell.hpp"

namespace hila::core {

// The joint box that roadmaps, bridges and LazyPRM sample.
struct JointBox {
  Eigen::VectorXd lower;
  Eigen::VectorXd upper;
};

// Each joint within its limits. A joint whose limits span more than `joint_range` each way
// reaches every configuration several times (a UR's +-2 pi joints): it is narrowed to home +-
// joint_range, one representative per configuration. A joint that cannot turn that far (a UR's
// elbow, limited to +-pi) keeps its whole range: narrowing it around home would cut off the
// configurations on the far side of its limit span.
JointBox joint_box(const Arm& arm, double joint_range);

}  // namespace hila::core
