#include <gtest/gtest.h>

#include <optional>
#include <random>

#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/offline/roadmap.hpp"
#include "hila/online/arm_motion.hpp"
#include "hila/online/validator.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

const core::ProductSpec& cabinet() {
  static const core::ProductSpec product = core::load_product(test::product_path());
  return product;
}

// A small left-arm roadmap of the reference cell (the offline builder, as the database stores it).
const online::ArmRoadmap& left_roadmap() {
  static const online::ArmRoadmap roadmap = [] {
    offline::RoadmapSettings settings;
    settings.nodes = 400;
    return online::ArmRoadmap(
        offline::to_record(offline::build_roadmap(*test::reference_cell(), "left", settings)));
  }();
  return roadmap;
}

// A roadmap record of `nodes` joined by `edges` (node indices).
db::RoadmapRecord roadmap_of(const std::vector<Eigen::VectorXd>& nodes,
                             const std::vector<std::pair<int, int>>& edges) {
  db::RoadmapRecord r = left_roadmap().record;
  r.nodes = nodes;
  r.node_gravity.assign(nodes.size(), Eigen::Vector3d::UnitZ());
  r.node_inclination_deg.assign(nodes.size(), 0.0);
  r.edges = edges;
  r.edge_length.clear();
  for (const auto& [a, b] : edges) {
    r.edge_length.push_back(
        (nodes[static_cast<std::size_t>(b)] - nodes[static_cast<std::size_t>(a)]).norm());
  }
  r.edge_max_inclination_deg.assign(edges.size(), 0.0);
  return r;
}

// A roadmap record of `nodes`, the first nodes.size() - loose chained by edges in order, the
// last `loose` without edges.
db::RoadmapRecord chain_roadmap(const std::vector<Eigen::VectorXd>& nodes, std::size_t loose = 0) {
  std::vector<std::pair<int, int>> edges;
  for (std::size_t i = 0; i + 1 + loose < nodes.size(); ++i) {
    edges.emplace_back(static_cast<int>(i), static_cast<int>(i + 1));
  }
  return roadmap_of(nodes, edges);
}

// Waypoints 4 s apart: slow enough for every velocity and acceleration limit.
online::Motion timed(const std::vector<Eigen::VectorXd>& path, const core::Pose& board) {
  online::Motion m;
  m.arm = "left";
  m.q = path;
  for (std::size_t i = 0; i < path.size(); ++i) m.time.push_back(4.0 * static_cast<double>(i));
  m.robot_q = test::reference_cell()->home_configuration();
  m.board_world = board;
  return m;
}

std::string describe(const online::ValidationReport& r) {
  std::string out;
  for (const auto& v : r.violations) out += v.kind + ": " + v.detail + "; ";
  return out;
}

// The independent validator's report on a planned path, timed slowly, in `world`.
online::ValidationReport validate_in(const online::World& world,
                                     const std::vector<Eigen::VectorXd>& path) {
  core::CollisionData data = world.make_data();
  return online::validate_motion(world, data, timed(path, cabinet().part("top").initial));
}

online::MotionRequest request(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  online::MotionRequest q;
  q.start = a;
  q.goal = b;
  q.robot_q = test::reference_cell()->home_configuration();
  q.board_world = cabinet().part("top").initial;
  return q;
}

// Seeded far-apart node pairs of the roadmap.
std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> far_pairs(int count) {
  const auto& nodes = left_roadmap().record.nodes;
  std::mt19937_64 rng(7);
  std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> out;
  while (static_cast<int>(out.size()) < count) {
    const auto& a = nodes[rng() % nodes.size()];
    const auto& b = nodes[rng() % nodes.size()];
    if ((a - b).norm() > 2.0) out.emplace_back(a, b);
  }
  return out;
}

online::SceneObstacle crate_at(const Eigen::Vector3d& p, double size) {
  online::SceneObstacle crate;
  crate.name = "crate";
  crate.box_size = Eigen::Vector3d::Constant(size);
  crate.pose = core::Pose(Eigen::Translation3d(p));
  return crate;
}

// A start `fraction` of the way from far node `a` to `b` whose path through the roadmap in the
// nominal scene (`nominal_planner`'s, no bridges) enters it at an interior waypoint, and the
// scene with a crate on the middle of that join (nothing when the pair's path is not so).
struct CratedJoin {
  online::MotionRequest request;  // start to b, no bridges
  Eigen::VectorXd entry;          // the path's second waypoint in the nominal scene
  online::Scene crated;
};

std::optional<CratedJoin> crate_on_the_join(online::ArmMotionPlanner& nominal_planner,
                                            const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                            double fraction) {
  const auto& cell = *test::reference_cell();
  const core::Arm& left = cell.arm("left");
  const Eigen::VectorXd start = a + fraction * (b - a);
  CratedJoin join{request(start, b), {}, online::nominal_scene(cell, cabinet())};
  join.request.allow_bridge = false;
  const auto before = nominal_planner.plan(join.request);
  if (!before.solved() || before.via != online::MotionVia::kRoadmap || before.path.size() < 3)
    return std::nullopt;
  join.entry = before.path[1];
  const core::Pose middle =
      core::arm_base_in_world(cell, left) * left.chain.fk(0.5 * (start + join.entry));
  join.crated.obstacles.push_back(crate_at(middle.translation(), 0.06));
  return join;
}

// A roadmap path with interior nodes in the nominal scene, between far node pairs `a` and `b`,
// and the scene with a crate at the TCP of its middle waypoint (nothing when no pair plans so).
struct CratedPath {
  Eigen::VectorXd a, b;
  online::MotionResult before;  // in the nominal scene
  online::Scene blocked;
};

std::optional<CratedPath> crate_on_a_roadmap_path() {
  const auto& cell = *test::reference_cell();
  const online::Scene nominal = online::nominal_scene(cell, cabinet());
  const online::World nominal_world(cell, cabinet(), nominal, "top");
  online::ArmMotionPlanner planner(nominal_world, left_roadmap(), "left");
  for (const auto& pair : far_pairs(20)) {
    online::MotionResult before = planner.plan(request(pair.first, pair.second));
    if (!before.solved() || before.via != online::MotionVia::kRoadmap || before.path.size() < 4)
      continue;
    const core::Arm& left = cell.arm("left");
    const core::Pose tcp =
        core::arm_base_in_world(cell, left) * left.chain.fk(before.path[before.path.size() / 2]);
    online::Scene blocked = nominal;
    blocked.obstacles.push_back(crate_at(tcp.translation(), 0.08));
    return CratedPath{pair.first, pair.second, std::move(before), std::move(blocked)};
  }
  return std::nullopt;
}

