#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hila/online/arm_motion.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/scene.hpp"
#include "hila/online/smoother.hpp"
#include "hila/online/validator.hpp"

namespace hila::online {

// The order in which a goal's ways are planned (the goals themselves are always taken in Eq. 8
// order: the human's comfort and least re-orientation come first, the robot's time second).
// kEstimatedTime: by the way's estimated robot time from where the robot and tool are (Run's
// estimate: the regrasp graph's stored durations, else straight joint moves), exchanges the
// offline regrasp graph did not connect end to end last (they mostly fail, and their estimate
// omits the detour they would need). kFixed: direct, regrasp on the table, suction, exchange,
// each in the database's record order (connected exchanges first): a baseline to measure by.
// kCheapestFirst: every way of every goal tried by its estimate alone (unconnected exchanges
// last, Eq. 8 order between equal estimates): the least robot time first, whatever the goal's
// comfort rank; measured against kEstimatedTime (docs/online.md), not the default.
enum class WayOrder { kEstimatedTime, kFixed, kCheapestFirst };
const char* to_string(WayOrder order);

struct BoardPlanSettings {
  double approach = 0.05;  // m: straight approach and retreat along the cup's / gripper's axis
  double lift = 0.15;      // m: straight up from the table after the suction pick
  // Goals tried in Eq. 8 order; with natural_posture_first, up to as many natural and as many
  // upright ones before them.
  int goals = 10;
  WayOrder way_order = WayOrder::kEstimatedTime;  // within each goal
  int exchange_bridges = 2;   // receiving-arm IK branches at the exchange given a bridge
  double speed_scale = 0.5;   // of the arms' velocity and acceleration limits
  double jaw_margin = 0.005;  // m: the gripper opens this much wider than the board while holding
  bool smooth = true;         // smooth every found path with more than one segment (smoother.hpp)
  SmootherSettings smoother;
  double timing_step =
      0.05;  // rad: the timed trajectory's longest piece (time_parameterize_through)
  // rad: waypoints of the receiving arm's way back (its way in, reversed) at least this far
  // apart; the hint for its way home after the release (0 disables the hint).
  double way_back_spacing = 0.05;
  MotionSettings motion;
  ValidatorSettings validator;
  // The validator's dense pass is split over this many threads (the same report as one).
  int validation_threads = 2;
  // With two validation threads: each motion is validated on the second thread while the next
  // ones are planned (ValidationQueue); a stage planned past a step the validator then rejects
  // is planned again in order. false: each motion is validated before the next is planned.
  bool overlap_validation = true;
  // With the overlap: while the second thread is behind, a step is smoothed on the planner's
  // thread rather than queued with its validation (the plan is the same either way). false
  // queues every step's smoothing: slower, the work piling onto the thread already behind.
  bool smooth_here_when_behind = true;
  // Before anything of an exchange way is planned for a goal and grasp (the suction arm's pick
  // and transfer included), whether the receiving arm reaches the goal's robot-human pose with
  // that grasp at all (the transfer to the human's own first check): the same choice of way,
  // without planning picks, transfers and exchanges for grasps the goal cannot use. false plans
  // the exchange's stages first.
  bool reach_human_pose_first = true;
  // The human who is there. The stored goals are evaluated again for the scene's human (comfort
  // Q of paper Eq. 4, by the database's comfort maps). Those with Q of at least this (or of at
  // least their stored Q where that is lower, so that at the built stance every stored goal
  // qualifies and the order is the database's) are tried first, in Eq. 8 order; then those the
  // human's arm reaches by inverse kinematics, uncomfortably; the rest are never tried. The
  // build's comfort threshold (paper §VI-B).
  double worker_comfort_floor = 0.06;
  // Goals a person would choose. Among the goals the worker can take, those whose receiving
  // posture (check_receiving_posture in receiving_scores.hpp: the worker's posture from the
  // human arms' inverse kinematics, as the plan returns it) has no forward bend, every receiving
  // elbow below its shoulder, the part's centre of mass between the worker's hip and shoulder
  // height and a RULA grand score of at most natural_max_rula come first (the comfortable ones,
  // then the uncomfortable, each in Eq. 8 order), then the upright ones with a higher RULA (the
  // elbow low and the part in front of the chest wherever a goal allows it, the first
  // preference); then the others as without it. Eq. 8 ranks by
  // the arm's manipulability, which a hand above the shoulder can have; ergonomists would not
  // choose it. false: the comfort tiers and Eq. 8 order only (also where the cell's human model
  // is not one of `hila human`, whose joints the check reads).
  bool natural_posture_first = true;
  // RULA grand score a natural receiving posture keeps to: 3 and below is action level 1-2
  // ("acceptable", or "investigate further" at 3), what the issue asks of every handover.
  int natural_max_rula = 3;
  // A goal whose every way is an exchange the build found blocked at the suction arm's transfer
  // to the robot-robot pose (a stored transfer edge, not connected: docs/roadmap.md) is tried
  // after the goals of its list that have an open way: most fail again, each at the cost of a
  // bridge search (tens of ms). Not in the kFixed way order. false: in its place.
  bool blocked_exchanges_last = true;
};

// What happens with a step (PlanStep::start_event, end_event): the suction cup takes the board
// or lets go of it, the gripper closes on the board or opens, the tool is taken from the table or
// set down on it, the board is set down on the table (a regrasp or a relay), or the robot holds
// the board still for the human to take it.
enum class StepEvent {
  kNone,
  kSuctionOn,
  kSuctionOff,
  kGripperClose,
  kGripperOpen,
  kToolGrasped,
  kToolReleased,
  kSetDown,
  kWaitForHuman
};
// "suction_on", "suction_off", "gripper_close", "gripper_open", "tool_grasped",
// "tool_released", "set_down", "wait_for_human"; "" for kNone.
const char* to_string(StepEvent event);

// One arm's timed motion within the plan, with what happens at its start and at its end.
struct PlanStep {
  std::string name;  // e.g. "suction_pick", "transfer_to_robot_handover"
  std::string arm;
  MotionVia via = MotionVia::kNone;  // how the motion was found (MotionResult::via)
  bool staged = false;               // through a staging pose (MotionResult::staged)
  std::vector<double> time;          // s from the start of the board's plan
  std::vector<Eigen::VectorXd> q;
  // As the step starts (the arm lets go, then moves away: kSuctionOff, kGripperOpen) and when it
  // has arrived (every other event); kNone: nothing.
  StepEvent start_event = StepEvent::kNone;
  StepEvent end_event = StepEvent::kNone;
  double path_length = 0.0;  // rad, of the executed (smoothed) path
  bool smoothed = false;     // the found path was smoothed (else executed as found)
  ValidationReport validation;
};

// The step's events as the plan file writes them: "start,end", either alone, or "" for none.
std::string events_text(const PlanStep& step);
// How the step's motion was found as the plan file writes it: to_string(via), "+staging" after
// it where it went through a staging pose.
std::string via_text(const PlanStep& step);

// How the board reaches the human. kExchange: the suction arm picks the board with the tool and
// hands it to the other arm's gripper. kDirect: one arm's gripper picks it where it lies.
// kRegrasp: one arm's gripper picks it, sets it down on the table on another resting pose and
// takes it again with another grasp. The delivering arm's gripper then takes it to the human.
// kSuction: the suction arm picks it with the tool and presents it on the cup; the human takes
// it from the cup (where no gripper serves a comfortable goal).
enum class DeliveryMode { kExchange, kDirect, kRegrasp, kSuction };
const char* to_string(DeliveryMode mode);

// A handover goal tried by one way, and why it was left.
// How one chain of a goal ended: planned, failed at a step (the scene or the stored records
// allow no valid motion there), or cut short by the deadline.
enum class AttemptResult { kPlanned, kFailed, kDeadline };
const char* to_string(AttemptResult result);

struct GoalAttempt {
  int rank = -1;
  std::int64_t candidate_id = 0;
  DeliveryMode mode = DeliveryMode::kExchange;
  std::string arm;                     // the delivering arm
  std::int64_t robot_grasp_id = 0;     // 0 for the suction way
  std::int64_t suction_grasp_id = 0;   // the suction way's cup (the database's), else 0
  std::int64_t robot_handover_id = 0;  // 0 for a direct pick
  // The way's estimated robot time (s) by which it was ordered among its goal's ways (WayOrder).
  double estimated_seconds = 0.0;
  AttemptResult result = AttemptResult::kFailed;
  bool larger_bridges = false;  // tried in the second round (MotionSettings escalated budgets)
  // The step the chain stopped at (a PlanStep name such as "receiving_grasp", or a stage such as
  // "tool_pick" or "suction_pick"); "" when planned.
  std::string step;
  std::string outcome;  // "planned" or the whole reason, for people ("(larger bridges) " first)
};

// kHumanOutOfReach: the scene's human can take the board at none of its stored goals (where they
// stand, or how they face, puts every goal out of comfortable reach).
// kOverPayload: an arm would carry more than its payload (the part, its tooling and, on the
// suction cup, the tool: core::check_payload).
enum class BoardPlanStatus { kSolved, kNoGoal, kTimeout, kHumanOutOfReach, kOverPayload };
const char* to_string(BoardPlanStatus status);

// Where a board's planning time went (s, wall clock, summed over every goal attempt; the rest is
// the goals' IK, the stages' bookkeeping and the database's records): the motions' planning
// (ArmMotionPlanner::plan, stagings and fine retries included), smoothing, and the timing with
// the validator's re-check. The motions are what the planners differ in: the rest is the same
// work for hila's roadmaps and the from-scratch baselines.
// Seconds of BoardPlan::planning_seconds on the planner's thread, and the validator's own.
struct PlanTimes {
  double motions = 0.0;
  double smoothing = 0.0;
  double validation = 0.0;  // timing and validating, or waiting for the queue's reports
  // The queue's validation, and its smoothing and timing of the queued steps, on either thread
  // (BoardPlanSettings::overlap_validation), most of it alongside the planning: not a part of
  // planning_seconds.
  double queued_validation = 0.0;
  double queued_smoothing = 0.0;
};

struct BoardPlan {
  BoardPlanStatus status = BoardPlanStatus::kNoGoal;
  std::string reason;
  std::string board;
  int goal_rank = -1;
  std::int64_t candidate_id = 0;
  // The way chosen: who picks the board and how, the exchange (kExchange only: from the picking
  // arm's cup to the delivering arm's gripper at robot_handover) and who delivers it.
  DeliveryMode mode = DeliveryMode::kExchange;
  std::string picking_arm;
  std::string delivering_arm;
  std::int64_t robot_grasp_id = 0;
  std::int64_t suction_grasp_id = 0;  // 0 for a pick by a gripper
  // kRegrasp only: the grasp the board is picked and set down with, and where it is set down
  // (world); robot_grasp_id is the grasp it is taken again and delivered with.
  std::int64_t pick_grasp_id = 0;
  core::Pose set_down = core::Pose::Identity();
  double theta_c_deg = 90.0;
  // The worker planned for: the scene's `worker` (Scene::worker), nullptr for the cell's own
  // human. Its body's arms give human_joints and its model the receiving scores.
  std::shared_ptr<const core::HumanBody> worker;
  double quality = 0.0;  // the comfort Q of the scene's human at the goal (paper Eq. 4)
  // Stored goals the scene's human reaches only uncomfortably (tried after the comfortable ones)
  // or not at all (never tried), among those checked (BoardPlanSettings::worker_comfort_floor).
  int goals_out_of_reach = 0;
  int goals_uncomfortable = 0;
  // Goals whose receiving posture is natural (BoardPlanSettings::natural_posture_first), among
  // those checked, and whether the chosen goal's is.
  int goals_natural = 0;
  // Goals whose receiving posture was solved by the human arms' inverse kinematics (the reach
  // check and the natural posture's, each goal once): a work measure of the worker's checks.
  int human_postures_solved = 0;
  bool natural_posture = false;
  // The human's receiving posture at the goal: each hand's arm and its joints (rad), from the
  // human arm's inverse kinematics for the scene's stance (the build's own where it stands as
  // built). Empty second arm for a one-hand goal.
  std::string human_arm, second_human_arm;
  Eigen::VectorXd human_joints, second_human_joints;
  core::Pose robot_handover = core::Pose::Identity();  // board poses (world); kExchange only
  core::Pose human_handover = core::Pose::Identity();
  std::vector<PlanStep> steps;
  std::vector<GoalAttempt> attempts;
  double planning_seconds = 0.0;
  PlanTimes times;        // of planning_seconds
  double duration = 0.0;  // s, the robot's motion
  // The chosen way's estimated robot time (GoalAttempt::estimated_seconds), before the tool is
  // put back: beside `duration`, how good the estimate was.
  double estimated_seconds = 0.0;
  double path_length = 0.0;  // rad, both arms
  bool validated = false;    // every step passed the validator
  // Planned in the second round, with MotionSettings::escalated_bridge_checks per bridge (every
  // goal had failed within the cheaper budget).
  bool larger_bridges = false;
  // Motions the validator rejected as first planned (a fallback then passed, or the stage or
  // goal was given up), over every goal tried.
  int rejected_motions = 0;
  // Motions planned over every goal tried (fallbacks and re-plans included): the work done, as
  // no clock on a shared machine measures it.
  int motions_planned = 0;
  Eigen::VectorXd robot_q_after;    // the robot when the board has been taken
  bool tool_in_hand_after = false;  // an arm still holds the tool then: suction_arm
  std::string suction_arm;          // the arm that holds the tool in this plan
  // Where the suction arm could not take the tool where the scene has it (in the other arm's
  // hand, or standing out of the suction arm's reach): the plan's first tool_move_steps steps are
  // the other arm (tool_move_arm) taking it from the table (tool_taken_from_table) or already
  // holding it, setting it down at tool_place (the scene's place, or the relay both arms reach:
  // PlannerModel::tool_relay) and going home; the board's own steps follow, the tool standing
  // there, and the next board's scene has it there.
  int tool_move_steps = 0;
  std::string tool_move_arm;
  bool tool_taken_from_table = false;
  std::optional<core::Pose> tool_place;
  std::string tool_kept;  // why the tool was not put back (BoardPlanOptions::return_tool)
  bool solved() const { return status == BoardPlanStatus::kSolved; }
};

// Plans everything the robot does for one board (DESIGN §2). Goals in Eq. 8 order; for each,
// the direct ways first (fewer motions: an arm's gripper picks the board where it lies, carries
// it to the robot-human pose within its slip limit and retreats after the human takes it), then
// the exchange (the tool pick when the scene has it on the table, the suction pick at the
// detected pose with its approach and lift, the transfer to the robot-robot pose, the receiving
// arm's approach and grasp, the suction arm's release and retreat, the slip-constrained transfer
// to the robot-human pose and the retreat). Each motion through the stored roadmaps repaired
// for the scene; every step timed and re-checked by the validator: nothing invalid is returned.
// Failing pieces shared by several goals (a cup's pick, a transfer to a robot-robot pose, a
// gripper's pick) are planned once per call. One per thread.
// What one query asks beyond the scene and the board.
struct BoardPlanOptions {
  // Put the suction tool back where the scene has its place once the board is delivered, and
  // take that arm home (the next board is the other arm's to pick by suction). Where it cannot
  // be put back, the plan stands and keeps the tool in hand (BoardPlan::tool_kept says why).
  bool return_tool = false;
};

class BoardPlanner {
 public:
  explicit BoardPlanner(const PlannerModel& model, const BoardPlanSettings& settings = {});
  ~BoardPlanner();
  BoardPlanner(const BoardPlanner&) = delete;
  BoardPlanner& operator=(const BoardPlanner&) = delete;

