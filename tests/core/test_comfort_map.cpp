#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "hila/core/generic_ik.hpp"
#include "hila/core/comfort.hpp"
#include "hila/core/comfort_map.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {
const core::KinematicChain& right_arm() {
  return test::reference_cell()->human_arms()[1].chain;
}

core::ComfortMapSettings small_settings() {
  core::ComfortMapSettings s;
  s.spacing = 0.06;
  s.orientations = 100;
  s.samples = 100000;
  s.seed = 11;
  return s;
}

const core::ComfortMap& small_map() {
  static const core::ComfortMap map = core::ComfortMap::build(right_arm(), small_settings());
  return map;
}
}  // namespace

TEST(ComfortMap, OrientationsAreUnitAndSpreadEvenly) {
  const auto set = core::spread_orientations(128);
  ASSERT_EQ(set.size(), 128u);
  double min_gap = core::kPi;
  for (std::size_t i = 0; i < set.size(); ++i) {
    EXPECT_NEAR(set[i].norm(), 1.0, 1e-12);
    for (std::size_t k = i + 1; k < set.size(); ++k) {
      min_gap = std::min(min_gap, set[i].angularDistance(set[k]));
    }
  }
  // Covering: every random rotation is within 50 degrees of one of the 128; no two are closer
  // than 10 degrees.
  std::mt19937_64 rng(1);
  double worst = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Quaterniond q(test::random_pose(rng).linear());
    worst = std::max(worst, q.angularDistance(set[core::nearest_orientation(set, q)]));
  }
  EXPECT_LT(core::rad_to_deg(worst), 50.0);
  EXPECT_GT(core::rad_to_deg(min_gap), 10.0);
}

TEST(ComfortMap, FastIndexEqualsTheSvdIndex) {
  std::mt19937_64 rng(2);
  for (int i = 0; i < 200; ++i) {
    const Eigen::VectorXd q = core::random_configuration(right_arm(), rng);
    const core::Jacobian j = right_arm().jacobian(q);
    EXPECT_NEAR(core::comfort_index_fast(j, 0.6), core::comfort_index(j, 0.6), 1e-7);
  }
}

TEST(ComfortMap, EveryBinHoldsTheBestQOfTheSamplesThatLandedInIt) {
  // Replay the build's sample stream and bin by brute force.
  const auto& map = small_map();
  const auto settings = small_settings();
  const auto& arm = right_arm();
  const double reach = core::characteristic_length(arm);
  std::vector<std::uint8_t> expected(map.values().size(), 0);
  std::mt19937_64 rng(settings.seed);
  const std::size_t n_orient = map.orientations().size();
  for (long s = 0; s < settings.samples; ++s) {
    const Eigen::VectorXd q = core::random_configuration(arm, rng);
    const core::Pose tip = arm.fk(q);
    const double quality = core::comfort_index(arm.jacobian(q), reach);
    const Eigen::Vector3i node = map.nearest_node(tip.translation());
    // Brute-force nearest orientation by angle.
    std::size_t best = 0;
    double best_angle = 10.0;
    const Eigen::Quaterniond rq(tip.linear());
    for (std::size_t o = 0; o < n_orient; ++o) {
      const double a = rq.angularDistance(map.orientations()[o]);
      if (a < best_angle) {
        best_angle = a;
        best = o;
      }
    }
    const std::size_t cell =
        (static_cast<std::size_t>(node.x()) * map.dims().y() + node.y()) * map.dims().z() +
        node.z();
    auto& slot = expected[cell * n_orient + best];
    slot = std::max<std::uint8_t>(slot, static_cast<std::uint8_t>(std::lround(quality * 255.0)));
  }
  std::size_t differing = 0;
  const auto values = map.values();
  for (std::size_t i = 0; i < expected.size(); ++i) differing += expected[i] != values[i];
  // SVD vs eigenvalue rounding can move a value across a 1/255 step on rare ties.
  EXPECT_LE(differing, expected.size() / 10000);
  EXPECT_GT(std::count_if(values.begin(), values.end(), [](auto v) { return v > 0; }), 1000);
  EXPECT_EQ(map.filled_bins(),
            std::count_if(values.begin(), values.end(), [](auto v) { return v > 0; }));
}

TEST(ComfortMap, LookupAtANodeIsItsBinAndOutsideTheGridIsZero) {
  const auto& map = small_map();
  std::mt19937_64 rng(3);
  int checked = 0;
  for (int i = 0; i < 200000 && checked < 50; ++i) {
    const Eigen::Vector3i node(1 + rng() % (map.dims().x() - 2), 1 + rng() % (map.dims().y() - 2),
                               1 + rng() % (map.dims().z() - 2));
    const int o = static_cast<int>(rng() % map.orientations().size());
    if (map.bin(node, o) == 0.0) continue;
    core::Pose pose = core::Pose::Identity();
    pose.linear() = map.orientations()[static_cast<std::size_t>(o)].toRotationMatrix();
    pose.translation() = map.node_position(node);
    EXPECT_NEAR(map.lookup(pose), map.bin(node, o), 1e-12);
    ++checked;
  }
  EXPECT_EQ(checked, 50);
  EXPECT_EQ(map.lookup(core::make_pose({5, 5, 5})), 0.0);
}

