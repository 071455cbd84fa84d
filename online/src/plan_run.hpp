#pragma once

// Private to hila_online, never installed: one BoardPlanner::plan() call (Run) and what its
// files share. board_planner.cpp searches over the goals and ways; Run is built and runs every
// motion through the step pipeline (plan, smooth, time, validate) in plan_run.cpp, and plans the
// stages of the exchange in exchange_way.cpp and those of the direct way in direct_way.cpp.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "hila/core/time_parameterization.hpp"
#include "hila/online/arm_motion.hpp"
#include "hila/online/board_planner.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/validation_queue.hpp"
#include "hila/online/validator.hpp"
#include "hila/online/world.hpp"

namespace hila::online::detail {

using core::resample_path;
using core::time_parameterize_through;
using core::TimedPath;

// IK solutions of `arm` for a TCP pose in the world, nearest `seed` first (`preferred`, when
// given and among them, first of all).
std::vector<Eigen::VectorXd> solutions(const core::Cell& cell, const core::Arm& arm,
                                       const core::Pose& tcp, const Eigen::VectorXd& seed,
                                       const Eigen::VectorXd* preferred = nullptr);

// `pose` moved by `by` (m, in the world frame).
core::Pose shifted(const core::Pose& pose, const Eigen::Vector3d& by);

// `q` with each joint turned by whole turns into the box the roadmaps and bridges sample
// (core::joint_box, home +- pi) where the joint's limits allow it: the same configuration, with
// roadmap nodes near it. An IK solution wrapped towards a seed far from home (the robot-robot
// pose with a stand-in suction grasp, its wrist turned from the lift's) may lie a whole turn
// outside, where the nearest nodes are radians away.
Eigen::VectorXd in_roadmap_box(const core::Arm& arm, Eigen::VectorXd q);

// Where the robot is between stages.
struct ArmsState {
  Eigen::VectorXd robot_q;  // the whole robot, jaws included
  bool tool_in_hand = true;
};

// What a queued step's finish made of the found path, on whichever thread took the job: the
// path smoothed (or as found) and timed. Read once the job's report is in.
struct FinishedPath {
  std::vector<Eigen::VectorXd> path;
  TimedPath timed;
  bool smoothed = false;
  double smoothing_seconds = 0.0;
};

// A step planned whose smoothing, timing and validator report are still to come
// (ValidationQueue), with what its fallbacks need when the report is a rejection.
struct PendingCheck {
  std::size_t job = 0;    // the queue's
  std::size_t step = 0;   // in Stage::steps
  Motion frame;           // the validator's view of the motion, without its trajectory
  MotionRequest request;  // as planned (its hints left out)
  ArmMotionPlanner* planner = nullptr;
  const core::Arm* arm = nullptr;
  MotionResult found;  // the planner's path, before smoothing
  std::shared_ptr<const FinishedPath> finished;
  // A later step was planned with this one's path as a hint (Run::executed_path): where the
  // validator then rejects it, the stages planned after it are planned again in order, with the
  // path that replaces it, as they would have been without the overlap.
  mutable bool read_as_hint = false;
};

// A stage of the chain (e.g. the suction pick for one cup): its timed steps (from 0) and where
// it leaves the robot, or why it failed. Stages are memoised by what determines them, so a
// failing piece shared by many goals is planned once.
struct Stage {
  std::string failure;
  std::vector<PlanStep> steps;
  // Each step's path as executed, or, for a queued step whose smoothing is still to come, as
  // found: known before the step's timing is.
  std::vector<std::vector<Eigen::VectorXd>> paths;
  ArmsState end;
  // The stage re-plans the one before it in another order (the receiving arm waits at its
  // pre-grasp before the board is brought): the previous stage's steps are dropped.
  bool supersedes_previous = false;
  // Steps planned on the assumption that the validator passes them (Run::settle()).
  std::vector<PendingCheck> pending;
  // The validator rejected a step it had been planned past: the stage is planned again in order.
  bool rejected_late = false;
  // The failure is the deadline's: step() found it passed, or the motion planner stopped at it
  // (MotionStatus::kTimeout); receive() tries no other branch after it. Typed so that no
  // decision reads the reason, which is for the attempt's outcome.
  bool deadline_passed = false;
  // A transfer stage's: the suction grasp (database id) whose pick it follows and with which
  // the suction arm holds the board at the robot-robot pose (Run::transfer).
  std::int64_t cup = 0;
  bool ok() const { return failure.empty(); }
};

using Hints = std::vector<const std::vector<Eigen::VectorXd>*>;

inline constexpr const char* kNoHumanPoseIk =
    "transfer_to_human: no valid IK at the robot-human pose";

// The steps whose paths, reversed, lead the receiving arm home after the release (Run::leave),
// where its retreat attaches to no roadmap node.
inline constexpr std::array<std::string_view, 3> kWayBackSteps = {
    "transfer_to_human", "receiving_grasp", "receiving_approach"};

// One plan() call: the board's records, the scene's world, both arms' motion planners and the
// memoised stages.
class Run {
 public:
  Run(const PlannerModel& model, const BoardPlanSettings& settings, const Scene& scene,
      const core::PartSpec& part, const BoardRecords& records, const std::string& suction_arm,
      std::chrono::steady_clock::time_point deadline,
      std::map<std::string, std::unique_ptr<core::LazyPrmPlanner>>& lazy_prm);