// Tests that start from the crated roadmap path: it and the world of its crated scene, made
// before each of them.
class ArmMotionCrated : public ::testing::Test {
 protected:
  void SetUp() override {
    crated_ = crate_on_a_roadmap_path();
    ASSERT_TRUE(crated_.has_value()) << "a roadmap path with interior nodes";
    world_.emplace(*test::reference_cell(), cabinet(), crated_->blocked, "top");
  }
  const CratedPath& crated() const { return *crated_; }
  const online::World& crated_world() const { return *world_; }

 private:
  std::optional<CratedPath> crated_;
  std::optional<online::World> world_;
};

}  // namespace

TEST(ArmMotion, SolvedMotionsPassTheIndependentValidator) {
  const auto& cell = *test::reference_cell();
  const online::Scene scene = online::nominal_scene(cell, cabinet());
  const online::World world(cell, cabinet(), scene, "top");
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  core::CollisionData data = world.make_data();
  int solved = 0;
  for (const auto& [a, b] : far_pairs(8)) {
    const auto result = planner.plan(request(a, b));
    if (!result.solved()) continue;
    ++solved;
    ASSERT_GE(result.path.size(), 2u);
    EXPECT_TRUE(result.path.front().isApprox(a, 0.0));
    EXPECT_TRUE(result.path.back().isApprox(b, 0.0));
    const auto report =
        online::validate_motion(world, data, timed(result.path, cabinet().part("top").initial));
    EXPECT_TRUE(report.valid()) << online::to_string(result.via) << ": " << describe(report);
  }
  EXPECT_GE(solved, 6) << "of 8 node pairs";
}

TEST_F(ArmMotionCrated, AnObstacleOnTheStoredPathIsRepairedAround) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  core::CollisionData data = world.make_data();
  const auto old =
      online::validate_motion(world, data, timed(before.path, cabinet().part("top").initial));
  ASSERT_FALSE(old.valid()) << "the crate must block the stored path";

  online::ArmMotionPlanner repaired(world, left_roadmap(), "left");
  const auto after = repaired.plan(request(a, b));
  ASSERT_TRUE(after.solved()) << after.reason;
  EXPECT_TRUE(after.via == online::MotionVia::kBridge || after.edges_invalidated > 0)
      << online::to_string(after.via);
  const auto report =
      online::validate_motion(world, data, timed(after.path, cabinet().part("top").initial));
  EXPECT_TRUE(report.valid()) << describe(report);
}

// The same crate, the blocked roadmap path given as a stored path, and the roadmap allowed one
// search only: with a repair budget the stored path is bridged around the crate where it is
// blocked and kept elsewhere (its waypoint before the crate is still on the path); without one
// the motion falls through to a bridge across the whole motion.
TEST_F(ArmMotionCrated, AStoredPathBlockedMidwayIsRepairedLocally) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  core::CollisionData data = world.make_data();
  const std::vector<Eigen::VectorXd>& stored = before.path;
  const std::size_t crate_at = stored.size() / 2;  // the waypoint the crate sits on
  online::MotionRequest r = request(a, b);
  r.hints = {&stored};
  r.max_searches = 1;

  online::MotionSettings settings;
  settings.repair_checks = 20000;
  online::ArmMotionPlanner repairing(world, left_roadmap(), "left", settings);
  repairing.prepare(r);
  ASSERT_FALSE(repairing.valid(stored[crate_at])) << "the crate must block the stored path";
  const auto repaired = repairing.plan(r);
  ASSERT_TRUE(repaired.solved()) << repaired.reason;
  EXPECT_EQ(repaired.via, online::MotionVia::kStoredRepair);
  EXPECT_TRUE(repaired.path.front().isApprox(a, 0.0));
  EXPECT_TRUE(repaired.path.back().isApprox(b, 0.0));
  // Kept up to the blockage (shortcutting only drops waypoints between kept ones, and the
  // stored start's neighbour is where the stored path is left only if the crate is there).
  const auto kept = std::find(repaired.path.begin(), repaired.path.end(), stored[crate_at - 1]);
  EXPECT_TRUE(kept != repaired.path.end() || crate_at - 1 == 0 ||
              repairing.segment_valid(a, stored[crate_at + 1]))
      << "the stored path before the crate was not kept";
  const auto report =
      online::validate_motion(world, data, timed(repaired.path, cabinet().part("top").initial));
  EXPECT_TRUE(report.valid()) << describe(report);

  online::ArmMotionPlanner plain(world, left_roadmap(), "left");  // repair_checks 0
  const auto without = plain.plan(r);
  EXPECT_FALSE(without.wedged);
  EXPECT_NE(without.via, online::MotionVia::kStoredRepair);

  // Ends that attach to no roadmap node (none is tried here): the default settings repair
  // (wedged_repair_checks), and the motion says it was wedged only when it fails.
  online::MotionSettings unattached;
  unattached.attach_neighbours = 0;
  online::ArmMotionPlanner wedged(world, left_roadmap(), "left", unattached);
  const auto led = wedged.plan(r);
  ASSERT_TRUE(led.solved()) << led.reason;
  EXPECT_EQ(led.via, online::MotionVia::kStoredRepair);
  unattached.wedged_repair_checks = 0;
  unattached.bridge_checks = 200;
  online::ArmMotionPlanner no_repair(world, left_roadmap(), "left", unattached);
  const auto stuck = no_repair.plan(r);
  EXPECT_NE(stuck.via, online::MotionVia::kStoredRepair);
  if (!stuck.solved()) {
    EXPECT_TRUE(stuck.wedged);
    EXPECT_NE(stuck.reason.find("attaches to no roadmap node"), std::string::npos) << stuck.reason;
  }
}

