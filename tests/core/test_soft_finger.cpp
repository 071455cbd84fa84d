#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hila/core/pose.hpp"
#include "hila/core/soft_finger.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {
constexpr double kG = 9.81;
constexpr double kCapacity = 1.0;  // N·m, the cell's calibration (DESIGN §3)
}  // namespace

TEST(SoftFinger, PaperRelaxationLimitsOfTheCabinetBoards) {
  // Paper §VII: 0.8 kg board at the middle of a long edge (lever 0.144 m) and of a short edge
  // (0.195 m); 1.8 kg board at a long edge (0.1475 m); the 0.22 kg back panel is unconstrained.
  EXPECT_EQ(core::relaxation_limit_deg(0.8, kG, 0.144, kCapacity), 62.0);
  EXPECT_EQ(core::relaxation_limit_deg(0.8, kG, 0.195, kCapacity), 40.0);
  EXPECT_EQ(core::relaxation_limit_deg(1.8, kG, 0.1475, kCapacity), 22.0);
  EXPECT_EQ(core::relaxation_limit_deg(0.22, kG, 0.1985, kCapacity), 90.0);
  // The 1.8 kg board at its short edge (lever 0.2935 m): the tight case of the roadmap issue.
  EXPECT_EQ(core::relaxation_limit_deg(1.8, kG, 0.2935, kCapacity), 11.0);
}

TEST(SoftFinger, RelaxationEqualsTheClosedFormOnRandomBoxes) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> mass(0.05, 5.0), lever(0.01, 0.5), step(0.25, 5.0);
  for (int i = 0; i < 5000; ++i) {
    const double m = mass(rng), r = lever(rng);
    core::RelaxationSettings settings;
    settings.step_deg = i % 2 ? 1.0 : step(rng);
    const double ratio = kCapacity / (m * kG * r);
    double expected = 90.0;
    if (ratio < 1.0) {
      const double limit = core::rad_to_deg(std::asin(ratio));
      expected = std::floor(limit / settings.step_deg + 1e-12) * settings.step_deg;
    }
    EXPECT_NEAR(core::relaxation_limit_deg(m, kG, r, kCapacity, settings), expected, 1e-9)
        << "m " << m << " r " << r << " step " << settings.step_deg;
  }
}

TEST(SoftFinger, MaximumGravityTorqueIsTheMaximumOverAzimuths) {
  // Brute force over rotations about the vertical: the largest |tau| equals m g r sin(theta).
  const Eigen::Vector3d gravity(0, 0, -kG);
  const double m = 1.3, r = 0.2;
  for (const double theta_deg : {0.0, 10.0, 45.0, 80.0, 90.0}) {
    const double theta = core::deg_to_rad(theta_deg);
    double best = 0.0;
    for (int k = 0; k < 3600; ++k) {
      const double azimuth = core::deg_to_rad(k * 0.1);
      // Axis tilted by theta from the vertical; the CoM perpendicular to it at distance r, in
      // every direction around the axis.
      const Eigen::Vector3d axis(std::sin(theta), 0, std::cos(theta));
      const Eigen::Vector3d u(std::cos(theta), 0, -std::sin(theta));
      const Eigen::Vector3d v = axis.cross(u);
      const Eigen::Vector3d com = r * (std::cos(azimuth) * u + std::sin(azimuth) * v);
      best = std::max(best, std::abs(core::gravity_torque_about_axis(axis, Eigen::Vector3d::Zero(),
                                                                     com, m, gravity / kG * kG)));
    }
    EXPECT_NEAR(best, core::max_gravity_torque(m, kG, r, theta), 1e-4) << theta_deg;
  }
}

TEST(SoftFinger, GravityTorqueHandWorked) {
  // Axis along x through the origin, CoM 0.1 m along y, gravity -z: tau = x . (0.1 y x -m g z)
  // = -0.1 m g.
  EXPECT_NEAR(
      core::gravity_torque_about_axis(Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero(),
                                      Eigen::Vector3d(0, 0.1, 0), 2.0, Eigen::Vector3d(0, 0, -kG)),
      -0.1 * 2.0 * kG, 1e-12);
  // CoM on the axis line: no torque.
  EXPECT_NEAR(
      core::gravity_torque_about_axis(Eigen::Vector3d::UnitX(), Eigen::Vector3d::Zero(),
                                      Eigen::Vector3d(0.3, 0, 0), 2.0, Eigen::Vector3d(0, 0, -kG)),
      0.0, 1e-12);
}

TEST(SoftFinger, WinklerEccentricityHandWorked) {
  core::SoftFingerPad pad;
  pad.elastic_modulus = 1e6;
  pad.thickness = 0.003;
  pad.radius_1 = pad.radius_2 = 0.05;
  // (100 * 0.003 * 0.05 / (1e6 * pi))^(1/4) = 8.3129e-3; times 16/15.
  const double expected = 16.0 / 15.0 * std::pow(100 * 0.003 * 0.05 / (1e6 * core::kPi), 0.25);
  EXPECT_NEAR(core::winkler_eccentricity(pad, 100.0), expected, 1e-15);
  EXPECT_NEAR(expected, 8.867e-3, 1e-6);
  // e_n grows as P^(1/4): 16 times the force, twice the eccentricity.
  EXPECT_NEAR(core::winkler_eccentricity(pad, 1600.0) / core::winkler_eccentricity(pad, 100.0), 2.0,
              1e-12);
  EXPECT_NEAR(core::finger_friction_torque(pad, 100.0), 0.8 * 100.0 * expected, 1e-15);
  EXPECT_EQ(core::winkler_eccentricity(pad, 0.0), 0.0);
}

TEST(SoftFinger, PredicateHandWorkedCases) {
  core::SoftFingerPad pad;
  const double p = 50.0;
  const double e = core::winkler_eccentricity(pad, p);
  const double mu_p = pad.friction * p;  // 40 N
  EXPECT_TRUE(core::soft_finger_holds(pad, p, 0.0, 0.0));
  EXPECT_TRUE(core::soft_finger_holds(pad, p, 0.999 * mu_p, 0.0));   // pure force inside the cone
  EXPECT_FALSE(core::soft_finger_holds(pad, p, 1.001 * mu_p, 0.0));  // and outside
  EXPECT_TRUE(core::soft_finger_holds(pad, p, 0.0, 0.999 * mu_p * e));  // pure torque limit
  EXPECT_FALSE(core::soft_finger_holds(pad, p, 0.0, 1.001 * mu_p * e));
  // On the ellipse: (0.6 mu P)^2 + (0.8 mu P e)^2 / e^2 = (mu P)^2.
  EXPECT_TRUE(core::soft_finger_holds(pad, p, 0.6 * mu_p, 0.79 * mu_p * e));
  EXPECT_FALSE(core::soft_finger_holds(pad, p, 0.6 * mu_p, 0.81 * mu_p * e));
  EXPECT_FALSE(core::soft_finger_holds(pad, 0.0, 0.1, 0.0));  // no grip, no hold
}
