#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "hila/online/worker_comfort.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// The settings the fixture's cases plan with: the defaults with the goals in Eq. 8 order within
// the comfort tiers (natural_posture_first off), the order these cases' premises are about (a
// board going home along its way in, the nearest goal needing a bridge). The natural goals first
// are tested on their own below.
online::BoardPlanSettings eq8_order() {
  online::BoardPlanSettings s;
  s.natural_posture_first = false;
  return s;
}

std::chrono::steady_clock::time_point in_seconds(double s) {
  return std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(s * 1e6));
}

// Everything a solved plan must be: every step validated by the independent validator, each
// arm continuous from step to step, times increasing, the handover's events in order, both arms
// home at the end.
void expect_plan_well_formed(const online::PlannerModel& model, const online::Scene& scene,
                             const online::BoardPlan& plan) {
  EXPECT_TRUE(plan.validated);
  // The time split: every motion planned, smoothed and validated within the board's planning
  // time, the pieces disjoint (none counted inside another).
  EXPECT_GT(plan.times.motions, 0.0);
  EXPECT_GT(plan.times.validation, 0.0);
  EXPECT_GE(plan.times.smoothing, 0.0);
  EXPECT_LE(plan.times.motions + plan.times.smoothing + plan.times.validation,
            plan.planning_seconds);
  ASSERT_FALSE(plan.attempts.empty());
  EXPECT_EQ(plan.attempts.back().outcome, "planned");
  EXPECT_EQ(plan.attempts.back().result, online::AttemptResult::kPlanned);
  EXPECT_TRUE(plan.attempts.back().step.empty());
  // Every attempt before it failed at a named step, within the deadline: the outcome, after its
  // round, begins with that step.
  for (std::size_t i = 0; i + 1 < plan.attempts.size(); ++i) {
    const online::GoalAttempt& a = plan.attempts[i];
    EXPECT_EQ(a.result, online::AttemptResult::kFailed) << a.outcome;
    ASSERT_FALSE(a.step.empty()) << a.outcome;
    const std::string round = a.larger_bridges ? "(larger bridges) " : "";
    EXPECT_EQ(a.outcome.rfind(round + a.step + ": ", 0), 0u) << a.outcome;
  }
  EXPECT_LE(plan.theta_c_deg, 90.0);
  std::map<std::string, Eigen::VectorXd> at;  // each arm's joints as the plan goes
  for (const auto& [arm, q] : scene.robot) at[arm] = q;
  double clock = 0.0;
  std::string events;
  for (const auto& step : plan.steps) {
    ASSERT_FALSE(step.q.empty()) << step.name;
    EXPECT_TRUE(step.q.front().isApprox(at.at(step.arm), 1e-9)) << step.name << " starts elsewhere";
    EXPECT_GE(step.time.front(), clock - 1e-12) << step.name;
    clock = step.time.back();
    at[step.arm] = step.q.back();
    if (const std::string e = online::events_text(step); !e.empty()) events += e + " ";
    EXPECT_TRUE(step.validation.valid()) << step.name;
  }
  const std::vector<std::string> order =
      plan.mode == online::DeliveryMode::kExchange
          ? std::vector<std::string>{"suction_on", "gripper_close", "suction_off", "wait_for_human",
                                     "gripper_open"}
      : plan.mode == online::DeliveryMode::kSuction  // presented on the cup
          ? std::vector<std::string>{"suction_on", "wait_for_human", "suction_off"}
          : std::vector<std::string>{"gripper_close", "wait_for_human", "gripper_open"};
  std::size_t from = 0;
  for (const auto& e : order) {
    const auto found = events.find(e, from);
    EXPECT_NE(found, std::string::npos) << e << " missing or out of order in: " << events;
    if (found != std::string::npos) from = found;
  }
  for (const auto& arm : model.cell().arms()) {
    EXPECT_LT((at.at(arm.spec.name) - arm.spec.home).norm(), 1e-9) << arm.spec.name;
  }
}

