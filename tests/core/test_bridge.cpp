#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "hila/core/bridge.hpp"
#include "hila/core/joint_box.hpp"
#include "util/joint_wall.hpp"
#include "util/test_util.hpp"

using namespace hila;
using test::expect_path_valid;
using test::left_arm;
using test::Scenario;
using test::Validity;
using test::validity_of;
using test::wall_scenario;
using test::within_limits;

namespace {

// Dense brute force of segment_valid's contract: interior states only.
bool dense_segment_valid(const Validity& valid, const Eigen::VectorXd& a,
                         const Eigen::VectorXd& b) {
  const int steps = std::max(2, static_cast<int>(std::ceil((b - a).norm() / 1e-4)));
  for (int k = 1; k < steps; ++k) {
    if (!valid(a + (b - a) * (static_cast<double>(k) / steps))) return false;
  }
  return true;
}

}  // namespace

TEST(Bridge, ScenarioIsWellPosed) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  ASSERT_EQ(arm.chain.dof(), s.from.size());
  EXPECT_TRUE(within_limits(arm, s.from));
  EXPECT_TRUE(within_limits(arm, s.to));
  Eigen::VectorXd gap = s.from;
  gap[0] = s.wall.wall_q0;
  gap[1] = s.wall.gap_q1;
  EXPECT_TRUE(within_limits(arm, gap));
  const Validity valid = validity_of(s.wall);
  EXPECT_TRUE(valid(s.from));
  EXPECT_TRUE(valid(s.to));
  EXPECT_TRUE(valid(gap));
  EXPECT_FALSE(valid((s.from + s.to) / 2.0));
  EXPECT_FALSE(core::segment_valid(valid, s.from, s.to, 0.05));
}

TEST(Bridge, DetourAroundWallIsValid) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  const Validity valid = validity_of(s.wall);
  for (std::uint64_t seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    core::BridgeSettings settings;
    settings.seed = seed;
    const auto path = core::plan_bridge(arm, valid, s.from, s.to, settings);
    ASSERT_GE(path.size(), 3u) << "the straight line is blocked, so a detour needs a waypoint";
    EXPECT_EQ(path.front(), s.from);
    EXPECT_EQ(path.back(), s.to);
    for (const auto& q : path) {
      EXPECT_TRUE(within_limits(arm, q)) << q.transpose();
    }
    // Valid when re-sampled 5x denser: the detour really passes through the gap.
    expect_path_valid(path, valid, settings.resolution);
  }
}

TEST(Bridge, DetourHoldsAtFinerResolution) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  const Validity valid = validity_of(s.wall);
  core::BridgeSettings settings;
  settings.resolution = 0.01;
  settings.seed = 9;
  const auto path = core::plan_bridge(arm, valid, s.from, s.to, settings);
  ASSERT_GE(path.size(), 3u);
  EXPECT_EQ(path.front(), s.from);
  EXPECT_EQ(path.back(), s.to);
  expect_path_valid(path, valid, settings.resolution);
}

TEST(Bridge, SameSeedGivesIdenticalPath) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  const Validity valid = validity_of(s.wall);
  core::BridgeSettings settings;
  settings.seed = 42;
  const auto first = core::plan_bridge(arm, valid, s.from, s.to, settings);
  // Another plan with a different seed in between must not disturb the next one.
  core::BridgeSettings other = settings;
  other.seed = 43;
  const auto between = core::plan_bridge(arm, valid, s.from, s.to, other);
  EXPECT_FALSE(between.empty());
  const auto second = core::plan_bridge(arm, valid, s.from, s.to, settings);
  ASSERT_FALSE(first.empty());
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    ASSERT_EQ(first[i].size(), second[i].size());
    for (Eigen::Index j = 0; j < first[i].size(); ++j) {
      // Bitwise: not merely close.
      EXPECT_EQ(std::memcmp(&first[i][j], &second[i][j], sizeof(double)), 0)
          << "waypoint " << i << " joint " << j << ": " << first[i][j] << " vs " << second[i][j];
    }
  }
}

