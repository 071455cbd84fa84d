#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hila/core/bridge.hpp"
#include "hila/core/joint_box.hpp"
#include "hila/core/slip_projection.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// A board held at its edge: the opening axis along the TCP's y, the centre of mass off along x.
const Eigen::Vector3d kAxis = Eigen::Vector3d::UnitY();
const Eigen::Vector3d kLever = Eigen::Vector3d::UnitX();
const Eigen::Vector3d kDown(0.0, 0.0, -1.0);

const core::Arm& arm() {
  return test::reference_cell()->arms().front();
}
core::Pose base() {
  return core::arm_base_in_world(*test::reference_cell(), arm());
}

// The slip angle at q from the arm's FK, as the planner's check computes it.
double slip_at(const Eigen::VectorXd& q) {
  const core::Pose tcp = base() * arm().chain.fk(q);
  return core::slip_angle_deg(tcp.linear() * kAxis, tcp.linear() * kLever, kDown);
}

Eigen::VectorXd uniform(std::mt19937_64& rng) {
  const core::JointBox box = core::joint_box(arm(), M_PI);
  Eigen::VectorXd q(box.lower.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    q[i] = std::uniform_real_distribution<double>(box.lower[i], box.upper[i])(rng);
  }
  return q;
}

}  // namespace

TEST(SlipProjection, ConstraintIsTheSineOfTheSlipAngle) {
  const core::SlipProjection slip(arm(), base(), kAxis, kLever, 17.0);
  ASSERT_TRUE(slip.active());
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200; ++i) {
    const Eigen::VectorXd q = uniform(rng);
    EXPECT_NEAR(std::abs(slip.constraint(q)), std::sin(slip_at(q) * M_PI / 180.0), 1e-9);
  }
}

TEST(SlipProjection, GradientMatchesFiniteDifferences) {
  const core::SlipProjection slip(arm(), base(), kAxis, kLever, 17.0);
  std::mt19937_64 rng(13);
  const double h = 1e-6;
  for (int i = 0; i < 100; ++i) {
    const Eigen::VectorXd q = uniform(rng);
    const Eigen::VectorXd analytic = slip.gradient(q);
    ASSERT_EQ(analytic.size(), q.size());
    for (Eigen::Index j = 0; j < q.size(); ++j) {
      Eigen::VectorXd up = q;
      Eigen::VectorXd down = q;
      up[j] += h;
      down[j] -= h;
      const double numeric = (slip.constraint(up) - slip.constraint(down)) / (2.0 * h);
      EXPECT_NEAR(analytic[j], numeric, 1e-7) << "joint " << j << " at " << q.transpose();
    }
  }
}

TEST(SlipProjection, ProjectedSamplesHoldTheLimit) {
  for (const double theta_c : {5.0, 17.0, 45.0}) {
    SCOPED_TRACE("theta_c " + std::to_string(theta_c));
    const core::SlipProjection slip(arm(), base(), kAxis, kLever, theta_c);
    std::mt19937_64 rng(11);
    int projected = 0;
    int moved = 0;
    constexpr int kSamples = 300;
    for (int i = 0; i < kSamples; ++i) {
      const Eigen::VectorXd drawn = uniform(rng);
      Eigen::VectorXd q = drawn;
      if (!slip(q)) {
        EXPECT_EQ(q, drawn) << "a failed projection leaves the sample as drawn";
        continue;
      }
      ++projected;
      moved += q != drawn;
      EXPECT_LE(slip_at(q), theta_c + 1e-9) << q.transpose();
      // The band it keeps: |sin| within the default fill (0.8) of sin(theta_c).
      if (std::sin(slip_at(drawn) * M_PI / 180.0) <=
          0.8 * std::sin(theta_c * M_PI / 180.0) - 1e-9) {
        EXPECT_EQ(q, drawn) << "a sample well inside the limit is kept as it is";
      }
    }
    // Newton steps on one scalar: nearly every uniform sample reaches the limit.
    EXPECT_GE(projected, kSamples * 9 / 10);
    EXPECT_GT(moved, kSamples / 4) << "most uniform samples slip under these limits";
  }
}

TEST(SlipProjection, InactiveWithoutALimitOrALever) {
  std::mt19937_64 rng(3);
  const Eigen::VectorXd drawn = uniform(rng);
  for (const core::SlipProjection& slip :
       {core::SlipProjection(arm(), base(), kAxis, kLever, 90.0),
        core::SlipProjection(arm(), base(), kAxis, Eigen::Vector3d::Zero(), 17.0)}) {
    EXPECT_FALSE(slip.active());
    Eigen::VectorXd q = drawn;
    EXPECT_TRUE(slip(q));
    EXPECT_EQ(q, drawn);
  }
}

// A bridge whose validity is the slip limit alone: with the projection every sample it grows
// towards holds it, and the path it returns is valid at every waypoint and segment sample.
TEST(SlipProjection, ConstrainedBridgeKeepsTheLimit) {
  const double theta_c = 17.0;
  const core::SlipProjection slip(arm(), base(), kAxis, kLever, theta_c);
  const auto valid = [&](const Eigen::VectorXd& q) {
    return arm().chain.within_limits(q) && slip_at(q) <= theta_c;
  };
  std::mt19937_64 rng(5);
  Eigen::VectorXd from = uniform(rng);
  Eigen::VectorXd to = uniform(rng);
  ASSERT_TRUE(slip(from));
  ASSERT_TRUE(slip(to));
  ASSERT_TRUE(valid(from));
  ASSERT_TRUE(valid(to));
  core::BridgeSettings settings;
  settings.max_checks = 20000;
  settings.project = slip;
  const auto path = core::plan_bridge(arm(), valid, from, to, settings);
  ASSERT_GE(path.size(), 2u);
  EXPECT_EQ(path.front(), from);
  EXPECT_EQ(path.back(), to);
  for (std::size_t i = 1; i < path.size(); ++i) {
    EXPECT_TRUE(valid(path[i]));
    EXPECT_TRUE(core::segment_valid(valid, path[i - 1], path[i], settings.resolution));
  }
}

// The bridge's sampler draws through the projection: RRT-Connect grows towards states that hold
// the limit (its extensions are straight steps towards them, checked as ever).
TEST(SlipProjection, BridgeSamplesThroughTheProjection) {
  const double theta_c = 17.0;
  const core::SlipProjection slip(arm(), base(), kAxis, kLever, theta_c);
  std::mt19937_64 rng(5);
  Eigen::VectorXd from = uniform(rng);
  Eigen::VectorXd to = uniform(rng);
  ASSERT_TRUE(slip(from) && slip(to));
  const auto valid = [&](const Eigen::VectorXd& q) {
    return arm().chain.within_limits(q) && slip_at(q) <= theta_c;
  };
  long projected = 0;
  long holding = 0;
  core::BridgeSettings settings;
  settings.max_checks = 3000;
  settings.project = [&](Eigen::VectorXd& q) {
    ++projected;
    const bool ok = slip(q);
    holding += ok && slip_at(q) <= theta_c;
    return ok;
  };
  const auto path = core::plan_bridge(arm(), valid, from, to, settings);
  ASSERT_FALSE(path.empty());
  EXPECT_GT(projected, 10);
  EXPECT_GE(holding, projected * 9 / 10);
}