// Where the receiving arm's reach of the exchange failed for a grasp at a board pose, that grasp
// at that pose (under another robot-robot pose) comes back only after every chain of the goal
// not so failed (in the first round; the larger bridges' round starts afresh). Returns how many
// attempts came back so.
int expect_failed_receives_tried_last(const online::PlannerModel& model, const std::string& board,
                                      const online::BoardPlan& plan) {
  const online::BoardRecords& records = *model.board_records(board);
  const auto pose_of = [&](std::int64_t rr) -> const core::Pose& {
    return records.robot_handovers.at(rr).board;
  };
  const auto same = [&](std::int64_t grasp_a, std::int64_t rr_a, std::int64_t grasp_b,
                        std::int64_t rr_b) {
    return grasp_a == grasp_b && pose_of(rr_a).matrix() == pose_of(rr_b).matrix();
  };
  int came_back = 0;
  const auto& at = plan.attempts;
  for (std::size_t k = 0; k < at.size(); ++k) {
    if (at[k].larger_bridges) break;
    // The receives that failed before attempt k (in any goal: a stage is planned once a run).
    std::vector<const online::GoalAttempt*> failed;
    for (std::size_t i = 0; i < k; ++i) {
      if (at[i].step.rfind("receiving_", 0) == 0) failed.push_back(&at[i]);
    }
    const auto failed_like = [&](std::int64_t grasp, std::int64_t rr) {
      return std::any_of(failed.begin(), failed.end(), [&](const auto* f) {
        return f->robot_handover_id != rr &&
               same(f->robot_grasp_id, f->robot_handover_id, grasp, rr);
      });
    };
    if (!failed_like(at[k].robot_grasp_id, at[k].robot_handover_id)) continue;
    ++came_back;
    for (const auto& s : records.shared_grasps.at(at[k].candidate_id)) {
      if (failed_like(s.robot_grasp_id, s.robot_handover_id)) continue;
      const bool tried =
          std::any_of(at.begin(), at.begin() + static_cast<std::ptrdiff_t>(k), [&](const auto& a) {
            return a.candidate_id == at[k].candidate_id && a.robot_grasp_id == s.robot_grasp_id &&
                   a.robot_handover_id == s.robot_handover_id;
          });
      EXPECT_TRUE(tried) << board << ": attempt " << k << " (grasp " << at[k].robot_grasp_id
                         << ", rr " << at[k].robot_handover_id << ") came back before grasp "
                         << s.robot_grasp_id << ", rr " << s.robot_handover_id;
    }
  }
  return came_back;
}

// Whether the build found every way of a goal blocked: no direct, regrasp or suction way, and
// each shared grasp's robot-robot pose has a stored suction-arm transfer from its cup's pick,
// none connected (read from the regrasp graph's records, not through the planner's index).
bool all_exchanges_blocked(const online::BoardRecords& records,
                           const db::HandoverCandidateRecord& goal) {
  const auto has = [&](const auto& ways) {
    const auto it = ways.find(goal.id);
    return it != ways.end() && !it->second.empty();
  };
  if (has(records.direct_grasps) || has(records.table_regrasps) ||
      has(records.suction_deliveries)) {
    return false;
  }
  const auto shared = records.shared_grasps.find(goal.id);
  if (shared == records.shared_grasps.end() || shared->second.empty()) return false;
  for (const auto& s : shared->second) {
    const auto& rr = records.robot_handovers.at(s.robot_handover_id);
    int stored = 0, connected = 0;
    for (const auto& e : records.regrasp_edges) {
      const auto from = records.node_by_id.find(e.from_node);
      const auto to = records.node_by_id.find(e.to_node);
      if (e.kind != "transfer" || from == records.node_by_id.end() ||
          to == records.node_by_id.end() || from->second->kind != "pick" ||
          from->second->grasp_kind != "suction" || to->second->kind != "robot_handover" ||
          to->second->robot_handover_id != rr.id) {
        continue;
      }
      ++stored;
      connected += e.connected && from->second->grasp_id == rr.suction_grasp_id ? 1 : 0;
    }
    if (stored == 0 || connected > 0) return false;
  }
  return true;
}

// The same steps, point for point: the same names, smoothing, times and joints.
void expect_same_steps(const online::BoardPlan& a, const online::BoardPlan& b) {
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (std::size_t i = 0; i < b.steps.size(); ++i) {
    EXPECT_EQ(a.steps[i].name, b.steps[i].name);
    EXPECT_EQ(a.steps[i].smoothed, b.steps[i].smoothed) << b.steps[i].name;
    EXPECT_EQ(a.steps[i].time, b.steps[i].time) << b.steps[i].name;
    ASSERT_EQ(a.steps[i].q.size(), b.steps[i].q.size()) << b.steps[i].name;
    for (std::size_t k = 0; k < b.steps[i].q.size(); ++k) {
      ASSERT_EQ(a.steps[i].q[k], b.steps[i].q[k]) << b.steps[i].name << " " << k;
    }
  }
}

// How the receiving arm went home after the release ("(none)" without such a step).
std::string home_via(const online::BoardPlan& plan) {
  for (const auto& step : plan.steps) {
    if (step.name == "receiving_arm_home") return online::via_text(step);
  }
  return "(none)";
}

bool bridged(const online::BoardPlan& plan) {
  return std::any_of(plan.steps.begin(), plan.steps.end(),
                     [](const auto& step) { return step.via == online::MotionVia::kBridge; });
}

void print_plan(const online::BoardPlan& plan) {
  std::string attempts;
  for (const auto& a : plan.attempts)
    attempts += "\n  rank " + std::to_string(a.rank) + ": " + a.outcome;
  std::printf("%s: %s %s in %.1f ms, %zu steps, %zu attempts%s\n", plan.board.c_str(),
              online::to_string(plan.status), plan.reason.c_str(), 1e3 * plan.planning_seconds,
              plan.steps.size(), plan.attempts.size(), attempts.c_str());
}

online::Scene after(const online::PlannerModel& model, const online::Scene& scene,
                    const std::string& board) {
  online::Scene next = scene.with_finished(model.product(), board);
  next.tool_in_hand = true;
  for (const auto& arm : model.cell().arms()) next.robot[arm.spec.name] = arm.spec.home;
  return next;
}

