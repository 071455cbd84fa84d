#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <thread>

#include "hila/core/collision.hpp"
#include "hila/core/generic_ik.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

core::GeometrySpec box(double x, double y, double z) {
  core::GeometrySpec g;
  g.type = core::GeometrySpec::Type::Box;
  g.box_size = {x, y, z};
  return g;
}

core::GeometrySpec sphere(double r) {
  core::GeometrySpec g;
  g.type = core::GeometrySpec::Type::Sphere;
  g.radius = r;
  return g;
}

core::GeometrySpec cylinder(double r, double length) {
  core::GeometrySpec g;
  g.type = core::GeometrySpec::Type::Cylinder;
  g.radius = r;
  g.length = length;
  return g;
}

core::Pose random_rotation(std::mt19937_64& rng, const Eigen::Vector3d& at) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  core::Pose p = core::Pose::Identity();
  p.linear() = q.normalized().toRotationMatrix();
  p.translation() = at;
  return p;
}

struct Fixture {
  std::shared_ptr<const core::Cell> cell = test::reference_cell();
  core::CellScene scene = core::build_cell_scene(*cell, {.human_moves = true});
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

Eigen::VectorXd random_robot_q(const core::Cell& cell, std::mt19937_64& rng) {
  Eigen::VectorXd q = cell.home_configuration();
  for (const core::Arm& arm : cell.arms()) {
    cell.set_arm(q, arm, core::random_configuration(arm.chain, rng));
    cell.set_jaw(q, arm, std::uniform_real_distribution<double>(0.0, 0.085)(rng));
  }
  return q;
}

Eigen::VectorXd random_human_q(const core::Cell& cell, std::mt19937_64& rng) {
  const Eigen::VectorXd lo = cell.human().lower_limits();
  const Eigen::VectorXd hi = cell.human().upper_limits();
  Eigen::VectorXd q(lo.size());
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    q[i] = std::uniform_real_distribution<double>(lo[i], hi[i])(rng);
  }
  return q;
}

}  // namespace

TEST(Collision, HomeConfigurationIsCollisionFree) {
  auto& f = fixture();
  core::CollisionData data(f.scene.model);
  core::set_cell_state(*f.cell, f.scene, data, f.cell->home_configuration(0.085),
                       f.cell->human_neutral());
  core::CollisionPair pair;
  EXPECT_FALSE(core::in_collision(f.scene.model, data, &pair))
      << core::describe_pair(f.scene.model, pair);
  EXPECT_FALSE(core::in_collision_brute_force(f.scene.model, data));
  EXPECT_GT(core::min_distance(f.scene.model, data), 0.0);
}

TEST(Collision, BroadPhaseAgreesWithBruteForceOnRandomConfigurations) {
  auto& f = fixture();
  core::CollisionData data(f.scene.model);
  std::mt19937_64 rng(31);
  int colliding = 0;
  for (int i = 0; i < 600; ++i) {
    core::set_cell_state(*f.cell, f.scene, data, random_robot_q(*f.cell, rng),
                         i % 3 ? f.cell->human_neutral() : random_human_q(*f.cell, rng));
    core::CollisionPair fast_pair, slow_pair;
    const bool fast = core::in_collision(f.scene.model, data, &fast_pair);
    const bool slow = core::in_collision_brute_force(f.scene.model, data, &slow_pair);
    ASSERT_EQ(fast, slow) << "configuration " << i << ": broad phase says "
                          << core::describe_pair(f.scene.model, fast_pair) << ", brute force "
                          << core::describe_pair(f.scene.model, slow_pair);
    if (fast) {
      ++colliding;
      // The reported pair really collides and is not an allowed pair.
      EXPECT_FALSE(f.scene.model.allowed(fast_pair.body_a, fast_pair.body_b));
    }
  }
  // Random configurations of two arms collide often, but not always: both branches are tested.
  EXPECT_GT(colliding, 50);
  EXPECT_LT(colliding, 580);
}

