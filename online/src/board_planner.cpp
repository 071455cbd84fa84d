#include "hila/online/board_planner.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <iomanip>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <string_view>
#include <tuple>

#include "hila/core/bridge.hpp"
#include "hila/core/payload.hpp"
#include "hila/core/pre_grasp.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/online/smoother.hpp"
#include "hila/online/time_parameterization.hpp"
#include "hila/online/validation_queue.hpp"

namespace hila::online {

namespace {

double path_length(const std::vector<Eigen::VectorXd>& q) {
  double l = 0.0;
  for (std::size_t i = 1; i < q.size(); ++i) l += (q[i] - q[i - 1]).norm();
  return l;
}

// IK solutions of `arm` for a TCP pose in the world, nearest `seed` first (`preferred`, when
// given and among them, first of all).
std::vector<Eigen::VectorXd> solutions(const core::Cell& cell, const core::Arm& arm,
                                       const core::Pose& tcp, const Eigen::VectorXd& seed,
                                       const Eigen::VectorXd* preferred = nullptr) {
  core::UrIkSolutions ik;
  const int n = arm.ur_ik->solve(core::arm_base_in_world(cell, arm).inverse() * tcp, seed, ik);
  std::vector<Eigen::VectorXd> out;
  for (int i = 0; i < n; ++i) {
    Eigen::VectorXd q = ik.q[static_cast<std::size_t>(i)];
    // The stored branch may be the same solution with a joint turned by a full turn (the IK
    // wraps towards its seed): it is the stored one the offline paths end in.
    if (preferred != nullptr && preferred->size() == q.size()) {
      const Eigen::ArrayXd turns = (*preferred - q).array() / (2.0 * M_PI);
      if (((turns - turns.round()).abs() < 1e-6).all()) q = *preferred;
    }
    out.push_back(std::move(q));
  }
  std::sort(out.begin(), out.end(), [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    const bool pa = preferred && (a - *preferred).norm() < 1e-6;
    const bool pb = preferred && (b - *preferred).norm() < 1e-6;
    if (pa != pb) return pa;
    return (a - seed).norm() < (b - seed).norm();
  });
  return out;
}

core::Pose shifted(const core::Pose& pose, const Eigen::Vector3d& by) {
  core::Pose p = pose;
  p.translation() += by;
  return p;
}

}  // namespace

const char* to_string(DeliveryMode mode) {
  switch (mode) {
    case DeliveryMode::kExchange:
      return "exchange";
    case DeliveryMode::kDirect:
      return "direct";
  }
  return "?";
}

const char* to_string(BoardPlanStatus status) {
  switch (status) {
    case BoardPlanStatus::kSolved:
      return "solved";
    case BoardPlanStatus::kNoGoal:
      return "no goal";
    case BoardPlanStatus::kTimeout:
      return "timeout";
    case BoardPlanStatus::kHumanOutOfReach:
      return "human out of reach";
    case BoardPlanStatus::kOverPayload:
      return "over payload";
  }
  return "unknown";
}

namespace {

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
  bool ok() const { return failure.empty(); }
};

using Hints = std::vector<const std::vector<Eigen::VectorXd>*>;

constexpr const char* kNoHumanPoseIk = "transfer_to_human: no valid IK at the robot-human pose";

// The steps whose paths, reversed, lead the receiving arm home after the release (Run::leave),
// where its retreat attaches to no roadmap node.
constexpr std::array<std::string_view, 3> kWayBackSteps = {"transfer_to_human", "receiving_grasp",
                                                           "receiving_approach"};

// Adds the time from its construction to its destruction to `into`.
class Stopwatch {
 public:
  explicit Stopwatch(double& into) : into_(into), started_(std::chrono::steady_clock::now()) {}
  ~Stopwatch() {
    into_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  }
  Stopwatch(const Stopwatch&) = delete;
  Stopwatch& operator=(const Stopwatch&) = delete;

 private:
  double& into_;
  std::chrono::steady_clock::time_point started_;
};

// One plan() call: the board's records, the scene's world, both arms' motion planners and the
// memoised stages.
class Run {
 public:
  Run(const PlannerModel& model, const BoardPlanSettings& settings, const Scene& scene,
      const core::PartSpec& part, const BoardRecords& records,
      std::chrono::steady_clock::time_point deadline,
      std::map<std::string, std::unique_ptr<core::LazyPrmPlanner>>& lazy_prm)
      : model_(model),
        cell_(model.cell()),
        settings_(settings),
        scene_(scene),
        part_(part),
        record_(records.part),
        deadline_(deadline),
        robot_grasps_(records.robot_grasps),
        suction_grasps_(records.suction_grasps),
        handovers_(records.robot_handovers),
        filters_(records.filters),
        node_by_id_(records.node_by_id),
        edges_(records.regrasp_edges),
        world_(cell_, model.product(), scene, part.name),
        suction_(cell_.arms()[static_cast<std::size_t>(world_.stage().suction_arm)]),
        receiving_(cell_.arms()[world_.stage().suction_arm == 0 ? 1u : 0u]),
        suction_planner_(world_, model.roadmap(suction_.spec.name), suction_.spec.name,
                         settings.motion, baseline(lazy_prm, suction_, settings.motion)),
        receiving_planner_(world_, model.roadmap(receiving_.spec.name), receiving_.spec.name,
                           settings.motion, baseline(lazy_prm, receiving_, settings.motion)),
        board_initial_(scene.initial_pose(part)),
        opening_tcp_(cell_.spec().gripper.opening_axis.normalized()),
        approach_tcp_(cell_.spec().gripper.approach_axis.normalized()) {
    for (int t = 0; t < std::max(1, settings.validation_threads); ++t) {
      validation_data_.push_back(std::make_unique<core::CollisionData>(world_.make_data()));
      validation_threads_.push_back(validation_data_.back().get());
    }
    if (settings.overlap_validation && validation_data_.size() >= 2) {
      queue_.emplace(world_, settings.validator, *validation_data_[0], *validation_data_[1]);
      speculate_ = true;
    }
    start_.robot_q = cell_.home_configuration();
    for (const auto& arm : cell_.arms()) {
      const auto it = scene.robot.find(arm.spec.name);
      if (it != scene.robot.end()) cell_.set_arm(start_.robot_q, arm, it->second);
    }
    start_.tool_in_hand = scene.tool_in_hand;
  }

  const std::map<std::int64_t, db::RobotGraspRecord>& robot_grasps() const { return robot_grasps_; }
  const std::map<std::int64_t, db::RobotHandoverRecord>& handovers() const { return handovers_; }
  const core::Arm& suction_arm() const { return suction_; }
  const core::Arm& receiving_arm() const { return receiving_; }
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
  void stop_validation() {
    if (!queue_) return;
    if (tool_) abandon(*tool_);
    if (tool_down_) abandon(*tool_down_);
    each_memo([&](auto& stages) {
      for (auto& entry : stages) abandon(entry.second);
    });
    queued_seconds_ = queue_->seconds();  // the job it is on when joined is not counted
    queue_.reset();
  }

  // Bridges (a wedged end's too) of `checks` and stored-path repairs of `repair_checks` from now
  // on. The stages that failed are forgotten so that they are planned again; those that were
  // planned stand (a larger budget finds the same or more).
  void escalate(long checks, long repair_checks) {
    suction_planner_.set_bridge_checks(checks);
    receiving_planner_.set_bridge_checks(checks);
    suction_planner_.set_wedged_bridge_checks(checks);
    receiving_planner_.set_wedged_bridge_checks(checks);
    suction_planner_.set_repair_checks(repair_checks);
    receiving_planner_.set_repair_checks(repair_checks);
    forget([](const Stage& st) { return !st.ok(); });
  }

  // Whether the offline regrasp graph connected this goal with this shared grasp.
  bool connected_offline(const db::HandoverCandidateRecord& goal,
                         const db::SharedGraspRecord& shared) const {
    for (const auto& e : edges_) {
      if (!e.connected || e.kind != "transfer" || e.arm != receiving_.spec.name) continue;
      const auto* to = node(e.to_node);
      const auto* from = node(e.from_node);
      if (to != nullptr && from != nullptr && to->candidate_id == goal.id &&
          to->grasp_id == shared.robot_grasp_id &&
          from->robot_handover_id == shared.robot_handover_id) {
        return true;
      }
    }
    return false;
  }

  // Whether the receiving arm's reach of the exchange failed with this shared grasp's robot grasp
  // at its board pose, under another robot-robot pose of the same board pose (another suction
  // grasp holding the board there).
  bool receive_failed_at_same_pose(const db::SharedGraspRecord& shared) const {
    const auto rr = handovers_.find(shared.robot_handover_id);
    if (rr == handovers_.end()) return false;
    for (const auto& [key, stage] : receives_) {
      if (key.second != shared.robot_grasp_id || key.first == shared.robot_handover_id ||
          stage.ok()) {
        continue;
      }
      const auto other = handovers_.find(key.first);
      if (other != handovers_.end() && other->second.board.matrix() == rr->second.board.matrix()) {
        return true;
      }
    }
    return false;
  }

