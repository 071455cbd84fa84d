#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/mesh.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/human_comfort.hpp"

namespace hila::offline {

struct ErgonomicsSettings {
  // Where a robot without regard to ergonomics lays every board down: flat on the table in front
  // of the human, beside the assembly, longest side across the human (world, m).
  double table_spot_x = 0.68;
  double table_spot_y = 0.55;
  double flexion_step_deg = 5.0;  // torso flexion searched in these steps up to its limit
  int candidates_per_step = 3;    // best map-scored grasps confirmed by direct IK per step
  int ik_attempts = 12;
  std::uint64_t seed = 5;
};

// How the human takes a board at `board` (world): the least torso flexion (in steps) at which
// one of `grasps` (indices into `human_grasps`) is reachable by an arm, then the most
// comfortable of the best map-scored grasps there by direct IK. `stance` is where the human
// stands. With `only_arm` >= 0 just that arm is used. `body`: the worker's body (its model, arms
// and neutral posture; the cell human's comfort maps serve it through core::HumanBody::
// to_cell_arm); nullptr, or a body that is the cell's human (same_as_cell), the cell's human.
struct Posture {
  bool reachable = false;
  double torso_flexion_deg = 0.0;
  bool shoulder_elevated = false;  // elbow at or above the shoulder
  double reach = 0.0;              // shoulder to the grasp point, m
  double quality = 0.0;            // Q of the arm at the posture (paper Eq. 4)
  int arm = -1;
  int grasp = -1;
  Eigen::VectorXd arm_joints;
  // The whole configuration at the posture (the torso bent, the arm's joints, the rest neutral),
  // of the model the posture was searched on (the body's, else the cell's human); where the
  // human stood; where the board was (world). Empty q when not reachable.
  Eigen::VectorXd q;
  core::Pose stance = core::Pose::Identity();
  core::Pose board = core::Pose::Identity();
};

Posture receiving_posture(const core::Cell& cell, const HumanComfort& comfort,
                          const core::Pose& stance, const core::Pose& board,
                          const std::vector<db::HumanGraspRecord>& human_grasps,
                          const std::vector<int>& grasps, int only_arm,
                          const ErgonomicsSettings& settings,
                          const core::HumanBody* body = nullptr);

struct ErgonomicsInputs {
  core::Pose target = core::Pose::Identity();   // world
  core::Pose initial = core::Pose::Identity();  // on the stack, world
  // The part's most stable placement (part in plane, z up); without one no table drop is
  // evaluated (no "table" record).
  bool has_placement = false;
  core::Pose table_placement = core::Pose::Identity();
  const std::vector<db::HumanGraspRecord>* human_grasps = nullptr;
  // The first handover goal, if any: board pose, arm index and grasp index.
  bool has_goal = false;
  core::Pose goal = core::Pose::Identity();
  int goal_arm = -1;
  int goal_grasp = -1;
  // The part's symmetries (core::mesh_symmetries, part frame): the re-orientation left is the
  // least over them (a board handed over turned by a half turn it is symmetric under needs none).
  // Empty: the plain angle.
  std::vector<Eigen::Matrix3d> symmetries;
  // Where the human stands (world): nullopt, the cell's stance.
  std::optional<core::Pose> stance;
  // The worker (receiving_posture's `body`): nullptr, the cell's human. Not owned.
  const core::HumanBody* body = nullptr;
};

// The three ways of getting one board to the human (records in the order hila, table, alone;
// "hila" only with a goal, "table" only with a placement):
// hila's first goal with its human grasp; the board laid flat at the table spot; the human alone
// stepping sideways to face the stack and taking the board from it, each for inputs.body at
// inputs.stance. Board-specific inputs only;
// part_id is left unset. With `postures`, also each record's posture (its arm's joints), in the
// same order: what the database does not store, for `hila report ergonomics` to score.
std::vector<db::ErgonomicsRecord> evaluate_ergonomics(const core::Cell& cell,
                                                      const HumanComfort& comfort,
                                                      const ErgonomicsInputs& inputs,
                                                      const ErgonomicsSettings& settings,
                                                      std::vector<Posture>* postures = nullptr);

// The re-orientation left, done in the worker's hands: the board turned from where it was taken
// to its fitted orientation about its centre of mass, held at a turning point in front of the
// worker. What EAWS counts as shoulder work (the paper's Table 2: "the robot hands over the board
// in an already flipped pose") happens here as well as at the take.
struct TurnSettings {
  double step_deg = 15.0;  // the turn is checked at most this far apart (and at both ends)
  // Turning points: the centre of mass at each fraction of the worker's hip-to-shoulder band
  // (natural_height_band, 0 the hip, 1 the shoulder) and each distance (m) in front of the stance
  // (its x axis). The turn is scored at the point that suits the worker best; the higher and
  // farther points are where a long board turns clear of the body.
  std::vector<double> band_fractions = {0.4, 0.7, 1.0};
  std::vector<double> distances = {0.30, 0.40, 0.50};
};

struct Turn {
  double turned_deg = 0.0;  // the rotation, modulo the part's symmetries; 0: nothing to turn
  bool reachable = true;    // a grasp reachable at every step (torso bent up to its limit)
  // Steps where the board, at the posture found, runs into the worker's body: the torso, head and
  // legs (the arms that hold it excepted). Checked where the board's mesh is given.
  int blocked_steps = 0;
  int elevated_steps = 0;  // steps with the elbow at or above the shoulder
  double max_flexion_deg = 0.0;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // the turning point chosen (world)
  // The board (world) and the worker's posture at each step, from the taken orientation (first)
  // to the fitted one (last); empty with nothing to turn.
  std::vector<core::Pose> boards;
  std::vector<Posture> postures;
  std::vector<bool> blocked;  // per step: the board in the worker's body (blocked_steps)
  // Reachable at every step and clear of the body at every step.
  bool feasible() const { return reachable && blocked_steps == 0; }
};

// The turn from `from` (the board as taken, world) to `target` (world orientation; the nearest of
// its symmetric equivalents, `symmetries` in the part frame) with the centre of mass `com` (part
// frame) at each turning point; at each step the best posture receiving_posture finds with
// `grasps` (indices into human_grasps), and, with `mesh` (the part's, part frame), the board
// checked against the worker's body at that posture. The chosen point: the fewest steps
// unreachable or blocked, then the fewest with the elbow up, then the least torso flexion, then
// the first.
Turn turn_in_hands(const core::Cell& cell, const HumanComfort& comfort, const core::Pose& stance,
                   const core::Pose& from, const Eigen::Matrix3d& target,
                   const std::vector<Eigen::Matrix3d>& symmetries, const Eigen::Vector3d& com,
                   const core::TriangleMesh* mesh,
                   const std::vector<db::HumanGraspRecord>& human_grasps,
                   const std::vector<int>& grasps, const ErgonomicsSettings& settings,
                   const TurnSettings& turn, const core::HumanBody* body = nullptr);

// The world pose of a board laid on the table at the spot with `placement` (part in plane).
core::Pose table_drop_pose(const core::Cell& cell, const core::Pose& placement,
                           const ErgonomicsSettings& settings);

}  // namespace hila::offline
