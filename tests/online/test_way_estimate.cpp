#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>

#include "hila/core/time_parameterization.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

std::chrono::steady_clock::time_point in_seconds(double s) {
  return std::chrono::steady_clock::now() + std::chrono::microseconds(static_cast<long>(s * 1e6));
}

// lateral_right's scene as `hila plan --all` reaches it: base assembled, the suction arm holding
// the tool, both arms home.
online::Scene lateral_right_scene(const online::PlannerModel& model) {
  online::Scene scene = online::load_scene(test::data_path("cabinet/scene.yaml"), model.cell(),
                                           model.product())
                            .with_finished(model.product(), "base");
  scene.tool_in_hand = true;
  for (const auto& arm : model.cell().arms()) scene.robot[arm.spec.name] = arm.spec.home;
  return scene;
}

// The same with a crate at each of the board's first `goals` goals' hand-over points: the
// planner runs through those goals' ways before one is planned.
online::Scene crate_scene(const online::PlannerModel& model, const std::string& board,
                          std::size_t goals) {
  online::Scene scene = lateral_right_scene(model);
  const online::BoardRecords& records = *model.board_records(board);
  for (std::size_t g = 0; g < std::min(goals, records.goals.size()); ++g) {
    online::SceneObstacle crate;
    crate.name = "crate" + std::to_string(g);
    crate.pose = records.goals[g].board;
    crate.box_size = Eigen::Vector3d::Constant(0.06);
    scene.obstacles.push_back(crate);
  }
  return scene;
}

// The regrasp graph of one board read by brute force: every lookup a scan of the records.
struct Graph {
  std::vector<db::RegraspNodeRecord> nodes;
  std::vector<db::RegraspEdgeRecord> edges;
  const db::RegraspNodeRecord* node(std::int64_t id) const {
    for (const auto& n : nodes) {
      if (n.id == id) return &n;
    }
    return nullptr;
  }
  // The first connected edge (id order) of `kind` moving `arm` whose ends match.
  template <typename From, typename To>
  const db::RegraspEdgeRecord* edge(const std::string& kind, const std::string& arm, From from,
                                    To to) const {
    for (const auto& e : edges) {
      if (!e.connected || e.kind != kind || e.arm != arm || e.path.size() < 2) continue;
      const auto* a = node(e.from_node);
      const auto* b = node(e.to_node);
      if (a != nullptr && b != nullptr && from(*a) && to(*b)) return &e;
    }
    return nullptr;
  }
};

}  // namespace

// The cabinet database (HILA_TEST_DATABASE, else a build) and its model, once per process.
class WayEstimate : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::string path;
    if (const char* given = std::getenv("HILA_TEST_DATABASE")) {
      path = given;
    } else {
      dir_ = test::temp_dir("way_estimate_" + std::to_string(::getpid()));
      path = dir_ + "/cabinet.hila";
      // The default build with a smaller roadmap, as test_board_planner's (the quick settings'
      // goals are too few for lateral_right).
      offline::BuildSettings s;
      s.jobs = 2;
      s.roadmap.nodes = 1200;
      offline::build_database(test::product_path(), test::cell_path(), path, s);
    }
    model_ = online::PlannerModel::load(path, test::cell_path(), test::product_path());
  }
  static void TearDownTestSuite() {
    model_.reset();
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }
  static const online::PlannerModel& model() { return *model_; }

 private:
  static inline std::string dir_;
  static inline std::shared_ptr<const online::PlannerModel> model_;
};