  // The whole chain for one goal and shared grasp: the memoised stages in order.
  std::string chain(const db::HandoverCandidateRecord& goal, const db::SharedGraspRecord& shared,
                    std::vector<PlanStep>& steps, ArmsState& end) {
    const auto rr_it = handovers_.find(shared.robot_handover_id);
    if (rr_it == handovers_.end() || suction_grasps_.count(rr_it->second.suction_grasp_id) == 0 ||
        robot_grasps_.count(shared.robot_grasp_id) == 0) {
      return "the database's shared grasp refers to a missing record";
    }
    const db::RobotHandoverRecord& rr = rr_it->second;
    const db::RobotGraspRecord& grasp = robot_grasps_.at(shared.robot_grasp_id);
    const Stage* stages[7] = {};
    const auto plan_stages = [&] {
      stages[0] = &tool();
      if (stages[0]->ok()) stages[1] = &pick(rr.suction_grasp_id);
      if (stages[1] != nullptr && stages[1]->ok()) stages[2] = &transfer(rr);
      // The exchange and release are planned per grasp: not for one whose goal the receiving
      // arm cannot reach (the present stage's own first check, made first).
      if (stages[2] != nullptr && stages[2]->ok() &&
          (!settings_.reach_human_pose_first || reaches_human_pose(grasp, goal))) {
        stages[3] = &receive(rr, grasp);
      }
      if (stages[3] != nullptr && stages[3]->ok()) stages[4] = &release(rr, grasp);
      if (stages[4] != nullptr && stages[4]->ok()) stages[5] = &present(rr, grasp, goal);
      if (stages[5] != nullptr && stages[5]->ok()) stages[6] = &leave(rr, grasp, goal);
    };
    plan_stages();
    if (!settle(stages)) {
      // A stage planned past a step the validator then rejected, fallbacks and all, is planned
      // again in order, validating as it goes: after a rejection it may take another branch or
      // route. The stages after it stand (a memoised stage ends where its key says).
      forget([](const Stage& st) { return st.rejected_late; });
      const bool speculating = speculate_;
      speculate_ = false;
      std::fill(std::begin(stages), std::end(stages), nullptr);
      plan_stages();
      speculate_ = speculating;
    }
    double clock = 0.0;
    std::size_t previous_begin = 0;
    for (const Stage* stage : stages) {
      if (stage == nullptr) {  // the stages before it hold: only the reach check stops so
        assert(settings_.reach_human_pose_first);
        return kNoHumanPoseIk;
      }
      if (!stage->ok()) return stage->failure;
      if (stage->supersedes_previous) {
        steps.resize(previous_begin);
        clock = steps.empty() ? 0.0 : steps.back().time.back();
      }
      previous_begin = steps.size();
      for (PlanStep s : stage->steps) {
        for (double& t : s.time) t += clock;
        steps.push_back(std::move(s));
      }
      if (!steps.empty()) clock = steps.back().time.back();
      end = stage->end;
    }
    return "";
  }

 private:
  static core::LazyPrmPlanner* baseline(
      std::map<std::string, std::unique_ptr<core::LazyPrmPlanner>>& lazy_prm, const core::Arm& arm,
      const MotionSettings& motion) {
    // Checked as finely as held-board motions here: the baseline gets the same checks.
    auto& p = lazy_prm[arm.spec.name];
    if (!p) {
      core::LazyPrmSettings s;
      s.resolution = motion.held_resolution;
      // Over the whole joint range: the scene's IK solutions may lie anywhere within the limits,
      // and a persistent roadmap cannot widen its box per query as a bridge does.
      s.joint_range = 2.0 * M_PI;
      p = std::make_unique<core::LazyPrmPlanner>(arm, s);
    }
    return p.get();
  }

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
  }

  // Drops the memoised stages `which` picks, to be planned again when next asked for.
  template <typename Which>
  void forget(Which which) {
    if (tool_ && which(*tool_)) tool_.reset();
    if (tool_down_ && which(*tool_down_)) tool_down_.reset();
    each_memo([&](auto& stages) {
      std::erase_if(stages, [&](const auto& entry) { return which(entry.second); });
    });
  }

  const db::RegraspNodeRecord* node(std::int64_t id) const {
    const auto it = node_by_id_.find(id);
    return it == node_by_id_.end() ? nullptr : it->second;
  }

  const std::vector<bool>* filter_for(const core::Arm& arm, const std::string& kind,
                                      std::int64_t id) const {
    const auto it = filters_.find({arm.spec.name, kind, id});
    return it == filters_.end() ? nullptr : &it->second;
  }

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

  static Hints paths_of(const std::vector<const db::RegraspEdgeRecord*>& edges) {
    Hints out;
    for (const auto* e : edges) out.push_back(&e->path);
    return out;
  }

  // Plans, times and validates one motion of the stage; on success the step is appended and
  // the arm's joints advance to the goal. The reason when it fails.
  // `stagings`: configurations from which the goal is a straight, valid segment (further back
  // along an approach), tried as intermediate goals, roadmap only, when the goal itself cannot
  // be reached: a goal pressed against the robot's body or the other arm's load may attach to
  // no roadmap node while a pose a few centimetres away does.
  std::string step(Stage& stage, ArmMotionPlanner& planner, const core::Arm& arm,
                   MotionRequest request, const std::string& name, const std::string& start_event,
                   const std::string& end_event,
                   const std::vector<Eigen::VectorXd>& stagings = {}) {
    if (std::chrono::steady_clock::now() >= deadline_) return name + ": the deadline passed";
    request.robot_q = stage.end.robot_q;
    request.tool_in_hand = stage.end.tool_in_hand;
    request.tool_world = scene_.tool;
    request.deadline = deadline_;
    MotionResult motion = timed_plan(planner, request);
    for (std::size_t i = 0; !motion.solved() && motion.status != MotionStatus::kTimeout &&
                            motion.status != MotionStatus::kInvalidStart && i < stagings.size();
         ++i) {
      MotionRequest staged = request;
      staged.goal = stagings[i];
      staged.allow_bridge = false;
      staged.max_searches = settings_.motion.staging_searches;
      MotionResult via_staging = timed_plan(planner, staged);
      if (!via_staging.solved() || !planner.segment_valid(stagings[i], request.goal)) continue;
      via_staging.path.push_back(request.goal);
      via_staging.via += "+staging";
      motion = std::move(via_staging);
    }
    if (!motion.solved()) return name + ": " + to_string(motion.status) + ": " + motion.reason;
    PlanStep s;
    const Motion frame = motion_frame(stage, arm, request);
    const double clock = stage.steps.empty() ? 0.0 : stage.steps.back().time.back();
    std::vector<Eigen::VectorXd> path = motion.path;
    TimedPath timed;
    // While the other thread is behind, a queued step is smoothed here (the same result
    // either way: the plan does not depend on which thread smoothed).
    const bool smooth_here =
        !speculate_ || (settings_.smooth_here_when_behind && queue_->backlog() > 0);
    if (smooth_here && smooths(path, request)) {
      const Stopwatch watch(times_.smoothing);
      s.smoothed = smoothed(planner, path);
    }
    if (speculate_) {
      // Smoothed, timed and validated on whichever thread takes the job while the next steps
      // are planned; until settle() reads the report, the step stands for its ends.
      MotionRequest checked = request;
      checked.hints.clear();
      checked.late_hints = nullptr;  // refers to the caller's frame
      auto finished = std::make_shared<FinishedPath>();
      const bool smooth = !smooth_here && smooths(path, request);
      auto finish = [this, finished, &arm, checked = std::move(checked), found = path, smooth,
                     smoothed_here = s.smoothed](std::size_t slot, Motion& m) {
        finished->path = found;
        finished->smoothed = smoothed_here;
        if (smooth) {
          const Stopwatch watch(finished->smoothing_seconds);
          ArmMotionPlanner& checks = smoothing_checks(slot, arm);
          checks.prepare(checked);
          finished->smoothed = smoothed(checks, finished->path);
        }
        finished->timed = timed_path(arm, finished->path);
        m.time = finished->timed.time;
        m.q = finished->timed.q;
      };
      PendingCheck pending{queue_->submit(frame, std::move(finish)),
                           stage.steps.size(),
                           frame,
                           request,
                           &planner,
                           &arm,
                           std::move(motion),
                           finished};
      pending.request.hints.clear();
      pending.request.late_hints = nullptr;
      s.via = pending.found.via;
      timed.time = {0.0, 0.0};
      timed.q = {path.front(), path.back()};
      stage.pending.push_back(std::move(pending));
    } else {
      const bool valid = timed_and_valid(frame, arm, path, timed, s.validation);
      if (!valid) {
        if (auto e = recover(frame, request, planner, arm, name, motion, path, timed, s);
            !e.empty()) {
          return e;
        }
      }
      s.via = motion.via;
    }
    s.name = name;
    s.arm = arm.spec.name;
    for (const double t : timed.time) s.time.push_back(clock + t);
    s.q = timed.q;
    s.event =
        start_event.empty() ? end_event : start_event + (end_event.empty() ? "" : "," + end_event);
    s.path_length = path_length(path);
    cell_.set_arm(stage.end.robot_q, arm, path.back());
    stage.paths.push_back(std::move(path));
    stage.steps.push_back(std::move(s));
    return "";
  }

  // Whether a found path is smoothed: every one with more than one segment, unless its start
  // touches by design (a lift).
  bool smooths(const std::vector<Eigen::VectorXd>& path, const MotionRequest& request) const {
    return settings_.smooth && path.size() > 2 && !request.start_in_contact &&
           !request.end_in_contact;
  }

  // Smooths `path` in place (SuiteSparse) under `checks`, prepared for the motion's request;
  // whether it did (else the path is left as found).
  bool smoothed(ArmMotionPlanner& checks, std::vector<Eigen::VectorXd>& path) const {
    SmoothResult smooth = smooth_path(
        path,
        // Its points are new configurations, 0.05 rad apart: each is checked with the
        // segment reaching it (an empty arm's segment has no sample between its ends).
        [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return checks.step_valid(a, b); },
        settings_.smoother);
    if (!smooth.smoothed) return false;
    path = std::move(smooth.path);
    return true;
  }

  // The smoother's validity checks for a queued step of `arm`, on the queue's thread `slot`:
  // the planner's checks at the planner's resolutions, with their own collision data.
  ArmMotionPlanner& smoothing_checks(std::size_t slot, const core::Arm& arm) {
    auto& checks = smoothing_checks_[slot][&arm == &suction_ ? 0 : 1];
    if (!checks) {
      MotionSettings motion = settings_.motion;
      motion.planner = MotionPlannerKind::kRoadmap;  // only its checks are used
      checks = std::make_unique<ArmMotionPlanner>(world_, model_.roadmap(arm.spec.name),
                                                  arm.spec.name, motion);
    }
    return *checks;
  }