  BoardPlan plan(const Scene& scene, const std::string& board,
                 std::chrono::steady_clock::time_point deadline,
                 const BoardPlanOptions& options = {});

 private:
  // plan() for a scene where the board's suction arm has the tool in hand or on the table.
  BoardPlan plan_here(const Scene& scene, const std::string& board,
                      std::chrono::steady_clock::time_point deadline,
                      const BoardPlanOptions& options);
  // `mover` takes the tool (from the table where the scene has it there) and sets it down at
  // `place`, then goes home; the board is planned from there (plan_here) and the plan begins
  // with those steps.
  BoardPlan plan_after_tool_moved(const Scene& scene, const core::PartSpec& part,
                                  const BoardRecords& records, const std::string& mover,
                                  const core::Pose& place,
                                  std::chrono::steady_clock::time_point deadline,
                                  const BoardPlanOptions& options,
                                  std::chrono::steady_clock::time_point started);

  const PlannerModel& model_;
  BoardPlanSettings settings_;
  // The cell's human is a model the natural posture's check reads (a `hila human` body); else
  // the goals keep Eq. 8 order within the comfort tiers.
  bool natural_check_works_ = true;
  // The LazyPRM baseline's roadmaps, kept between queries (settings.motion.planner kLazyPrm).
  std::map<std::string, std::unique_ptr<core::LazyPrmPlanner>> lazy_prm_;
};

}  // namespace hila::online