TEST(Collision, ArmSubsetQueryAgreesWithBruteForceOverItsPairs) {
  auto& f = fixture();
  core::CollisionData data(f.scene.model);
  std::mt19937_64 rng(32);
  ASSERT_EQ(f.scene.arm_bodies.size(), 2u);
  // The left arm's bodies: its links and its gripper, nothing of the right arm.
  const auto& left = f.scene.arm_bodies[0];
  EXPECT_NE(std::find(left.begin(), left.end(), *f.scene.model.find_body("left_pad_l")),
            left.end());
  EXPECT_EQ(std::find(left.begin(), left.end(), *f.scene.model.find_body("right_pad_l")),
            left.end());
  int colliding = 0;
  for (int i = 0; i < 600; ++i) {
    // Alternate full-state and one-arm updates so the subset query sees stale broad-phase trees.
    Eigen::VectorXd q = random_robot_q(*f.cell, rng);
    if (i % 2) {
      std::vector<core::Pose> links;
      f.cell->robot().link_poses(q, links);
      core::set_robot_pose(data, f.scene.robot, links);
    } else {
      core::set_cell_state(*f.cell, f.scene, data, q, random_human_q(*f.cell, rng));
    }
    const auto& arm = f.scene.arm_bodies[i % 2];
    const bool fast = core::in_collision(f.scene.model, data, arm);
    const bool slow = core::in_collision_brute_force(f.scene.model, data, arm);
    ASSERT_EQ(fast, slow) << "configuration " << i;
    colliding += fast;
    // The whole-scene answer is at least as pessimistic as any subset's.
    if (fast) {
      EXPECT_TRUE(core::in_collision(f.scene.model, data));
    }
  }
  EXPECT_GT(colliding, 50);
  EXPECT_LT(colliding, 580);
}

// The subset query derives its pair lists once per set of bodies and keeps a few: sets asked in
// turn (more than it keeps, with repeats and bodies of both arms) must each get the brute-force
// answer, and a pair allowed meanwhile must drop out of every kept set.
TEST(Collision, SubsetQueriesOverManySetsAgreeWithBruteForce) {
  auto& f = fixture();
  core::CollisionModel model = core::build_cell_scene(*f.cell, {.human_moves = true}).model;
  core::CollisionData data(model);
  std::mt19937_64 rng(57);
  std::vector<std::vector<int>> sets;
  for (int s = 0; s < 11; ++s) {
    std::vector<int> set = f.scene.arm_bodies[static_cast<std::size_t>(s % 2)];
    std::shuffle(set.begin(), set.end(), rng);
    set.resize(set.size() / 2 + static_cast<std::size_t>(s) % (set.size() / 2));
    set.push_back(static_cast<int>(rng() % static_cast<std::uint64_t>(model.num_bodies())));
    set.push_back(set.front());  // a body named twice counts once
    sets.push_back(set);
  }
  int colliding = 0;
  for (int i = 0; i < 400; ++i) {
    core::set_cell_state(*f.cell, f.scene, data, random_robot_q(*f.cell, rng),
                         random_human_q(*f.cell, rng));
    const auto& set = sets[static_cast<std::size_t>(i) % sets.size()];
    const bool fast = core::in_collision(model, data, set);
    ASSERT_EQ(fast, core::in_collision_brute_force(model, data, set)) << "query " << i;
    colliding += fast;
    // The trees' query in between: FCL's transforms and world boxes catch up with the poses.
    if (i % 3 == 0) {
      ASSERT_EQ(core::in_collision(model, data), core::in_collision_brute_force(model, data))
          << "query " << i;
    }
  }
  EXPECT_GT(colliding, 20);
  EXPECT_LT(colliding, 380);
  // Every pair of the first set allowed: nothing of it is tested any more, kept or not.
  for (const int b : sets.front()) {
    for (int other = 0; other < model.num_bodies(); ++other) {
      if (other != b) model.allow(b, other);
    }
  }
  for (int i = 0; i < 50; ++i) {
    core::set_cell_state(*f.cell, f.scene, data, random_robot_q(*f.cell, rng),
                         random_human_q(*f.cell, rng));
    EXPECT_FALSE(core::in_collision(model, data, sets.front()));
  }
}