// Stored paths are tried in order, each followed whole: the one the crate blocks is passed
// over for the next (the database stores other bridges of a transfer after the first, for
// scenes that block it), whichever comes first.
TEST_F(ArmMotionCrated, AStoredPathTheSceneBlocksGivesWayToTheNextOne) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  core::CollisionData data = world.make_data();
  const std::vector<Eigen::VectorXd>& stored = before.path;
  // A way round the crate: planned in the crated scene without any stored path.
  online::ArmMotionPlanner finder(world, left_roadmap(), "left");
  const auto around = finder.plan(request(a, b));
  ASSERT_TRUE(around.solved()) << around.reason;
  ASSERT_GT(around.path.size(), 2u) << "a way round, not the straight motion";
  const std::vector<Eigen::VectorXd> other = around.path;

  for (const bool blocked_first : {true, false}) {
    SCOPED_TRACE(blocked_first ? "the blocked path first" : "the clear path first");
    online::MotionRequest r = request(a, b);
    r.hints = blocked_first ? std::vector<const std::vector<Eigen::VectorXd>*>{&stored, &other}
                            : std::vector<const std::vector<Eigen::VectorXd>*>{&other, &stored};
    online::ArmMotionPlanner planner(world, left_roadmap(), "left");
    const auto found = planner.plan(r);
    ASSERT_TRUE(found.solved()) << found.reason;
    EXPECT_EQ(found.via, online::MotionVia::kStored);
    EXPECT_EQ(found.searches, 0) << "no roadmap search when a stored path holds";
    // The clear path's waypoints (shortcutting keeps a subset, in order, ends exact).
    EXPECT_TRUE(found.path.front().isApprox(a, 0.0));
    EXPECT_TRUE(found.path.back().isApprox(b, 0.0));
    for (const auto& q : found.path) {
      EXPECT_TRUE(std::find(other.begin(), other.end(), q) != other.end())
          << "a waypoint not on the clear stored path";
    }
    const auto report =
        online::validate_motion(world, data, timed(found.path, cabinet().part("top").initial));
    EXPECT_TRUE(report.valid()) << describe(report);
  }
  // The blocked one alone is not followed.
  online::MotionRequest alone = request(a, b);
  alone.hints = {&stored};
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  EXPECT_NE(planner.plan(alone).via, online::MotionVia::kStored);
}

// A path the validator rejected (the crate planted on it after it was found): given back as
// MotionRequest::rejected, it is mended where the crate blocks it, kept elsewhere, and the
// mended path passes the validator; with no mending budget the motion is planned again instead.
TEST_F(ArmMotionCrated, ARejectedPathIsMendedWhereItIsBlocked) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  core::CollisionData data = world.make_data();
  const std::vector<Eigen::VectorXd>& rejected = before.path;
  const auto first_report =
      online::validate_motion(world, data, timed(rejected, cabinet().part("top").initial));
  ASSERT_FALSE(first_report.valid()) << "the crate must block the path";
  online::MotionRequest r = request(a, b);
  r.fine_checks = true;
  r.rejected = &rejected;
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  const auto mended = planner.plan(r);
  ASSERT_TRUE(mended.solved()) << mended.reason;
  EXPECT_EQ(mended.via, online::MotionVia::kRepaired);
  EXPECT_TRUE(mended.path.front().isApprox(a, 0.0));
  EXPECT_TRUE(mended.path.back().isApprox(b, 0.0));
  const auto report =
      online::validate_motion(world, data, timed(mended.path, cabinet().part("top").initial));
  EXPECT_TRUE(report.valid()) << describe(report);

  online::MotionSettings no_mending;
  no_mending.fine_repair_checks = 0;
  online::ArmMotionPlanner again(world, left_roadmap(), "left", no_mending);
  const auto replanned = again.plan(r);
  EXPECT_NE(replanned.via, online::MotionVia::kRepaired);
}

TEST(ArmMotion, AGoalInsideAnObstacleAndAPastDeadlineAreStatusesWithReasons) {
  const auto& cell = *test::reference_cell();
  const auto pair = far_pairs(1).front();
  const core::Arm& left = cell.arm("left");
  const core::Pose tcp = core::arm_base_in_world(cell, left) * left.chain.fk(pair.second);
  online::Scene scene = online::nominal_scene(cell, cabinet());
  scene.obstacles.push_back(crate_at(tcp.translation(), 0.12));  // wider than the open jaw
  const online::World world(cell, cabinet(), scene, "top");
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  const auto blocked = planner.plan(request(pair.first, pair.second));
  EXPECT_EQ(blocked.status, online::MotionStatus::kInvalidGoal);
  EXPECT_NE(blocked.reason.find("obstacle/crate"), std::string::npos) << blocked.reason;
  EXPECT_TRUE(blocked.path.empty());

  const online::World free_world(cell, cabinet(), online::nominal_scene(cell, cabinet()), "top");
  online::ArmMotionPlanner free_planner(free_world, left_roadmap(), "left");
  auto late = request(pair.first, pair.second);
  late.deadline = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  const auto result = free_planner.plan(late);
  // Only a direct straight segment can beat a deadline that has passed.
  if (result.via != online::MotionVia::kDirect) {
    EXPECT_EQ(result.status, online::MotionStatus::kTimeout) << result.reason;
    EXPECT_TRUE(result.path.empty());
  }
}