  // The stage's step `i` as executed: for a queued step, once its smoothing is in (waited for).
  // Asked for while a motion is planned (MotionRequest::late_hints): the wait is counted as
  // validation, not as the motion's planning.
  const std::vector<Eigen::VectorXd>& executed_path(const Stage& st, std::size_t i) {
    for (const PendingCheck& p : st.pending) {
      if (p.step != i) continue;
      double waited = 0.0;
      {
        const Stopwatch watch(waited);
        queue_->wait_all({p.job});  // not the other attempts' jobs queued before it
      }
      times_.validation += waited;
      times_.motions -= waited;
      if (!p.finished->path.empty()) return p.finished->path;
      break;  // a discarded job never finished: as found
    }
    return st.paths[i];
  }

  // The step's path, timing and length as `path`, timed: the stage's later steps move by the
  // change in its duration.
  static void retime(Stage& st, std::size_t step, const std::vector<Eigen::VectorXd>& path,
                     const TimedPath& timed) {
    PlanStep& s = st.steps[step];
    const double begin = s.time.front();
    const double shift = timed.time.back() - (s.time.back() - begin);
    s.time.clear();
    for (const double t : timed.time) s.time.push_back(begin + t);
    s.q = timed.q;
    s.path_length = path_length(path);
    st.paths[step] = path;
    for (std::size_t later = step + 1; later < st.steps.size(); ++later) {
      for (double& t : st.steps[later].time) t += shift;
    }
  }

  // After the validator rejected the step's path (`s.validation`): the found path when the
  // rejected one was smoothed, then a re-plan at the validator's resolution. Leaves the motion,
  // its path, timing and report in place; the reason when nothing passed.
  std::string recover(const Motion& frame, const MotionRequest& request, ArmMotionPlanner& planner,
                      const core::Arm& arm, const std::string& name, MotionResult& motion,
                      std::vector<Eigen::VectorXd>& path, TimedPath& timed, PlanStep& s) {
    ++rejected_motions_;
    bool valid = false;
    if (s.smoothed) {
      path = motion.path;
      s.smoothed = false;
      valid = timed_and_valid(frame, arm, path, timed, s.validation);
    }
    if (!valid && !request.fine_checks &&
        (s.validation.violations.front().kind == "collision" ||
         s.validation.violations.front().kind == "slip")) {
      // The planner checks coarser than the validator (the roadmap's resolution with the arm
      // empty, MotionSettings::held_resolution with a board): a thin collision or a slip peak
      // between its samples is planned around once at the validator's.
      MotionRequest fine = request;
      fine.fine_checks = true;
      // A bridge, found at a large cost, is mended where it is blocked rather than searched for
      // again at that cost; a roadmap path is searched again, which is cheap and finds shorter
      // ways than mending.
      if (motion.via.find("bridge") != std::string::npos) fine.rejected = &motion.path;
      MotionResult again = timed_plan(planner, fine);
      if (again.solved()) {
        motion = std::move(again);
        path = motion.path;
        timed_and_valid(frame, arm, path, timed, s.validation);
      }
    }
    if (!s.validation.valid()) {
      const auto& v = s.validation.violations.front();
      return name + ": the validator rejected the plan (" + v.kind + ": " + v.detail + ")";
    }
    return "";
  }

  // The queue's reports for the steps planned on without them, oldest first, with each rejected
  // step's fallbacks (recover()) as step() would have run them. False when a stage's step is
  // still rejected: that stage (marked rejected_late) must be planned again in order, since
  // its alternatives come after a rejection.
  // Only the chain's stages are settled, and only once it is planned through: the stages of
  // attempts that failed further on are settled when a chain that plans through uses them, and
  // until then their jobs wait for the worker instead of holding up this chain.
  bool settle(std::span<const Stage* const> chain) {
    if (!queue_) return true;
    auto drop_failed = [&](Stage& st) {
      if (!st.ok()) abandon(st);  // failed as planned: its reports do not matter
    };
    if (tool_) drop_failed(*tool_);
    if (tool_down_) drop_failed(*tool_down_);
    each_memo([&](auto& stages) {
      for (auto& entry : stages) drop_failed(entry.second);
    });
    for (const Stage* st : chain) {
      if (st == nullptr || !st->ok()) return true;
    }
    std::vector<Stage*> waiting;
    auto add = [&](Stage& st) {
      if (!st.pending.empty() && std::find(chain.begin(), chain.end(), &st) != chain.end()) {
        waiting.push_back(&st);
      }
    };
    if (tool_) add(*tool_);
    if (tool_down_) add(*tool_down_);
    each_memo([&](auto& stages) {
      for (auto& entry : stages) add(entry.second);
    });
    std::sort(waiting.begin(), waiting.end(), [](const Stage* a, const Stage* b) {
      return a->pending.front().job < b->pending.front().job;
    });
    {
      // Every report of the chain in before any fallback: the caller validates those the worker
      // has not started.
      std::vector<std::size_t> jobs;
      for (const Stage* st : waiting) {
        for (const PendingCheck& p : st->pending) jobs.push_back(p.job);
      }
      const Stopwatch watch(times_.validation);
      queue_->wait_all(jobs);
    }
    bool all_passed = true;
    for (Stage* st : waiting) {
      for (PendingCheck& p : st->pending) {
        PlanStep& s = st->steps[p.step];
        s.validation = queue_->wait(p.job);
        const FinishedPath& finished = *p.finished;
        times_.queued_smoothing += finished.smoothing_seconds;
        s.smoothed = finished.smoothed;
        retime(*st, p.step, finished.path, finished.timed);
        if (s.validation.valid()) continue;
        std::vector<Eigen::VectorXd> path = finished.path;
        TimedPath timed = finished.timed;
        const std::string e =
            recover(p.frame, p.request, *p.planner, *p.arm, s.name, p.found, path, timed, s);
        if (!e.empty()) {
          st->failure = e;
          st->rejected_late = true;
          all_passed = false;
          break;
        }
        // Another path between the same ends (the found one, or a new plan).
        retime(*st, p.step, path, timed);
        s.via = p.found.via;
      }
      abandon(*st);  // after a step it could not recover, the rest are not wanted either
    }
    return all_passed;
  }

  // The stage's queued reports are not wanted (an attempt given up, a stage that failed).
  void abandon(Stage& st) {
    for (const PendingCheck& p : st.pending) queue_->discard(p.job);
    st.pending.clear();
  }

  MotionResult timed_plan(ArmMotionPlanner& planner, const MotionRequest& request) {
    const Stopwatch watch(times_.motions);
    ++motions_planned_;
    return planner.plan(request);
  }

  TimedPath timed_path(const core::Arm& arm, const std::vector<Eigen::VectorXd>& path) const {
    return time_parameterize_through(path, arm.spec.max_velocity, arm.spec.max_acceleration,
                                     settings_.speed_scale, settings_.timing_step);
  }

  // What the validator needs to know of a motion of the stage besides its trajectory.
  Motion motion_frame(const Stage& stage, const core::Arm& arm,
                      const MotionRequest& request) const {
    Motion check;
    check.arm = arm.spec.name;
    check.robot_q = stage.end.robot_q;
    check.holds_board = request.held.held;
    check.board_in_tcp = request.held.board_in_tcp;
    check.slip_axis_tcp = request.held.axis_tcp;
    check.slip_lever_tcp = request.held.lever_tcp;
    check.theta_c_deg = request.held.theta_c_deg;
    check.board_world = request.board_world;
    check.tool_in_hand = stage.end.tool_in_hand;
    check.tool_world = scene_.tool;
    check.start_in_contact = request.start_in_contact;
    check.end_in_contact = request.end_in_contact;
    if (request.held.held && !(&arm == &suction_ && stage.end.tool_in_hand)) {
      cell_.set_jaw(check.robot_q, arm, request.held.jaw);  // in the gripper, not on the cup
    }
    return check;
  }

  // Times the path and re-checks it with the validator, here and now: whether it passed.
  bool timed_and_valid(const Motion& frame, const core::Arm& arm,
                       const std::vector<Eigen::VectorXd>& path, TimedPath& timed,
                       ValidationReport& report) {
    const Stopwatch watch(times_.validation);
    timed = timed_path(arm, path);
    Motion check = frame;
    check.time = timed.time;
    check.q = timed.q;
    report = validate_motion(world_, inline_validation(), check, settings_.validator);
    return report.valid();
  }

  // The data a step validated here and now uses. With a queue, not the worker's: it may still be
  // validating other attempts' steps (settle() waits for the chain's only). Made when first
  // needed (a rejected step's fallbacks, a stage planned again in order: rare).
  const std::vector<core::CollisionData*>& inline_validation() {
    if (!queue_) return validation_threads_;
    if (!inline_data_) {
      inline_data_ = std::make_unique<core::CollisionData>(world_.make_data());
      // The queue's caller data is this thread's, and this thread is not waiting on the queue.
      inline_threads_ = {inline_data_.get(), validation_data_[1].get()};
    }
    return inline_threads_;
  }

  // The first of `candidates` valid for the planner under `request` in the stage's state.
  std::optional<Eigen::VectorXd> first_valid(const Stage& stage, ArmMotionPlanner& planner,
                                             MotionRequest request,
                                             const std::vector<Eigen::VectorXd>& candidates) {
    request.robot_q = stage.end.robot_q;
    request.tool_in_hand = stage.end.tool_in_hand;
    request.tool_world = scene_.tool;
    planner.prepare(request);
    for (const auto& q : candidates) {
      if (planner.valid(q)) return q;
    }
    return std::nullopt;
  }