TEST(Bridge, StraightLineValidReturnsJustTheEnds) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  const Validity valid = validity_of(s.wall);
  // Both on the near side of the wall, moving along joints the wall does not constrain.
  Eigen::VectorXd from = s.from, to = s.from;
  to[1] += 0.4;
  to[2] -= 0.3;
  to[5] += 0.7;
  ASSERT_TRUE(core::segment_valid(valid, from, to, 0.05));
  const auto path = core::plan_bridge(arm, valid, from, to, {});
  ASSERT_EQ(path.size(), 2u);
  EXPECT_EQ(path[0], from);
  EXPECT_EQ(path[1], to);
  // Also when the segment passes straight through the gap.
  from[1] = to[1] = s.wall.gap_q1;
  to = from;
  to[0] += 1.0;
  ASSERT_TRUE(valid(from) && valid(to));
  const auto through = core::plan_bridge(arm, valid, from, to, {});
  ASSERT_EQ(through.size(), 2u);
  EXPECT_EQ(through[0], from);
  EXPECT_EQ(through[1], to);
}

TEST(Bridge, InvalidEndsReturnNothing) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  long calls = 0;
  const Validity valid = [&](const Eigen::VectorXd& q) {
    ++calls;
    return !s.wall.blocked(q);
  };
  Eigen::VectorXd inside = s.from;
  inside[0] = s.wall.wall_q0;
  ASSERT_FALSE(valid(inside));
  calls = 0;
  EXPECT_TRUE(core::plan_bridge(arm, valid, s.from, inside, {}).empty());
  EXPECT_TRUE(core::plan_bridge(arm, valid, inside, s.to, {}).empty());
  // Rejected up front, not after spending the budget.
  EXPECT_LE(calls, 4);
}

TEST(Bridge, EnclosedGoalReturnsNothingWithinBudget) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  // `to` is valid but sealed in a shell (0.15 < |q - to| < 0.4) far thicker than the resolution.
  const Eigen::VectorXd goal = s.to;
  long calls = 0;
  const Validity valid = [&](const Eigen::VectorXd& q) {
    ++calls;
    const double r = (q - goal).norm();
    return !(r > 0.15 && r < 0.4);
  };
  core::BridgeSettings settings;
  settings.max_checks = 5000;
  settings.seed = 5;
  const auto path = core::plan_bridge(arm, valid, s.from, goal, settings);
  EXPECT_TRUE(path.empty());
  // The budget was spent (the planner did not give up early) and respected, give or take one
  // motion's worth of checks.
  EXPECT_GE(calls, settings.max_checks);
  EXPECT_LE(calls, settings.max_checks + 2000);
}

// Several ends: invalid ones are skipped, and the path ends exactly at a valid one, valid all
// the way at the resolution. One in straight reach is joined directly.
TEST(Bridge, ToAnyEndsAtOneOfTheValidTargets) {
  const core::Arm& arm = left_arm();
  const Scenario s = wall_scenario();
  const Validity valid = validity_of(s.wall);
  Eigen::VectorXd inside = s.from;
  inside[0] = s.wall.wall_q0;
  ASSERT_FALSE(valid(inside));
  Eigen::VectorXd beyond = s.to;
  beyond[5] += 0.5;
  ASSERT_TRUE(valid(beyond));
  ASSERT_FALSE(core::segment_valid(valid, s.from, beyond, 0.05));
  const std::vector<Eigen::VectorXd> targets{inside, s.to, beyond};
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    core::BridgeSettings settings;
    settings.seed = seed;
    const auto path = core::plan_bridge_to_any(arm, valid, s.from, targets, settings);
    ASSERT_GE(path.size(), 3u);
    EXPECT_EQ(path.front(), s.from);
    EXPECT_TRUE(path.back() == s.to || path.back() == beyond) << path.back().transpose();
    // The contract: valid at the resolution (a segment may clip the gap's corner between
    // samples, as any resolution-checked path may).
    expect_path_valid(path, valid, 5.0 * settings.resolution);
  }
  // Only the wall's side the start is on in straight reach: joined directly.
  Eigen::VectorXd near = s.from;
  near[5] += 0.3;
  ASSERT_TRUE(core::segment_valid(valid, s.from, near, 0.05));
  const auto direct = core::plan_bridge_to_any(arm, valid, s.from, {inside, s.to, near}, {});
  ASSERT_EQ(direct.size(), 2u);
  EXPECT_EQ(direct.back(), near);
  // No valid target: nothing, at once.
  long calls = 0;
  const Validity counting = [&](const Eigen::VectorXd& q) {
    ++calls;
    return valid(q);
  };
  EXPECT_TRUE(core::plan_bridge_to_any(arm, counting, s.from, {inside}, {}).empty());
  EXPECT_LE(calls, 2);
}