// An arm's last link with its gripper moves as one piece: a query that leaves the pairs among
// them out, with those pairs checked on their own, gives the whole query's answer.
TEST(Collision, PairsWithinTheRigidTipCheckedApartGiveTheSameAnswer) {
  auto& f = fixture();
  const core::RobotModel& robot = f.cell->robot();
  const core::Arm& left = f.cell->arm("left");
  const auto rigid =
      core::rigid_tip_bodies(robot, f.scene.robot, robot.link_index(left.spec.tip_link));
  std::vector<std::string> names;
  for (const int b : rigid) names.push_back(f.scene.model.body_name(b));
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"left_finger_l", "left_finger_r", "left_ft_sensor",
                                             "left_gripper_palm", "left_pad_l", "left_pad_r",
                                             "left_wrist_3_link"}));
  core::CollisionData data(f.scene.model);
  std::mt19937_64 rng(61);
  const auto& arm = f.scene.arm_bodies[0];
  int colliding = 0;
  int among = 0;
  for (int i = 0; i < 600; ++i) {
    core::set_cell_state(*f.cell, f.scene, data, random_robot_q(*f.cell, rng),
                         random_human_q(*f.cell, rng));
    const bool whole = core::in_collision(f.scene.model, data, arm);
    const bool within = core::in_collision_among(f.scene.model, data, rigid);
    const bool rest = core::in_collision(f.scene.model, data, arm, nullptr, rigid);
    ASSERT_EQ(whole, within || rest) << "configuration " << i;
    ASSERT_EQ(whole, core::in_collision_brute_force(f.scene.model, data, arm));
    colliding += whole;
    among += within;
  }
  EXPECT_GT(colliding, 50);
  EXPECT_LT(colliding, 580);
  EXPECT_EQ(among, 0) << "the gripper's own links never touch at any jaw";
}

TEST(Collision, ArmPushedIntoTheTableCollidesWithTheTable) {
  auto& f = fixture();
  const core::Arm& arm = f.cell->arm("left");
  std::vector<core::Pose> links;
  const Eigen::VectorXd home = f.cell->home_configuration();
  f.cell->robot().link_poses(home, links);
  const core::Pose base = links[f.cell->robot().link_index(arm.spec.base_link)];
  // TCP 3 cm below the table top, gripper pointing down.
  core::Pose tcp_world = core::make_pose({0.35, 0.30, 1.094 - 0.03}, {core::kPi, 0, 0});
  core::UrIkSolutions sols;
  ASSERT_GT(arm.ur_ik->solve(base.inverse() * tcp_world, arm.spec.home, sols), 0);
  core::CollisionData data(f.scene.model);
  for (int k = 0; k < sols.count; ++k) {
    Eigen::VectorXd q = home;
    f.cell->set_arm(q, arm, sols.q[k]);
    core::set_cell_state(*f.cell, f.scene, data, q, f.cell->human_neutral());
    core::CollisionPair pair;
    ASSERT_TRUE(core::in_collision(f.scene.model, data, &pair)) << "solution " << k;
    EXPECT_LE(core::min_distance(f.scene.model, data), 0.0);
  }
  // And the same TCP 10 cm above the table is free for the elbow-up solution.
  tcp_world.translation().z() = 1.094 + 0.10;
  ASSERT_GT(arm.ur_ik->solve(base.inverse() * tcp_world, arm.spec.home, sols), 0);
  bool some_free = false;
  for (int k = 0; k < sols.count; ++k) {
    Eigen::VectorXd q = home;
    f.cell->set_arm(q, arm, sols.q[k]);
    core::set_cell_state(*f.cell, f.scene, data, q, f.cell->human_neutral());
    some_free = some_free || !core::in_collision(f.scene.model, data);
  }
  EXPECT_TRUE(some_free);
}

TEST(Collision, TableContactNamesTheTable) {
  auto& f = fixture();
  core::CollisionData data(f.scene.model);
  Eigen::VectorXd q = f.cell->home_configuration();
  // Shoulder lift swings the left arm down through the table.
  Eigen::VectorXd arm_q = f.cell->arm("left").spec.home;
  arm_q[1] += core::deg_to_rad(60);
  f.cell->set_arm(q, f.cell->arm("left"), arm_q);
  core::set_cell_state(*f.cell, f.scene, data, q, f.cell->human_neutral());
  core::CollisionPair pair;
  if (core::in_collision(f.scene.model, data, &pair)) {
    const std::string names = core::describe_pair(f.scene.model, pair);
    EXPECT_NE(names.find("left_"), std::string::npos) << names;
  }
  // Whatever the pose, the two phases agree.
  EXPECT_EQ(core::in_collision(f.scene.model, data),
            core::in_collision_brute_force(f.scene.model, data));
}

