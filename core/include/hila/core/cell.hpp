#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/collision.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/payload.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/robot_model.hpp"
#include "hila/core/ur_ik.hpp"

namespace hila::core {

struct PadSpec {
  double friction = 0.5;         // Coulomb coefficient pad/part
  double elastic_modulus = 1e6;  // Pa (Winkler foundation K)
  double thickness = 0.003;      // m, elastic layer depth h
  double radius_1 = 0.05;        // m, principal relative radii R', R''
  double radius_2 = 0.05;
  double width = 0.022;   // m, contact patch extent across the finger
  double length = 0.037;  // m, along the approach
};

struct GripperSpec {
  Pose tcp_in_flange = Pose::Identity();
  Eigen::Vector3d opening_axis = Eigen::Vector3d::UnitY();   // in the TCP frame
  Eigen::Vector3d approach_axis = Eigen::Vector3d::UnitZ();  // in the TCP frame
  double jaw_min = 0.0;
  double jaw_max = 0.085;
  double grip_force_min = 20.0;
  double grip_force_max = 235.0;
  double grip_force = 100.0;
  PadSpec pad;
  // Calibration (DESIGN §3): total friction torque both fingers resist, N·m. Reproduces the
  // paper's relaxation limits with 1-degree steps.
  double friction_torque_capacity = 1.0;
  double slip_step_deg = 1.0;
};

struct SuctionSpec {
  std::string tool_urdf;
  std::string handle_link;  // where the gripper holds the tool
  std::string cup_link;     // suction face, z out of the cup
  double handle_width = 0.03;
  double cup_radius = 0.02;
  double max_force = 40.0;  // N, pull-off force with safety factor
  double max_moment = 0.8;  // N·m
  // The handle frame in the gripper's TCP frame while the gripper holds the tool.
  Pose handle_in_tcp = Pose::Identity();
  double mass = 0.0;                              // kg, carried on top of the arm's tooling
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  // m, handle frame
};

struct ArmSpec {
  std::string name;
  std::string base_link;
  std::string tip_link;
  std::string flange_link;
  std::string finger_joint;
  std::optional<UrDhParameters> ur_dh;
  Eigen::VectorXd home;              // rad
  Eigen::VectorXd max_velocity;      // rad/s
  Eigen::VectorXd max_acceleration;  // rad/s^2
  PayloadSpec payload;               // what the arm may carry at its flange
};

// The human hand as a 1-DoF gripper (paper §IV): fingertip pads of skin (mu = 0.8) closing along
// the grasp frame's y axis with a comfortable pinch force.
struct HumanHandSpec {
  double aperture_min = 0.0;   // m
  double aperture_max = 0.09;  // m, thumb-index span for a pinch
  double grip_force = 40.0;    // N, sustained comfortable pinch per finger
  PadSpec pad;                 // fingertip: friction, skin modulus, soft-tissue depth, radii, size
  double finger_thickness = 0.016;  // m, along the closing axis
  double finger_width = 0.02;       // m
  double finger_length = 0.06;      // m, along the approach, centred on the grasp point
  double palm_width = 0.085;        // m, across the fingers
  double palm_length = 0.09;        // m, behind the fingertips
  double palm_thickness = 0.03;     // m
};

struct HumanArmSpec {
  std::string name;
  std::string base_link;
  std::string tip_link;
};

struct BoxObstacle {
  std::string name;
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  Pose pose = Pose::Identity();
};

struct CellSpec {
  std::string file;
  std::string robot_urdf;
  std::vector<ArmSpec> arms;
  GripperSpec gripper;
  SuctionSpec suction;
  std::vector<BoxObstacle> obstacles;
  std::vector<std::pair<std::string, std::string>> allowed_collisions;
  std::string human_urdf;
  Pose human_stance = Pose::Identity();
  std::vector<HumanArmSpec> human_arms;
  HumanHandSpec human_hand;
  Eigen::VectorXd human_neutral;  // empty: human_neutral_configuration() of the human model
  double gravity = 9.81;
};

// Parses and validates a cell file; link and joint names are checked against the URDFs.
CellSpec load_cell_spec(const std::string& path);

struct Arm {
  ArmSpec spec;
  KinematicChain chain;
  std::optional<UrIk> ur_ik;
  int finger_variable = -1;  // robot configuration index of the jaw joint
};

struct HumanArm {
  HumanArmSpec spec;
  KinematicChain chain;
};

// A loaded cell: models, chains and the analytic IK, immutable and shareable between threads.
class Cell {
 public:
  static std::shared_ptr<const Cell> load(const std::string& path);

  const CellSpec& spec() const { return spec_; }
  const RobotModel& robot() const { return robot_; }
  const RobotModel& human() const { return human_; }
  const RobotModel& suction_tool() const { return tool_; }
  const std::vector<Arm>& arms() const { return arms_; }
  const std::vector<HumanArm>& human_arms() const { return human_arms_; }
  const Arm& arm(const std::string& name) const;  // throws InputError if unknown

  // The robot's configuration with every arm at home and the jaws at `jaw_opening`.
  Eigen::VectorXd home_configuration(double jaw_opening = 0.085) const;
  void set_arm(Eigen::VectorXd& robot_q, const Arm& arm, const Eigen::VectorXd& arm_q) const;
  Eigen::VectorXd arm_joints(const Eigen::VectorXd& robot_q, const Arm& arm) const;
  void set_jaw(Eigen::VectorXd& robot_q, const Arm& arm, double opening) const;
  // The human's posture while the robot works: human.neutral_deg, or without it the model's
  // relaxed standing posture (human_neutral_configuration).
  Eigen::VectorXd human_neutral() const;

 private:
  CellSpec spec_;
  RobotModel robot_;
  RobotModel human_;
  RobotModel tool_;
  std::vector<Arm> arms_;
  std::vector<HumanArm> human_arms_;
  Eigen::VectorXd human_neutral_;
};

// The static cell as a collision scene: robot links, table and obstacles, the human at the
// stance. Built once; use one CollisionData per thread.
struct CellScene {
  CollisionModel model;
  RobotBodies robot;
  RobotBodies human;
  std::vector<int> obstacles;
  std::vector<std::vector<int>> arm_bodies;  // per arm (Cell::arms order): links and gripper
};

struct CellSceneOptions {
  // The human is part of the static scene while the robot plans (human-human and human-table
  // pairs are then not checked); checking the human's own posture needs it to move.
  bool human_moves = false;
};

CellScene build_cell_scene(const Cell& cell, const CellSceneOptions& options = {});

// Throws InputError (field human.stance) when the human at the stance, in the neutral posture,
// intersects an obstacle (the table) or the robot at home: a stance inside the table; (field
// human.neutral_deg, or human.urdf without it) when that posture intersects the human itself.
void check_human_stance(const Cell& cell);

// Poses the robot's bodies only (the human unchanged): what a robot motion check needs.
void set_robot_state(const Cell& cell, const CellScene& scene, CollisionData& data,
                     const Eigen::VectorXd& robot_q);

// Poses every robot and human body for the given configurations.
void set_cell_state(const Cell& cell, const CellScene& scene, CollisionData& data,
                    const Eigen::VectorXd& robot_q, const Eigen::VectorXd& human_q);

}  // namespace hila::core