// An end wedged as the scene wedges a held board: free right around it, but every straight step
// of the bridge's range toward the joint box's middle blocked (a shell around the end, open
// only in a cone facing the box's edge). Toward uniform samples its tree cannot leave its root,
// and the other tree must find the cone's mouth by chance; with part of the samples drawn
// around the end, its tree grows out through the cone. Same seeds and budget for both.
TEST(Bridge, FocusAroundAWedgedEndGetsOutOfIt) {
  const core::Arm& arm = left_arm();
  const core::JointBox box = core::joint_box(arm, core::BridgeSettings{}.joint_range);
  const Eigen::VectorXd middle = (box.lower + box.upper) / 2.0;
  Eigen::VectorXd goal = middle;
  goal[0] = box.upper[0] - 0.5;
  Eigen::VectorXd start = middle;
  start[0] -= 1.5;
  const Eigen::VectorXd outward = Eigen::VectorXd::Unit(goal.size(), 0);
  long calls = 0;
  const Validity valid = [&](const Eigen::VectorXd& q) {
    ++calls;
    const Eigen::VectorXd d = q - goal;
    const double r = d.norm();
    return !(r > 0.12 && r < 0.8 && d.dot(outward) < 0.3 * r);
  };
  ASSERT_TRUE(valid(start) && valid(goal));
  ASSERT_TRUE(within_limits(arm, start) && within_limits(arm, goal));
  int uniform_found = 0;
  int focused_found = 0;
  long uniform_calls = 0;
  long focused_calls = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    core::BridgeSettings settings;
    settings.seed = seed;
    settings.max_checks = 3000;
    calls = 0;
    const auto uniform = core::plan_bridge(arm, valid, start, goal, settings);
    uniform_calls += calls;
    uniform_found += uniform.empty() ? 0 : 1;
    settings.focus = {goal};
    settings.focus_fraction = 0.6;
    calls = 0;
    const auto focused = core::plan_bridge(arm, valid, start, goal, settings);
    focused_calls += calls;
    if (focused.empty()) continue;
    ++focused_found;
    // Drawn from the seeded generator too: the same seed, the same path.
    EXPECT_EQ(core::plan_bridge(arm, valid, start, goal, settings), focused);
    EXPECT_EQ(focused.front(), start);
    EXPECT_EQ(focused.back(), goal);
    for (const auto& q : focused) EXPECT_TRUE(within_limits(arm, q)) << q.transpose();
    expect_path_valid(focused, valid, settings.resolution);
  }
  // Measured: 0 of 10 uniform, 10 of 10 focused, with under a quarter of the checks.
  EXPECT_GE(focused_found, 8);
  EXPECT_GT(focused_found, uniform_found + 3);
  EXPECT_LT(focused_calls, uniform_calls);
}