// Every exchange attempt's estimate is found again from the database's records by brute force:
// the suction arm from home to its pick, the stored transfer to the exchange (or the straight
// move), home; the receiving arm's stored way in, its stored transfer to the human (or straight
// moves), home. Each stored motion counts its stored duration, which is the stored path timed
// as the planner times a motion.
TEST_F(WayEstimate, AnExchangesEstimateIsItsStoredDurationsAndStraightMoves) {
  const online::PlannerModel& m = model();
  const online::Scene scene = crate_scene(m, "lateral_right", 1);
  online::BoardPlanSettings settings;
  const online::BoardPlan plan =
      online::BoardPlanner(m, settings).plan(scene, "lateral_right", in_seconds(120.0));
  ASSERT_FALSE(plan.attempts.empty()) << plan.reason;
  const online::BoardRecords& records = *m.board_records("lateral_right");
  Graph graph{records.regrasp_nodes, records.regrasp_edges};
  const core::Arm& suction = m.cell().arm(records.suction_arm.empty() ? "right"
                                                                       : records.suction_arm);
  const core::Arm& receiving = m.cell().arm(suction.spec.name == "right" ? "left" : "right");
  auto straight = [&](const core::Arm& arm, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return core::rest_to_rest_duration({a, b}, arm.spec.max_velocity, arm.spec.max_acceleration,
                                       settings.speed_scale);
  };
  auto seconds = [&](const core::Arm& arm, const db::RegraspEdgeRecord* e, double otherwise) {
    if (e == nullptr) return otherwise;
    const double timed =
        core::time_parameterize_through(e->path, arm.spec.max_velocity,
                                        arm.spec.max_acceleration, settings.speed_scale,
                                        settings.timing_step)
            .time.back();
    // A file written before durations were stored has 0: the path is then timed rest to rest.
    if (e->duration == 0.0) {
      return core::rest_to_rest_duration(e->path, arm.spec.max_velocity,
                                         arm.spec.max_acceleration, settings.speed_scale);
    }
    EXPECT_NEAR(e->duration, timed, 1e-9) << "edge " << e->id;
    return e->duration;
  };
  int checked = 0, stored = 0;
  // The first goal's ways: estimated before anything of the board was planned, so each
  // exchange picks with its robot-robot pose's own cup (no stand-in found yet).
  for (const auto& a : plan.attempts) {
    if (a.candidate_id != plan.attempts.front().candidate_id || a.larger_bridges) continue;
    if (a.mode != online::DeliveryMode::kExchange) continue;
    const db::RobotHandoverRecord& rr = records.robot_handovers.at(a.robot_handover_id);
    const db::SharedGraspRecord* shared = nullptr;
    for (const auto& s : records.shared_grasps.at(a.candidate_id)) {
      if (s.robot_grasp_id == a.robot_grasp_id && s.robot_handover_id == a.robot_handover_id) {
        shared = &s;
      }
    }
    ASSERT_NE(shared, nullptr);
    const std::int64_t cup = rr.suction_grasp_id;
    const db::RegraspNodeRecord* pick = nullptr;
    for (const auto& n : graph.nodes) {
      if (pick == nullptr && n.kind == "pick" && n.arm == suction.spec.name &&
          n.grasp_kind == "suction" && n.grasp_id == cup) {
        pick = &n;
      }
    }
    double t = 0.0;
    if (pick == nullptr) {
      t += straight(suction, suction.spec.home, rr.joints);
    } else {
      const auto* e = graph.edge(
          "transfer", suction.spec.name,
          [&](const auto& n) { return n.kind == "pick" && n.grasp_id == cup; },
          [&](const auto& n) {
            return n.kind == "robot_handover" && n.robot_handover_id == rr.id;
          });
      stored += e != nullptr;
      t += straight(suction, suction.spec.home, pick->solutions.front()) +
           seconds(suction, e, straight(suction, pick->solutions.front(), rr.joints));
    }
    t += straight(suction, rr.joints, suction.spec.home);
    auto at_exchange = [&](const auto& n) {
      return n.kind == "robot_handover" && n.robot_handover_id == rr.id &&
             n.grasp_id == shared->robot_grasp_id;
    };
    const auto* in = graph.edge(
        "transit", receiving.spec.name, [](const auto& n) { return n.kind == "home"; },
        at_exchange);
    const auto* out = graph.edge("transfer", receiving.spec.name, at_exchange, [&](const auto& n) {
      return n.kind == "human_handover" && n.candidate_id == a.candidate_id &&
             n.grasp_id == shared->robot_grasp_id;
    });
    stored += (in != nullptr) + (out != nullptr);
    t += seconds(receiving, in, straight(receiving, receiving.spec.home, shared->joints_rr)) +
         seconds(receiving, out, straight(receiving, shared->joints_rr, shared->joints_rh)) +
         straight(receiving, shared->joints_rh, receiving.spec.home);
    EXPECT_NEAR(a.estimated_seconds, t, 1e-9)
        << "goal " << a.candidate_id << " grasp " << a.robot_grasp_id << " rr " << rr.id;
    ++checked;
  }
  EXPECT_GE(checked, 2);
  EXPECT_GE(stored, 1) << "no stored motion was counted: the check would not see their durations";
  if (plan.solved()) {
    EXPECT_DOUBLE_EQ(plan.estimated_seconds, plan.attempts.back().estimated_seconds);
  }
}

