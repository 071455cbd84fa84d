#include <gtest/gtest.h>

#include "hila/core/product.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/online/validator.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

const core::ProductSpec& cabinet() {
  static const core::ProductSpec product = core::load_product(test::product_path());
  return product;
}

// A slow straight joint-space motion of `arm` through the waypoints, 1 s apart.
online::Motion slow_motion(const std::string& arm, const std::vector<Eigen::VectorXd>& q) {
  online::Motion m;
  m.arm = arm;
  m.q = q;
  for (std::size_t i = 0; i < q.size(); ++i) m.time.push_back(static_cast<double>(i) * 4.0);
  m.robot_q = test::reference_cell()->home_configuration();
  m.board_world = cabinet().part("top").initial;
  return m;
}

bool has(const online::ValidationReport& r, const std::string& kind) {
  for (const auto& v : r.violations) {
    if (v.kind == kind) return true;
  }
  return false;
}

std::string describe(const online::ValidationReport& r) {
  std::string out;
  for (const auto& v : r.violations)
    out += v.kind + " @" + std::to_string(v.time) + ": " + v.detail + "; ";
  return out;
}

struct Fixture {
  std::shared_ptr<const core::Cell> cell = test::reference_cell();
  online::Scene scene = online::nominal_scene(*cell, cabinet());
  const core::Arm& left = cell->arm("left");

  // One thread's report, checked against the same validation split over two threads.
  online::ValidationReport run(const online::Motion& m, const online::Scene& s) const {
    const online::World world(*cell, cabinet(), s, "top");
    core::CollisionData data = world.make_data();
    const online::ValidationReport one = online::validate_motion(world, data, m);
    core::CollisionData a = world.make_data();
    core::CollisionData b = world.make_data();
    const online::ValidationReport two = online::validate_motion(world, {&a, &b}, m);
    EXPECT_EQ(describe(two), describe(one)) << "two threads";
    EXPECT_EQ(two.samples, one.samples);
    EXPECT_EQ(two.worst_slip_deg, one.worst_slip_deg);
    return one;
  }
  online::ValidationReport run(const online::Motion& m) const { return run(m, scene); }

  // The left arm's first IK solution for a TCP pointing down at `p` (world).
  Eigen::VectorXd left_at(const Eigen::Vector3d& p) const {
    return test::arm_pointing_down_at(*cell, left, p);
  }
};

}  // namespace

TEST(Validator, ASmallSlowMotionAwayFromHomeIsValid) {
  Fixture f;
  Eigen::VectorXd to = f.left.spec.home;
  to[0] += 0.2;
  const auto report = f.run(slow_motion("left", {f.left.spec.home, to}));
  EXPECT_TRUE(report.valid()) << describe(report);
  // 0.2 rad at 0.01 rad per sample, plus the start.
  EXPECT_EQ(report.samples, 21);
}

TEST(Validator, AMotionPushedIntoTheTableIsACollisionWithTheTable) {
  Fixture f;
  // Above the table, then 1 cm below its top (1.094 m).
  const Eigen::VectorXd above = f.left_at({0.40, 0.20, 1.30});
  const Eigen::VectorXd inside = f.left_at({0.40, 0.20, 1.084});
  const auto clear = f.run(slow_motion("left", {above}));
  EXPECT_TRUE(clear.valid()) << describe(clear);
  const auto report = f.run(slow_motion("left", {above, inside}));
  ASSERT_TRUE(has(report, "collision")) << describe(report);
  std::string detail;
  for (const auto& v : report.violations) {
    if (v.kind == "collision") detail = v.detail;
  }
  EXPECT_NE(detail.find("table"), std::string::npos) << detail;
}

// A long motion (split over two threads by run()) that reaches into the table in its second
// half: both splits report the same first contact, after the clear first half.
TEST(Validator, ALongMotionSplitOverThreadsReportsTheSameFirstContact) {
  Fixture f;
  const Eigen::VectorXd above = f.left_at({0.40, 0.20, 1.30});
  const Eigen::VectorXd inside = f.left_at({0.40, 0.20, 1.084});
  const online::Motion m = slow_motion("left", {f.left.spec.home, above, inside, above});
  const auto report = f.run(m);
  ASSERT_GE(report.samples, 256) << "long enough for two threads";
  ASSERT_TRUE(has(report, "collision")) << describe(report);
  for (const auto& v : report.violations) {
    if (v.kind == "collision") {
      EXPECT_GT(v.time, m.time[1]);
      EXPECT_LT(v.time, m.time[2]);
    }
  }
}