// The planner keeps the edges it found blocked while the scene is posed the same: a second
// request finds the same path without invalidating them again, and a request posing the rest
// of the robot differently starts over (matching a fresh planner).
TEST_F(ArmMotionCrated, BlockedEdgesAreRememberedOnlyWhileTheSceneIsPosedTheSame) {
  const auto& cell = *test::reference_cell();
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();

  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  const auto first = planner.plan(request(a, b));
  ASSERT_TRUE(first.solved()) << first.reason;
  ASSERT_EQ(first.via, online::MotionVia::kRoadmap)
      << "the crate should cut single edges, not the roadmap";
  ASSERT_GT(first.edges_invalidated, 0);
  const auto again = planner.plan(request(a, b));
  ASSERT_TRUE(again.solved());
  EXPECT_EQ(again.edges_invalidated, 0);
  EXPECT_LT(again.searches, first.searches);
  ASSERT_EQ(again.path.size(), first.path.size());
  for (std::size_t i = 0; i < again.path.size(); ++i) {
    EXPECT_TRUE(again.path[i].isApprox(first.path[i], 0.0)) << "waypoint " << i;
  }

  // The left arm's own joints in the request's robot state are set by every check: they do not
  // make the scene different, and what was learnt still holds.
  online::MotionRequest own_joints_elsewhere = request(a, b);
  cell.set_arm(own_joints_elsewhere.robot_q, cell.arm("left"), b);
  const auto reused = planner.plan(own_joints_elsewhere);
  ASSERT_TRUE(reused.solved());
  EXPECT_EQ(reused.edges_invalidated, 0);
  EXPECT_EQ(reused.searches, again.searches);

  // The right arm elsewhere: a different scene for the left arm's checks.
  online::MotionRequest moved = request(a, b);
  Eigen::VectorXd right_q = cell.arm("right").spec.home;
  right_q[0] += 0.3;
  cell.set_arm(moved.robot_q, cell.arm("right"), right_q);
  const auto relearned = planner.plan(moved);
  online::ArmMotionPlanner fresh(world, left_roadmap(), "left");
  const auto reference = fresh.plan(moved);
  ASSERT_EQ(relearned.status, reference.status);
  EXPECT_GT(reference.edges_invalidated, 0) << "the crate still cuts edges";
  EXPECT_EQ(relearned.edges_invalidated, reference.edges_invalidated);
  EXPECT_EQ(relearned.searches, reference.searches);
  ASSERT_EQ(relearned.path.size(), reference.path.size());
  for (std::size_t i = 0; i < relearned.path.size(); ++i) {
    EXPECT_TRUE(relearned.path[i].isApprox(reference.path[i], 0.0)) << "waypoint " << i;
  }
}

// The roadmap node a search enters by is valid but a crate blocks the straight join to it: the
// join, taken unchecked for the first search, fails when the path is checked and another holds.
TEST(ArmMotion, ABlockedJoinIntoTheRoadmapIsReplacedByOneThatHolds) {
  const auto& cell = *test::reference_cell();
  const online::World nominal_world(cell, cabinet(), online::nominal_scene(cell, cabinet()), "top");
  online::MotionSettings settings;
  settings.shortcut_checks = 0;  // the path as searched: its second waypoint is the entry node
  online::ArmMotionPlanner nominal_planner(nominal_world, left_roadmap(), "left", settings);
  int tried = 0;
  for (const auto& [a, b] : far_pairs(20)) {
    // A start off the roadmap, a quarter of the way to the far node.
    const auto join = crate_on_the_join(nominal_planner, a, b, 0.25);
    if (!join) continue;
    const online::MotionRequest& r = join->request;
    const Eigen::VectorXd& start = r.start;
    const Eigen::VectorXd& entry = join->entry;
    const online::World world(cell, cabinet(), join->crated, "top");
    online::ArmMotionPlanner planner(world, left_roadmap(), "left", settings);
    planner.prepare(r);
    if (!planner.valid(start) || !planner.valid(b) || !planner.valid(entry) ||
        planner.segment_valid(start, entry)) {
      continue;
    }
    ++tried;
    const auto result = planner.plan(r);
    if (!result.solved()) continue;  // the crate may cut every way out: not this test's case
    ASSERT_GE(result.path.size(), 3u);
    EXPECT_FALSE(result.path[1].isApprox(entry, 0.0)) << "entered through the blocked join";
    const auto report = validate_in(world, result.path);
    EXPECT_TRUE(report.valid()) << online::to_string(result.via) << ": " << describe(report);
    return;
  }
  FAIL() << "no far pair with a blocked join that plans (" << tried << " tried)";
}

// The same blocked join, from a start half way between far nodes: the start is then joined
// with checked segments, and only the first MotionSettings::checked_attachments nodes that hold
// are kept (each costs a whole segment's checks). Keeping 2 instead of 6 spends fewer checks
// over the pairs; every path passes the validator.
TEST(ArmMotion, CheckedJoinsKeepOnlyTheFirstThatHold) {
  const auto& cell = *test::reference_cell();
  const online::World nominal_world(cell, cabinet(), online::nominal_scene(cell, cabinet()), "top");
  online::MotionSettings settings;
  ASSERT_EQ(settings.checked_attachments, 2);
  online::ArmMotionPlanner nominal_planner(nominal_world, left_roadmap(), "left", settings);
  int compared = 0;
  long checks_two = 0;
  long checks_six = 0;
  for (const auto& [a, b] : far_pairs(20)) {
    // A start half way between two far nodes: its joins to the roadmap are long.
    const auto join = crate_on_the_join(nominal_planner, a, b, 0.5);
    if (!join) continue;
    const online::MotionRequest& r = join->request;
    const Eigen::VectorXd& start = r.start;
    const online::World world(cell, cabinet(), join->crated, "top");
    online::MotionSettings six = settings;
    six.checked_attachments = 6;
    online::ArmMotionPlanner two_kept(world, left_roadmap(), "left", settings);
    online::ArmMotionPlanner six_kept(world, left_roadmap(), "left", six);
    two_kept.prepare(r);
    if (!two_kept.valid(start) || !two_kept.valid(b) || two_kept.segment_valid(start, b)) continue;
    const auto with_two = two_kept.plan(r);
    const auto with_six = six_kept.plan(r);
    if (!with_two.solved() || !with_six.solved()) continue;  // the crate may cut every way out
    ++compared;
    for (const auto* result : {&with_two, &with_six}) {
      const auto report = validate_in(world, result->path);
      EXPECT_TRUE(report.valid()) << online::to_string(result->via) << ": " << describe(report);
    }
    checks_two += two_kept.checks();
    checks_six += six_kept.checks();
  }
  EXPECT_GE(compared, 3) << "far pairs with a crate on the join that both plan";
  // A pair may take a few more checks with fewer entries (another search), most take fewer:
  // measured 1202 against 2310 over 5 pairs.
  EXPECT_LT(checks_two, checks_six);
}

