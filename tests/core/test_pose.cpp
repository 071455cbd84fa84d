#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "hila/core/error.hpp"
#include "hila/core/pose.hpp"
#include "util/test_util.hpp"

using namespace hila::core;
using namespace hila::test;

namespace {

// Smallest signed difference between two angles.
double angle_diff(double a, double b) {
  return std::remainder(a - b, 2.0 * kPi);
}

}  // namespace

TEST(Pose, RpyRoundTripOnRandomAngles) {
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> full(-kPi + 1e-6, kPi - 1e-6);
  // Stay away from the gimbal lock at pitch = +-pi/2, where roll and yaw are not unique.
  std::uniform_real_distribution<double> pitch(-kPi / 2 + 1e-3, kPi / 2 - 1e-3);
  for (int trial = 0; trial < 1000; ++trial) {
    const Eigen::Vector3d rpy(full(rng), pitch(rng), full(rng));
    const Eigen::Matrix3d r = rpy_to_matrix(rpy);
    ASSERT_TRUE(r.allFinite());
    EXPECT_NEAR((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
    const Eigen::Vector3d back = matrix_to_rpy(r);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(angle_diff(back[k], rpy[k]), 0.0, 1e-9) << "trial " << trial << " axis " << k;
    }
    EXPECT_LT((rpy_to_matrix(back) - r).cwiseAbs().maxCoeff(), 1e-12) << "trial " << trial;
  }
}

TEST(Pose, RpyConventionIsFixedXThenYThenZ) {
  // Roll alone turns y into z.
  const Eigen::Matrix3d roll = rpy_to_matrix(Eigen::Vector3d(kPi / 2, 0, 0));
  EXPECT_LT((roll * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  // Yaw alone turns x into y.
  const Eigen::Matrix3d yaw = rpy_to_matrix(Eigen::Vector3d(0, 0, kPi / 2));
  EXPECT_LT((yaw * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  // Pitch alone turns z into x.
  const Eigen::Matrix3d pitch = rpy_to_matrix(Eigen::Vector3d(0, kPi / 2, 0));
  EXPECT_LT((pitch * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  // Combined: R = Rz(yaw) * Ry(pitch) * Rx(roll) (roll applied first, about the fixed x axis).
  const Eigen::Vector3d rpy(0.3, -0.4, 1.1);
  const Eigen::Matrix3d expected = (Eigen::AngleAxisd(1.1, Eigen::Vector3d::UnitZ()) *
                                    Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()) *
                                    Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
                                       .toRotationMatrix();
  EXPECT_LT((rpy_to_matrix(rpy) - expected).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(Pose, MakePoseSetsTranslationAndRotation) {
  const Eigen::Vector3d xyz(0.1, -2.0, 3.5);
  const Eigen::Vector3d rpy(0.2, 0.3, -0.7);
  const Pose pose = make_pose(xyz, rpy);
  EXPECT_EQ(pose.translation(), xyz);
  EXPECT_LT((pose.linear() - rpy_to_matrix(rpy)).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(pose.matrix().row(3), Eigen::RowVector4d(0, 0, 0, 1));
  // A point in the pose frame maps to R p + t.
  const Eigen::Vector3d p(1.0, 2.0, 3.0);
  EXPECT_LT(((pose * p) - (rpy_to_matrix(rpy) * p + xyz)).norm(), 1e-12);

  const Pose translation_only = make_pose(xyz);
  EXPECT_TRUE(translation_only.linear().isIdentity(0.0));
  EXPECT_EQ(translation_only.translation(), xyz);
}

TEST(Pose, IsValidPose) {
  std::mt19937_64 rng(11);
  for (int i = 0; i < 20; ++i) EXPECT_TRUE(is_valid_pose(random_pose(rng)));
  EXPECT_TRUE(is_valid_pose(Pose::Identity()));

  Pose nan_translation = make_pose(Eigen::Vector3d(0.1, 0.2, 0.3));
  nan_translation.translation().y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(is_valid_pose(nan_translation));

  Pose nan_rotation = Pose::Identity();
  nan_rotation.linear()(1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(is_valid_pose(nan_rotation));

  Pose inf_translation = Pose::Identity();
  inf_translation.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(is_valid_pose(inf_translation));

  Pose scaled = make_pose(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1, 0.2, 0.3));
  scaled.linear() *= 1.01;
  EXPECT_FALSE(is_valid_pose(scaled));

  Pose sheared = Pose::Identity();
  sheared.linear()(0, 1) = 0.05;
  EXPECT_FALSE(is_valid_pose(sheared));

  Pose reflection = Pose::Identity();
  reflection.linear()(2, 2) = -1.0;  // orthonormal but det -1
  EXPECT_FALSE(is_valid_pose(reflection));

  // Within tolerance is accepted; the tolerance parameter is honoured.
  Pose almost = Pose::Identity();
  almost.linear()(0, 1) = 1e-9;
  EXPECT_TRUE(is_valid_pose(almost));
  Pose loose = Pose::Identity();
  loose.linear()(0, 1) = 1e-3;
  EXPECT_FALSE(is_valid_pose(loose));
  EXPECT_TRUE(is_valid_pose(loose, 1e-2));
}

TEST(Pose, CheckPoseNamesFileAndField) {
  EXPECT_NO_THROW(check_pose(make_pose(Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(0.1, 0.2, 0.3)),
                             "cell.yaml", "human.stance"));

  Pose nan_pose = Pose::Identity();
  nan_pose.translation().z() = std::numeric_limits<double>::quiet_NaN();
  expect_input_error([&] { check_pose(nan_pose, "some/dir/cell.yaml", "human.stance"); },
                     {"some/dir/cell.yaml", "human.stance", "finite"});

  Pose skewed = Pose::Identity();
  skewed.linear()(0, 1) = 0.2;
  expect_input_error([&] { check_pose(skewed, "product.yaml", "parts[3].target"); },
                     {"product.yaml", "parts[3].target", "orthonormal"});

  Pose reflection = Pose::Identity();
  reflection.linear()(0, 0) = -1.0;
  expect_input_error([&] { check_pose(reflection, "product.yaml", "assembly_frame"); },
                     {"product.yaml", "assembly_frame", "determinant"});

  // The accessors carry the same file and field.
  try {
    check_pose(skewed, "a.yaml", "b.c");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), "a.yaml");
    EXPECT_EQ(e.field(), "b.c");
    EXPECT_EQ(std::string(e.what()).rfind("a.yaml: b.c: expected ", 0), 0u) << e.what();
  }
}

TEST(Pose, RotationDistanceOfKnownAngle) {
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  EXPECT_NEAR(rotation_distance(identity, identity), 0.0, 1e-12);
  const Eigen::Matrix3d rz = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR(rotation_distance(identity, rz), 0.7, 1e-12);
  EXPECT_NEAR(rotation_distance(rz, identity), 0.7, 1e-12);
  // A half turn is the maximum.
  const Eigen::Matrix3d half = Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_NEAR(rotation_distance(identity, half), kPi, 1e-9);
  // 1.9 * pi about an axis is 0.1 * pi the other way.
  const Eigen::Matrix3d big =
      Eigen::AngleAxisd(1.9 * kPi, Eigen::Vector3d::UnitY()).toRotationMatrix();
  EXPECT_NEAR(rotation_distance(identity, big), 0.1 * kPi, 1e-9);

  // Independent of the common frame: d(R, R * Rel) = angle(Rel).
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> angle(0.0, kPi - 1e-3);
  for (int i = 0; i < 100; ++i) {
    const Eigen::Matrix3d r = random_pose(rng).linear();
    const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    const double a = angle(rng);
    const Eigen::Matrix3d rel = Eigen::AngleAxisd(a, axis).toRotationMatrix();
    EXPECT_NEAR(rotation_distance(r, r * rel), a, 1e-9);
    EXPECT_NEAR(rotation_distance(r * rel, r), a, 1e-9);
  }
}

TEST(Pose, DegreeConversions) {
  EXPECT_DOUBLE_EQ(deg_to_rad(180.0), kPi);
  EXPECT_DOUBLE_EQ(rad_to_deg(kPi / 2), 90.0);
  EXPECT_NEAR(rad_to_deg(deg_to_rad(-37.5)), -37.5, 1e-12);
}