// With a crate where the first goals hand the board over, the planner runs through many of
// their ways: within each goal they come in the order of their estimates (exchanges the offline
// graph connected first), and in the fixed order (the baseline) they do not always — so the
// check tells the two apart. With every goal's ways by estimate alone (kCheapestFirst) the whole
// sequence is in that order. No order plans anything invalid.
TEST_F(WayEstimate, AGoalsWaysArePlannedInTheOrderOfTheirEstimates) {
  const online::PlannerModel& m = model();
  const online::Scene scene = crate_scene(m, "lateral_right", 3);
  const online::BoardRecords& records = *m.board_records("lateral_right");
  // Whether the offline graph connected the goal with the grasp at the exchange (brute force).
  Graph graph{records.regrasp_nodes, records.regrasp_edges};
  auto connected = [&](const online::GoalAttempt& a) {
    if (a.mode != online::DeliveryMode::kExchange) return true;
    return graph.edge(
               "transfer", a.arm,
               [&](const auto& n) {
                 return n.kind == "robot_handover" && n.robot_handover_id == a.robot_handover_id;
               },
               [&](const auto& n) {
                 return n.kind == "human_handover" && n.candidate_id == a.candidate_id &&
                        n.grasp_id == a.robot_grasp_id;
               }) != nullptr;
  };
  // Pairs of consecutive first-round attempts of one goal out of (unconnected, estimate) order,
  // and how many pairs there were. A receive that failed defers that grasp's other exchange
  // poses of the same board pose: those come back last and are left out.
  auto out_of_order = [&](const online::BoardPlan& plan, int& pairs) {
    int wrong = 0;
    std::set<std::int64_t> receive_failed_grasps;
    for (std::size_t i = 0; i + 1 < plan.attempts.size(); ++i) {
      const auto& a = plan.attempts[i];
      const auto& b = plan.attempts[i + 1];
      if (a.step.rfind("receiving_", 0) == 0) receive_failed_grasps.insert(a.robot_grasp_id);
      if (a.larger_bridges || b.larger_bridges || a.candidate_id != b.candidate_id) continue;
      if (receive_failed_grasps.count(b.robot_grasp_id) > 0) continue;
      ++pairs;
      const auto ka = std::make_pair(!connected(a), a.estimated_seconds);
      const auto kb = std::make_pair(!connected(b), b.estimated_seconds);
      wrong += kb < ka;
    }
    return wrong;
  };
  online::BoardPlanSettings by_time;
  const online::BoardPlan timed =
      online::BoardPlanner(m, by_time).plan(scene, "lateral_right", in_seconds(120.0));
  online::BoardPlanSettings fixed;
  fixed.way_order = online::WayOrder::kFixed;
  const online::BoardPlan baseline =
      online::BoardPlanner(m, fixed).plan(scene, "lateral_right", in_seconds(120.0));
  int timed_pairs = 0, baseline_pairs = 0;
  EXPECT_EQ(out_of_order(timed, timed_pairs), 0);
  EXPECT_GE(timed_pairs, 3) << "too few ways of one goal tried to see their order";
  EXPECT_GT(out_of_order(baseline, baseline_pairs), 0)
      << "the fixed order happened to be the estimates' here: the check cannot fail";
  // Every goal's ways by estimate alone (the measurement setting): one sequence across goals.
  online::BoardPlanSettings cheapest;
  cheapest.way_order = online::WayOrder::kCheapestFirst;
  const online::BoardPlan across =
      online::BoardPlanner(m, cheapest).plan(scene, "lateral_right", in_seconds(120.0));
  std::set<std::int64_t> receive_failed;
  int across_pairs = 0, across_wrong = 0;
  for (std::size_t i = 0; i + 1 < across.attempts.size(); ++i) {
    const auto& a = across.attempts[i];
    const auto& b = across.attempts[i + 1];
    if (a.step.rfind("receiving_", 0) == 0) receive_failed.insert(a.robot_grasp_id);
    if (a.larger_bridges || b.larger_bridges || receive_failed.count(b.robot_grasp_id) > 0) continue;
    ++across_pairs;
    across_wrong += std::make_pair(!connected(b), b.estimated_seconds) <
                    std::make_pair(!connected(a), a.estimated_seconds);
  }
  EXPECT_EQ(across_wrong, 0);
  EXPECT_GE(across_pairs, 3);
  for (const auto* plan : {&timed, &baseline, &across}) {
    if (plan->solved()) {
      EXPECT_TRUE(plan->validated);
    }
    for (const auto& a : plan->attempts) EXPECT_GT(a.estimated_seconds, 0.0);
  }
}