TEST(Bridge, SegmentValidMatchesDenseCheck) {
  const Scenario s = wall_scenario();
  const Validity valid = validity_of(s.wall);
  const double resolution = 0.05;
  struct Case {
    Eigen::VectorXd a, b;
    bool expected;
  };
  std::vector<Case> cases;
  // Straight across the wall: blocked.
  cases.push_back({s.from, s.to, false});
  // Across the wall through the gap: clear.
  {
    Eigen::VectorXd a = s.from, b = s.to;
    a[1] = b[1] = s.wall.gap_q1;
    cases.push_back({a, b, true});
  }
  // Along the near side, never reaching the wall: clear.
  {
    Eigen::VectorXd b = s.from;
    b[1] += 2.0;
    b[3] -= 1.0;
    cases.push_back({s.from, b, true});
  }
  // Diagonally across the wall, reaching the gap only half-way through: blocked.
  {
    Eigen::VectorXd a = s.from, b = s.to;
    a[1] = s.wall.gap_q1 - 1.5;
    b[1] = s.wall.gap_q1 + 0.5;
    b[4] += 0.5;
    cases.push_back({a, b, false});
  }
  // Starting inside the gap and leaving it sideways inside the wall: blocked.
  {
    Eigen::VectorXd a = s.from;
    a[0] = s.wall.wall_q0;
    a[1] = s.wall.gap_q1;
    Eigen::VectorXd b = a;
    b[1] += 1.0;
    b[0] += 0.3;
    cases.push_back({a, b, false});
  }
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const auto& c = cases[i];
    EXPECT_EQ(dense_segment_valid(valid, c.a, c.b), c.expected) << "case " << i;
    EXPECT_EQ(core::segment_valid(valid, c.a, c.b, resolution), c.expected) << "case " << i;
  }

  // Random segments against a ball obstacle, built around their closest approach to the centre:
  // either well inside the ball (a chord far longer than the resolution) or outside it, with
  // both ends outside.
  const Eigen::VectorXd centre = s.from;
  const double radius = 0.5;
  const Validity ball = [&](const Eigen::VectorXd& q) { return (q - centre).norm() >= radius; };
  std::mt19937_64 rng(8);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto dim = centre.size();
  for (int trial = 0; trial < 60; ++trial) {
    Eigen::VectorXd u(dim), v(dim);
    for (Eigen::Index j = 0; j < dim; ++j) {
      u[j] = normal(rng);
      v[j] = normal(rng);
    }
    u.normalize();
    v = (v - v.dot(u) * u).normalized();
    const bool through = trial % 2 == 0;
    const double approach = through ? 0.3 * unit(rng) : radius + 1e-6 + 0.5 * unit(rng);
    const Eigen::VectorXd closest = centre + approach * v;
    const Eigen::VectorXd a = closest - (0.6 + 0.9 * unit(rng)) * u;
    const Eigen::VectorXd b = closest + (0.6 + 0.9 * unit(rng)) * u;
    ASSERT_TRUE(ball(a) && ball(b));
    EXPECT_EQ(dense_segment_valid(ball, a, b), !through) << "trial " << trial;
    EXPECT_EQ(core::segment_valid(ball, a, b, resolution), !through) << "trial " << trial;
  }
}

TEST(Bridge, SegmentValidChecksInteriorOnly) {
  Eigen::VectorXd a(2), b(2);
  a << 0.0, 0.0;
  b << 1.0, 0.0;
  // Only the two ends are invalid: the documented contract is that they are assumed checked.
  const Validity ends_invalid = [&](const Eigen::VectorXd& q) { return q != a && q != b; };
  EXPECT_TRUE(core::segment_valid(ends_invalid, a, b, 0.05));
  // A single invalid interior state on the sampling grid is caught.
  Eigen::VectorXd mid(2);
  mid << 0.5, 0.0;
  const Validity mid_invalid = [&](const Eigen::VectorXd& q) { return (q - mid).norm() > 1e-9; };
  EXPECT_FALSE(core::segment_valid(mid_invalid, a, b, 0.25));
  // Resolution coarser than the segment: no interior samples at all.
  long calls = 0;
  const Validity counting = [&](const Eigen::VectorXd&) {
    ++calls;
    return false;
  };
  EXPECT_TRUE(core::segment_valid(counting, a, b, 2.0));
  EXPECT_EQ(calls, 0);
  // At resolution 1/8 a unit segment has 7 interior samples.
  EXPECT_FALSE(core::segment_valid(counting, a, b, 0.125));
  calls = 0;
  const Validity counting_ok = [&](const Eigen::VectorXd&) {
    ++calls;
    return true;
  };
  EXPECT_TRUE(core::segment_valid(counting_ok, a, b, 0.125));
  EXPECT_EQ(calls, 7);
}