online::SceneObstacle box_at(const std::string& name, const Eigen::Vector3d& centre, double side) {
  online::SceneObstacle box;
  box.name = name;
  box.pose.translation() = centre;
  box.box_size = Eigen::Vector3d::Constant(side);
  return box;
}

}  // namespace

// The cabinet database, its model and the nominal run, made once per test process and shared
// read-only by every case (a case copies a scene before it adds an obstacle): the database build
// is most of the work. The nominal run is the cabinet in assembly order, each scene following
// from the last and a board that cannot be planned assembled by hand (as hila plan --all), with
// the default settings. Every plan has a 120 s deadline: a bound, not a goal. ctest runs each
// case in a process of its own: HILA_TEST_DATABASE shares one database among them.
class BoardPlanner : public ::testing::Test {
 protected:
  // Each board's scene (the boards before it assembled) and its plan there.
  struct Nominal {
    std::map<std::string, online::Scene> scene_of;
    std::map<std::string, online::BoardPlan> plan_of;
  };
  // A board whose receiving arm went home along its way in, planned again without that hint.
  struct WayBack {
    std::string board;
    online::BoardPlan without;
  };
  // lateral_right's scene with a crate where its first goal hands the board over, and its plan.
  struct Blocked {
    online::Scene scene;
    online::BoardPlan plan;
  };

  static void SetUpTestSuite() {
    const std::string path = database();
    model_ = online::PlannerModel::load(path, test::cell_path(), test::product_path());
    nominal_ = std::make_unique<Nominal>();
    online::BoardPlanner planner(*model_, eq8_order());
    online::Scene scene = online::load_scene(test::data_path("cabinet/scene.yaml"), model_->cell(),
                                             model_->product());
    for (const auto& part : model_->product().parts) {
      const auto plan = planner.plan(scene, part.name, in_seconds(120.0));
      print_plan(plan);
      nominal_->scene_of[part.name] = scene;
      nominal_->plan_of[part.name] = plan;
      scene = after(*model_, scene, part.name);
    }
  }

  static void TearDownTestSuite() {
    way_back_.reset();
    way_back_planned_ = false;
    blocked_.reset();
    nominal_.reset();
    model_.reset();
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
    dir_.clear();
  }

  void SetUp() override {
    ASSERT_TRUE(model_ && nominal_) << "the cabinet database could not be built or loaded";
  }

  static const online::PlannerModel& model() { return *model_; }
  static const std::map<std::string, online::BoardPlan>& plans() { return nominal_->plan_of; }
  static const online::Scene& scene_of(const std::string& board) {
    return nominal_->scene_of.at(board);
  }
  static const online::BoardPlan& plan_of(const std::string& board) {
    return nominal_->plan_of.at(board);
  }

  // The first board (in name order) whose nominal plan sends the receiving arm home along its
  // way in; nullptr when none does. Planned once per process, for whichever case asks first.
  static const WayBack* way_back_board() {
    if (!way_back_planned_) {
      way_back_planned_ = true;
      const auto it = std::find_if(plans().begin(), plans().end(), [](const auto& kv) {
        return home_via(kv.second).find("stored") == 0;
      });
      if (it != plans().end()) {
        online::BoardPlanSettings no_way_back = eq8_order();
        no_way_back.way_back_spacing = 0.0;
        auto without = online::BoardPlanner(*model_, no_way_back)
                           .plan(scene_of(it->first), it->first, in_seconds(120.0));
        print_plan(without);
        way_back_ = WayBack{it->first, std::move(without)};
      }
    }
    return way_back_ ? &*way_back_ : nullptr;
  }

  // A crate where lateral_right's first goal hands the board over, planned with the default
  // settings. Planned once per process, for whichever case asks first.
  static const Blocked& crate_at_first_goal() {
    if (!blocked_) {
      const std::string board = "lateral_right";
      online::Scene scene = scene_of(board);
      scene.obstacles.push_back(box_at("crate", plan_of(board).human_handover.translation(), 0.06));
      auto plan = online::BoardPlanner(*model_, eq8_order()).plan(scene, board, in_seconds(120.0));
      print_plan(plan);
      blocked_ = Blocked{std::move(scene), std::move(plan)};
    }
    return *blocked_;
  }

 private:
  // The cabinet database the cases plan from: a prebuilt one named by HILA_TEST_DATABASE (e.g.
  // tools/demo's out/cabinet.hila), else the default build with a smaller roadmap (the full one
  // takes minutes), in a directory of this process's own (ctest may run cases side by side).
  static std::string database() {
    if (const char* given = std::getenv("HILA_TEST_DATABASE")) return given;
    offline::BuildSettings s;
    s.jobs = 2;
    s.roadmap.nodes = 1200;
    dir_ = test::temp_dir("board_planner_" + std::to_string(::getpid()));
    const std::string out = dir_ + "/cabinet.hila";
    offline::build_database(test::product_path(), test::cell_path(), out, s);
    return out;
  }

  static inline std::string dir_;
  static inline std::shared_ptr<const online::PlannerModel> model_;
  static inline std::unique_ptr<Nominal> nominal_;
  static inline bool way_back_planned_ = false;
  static inline std::optional<WayBack> way_back_;
  static inline std::optional<Blocked> blocked_;
};

