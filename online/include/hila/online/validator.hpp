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
  bool end_in_contact = false;    // the last sample's are (the tool set down)
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

// validate_motion in parts that separate threads may check (ValidationQueue shares a long
// motion's parts between its two threads): made with the format and rate checks and the dense
// samples; then each part of kPartSamples consecutive samples is checked on its own, with the
// checking thread's CollisionData; the report once every part is. The parts depend on the motion
// alone, and the report is validate_motion's however they are spread. `world` and `motion` must
// outlive it.
class MotionValidation {
 public:
  // A part's set-up (posing the whole robot, the tool, the rigid tip's own pairs) is some tens
  // of samples' work: parts much smaller would cost more than they share.
  static constexpr std::size_t kPartSamples = 256;

  MotionValidation(const World& world, const Motion& motion, const ValidatorSettings& settings);
  // 0 when the format is wrong (the report says why) or the arm unknown.
  std::size_t parts() const { return findings_.size(); }
  // Checks parts [first, last) in one pass. Disjoint ranges may be checked at once, each on its
  // own thread with its own data.
  void check_parts(std::size_t first, std::size_t last, core::CollisionData& data);
  // Once every part is checked.
  ValidationReport report() const;

  struct Findings {  // one part's: the first violation of each kind, the worst slip
    std::vector<Violation> violations;
    double worst_slip_deg = 0.0;
  };

 private:
  const World& world_;
  const Motion& motion_;
  ValidatorSettings settings_;
  const core::Arm* arm_ = nullptr;
  std::size_t arm_index_ = 0;
  ValidationReport head_;    // the format and rate checks
  Eigen::MatrixXd samples_;  // one column per sample, in time order
  std::vector<double> times_;
  std::vector<Findings> findings_;  // per part
};

}  // namespace hila::online