// A start from which no straight segment reaches the roadmap, while a stored path still leads
// from it: the roadmap is entered where the stored path, re-validated, takes the arm. The
// roadmap here is the tail of a shortened roadmap path (greedy shortcuts: no waypoint past the
// next one is in straight reach), without its first two waypoints; the stored path goes halfway
// to the first node the start left for, then to it.
TEST(ArmMotion, AWedgedStartEntersTheRoadmapAlongAStoredPath) {
  const auto& cell = *test::reference_cell();
  const online::World world(cell, cabinet(), online::nominal_scene(cell, cabinet()), "top");
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  core::CollisionData data = world.make_data();
  for (const auto& [a, b] : far_pairs(20)) {
    const auto before = planner.plan(request(a, b));
    if (!before.solved() || before.path.size() < 4) continue;
    const auto& p = before.path;
    // A stored path that holds from the start but stops short of the goal: halfway to p[1], p[1].
    const std::vector<Eigen::VectorXd> stored{a + 0.5 * (p[1] - a), p[1]};
    bool wedged = true;  // nothing after p[1] in straight reach of a, b out of the stored path's
    for (std::size_t k = 2; k < p.size(); ++k) wedged = wedged && !planner.segment_valid(a, p[k]);
    wedged = wedged && !planner.segment_valid(stored[0], b) && !planner.segment_valid(p[1], b);
    if (!wedged) continue;

    const online::ArmRoadmap roadmap(chain_roadmap({p.begin() + 2, p.end()}));
    online::ArmMotionPlanner cut(world, roadmap, "left");
    online::MotionRequest r = request(a, b);
    r.allow_bridge = false;
    const auto alone = cut.plan(r);
    EXPECT_FALSE(alone.solved()) << "the start attaches to no node of the roadmap: "
                                 << online::to_string(alone.via);

    r.hints = {&stored};
    const auto led = cut.plan(r);
    ASSERT_TRUE(led.solved()) << led.reason;
    EXPECT_EQ(led.via, online::MotionVia::kStoredRoadmap);
    ASSERT_GE(led.path.size(), 3u);
    EXPECT_TRUE(led.path.front().isApprox(a, 0.0));
    // Through the stored path's end (its halfway point shortcut away).
    EXPECT_TRUE(led.path[1].isApprox(p[1], 0.0));
    EXPECT_TRUE(led.path.back().isApprox(b, 0.0));
    const auto report =
        online::validate_motion(world, data, timed(led.path, cabinet().part("top").initial));
    EXPECT_TRUE(report.valid()) << describe(report);

    // The same stored path given late (MotionRequest::late_hints): fetched once, when the
    // start is found wedged, and the same path; a motion whose ends attach never asks for it.
    online::MotionRequest late = request(a, b);
    late.allow_bridge = false;
    late.follow_hints = false;
    int asked = 0;
    late.late_hints = [&] {
      ++asked;
      return std::vector<const std::vector<Eigen::VectorXd>*>{&stored};
    };
    const auto led_late = cut.plan(late);
    ASSERT_TRUE(led_late.solved()) << led_late.reason;
    EXPECT_EQ(asked, 1);
    EXPECT_EQ(led_late.via, led.via);
    ASSERT_EQ(led_late.path.size(), led.path.size());
    for (std::size_t k = 0; k < led.path.size(); ++k) {
      EXPECT_TRUE(led_late.path[k].isApprox(led.path[k], 0.0)) << k;
    }
    online::MotionRequest attached = request(a, b);
    attached.follow_hints = false;
    attached.late_hints = late.late_hints;
    asked = 0;
    EXPECT_TRUE(planner.plan(attached).solved());
    EXPECT_EQ(asked, 0) << "both ends attach to the whole roadmap";
    return;
  }
  FAIL() << "no far node pair gave a roadmap path of four waypoints with a wedged start";
}

// Both ends attach, but the roadmap is cut between their nodes: the start joins only an
// isolated node, while a stored path leads from the start to where the rest of the roadmap is
// in straight reach. The search starts again along the stored path before any bridge. The
// roadmap is the tail of a shortened roadmap path (p[2] on) plus a node alone on the way from
// the start to p[1].
TEST(ArmMotion, ACutRoadmapIsEnteredAlongAStoredPathBeforeABridge) {
  const auto& cell = *test::reference_cell();
  const online::World world(cell, cabinet(), online::nominal_scene(cell, cabinet()), "top");
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  core::CollisionData data = world.make_data();
  for (const auto& [a, b] : far_pairs(20)) {
    const auto before = planner.plan(request(a, b));
    if (!before.solved() || before.path.size() < 4) continue;
    const auto& p = before.path;
    const Eigen::VectorXd alone = a + 0.3 * (p[1] - a);
    const std::vector<Eigen::VectorXd> stored{a + 0.5 * (p[1] - a), p[1]};
    // Nothing of the tail in straight reach of the start or of the lone node.
    bool cut = !planner.segment_valid(stored[0], b) && !planner.segment_valid(p[1], b);
    for (std::size_t k = 2; k < p.size(); ++k) {
      cut = cut && !planner.segment_valid(a, p[k]) && !planner.segment_valid(alone, p[k]);
    }
    if (!cut) continue;

    std::vector<Eigen::VectorXd> nodes(p.begin() + 2, p.end());
    nodes.push_back(alone);  // no edges
    const online::ArmRoadmap roadmap(chain_roadmap(nodes, 1));
    online::ArmMotionPlanner cut_planner(world, roadmap, "left");
    online::MotionRequest r = request(a, b);
    r.allow_bridge = false;
    r.follow_hints = false;  // the stored path only leads in, as for the way home
    const auto without = cut_planner.plan(r);
    ASSERT_FALSE(without.solved()) << online::to_string(without.via);
    EXPECT_NE(without.reason.find("does not connect"), std::string::npos) << without.reason;

    r.hints = {&stored};
    const auto led = cut_planner.plan(r);
    ASSERT_TRUE(led.solved()) << led.reason;
    EXPECT_EQ(led.via, online::MotionVia::kStoredRoadmap);
    EXPECT_TRUE(led.path.front().isApprox(a, 0.0));
    EXPECT_TRUE(led.path.back().isApprox(b, 0.0));
    EXPECT_NE(std::find_if(led.path.begin(), led.path.end(),
                           [&](const Eigen::VectorXd& q) { return q.isApprox(p[1], 0.0); }),
              led.path.end())
        << "through the stored path's end";
    const auto report =
        online::validate_motion(world, data, timed(led.path, cabinet().part("top").initial));
    EXPECT_TRUE(report.valid()) << describe(report);
    return;
  }
  FAIL() << "no far node pair gave a roadmap path of four waypoints cut from its start";
}