// Every board plans, in order, on this smaller roadmap too (base with the tool pick first), and
// every plan is well formed; a board that did not plan would say why and emit nothing. Where a
// receive failed at a board pose, the goal's other chains came first.
TEST_F(BoardPlanner, EveryBoardPlansInAssemblyOrderAndValidates) {
  std::vector<std::string> solved;
  for (const auto& part : model().product().parts) {
    SCOPED_TRACE(part.name);
    const online::BoardPlan& plan = plan_of(part.name);
    expect_failed_receives_tried_last(model(), part.name, plan);
    if (plan.solved()) {
      solved.push_back(part.name);
      expect_plan_well_formed(model(), scene_of(part.name), plan);
    } else {
      EXPECT_FALSE(plan.reason.empty());
      EXPECT_FALSE(plan.attempts.empty());
      for (const auto& a : plan.attempts) EXPECT_NE(a.outcome, "planned");
      EXPECT_TRUE(plan.steps.empty()) << "nothing of a failed plan is emitted";
    }
  }
  EXPECT_EQ(solved.size(), model().product().parts.size());
  ASSERT_GE(solved.size(), 4u);
  EXPECT_EQ(solved[0], "base");
  EXPECT_EQ(solved[1], "lateral_right");
  EXPECT_EQ(solved[2], "back_lower");
  EXPECT_EQ(solved[3], "shelf_middle");
}

// The smoother is part of the pipeline: multi-waypoint motions are smoothed (and validated)
// rather than all falling back to the found paths.
TEST_F(BoardPlanner, MultiWaypointMotionsAreSmoothed) {
  int smoothed = 0;
  for (const auto& [name, plan] : plans()) {
    for (const auto& step : plan.steps) smoothed += step.smoothed ? 1 : 0;
  }
  EXPECT_GT(smoothed, 0);
}

// With the overlap on, steps are smoothed on either thread (queued, or on the planner's while
// the queue is behind): the plans are exactly those smoothed and validated in order. Which
// thread smoothed a step depends on timing; with every smoothing queued
// (smooth_here_when_behind false) none is done on the planner's thread, whatever the timing.
TEST_F(BoardPlanner, WhereAStepIsSmoothedAndValidatedDoesNotChangeThePlan) {
  online::BoardPlanSettings in_order_settings = eq8_order();
  in_order_settings.overlap_validation = false;
  online::BoardPlanner in_order_planner(model(), in_order_settings);
  online::BoardPlanSettings all_queued_settings = eq8_order();
  all_queued_settings.smooth_here_when_behind = false;
  online::BoardPlanner all_queued_planner(model(), all_queued_settings);
  double queued_smoothing = 0.0;
  for (const auto& [name, plan] : plans()) {
    SCOPED_TRACE(name);
    const auto in_order = in_order_planner.plan(scene_of(name), name, in_seconds(120.0));
    EXPECT_EQ(in_order.times.queued_smoothing, 0.0);
    expect_same_steps(in_order, plan);
    const auto all_queued = all_queued_planner.plan(scene_of(name), name, in_seconds(120.0));
    // (a step the validator rejects is planned again in order, smoothed where it is planned)
    if (all_queued.rejected_motions == 0) {
      EXPECT_EQ(all_queued.times.smoothing, 0.0) << "smoothed on the planner's thread";
    }
    queued_smoothing += all_queued.times.queued_smoothing;
    expect_same_steps(in_order, all_queued);
  }
  EXPECT_GT(queued_smoothing, 0.0) << "the queued steps were smoothed";
}

// The receiving arm's way home after the release follows its way in, reversed, on some board;
// the same board without that hint goes home some other way (the hint was the cause).
TEST_F(BoardPlanner, TheReceivingArmGoesHomeAlongItsWayIn) {
  const WayBack* way_back = way_back_board();
  ASSERT_NE(way_back, nullptr) << "no board went home along its way in";
  const online::BoardPlan& other = way_back->without;
  ASSERT_TRUE(other.solved()) << way_back->board << ": " << other.reason;
  expect_plan_well_formed(model(), scene_of(way_back->board), other);
  EXPECT_EQ(home_via(other).find("stored"), std::string::npos) << way_back->board;
}

// A board whose plan without the way back needs a bridge (the board above, or one whose nominal
// plan does), planned again with no bridge budget at first, no way back and only its nearest
// goal: every chain of that goal fails in the first round (on this database each needs a
// bridge), and the second round, with bridges as large as the baselines' budget, plans it (the
// escalation). A plan with a bridge can only come from that round.
TEST_F(BoardPlanner, EveryChainFailingEscalatesToLargerBridges) {
  const WayBack* way_back = way_back_board();
  std::string needs_bridge = way_back && bridged(way_back->without) ? way_back->board : "";
  for (const auto& [name, plan] : plans()) {
    if (needs_bridge.empty() && bridged(plan)) needs_bridge = name;
  }
  ASSERT_FALSE(needs_bridge.empty()) << "some board of the cabinet needs a bridge";
  online::BoardPlanSettings no_bridges = eq8_order();
  no_bridges.motion.bridge_checks = 0;
  no_bridges.goals = 1;
  no_bridges.way_back_spacing = 0.0;
  online::BoardPlanner escalating(model(), no_bridges);
  const auto escalated = escalating.plan(scene_of(needs_bridge), needs_bridge, in_seconds(120.0));
  print_plan(escalated);
  ASSERT_TRUE(escalated.solved()) << needs_bridge << ": " << escalated.reason;
  expect_plan_well_formed(model(), scene_of(needs_bridge), escalated);
  EXPECT_TRUE(escalated.larger_bridges || !bridged(escalated)) << needs_bridge;
  EXPECT_TRUE(escalated.larger_bridges) << needs_bridge;
  EXPECT_EQ(escalated.goal_rank, 0);
  EXPECT_NE(escalated.attempts.front().outcome.find("no path"), std::string::npos)
      << escalated.attempts.front().outcome;
}