// MotionValidation's parts checked one by one in reverse order, alternating between two
// CollisionData (as the queue's two threads may take them), or in uneven ranges: the report is
// validate_motion's, the first contact and the worst slip included. A held board over a long
// motion into the table and back, so that collisions and slip fall in several parts.
TEST(Validator, PartsCheckedInAnyOrderGiveTheWholeMotionsReport) {
  Fixture f;
  const Eigen::VectorXd above = f.left_at({0.40, 0.20, 1.30});
  const Eigen::VectorXd inside = f.left_at({0.40, 0.20, 1.084});
  Eigen::VectorXd tilted = above;
  tilted[4] += 0.8;
  online::Motion m =
      slow_motion("left", {f.left.spec.home, above, inside, above, tilted, f.left.spec.home});
  m.holds_board = true;
  m.board_in_tcp = core::Pose(Eigen::Translation3d(0.0, 0.0, 0.15));
  m.slip_axis_tcp = Eigen::Vector3d::UnitY();
  m.slip_lever_tcp = Eigen::Vector3d::UnitZ();
  m.theta_c_deg = 20.0;
  const online::World world(*f.cell, cabinet(), f.scene, "top");
  core::CollisionData a = world.make_data();
  core::CollisionData b = world.make_data();
  const std::string whole = describe(online::validate_motion(world, a, m));
  ASSERT_NE(whole.find("collision"), std::string::npos) << whole;
  ASSERT_NE(whole.find("slip"), std::string::npos) << whole;

  online::MotionValidation reversed(world, m, {});
  ASSERT_GE(reversed.parts(), 4u) << "long enough for several parts";
  for (std::size_t p = reversed.parts(); p-- > 0;) reversed.check_parts(p, p + 1, p % 2 ? a : b);
  const online::ValidationReport r = reversed.report();
  EXPECT_EQ(describe(r), whole);
  EXPECT_EQ(r.samples, online::validate_motion(world, b, m).samples);
  EXPECT_EQ(r.worst_slip_deg, online::validate_motion(world, b, m).worst_slip_deg);

  online::MotionValidation uneven(world, m, {});
  const std::size_t n = uneven.parts();
  uneven.check_parts(n - 1, n, a);
  uneven.check_parts(1, n - 1, b);
  uneven.check_parts(0, 1, b);
  EXPECT_EQ(describe(uneven.report()), whole);
}

TEST(Validator, AJointJumpIsAVelocityViolation) {
  Fixture f;
  Eigen::VectorXd to = f.left.spec.home;
  to[0] += 1.0;
  online::Motion m = slow_motion("left", {f.left.spec.home, to});
  m.time = {0.0, 0.01};  // 100 rad/s against 3.14
  const auto report = f.run(m);
  EXPECT_TRUE(has(report, "velocity")) << describe(report);
  // The same motion over 4 s keeps the limits.
  m.time = {0.0, 4.0};
  EXPECT_FALSE(has(f.run(m), "velocity"));
}

TEST(Validator, AnAbruptStopIsAnAccelerationViolation) {
  Fixture f;
  Eigen::VectorXd a = f.left.spec.home, b = a, c = a;
  b[0] += 0.30;   // 3.0 rad/s for 0.1 s ...
  c[0] += 0.301;  // ... then 0.01 rad/s: 29.9 rad/s^2 against 170 deg/s^2 = 2.97
  online::Motion m = slow_motion("left", {a, b, c});
  m.time = {0.0, 0.1, 0.2};
  const auto report = f.run(m);
  EXPECT_TRUE(has(report, "acceleration")) << describe(report);
  EXPECT_FALSE(has(report, "velocity")) << describe(report);
}

TEST(Validator, MalformedMotionsAreFormatViolations) {
  Fixture f;
  online::Motion m = slow_motion("left", {f.left.spec.home, f.left.spec.home});
  m.time = {1.0, 1.0};
  EXPECT_TRUE(has(f.run(m), "format"));
  m = slow_motion("left", {f.left.spec.home, Eigen::VectorXd::Zero(3)});
  EXPECT_TRUE(has(f.run(m), "format"));
  Eigen::VectorXd nan = f.left.spec.home;
  nan[2] = std::nan("");
  m = slow_motion("left", {f.left.spec.home, nan});
  EXPECT_TRUE(has(f.run(m), "format"));
  m = slow_motion("middle", {f.left.spec.home});
  EXPECT_TRUE(has(f.run(m), "format"));
}