  const std::map<std::int64_t, db::RobotGraspRecord>& robot_grasps() const { return robot_grasps_; }
  const std::map<std::int64_t, db::RobotHandoverRecord>& handovers() const { return handovers_; }
  const core::Arm& suction_arm() const { return suction_; }
  const core::Arm& receiving_arm() const { return receiving_; }
  const ArmsState& start() const { return start_; }  // the robot and the tool as the scene has them
  // The run's times so far, the validator's own time on either thread included.
  int rejected_motions() const { return rejected_motions_; }
  int motions_planned() const { return motions_planned_; }
  PlanTimes times() const {
    PlanTimes t = times_;
    t.queued_validation = queue_ ? queue_->seconds() : queued_seconds_;
    return t;
  }

  // The plan is decided: the queued validations no chain used are dropped and the worker is
  // joined (after the job it is on, if any), so that the plan's time includes the wait.
  void stop_validation();

  // Bridges (a wedged end's too) of `checks` and stored-path repairs of `repair_checks` from now
  // on. The stages that failed are forgotten so that they are planned again; those that were
  // planned stand (a larger budget finds the same or more).
  void escalate(long checks, long repair_checks);

  // --- The exchange: the suction arm picks the board with the tool and hands it to the other
  // arm's gripper, which delivers it (exchange_way.cpp) ----------------------------------------

  // Whether the offline regrasp graph connected this goal with this shared grasp.
  bool connected_offline(const db::HandoverCandidateRecord& goal,
                         const db::SharedGraspRecord& shared);
  // Whether the build examined the suction arm's transfer from the pick to this shared grasp's
  // robot-robot pose and found none: blocked at the board's nominal stage.
  bool exchange_blocked_offline(const db::SharedGraspRecord& shared);

  // Whether the receiving arm's reach of the exchange failed with this shared grasp's robot grasp
  // at its board pose, under another robot-robot pose of the same board pose (another suction
  // grasp holding the board there).
  bool receive_failed_at_same_pose(const db::SharedGraspRecord& shared) const;

  // The suction grasp the exchange at `rr` picks and holds the board with (its transfer's; the
  // database's for a robot-robot pose not planned).
  std::int64_t suction_grasp_of(const db::RobotHandoverRecord& rr) const;

  // After a planned way that ends with the suction arm holding the tool (`end`): the tool put
  // back where the scene has its place and the arm home (steps tool_to_place, tool_lower,
  // tool_retreat, tool_to_home_empty), appended to `steps` with their times after the last, and
  // `end` updated; the board stands at `board_world` (the human has it). "" or the failure
  // (steps and end then unchanged). Settled before it returns.
  std::string return_tool(const core::Pose& board_world, std::vector<PlanStep>& steps,
                          ArmsState& end);

  // Where the scene has the tool on the table: the suction arm takes it and goes home with it
  // (steps tool_approach, tool_grasp, tool_lift, tool_to_home), appended to `steps` as
  // return_tool's, `end` updated. "" or the failure. Settled before it returns.
  std::string take_tool(std::vector<PlanStep>& steps, ArmsState& end);

  // The whole chain for one goal and shared grasp: the memoised stages in order.
  std::string chain(const db::HandoverCandidateRecord& goal, const db::SharedGraspRecord& shared,
                    std::vector<PlanStep>& steps, ArmsState& end);

