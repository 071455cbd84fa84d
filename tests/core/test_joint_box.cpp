#include <gtest/gtest.h>

#include <cmath>

#include "hila/core/joint_box.hpp"
#include "util/test_util.hpp"

using namespace hila;

// The cell's UR3s: every joint turns +-2 pi except the elbow (+-pi, where the forearm folds onto
// the upper arm).
TEST(JointBox, TwoTurnJointsNarrowToOneTurnAroundHomeAndTheElbowKeepsItsLimits) {
  for (const char* name : {"left", "right"}) {
    SCOPED_TRACE(name);
    const core::Arm& arm = test::reference_cell()->arm(name);
    const core::JointBox box = core::joint_box(arm, M_PI);
    const Eigen::VectorXd lo = arm.chain.lower_limits();
    const Eigen::VectorXd hi = arm.chain.upper_limits();
    ASSERT_EQ(box.lower.size(), 6);
    for (int j = 0; j < 6; ++j) {
      if (j == 2) {
        EXPECT_NEAR(lo[j], -M_PI, 1e-12);
        EXPECT_NEAR(hi[j], M_PI, 1e-12);
        EXPECT_EQ(box.lower[j], lo[j]);
        EXPECT_EQ(box.upper[j], hi[j]);
      } else {
        EXPECT_NEAR(lo[j], -2.0 * M_PI, 1e-12);
        EXPECT_NEAR(box.lower[j], std::max(lo[j], arm.spec.home[j] - M_PI), 1e-12);
        EXPECT_NEAR(box.upper[j], std::min(hi[j], arm.spec.home[j] + M_PI), 1e-12);
      }
    }
  }
}

// Narrower ranges narrow every joint whose limits span more than twice the range, the elbow
// included (its +-pi span exceeds 2 * 1 rad).
TEST(JointBox, AJointIsNarrowedOnlyWhenItsLimitsSpanMoreThanTwiceTheRange) {
  const core::Arm& arm = test::reference_cell()->arm("left");
  const core::JointBox box = core::joint_box(arm, 1.0);
  for (int j = 0; j < 6; ++j) {
    EXPECT_NEAR(box.lower[j], std::max(arm.chain.lower_limits()[j], arm.spec.home[j] - 1.0), 1e-12);
    EXPECT_NEAR(box.upper[j], std::min(arm.chain.upper_limits()[j], arm.spec.home[j] + 1.0), 1e-12);
    EXPECT_LE(box.lower[j], arm.spec.home[j]);
    EXPECT_GE(box.upper[j], arm.spec.home[j]);
  }
}
