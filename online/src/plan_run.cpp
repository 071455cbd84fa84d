// Run (one BoardPlanner::plan() call): its construction, the memoised stages' bookkeeping and
// the board's records; the step pipeline every motion of a stage goes through (plan, smooth,
// time, validate: here and now, or queued while the next steps are planned, then settled); and
// the pieces the stages of both ways share.

#include "plan_run.hpp"

#include <algorithm>
#include <cmath>

#include "hila/core/bridge.hpp"
#include "hila/core/joint_box.hpp"
#include "hila/core/pre_grasp.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/online/smoother.hpp"

namespace hila::online::detail {

namespace {

double path_length(const std::vector<Eigen::VectorXd>& q) {
  double l = 0.0;
  for (std::size_t i = 1; i < q.size(); ++i) l += (q[i] - q[i - 1]).norm();
  return l;
}

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

}  // namespace

std::vector<Eigen::VectorXd> solutions(const core::Cell& cell, const core::Arm& arm,
                                       const core::Pose& tcp, const Eigen::VectorXd& seed,
                                       const Eigen::VectorXd* preferred) {
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

Eigen::VectorXd in_roadmap_box(const core::Arm& arm, Eigen::VectorXd q) {
  const core::JointBox box = core::joint_box(arm, core::BridgeSettings{}.joint_range);
  const Eigen::VectorXd lower = arm.chain.lower_limits();
  const Eigen::VectorXd upper = arm.chain.upper_limits();
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    const double turns = std::round((0.5 * (box.lower[i] + box.upper[i]) - q[i]) / (2.0 * M_PI));
    const double turned = q[i] + 2.0 * M_PI * turns;
    if (turned >= lower[i] && turned <= upper[i]) q[i] = turned;
  }
  return q;
}

Run::Run(const PlannerModel& model, const BoardPlanSettings& settings, const Scene& scene,
         const core::PartSpec& part, const BoardRecords& records, const std::string& suction_arm,
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
      world_(cell_, model.product(), scene, part.name, suction_arm),
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
  // The tool in the other arm's hand is put back first (BoardPlanner::plan).
  start_.tool_in_hand = scene.tool_in_hand && scene.tool_arm == suction_.spec.name;
}

void Run::stop_validation() {
  if (!queue_) return;
  if (tool_) abandon(*tool_);
  if (tool_down_) abandon(*tool_down_);
  if (tool_return_) abandon(*tool_return_);
  each_memo([&](auto& stages) {
    for (auto& entry : stages) abandon(entry.second);
  });
  queued_seconds_ = queue_->seconds();  // the job it is on when joined is not counted
  queue_.reset();
}

void Run::escalate(long checks, long repair_checks) {
  suction_planner_.set_bridge_checks(checks);
  receiving_planner_.set_bridge_checks(checks);
  suction_planner_.set_wedged_bridge_checks(checks);
  receiving_planner_.set_wedged_bridge_checks(checks);
  suction_planner_.set_repair_checks(repair_checks);
  receiving_planner_.set_repair_checks(repair_checks);
  forget([](const Stage& st) { return !st.ok(); });
}

core::LazyPrmPlanner* Run::baseline(
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

const db::RegraspNodeRecord* Run::node(std::int64_t id) const {
  const auto it = node_by_id_.find(id);
  return it == node_by_id_.end() ? nullptr : it->second;
}

const std::vector<bool>* Run::filter_for(const core::Arm& arm, const std::string& kind,
                                         std::int64_t id) const {
  const auto it = filters_.find({arm.spec.name, kind, id});
  return it == filters_.end() ? nullptr : &it->second;
}

Hints Run::paths_of(const std::vector<const db::RegraspEdgeRecord*>& edges) {
  Hints out;
  for (const auto* e : edges) out.push_back(&e->path);
  return out;
}

// --- The step pipeline ---------------------------------------------------------------------------

std::string Run::step(Stage& stage, ArmMotionPlanner& planner, const core::Arm& arm,
                      MotionRequest request, const std::string& name, StepEvent start_event,
                      StepEvent end_event, const std::vector<Eigen::VectorXd>& stagings) {
  if (std::chrono::steady_clock::now() >= deadline_) {
    stage.deadline_passed = true;
    return name + ": the deadline passed";
  }
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
    via_staging.staged = true;
    motion = std::move(via_staging);
  }
  if (!motion.solved()) {
    if (motion.status == MotionStatus::kTimeout) stage.deadline_passed = true;
    return name + ": " + to_string(motion.status) + ": " + motion.reason;
  }
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
    s.staged = pending.found.staged;
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
    s.staged = motion.staged;
  }
  s.name = name;
  s.arm = arm.spec.name;
  for (const double t : timed.time) s.time.push_back(clock + t);
  s.q = timed.q;
  s.start_event = start_event;
  s.end_event = end_event;
  s.path_length = path_length(path);
  cell_.set_arm(stage.end.robot_q, arm, path.back());
  stage.paths.push_back(std::move(path));
  stage.steps.push_back(std::move(s));
  return "";
}

