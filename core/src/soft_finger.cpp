#include "hila/core/soft_finger.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cassert>
#include <cmath>

#include "hila/core/pose.hpp"

namespace hila::core {

double winkler_eccentricity(const SoftFingerPad& pad, double normal_force) {
  if (normal_force <= 0.0) return 0.0;
  const double r = std::sqrt(pad.radius_1 * pad.radius_2);
  return (16.0 / 15.0) *
         std::pow(normal_force * pad.thickness * r / (pad.elastic_modulus * kPi), 0.25);
}

double finger_friction_torque(const SoftFingerPad& pad, double normal_force) {
  return pad.friction * normal_force * winkler_eccentricity(pad, normal_force);
}

bool soft_finger_holds(const SoftFingerPad& pad, double normal_force, double tangential_force,
                       double normal_torque) {
  if (normal_force <= 0.0) return tangential_force == 0.0 && normal_torque == 0.0;
  const double e = winkler_eccentricity(pad, normal_force);
  const double lhs =
      tangential_force * tangential_force + (normal_torque * normal_torque) / (e * e);
  const double rhs = pad.friction * pad.friction * normal_force * normal_force;
  return lhs <= rhs;
}

double gravity_torque_about_axis(const Eigen::Vector3d& axis, const Eigen::Vector3d& contact_centre,
                                 const Eigen::Vector3d& com, double mass,
                                 const Eigen::Vector3d& gravity) {
  return axis.dot((com - contact_centre).cross(mass * gravity));
}

double max_gravity_torque(double mass, double gravity, double lever, double inclination) {
  return mass * gravity * lever * std::sin(inclination);
}

double relaxation_limit_deg(double mass, double gravity, double lever, double capacity,
                            const RelaxationSettings& settings) {
  assert(settings.step_deg > 0.0);
  const int steps = static_cast<int>(std::floor(90.0 / settings.step_deg + 1e-9));
  double last_safe = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const double theta_deg = k * settings.step_deg;  // no accumulated rounding
    if (max_gravity_torque(mass, gravity, lever, deg_to_rad(theta_deg)) > capacity) break;
    last_safe = theta_deg;
  }
  // Every step safe: the grasp holds at any inclination.
  if (max_gravity_torque(mass, gravity, lever, kPi / 2) <= capacity) return 90.0;
  return last_safe;
}

double axis_inclination_deg(const Eigen::Vector3d& axis, const Eigen::Vector3d& gravity_direction) {
  const double c = std::min(1.0, std::abs(axis.dot(gravity_direction)));
  return rad_to_deg(std::acos(c));
}

double slip_angle_deg(const Eigen::Vector3d& axis, const Eigen::Vector3d& lever,
                      const Eigen::Vector3d& gravity_direction) {
  const double s = std::min(1.0, std::abs(gravity_direction.dot(axis.cross(lever))));
  return rad_to_deg(std::asin(s));
}

Eigen::Vector3d lever_direction(const Eigen::Vector3d& axis, const Eigen::Vector3d& contact_centre,
                                const Eigen::Vector3d& com) {
  const Eigen::Vector3d r = com - contact_centre;
  const Eigen::Vector3d perp = r - r.dot(axis) * axis;
  const double n = perp.norm();
  return n > 1e-12 ? Eigen::Vector3d(perp / n) : Eigen::Vector3d::Zero();
}

}  // namespace hila::core