  // --- The direct way: one arm's gripper picks the board where it lies and delivers it ------
  // (direct_way.cpp)

  // The whole direct chain for one goal and direct grasp: pick, present, retreat.
  std::string direct_chain(const db::HandoverCandidateRecord& goal,
                           const db::DirectGraspRecord& direct, std::vector<PlanStep>& steps,
                           ArmsState& end);

  // --- The regrasp way: the gripper picks the board, sets it down on the table on another
  // resting pose, takes it again with the grasp that serves the goal and delivers it
  // (regrasp_way.cpp)

  std::string regrasp_chain(const db::HandoverCandidateRecord& goal,
                            const db::TableRegraspRecord& regrasp, std::vector<PlanStep>& steps,
                            ArmsState& end);

  // --- The suction way: the suction arm picks the board with the tool and presents it on its
  // cup; the human takes it from the cup (suction_way.cpp) ---------------------------------------

  std::string suction_chain(const db::HandoverCandidateRecord& goal,
                            const db::SuctionDeliveryRecord& delivery, std::vector<PlanStep>& steps,
                            ArmsState& end);
  // The suction grasp the delivery picks and presents the board with (a stand-in of the
  // database's where that one's pick or presentation failed; the database's when not planned).
  std::int64_t suction_delivery_cup(const db::SuctionDeliveryRecord& delivery,
                                    const db::HandoverCandidateRecord& goal) const;

  // --- Estimates: a way's robot time before it is planned (way_estimate.cpp) ------------------

  // The robot time (s) the way would take from where the robot and the tool are (start()): its
  // arms' motions one after another, as the plan runs them. A motion the regrasp graph stores
  // counts its stored duration (RegraspEdgeRecord::duration; in a file without durations, its
  // stored path timed rest to rest); any other is the straight joint-space move between the
  // configurations the records store, timed rest to rest (core::rest_to_rest_duration) at the
  // planner's speed scale. The tool is taken from (or set down on) its place where the way needs
  // it. Left out: the straight approaches, lifts and retreats of a few centimetres, which every
  // way has, and the detour a planned motion makes around what the straight move would cross.
  // Infinite where no estimate can be made (a record naming an arm or pose the run lacks, the
  // tool out of the suction arm's reach): such a way is tried after the others.
  double estimate(const db::HandoverCandidateRecord& goal, const db::DirectGraspRecord& direct);
  double estimate(const db::HandoverCandidateRecord& goal, const db::TableRegraspRecord& regrasp);
  double estimate(const db::HandoverCandidateRecord& goal,
                  const db::SuctionDeliveryRecord& delivery);
  double estimate(const db::HandoverCandidateRecord& goal, const db::SharedGraspRecord& shared);

 private:
  // --- Construction, the memoised stages and the board's records (plan_run.cpp) --------------

  static core::LazyPrmPlanner* baseline(
      std::map<std::string, std::unique_ptr<core::LazyPrmPlanner>>& lazy_prm, const core::Arm& arm,
      const MotionSettings& motion);

  // Calls `visit` with every memo of stages after the tool's (each a map to Stage).
  template <typename Visit>
  void each_memo(Visit visit) {
    visit(picks_);
    visit(transfers_);
    visit(receives_);
    visit(releases_);
    visit(presents_);
    visit(leaves_);
    visit(gripper_picks_);
    visit(direct_presents_);
    visit(direct_leaves_);
    visit(set_downs_);
    visit(repicks_);
    visit(regrasp_presents_);
    visit(regrasp_leaves_);
    visit(relay_tool_downs_);
    visit(suction_presents_);
    visit(suction_leaves_);
  }

  // Drops the memoised stages `which` picks, to be planned again when next asked for.
  template <typename Which>
  void forget(Which which) {
    if (tool_ && which(*tool_)) tool_.reset();
    if (tool_down_ && which(*tool_down_)) tool_down_.reset();
    if (tool_return_ && which(*tool_return_)) tool_return_.reset();
    each_memo([&](auto& stages) {
      std::erase_if(stages, [&](const auto& entry) { return which(entry.second); });
    });
  }

  const db::RegraspNodeRecord* node(std::int64_t id) const;
  const std::vector<bool>* filter_for(const core::Arm& arm, const std::string& kind,
                                      std::int64_t id) const;

