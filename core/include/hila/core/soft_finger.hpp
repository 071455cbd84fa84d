#pragma once

#include <Eigen/Core>

namespace hila::core {

// Soft-finger contact of the paper (Eq. 2-3): a finger pad pressed with normal force P holds while
//   f_t^2 + tau_n^2 / e_n^2 <= mu^2 P^2,
// f_t the tangential force and tau_n the torque about the contact normal it must transmit.
struct SoftFingerPad {
  double friction = 0.8;         // mu
  double elastic_modulus = 1e6;  // K, Pa
  double thickness = 0.003;      // h, m (elastic layer depth)
  double radius_1 = 0.05;        // R', m
  double radius_2 = 0.05;        // R'', m
};

// Eccentricity e_n of the Winkler elastic foundation (Johnson, Contact Mechanics §5.9):
//   e_n = (16/15) * (P h sqrt(R' R'') / (K pi))^(1/4).
// The paper prints a square root; that makes e_n an area, not a length. The contact radius of a
// Winkler foundation obeys a^4 = 4 P h R / (pi K), so the fourth root is the consistent reading.
double winkler_eccentricity(const SoftFingerPad& pad, double normal_force);

// Largest pure torque about the normal one finger transmits: mu * P * e_n.
double finger_friction_torque(const SoftFingerPad& pad, double normal_force);

// The stability predicate of one contact for a given load.
bool soft_finger_holds(const SoftFingerPad& pad, double normal_force, double tangential_force,
                       double normal_torque);

// Gravity torque about the grasp axis (the line through both contacts along the unit opening
// direction `axis`, through `contact_centre`) of a part of mass m with centre of mass `com`:
//   tau = axis . ((com - contact_centre) x m g).
double gravity_torque_about_axis(const Eigen::Vector3d& axis, const Eigen::Vector3d& contact_centre,
                                 const Eigen::Vector3d& com, double mass,
                                 const Eigen::Vector3d& gravity);

// Its maximum over all rotations about the vertical at inclination theta (the angle between the
// axis line and gravity): m g r_perp sin(theta), r_perp the distance of the CoM from the axis.
double max_gravity_torque(double mass, double gravity, double lever, double inclination);

// Angle between the line of a grasp's opening axis and gravity, degrees in [0, 90] (both unit
// vectors). DESIGN §3's inclination: the worst case over the rotation about gravity.
double axis_inclination_deg(const Eigen::Vector3d& axis, const Eigen::Vector3d& gravity_direction);

// The slip angle of a held part at one orientation, degrees in [0, 90]: the inclination at which
// the worst-case torque m g r_perp sin(theta) equals the actual gravity torque about the grasp
// axis, sin(theta_s) = |g . (axis x lever)| with `lever` the unit direction from the axis to the
// centre of mass (perpendicular to the axis). The grasp holds statically while theta_s <= theta_c.
// theta_s <= axis_inclination_deg: a board hanging straight below its grasp has theta_s = 0 at
// any inclination of the axis.
double slip_angle_deg(const Eigen::Vector3d& axis, const Eigen::Vector3d& lever,
                      const Eigen::Vector3d& gravity_direction);

// Unit direction from the grasp axis (through `contact_centre` along unit `axis`) to the centre
// of mass, perpendicular to the axis; zero when the centre of mass lies on the axis.
Eigen::Vector3d lever_direction(const Eigen::Vector3d& axis, const Eigen::Vector3d& contact_centre,
                                const Eigen::Vector3d& com);

struct RelaxationSettings {
  double step_deg = 1.0;  // the paper's even steps
};

// The relaxation limit theta_c of paper §V-C in degrees: raise the inclination in even steps from
// 0; theta_c is the last step whose gravity torque m g r_perp sin(theta) is still within the
// grasp's friction-torque capacity (both fingers). 90 means no constraint.
double relaxation_limit_deg(double mass, double gravity, double lever, double capacity,
                            const RelaxationSettings& settings = {});

}  // namespace hila::core
