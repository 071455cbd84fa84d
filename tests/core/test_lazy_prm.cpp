#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <vector>

#include "hila/core/lazy_prm.hpp"
#include "util/joint_wall.hpp"

using namespace hila;

namespace {

// The bridge tests' wall with a wider gap: a roadmap of uniform samples (no tree bias towards
// the goal) finds a 0.6 rad gap in 6 joints only with many thousands of vertices.
test::Scenario lazy_scenario() {
  test::Scenario s = test::wall_scenario();
  s.wall.half_gap = 1.0;
  return s;
}

std::chrono::steady_clock::time_point far_future() {
  return std::chrono::steady_clock::now() + std::chrono::hours(1);
}

}  // namespace

// The baseline around the wall: ends kept, every state valid when re-sampled 5x denser.
TEST(LazyPrm, DetourAroundWallIsValid) {
  const core::Arm& arm = test::left_arm();
  const test::Scenario s = lazy_scenario();
  const test::Validity valid = test::validity_of(s.wall);
  core::LazyPrmPlanner planner(arm);
  const auto path = planner.plan(valid, s.from, s.to, 200000, far_future());
  ASSERT_GE(path.size(), 3u) << "the straight line is blocked, so a detour needs a waypoint";
  EXPECT_EQ(path.front(), s.from);
  EXPECT_EQ(path.back(), s.to);
  for (const auto& q : path) EXPECT_TRUE(test::within_limits(arm, q)) << q.transpose();
  test::expect_path_valid(path, valid, core::LazyPrmSettings{}.resolution);
}

// Persistent: the roadmap grown for one query is kept for the next, while validity is not (the
// second query's wall is elsewhere and its path must respect it, not the first one's).
TEST(LazyPrm, RoadmapPersistsButValidityIsPerQuery) {
  const core::Arm& arm = test::left_arm();
  const test::Scenario s = lazy_scenario();
  core::LazyPrmPlanner planner(arm);
  ASSERT_FALSE(planner.plan(test::validity_of(s.wall), s.from, s.to, 200000, far_future()).empty());
  const std::size_t grown = planner.roadmap_vertices();
  EXPECT_GT(grown, 2u);

  test::Scenario moved = s;
  moved.wall.gap_q1 = arm.spec.home[1] - 1.5;  // the gap on the other side
  const test::Validity valid = test::validity_of(moved.wall);
  const auto path = planner.plan(valid, moved.from, moved.to, 200000, far_future());
  ASSERT_GE(path.size(), 3u);
  test::expect_path_valid(path, valid, core::LazyPrmSettings{}.resolution);
  EXPECT_GE(planner.roadmap_vertices(), grown);
}

TEST(LazyPrm, SameSeedSamePath) {
  const core::Arm& arm = test::left_arm();
  const test::Scenario s = lazy_scenario();
  const test::Validity valid = test::validity_of(s.wall);
  core::LazyPrmPlanner a(arm), b(arm);
  EXPECT_EQ(a.plan(valid, s.from, s.to, 200000, far_future()),
            b.plan(valid, s.from, s.to, 200000, far_future()));
}

TEST(LazyPrm, InvalidEndsAndExhaustedBudgetGiveNothing) {
  const core::Arm& arm = test::left_arm();
  const test::Scenario s = lazy_scenario();
  const test::Validity valid = test::validity_of(s.wall);
  core::LazyPrmPlanner planner(arm);
  Eigen::VectorXd in_wall = s.from;
  in_wall[0] = s.wall.wall_q0;
  EXPECT_TRUE(planner.plan(valid, in_wall, s.to, 200000, far_future()).empty());
  EXPECT_TRUE(planner.plan(valid, s.from, s.to, 10, far_future()).empty());
  EXPECT_TRUE(planner.plan(valid, s.from, s.to, 200000, std::chrono::steady_clock::now()).empty());
  // Straight when the straight motion is clear.
  const test::Validity free = [](const Eigen::VectorXd&) { return true; };
  EXPECT_EQ(planner.plan(free, s.from, s.to, 10, far_future()).size(), 2u);
}

// The check budget holds inside LazyPRM's own search-check-remove loop too (OMPL tests the
// termination condition only between growth steps): with a wall to find a way around, a query
// calls the validity at most the budget plus its own pre-checks of the ends and the straight
// segment, and the planner answers the next query as before.
TEST(LazyPrm, TheCheckBudgetHoldsInsideTheLazySearch) {
  const core::Arm& arm = test::left_arm();
  const test::Scenario s = lazy_scenario();
  const test::Validity wall = test::validity_of(s.wall);
  core::LazyPrmPlanner planner(arm);
  for (const long budget : {5L, 10L, 20L}) {
    long calls = 0;
    const test::Validity counted = [&](const Eigen::VectorXd& q) {
      ++calls;
      return wall(q);
    };
    planner.plan(counted, s.from, s.to, budget, far_future());
    const long pre_checks = 2 + static_cast<long>(std::ceil((s.to - s.from).norm() / 0.05));
    EXPECT_LE(calls, budget + pre_checks) << "budget " << budget;
  }
  const auto path = planner.plan(wall, s.from, s.to, 200000, far_future());
  ASSERT_FALSE(path.empty());
  test::expect_path_valid(path, wall, 0.05);
}