  // The connected regrasp edges of `kind` moving `arm` whose ends satisfy the predicates: their
  // stored paths (hints) and where they end (preferred IK branches).
  template <typename ToMatch, typename FromMatch>
  std::vector<const db::RegraspEdgeRecord*> stored_edges(const std::string& kind,
                                                         const core::Arm& arm, ToMatch to_match,
                                                         FromMatch from_match) const {
    std::vector<const db::RegraspEdgeRecord*> out;
    for (const auto& e : edges_) {
      if (!e.connected || e.kind != kind || e.arm != arm.spec.name || e.path.size() < 2) continue;
      const auto* to = node(e.to_node);
      const auto* from = node(e.from_node);
      if (to != nullptr && from != nullptr && to_match(*to) && from_match(*from)) {
        out.push_back(&e);
      }
    }
    return out;
  }

  static Hints paths_of(const std::vector<const db::RegraspEdgeRecord*>& edges);

  // --- Estimates (way_estimate.cpp) --------------------------------------------------------------

  // The straight move's rest-to-rest time at the planner's speed scale (s).
  double straight_seconds(const core::Arm& arm, const Eigen::VectorXd& from,
                          const Eigen::VectorXd& to) const;
  // The stored motion `edge` in seconds, or `otherwise` when there is none (nullptr).
  double stored_seconds(const core::Arm& arm, const db::RegraspEdgeRecord* edge,
                        double otherwise) const;
  // The stored motions and pick configurations the estimates look up, by what they join: the
  // first connected edge of each (id order, as the stages' hints), indexed in one pass over the
  // board's graph when first needed.
  struct EstimateIndex {
    // (arm, suction grasp): the pick node's first solution.
    std::map<std::pair<std::string, std::int64_t>, const Eigen::VectorXd*> suction_pick;
    // (robot handover, suction grasp): the suction arm's transfer from the pick.
    std::map<std::pair<std::int64_t, std::int64_t>, const db::RegraspEdgeRecord*> to_exchange;
    // (robot handover, robot grasp): the receiving arm's transit from home.
    std::map<std::pair<std::int64_t, std::int64_t>, const db::RegraspEdgeRecord*> way_in;
    // (robot handover, robot grasp, goal): the receiving arm's transfer to the human (also what
    // connected_offline() asks).
    std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, const db::RegraspEdgeRecord*>
        to_human;
    // (arm, suction grasp, goal): the suction delivery's transfer from the pick.
    std::map<std::tuple<std::string, std::int64_t, std::int64_t>, const db::RegraspEdgeRecord*>
        on_cup;
    // Robot handovers whose suction-arm transfer from the pick the build stored, connected or
    // not (a goal it examined used them).
    std::set<std::int64_t> exchange_examined;
  };
  const EstimateIndex& estimate_index();
  // The suction arm from home to the tool's place in the scene and back: taking the tool or
  // setting it down (computed once per run).
  double tool_seconds();
  // The arm's joints where the scene has them.
  Eigen::VectorXd start_joints(const core::Arm& arm) const;

  // --- The step pipeline: plan a motion, smooth, time, validate (plan_run.cpp) ----------------

  // Plans, times and validates one motion of the stage; on success the step is appended and
  // the arm's joints advance to the goal. The reason when it fails.
  // `stagings`: configurations from which the goal is a straight, valid segment (further back
  // along an approach), tried as intermediate goals, roadmap only, when the goal itself cannot
  // be reached: a goal pressed against the robot's body or the other arm's load may attach to
  // no roadmap node while a pose a few centimetres away does.
  // A failure that is the deadline's marks the stage (Stage::deadline_passed).
  std::string step(Stage& stage, ArmMotionPlanner& planner, const core::Arm& arm,
                   MotionRequest request, const std::string& name,
                   StepEvent start_event = StepEvent::kNone, StepEvent end_event = StepEvent::kNone,
                   const std::vector<Eigen::VectorXd>& stagings = {});

  // Whether a found path is smoothed: every one with more than one segment, unless its start
  // touches by design (a lift).
  bool smooths(const std::vector<Eigen::VectorXd>& path, const MotionRequest& request) const;

  // Smooths `path` in place (SuiteSparse) under `checks`, prepared for the motion's request;
  // whether it did (else the path is left as found).
  bool smoothed(ArmMotionPlanner& checks, std::vector<Eigen::VectorXd>& path) const;

