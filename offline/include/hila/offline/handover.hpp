#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/human_comfort.hpp"
#include "hila/offline/table_regrasp.hpp"

namespace hila::offline {

struct HandoverSettings {
  // Eq. 1: candidates around the target pose.
  int candidates = 500;  // poses satisfying Eq. 1 per batch (the first batch always)
  // Boards with fewer goals than min_goals get further batches, up to max_candidates.
  int min_goals = 5;
  int max_candidates = 3000;
  int max_draws = 100000;          // give up drawing after this many
  double max_rotation_deg = 45.0;  // from the target orientation
  double max_offset = 0.5;         // m from the target position
  // Natural bands: for each worker (the cell's human and every body of the set) whose natural
  // band (core::natural_height_band: hip to shoulder height) the part's centre at its target
  // lies outside of, this many more candidates with the part's centre in that band (the target's
  // orientation within max_rotation_deg, its horizontal position within max_offset): goals the
  // worker takes with the elbow low and the part in front of the chest, which the online planner
  // tries first (BoardPlanSettings::natural_posture_first). 0: Eq. 1's candidates only.
  int natural_candidates = 200;
  // A worker none of whose goals is natural for them (natural_max_rula), after every other batch,
  // gets batches of natural_candidates more in their band within this of the target's
  // orientation (deg), up to max_candidates, until one is: a part too tall to stand within 45
  // degrees of its fitted orientation below a short worker's shoulder above the table (the
  // cabinet's 587 mm laterals for a 1.50 m woman) is presented lying further over, and the worker
  // has more to turn; a part whose goals all came out held high is presented lower. Equal to
  // max_rotation_deg: no wider batches.
  double natural_max_rotation_deg = 90.0;
  // A natural posture, as the online planner judges it (BoardPlanSettings::natural_max_rula,
  // core::PostureCheck::natural): the worker's arm IK at the goal's grasps upright (no forward
  // bend, elbows below the shoulders, the part's centre between hip and shoulder height) with a
  // RULA grand score of at most this.
  int natural_max_rula = 3;
  // With a body set (BuildSettings::human_bodies), each body's own Eq. 1 candidates besides the
  // cell human's `candidates`: the human's grasps chosen and the goal confirmed for that body.
  int body_candidates = 250;
  // S (Eq. 9): the best human grasp's Q must exceed this. The cell human's Q peaks near 0.15
  // (a 7-DoF arm with the reach as length scale); 0.06 keeps the better ~40 % of the reachable
  // hand poses.
  double comfort_threshold = 0.06;
  // A part with no goal above comfort_threshold (the comfortable candidates out of the delivering
  // arm's reach, or the human's own inverse kinematics finding the maps' Q too high there) gets
  // the goals it has down to this Q, in two steps (halfway, then here): delivered as comfortably
  // as the cell allows rather than left on the table for the human to fetch. Equal to
  // comfort_threshold: off.
  double comfort_floor = 0.02;
  double two_hand_separation = 0.20;  // m between the two hands' grasp points (two-hand boards)
  // Eq. 8: distance = position offset + rotation_weight * rotation angle (m per rad): 10 degrees
  // count as 3.5 cm.
  double rotation_weight = 0.2;
  // Robot-robot handover: the suction arm holds the board at its CoM in the shared workspace.
  std::string suction_arm = "right";
  std::string receiving_arm = "left";
  std::vector<Eigen::Vector3d> rr_positions = {
      {0.35, -0.08, 1.30}, {0.35, 0.0, 1.30}, {0.35, 0.08, 1.30},
      {0.45, -0.08, 1.30}, {0.45, 0.0, 1.30}, {0.45, 0.08, 1.30},
      {0.35, 0.0, 1.42},   {0.45, 0.0, 1.42}, {0.40, 0.0, 1.20}};
  // Only suction grasps the suction arm can use to take the board from the stack (IK and
  // collision at the initial pose, then a collision-free lift of pick_lift m straight up checked
  // at pick_resolution rad) are used at robot-robot poses.
  double pick_lift = 0.15;
  double pick_resolution = 0.05;
  // The receiving arm needs a way in at a robot-robot pose: a pre-grasp this far (m) back from
  // the grasp or along the board's edge with the straight motion into the grasp clear at
  // exchange_resolution (rad), as the online approach (core::find_pre_grasp).
  double exchange_approach = 0.05;
  double exchange_resolution = 0.01;
  int rr_orientations = 64;  // board orientations tried per position (spread over SO(3))
  int rr_poses = 24;         // suction-feasible robot-robot poses examined for receiving grasps
  int shared_stored = 8;     // shared grasps searched for and stored per goal
  // Robot-robot poses stored per shared grasp (one shared-grasp record each, in search order):
  // when the suction arm's transfer to one is cut in the roadmap, the regrasp graph tries the next.
  int rr_per_grasp = 3;
  // The first goals in Eq. 8 order are confirmed by direct IK of the human arm (best Q over
  // restarts; a candidate failing it leaves S) and carry the human's posture.
  int human_ik_goals = 10;
  // Direct picks: either arm's gripper takes the part where it lies and holds it at the goal
  // (no tool, no exchange; the suction arm only with the tool put down on the table). Up to
  // direct_stored robot grasps per goal and arm are stored.
  bool direct = true;
  int direct_stored = 4;
  // Regrasps on the table, for a comfortable candidate no exchange and no direct grasp serves: the
  // arm that picks the part sets it down where it lay on another resting pose and takes it again
  // with a grasp that holds it at the goal (up to direct_stored per goal and arm).
  TableRegraspSettings table_regrasp;
  // Suction deliveries, for a comfortable candidate no exchange, direct grasp or regrasp serves:
  // the suction arm presents the part on its cup (a suction grasp it picks the part with from
  // where it lies, its IK at the candidate clear of the cell and of the human's hands; up to
  // direct_stored per goal). The cup holds the weight at any tilt (suction_grasps.hpp).
  bool suction_delivery = true;
  // A part with no goal in these roles is tried again with the arms' roles swapped (the
  // receiving arm takes the tool and picks by suction, the suction arm receives), and the swapped
  // roles are kept when they give goals and the new suction arm reaches the tool on its stand.
  bool swap_roles = true;
  std::uint64_t seed = 3;
};

// The result for one board, with references given as 0-based indices into the inputs (robot,
// suction and human grasp vectors, robot_handovers, candidates) and -1 for none; the database
// writer turns them into ids.
struct HandoverResult {
  db::HandoverStageRecord stage;
  std::vector<db::RobotHandoverRecord> robot_handovers;
  std::vector<db::HandoverCandidateRecord> candidates;        // in sample order
  std::vector<db::SharedGraspRecord> shared;                  // for the goals, by rank
  std::vector<db::DirectGraspRecord> direct;                  // for the goals, by rank
  std::vector<db::TableRegraspRecord> regrasps;               // for the goals, by rank
  std::vector<db::SuctionDeliveryRecord> suction_deliveries;  // for the goals, by rank
  double seconds = 0.0;
};

struct BoardGrasps {
  std::vector<db::RobotGraspRecord> robot;
  std::vector<db::SuctionGraspRecord> suction;
  std::vector<db::HumanGraspRecord> human;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  // part frame
  std::vector<db::PlacementRecord> placements;    // resting poses, most stable first
};

// Handover goals of product.parts[index] at its assembly stage (the parts before it finished at
// their targets): Eq. 1 candidates, S by the comfort maps, robot-robot handover poses, 𝕊 by
// shared grasps (receiving-arm IK, slip angle within theta_c and collision-free at both poses)
// and by direct grasps (an arm's gripper picks the part where it lies and holds it at the
// goal), ranked by Eq. 8. Never throws for an infeasible board: stage.failure says why.
HandoverResult plan_handover_goals(const core::Cell& cell, const core::ProductSpec& product,
                                   std::size_t index, const BoardGrasps& grasps,
                                   const HumanComfort& comfort, const HandoverSettings& settings);

// Eq. 8 distance between two poses.
double handover_distance(const core::Pose& a, const core::Pose& b, double rotation_weight);
// Rotation angle between two orientations, degrees.
double rotation_angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

}  // namespace hila::offline