TEST(Bridge, CoarseToFineVisitsEveryEdgeSampleOnceMiddleFirst) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::VectorXd a(6), b(6);
    for (int j = 0; j < 6; ++j) {
      a[j] = u(rng);
      b[j] = u(rng);
    }
    const double resolution = trial % 2 == 0 ? 0.01 : 0.05;
    const auto reference = core::edge_samples(a, b, resolution);
    std::vector<Eigen::VectorXd> seen;
    long visited = 0;
    EXPECT_TRUE(core::all_samples_coarse_to_fine(
        a, b, resolution,
        [&](const Eigen::VectorXd& q) {
          seen.push_back(q);
          return true;
        },
        &visited));
    ASSERT_EQ(seen.size(), reference.size());
    EXPECT_EQ(visited, static_cast<long>(reference.size()));
    // The same samples, each once (matched to the sequential ones).
    std::vector<bool> used(reference.size(), false);
    for (const auto& q : seen) {
      bool matched = false;
      for (std::size_t i = 0; i < reference.size() && !matched; ++i) {
        if (!used[i] && q.isApprox(reference[i], 1e-12)) used[i] = matched = true;
      }
      EXPECT_TRUE(matched);
    }
    if (!reference.empty()) {
      EXPECT_TRUE(seen.front().isApprox(reference[(reference.size()) / 2], 1e-12) ||
                  seen.front().isApprox(reference[(reference.size() - 1) / 2], 1e-12));
    }
    // Stops at the first rejection: a segment blocked at its middle costs one check.
    long blocked = 0;
    if (reference.size() >= 3) {
      EXPECT_FALSE(core::all_samples_coarse_to_fine(
          a, b, resolution, [](const Eigen::VectorXd&) { return false; }, &blocked));
      EXPECT_EQ(blocked, 1);
    }
  }
}

namespace {

// Greedy farthest-reach shortcuts, written out plainly: every sample of edge_samples checked in
// order (the function under test visits them coarse to fine).
std::vector<Eigen::VectorXd> greedy_reference(const std::vector<Eigen::VectorXd>& path,
                                              const Validity& valid, double resolution) {
  const auto clear = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    const auto samples = core::edge_samples(a, b, resolution);
    return std::all_of(samples.begin(), samples.end(), valid);
  };
  std::vector<Eigen::VectorXd> out{path.front()};
  std::size_t at = 0;
  while (at + 1 < path.size()) {
    std::size_t next = at + 1;
    for (std::size_t j = at + 2; j < path.size(); ++j) {
      if (clear(path[at], path[j])) next = j;  // the farthest that holds
    }
    out.push_back(path[next]);
    at = next;
  }
  return out;
}

// Every waypoint and every sample at `resolution` between them holds (the shortcut's contract:
// a denser check may find a segment that grazes the ball between samples).
void expect_sampled_valid(const std::vector<Eigen::VectorXd>& path, const Validity& valid,
                          double resolution) {
  for (std::size_t i = 0; i < path.size(); ++i) {
    EXPECT_TRUE(valid(path[i])) << "waypoint " << i;
    if (i == 0) continue;
    for (const auto& q : core::edge_samples(path[i - 1], path[i], resolution)) {
      EXPECT_TRUE(valid(q)) << "segment " << i - 1;
    }
  }
}

// A ball of invalid configurations and a random walk round it in 6 joints.
struct BallWorld {
  Eigen::VectorXd centre = Eigen::VectorXd::Zero(6);
  double radius = 0.6;
  Validity valid() const {
    return [c = centre, r = radius](const Eigen::VectorXd& q) { return (q - c).norm() > r; };
  }
};