// A roadmap node inside a crate, on the shortest way from many entries: the first time the search
// meets it, all its edges are dropped, not one per search (the start, the goal, the blocked node
// halfway between them, five spokes beside the start each joined to it, and a longer detour of
// two nodes). Dropping only the edge a path used cost a search per spoke.
TEST(ArmMotion, ABlockedNodeIsDroppedWithAllItsEdgesAtOnce) {
  const auto& cell = *test::reference_cell();
  const core::Arm& left = cell.arm("left");
  const online::Scene nominal = online::nominal_scene(cell, cabinet());
  const Eigen::VectorXd s = left.spec.home;
  Eigen::VectorXd g = s;
  g[0] += 0.8;
  const Eigen::VectorXd x = 0.5 * (s + g);
  online::Scene crated = nominal;
  const core::Pose tcp = core::arm_base_in_world(cell, left) * left.chain.fk(x);
  crated.obstacles.push_back(crate_at(tcp.translation(), 0.12));  // wider than the open jaw
  const online::World world(cell, cabinet(), crated, "top");
  online::MotionSettings settings;
  settings.shortcut_checks = 0;  // the path as searched
  int tried = 0;
  for (int joint = 1; joint < 6; ++joint) {
    for (const double lift : {0.8, -0.8}) {
      Eigen::VectorXd d1 = s;
      Eigen::VectorXd d2 = g;
      d1[joint] += lift;
      d2[joint] += lift;
      std::vector<Eigen::VectorXd> nodes{s, g, x, d1, d2};
      std::vector<std::pair<int, int>> edges{{0, 2}, {2, 1}, {0, 3}, {3, 4}, {4, 1}};
      for (int spoke = 1; spoke < 6; ++spoke) {
        Eigen::VectorXd y = s;
        y[spoke] += 0.04;
        nodes.push_back(y);
        const int n = static_cast<int>(nodes.size()) - 1;
        edges.emplace_back(0, n);
        edges.emplace_back(n, 2);
      }
      const online::ArmRoadmap roadmap(roadmap_of(nodes, edges));
      online::ArmMotionPlanner planner(world, roadmap, "left", settings);
      online::MotionRequest r = request(s, g);
      r.allow_bridge = false;
      planner.prepare(r);
      bool premises = !planner.valid(x) && planner.segment_valid(s, d1) &&
                      planner.segment_valid(d1, d2) && planner.segment_valid(d2, g);
      for (std::size_t k = 3; k < nodes.size(); ++k) premises = premises && planner.valid(nodes[k]);
      if (!premises) continue;
      ++tried;
      const auto result = planner.plan(r);
      ASSERT_TRUE(result.solved()) << result.reason;
      for (const auto& q : result.path) EXPECT_FALSE(q.isApprox(x, 0.0)) << "through the crate";
      EXPECT_LE(result.searches, 2) << "the blocked node's edges were dropped one search at a time";
      EXPECT_EQ(result.edges_invalidated, 7) << "every edge of the blocked node, each once";
      const auto report = validate_in(world, result.path);
      EXPECT_TRUE(report.valid()) << online::to_string(result.via) << ": " << describe(report);
      return;
    }
  }
  FAIL() << "no detour around the crated node holds (" << tried << " tried)";
}

// Two short chains of nodes, one around the start and one around the goal, joined by one edge
// that the grasp's filter leaves out; a crate blocks the straight motion. The first plan
// searches (A* expands the start's chain) and fails; asked again under the same context and
// filter, it fails the same way without A* expanding a node: the filtered roadmap's components
// are known, and no entry shares one with an exit. A fresh planner expands as the first did;
// with every edge allowed the same planner searches anew (each filter has its own components).
TEST(ArmMotion, EndsTheFilteredRoadmapDoesNotJoinAreNotSearchedAgain) {
  const auto& cell = *test::reference_cell();
  const core::Arm& left = cell.arm("left");
  const Eigen::VectorXd s = left.spec.home;
  Eigen::VectorXd g = s;
  g[0] += 0.8;
  online::Scene crated = online::nominal_scene(cell, cabinet());
  const core::Pose tcp = core::arm_base_in_world(cell, left) * left.chain.fk(0.5 * (s + g));
  crated.obstacles.push_back(crate_at(tcp.translation(), 0.12));
  const online::World world(cell, cabinet(), crated, "top");
  online::MotionSettings settings;
  settings.repair_checks = 0;
  for (int joint = 1; joint < 6; ++joint) {
    std::vector<Eigen::VectorXd> nodes;
    std::vector<std::pair<int, int>> edges;
    for (const Eigen::VectorXd& end : {s, g}) {
      const int first = static_cast<int>(nodes.size());
      for (int k = 0; k < 7; ++k) {  // more than an end attaches to: all in its own chain
        Eigen::VectorXd q = end;
        q[joint] += 0.04 * k;
        nodes.push_back(q);
        if (k > 0) edges.emplace_back(first + k - 1, first + k);
      }
    }
    edges.emplace_back(6, 13);  // the chains' far ends: the only way across
    std::vector<bool> cut(edges.size(), true);
    cut.back() = false;
    const online::ArmRoadmap roadmap(roadmap_of(nodes, edges));
    online::ArmMotionPlanner planner(world, roadmap, "left", settings);
    online::MotionRequest r = request(s, g);
    r.filter = &cut;
    r.allow_bridge = false;
    planner.prepare(r);
    bool premises = !planner.segment_valid(s, g);
    for (std::size_t k = 1; k < nodes.size(); ++k) {
      premises = premises && planner.valid(nodes[k]) &&
                 (k == 7 || planner.segment_valid(nodes[k - 1], nodes[k]));
    }
    if (!premises) continue;
    const auto once = planner.plan(r);
    ASSERT_FALSE(once.solved()) << online::to_string(once.via);
    ASSERT_GT(once.nodes_expanded, 0);
    const auto again = planner.plan(r);
    EXPECT_EQ(again.status, once.status);
    EXPECT_EQ(again.reason, once.reason);
    EXPECT_EQ(again.searches, once.searches);
    EXPECT_EQ(again.nodes_expanded, 0) << "searched again though its ends are apart";
    online::ArmMotionPlanner fresh(world, roadmap, "left", settings);
    const auto anew = fresh.plan(r);
    EXPECT_EQ(anew.reason, once.reason);
    EXPECT_EQ(anew.nodes_expanded, once.nodes_expanded);
    online::MotionRequest every_edge = r;
    every_edge.filter = nullptr;
    EXPECT_GT(planner.plan(every_edge).nodes_expanded, 0);
    return;
  }
  FAIL() << "no joint gives two valid chains around a blocked straight motion";
}

