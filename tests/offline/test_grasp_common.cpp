#include <gtest/gtest.h>

#include "hila/core/mesh.hpp"
#include "hila/offline/grasp_common.hpp"
#include "util/test_util.hpp"

using namespace hila;

TEST(GraspCommon, AntipodalPairsOfABoxAreAcrossItsFaces) {
  const offline::SurfaceQuery surface(core::make_box_mesh({0.05, 0.3, 0.2}));
  offline::AntipodalSettings settings;
  settings.samples = 400;
  settings.max_width = 0.08;
  const auto pairs = offline::sample_antipodal_pairs(surface, settings);
  ASSERT_FALSE(pairs.empty());
  for (const auto& p : pairs) {
    // Only the 50 mm dimension fits the 80 mm limit: pairs across x, normals opposite.
    EXPECT_NEAR(p.width, 0.05, 1e-9);
    EXPECT_NEAR(std::abs(p.axis.x()), 1.0, 1e-9);
    EXPECT_NEAR(p.first.normal.dot(p.second.normal), -1.0, 1e-9);
    EXPECT_NEAR(p.alignment, 1.0, 1e-9);
  }
}

TEST(GraspCommon, GraspFramesAreRightHandedAndTurnAboutTheAxis) {
  offline::ContactPair pair;
  pair.axis = Eigen::Vector3d(0, 0, 1);
  pair.centre = Eigen::Vector3d(0.1, 0.2, 0.3);
  const auto frames = offline::grasp_frames_about_axis(pair, 8);
  ASSERT_EQ(frames.size(), 8u);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_TRUE(core::is_valid_pose(frames[k], 1e-12));
    EXPECT_TRUE(frames[k].linear().col(1).isApprox(pair.axis, 1e-12));
    EXPECT_TRUE(frames[k].translation().isApprox(pair.centre, 1e-12));
    if (k > 0) {
      EXPECT_NEAR(core::rotation_distance(frames[k - 1].linear(), frames[k].linear()),
                  core::kPi / 4, 1e-9);
    }
  }
}

TEST(GraspCommon, AxisLeverIsTheDistanceToTheLine) {
  EXPECT_NEAR(offline::axis_lever({0, 0.3, 0.7}, {0, 0, 0}, {0, 0, 1}), 0.3, 1e-12);
  EXPECT_NEAR(offline::axis_lever({1, 1, 0}, {0, 0, 0}, Eigen::Vector3d(1, 1, 0).normalized()), 0.0,
              1e-12);
}

TEST(GraspCommon, DistinctPosesMergesNeighboursAndTheSymmetricFlip) {
  std::vector<core::Pose> poses;
  poses.push_back(core::make_pose({0, 0, 0}));
  poses.push_back(core::make_pose({0.005, 0, 0}, {0, 0, 0.1}));        // near: merged
  poses.push_back(core::make_pose({0, 0, 0}, {0, 0, core::kPi}));      // flipped about z: merged
  poses.push_back(core::make_pose({0.05, 0, 0}));                      // far: kept
  poses.push_back(core::make_pose({0, 0, 0}, {core::kPi / 2, 0, 0}));  // turned: kept
  EXPECT_EQ(offline::distinct_poses(poses, 0.01, core::deg_to_rad(20)),
            (std::vector<int>{0, 3, 4}));
}

TEST(GraspCommon, HandPartCheckerSeesFingersOpenAndClosed) {
  const core::TriangleMesh board = core::make_box_mesh({0.3, 0.3, 0.01});
  offline::HandGeometry hand;
  core::GeometrySpec finger;
  finger.box_size = {0.02, 0.01, 0.04};
  finger.origin = core::make_pose({0, 0.005, 0});
  hand.finger_pos.push_back(finger);
  finger.origin = core::make_pose({0, -0.005, 0});
  hand.finger_neg.push_back(finger);
  offline::HandPartChecker checker(hand, board);
  // Pinching the board's edge (y = closing axis along the board's thickness, z).
  core::Pose grasp = core::make_pose({0.14, 0, 0}, {core::kPi / 2, 0, 0});
  EXPECT_FALSE(checker.collides(grasp, 0.02));  // open wider than the board
  EXPECT_TRUE(checker.collides(grasp, 0.005));  // closed into it
}