TEST(Collision, HeldBoardFollowsTheGripperAndHitsTheTable) {
  // A lateral board (587 x 295 x 10 mm) held at the middle of a long edge, 2 cm deep: thickness
  // along the opening axis (TCP y), width along the approach (TCP z).
  auto cell = test::reference_cell();
  core::CellScene scene = core::build_cell_scene(*cell);
  const int tcp_link = cell->robot().link_index("left_tcp");
  const int board = scene.model.add_body("board", {box(0.587, 0.010, 0.295)}, false);
  std::vector<int> gripper;
  for (const char* name : {"left_pad_l", "left_pad_r", "left_finger_l", "left_finger_r"}) {
    gripper.push_back(*scene.model.find_body(name));
  }
  const core::Attachment held =
      core::attach(scene.model, board, tcp_link, core::make_pose({0, 0, 0.1475 - 0.02}), gripper);
  std::vector<int> active = scene.arm_bodies[0];
  active.push_back(board);

  const core::Arm& arm = cell->arm("left");
  std::vector<core::Pose> links;
  Eigen::VectorXd q = cell->home_configuration(0.010);
  cell->robot().link_poses(q, links);
  const core::Pose base = links[cell->robot().link_index(arm.spec.base_link)];
  core::CollisionData data(scene.model);
  auto pose_arm = [&](double tcp_height) {
    // Gripper pointing down, TCP `tcp_height` above the table top.
    const core::Pose tcp = core::make_pose({0.35, 0.30, 1.094 + tcp_height}, {core::kPi, 0, 0});
    core::UrIkSolutions sols;
    EXPECT_GT(arm.ur_ik->solve(base.inverse() * tcp, arm.spec.home, sols), 0);
    // The first IK solution whose arm (without the board) is collision-free.
    for (int k = 0; k < sols.count; ++k) {
      cell->set_arm(q, arm, sols.q[k]);
      core::set_cell_state(*cell, scene, data, q, cell->human_neutral());
      if (!core::in_collision(scene.model, data, scene.arm_bodies[0])) break;
    }
    cell->robot().link_poses(q, links);
    core::set_attachment_pose(data, held, links);
  };
  pose_arm(0.40);  // the board's lower edge 12.5 cm above the table
  EXPECT_TRUE(data.body_pose(board).isApprox(links[tcp_link] * held.link_to_body, 1e-12));
  EXPECT_FALSE(core::in_collision(scene.model, data, active));
  pose_arm(0.15);  // the gripper is clear, the board reaches 12.5 cm below the table top
  core::CollisionPair pair;
  ASSERT_TRUE(core::in_collision(scene.model, data, active, &pair));
  EXPECT_EQ(core::describe_pair(scene.model, pair), "table <-> board");
  EXPECT_FALSE(
      core::in_collision(scene.model, data, scene.arm_bodies[0]));  // the arm alone is free
  EXPECT_EQ(core::in_collision(scene.model, data),
            core::in_collision_brute_force(scene.model, data));
}

