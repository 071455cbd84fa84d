#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "pose_codec.hpp"
#include "util/test_util.hpp"

using namespace hila;
using namespace hila::db::detail;

namespace {
double max_error(const core::Pose& a, const core::Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}
}  // namespace

TEST(PoseCodec, RoundTripTo1e12OnRandomPoses) {
  std::mt19937_64 rng(42);
  for (int i = 0; i < 2000; ++i) {
    const core::Pose pose = test::random_pose(rng, 5.0);
    const PoseColumns c = encode_pose(pose);
    const auto back = decode_pose(c);
    ASSERT_TRUE(back.has_value()) << "pose " << i;
    EXPECT_LT(max_error(*back, pose), 1e-12) << "pose " << i;
    EXPECT_EQ(back->translation(), pose.translation()) << "translation is stored exactly";
  }
}

TEST(PoseCodec, QuaternionIsUnitWithNonNegativeW) {
  std::mt19937_64 rng(3);
  for (int i = 0; i < 500; ++i) {
    const PoseColumns c = encode_pose(test::random_pose(rng));
    EXPECT_GE(c[3], 0.0) << "pose " << i;
    EXPECT_NEAR(std::sqrt(c[3] * c[3] + c[4] * c[4] + c[5] * c[5] + c[6] * c[6]), 1.0, 1e-15);
  }
}

TEST(PoseCodec, RotationsThatDifferOnlyInQuaternionSignEncodeIdentically) {
  // A rotation close to a half turn: its matrix-derived quaternion may come out with w < 0.
  for (const Eigen::Vector3d& axis : {Eigen::Vector3d(1, 2, 3).normalized(),
                                      Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(0, -1, 0)}) {
    for (double angle : {core::kPi, core::kPi - 1e-9, -core::kPi + 1e-9, 3.0, -3.0}) {
      core::Pose a = core::Pose::Identity();
      a.linear() = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
      core::Pose b = core::Pose::Identity();
      // The same rotation reached through the negated quaternion.
      Eigen::Quaterniond q(Eigen::AngleAxisd(angle, axis));
      b.linear() = Eigen::Quaterniond(-q.coeffs()).toRotationMatrix();
      const PoseColumns ca = encode_pose(a);
      const PoseColumns cb = encode_pose(b);
      for (int k = 3; k < 7; ++k) EXPECT_NEAR(ca[k], cb[k], 1e-15) << "angle " << angle;
      EXPECT_GE(ca[3], 0.0);
    }
  }
}

TEST(PoseCodec, ExactHalfTurnHasPositiveFirstVectorComponent) {
  core::Pose pose = core::Pose::Identity();
  pose.linear() = Eigen::Vector3d(-1.0, 1.0, -1.0).asDiagonal();  // half turn about y
  const PoseColumns c = encode_pose(pose);
  EXPECT_EQ(c[3], 0.0);
  EXPECT_FALSE(std::signbit(c[3])) << "no -0.0";
  EXPECT_EQ(c[4], 0.0);
  EXPECT_NEAR(c[5], 1.0, 1e-15) << "qy must be +1, not -1";
  EXPECT_LT(max_error(*decode_pose(c), pose), 1e-15);
}

TEST(PoseCodec, IdentityIsExact) {
  const PoseColumns c = encode_pose(core::Pose::Identity());
  EXPECT_EQ(c, (PoseColumns{0, 0, 0, 1, 0, 0, 0}));
  EXPECT_TRUE(decode_pose(c)->isApprox(core::Pose::Identity(), 0.0));
}

TEST(PoseCodec, DecodeRejectsNonUnitQuaternionAndNonFiniteValues) {
  EXPECT_FALSE(decode_pose({0, 0, 0, 0, 0, 0, 0}).has_value());
  EXPECT_FALSE(decode_pose({0, 0, 0, 2, 0, 0, 0}).has_value());
  EXPECT_FALSE(decode_pose({0, 0, 0, 1, 1e-4, 0, 0}).has_value());
  EXPECT_FALSE(decode_pose({std::nan(""), 0, 0, 1, 0, 0, 0}).has_value());
  EXPECT_FALSE(
      decode_pose({std::numeric_limits<double>::infinity(), 0, 0, 1, 0, 0, 0}).has_value());
  // Within 1e-9 of unit length is accepted (and renormalised).
  EXPECT_TRUE(decode_pose({0, 0, 0, 1 + 1e-12, 0, 0, 0}).has_value());
}