  // The smoother's validity checks for a queued step of `arm`, on the queue's thread `slot`:
  // the planner's checks at the planner's resolutions, with their own collision data.
  ArmMotionPlanner& smoothing_checks(std::size_t slot, const core::Arm& arm);

  // The stage's step `i` as executed: for a queued step, once its smoothing is in (waited for).
  // Asked for while a motion is planned (MotionRequest::late_hints): the wait is counted as
  // validation, not as the motion's planning.
  const std::vector<Eigen::VectorXd>& executed_path(const Stage& st, std::size_t i);

  // The step's path, timing and length as `path`, timed: the stage's later steps move by the
  // change in its duration.
  static void retime(Stage& st, std::size_t step, const std::vector<Eigen::VectorXd>& path,
                     const TimedPath& timed);

  // After the validator rejected the step's path (`s.validation`): the found path when the
  // rejected one was smoothed, then a re-plan at the validator's resolution. Leaves the motion,
  // its path, timing and report in place; the reason when nothing passed.
  std::string recover(const Motion& frame, const MotionRequest& request, ArmMotionPlanner& planner,
                      const core::Arm& arm, const std::string& name, MotionResult& motion,
                      std::vector<Eigen::VectorXd>& path, TimedPath& timed, PlanStep& s);

  // The queue's reports for the steps planned on without them, oldest first, with each rejected
  // step's fallbacks (recover()) as step() would have run them. False when a stage's step is
  // still rejected: that stage (marked rejected_late) must be planned again in order, since
  // its alternatives come after a rejection.
  // Only the chain's stages are settled, and only once it is planned through: the stages of
  // attempts that failed further on are settled when a chain that plans through uses them, and
  // until then their jobs wait for the worker instead of holding up this chain.
  bool settle(std::span<const Stage* const> chain);
  // Plans a way's chain (`plan_stages` fills `stages`) and settles it from stages[first] on. A
  // stage planned past a step the validator then rejected, fallbacks and all, is planned again
  // in order, validating as it goes: after a rejection it may take another branch or route.
  // The stages after it stand (a memoised stage ends where its key says).
  void plan_settled(std::span<const Stage*> stages, std::size_t first,
                    const std::function<void()>& plan_stages);

  // The stage's queued reports are not wanted (an attempt given up, a stage that failed).
  void abandon(Stage& st);

  MotionResult timed_plan(ArmMotionPlanner& planner, const MotionRequest& request);

  TimedPath timed_path(const core::Arm& arm, const std::vector<Eigen::VectorXd>& path) const;

  // What the validator needs to know of a motion of the stage besides its trajectory.
  Motion motion_frame(const Stage& stage, const core::Arm& arm, const MotionRequest& request) const;

  // Times the path and re-checks it with the validator, here and now: whether it passed.
  bool timed_and_valid(const Motion& frame, const core::Arm& arm,
                       const std::vector<Eigen::VectorXd>& path, TimedPath& timed,
                       ValidationReport& report);

  // The data a step validated here and now uses. With a queue, not the worker's: it may still be
  // validating other attempts' steps (settle() waits for the chain's only). Made when first
  // needed (a rejected step's fallbacks, a stage planned again in order: rare).
  const std::vector<core::CollisionData*>& inline_validation();

  // --- What the stages of both ways share (plan_run.cpp) --------------------------------------

  // The first of `candidates` valid for the planner under `request` in the stage's state.
  std::optional<Eigen::VectorXd> first_valid(const Stage& stage, ArmMotionPlanner& planner,
                                             MotionRequest request,
                                             const std::vector<Eigen::VectorXd>& candidates);

  Eigen::VectorXd arm_q(const Stage& stage, const core::Arm& arm) const;

  ArmMotionPlanner& planner_of(const core::Arm& arm);

  double jaw_for(const db::RobotGraspRecord& grasp) const;

  HeldBoard in_gripper(const db::RobotGraspRecord& grasp) const;

  // Where the gripper opens before closing on the board (core::find_pre_grasp, as the offline
  // exchange check), under `request`; nothing when the grasp can only be reached directly.
  std::optional<Eigen::VectorXd> pre_grasp(const Stage& st, const core::Arm& arm,
                                           const MotionRequest& request,
                                           const Eigen::VectorXd& grasp_q);