TEST(Validator, JointsBeyondTheLimitsAreReported) {
  Fixture f;
  Eigen::VectorXd q = f.left.spec.home;
  q[5] = 7.0;  // limit 2 pi
  const auto report = f.run(slow_motion("left", {q}));
  EXPECT_TRUE(has(report, "joint_limit")) << describe(report);
}

TEST(Validator, AHeldBoardTiltedPastThetaCIsASlipViolation) {
  Fixture f;
  // The TCP turns about its x axis from pointing down: a grasp whose opening axis is the TCP's
  // y and whose lever is its z tilts its slip angle with the turn.
  const Eigen::VectorXd start = f.left_at({0.35, 0.20, 1.35});
  Eigen::VectorXd end = start;
  end[5] += 0.6;  // wrist 3: about the TCP's z; then tilts from wrists 1 and 2
  end[4] += 1.0;
  end[3] += 0.5;
  online::Motion m = slow_motion("left", {start, end});
  m.holds_board = true;
  m.board_in_tcp = core::Pose(Eigen::Translation3d(0.0, 0.0, 0.15));  // the board below the pads
  m.slip_axis_tcp = Eigen::Vector3d::UnitY();
  m.slip_lever_tcp = Eigen::Vector3d::UnitZ();
  // Independent slip along the straight joint path: FK through the chain at 200 samples.
  const core::Pose base = core::arm_base_in_world(*f.cell, f.left);
  double first = 0.0, worst = 0.0;
  for (int k = 0; k <= 200; ++k) {
    const Eigen::VectorXd q = start + (end - start) * (k / 200.0);
    const core::Pose tcp = base * f.left.chain.fk(q);
    const Eigen::Vector3d n =
        tcp.linear() * Eigen::Vector3d::UnitY().cross(Eigen::Vector3d::UnitZ());
    const double slip = core::rad_to_deg(std::asin(std::min(1.0, std::abs(n.z()))));
    if (k == 0) first = slip;
    worst = std::max(worst, slip);
  }
  ASSERT_GT(worst - first, 5.0) << "the motion must tilt the grasp";
  m.theta_c_deg = 0.5 * (first + worst);
  auto report = f.run(m);
  EXPECT_TRUE(has(report, "slip")) << describe(report);
  EXPECT_NEAR(report.worst_slip_deg, worst, 0.5);
  m.theta_c_deg = worst + 1.0;
  report = f.run(m);
  EXPECT_FALSE(has(report, "slip")) << describe(report);
}

TEST(Validator, ASceneObstacleOnThePathIsACollisionAndItsAbsenceIsNot) {
  Fixture f;
  const Eigen::VectorXd a = f.left_at({0.40, 0.25, 1.35});
  const Eigen::VectorXd b = f.left_at({0.40, 0.05, 1.35});
  const online::Motion m = slow_motion("left", {a, b});
  const auto clear = f.run(m);
  ASSERT_TRUE(clear.valid()) << describe(clear);
  // A crate where the TCP passes midway (FK of the joint midpoint), as a box and as a mesh
  // (the world adds a scene's obstacles last, and a mesh added last once went unchecked).
  const core::Pose mid = core::arm_base_in_world(*f.cell, f.left) * f.left.chain.fk(0.5 * (a + b));
  online::SceneObstacle crate;
  crate.name = "crate";
  crate.box_size = Eigen::Vector3d(0.06, 0.06, 0.06);
  crate.pose = core::Pose(Eigen::Translation3d(mid.translation()));
  online::SceneObstacle jig = crate;
  jig.name = "jig";
  jig.mesh_file = "jig.stl";  // as loaded from a scene file
  jig.mesh = core::make_box_mesh(crate.box_size);
  for (const online::SceneObstacle& obstacle : {crate, jig}) {
    online::Scene s = f.scene;
    s.obstacles.push_back(obstacle);
    const auto report = f.run(m, s);
    ASSERT_TRUE(has(report, "collision")) << obstacle.name << ": " << describe(report);
    EXPECT_NE(report.violations.front().detail.find("obstacle/" + obstacle.name), std::string::npos)
        << describe(report);
  }
}