// A segment found blocked is not sampled again for the same request (the straight motion is
// asked again as the first shortcut of the path found): the same verdict without a check, until
// the next prepare(); the other direction is its own segment.
TEST(ArmMotion, ABlockedSegmentIsCheckedOncePerRequest) {
  const auto crated = crate_on_a_roadmap_path();
  ASSERT_TRUE(crated.has_value()) << "a roadmap path with interior nodes";
  const auto& [a, b, before, blocked] = *crated;
  const auto& cell = *test::reference_cell();
  const online::World world(cell, cabinet(), blocked, "top");
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  planner.prepare(request(a, b));
  const long at_start = planner.checks();
  ASSERT_FALSE(planner.segment_valid(a, b)) << "the crate blocks the straight motion";
  const long first = planner.checks() - at_start;
  EXPECT_GT(first, 0);
  EXPECT_FALSE(planner.segment_valid(a, b));
  EXPECT_EQ(planner.checks() - at_start, first) << "sampled again";
  planner.prepare(request(a, b));
  const long again = planner.checks();
  EXPECT_FALSE(planner.segment_valid(a, b));
  EXPECT_EQ(planner.checks() - again, first) << "the same samples after prepare()";
  // A fresh planner agrees on both directions.
  online::ArmMotionPlanner fresh(world, left_roadmap(), "left");
  fresh.prepare(request(a, b));
  EXPECT_EQ(planner.segment_valid(b, a), fresh.segment_valid(b, a));
}

// A segment no longer than the resolution has no sample between its ends: segment_valid()
// passes it whatever its end is, step_valid() (what the smoother checks its new points with)
// does not. The end here is past the base joint's limit.
TEST(ArmMotion, AStepOntoAnUncheckedConfigurationChecksIt) {
  const auto& cell = *test::reference_cell();
  const core::Arm& left = cell.arm("left");
  const online::World world(cell, cabinet(), online::nominal_scene(cell, cabinet()), "top");
  online::ArmMotionPlanner planner(world, left_roadmap(), "left");
  const double upper = left.chain.upper_limits()[0];
  Eigen::VectorXd a = left.spec.home;
  a[0] = upper - 0.01;
  Eigen::VectorXd past = a;
  past[0] = upper + 0.02;  // 0.03 rad on: shorter than the roadmap's 0.05
  Eigen::VectorXd back = a;
  back[0] -= 0.04;
  planner.prepare(request(a, past));
  ASSERT_TRUE(planner.valid(a));
  ASSERT_FALSE(planner.valid(past));
  EXPECT_TRUE(planner.segment_valid(a, past)) << "no sample between the ends";
  EXPECT_FALSE(planner.step_valid(a, past));
  ASSERT_TRUE(planner.valid(back));
  EXPECT_TRUE(planner.step_valid(a, back));
}

// A bridge that failed within its budget is not run again for the same ends under the same
// checks (another goal with the same configuration asks the same): the same failure, without
// its checks. A larger budget runs it again.
TEST_F(ArmMotionCrated, AFailedBridgeIsNotRunAgainForTheSameEnds) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  online::MotionRequest r = request(a, b);
  online::MotionSettings settings;
  settings.attach_neighbours = 0;  // both ends wedged: straight to the bridge
  settings.wedged_repair_checks = 0;
  settings.bridge_checks = 30;  // too few to get around the crate
  settings.wedged_focus = 0.0;  // uniform samples: drawn around the wedged end, 30 get round
  online::ArmMotionPlanner planner(world, left_roadmap(), "left", settings);
  planner.prepare(r);
  ASSERT_FALSE(planner.segment_valid(a, b)) << "the crate must block the straight motion";

  const long before_first = planner.checks();
  const auto first = planner.plan(r);
  const long first_checks = planner.checks() - before_first;
  ASSERT_FALSE(first.solved()) << "a 30-check bridge should not get around the crate";
  const auto second = planner.plan(r);
  const long second_checks = planner.checks() - before_first - first_checks;
  EXPECT_EQ(second.status, first.status);
  EXPECT_EQ(second.reason, first.reason);
  EXPECT_LT(second_checks, first_checks - 25) << "the bridge's checks were spent again";

  // A fresh planner fails the same way, spending the bridge.
  online::ArmMotionPlanner fresh(world, left_roadmap(), "left", settings);
  const auto again = fresh.plan(r);
  EXPECT_EQ(again.reason, first.reason);
  EXPECT_EQ(fresh.checks(), first_checks);

  // Another budget is another bridge.
  planner.set_bridge_checks(60);
  const long before_larger = planner.checks();
  planner.plan(r);
  EXPECT_GE(planner.checks() - before_larger, first_checks);
}

// Both ends wedged (attached to no node): the whole-motion bridge draws most of its samples
// around the end it leaves from (MotionSettings::wedged_focus) and gets at most
// wedged_bridge_checks in the first round, whatever bridge_checks allows; the larger bridges'
// round lifts the cap (set_wedged_bridge_checks). The path it finds passes the independent
// validator. (That the focus gets a wedged end out where uniform samples do not is
// test_bridge's FocusAroundAWedgedEndGetsOutOfIt: this crate wedges nothing directionally.)
TEST_F(ArmMotionCrated, AWedgedEndsBridgeIsFocusedAndCappedInTheFirstRound) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  online::MotionSettings settings;
  settings.attach_neighbours = 0;  // both ends wedged: straight to the bridge
  settings.wedged_repair_checks = 0;
  settings.bridge_checks = 10000;
  settings.wedged_bridge_checks = 400;  // measured: 1244 needed here
  ASSERT_GT(settings.wedged_focus, 0.0);
  online::ArmMotionPlanner planner(world, left_roadmap(), "left", settings);
  const long at_capped = planner.checks();
  const auto capped = planner.plan(request(a, b));
  ASSERT_FALSE(capped.solved()) << "400 checks got round the crate";
  EXPECT_TRUE(capped.wedged);
  EXPECT_LT(planner.checks() - at_capped, 1000) << "the bridge ran with bridge_checks";

  planner.set_wedged_bridge_checks(settings.bridge_checks);
  const auto lifted = planner.plan(request(a, b));
  ASSERT_TRUE(lifted.solved()) << lifted.reason;
  EXPECT_EQ(lifted.via, online::MotionVia::kBridge);
  EXPECT_TRUE(lifted.path.front().isApprox(a, 0.0));
  EXPECT_TRUE(lifted.path.back().isApprox(b, 0.0));
  const auto report = validate_in(world, lifted.path);
  EXPECT_TRUE(report.valid()) << describe(report);
}