TEST(ComfortMap, AgreesWithDirectEvaluationAtReachablePoses) {
  // The map is a max over a bin (6 cm here, ~30 degrees): near, not equal, to the best Q of
  // the exact pose found by IK.
  const auto& map = small_map();
  const auto& arm = right_arm();
  std::mt19937_64 rng(4);
  std::vector<double> errors;
  for (int i = 0; i < 60; ++i) {
    const Eigen::VectorXd q = core::random_configuration(arm, rng);
    const core::Pose pose = arm.fk(q);
    const auto direct = core::best_comfort(arm, pose, q);
    ASSERT_TRUE(direct.reachable);
    errors.push_back(std::abs(map.lookup(pose) - direct.quality));
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.1);
}

TEST(ComfortMap, SameSeedSameMap) {
  const auto again = core::ComfortMap::build(right_arm(), small_settings());
  EXPECT_EQ(again.values(), small_map().values());
  EXPECT_GT(small_map().coverage(), 0.0);
  EXPECT_LT(small_map().coverage(), 1.0);
}

// The acceptance check at the default resolution (3 cm, 128 orientations, 3 M samples):
// Q looked up at random reachable hand poses within 0.05 of direct IK evaluation on average, and
// sampled filled bins confirmed reachable by IK aimed into them (a solution whose hand pose falls
// in that bin).
TEST(ComfortMap, DefaultResolutionMatchesDirectIkAndMarksOnlyReachableBins) {
  const auto& arm = right_arm();
  const core::ComfortMapSettings settings;  // the database's defaults
  const core::ComfortMap map = core::ComfortMap::build(arm, settings);
  std::mt19937_64 rng(21);

  double error_sum = 0.0;
  const int queries = 200;
  for (int i = 0; i < queries; ++i) {
    const Eigen::VectorXd q = core::random_configuration(arm, rng);
    const core::Pose pose = arm.fk(q);
    const auto direct = core::best_comfort(arm, pose, q);
    ASSERT_TRUE(direct.reachable);
    error_sum += std::abs(map.lookup(pose) - direct.quality);
  }
  EXPECT_LE(error_sum / queries, 0.05);

  std::vector<std::size_t> filled;
  const auto values = map.values();
  for (std::size_t b = 0; b < values.size(); ++b) {
    if (values[b] > 0) filled.push_back(b);
  }
  ASSERT_FALSE(filled.empty());
  const auto n_orient = map.orientations().size();
  const auto& dims = map.dims();
  core::GenericIkSettings ik;
  ik.max_attempts = 1;
  ik.max_iterations = 300;
  int confirmed = 0;
  const int bins = 100;
  for (int i = 0; i < bins; ++i) {
    const std::size_t b = filled[rng() % filled.size()];
    const int o = static_cast<int>(b % n_orient);
    std::size_t cell = b / n_orient;
    const Eigen::Vector3i node(static_cast<int>(cell / (dims.y() * dims.z())),
                               static_cast<int>((cell / dims.z()) % dims.y()),
                               static_cast<int>(cell % dims.z()));
    core::Pose centre = core::Pose::Identity();
    centre.linear() = map.orientations()[static_cast<std::size_t>(o)].toRotationMatrix();
    centre.translation() = map.node_position(node);
    bool found = false;
    std::uniform_real_distribution<double> offset(-0.5 * map.spacing(), 0.5 * map.spacing());
    std::normal_distribution<double> normal(0.0, 1.0);
    for (int attempt = 0; attempt < 60 && !found; ++attempt) {
      // Aim at the centre first, then at random poses inside the bin (a boundary bin's centre
      // may lie outside the reachable set while part of the bin does not).
      core::Pose aim = centre;
      if (attempt > 0) {
        aim.translation() += Eigen::Vector3d(offset(rng), offset(rng), offset(rng));
        const Eigen::Vector3d axis(normal(rng), normal(rng), normal(rng));
        aim.linear() =
            centre.linear() *
            Eigen::AngleAxisd(0.4 * std::abs(normal(rng)), axis.normalized()).toRotationMatrix();
        if (core::nearest_orientation(map.orientations(), Eigen::Quaterniond(aim.linear())) !=
            o) {
          continue;
        }
      }
      const auto r = core::solve_ik(arm, aim, core::random_configuration(arm, rng), rng, ik);
      const core::Pose reached = arm.fk(r.q);
      found = map.nearest_node(reached.translation()) == node &&
              core::nearest_orientation(map.orientations(),
                                           Eigen::Quaterniond(reached.linear())) == o;
    }
    confirmed += found ? 1 : 0;
  }
  // Exactly, every filled bin holds a sampled configuration (EveryBinHoldsTheBestQ... replays
  // them). Aimed IK is a random search and misses bins reachable only in a sliver at the edge of
  // the reachable set: measured 90 of 100 with this seed; 85 leaves room for the search, not for
  // a map that marks unreachable bins (a wrong frame or limit drops this far below).
  EXPECT_GE(confirmed, 85);
}

TEST(ComfortMap, OrientationIndexEqualsTheLinearScan) {
  for (const int count : {100, 128, 300}) {
    const auto set = core::spread_orientations(count);
    const core::OrientationIndex index(set);
    EXPECT_LT(index.mean_candidates(), 0.2 * count);  // the point of the index
    std::mt19937_64 rng(static_cast<std::uint64_t>(count));
    std::normal_distribution<double> n(0.0, 1.0);
    for (int i = 0; i < 50000; ++i) {
      Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
      q.normalize();
      ASSERT_EQ(index.nearest(q), core::nearest_orientation(set, q)) << i;
    }
    // Exactly on the members, and at their negatives (the same rotations).
    for (int i = 0; i < count; ++i) {
      const auto& q = set[static_cast<std::size_t>(i)];
      EXPECT_EQ(index.nearest(q), i);
      EXPECT_EQ(index.nearest(Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z())), i);
    }
  }
}