  // After the human takes the board (wrist F/T): the gripper opens, `arm` backs off the way a
  // gripper would come in (the offline search required one at this pose) and goes home. The
  // reason when it fails.
  // `way_back`: steps (of stages, by name) whose paths, reversed, lead the arm home where its
  // retreat attaches to no roadmap node: from beside the human's hands a straight segment often
  // reaches no roadmap node, while the arm's own way in, now empty-handed, is clear for a while.
  std::string retreat(Stage& st, const core::Arm& arm, const db::HandoverCandidateRecord& goal,
                      const std::string& home_step,
                      const std::vector<std::pair<const Stage*, std::string_view>>& way_back_of);

  // --- The exchange's stages, in order (exchange_way.cpp) -------------------------------------

  // 0. The tool, when it still stands on the table: approach, grasp, lift, home (where the
  // offline chain home -> pick starts).
  const Stage& tool();

  HeldBoard on_cup(const db::SuctionGraspRecord& cup) const;

  // 1. Suction pick at the detected pose: approach along the cup's axis, pick, lift. Every IK
  // branch whose approach and lift stay in it (their nearest solutions) and whose three ends are
  // valid, in order, until one's motions plan: near the robot's body the first branch's pre-pick
  // may attach to no roadmap node while another's does.
  const Stage& pick(std::int64_t cup_id);

  // The suction grasps that can stand in for `cup` at a robot-robot pose: the cup is symmetric
  // about its axis, so a grasp at the same point of the same face, turned about the axis, holds
  // the board at the same pose with the suction arm's TCP turned about the cup's axis. `cup`
  // first (the database's chain, its stored paths), then the others by how little their pick at
  // the detected pose turns the TCP from `cup`'s pick at the board's nominal pose: where the
  // stack is turned, the one whose arm posture at the pick is the one the build planned.
  std::vector<std::int64_t> stand_in_cups(const db::SuctionGraspRecord& cup) const;

  // 2. The pick (by stand_in_cups(), the first whose pick and transfer plan) and the transfer to
  // the robot-robot pose through the suction grasp's filtered roadmap. Stage::cup says which.
  const Stage& transfer(const db::RobotHandoverRecord& rr);

  // Drops the memoised stages after the transfer to robot-robot pose `rr_id` (the exchange, the
  // release, the presentation and the leave there): they start where that transfer ended, and
  // it is being planned anew (after a late rejection, perhaps with another suction grasp).
  void forget_after_transfer(std::int64_t rr_id);

  // The suction arm, holding the board on `cup_id` after the lift, to the robot-robot pose.
  std::string transfer_steps(Stage& st, const db::RobotHandoverRecord& rr, std::int64_t cup_id);

  // 3. The receiving arm's approach and grasp, the board held by the suction arm. The approach
  // backs off along the gripper's axis as far as the scene lets it (the exchange may be close
  // to the robot's body), else the arm goes to the grasp directly.
  const Stage& receive(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp);

  // From the lift: the receiving arm to its pre-grasp (the board on the suction cup above its
  // pick pose), the suction arm to the robot-robot pose past it, the grasp.
  std::string preposition(Stage& st, const db::RobotHandoverRecord& rr,
                          const Eigen::VectorXd& grasp_q);

  // pre_grasp() for the receiving arm.
  std::optional<Eigen::VectorXd> pre_grasp(const Stage& st, const MotionRequest& request,
                                           const Eigen::VectorXd& grasp_q);

  // The receiving arm to `grasp_q` at the exchange: an approach from behind the grasp where the
  // scene lets it, staging poses when the approach's start is boxed in.
  std::string reach_exchange(Stage& st, const db::RobotHandoverRecord& rr,
                             const db::RobotGraspRecord& grasp, const Eigen::VectorXd& grasp_q,
                             bool bridges, Hints hints);

  // 4. Suction off; the suction arm backs off along the cup's axis where it can (else it leaves
  // directly) and goes home.
  const Stage& release(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp);

  // Suction off with the board held at `board_world` on `cup` (by the other arm's gripper, or by
  // the human): the suction arm backs off along the cup's axis where it can (else it leaves
  // directly) and goes home. "" or the failure.
  std::string let_go_of_cup(Stage& st, const db::SuctionGraspRecord& cup,
                            const core::Pose& board_world);

  // 5. The slip-constrained transfer to the human.
  const Stage& present(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp,
                       const db::HandoverCandidateRecord& goal);