// A crate on lateral_right's stored path (at the gripper in the middle of the transfer to the
// human, so the nominal motion certainly hits it) is planned around: a different, validated plan.
TEST_F(BoardPlanner, ACrateOnTheStoredPathIsPlannedAround) {
  const std::string board = "lateral_right";
  const online::BoardPlan& nominal = plan_of(board);
  const auto transfer = std::find_if(nominal.steps.begin(), nominal.steps.end(),
                                     [](const auto& s) { return s.name == "transfer_to_human"; });
  ASSERT_NE(transfer, nominal.steps.end());
  const core::Arm& arm = model().cell().arm(transfer->arm);
  const Eigen::VectorXd& middle = transfer->q[transfer->q.size() / 2];
  const Eigen::Vector3d gripper =
      (core::arm_base_in_world(model().cell(), arm) * arm.chain.fk(middle)).translation();
  online::Scene crated = scene_of(board);
  crated.obstacles.push_back(box_at("crate", gripper, 0.08));
  const auto repaired =
      online::BoardPlanner(model(), eq8_order()).plan(crated, board, in_seconds(120.0));
  print_plan(repaired);
  ASSERT_TRUE(repaired.solved()) << repaired.reason;
  expect_plan_well_formed(model(), crated, repaired);
  bool differs = repaired.candidate_id != nominal.candidate_id ||
                 repaired.steps.size() != nominal.steps.size();
  for (std::size_t i = 0; !differs && i < repaired.steps.size(); ++i) {
    differs = repaired.steps[i].q.size() != nominal.steps[i].q.size() ||
              !repaired.steps[i].q.back().isApprox(nominal.steps[i].q.back()) ||
              !repaired.steps[i].q[repaired.steps[i].q.size() / 2].isApprox(
                  nominal.steps[i].q[nominal.steps[i].q.size() / 2]);
  }
  EXPECT_TRUE(differs) << "the crate stands where the nominal plan's gripper passes";
}

// A crate where lateral_right's first goal hands the board over makes the planner fall back to a
// later goal.
TEST_F(BoardPlanner, ACrateAtTheFirstGoalFallsBackToALaterGoal) {
  const online::BoardPlan& nominal = plan_of("lateral_right");
  const Blocked& blocked = crate_at_first_goal();
  const online::BoardPlan& fallback = blocked.plan;
  ASSERT_TRUE(fallback.solved()) << fallback.reason;
  expect_plan_well_formed(model(), blocked.scene, fallback);
  EXPECT_GT(fallback.goal_rank, nominal.goal_rank);
  EXPECT_NE(fallback.candidate_id, nominal.candidate_id);
  EXPECT_GE(fallback.attempts.size(), 2u);
  EXPECT_EQ(fallback.attempts.front().rank, nominal.goal_rank);
  EXPECT_NE(fallback.attempts.front().outcome, "planned");
}

// The crate at the first goal leaves no valid IK branch at its robot-human pose. Checked before
// the exchange is planned (the default), the grasps that cannot serve that goal cost no
// exchange: the same attempts and plan as planning the exchange first, with fewer motions
// planned.
TEST_F(BoardPlanner, ReachOfTheHumanPoseIsCheckedBeforeTheExchange) {
  const Blocked& blocked = crate_at_first_goal();
  const online::BoardPlan& fallback = blocked.plan;
  ASSERT_TRUE(fallback.solved()) << fallback.reason;
  online::BoardPlanSettings exchange_first = eq8_order();
  exchange_first.reach_human_pose_first = false;
  const auto late = online::BoardPlanner(model(), exchange_first)
                        .plan(blocked.scene, "lateral_right", in_seconds(120.0));
  ASSERT_TRUE(late.solved()) << late.reason;
  EXPECT_EQ(late.candidate_id, fallback.candidate_id);
  ASSERT_EQ(late.attempts.size(), fallback.attempts.size());
  int unreachable = 0;
  for (std::size_t i = 0; i < late.attempts.size(); ++i) {
    EXPECT_EQ(late.attempts[i].outcome, fallback.attempts[i].outcome) << "attempt " << i;
    const std::string& outcome = fallback.attempts[i].outcome;
    if (outcome.find("no valid IK at the robot-human pose") != std::string::npos) ++unreachable;
  }
  expect_same_steps(late, fallback);
  ASSERT_GT(unreachable, 0) << "the crate must leave the first goal unreachable";
  EXPECT_LT(fallback.motions_planned, late.motions_planned);
  std::printf(
      "robot-human pose checked first: %d motions planned, exchange first: %d (%d "
      "attempts without a valid IK there)\n",
      fallback.motions_planned, late.motions_planned, unreachable);
}