// A wedged motion's repair of a stored path that fails within its budget fails again for the
// same ends, path, budget and context: not run again, even after the planner served another
// context in between (the larger bridges' round comes back to the first round's contexts).
TEST_F(ArmMotionCrated, AFailedRepairIsNotRunAgainUnderTheSameContext) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  const std::vector<Eigen::VectorXd>& stored = before.path;
  online::MotionRequest r = request(a, b);
  r.hints = {&stored};
  online::MotionSettings settings;
  settings.attach_neighbours = 0;      // both ends wedged: the repair, then the bridge
  settings.wedged_repair_checks = 40;  // too few to get around the crate
  settings.bridge_checks = 30;
  settings.wedged_focus = 0.0;  // uniform samples: what the budgets above are too few for
  settings.repair_focus = 0.0;
  online::ArmMotionPlanner planner(world, left_roadmap(), "left", settings);
  planner.prepare(r);
  ASSERT_FALSE(planner.valid(stored[stored.size() / 2])) << "the crate must block the stored path";

  const long at_first = planner.checks();
  const auto first = planner.plan(r);
  const long first_checks = planner.checks() - at_first;
  ASSERT_FALSE(first.solved()) << "40 checks should not repair around the crate";
  ASSERT_TRUE(first.wedged);

  // Another context in between: the board standing elsewhere.
  online::MotionRequest other = r;
  other.board_world.translation().x() += 0.3;
  planner.plan(other);

  const long at_second = planner.checks();
  const auto second = planner.plan(r);
  const long second_checks = planner.checks() - at_second;
  EXPECT_EQ(second.status, first.status);
  EXPECT_EQ(second.reason, first.reason);
  // Neither the repair (two bridges of 40 checks, and the stored path walked to each) nor the
  // whole-motion bridge (30) runs again: what is left is the ends and the straight motion.
  // Measured 465 then 198; with the repair run again, 375; with the bridge run again, 288.
  EXPECT_LT(second_checks, first_checks - 250) << first_checks << " then " << second_checks;

  // A fresh planner spends them all again, and fails the same way.
  online::ArmMotionPlanner fresh(world, left_roadmap(), "left", settings);
  const auto again = fresh.plan(r);
  EXPECT_EQ(again.reason, first.reason);
  EXPECT_EQ(fresh.checks(), first_checks);
}

// A wedged motion with two stored paths: the first blocked by the crate (its repair needs
// hundreds of checks), the second a way round the crate with one waypoint planted in it (a
// repair of a few checks). With a cheap first pass (wedged_first_repair_checks) each stored
// path is tried cheaply before either at full budget: the second is taken, for fewer checks;
// with the full budget only, the first is repaired at length. Both pass the validator.
TEST_F(ArmMotionCrated, AWedgedMotionTriesEveryStoredPathCheaplyFirst) {
  const auto& [a, b, before, blocked] = crated();
  const online::World& world = crated_world();
  const std::vector<Eigen::VectorXd>& crated_path = before.path;
  online::MotionSettings settings;
  settings.attach_neighbours = 0;  // both ends wedged: the repairs, then the bridge
  settings.wedged_repair_checks = 20000;
  settings.wedged_first_repair_checks = 0;

  // A way round the crate (a bridge's), with the crated path's blocked middle planted in it.
  online::ArmMotionPlanner finder(world, left_roadmap(), "left", settings);
  const auto round = finder.plan(request(a, b));
  ASSERT_TRUE(round.solved()) << round.reason;
  ASSERT_GE(round.path.size(), 3u);
  const Eigen::VectorXd& planted = crated_path[crated_path.size() / 2];
  finder.prepare(request(a, b));
  ASSERT_FALSE(finder.valid(planted)) << "the crate must block the crated path's middle";
  std::vector<Eigen::VectorXd> around = round.path;
  around.insert(around.begin() + 2, planted);

  online::MotionRequest r = request(a, b);
  r.hints = {&crated_path, &around};
  online::ArmMotionPlanner full_only(world, left_roadmap(), "left", settings);
  const auto at_full = full_only.plan(r);
  settings.wedged_first_repair_checks = 100;
  online::ArmMotionPlanner cheap_first(world, left_roadmap(), "left", settings);
  const auto at_cheap = cheap_first.plan(r);

  for (const auto* result : {&at_full, &at_cheap}) {
    ASSERT_TRUE(result->solved()) << result->reason;
    EXPECT_EQ(result->via, online::MotionVia::kStoredRepair);
    EXPECT_TRUE(result->wedged);
    EXPECT_TRUE(result->path.front().isApprox(a, 0.0));
    EXPECT_TRUE(result->path.back().isApprox(b, 0.0));
    const auto report = validate_in(world, result->path);
    EXPECT_TRUE(report.valid()) << describe(report);
  }
  const auto passes_through = [](const std::vector<Eigen::VectorXd>& path,
                                 const Eigen::VectorXd& q) {
    return std::any_of(path.begin(), path.end(),
                       [&](const Eigen::VectorXd& p) { return p.isApprox(q, 0.0); });
  };
  // The full budget repairs the crated path (its first interior waypoint kept); the cheap pass
  // takes the way round (its waypoint before the planted one kept).
  EXPECT_TRUE(passes_through(at_full.path, crated_path[1]));
  EXPECT_FALSE(passes_through(at_full.path, around[1]));
  EXPECT_TRUE(passes_through(at_cheap.path, around[1]));
  EXPECT_FALSE(passes_through(at_cheap.path, crated_path[1]));
  EXPECT_LT(cheap_first.checks(), full_only.checks())
      << cheap_first.checks() << " against " << full_only.checks();
}