  // Whether any IK branch of the receiving arm at the goal's robot-human pose with `grasp` is
  // valid in the state present() checks it in (the suction arm home, the board in hand): the
  // same answer without planning the exchange first. Per grasp and goal.
  bool reaches_human_pose(const db::RobotGraspRecord& grasp,
                          const db::HandoverCandidateRecord& goal);

  // 6. The human takes it (wrist F/T): open, back off, home. Once per present stage.
  const Stage& leave(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp,
                     const db::HandoverCandidateRecord& goal);

  // --- The direct way's stages, in order (direct_way.cpp) -----------------------------------

  const core::Arm* arm_named(const std::string& name) const;

  // The suction arm sets the tool down where the scene has its place on the table, freeing its
  // gripper for a direct pick: above the place, straight down (the tool's foot meets the table:
  // the last sample touches by design), the gripper opens (`tool_released`), back along the
  // gripper's approach axis. Once per call, from the start.
  const Stage& tool_down();
  // The same from st.end (the suction arm holding the tool), the board standing at
  // `board_world`: fills st's steps and end, or its failure.
  void put_tool_down(Stage& st, const core::Pose& board_world);

  // The gripper's pick at the detected pose: the open gripper from a pre-grasp (approach) to the
  // grasp, closed, and the lift straight up. A branch whose way in, grasp and lift are valid;
  // the build's branch first.
  const Stage& gripper_pick(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                            const db::DirectGraspRecord& direct);

  // The slip-constrained transfer from the lift to the robot-human pose.
  const Stage& direct_present(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                              const db::HandoverCandidateRecord& goal,
                              const db::DirectGraspRecord& direct);

  const Stage& direct_leave(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                            const db::HandoverCandidateRecord& goal,
                            const db::DirectGraspRecord& direct);

  // What a gripper pick does, into `st` from its end state: the open gripper from a pre-grasp to
  // the grasp of the board standing at `board`, closed, and the lift straight up; the IK branch
  // `preferred` first. `again`: the board was set down for a regrasp (the steps' names say so).
  void take(Stage& st, const core::Arm& arm, const db::RobotGraspRecord& grasp,
            const core::Pose& board, const Eigen::VectorXd& preferred, bool again);

  // The slip-constrained transfer to the robot-human pose, into `st` from its end state.
  void present_held(Stage& st, const core::Arm& arm, const db::RobotGraspRecord& grasp,
                    const db::HandoverCandidateRecord& goal, const Eigen::VectorXd& preferred);

  // Concatenates the chain's stages, each starting where the previous ended (a null first stage:
  // none, a null later stage: the chain stops there); the first failure, else "".
  static std::string join_stages(std::span<const Stage* const> stages, std::vector<PlanStep>& steps,
                                 ArmsState& end);

  // --- The regrasp way's stages after the pick (regrasp_way.cpp) ---------------------------

  // From the lift: above the set-down pose (within the pick grasp's slip limit), straight down
  // until the board rests on the table (`set_down`: the last sample touches by design), the
  // gripper opens, back along its approach.
  const Stage& set_down(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                        const db::TableRegraspRecord& regrasp, const Stage& picked);
  // A relay to the suction arm holding the tool: it sets the tool down where the scene has its
  // place (put_tool_down), the board set down at the record's placement.
  const Stage& tool_down_after_set_down(const db::TableRegraspRecord& regrasp, const Stage& set);
  // The gripper takes the board again where it was set down (take(), `again`).
  const Stage& repick(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                      const db::TableRegraspRecord& regrasp, const Stage& set);
  const Stage& regrasp_present(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                               const db::HandoverCandidateRecord& goal,
                               const db::TableRegraspRecord& regrasp, const Stage& taken);
  const Stage& regrasp_leave(const core::Arm& arm, const db::HandoverCandidateRecord& goal,
                             const db::TableRegraspRecord& regrasp, const Stage& presented);

  // --- The suction way's stages after the pick (suction_way.cpp) ----------------------------

  // The pick (by stand_in_cups(), the first whose pick and presentation plan) and the transfer,
  // the board on the cup, to the goal's robot-human pose through the suction grasp's filtered
  // roadmap (`wait_for_human`). Stage::cup says which cup.
  const Stage& suction_present(const db::SuctionDeliveryRecord& delivery,
                               const db::HandoverCandidateRecord& goal);
  // The human holds the board: suction off, back along the cup's axis where the scene lets it,
  // home with the tool.
  const Stage& suction_leave(const db::SuctionDeliveryRecord& delivery,
                             const db::HandoverCandidateRecord& goal);