// The subset query settles most pairs with oriented boxes around the shapes before FCL's narrow
// phase: near contact, where the world boxes of rotated shapes overlap but the shapes may not,
// its verdicts must still be FCL's own (the brute-force query runs FCL on every pair).
TEST(Collision, OrientedBoxMidPhaseKeepsFclVerdictsNearContact) {
  core::CollisionModel model;
  std::mt19937_64 rng(57);
  // Static shapes of every kind the cell uses, turned arbitrarily: a board (convex mesh), a
  // plate, a cylinder and a ball.
  model.add_mesh_body("board", core::make_box_mesh({0.6, 0.3, 0.018}), true,
                      random_rotation(rng, {0.0, 0.0, 0.0}));
  model.add_body("plate", {box(0.4, 0.02, 0.3)}, true, random_rotation(rng, {0.5, 0.0, 0.0}));
  model.add_body("post", {cylinder(0.04, 0.5)}, true, random_rotation(rng, {0.0, 0.5, 0.0}));
  model.add_body("ball", {sphere(0.08)}, true, core::make_pose({0.5, 0.5, 0.0}));
  // A moving link: a cylinder with a box beside it (two shapes of one body, as on the UR3).
  core::GeometrySpec side = box(0.06, 0.1, 0.085);
  side.origin = core::make_pose({0.0, 0.0, 0.15});
  const int link = model.add_body("link", {cylinder(0.032, 0.2), side}, false);
  core::CollisionData data(model);
  std::uniform_real_distribution<double> coord(-0.35, 0.85);
  std::uniform_real_distribution<double> height(-0.25, 0.25);
  int colliding = 0;
  int near_miss = 0;  // free, yet within 2 cm of a static shape
  for (int i = 0; i < 4000; ++i) {
    data.set_body_pose(link, random_rotation(rng, {coord(rng), coord(rng), height(rng)}));
    core::CollisionPair fast_pair;
    const bool fast = core::in_collision(model, data, std::vector<int>{link}, &fast_pair);
    const bool slow = core::in_collision_brute_force(model, data, std::vector<int>{link});
    ASSERT_EQ(fast, slow) << "pose " << i << ": subset query says "
                          << core::describe_pair(model, fast_pair);
    // The whole-scene query (broad-phase trees, the same mid phase) agrees as well.
    ASSERT_EQ(core::in_collision(model, data), slow) << "pose " << i;
    if (fast) {
      ++colliding;
      EXPECT_EQ(fast_pair.body_b, link);
    } else if (core::min_distance(model, data) < 0.02) {
      ++near_miss;
    }
  }
  // Both verdicts, and many free poses close enough that rotated world boxes overlap.
  EXPECT_GT(colliding, 400);
  EXPECT_GT(near_miss, 200);
}

TEST(Collision, DistanceBetweenPrimitivesMatchesClosedForm) {
  core::CollisionModel model;
  model.add_body("wall", {box(1.0, 1.0, 1.0)}, true, core::make_pose({0, 0, 0}));
  const int ball = model.add_body("ball", {sphere(0.1)}, false);
  core::CollisionData data(model);
  data.set_body_pose(ball, core::make_pose({1.2, 0.0, 0.0}));
  EXPECT_NEAR(core::min_distance(model, data), 1.2 - 0.5 - 0.1, 1e-6);
  EXPECT_FALSE(core::in_collision(model, data));
  data.set_body_pose(ball, core::make_pose({0.55, 0.0, 0.0}));
  core::CollisionPair pair;
  EXPECT_TRUE(core::in_collision(model, data, &pair));
  EXPECT_EQ(core::describe_pair(model, pair), "wall <-> ball");
}

TEST(Collision, AllowedStaticAndDisabledPairsAreSkipped) {
  core::CollisionModel model;
  const int a = model.add_body("a", {box(1, 1, 1)}, true);
  model.add_body("b", {box(1, 1, 1)}, true, core::make_pose({0.2, 0, 0}));  // static-static
  const int c = model.add_body("c", {sphere(0.3)}, false);
  core::CollisionData data(model);
  EXPECT_TRUE(core::in_collision(model, data));  // c overlaps a and b
  model.allow("c", "a");
  EXPECT_TRUE(core::in_collision(model, data));                       // still overlaps b
  EXPECT_TRUE(core::in_collision(model, data, std::vector<int>{c}));  // the subset query too
  model.allow("c", "b");
  EXPECT_FALSE(core::in_collision(model, data));
  EXPECT_FALSE(core::in_collision(model, data, std::vector<int>{c}));
  EXPECT_FALSE(core::in_collision_brute_force(model, data));
  // Allowed and disabled after the data was made: pairs follow the model as it is now.
  model.set_enabled(c, false);
  EXPECT_FALSE(core::in_collision(model, data));
  EXPECT_FALSE(core::in_collision(model, data, std::vector<int>{c}));
  EXPECT_TRUE(model.allowed(a, c));
  test::expect_input_error([&] { model.allow("c", "nope"); }, {"nope"});
}