std::vector<Eigen::VectorXd> walk_round(const BallWorld& world, std::mt19937_64& rng, int n) {
  std::uniform_real_distribution<double> u(-0.35, 0.35);
  const Validity valid = world.valid();
  std::vector<Eigen::VectorXd> path;
  Eigen::VectorXd q = Eigen::VectorXd::Constant(6, 0.9);
  path.push_back(q);
  while (static_cast<int>(path.size()) < n) {
    Eigen::VectorXd step(6);
    for (int j = 0; j < 6; ++j) step[j] = u(rng);
    // Drift round the ball: the walk's segments hold, many shortcuts across it do not.
    step[0] -= 0.08;
    step[1] += 0.05;
    const Eigen::VectorXd next = q + step;
    if (!valid(next) || !core::segment_valid(valid, q, next, 0.05)) continue;
    path.push_back(next);
    q = next;
  }
  return path;
}

}  // namespace

TEST(Bridge, ShortcutPathIsTheGreedyFarthestReach) {
  const BallWorld world;
  const Validity valid = world.valid();
  std::mt19937_64 rng(11);
  int shortened = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const auto path = walk_round(world, rng, 12 + trial % 7);
    const auto out = core::shortcut_path(path, valid, 0.05);
    const auto want = greedy_reference(path, valid, 0.05);
    ASSERT_EQ(out.size(), want.size()) << "trial " << trial;
    for (std::size_t i = 0; i < out.size(); ++i) EXPECT_EQ(out[i], want[i]) << "trial " << trial;
    EXPECT_EQ(out.front(), path.front());
    EXPECT_EQ(out.back(), path.back());
    // Maximal: skipping any kept waypoint would cross the ball (else greedy had gone further).
    for (std::size_t k = 0; k + 2 < out.size(); ++k) {
      EXPECT_FALSE(core::segment_valid(valid, out[k], out[k + 2], 0.05)) << "trial " << trial;
    }
    expect_sampled_valid(out, valid, 0.05);
    shortened += out.size() < path.size() ? 1 : 0;
  }
  EXPECT_GT(shortened, 20);  // the test means something only if most paths do shorten
}

TEST(Bridge, ShortcutPathSpendsAtMostItsBudget) {
  const BallWorld world;
  const Validity valid = world.valid();
  std::mt19937_64 rng(12);
  const auto path = walk_round(world, rng, 16);
  long none = 0;
  EXPECT_EQ(core::shortcut_path(path, valid, 0.05, &none), path);  // nothing to spend: as given
  long unlimited_spent = 0;
  const Validity counting = [&](const Eigen::VectorXd& q) {
    ++unlimited_spent;
    return valid(q);
  };
  const auto full = core::shortcut_path(path, counting, 0.05);
  for (const long budget : {5L, 40L, 200L}) {
    long left = budget;
    long spent = 0;
    const Validity counted = [&](const Eigen::VectorXd& q) {
      ++spent;
      return valid(q);
    };
    const auto out = core::shortcut_path(path, counted, 0.05, &left);
    EXPECT_EQ(budget - left, spent) << "budget " << budget;  // every check is charged
    EXPECT_LE(spent, unlimited_spent);
    // Waypoints of the path, in order, from its start to its end.
    std::size_t at = 0;
    for (const auto& q : out) {
      while (at < path.size() && path[at] != q) ++at;
      EXPECT_LT(at, path.size()) << "budget " << budget << ": a waypoint not of the path";
    }
    EXPECT_EQ(out.front(), path.front());
    EXPECT_EQ(out.back(), path.back());
    expect_sampled_valid(out, valid, 0.05);
  }
  long plenty = 1000000;
  EXPECT_EQ(core::shortcut_path(path, valid, 0.05, &plenty), full);
}

TEST(Bridge, ShortcutPathChecksKeptSegmentsOnlyWhenAsked) {
  Eigen::VectorXd a = Eigen::VectorXd::Zero(6), b = Eigen::VectorXd::Zero(6);
  a[0] = -1.0;
  b[0] = 1.0;
  const BallWorld world;  // centred between a and b
  const std::vector<Eigen::VectorXd> through{a, b};
  // Taken as valid by default (a planner's own segments), refused when checked.
  EXPECT_EQ(core::shortcut_path(through, world.valid(), 0.05), through);
  EXPECT_TRUE(core::shortcut_path(through, world.valid(), 0.05, nullptr, true).empty());
}