bool Run::smooths(const std::vector<Eigen::VectorXd>& path, const MotionRequest& request) const {
  return settings_.smooth && path.size() > 2 && !request.start_in_contact &&
         !request.end_in_contact;
}

bool Run::smoothed(ArmMotionPlanner& checks, std::vector<Eigen::VectorXd>& path) const {
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

ArmMotionPlanner& Run::smoothing_checks(std::size_t slot, const core::Arm& arm) {
  auto& checks = smoothing_checks_[slot][&arm == &suction_ ? 0 : 1];
  if (!checks) {
    MotionSettings motion = settings_.motion;
    motion.planner = MotionPlannerKind::kRoadmap;  // only its checks are used
    checks = std::make_unique<ArmMotionPlanner>(world_, model_.roadmap(arm.spec.name),
                                                arm.spec.name, motion);
  }
  return *checks;
}

const std::vector<Eigen::VectorXd>& Run::executed_path(const Stage& st, std::size_t i) {
  for (const PendingCheck& p : st.pending) {
    if (p.step != i) continue;
    double waited = 0.0;
    {
      const Stopwatch watch(waited);
      queue_->wait_all({p.job});  // not the other attempts' jobs queued before it
    }
    times_.validation += waited;
    times_.motions -= waited;
    p.read_as_hint = true;
    if (!p.finished->path.empty()) return p.finished->path;
    break;  // a discarded job never finished: as found
  }
  return st.paths[i];
}

void Run::retime(Stage& st, std::size_t step, const std::vector<Eigen::VectorXd>& path,
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

std::string Run::recover(const Motion& frame, const MotionRequest& request,
                         ArmMotionPlanner& planner, const core::Arm& arm, const std::string& name,
                         MotionResult& motion, std::vector<Eigen::VectorXd>& path, TimedPath& timed,
                         PlanStep& s) {
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
    if (motion.via == MotionVia::kBridge) fine.rejected = &motion.path;
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

void Run::plan_settled(std::span<const Stage*> stages, std::size_t first,
                       const std::function<void()>& plan_stages) {
  plan_stages();
  if (settle(std::span<const Stage* const>(stages).subspan(first))) return;
  forget([](const Stage& st) { return st.rejected_late; });
  const bool speculating = speculate_;
  speculate_ = false;
  std::fill(stages.begin(), stages.end(), nullptr);
  plan_stages();
  speculate_ = speculating;
}

bool Run::settle(std::span<const Stage* const> chain) {
  if (!queue_) return true;
  auto drop_failed = [&](Stage& st) {
    if (!st.ok()) abandon(st);  // failed as planned: its reports do not matter
  };
  if (tool_) drop_failed(*tool_);
  if (tool_down_) drop_failed(*tool_down_);
  if (tool_return_) drop_failed(*tool_return_);
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
  if (tool_return_) add(*tool_return_);
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
  // The first stage whose rejected step was read as a hint (replaced by another path, or the
  // stage planned again).
  const Stage* hint_replaced = nullptr;
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
      if (p.read_as_hint && hint_replaced == nullptr) hint_replaced = st;
      if (!e.empty()) {
        st->failure = e;
        st->rejected_late = true;
        all_passed = false;
        break;
      }
      // Another path between the same ends (the found one, or a new plan).
      retime(*st, p.step, path, timed);
      s.via = p.found.via;
      s.staged = p.found.staged;
    }
    abandon(*st);  // after a step it could not recover, the rest are not wanted either
  }
  if (hint_replaced != nullptr) {
    // The stages after it were planned with the rejected path as a hint: planned again.
    const auto at = std::find(chain.begin(), chain.end(), hint_replaced);
    const std::span<const Stage* const> later =
        at == chain.end() ? chain.last(0)
                          : chain.subspan(static_cast<std::size_t>(at - chain.begin()) + 1);
    auto mark = [&](Stage& st) {
      if (std::find(later.begin(), later.end(), &st) != later.end()) st.rejected_late = true;
    };
    if (tool_) mark(*tool_);
    if (tool_down_) mark(*tool_down_);
    if (tool_return_) mark(*tool_return_);
    each_memo([&](auto& stages) {
      for (auto& entry : stages) mark(entry.second);
    });
    all_passed = false;
  }
  return all_passed;
}

void Run::abandon(Stage& st) {
  for (const PendingCheck& p : st.pending) queue_->discard(p.job);
  st.pending.clear();
}

MotionResult Run::timed_plan(ArmMotionPlanner& planner, const MotionRequest& request) {
  const Stopwatch watch(times_.motions);
  ++motions_planned_;
  return planner.plan(request);
}

TimedPath Run::timed_path(const core::Arm& arm, const std::vector<Eigen::VectorXd>& path) const {
  return time_parameterize_through(path, arm.spec.max_velocity, arm.spec.max_acceleration,
                                   settings_.speed_scale, settings_.timing_step);
}

Motion Run::motion_frame(const Stage& stage, const core::Arm& arm,
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

bool Run::timed_and_valid(const Motion& frame, const core::Arm& arm,
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

const std::vector<core::CollisionData*>& Run::inline_validation() {
  if (!queue_) return validation_threads_;
  if (!inline_data_) {
    inline_data_ = std::make_unique<core::CollisionData>(world_.make_data());
    // The queue's caller data is this thread's, and this thread is not waiting on the queue.
    inline_threads_ = {inline_data_.get(), validation_data_[1].get()};
  }
  return inline_threads_;
}

// --- What the stages of both ways share ---------------------------------------------------------

std::optional<Eigen::VectorXd> Run::first_valid(const Stage& stage, ArmMotionPlanner& planner,
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

Eigen::VectorXd Run::arm_q(const Stage& stage, const core::Arm& arm) const {
  return cell_.arm_joints(stage.end.robot_q, arm);
}

ArmMotionPlanner& Run::planner_of(const core::Arm& arm) {
  return &arm == &suction_ ? suction_planner_ : receiving_planner_;
}

double Run::jaw_for(const db::RobotGraspRecord& grasp) const {
  return std::min(cell_.spec().gripper.jaw_max, grasp.jaw_width + settings_.jaw_margin);
}

HeldBoard Run::in_gripper(const db::RobotGraspRecord& grasp) const {
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

std::optional<Eigen::VectorXd> Run::pre_grasp(const Stage& st, const core::Arm& arm,
                                              const MotionRequest& request,
                                              const Eigen::VectorXd& grasp_q) {
  ArmMotionPlanner& planner = planner_of(arm);
  first_valid(st, planner, request, {});
  return core::find_pre_grasp(cell_, arm, grasp_q, settings_.approach,
                              settings_.validator.resolution,
                              [&](const Eigen::VectorXd& q) { return planner.valid(q); });
}

std::string Run::retreat(
    Stage& st, const core::Arm& arm, const db::HandoverCandidateRecord& goal,
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
  if (auto e = step(st, planner, arm, release, "release_retreat", StepEvent::kGripperOpen,
                    StepEvent::kNone);
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
  return step(st, planner, arm, release, home_step);
}

}  // namespace hila::online::detail