// With only the crated first goal to try, every way ends at the reach check: the receiving arm
// has no valid IK branch at its robot-human pose with any grasp. Checked first (the default),
// nothing at all is planned for it: neither the exchange nor the suction arm's tool, pick and
// transfer to the robot-robot pose, which are planned (and may fail expensively where the scene
// moved) when the exchange's stages come first.
TEST_F(BoardPlanner, NothingIsPlannedForAGoalTheReceivingArmCannotReach) {
  const Blocked& blocked = crate_at_first_goal();
  online::BoardPlanSettings first_only = eq8_order();
  first_only.goals = 1;
  const auto checked = online::BoardPlanner(model(), first_only)
                           .plan(blocked.scene, "lateral_right", in_seconds(120.0));
  online::BoardPlanSettings exchange_first = first_only;
  exchange_first.reach_human_pose_first = false;
  const auto late = online::BoardPlanner(model(), exchange_first)
                        .plan(blocked.scene, "lateral_right", in_seconds(120.0));
  print_plan(checked);
  ASSERT_FALSE(checked.attempts.empty());
  for (const auto& a : checked.attempts) {
    EXPECT_EQ(a.candidate_id, checked.attempts.front().candidate_id);
    EXPECT_NE(a.outcome.find("no valid IK at the robot-human pose"), std::string::npos)
        << "the crate must leave every way of the first goal unreachable: " << a.outcome;
  }
  EXPECT_FALSE(checked.solved());
  EXPECT_EQ(late.status, checked.status);
  EXPECT_EQ(checked.motions_planned, 0);
  EXPECT_GT(late.motions_planned, 0);
  std::printf(
      "the unreachable goal alone: %d motions planned with the reach checked first, %d "
      "with the exchange first\n",
      checked.motions_planned, late.motions_planned);
}

// A validator stricter than the planner (a held board kept 2 deg inside theta_c) rejects
// transfers the planner has already planned past: with the validation overlapped, each is
// caught when the goal settles, its fallbacks run and its stage is planned again in order.
// The outcome is the one validating every motion before the next gives: the same goal, the
// same attempts, every emitted step passing the stricter validator. (On this database lateral
// right's first goal is rejected so, 15 times in order, and its second plans.)
TEST_F(BoardPlanner, ARejectionFoundLateGivesThePlanOfValidatingInOrder) {
  online::BoardPlanSettings strict = eq8_order();
  strict.validator.slip_tolerance_deg = -2.0;
  online::BoardPlanSettings strict_in_order = strict;
  strict_in_order.overlap_validation = false;
  int rejected = 0;
  for (const std::string name : {"lateral_right", "top"}) {
    SCOPED_TRACE(name);
    const online::Scene& s = scene_of(name);
    const auto overlapped = online::BoardPlanner(model(), strict).plan(s, name, in_seconds(120.0));
    const auto in_order =
        online::BoardPlanner(model(), strict_in_order).plan(s, name, in_seconds(120.0));
    print_plan(overlapped);
    rejected += overlapped.rejected_motions;
    // Each rejected stage is planned twice when overlapped: first on, then in order.
    EXPECT_GE(overlapped.rejected_motions, in_order.rejected_motions);
    ASSERT_EQ(overlapped.status, in_order.status);
    EXPECT_EQ(overlapped.candidate_id, in_order.candidate_id);
    ASSERT_EQ(overlapped.attempts.size(), in_order.attempts.size());
    for (std::size_t i = 0; i < overlapped.attempts.size(); ++i) {
      EXPECT_EQ(overlapped.attempts[i].outcome, in_order.attempts[i].outcome) << "attempt " << i;
    }
    if (overlapped.solved()) expect_plan_well_formed(model(), s, overlapped);
  }
  EXPECT_GT(rejected, 0) << "the stricter validator must reject something";
}

// A box beside back_lower's exchange where the receiving arm cannot reach some grasps at the
// first goals' robot-robot pose (found by trying boxes around it on this database): once a
// grasp's reach fails at a board pose, the goal's other chains come before that grasp at that
// pose again (held there by another suction grasp).
TEST_F(BoardPlanner, AGraspWhoseReceiveFailedAtABoardPoseComesBackLast) {
  const std::string name = "back_lower";
  online::Scene boxed = scene_of(name);
  boxed.obstacles.push_back(box_at(
      "crate", plan_of(name).robot_handover.translation() + Eigen::Vector3d(0, 0.22, 0), 0.1));
  const auto plan = online::BoardPlanner(model(), eq8_order()).plan(boxed, name, in_seconds(120.0));
  print_plan(plan);
  ASSERT_TRUE(plan.solved()) << plan.reason;
  expect_plan_well_formed(model(), boxed, plan);
  EXPECT_GT(expect_failed_receives_tried_last(model(), name, plan), 0)
      << "no grasp came back to a board pose where its reach had failed";
}

