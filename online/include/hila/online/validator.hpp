#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hila/core/collision.hpp"
#include "hila/core/pose.hpp"
#include "hila/online/world.hpp"

namespace hila::online {

// One arm's time-stamped joint trajectory and what the rest of the cell does meanwhile.
struct Motion {
  std::string arm;
  std::vector<double> time;        // s, strictly increasing
  std::vector<Eigen::VectorXd> q;  // this arm's joints at each time (rad)
  Eigen::VectorXd robot_q;         // the whole robot (the other arm, the jaws) while it moves
  bool holds_board = false;        // the board follows this arm's TCP
  core::Pose board_in_tcp = core::Pose::Identity();
  // Gripper holds: the opening axis and the unit lever to the board's centre of mass, both in
  // the TCP frame, and the grasp's slip limit (90: none, e.g. suction).
  Eigen::Vector3d slip_axis_tcp = Eigen::Vector3d::UnitY();
  Eigen::Vector3d slip_lever_tcp = Eigen::Vector3d::Zero();
  double theta_c_deg = 90.0;
  core::Pose board_world = core::Pose::Identity();  // where the board is when not held
  bool tool_in_hand = true;                         // the suction arm holds the tool
  core::Pose tool_world = core::Pose::Identity();   // the tool's handle when not in hand
  bool start_in_contact = false;  // the first sample's collisions are by design (a lift)
};

struct ValidatorSettings {
  double resolution = 0.01;       // rad: the largest joint-space step between checked samples
  double limit_tolerance = 1e-9;  // rad, joint limits
  double rate_tolerance = 0.02;   // relative, velocity and acceleration limits
  double slip_tolerance_deg = 1e-6;
};

struct Violation {
  std::string kind;  // "format", "joint_limit", "velocity", "acceleration", "collision", "slip"
  double time = 0.0;
  std::string detail;
};

struct ValidationReport {
  std::vector<Violation> violations;  // the first of each kind, in time order per kind
  int samples = 0;                    // configurations checked
  double worst_slip_deg = 0.0;        // over the samples, when holding with a slip limit
  bool valid() const { return violations.empty(); }
};

// Re-checks a motion independently of the planner that made it: the format, joint limits at
// every waypoint and sample, joint velocities and accelerations (finite differences of the
// waypoints) against the arm's limits, and at samples no farther apart than the resolution the
// whole robot posed by FK with the tool and the board (held or standing), checked for collision
// against everything in the world, and a held board's slip angle against theta_c. `data` is the
// caller's (World::make_data()).
ValidationReport validate_motion(const World& world, core::CollisionData& data,
                                 const Motion& motion, const ValidatorSettings& settings = {});
// The same, its samples split over one thread per CollisionData (each the caller's, from
// World::make_data(), none shared with another thread): the same report as one thread's.
ValidationReport validate_motion(const World& world, const std::vector<core::CollisionData*>& data,
                                 const Motion& motion, const ValidatorSettings& settings = {});

}  // namespace hila::online