TEST(Validator, FinishedBoardsStandWhereTheSceneSays) {
  Fixture f;
  // The base finished at a measured pose (not its target): lying on the table under the
  // left arm. A TCP pushed to the board's mid-plane collides with it there.
  online::Scene s = f.scene.with_finished(cabinet(), "base");
  s.finished.front().pose = core::Pose(Eigen::Translation3d(0.40, 0.20, 1.100));
  const Eigen::VectorXd above = f.left_at({0.40, 0.20, 1.35});
  const Eigen::VectorXd into = f.left_at({0.40, 0.20, 1.100});
  const auto report = f.run(slow_motion("left", {above, into}), s);
  ASSERT_TRUE(has(report, "collision")) << describe(report);
  EXPECT_NE(report.violations.front().detail.find("base"), std::string::npos) << describe(report);
  // At its target instead, the base is out of this motion's way.
  const auto at_target =
      f.run(slow_motion("left", {above, into}), f.scene.with_finished(cabinet(), "base"));
  for (const auto& v : at_target.violations) {
    EXPECT_EQ(v.detail.find("base"), std::string::npos) << v.detail;
  }
}

// The boards not yet handled stand in the stack where the scene has them (detected, else
// nominal), under the board being handled: the laterals are longer than the base on top, so a
// TCP pushed down beside the base's end meets lateral_right, the next board down.
TEST(Validator, BoardsStillInTheStackAreObstaclesWhereTheSceneHasThem) {
  Fixture f;
  const auto check = [&](const online::Scene& s, const online::Motion& m) {
    const online::World world(*f.cell, cabinet(), s, "base");
    core::CollisionData data = world.make_data();
    return online::validate_motion(world, data, m);
  };
  const Eigen::Vector3d beside_base(0.30, -0.035, 1.141);  // lateral_right's mid-plane
  const Eigen::VectorXd above = f.left_at(beside_base + Eigen::Vector3d(0.0, 0.0, 0.2));
  const Eigen::VectorXd into = f.left_at(beside_base);
  online::Motion m = slow_motion("left", {above, into});
  m.board_world = cabinet().part("base").initial;
  const auto report = check(f.scene, m);
  ASSERT_TRUE(has(report, "collision")) << describe(report);
  EXPECT_NE(report.violations.front().detail.find("stack/lateral_right"), std::string::npos)
      << describe(report);
  // Detected 40 cm further along the table, lateral_right is out of this motion's way.
  online::Scene moved = f.scene;
  moved.detected["lateral_right"] = cabinet().part("lateral_right").initial;
  moved.detected["lateral_right"].translation().x() += 0.40;
  for (const auto& v : check(moved, m).violations) {
    EXPECT_EQ(v.detail.find("lateral_right"), std::string::npos) << v.detail;
  }
  // Finished, it stands in the assembly instead.
  for (const auto& v : check(f.scene.with_finished(cabinet(), "lateral_right"), m).violations) {
    EXPECT_EQ(v.detail.find("stack/lateral_right"), std::string::npos) << v.detail;
  }
}

// A board held into the gripper's palm: the gripper and its load move as one piece, so the
// contact is at every sample, and the validator reports it with the pair it is between.
TEST(Validator, ABoardHeldIntoThePalmCollidesAtEverySample) {
  Fixture f;
  const Eigen::VectorXd start = f.left_at({0.35, 0.20, 1.35});
  Eigen::VectorXd end = start;
  end[5] += 0.5;  // the wrist turns the held board about the TCP
  online::Motion m = slow_motion("left", {start, end});
  m.holds_board = true;
  m.board_in_tcp = core::Pose(Eigen::Translation3d(0.0, 0.0, 0.15));  // below the pads: clear
  const auto clear = f.run(m);
  EXPECT_FALSE(has(clear, "collision")) << describe(clear);
  m.board_in_tcp = core::Pose(Eigen::Translation3d(0.0, 0.0, -0.1));  // into the palm
  const auto into = f.run(m);
  ASSERT_TRUE(has(into, "collision")) << describe(into);
  EXPECT_EQ(into.violations.front().detail, "left_gripper_palm vs board") << describe(into);
  EXPECT_EQ(into.violations.front().time, 0.0) << "from the first sample on";
}