  Eigen::VectorXd arm_q(const Stage& stage, const core::Arm& arm) const {
    return cell_.arm_joints(stage.end.robot_q, arm);
  }

  // 0. The tool, when it still stands on the table: approach, grasp, lift, home (where the
  // offline chain home -> pick starts).
  const Stage& tool() {
    if (tool_) return *tool_;
    tool_.emplace();
    Stage& st = *tool_;
    st.end = start_;
    if (st.end.tool_in_hand) return st;
    auto fail = [&](std::string why) -> const Stage& {
      st.failure = "tool_pick: " + std::move(why);
      return st;
    };
    const core::Pose tcp = scene_.tool * cell_.spec().suction.handle_in_tcp.inverse();
    const core::Pose pre = shifted(tcp, -settings_.approach * (tcp.linear() * approach_tcp_));
    MotionRequest r;
    r.board_world = board_initial_;
    const auto at =
        first_valid(st, suction_planner_, r, solutions(cell_, suction_, tcp, suction_.spec.home));
    if (!at) return fail("no valid IK at the tool's handle");
    const auto before = solutions(cell_, suction_, pre, *at);
    if (before.empty()) return fail("no IK before the handle");
    MotionRequest approach = r;
    approach.start = arm_q(st, suction_);
    approach.goal = before.front();
    if (auto e = step(st, suction_planner_, suction_, approach, "tool_approach", "", "");
        !e.empty()) {
      st.failure = e;
      return st;
    }
    MotionRequest in = r;
    in.start = before.front();
    in.goal = *at;
    if (auto e = step(st, suction_planner_, suction_, in, "tool_grasp", "", "tool_grasped");
        !e.empty()) {
      st.failure = e;
      return st;
    }
    st.end.tool_in_hand = true;
    cell_.set_jaw(st.end.robot_q, suction_, cell_.spec().suction.handle_width);
    const auto raised =
        solutions(cell_, suction_, shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift)), *at);
    if (raised.empty()) return fail("no IK above the tool's place");
    MotionRequest lift = r;
    lift.start = *at;
    lift.goal = raised.front();
    lift.start_in_contact = true;  // the cup still stands on the table
    if (auto e = step(st, suction_planner_, suction_, lift, "tool_lift", "", ""); !e.empty()) {
      st.failure = e;
      return st;
    }
    MotionRequest home = r;
    home.start = raised.front();
    home.goal = suction_.spec.home;
    if (auto e = step(st, suction_planner_, suction_, home, "tool_to_home", "", ""); !e.empty()) {
      st.failure = e;
    }
    return st;
  }

  // The suction arm sets the tool down where the scene has its place on the table, freeing its
  // gripper for a direct pick: above the place, straight down (the tool's foot meets the table:
  // the last sample touches by design), the gripper opens (`tool_released`), back along the
  // gripper's approach axis. Once per call, from the start.
  const Stage& tool_down() {
    if (tool_down_) return *tool_down_;
    tool_down_.emplace();
    Stage& st = *tool_down_;
    st.end = start_;
    if (!st.end.tool_in_hand) return st;
    auto fail = [&](std::string why) -> const Stage& {
      st.failure = "tool_place: " + std::move(why);
      return st;
    };
    const core::Pose tcp = scene_.tool * cell_.spec().suction.handle_in_tcp.inverse();
    const core::Pose pre = shifted(tcp, -settings_.approach * (tcp.linear() * approach_tcp_));
    const core::Pose raised = shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
    MotionRequest r;
    r.board_world = board_initial_;
    // At the place the tool stands on the table in the open hand (as the tool pick sees it).
    Stage standing = st;
    standing.end.tool_in_hand = false;
    const auto at = first_valid(standing, suction_planner_, r,
                                solutions(cell_, suction_, tcp, suction_.spec.home));
    if (!at) return fail("no valid IK at the tool's place");
    const auto above = solutions(cell_, suction_, raised, *at);
    const auto before = solutions(cell_, suction_, pre, *at);
    if (above.empty() || !first_valid(st, suction_planner_, r, {above.front()})) {
      return fail("no valid IK above the tool's place");
    }
    if (before.empty() || !first_valid(standing, suction_planner_, r, {before.front()})) {
      return fail("no valid IK to back off from the tool's handle");
    }
    MotionRequest to = r;
    to.start = arm_q(st, suction_);
    to.goal = above.front();
    if (auto e = step(st, suction_planner_, suction_, to, "tool_to_place", "", ""); !e.empty()) {
      st.failure = e;
      return st;
    }
    MotionRequest down = r;
    down.start = above.front();
    down.goal = *at;
    down.end_in_contact = true;
    if (auto e = step(st, suction_planner_, suction_, down, "tool_lower", "", "tool_released");
        !e.empty()) {
      st.failure = e;
      return st;
    }
    st.end.tool_in_hand = false;
    cell_.set_jaw(st.end.robot_q, suction_, cell_.spec().gripper.jaw_max);
    MotionRequest back = r;
    back.start = *at;
    back.goal = before.front();
    if (auto e = step(st, suction_planner_, suction_, back, "tool_retreat", "", ""); !e.empty()) {
      st.failure = e;
      return st;
    }
    return st;
  }

  HeldBoard on_cup(const db::SuctionGraspRecord& cup) const {
    HeldBoard h;
    h.held = true;
    h.board_in_tcp = world_.stage().cup_in_tcp * cup.cup.inverse();
    return h;
  }

  // 1. Suction pick at the detected pose: approach along the cup's axis, pick, lift. A branch
  // whose approach and lift stay in it (their nearest solutions) and are valid.
  const Stage& pick(std::int64_t cup_id) {
    const auto found = picks_.find(cup_id);
    if (found != picks_.end()) return found->second;
    Stage& st = picks_[cup_id];
    st.end = tool().end;
    const db::SuctionGraspRecord& cup = suction_grasps_.at(cup_id);
    const core::Pose cup_in_tcp = world_.stage().cup_in_tcp;
    const core::Pose cup_world = board_initial_ * cup.cup;
    const core::Pose pick_tcp = cup_world * cup_in_tcp.inverse();
    const Eigen::Vector3d into = cup_world.linear().col(2);  // z into the part
    const core::Pose pre_pick = shifted(pick_tcp, -settings_.approach * into);
    const core::Pose lifted = shifted(pick_tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
    MotionRequest standing;
    standing.board_world = board_initial_;
    MotionRequest carry;
    carry.held = on_cup(cup);
    const auto transits = stored_edges(
        "transit", suction_,
        [&](const auto& n) { return n.kind == "pick" && n.grasp_id == cup_id; },
        [](const auto&) { return true; });
    const Eigen::VectorXd* preferred = transits.empty() ? nullptr : &transits.front()->path.back();
    std::optional<Eigen::VectorXd> at, up, before;
    const Eigen::VectorXd suction_now = arm_q(st, suction_);
    for (const auto& q :
         solutions(cell_, suction_, pick_tcp, preferred ? *preferred : suction_now)) {
      if (!first_valid(st, suction_planner_, standing, {q})) continue;
      const auto p = solutions(cell_, suction_, pre_pick, q);
      const auto l = solutions(cell_, suction_, lifted, q);
      if (p.empty() || l.empty() || !first_valid(st, suction_planner_, standing, {p.front()}) ||
          !first_valid(st, suction_planner_, carry, {l.front()})) {
        continue;
      }
      at = q;
      before = p.front();
      up = l.front();
      break;
    }
    if (!at) {
      st.failure =
          "suction_pick: no IK branch with a valid approach, pick and lift at the detected board "
          "pose";
      return st;
    }
    MotionRequest r = standing;
    r.start = suction_now;
    r.goal = *before;
    r.hints = paths_of(transits);
    if (auto e = step(st, suction_planner_, suction_, r, "suction_approach", "", ""); !e.empty()) {
      st.failure = e;
      return st;
    }
    r.hints.clear();
    r.start = *before;
    r.goal = *at;
    if (auto e = step(st, suction_planner_, suction_, r, "suction_pick", "", "suction_on");
        !e.empty()) {
      st.failure = e;
      return st;
    }
    carry.start = *at;
    carry.goal = *up;
    carry.start_in_contact = true;  // the board still rests where it was detected
    if (auto e = step(st, suction_planner_, suction_, carry, "lift", "", ""); !e.empty()) {
      st.failure = e;
    }
    return st;
  }

  // 2. To the robot-robot pose through the suction grasp's filtered roadmap.
  const Stage& transfer(const db::RobotHandoverRecord& rr) {
    const auto found = transfers_.find(rr.id);
    if (found != transfers_.end()) return found->second;
    Stage& st = transfers_[rr.id];
    st.end = pick(rr.suction_grasp_id).end;
    st.failure = transfer_steps(st, rr);
    return st;
  }

  // The suction arm, holding the board after the lift, to the robot-robot pose.
  std::string transfer_steps(Stage& st, const db::RobotHandoverRecord& rr) {
    const db::SuctionGraspRecord& cup = suction_grasps_.at(rr.suction_grasp_id);
    const core::Pose rr_tcp = rr.board * cup.cup * world_.stage().cup_in_tcp.inverse();
    const auto stored = stored_edges(
        "transfer", suction_,
        [&](const auto& n) { return n.kind == "robot_handover" && n.robot_handover_id == rr.id; },
        [](const auto&) { return true; });
    MotionRequest carry;
    carry.held = on_cup(cup);
    const Eigen::VectorXd up = arm_q(st, suction_);
    const auto rr_q =
        first_valid(st, suction_planner_, carry,
                    solutions(cell_, suction_, rr_tcp, up,
                              stored.empty() ? nullptr : &stored.front()->path.back()));
    if (!rr_q) return "transfer_to_robot_handover: no valid IK at the robot-robot pose";
    carry.start = up;
    carry.goal = *rr_q;
    carry.filter = filter_for(suction_, "suction", cup.id);
    carry.hints = paths_of(stored);
    return step(st, suction_planner_, suction_, carry, "transfer_to_robot_handover", "", "");
  }

  double jaw_for(const db::RobotGraspRecord& grasp) const {
    return std::min(cell_.spec().gripper.jaw_max, grasp.jaw_width + settings_.jaw_margin);
  }

  // 3. The receiving arm's approach and grasp, the board held by the suction arm. The approach
  // backs off along the gripper's axis as far as the scene lets it (the exchange may be close
  // to the robot's body), else the arm goes to the grasp directly.
  const Stage& receive(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp) {
    const auto key = std::make_pair(rr.id, grasp.id);
    const auto found = receives_.find(key);
    if (found != receives_.end()) return found->second;
    Stage& st = receives_[key];
    st.end = transfer(rr).end;
    const core::Pose grasp_tcp = rr.board * grasp.tcp;
    auto at_exchange = [&](const auto& n) {
      return n.kind == "robot_handover" && n.grasp_id == grasp.id && n.robot_handover_id == rr.id;
    };
    const auto transits =
        stored_edges("transit", receiving_, at_exchange, [](const auto&) { return true; });
    // The branch the offline transfer to the human leaves from, else one a transit reaches.
    const auto onwards = stored_edges(
        "transfer", receiving_, [](const auto&) { return true; }, at_exchange);
    const Eigen::VectorXd* preferred = !onwards.empty()    ? &onwards.front()->path.front()
                                       : !transits.empty() ? &transits.front()->path.back()
                                                           : nullptr;
    MotionRequest reach;
    reach.board_world = rr.board;
    // Every valid branch at the exchange (the preferred first): an arm about to hold a long
    // board under a tight theta_c cannot change branch later, and near the robot's body one
    // branch may be boxed in where another is free. Through the roadmap first, then bridges
    // for the first few, as offline.
    std::vector<Eigen::VectorXd> branches;
    for (const auto& q : solutions(cell_, receiving_, grasp_tcp, receiving_.spec.home, preferred)) {
      if (first_valid(st, receiving_planner_, reach, {q})) branches.push_back(q);
    }
    if (branches.empty()) {
      st.failure = "receiving_grasp: no valid IK at the robot-robot pose";
      return st;
    }
    const Stage before = st;
    std::string first_failure;
    // Through the roadmap first, then (where the board in place blocks every way in) with the
    // receiving arm waiting at its pre-grasp while the suction arm is still at the lift and
    // brings the board to it, and only then with bridges to the board in place: those are
    // planned at the empty arm's resolution beside the held board, and the validator often
    // rejects them, each rejection a bridge's checks spent for nothing.
    const auto direct = [&](bool bridges) {
      for (std::size_t b = 0; b < branches.size(); ++b) {
        if (bridges && static_cast<int>(b) >= settings_.exchange_bridges) break;
        Stage attempt = before;
        const std::string failure = reach_exchange(attempt, rr, grasp, branches[b], bridges,
                                                   bridges ? Hints{} : paths_of(transits));
        if (failure.empty()) {
          st = std::move(attempt);
          cell_.set_jaw(st.end.robot_q, receiving_, jaw_for(grasp));
          return true;
        }
        abandon(attempt);
        if (first_failure.empty()) first_failure = failure;
        if (failure.find("deadline") != std::string::npos) {
          st.failure = failure;
          return true;
        }
      }
      return false;
    };
    const auto waiting = [&] {
      const Stage& lifted = pick(rr.suction_grasp_id);
      for (std::size_t b = 0; b < branches.size() && lifted.ok(); ++b) {
        Stage attempt;
        attempt.end = lifted.end;
        if (preposition(attempt, rr, branches[b]).empty()) {
          st = std::move(attempt);
          st.supersedes_previous = true;
          cell_.set_jaw(st.end.robot_q, receiving_, jaw_for(grasp));
          return true;
        }
        abandon(attempt);
      }
      return false;
    };
    if (direct(false) || waiting() || direct(true)) return st;
    st.failure = first_failure;
    return st;
  }

  // From the lift: the receiving arm to its pre-grasp (the board on the suction cup above its
  // pick pose), the suction arm to the robot-robot pose past it, the grasp.
  std::string preposition(Stage& st, const db::RobotHandoverRecord& rr,
                          const Eigen::VectorXd& grasp_q) {
    MotionRequest at_exchange;
    at_exchange.board_world = rr.board;
    const std::optional<Eigen::VectorXd> pre_q = pre_grasp(st, at_exchange, grasp_q);
    if (!pre_q) return "receiving_approach: no pre-grasp to wait at";
    const db::SuctionGraspRecord& cup = suction_grasps_.at(rr.suction_grasp_id);
    const core::Pose up_tcp =
        core::arm_base_in_world(cell_, suction_) * suction_.chain.fk(arm_q(st, suction_));
    MotionRequest wait;
    wait.board_world = up_tcp * on_cup(cup).board_in_tcp;
    wait.start = arm_q(st, receiving_);
    wait.goal = *pre_q;
    if (auto e = step(st, receiving_planner_, receiving_, wait, "receiving_approach", "", "");
        !e.empty()) {
      return e;
    }
    if (auto e = transfer_steps(st, rr); !e.empty()) return e;
    at_exchange.start = *pre_q;
    at_exchange.goal = grasp_q;
    return step(st, receiving_planner_, receiving_, at_exchange, "receiving_grasp", "",
                "gripper_close");
  }

  // Where the gripper opens before closing on the board (core::find_pre_grasp, as the offline
  // exchange check), under `request`; nothing when the grasp can only be reached directly.
  std::optional<Eigen::VectorXd> pre_grasp(const Stage& st, const MotionRequest& request,
                                           const Eigen::VectorXd& grasp_q) {
    return pre_grasp(st, receiving_, request, grasp_q);
  }
  std::optional<Eigen::VectorXd> pre_grasp(const Stage& st, const core::Arm& arm,
                                           const MotionRequest& request,
                                           const Eigen::VectorXd& grasp_q) {
    ArmMotionPlanner& planner = planner_of(arm);
    first_valid(st, planner, request, {});
    return core::find_pre_grasp(cell_, arm, grasp_q, settings_.approach,
                                settings_.validator.resolution,
                                [&](const Eigen::VectorXd& q) { return planner.valid(q); });
  }

  ArmMotionPlanner& planner_of(const core::Arm& arm) {
    return &arm == &suction_ ? suction_planner_ : receiving_planner_;
  }

  // The receiving arm to `grasp_q` at the exchange: an approach from behind the grasp where the
  // scene lets it, staging poses when the approach's start is boxed in.
  std::string reach_exchange(Stage& st, const db::RobotHandoverRecord& rr,
                             const db::RobotGraspRecord& grasp, const Eigen::VectorXd& grasp_q,
                             bool bridges, Hints hints) {
    const core::Pose grasp_tcp = rr.board * grasp.tcp;
    MotionRequest reach;
    reach.board_world = rr.board;
    reach.allow_bridge = bridges;
    const std::optional<Eigen::VectorXd> pre_q = pre_grasp(st, reach, grasp_q);
    // Staging poses for the first motion: further back along the gripper's axis, or above.
    const Eigen::VectorXd& target = pre_q ? *pre_q : grasp_q;
    const Eigen::Vector3d back = -(grasp_tcp.linear() * approach_tcp_);
    const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
    std::vector<Eigen::VectorXd> stagings;
    for (const Eigen::Vector3d& offset :
         {Eigen::Vector3d(0.10 * back), Eigen::Vector3d(0.15 * back),
          Eigen::Vector3d(0.10 * up + 0.05 * back), Eigen::Vector3d(0.15 * up),
          Eigen::Vector3d(0.10 * up + 0.10 * back), Eigen::Vector3d(0.20 * back)}) {
      const auto q = solutions(cell_, receiving_, shifted(grasp_tcp, offset), target);
      if (!q.empty() && first_valid(st, receiving_planner_, reach, {q.front()}) &&
          receiving_planner_.segment_valid(q.front(), target)) {
        stagings.push_back(q.front());
      }
    }
    reach.start = arm_q(st, receiving_);
    reach.hints = std::move(hints);
    if (pre_q) {
      reach.goal = *pre_q;
      if (auto e = step(st, receiving_planner_, receiving_, reach, "receiving_approach", "", "",
                        stagings);
          !e.empty()) {
        return e;
      }
      reach.start = *pre_q;
      reach.hints.clear();
      stagings.clear();
    }
    reach.goal = grasp_q;
    return step(st, receiving_planner_, receiving_, reach, "receiving_grasp", "", "gripper_close",
                stagings);
  }

  // 4. Suction off; the suction arm backs off along the cup's axis where it can (else it leaves
  // directly) and goes home.
  const Stage& release(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp) {
    const auto key = std::make_pair(rr.id, grasp.id);
    const auto found = releases_.find(key);
    if (found != releases_.end()) return found->second;
    Stage& st = releases_[key];
    st.end = receive(rr, grasp).end;
    const db::SuctionGraspRecord& cup = suction_grasps_.at(rr.suction_grasp_id);
    const Eigen::VectorXd rr_q = arm_q(st, suction_);
    const core::Pose rr_tcp = rr.board * cup.cup * world_.stage().cup_in_tcp.inverse();
    const Eigen::Vector3d cup_axis = (rr.board * cup.cup).linear().col(2);
    const auto back =
        solutions(cell_, suction_, shifted(rr_tcp, -settings_.approach * cup_axis), rr_q);
    MotionRequest leave;
    leave.board_world = rr.board;
    leave.start = rr_q;
    bool backed_off = false;
    if (!back.empty() && first_valid(st, suction_planner_, leave, {back.front()}) &&
        suction_planner_.segment_valid(rr_q, back.front())) {
      leave.goal = back.front();
      if (auto e =
              step(st, suction_planner_, suction_, leave, "suction_retreat", "suction_off", "");
          !e.empty()) {
        st.failure = e;
        return st;
      }
      leave.start = back.front();
      backed_off = true;
    }
    leave.goal = suction_.spec.home;
    if (auto e = step(st, suction_planner_, suction_, leave, "suction_arm_home",
                      backed_off ? "" : "suction_off", "");
        !e.empty()) {
      st.failure = e;
    }
    return st;
  }

  HeldBoard in_gripper(const db::RobotGraspRecord& grasp) const {
    HeldBoard h;
    h.held = true;
    h.board_in_tcp = grasp.tcp.inverse();
    h.jaw = jaw_for(grasp);
    const Eigen::Vector3d axis_part = grasp.tcp.linear() * opening_tcp_;
    const Eigen::Vector3d lever_part = core::lever_direction(
        axis_part, 0.5 * (grasp.contact_1 + grasp.contact_2), record_.mass_properties.com);
    h.axis_tcp = opening_tcp_;
    h.lever_tcp = grasp.tcp.linear().transpose() * lever_part;
    h.theta_c_deg = grasp.theta_c_deg;
    return h;
  }

  // 5. The slip-constrained transfer to the human.
  const Stage& present(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp,
                       const db::HandoverCandidateRecord& goal) {
    const auto key = std::make_tuple(rr.id, grasp.id, goal.id);
    const auto found = presents_.find(key);
    if (found != presents_.end()) return found->second;
    Stage& st = presents_[key];
    st.end = release(rr, grasp).end;
    const auto stored = stored_edges(
        "transfer", receiving_,
        [&](const auto& n) {
          return n.kind == "human_handover" && n.grasp_id == grasp.id && n.candidate_id == goal.id;
        },
        [&](const auto& n) { return n.robot_handover_id == rr.id; });
    MotionRequest present;
    present.held = in_gripper(grasp);
    const Eigen::VectorXd grasp_q = arm_q(st, receiving_);
    const core::Pose rh_tcp = goal.board * grasp.tcp;
    const auto rh_q =
        first_valid(st, receiving_planner_, present,
                    solutions(cell_, receiving_, rh_tcp, grasp_q,
                              stored.empty() ? nullptr : &stored.front()->path.back()));
    assert(rh_q.has_value() == reaches_human_pose(grasp, goal));
    if (!rh_q) {
      st.failure = kNoHumanPoseIk;
      return st;
    }
    present.start = grasp_q;
    present.goal = *rh_q;
    present.filter = filter_for(receiving_, "gripper", grasp.id);
    present.hints = paths_of(stored);
    if (auto e = step(st, receiving_planner_, receiving_, present, "transfer_to_human", "",
                      "wait_for_human");
        !e.empty()) {
      st.failure = e;
    }
    return st;
  }

  // Whether any IK branch of the receiving arm at the goal's robot-human pose with `grasp` is
  // valid in the state present() checks it in (the suction arm home, the board in hand): the
  // same answer without planning the exchange first. Per grasp and goal.
  bool reaches_human_pose(const db::RobotGraspRecord& grasp,
                          const db::HandoverCandidateRecord& goal) {
    const auto key = std::make_pair(grasp.id, goal.id);
    if (const auto found = human_reach_.find(key); found != human_reach_.end()) {
      return found->second;
    }
    Stage at;
    at.end = tool().end;  // the suction arm's jaw as it holds the tool; its joints home below
    cell_.set_arm(at.end.robot_q, suction_, suction_.spec.home);
    MotionRequest present;
    present.held = in_gripper(grasp);
    const bool reached =
        first_valid(at, receiving_planner_, present,
                    solutions(cell_, receiving_, goal.board * grasp.tcp, receiving_.spec.home))
            .has_value();
    human_reach_.emplace(key, reached);
    return reached;
  }

  // 6. The human takes it (wrist F/T): open, back off, home. Once per present stage.
  const Stage& leave(const db::RobotHandoverRecord& rr, const db::RobotGraspRecord& grasp,
                     const db::HandoverCandidateRecord& goal) {
    const auto key = std::make_tuple(rr.id, grasp.id, goal.id);
    const auto found = leaves_.find(key);
    if (found != leaves_.end()) return found->second;
    Stage& st = leaves_[key];
    st.end = present(rr, grasp, goal).end;
    const Stage& presented = present(rr, grasp, goal);
    const Stage& received = receive(rr, grasp);
    st.failure = retreat(st, receiving_, goal, "receiving_arm_home",
                         {{&presented, kWayBackSteps[0]},
                          {&received, kWayBackSteps[1]},
                          {&received, kWayBackSteps[2]}});
    return st;
  }

  // After the human takes the board (wrist F/T): the gripper opens, `arm` backs off the way a
  // gripper would come in (the offline search required one at this pose) and goes home. The
  // reason when it fails.
  // `way_back`: steps (of stages, by name) whose paths, reversed, lead the arm home where its
  // retreat attaches to no roadmap node: from beside the human's hands a straight segment often
  // reaches no roadmap node, while the arm's own way in, now empty-handed, is clear for a while.
  std::string retreat(Stage& st, const core::Arm& arm, const db::HandoverCandidateRecord& goal,
                      const std::string& home_step,
                      const std::vector<std::pair<const Stage*, std::string_view>>& way_back_of) {
    ArmMotionPlanner& planner = planner_of(arm);
    cell_.set_jaw(st.end.robot_q, arm, cell_.spec().gripper.jaw_max);
    const Eigen::VectorXd rh_q = arm_q(st, arm);
    MotionRequest release;
    release.board_world = goal.board;
    const auto away = pre_grasp(st, arm, release, rh_q);
    if (!away) return "release_retreat: no clear way back from the robot-human pose";
    release.start = rh_q;
    release.goal = *away;
    if (auto e = step(st, planner, arm, release, "release_retreat", "gripper_open", "");
        !e.empty()) {
      return e;
    }
    release.start = *away;
    release.goal = arm.spec.home;
    // Asked for only where the retreat attaches to no roadmap node (late_hints): a queued
    // step's smoothing is then waited for, not done on this thread for every board.
    std::vector<Eigen::VectorXd> way_back;
    // As executed (resampled as timed).
    const auto add_reversed = [&](const Stage& from, std::string_view name) {
      for (std::size_t i = 0; i < from.steps.size(); ++i) {
        if (from.steps[i].name != name) continue;
        const auto came = resample_path(executed_path(from, i), settings_.timing_step);
        for (auto q = came.rbegin(); q != came.rend(); ++q) {
          if (way_back.empty() || (*q - way_back.back()).norm() >= settings_.way_back_spacing) {
            way_back.push_back(*q);
          }
        }
      }
    };
    if (settings_.way_back_spacing > 0.0) {
      release.late_hints = [&]() -> Hints {
        way_back.clear();  // asked again by a re-plan of the same step
        for (const auto& [from, name] : way_back_of) add_reversed(*from, name);
        return way_back.size() > 1 ? Hints{&way_back} : Hints{};
      };
    }
    // Only where the retreat attaches to no roadmap node: mostly the roadmap's way is shorter.
    release.follow_hints = false;
    // The board is the human's now; it no longer stands where the arm goes home.
    return step(st, planner, arm, release, home_step, "", "");
  }

  // --- The direct way: one arm's gripper picks the board where it lies and delivers it ------
 public:

  // The whole direct chain for one goal and direct grasp: pick, present, retreat.
  std::string direct_chain(const db::HandoverCandidateRecord& goal,
                           const db::DirectGraspRecord& direct, std::vector<PlanStep>& steps,
                           ArmsState& end) {
    const auto grasp_it = robot_grasps_.find(direct.robot_grasp_id);
    const core::Arm* arm = arm_named(direct.arm);
    if (grasp_it == robot_grasps_.end() || arm == nullptr) {
      return "the database's direct grasp refers to a missing record";
    }
    const db::RobotGraspRecord& grasp = grasp_it->second;
    // The suction arm's gripper is free once the tool is set down.
    const bool sets_tool_down = arm == &suction_ && start_.tool_in_hand;
    const Stage* stages[4] = {};
    const auto plan_stages = [&] {
      stages[0] = sets_tool_down ? &tool_down() : nullptr;
      if (stages[0] != nullptr && !stages[0]->ok()) return;
      stages[1] = &gripper_pick(*arm, grasp, direct);
      if (stages[1]->ok()) stages[2] = &direct_present(*arm, grasp, goal, direct);
      if (stages[2] != nullptr && stages[2]->ok()) {
        stages[3] = &direct_leave(*arm, grasp, goal, direct);
      }
    };
    plan_stages();
    // settle() reads a null as a chain stopped before it: without the tool stage, from the pick.
    if (!settle(std::span<const Stage* const>(stages).subspan(sets_tool_down ? 0 : 1))) {
      forget([](const Stage& st) { return st.rejected_late; });
      const bool speculating = speculate_;
      speculate_ = false;
      std::fill(std::begin(stages), std::end(stages), nullptr);
      plan_stages();
      speculate_ = speculating;
    }
    double clock = 0.0;
    for (std::size_t k = 0; k < std::size(stages); ++k) {
      const Stage* stage = stages[k];
      if (stage == nullptr && k == 0) continue;  // the tool stays where it is
      if (stage == nullptr) break;
      if (!stage->ok()) return stage->failure;
      for (PlanStep s : stage->steps) {
        for (double& t : s.time) t += clock;
        steps.push_back(std::move(s));
      }
      if (!steps.empty()) clock = steps.back().time.back();
      end = stage->end;
    }
    return "";
  }

 private:
  const core::Arm* arm_named(const std::string& name) const {
    if (name == suction_.spec.name) return &suction_;
    if (name == receiving_.spec.name) return &receiving_;
    return nullptr;
  }

  // The gripper's pick at the detected pose: the open gripper from a pre-grasp (approach) to the
  // grasp, closed, and the lift straight up. A branch whose way in, grasp and lift are valid;
  // the build's branch first.
  const Stage& gripper_pick(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                            const db::DirectGraspRecord& direct) {
    const auto key = std::make_pair(arm.spec.name, grasp.id);
    const auto found = gripper_picks_.find(key);
    if (found != gripper_picks_.end()) return found->second;
    Stage& st = gripper_picks_[key];
    st.end = &arm == &suction_ && start_.tool_in_hand ? tool_down().end : start_;
    if (&arm == &suction_ && st.end.tool_in_hand) {
      st.failure = "gripper_pick: the " + arm.spec.name + " arm holds the suction tool";
      return st;
    }
    ArmMotionPlanner& planner = planner_of(arm);
    const core::Pose tcp = board_initial_ * grasp.tcp;
    const core::Pose lifted = shifted(tcp, Eigen::Vector3d(0.0, 0.0, settings_.lift));
    MotionRequest standing;
    standing.board_world = board_initial_;
    MotionRequest carry;
    carry.held = in_gripper(grasp);
    const Eigen::VectorXd now = arm_q(st, arm);
    std::optional<Eigen::VectorXd> at, before, up;
    for (const auto& q : solutions(cell_, arm, tcp, now, &direct.joints_pick)) {
      if (!first_valid(st, planner, standing, {q})) continue;
      const auto pre = pre_grasp(st, arm, standing, q);
      const auto l = solutions(cell_, arm, lifted, q);
      if (!pre || l.empty()) continue;
      Stage holding = st;
      cell_.set_jaw(holding.end.robot_q, arm, jaw_for(grasp));
      if (!first_valid(holding, planner, carry, {l.front()})) continue;
      at = q;
      before = *pre;
      up = l.front();
      break;
    }
    if (!at) {
      st.failure =
          "gripper_pick: no IK branch with a way in, a valid grasp and lift at the detected board "
          "pose";
      return st;
    }
    MotionRequest r = standing;
    r.start = now;
    r.goal = *before;
    if (auto e = step(st, planner, arm, r, "gripper_approach", "", ""); !e.empty()) {
      st.failure = e;
      return st;
    }
    r.start = *before;
    r.goal = *at;
    if (auto e = step(st, planner, arm, r, "gripper_grasp", "", "gripper_close"); !e.empty()) {
      st.failure = e;
      return st;
    }
    cell_.set_jaw(st.end.robot_q, arm, jaw_for(grasp));
    carry.start = *at;
    carry.goal = *up;
    carry.start_in_contact = true;  // the board still rests where it was detected
    if (auto e = step(st, planner, arm, carry, "lift", "", ""); !e.empty()) st.failure = e;
    return st;
  }

  // The slip-constrained transfer from the lift to the robot-human pose.
  const Stage& direct_present(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                              const db::HandoverCandidateRecord& goal,
                              const db::DirectGraspRecord& direct) {
    const auto key = std::make_tuple(arm.spec.name, grasp.id, goal.id);
    const auto found = direct_presents_.find(key);
    if (found != direct_presents_.end()) return found->second;
    Stage& st = direct_presents_[key];
    st.end = gripper_pick(arm, grasp, direct).end;
    ArmMotionPlanner& planner = planner_of(arm);
    MotionRequest present;
    present.held = in_gripper(grasp);
    const Eigen::VectorXd up = arm_q(st, arm);
    const auto rh_q = first_valid(
        st, planner, present, solutions(cell_, arm, goal.board * grasp.tcp, up, &direct.joints_rh));
    if (!rh_q) {
      st.failure = kNoHumanPoseIk;
      return st;
    }
    present.start = up;
    present.goal = *rh_q;
    present.filter = filter_for(arm, "gripper", grasp.id);
    if (auto e = step(st, planner, arm, present, "transfer_to_human", "", "wait_for_human");
        !e.empty()) {
      st.failure = e;
    }
    return st;
  }

  const Stage& direct_leave(const core::Arm& arm, const db::RobotGraspRecord& grasp,
                            const db::HandoverCandidateRecord& goal,
                            const db::DirectGraspRecord& direct) {
    const auto key = std::make_tuple(arm.spec.name, grasp.id, goal.id);
    const auto found = direct_leaves_.find(key);
    if (found != direct_leaves_.end()) return found->second;
    Stage& st = direct_leaves_[key];
    const Stage& presented = direct_present(arm, grasp, goal, direct);
    st.end = presented.end;
    st.failure = retreat(st, arm, goal, "arm_home", {{&presented, kWayBackSteps[0]}});
    return st;
  }

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
  std::optional<Stage> tool_;
  std::optional<Stage> tool_down_;
  std::map<std::int64_t, Stage> picks_;                              // by suction grasp
  std::map<std::int64_t, Stage> transfers_;                          // by robot handover
  std::map<std::pair<std::int64_t, std::int64_t>, Stage> receives_;  // by (handover, grasp)
  std::map<std::pair<std::int64_t, std::int64_t>, Stage> releases_;
  std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, Stage> presents_;
  std::map<std::pair<std::int64_t, std::int64_t>, bool> human_reach_;  // by (grasp, goal)
  std::map<std::tuple<std::int64_t, std::int64_t, std::int64_t>, Stage> leaves_;
  // The direct way's, by (arm, robot grasp) and (arm, robot grasp, goal).
  std::map<std::pair<std::string, std::int64_t>, Stage> gripper_picks_;
  std::map<std::tuple<std::string, std::int64_t, std::int64_t>, Stage> direct_presents_;
  std::map<std::tuple<std::string, std::int64_t, std::int64_t>, Stage> direct_leaves_;
};

}  // namespace