  // --- The run's state -----------------------------------------------------------------------

  const PlannerModel& model_;
  const core::Cell& cell_;
  const BoardPlanSettings& settings_;
  const Scene& scene_;
  const core::PartSpec& part_;
  const db::PartRecord& record_;
  std::chrono::steady_clock::time_point deadline_;
  // The board's records (PlannerModel::board_records).
  const std::map<std::int64_t, db::RobotGraspRecord>& robot_grasps_;
  const std::map<std::int64_t, db::SuctionGraspRecord>& suction_grasps_;
  const std::map<std::int64_t, db::RobotHandoverRecord>& handovers_;
  const std::map<std::tuple<std::string, std::string, std::int64_t>, std::vector<bool>>& filters_;
  const std::map<std::int64_t, const db::RegraspNodeRecord*>& node_by_id_;
  const std::vector<db::RegraspEdgeRecord>& edges_;
  World world_;
  const core::Arm& suction_;
  const core::Arm& receiving_;
  ArmMotionPlanner suction_planner_;
  ArmMotionPlanner receiving_planner_;
  // The smoother's checks for queued steps, per queue slot (ValidationQueue::kWorkerSlot,
  // kCallerSlot) and arm (suction, receiving); made when first needed. Before the queue, whose
  // worker uses them until it is joined.
  std::array<std::array<std::unique_ptr<ArmMotionPlanner>, 2>, 2> smoothing_checks_;
  std::vector<std::unique_ptr<core::CollisionData>> validation_data_;  // one per thread
  std::vector<core::CollisionData*> validation_threads_;
  std::unique_ptr<core::CollisionData> inline_data_;  // inline_validation()
  std::vector<core::CollisionData*> inline_threads_;
  double queued_seconds_ = 0.0;  // the queue's, once stop_validation() dropped it
  // Validates the steps on the second thread while the next are planned (after the data).
  std::optional<ValidationQueue> queue_;
  bool speculate_ = false;  // step() queues its motion's validation and plans on
  int rejected_motions_ = 0;
  int motions_planned_ = 0;
  core::Pose board_initial_;
  Eigen::Vector3d opening_tcp_;
  Eigen::Vector3d approach_tcp_;
  ArmsState start_;

  PlanTimes times_;
  std::optional<double> tool_seconds_;  // tool_seconds()'s, once computed
  std::optional<EstimateIndex> estimate_index_;
  std::optional<Stage> tool_;
  std::optional<Stage> tool_down_;
  std::optional<Stage> tool_return_;         // return_tool's, once a way is planned
  std::map<std::int64_t, Stage> picks_;      // by suction grasp
  std::map<std::int64_t, Stage> transfers_;  // by robot handover
  std::map<std::pair<std::int64_t, std::int64_t>, Stage> receives_;  // by (handover, grasp)
  std::map<std::pair<std::int64_t, std::int64_t>, Stage> releases_;
  std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, Stage> presents_;
  std::map<std::pair<std::int64_t, std::int64_t>, bool> human_reach_;  // by (grasp, goal)
  std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, Stage> leaves_;
  // The direct way's, by (arm, robot grasp) and (arm, robot grasp, goal).
  std::map<std::pair<std::string, std::int64_t>, Stage> gripper_picks_;
  std::map<std::tuple<std::string, std::int64_t, std::int64_t>, Stage> direct_presents_;
  std::map<std::tuple<std::string, std::int64_t, std::int64_t>, Stage> direct_leaves_;
  // The regrasp way's stages after the pick, by table regrasp record (one per goal, arm, grasps
  // and set-down pose).
  std::map<std::int64_t, Stage> set_downs_;
  std::map<std::int64_t, Stage> repicks_;
  std::map<std::int64_t, Stage> regrasp_presents_;
  std::map<std::int64_t, Stage> regrasp_leaves_;
  std::map<std::int64_t, Stage> relay_tool_downs_;  // by table regrasp record
  // The suction way's, by (the delivery's suction grasp, goal).
  std::map<std::pair<std::int64_t, std::int64_t>, Stage> suction_presents_;
  std::map<std::pair<std::int64_t, std::int64_t>, Stage> suction_leaves_;
};

}  // namespace hila::online::detail