// A scene's mesh obstacle is the last body the world adds: the subset query (the planner's and
// the validator's) must see it as it sees one added earlier.
TEST(Collision, AMeshBodyAddedLastIsSeenByTheSubsetQuery) {
  core::CollisionModel model;
  const int link = model.add_body("link", {box(0.2, 0.2, 0.2)}, false);
  const int obstacle = model.add_mesh_body("obstacle", core::make_box_mesh({0.3, 0.3, 0.3}), true,
                                           core::make_pose({0.1, 0.0, 0.0}));
  core::CollisionData data(model);
  core::CollisionPair pair;
  EXPECT_TRUE(core::in_collision_brute_force(model, data, std::vector<int>{link}));
  ASSERT_TRUE(core::in_collision(model, data, std::vector<int>{link}, &pair));
  EXPECT_EQ(pair.body_b, obstacle);
  EXPECT_TRUE(core::in_collision(model, data));
  data.set_body_pose(link, core::make_pose({1.0, 0.0, 0.0}));
  EXPECT_FALSE(core::in_collision(model, data, std::vector<int>{link}));
}

TEST(Collision, ARigidPartsOwnContactIsFoundByTheAmongQueryOnly) {
  core::CollisionModel model;
  const int palm = model.add_body("palm", {box(0.1, 0.1, 0.1)}, false);
  const int board = model.add_body("board", {box(0.4, 0.1, 0.02)}, false,
                                   core::make_pose({0.05, 0.0, 0.0}));  // into the palm
  const int wrist = model.add_body("wrist", {sphere(0.03)}, false, core::make_pose({0, 0, 0.5}));
  model.add_body("table", {box(2, 2, 0.1)}, true, core::make_pose({0, 0, -1}));
  core::CollisionData data(model);
  const std::vector<int> moving{wrist, palm, board};
  const std::vector<int> rigid{palm, board};
  core::CollisionPair pair;
  EXPECT_TRUE(core::in_collision(model, data, moving, &pair));
  EXPECT_EQ(core::describe_pair(model, pair), "palm <-> board");
  EXPECT_FALSE(core::in_collision(model, data, moving, nullptr, rigid));
  EXPECT_TRUE(core::in_collision_among(model, data, rigid, &pair));
  EXPECT_EQ(core::describe_pair(model, pair), "palm <-> board");
  EXPECT_FALSE(core::in_collision_among(model, data, {wrist, board}));
  // Out of the rigid part, the board still meets the table.
  data.set_body_pose(board, core::make_pose({0.05, 0.0, -0.96}));
  EXPECT_TRUE(core::in_collision(model, data, moving, &pair, rigid));
  EXPECT_EQ(core::describe_pair(model, pair), "board <-> table");
}

TEST(Collision, AdjacentRobotLinksAreAllowedThroughFramesWithoutGeometry) {
  auto& f = fixture();
  const auto& m = f.scene.model;
  // wrist_3 -> tool0 (no geometry) -> ft_sensor
  EXPECT_TRUE(m.allowed(*m.find_body("left_wrist_3_link"), *m.find_body("left_ft_sensor")));
  EXPECT_TRUE(m.allowed(*m.find_body("left_shoulder_link"), *m.find_body("left_upper_arm_link")));
  EXPECT_FALSE(m.allowed(*m.find_body("left_upper_arm_link"), *m.find_body("left_wrist_2_link")));
}

TEST(Collision, PerThreadDataGivesTheSameAnswers) {
  auto& f = fixture();
  std::mt19937_64 rng(41);
  std::vector<Eigen::VectorXd> configs;
  for (int i = 0; i < 200; ++i) configs.push_back(random_robot_q(*f.cell, rng));
  auto run = [&](std::vector<int>& out) {
    core::CollisionData data(f.scene.model);
    for (const auto& q : configs) {
      core::set_cell_state(*f.cell, f.scene, data, q, f.cell->human_neutral());
      out.push_back(core::in_collision(f.scene.model, data));
    }
  };
  std::vector<int> a, b;
  std::thread ta(run, std::ref(a)), tb(run, std::ref(b));
  ta.join();
  tb.join();
  EXPECT_EQ(a, b);
}