BoardPlanner::BoardPlanner(const PlannerModel& model, const BoardPlanSettings& settings)
    : model_(model), settings_(settings) {}

BoardPlanner::~BoardPlanner() = default;

BoardPlan BoardPlanner::plan(const Scene& scene, const std::string& board,
                             std::chrono::steady_clock::time_point deadline) {
  const auto started = std::chrono::steady_clock::now();
  BoardPlan result;
  result.board = board;
  Run* running = nullptr;  // once it is under way
  auto finish = [&](BoardPlanStatus status, std::string reason) {
    if (running != nullptr) {
      running->stop_validation();
      result.times = running->times();
      result.rejected_motions = running->rejected_motions();
      result.motions_planned = running->motions_planned();
    }
    result.status = status;
    result.reason = std::move(reason);
    result.planning_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return result;
  };
  const core::PartSpec* part = nullptr;
  for (const auto& p : model_.product().parts) {
    if (p.name == board) part = &p;
  }
  if (part == nullptr) return finish(BoardPlanStatus::kNoGoal, "unknown board '" + board + "'");
  if (scene.is_finished(board)) {
    return finish(BoardPlanStatus::kNoGoal, "'" + board + "' is already finished in the scene");
  }
  const BoardRecords* records = model_.board_records(board);
  if (records == nullptr) {
    return finish(BoardPlanStatus::kNoGoal, "the database has no board '" + board + "'");
  }
  Run run(model_, settings_, scene, *part, *records, deadline, lazy_prm_);
  running = &run;
  // Payload. The exchange: the suction arm carries the board on the tool, the receiving arm in
  // its jaws. A direct pick: the picking arm in its jaws. A way over an arm's payload is not
  // tried; with none left, the status says so.
  std::string over_payload;
  bool exchange_within_payload = true;
  for (const auto& check :
       {core::check_payload(run.suction_arm().spec.name, run.suction_arm().spec.payload, part->mass,
                            core::CarryMode::kSuction, model_.cell().spec().suction.mass),
        core::check_payload(run.receiving_arm().spec.name, run.receiving_arm().spec.payload,
                            part->mass, core::CarryMode::kGripper,
                            model_.cell().spec().suction.mass)}) {
    if (!check.within_allowed()) {
      exchange_within_payload = false;
      if (over_payload.empty()) over_payload = "over the payload: " + check.describe();
    }
  }
  std::set<std::string> direct_within_payload;
  for (const core::Arm* arm : {&run.receiving_arm(), &run.suction_arm()}) {
    const auto check = core::check_payload(arm->spec.name, arm->spec.payload, part->mass,
                                           core::CarryMode::kGripper,
                                           model_.cell().spec().suction.mass);
    if (check.within_allowed()) {
      direct_within_payload.insert(arm->spec.name);
    } else if (over_payload.empty()) {
      over_payload = "over the payload: " + check.describe();
    }
  }
  if (!exchange_within_payload && direct_within_payload.empty()) {
    return finish(BoardPlanStatus::kOverPayload, over_payload);
  }
  // At the stance the goals were built for, their stored Q is the scene human's (the same
  // lookup); elsewhere the comfort maps are looked up again.
  const bool built_stance = scene.human_stance.isApprox(model_.cell().spec().human_stance, 1e-12);
  const WorkerComfort* comfort = nullptr;
  if (!built_stance) {
    std::string error;
    comfort = model_.worker_comfort(&error);
    if (comfort == nullptr) {
      return finish(BoardPlanStatus::kNoGoal,
                    "the human stands elsewhere than the database's goals were built for, and "
                    "its comfort maps could not be read: " +
                        error);
    }
  }
  // Whether the scene's human reaches a goal's grasp, by the human arms' inverse kinematics
  // (the build's own postures where the human stands as built and the build confirmed the goal),
  // each goal once; a goal they do not reach is never tried.
  std::map<std::int64_t, WorkerComfort::GoalReach> reach_of;
  std::set<std::int64_t> out_of_reach;
  auto reach = [&](const db::HandoverCandidateRecord& goal) -> const WorkerComfort::GoalReach& {
    const auto it = reach_of.find(goal.id);
    if (it != reach_of.end()) return it->second;
    WorkerComfort::GoalReach r;
    if (built_stance && goal.human_joints.size() > 0 &&
        (goal.second_arm.empty() || goal.second_joints.size() > 0)) {
      r.reachable = true;
      r.quality = goal.quality;
      r.joints = goal.human_joints;
      r.second_joints = goal.second_joints;
    } else {  // the human arms' IK: no comfort maps needed
      r = WorkerComfort::goal_reach(model_.cell(), goal, records->human_grasps, scene.human_stance);
      if (built_stance) r.quality = goal.quality;  // the stored Q is this human's
    }
    if (!r.reachable && out_of_reach.insert(goal.id).second) ++result.goals_out_of_reach;
    return reach_of.emplace(goal.id, std::move(r)).first->second;
  };
  // The goals in Eq. 8 order that the scene's human can take: first those they take
  // comfortably (by the comfort maps), then those they reach only uncomfortably, as far as the
  // goal count needs them; the first BoardPlanSettings::goals.
  const auto goal_limit = static_cast<std::size_t>(std::max(0, settings_.goals));
  std::vector<const db::HandoverCandidateRecord*> goals, below_comfort;
  std::map<std::int64_t, double> worker_quality;  // by goal id
  double best_out_of_reach = 0.0;
  for (const auto& goal : records->goals) {
    const double q = built_stance
                         ? goal.quality
                         : comfort->goal_quality(goal, records->human_grasps, scene.human_stance);
    worker_quality[goal.id] = q;
    if (q >= std::min(settings_.worker_comfort_floor, goal.quality)) {
      goals.push_back(&goal);
    } else {
      below_comfort.push_back(&goal);
    }
  }
  for (const auto* goal : below_comfort) {
    if (goals.size() >= goal_limit) break;
    const auto& r = reach(*goal);
    if (r.reachable) {
      goals.push_back(goal);
      worker_quality[goal->id] = r.quality;
      ++result.goals_uncomfortable;
    } else {
      best_out_of_reach = std::max(best_out_of_reach, worker_quality[goal->id]);
    }
  }
  goals.resize(std::min(goals.size(), goal_limit));
  // Where the scene's human can take none of the goals: says where they stand and how they face.
  auto human_out_of_reach = [&]() {
    const core::Pose& stance = scene.human_stance;
    const double facing =
        core::rad_to_deg(std::atan2(stance.linear()(1, 0), stance.linear()(0, 0)));
    std::ostringstream reason;
    reason << std::fixed << std::setprecision(2) << "the human at (" << stance.translation().x()
           << ", " << stance.translation().y() << ", " << stance.translation().z() << ") m facing "
           << std::setprecision(0) << facing << " deg cannot take '" << board << "' at any of its "
           << records->goals.size() << " stored goals (best comfort Q " << std::setprecision(3)
           << best_out_of_reach
           << " by the maps; the arms reach none of the grasps tried): move the human or rebuild "
              "the database for this stance";
    return finish(BoardPlanStatus::kHumanOutOfReach, reason.str());
  };
  if (goals.empty() && !records->goals.empty()) return human_out_of_reach();
  bool any_connected_offline = false;
  // What both ways fill in once a chain of a goal is planned.
  auto planned = [&](const db::HandoverCandidateRecord& goal, std::int64_t robot_grasp_id,
                     std::vector<PlanStep>& steps, const ArmsState& end) {
    result.steps = std::move(steps);
    result.goal_rank = goal.rank;
    result.candidate_id = goal.id;
    result.robot_grasp_id = robot_grasp_id;
    result.theta_c_deg = run.robot_grasps().at(robot_grasp_id).theta_c_deg;
    result.quality = worker_quality.at(goal.id);
    const auto& posture = reach_of.at(goal.id);
    result.human_arm = goal.human_arm;
    result.human_joints = posture.joints;
    result.second_human_arm = goal.second_arm;
    result.second_human_joints = posture.second_joints;
    result.human_handover = goal.board;
    result.duration = result.steps.back().time.back();
    for (const auto& st : result.steps) result.path_length += st.path_length;
    result.validated = true;
    result.robot_q_after = end.robot_q;
    result.tool_in_hand_after = end.tool_in_hand;
  };
  // One direct chain of a goal; true when it is planned (result filled in).
  auto try_direct = [&](const std::string& round, const db::HandoverCandidateRecord& goal,
                        const db::DirectGraspRecord& d) {
    GoalAttempt attempt;
    attempt.rank = goal.rank;
    attempt.candidate_id = goal.id;
    attempt.mode = DeliveryMode::kDirect;
    attempt.arm = d.arm;
    attempt.robot_grasp_id = d.robot_grasp_id;
    std::vector<PlanStep> steps;
    ArmsState end;
    const std::string failure = run.direct_chain(goal, d, steps, end);
    attempt.outcome = failure.empty() ? "planned" : round + failure;
    result.attempts.push_back(attempt);
    if (!failure.empty()) return false;
    planned(goal, d.robot_grasp_id, steps, end);
    result.mode = DeliveryMode::kDirect;
    result.picking_arm = d.arm;
    result.delivering_arm = d.arm;
    result.suction_grasp_id = 0;
    return true;
  };
  // One exchange chain of a goal under the round's budgets; true when it is planned (result
  // filled in).
  auto try_shared = [&](const std::string& round, const db::HandoverCandidateRecord& goal,
                        const db::SharedGraspRecord& s) {
    GoalAttempt attempt;
    attempt.rank = goal.rank;
    attempt.candidate_id = goal.id;
    attempt.mode = DeliveryMode::kExchange;
    attempt.arm = run.receiving_arm().spec.name;
    attempt.robot_grasp_id = s.robot_grasp_id;
    attempt.robot_handover_id = s.robot_handover_id;
    std::vector<PlanStep> steps;
    ArmsState end;
    const std::string failure = run.chain(goal, s, steps, end);
    attempt.outcome = failure.empty() ? "planned" : round + failure;
    result.attempts.push_back(attempt);
    if (!failure.empty()) return false;
    const auto& rr = run.handovers().at(s.robot_handover_id);
    planned(goal, s.robot_grasp_id, steps, end);
    result.mode = DeliveryMode::kExchange;
    result.picking_arm = run.suction_arm().spec.name;
    result.delivering_arm = run.receiving_arm().spec.name;
    result.suction_grasp_id = rr.suction_grasp_id;
    result.robot_handover = rr.board;
    return true;
  };
  // Every goal in order under the round's budgets; true when one is planned (result filled in).
  auto try_goals = [&](const std::string& round) {
    for (const auto* goal_record : goals) {
      const auto& goal = *goal_record;
      // A goal the maps call comfortable may still be out of reach (a map bin holds the best of
      // the samples near it): confirmed before it is planned.
      if (!reach(goal).reachable) {
        best_out_of_reach = std::max(best_out_of_reach, worker_quality[goal.id]);
        continue;
      }
      // The direct ways first: a third of the exchange's motions.
      if (const auto direct = records->direct_grasps.find(goal.id);
          direct != records->direct_grasps.end()) {
        for (const auto& d : direct->second) {
          if (std::chrono::steady_clock::now() >= deadline) return false;
          if (direct_within_payload.count(d.arm) == 0) continue;
          if (try_direct(round, goal, d)) return true;
        }
      }
      if (!exchange_within_payload) continue;
      // The shared grasps the offline regrasp graph connected for this goal first: their
      // stored paths and IK branches are what the motions re-validate.
      std::vector<db::SharedGraspRecord> shared = records->shared_grasps.at(goal.id);
      const auto connected =
          std::stable_partition(shared.begin(), shared.end(),
                                [&](const auto& s) { return run.connected_offline(goal, s); });
      any_connected_offline = any_connected_offline || connected != shared.begin();
      // Where the receiving arm did not reach the exchange with a grasp, that grasp at the same
      // board pose (another suction grasp holding it there) is tried after the goal's other
      // chains: what blocked it is still there, so it would most likely fail again.
      std::vector<const db::SharedGraspRecord*> later;
      for (const auto& s : shared) {
        if (std::chrono::steady_clock::now() >= deadline) return false;
        if (run.receive_failed_at_same_pose(s)) {
          later.push_back(&s);
          continue;
        }
        if (try_shared(round, goal, s)) return true;
      }
      for (const auto* s : later) {
        if (std::chrono::steady_clock::now() >= deadline) return false;
        if (try_shared(round, goal, *s)) return true;
      }
    }
    return false;
  };
  if (try_goals("")) return finish(BoardPlanStatus::kSolved, "");
  // Every goal failed within the cheap budgets and time is left: once more with bridges as
  // large as the baselines' from-scratch budget, where the roadmap is cut.
  if (settings_.motion.planner == MotionPlannerKind::kRoadmap &&
      settings_.motion.escalated_bridge_checks > settings_.motion.bridge_checks && !goals.empty() &&
      std::chrono::steady_clock::now() < deadline) {
    run.escalate(settings_.motion.escalated_bridge_checks,
                 settings_.motion.escalated_repair_checks);
    if (try_goals("(larger bridges) ")) {
      result.larger_bridges = true;
      return finish(BoardPlanStatus::kSolved, "");
    }
  }
  if (!goals.empty() && std::all_of(goals.begin(), goals.end(), [&](const auto* goal) {
        return out_of_reach.count(goal->id) > 0;
      })) {
    return human_out_of_reach();
  }
  if (std::chrono::steady_clock::now() >= deadline) {
    return finish(
        BoardPlanStatus::kTimeout,
        "the deadline passed after " + std::to_string(result.attempts.size()) + " goal attempts");
  }
  return finish(BoardPlanStatus::kNoGoal,
                goals.empty()
                    ? "the database has no handover goal for '" + board + "'"
                    : "none of the first " + std::to_string(goals.size()) +
                          " goals could be planned in this scene (see attempts)" +
                          (any_connected_offline ? ""
                                                 : "; the database connects none of their chains "
                                                   "(hila inspect DB roadmap)"));
}

}  // namespace hila::online