// Under the UR3's datasheet payload (the reference cell's allowance of 3.5 kg taken out), the
// 1.8 kg laterals on the suction tool are over it: the planner says so, with the sums, before
// anything is planned; a 0.8 kg board is planned as usual.
TEST(BoardPlannerPayload, APartOverThePayloadIsRefusedWithTheSums) {
  const std::string dir = test::temp_dir("board_planner_payload");
  const std::string cell_path = test::cell_variant(dir, "        allowed_kg: 3.5\n", "");
  offline::build_database(test::product_path(), cell_path, dir + "/cabinet.hila",
                          test::quick_build_settings(7, 2));
  const auto model =
      online::PlannerModel::load(dir + "/cabinet.hila", cell_path, test::product_path());
  online::BoardPlanner planner(*model);
  const online::Scene scene = online::nominal_scene(model->cell(), model->product());
  const online::BoardPlan lateral = planner.plan(scene, "lateral_right", in_seconds(30));
  EXPECT_EQ(lateral.status, online::BoardPlanStatus::kOverPayload);
  EXPECT_EQ(lateral.reason,
            "over the payload: part 1.80 kg + tooling 1.30 kg + suction tool 0.25 kg = 3.35 kg > "
            "3.00 kg allowed at arm 'right'");
  EXPECT_STREQ(online::to_string(lateral.status), "over payload");
  EXPECT_EQ(lateral.motions_planned, 0);
  const online::BoardPlan base = planner.plan(scene, "base", in_seconds(30));
  EXPECT_NE(base.status, online::BoardPlanStatus::kOverPayload) << base.reason;
}

// Goals a person would choose (BoardPlanSettings::natural_posture_first, on by default): the
// first goal tried is the first in Eq. 8 order whose receiving posture has the trunk upright, the
// elbows below the shoulders, the part's centre of mass between hip and shoulder height and RULA
// grand <= 3 — computed here from the anthropometric ratios (hip 0.530 H, shoulder 0.818 H) and
// the elbow by a chain of its own (torso to the elbow link), not by the planner's check. At the
// built stance every stored goal is comfortable, and the posture is the build's where it stored
// one, else the human arm's inverse kinematics (WorkerComfort::goal_reach). Brute force over
// every stored goal of every board.
TEST_F(BoardPlanner, TheFirstGoalTriedIsTheFirstNaturalOneInEq8Order) {
  const core::Cell& cell = model().cell();
  const online::BoardPlanSettings settings;
  ASSERT_TRUE(settings.natural_posture_first);
  ASSERT_TRUE(settings.blocked_exchanges_last);
  online::BoardPlanSettings in_place_settings;
  in_place_settings.blocked_exchanges_last = false;
  online::BoardPlanner in_place_planner(model(), in_place_settings);
  int blocked_boards = 0;           // boards whose first natural goal the build found blocked
  int blocked_failed_in_place = 0;  // of those, boards where it fails when tried first
  const core::HumanDimensions dims = core::human_dimensions(core::HumanBodySpec{});
  int reordered = 0, natural_boards = 0;
  int lazy_stops = 0;  // boards planned at the first of several natural goals
  online::BoardPlanner planner(model(), settings);
  for (const auto& part : model().product().parts) {
    SCOPED_TRACE(part.name);
    const online::BoardRecords* records = model().board_records(part.name);
    ASSERT_NE(records, nullptr);
    const online::BoardPlan plan = planner.plan(scene_of(part.name), part.name, in_seconds(120.0));
    const core::Pose stance = scene_of(part.name).human_stance;
    ASSERT_TRUE(stance.isApprox(cell.spec().human_stance, 1e-12));
    const double hip_z = (stance * Eigen::Vector3d(0, 0, dims.hip_height)).z();
    const double shoulder_z = (stance * Eigen::Vector3d(0, 0, dims.shoulder_height)).z();
    std::vector<std::int64_t> natural;
    int solved = 0;                 // postures the human arms' IK solves (no stored one)
    std::vector<int> solved_until;  // by natural goal (Eq. 8 order): postures solved up to it
    for (const auto& goal : records->goals) {
      const double centre_z = (goal.board * records->part.mass_properties.com).z();
      if (centre_z < hip_z || centre_z > shoulder_z) continue;
      online::WorkerComfort::GoalReach r;
      if (goal.human_joints.size() > 0 && (goal.second_arm.empty() || goal.second_joints.size())) {
        r.reachable = true;
        r.joints = goal.human_joints;
        r.second_joints = goal.second_joints;
      } else {
        r = online::WorkerComfort::goal_reach(cell, goal, records->human_grasps, stance);
        ++solved;
      }
      if (!r.reachable) continue;
      std::vector<std::pair<std::string, Eigen::VectorXd>> arms{{goal.human_arm, r.joints}};
      if (!goal.second_arm.empty()) arms.emplace_back(goal.second_arm, r.second_joints);
      bool elbows_low = true;
      int rula = 0;
      const Eigen::VectorXd q = core::human_posture(cell, arms);
      for (const auto& [side, joints] : arms) {
        const core::KinematicChain to_elbow(cell.human(), "torso", side + "_elbow_link");
        ASSERT_EQ(to_elbow.dof(), 4);
        const double elbow_in_torso = to_elbow.fk(joints.head(4)).translation().z();
        elbows_low = elbows_low && elbow_in_torso < dims.shoulder_height - dims.hip_height;
        rula = std::max(rula, core::rula(core::rula_inputs_from_posture(cell.human(), q, side,
                                                                        part.mass, arms.size() > 1))
                                  .grand);
      }
      const double trunk =
          q[cell.human()
                .joints()[static_cast<std::size_t>(cell.human().joint_index("torso_flexion"))]
                .variable];
      if (std::abs(trunk) < 1e-12 && elbows_low && rula <= 3) {
        solved_until.push_back(solved);
        natural.push_back(goal.id);
      }
    }
    ASSERT_FALSE(plan.attempts.empty());
    if (natural.empty()) {
      EXPECT_FALSE(plan.natural_posture);
      EXPECT_EQ(plan.goals_natural, 0);
      continue;
    }
    ++natural_boards;
    const auto goal_of = [&](std::int64_t id) -> const db::HandoverCandidateRecord& {
      return *std::find_if(records->goals.begin(), records->goals.end(),
                           [&](const auto& g) { return g.id == id; });
    };
    const bool first_blocked = all_exchanges_blocked(*records, goal_of(natural.front()));
    // The first natural goal whose ways are not all blocked (Eq. 8 order).
    std::size_t first_open = 0;
    while (first_open < natural.size() &&
           all_exchanges_blocked(*records, goal_of(natural[first_open]))) {
      ++first_open;
    }
    if (first_open < natural.size() && plan.solved() && plan.candidate_id == natural[first_open]) {
      // Planned at the first open natural goal: the search stopped there (lazy), its postures
      // solved only up to that goal.
      EXPECT_EQ(plan.goals_natural, static_cast<int>(first_open) + 1);
      EXPECT_EQ(plan.human_postures_solved, solved_until[first_open]);
      lazy_stops += natural.size() > first_open + 1 ? 1 : 0;
    } else {
      // The planner looks no further once it has as many natural goals as it tries.
      EXPECT_EQ(plan.goals_natural,
                std::min(static_cast<int>(natural.size()), online::BoardPlanSettings{}.goals));
    }
    // Natural goals whose every exchange the build found blocked come after the open ones.
    const auto first_natural_eq8 = natural.front();
    const auto open_end = std::stable_partition(natural.begin(), natural.end(), [&](auto id) {
      return !all_exchanges_blocked(*records, goal_of(id));
    });
    const auto open_natural = static_cast<std::size_t>(open_end - natural.begin());
    if (first_blocked) {
      // In its place, the blocked goal is the first tried (where it often fails).
      ++blocked_boards;
      const online::BoardPlan in_place =
          in_place_planner.plan(scene_of(part.name), part.name, in_seconds(120.0));
      ASSERT_FALSE(in_place.attempts.empty());
      EXPECT_EQ(in_place.attempts.front().candidate_id, first_natural_eq8);
      EXPECT_NE(plan.attempts.front().candidate_id, first_natural_eq8);
      blocked_failed_in_place += in_place.attempts.front().outcome != "planned" ? 1 : 0;
    }
    EXPECT_EQ(plan.attempts.front().candidate_id, natural.front());
    // The goals tried go through the natural ones in Eq. 8 order before any other.
    std::vector<std::int64_t> tried;  // distinct, in the order first tried (a second round
                                      // with larger bridges starts over)
    for (const auto& a : plan.attempts) {
      if (std::find(tried.begin(), tried.end(), a.candidate_id) == tried.end()) {
        tried.push_back(a.candidate_id);
      }
    }
    for (std::size_t i = 0; i < tried.size() && i < open_natural; ++i) {
      EXPECT_EQ(tried[i], natural[i]) << "goal tried " << i;
    }
    // Once a blocked goal is tried, every goal after it is blocked too (within a round).
    bool blocked_seen = false;
    for (const auto& a : plan.attempts) {
      if (a.larger_bridges) break;
      const bool blocked = all_exchanges_blocked(*records, goal_of(a.candidate_id));
      EXPECT_TRUE(blocked || !blocked_seen) << "goal " << a.candidate_id << " after a blocked one";
      blocked_seen = blocked_seen || blocked;
    }
    if (plan.solved()) {
      EXPECT_EQ(plan.natural_posture,
                std::find(natural.begin(), natural.end(), plan.candidate_id) != natural.end());
    }
    reordered += natural.front() != records->goals.front().id ? 1 : 0;
  }
  EXPECT_GT(natural_boards, 0);
  EXPECT_GT(reordered, 0);                // the tiers change a first goal on the cabinet
  EXPECT_GT(lazy_stops, 0);               // the lazy search saved the other natural goals' postures
  EXPECT_GT(blocked_boards, 0);           // back_upper's first natural goal: every exchange blocked
  EXPECT_GT(blocked_failed_in_place, 0);  // back_upper's fails at the suction arm's transfer
}
