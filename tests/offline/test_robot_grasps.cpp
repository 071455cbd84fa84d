#include <gtest/gtest.h>

#include <cmath>

#include "hila/core/collision.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/offline/robot_grasps.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

struct Board {
  core::TriangleMesh mesh;
  offline::PartAnalysis analysis;
  double mass = 0.0;
  std::vector<db::RobotGraspRecord> grasps;
};

Board plan(const std::string& file, double mass, std::uint64_t seed = 1) {
  Board b;
  b.mesh = core::load_mesh(test::data_path("cabinet/" + file), 0.001);
  b.mass = mass;
  b.analysis = offline::analyze_part(file, b.mesh, mass);
  offline::RobotGraspSettings settings;
  settings.seed = seed;
  b.grasps =
      offline::plan_robot_grasps(b.mesh, b.analysis, mass, *test::reference_cell(), settings);
  return b;
}

const Board& shelf() {
  static const Board b = plan("shelf.stl", 0.8);
  return b;
}
const Board& back_panel() {
  static const Board b = plan("back_panel.stl", 0.22);
  return b;
}
const Board& lateral() {
  static const Board b = plan("lateral.stl", 1.8);
  return b;
}

// The gripper straight from the URDF (independent of offline::gripper_geometry): every link below
// the left flange, posed for the grasp's TCP at the jaw opening the planner uses.
// `support`: a box (world = part frame) the part rests on, checked too; size zero: none.
bool gripper_collides_independently(const Board& board, const db::RobotGraspRecord& g,
                                    const core::Pose& support = core::Pose::Identity(),
                                    const Eigen::Vector3d& support_size = Eigen::Vector3d::Zero()) {
  const auto cell = test::reference_cell();
  const core::Arm& arm = cell->arm("left");
  const core::RobotModel& robot = cell->robot();
  const double opening = std::min(g.jaw_width + offline::RobotGraspSettings{}.opening_margin,
                                  cell->spec().gripper.jaw_max);
  std::vector<core::Pose> links;
  robot.link_poses(cell->home_configuration(opening), links);
  const core::Pose part_from_world = g.tcp * links[robot.link_index(arm.spec.tip_link)].inverse();
  core::CollisionModel model;
  model.add_mesh_body("part", board.mesh, true);
  if (support_size.minCoeff() > 0.0) {
    core::GeometrySpec box;
    box.box_size = support_size;
    model.add_body("support", {box}, true, support);
  }
  std::vector<int> bodies;
  std::vector<int> stack{robot.link_index(arm.spec.flange_link)};
  while (!stack.empty()) {
    const int link = stack.back();
    stack.pop_back();
    for (int j : robot.links()[link].child_joints) stack.push_back(robot.joints()[j].child_link);
    if (robot.links()[link].collisions.empty()) continue;
    bodies.push_back(model.add_body(robot.links()[link].name, robot.links()[link].collisions, false,
                                    part_from_world * links[link]));
  }
  for (int a : bodies) {
    for (int b : bodies) {
      if (a != b) model.allow(a, b);
    }
  }
  core::CollisionData data(model);
  return core::in_collision_brute_force(model, data);
}

}  // namespace

TEST(RobotGrasps, EveryGraspIsAntipodalInsideTheFrictionConeAndTheJawRange) {
  const auto& gripper = test::reference_cell()->spec().gripper;
  const double cos_cone = std::cos(std::atan(gripper.pad.friction));
  for (const Board* board : {&shelf(), &back_panel(), &lateral()}) {
    ASSERT_FALSE(board->grasps.empty());
    for (const auto& g : board->grasps) {
      const Eigen::Vector3d d = g.contact_2 - g.contact_1;
      const Eigen::Vector3d axis = d.normalized();
      EXPECT_NEAR(d.norm(), g.jaw_width, 1e-9);
      EXPECT_GE(-g.normal_1.dot(axis), cos_cone - 1e-12);
      EXPECT_GE(g.normal_2.dot(axis), cos_cone - 1e-12);
      EXPECT_LE(g.jaw_width, gripper.jaw_max - offline::RobotGraspSettings{}.opening_margin);
      EXPECT_GE(g.jaw_width, gripper.jaw_min);
      // The TCP sits between the contacts with its opening axis along the contact line (the
      // boards' fingertips never reach past them: no grasp is set back).
      EXPECT_LT((g.tcp.translation() - 0.5 * (g.contact_1 + g.contact_2)).norm(), 1e-9);
      EXPECT_GT(std::abs(g.tcp.linear().col(1).dot(axis)), 1 - 1e-9);
      EXPECT_TRUE(core::is_valid_pose(g.tcp, 1e-9));
    }
  }
}

TEST(RobotGrasps, AnIndependentFclCheckConfirmsEveryGraspCollisionFree) {
  for (const Board* board : {&shelf(), &back_panel()}) {
    for (const auto& g : board->grasps) {
      ASSERT_FALSE(gripper_collides_independently(*board, g)) << "grasp id " << g.id;
    }
  }
}

TEST(RobotGrasps, TenAndThreeMillimetreBoardsGetEdgeGraspsAllAroundTheRim) {
  for (const Board* board : {&shelf(), &back_panel(), &lateral()}) {
    const Eigen::Vector3d half = 0.5 * (board->mesh.max_corner() - board->mesh.min_corner());
    // Edges: +x, -x (short edges), +y, -y (long edges) of the board in its mesh frame.
    int edges_with_grasps = 0;
    for (int axis = 0; axis < 2; ++axis) {
      for (const double side : {-1.0, 1.0}) {
        bool found = false;
        for (const auto& g : board->grasps) {
          const Eigen::Vector3d c = g.tcp.translation();
          const bool across_thickness = std::abs(g.tcp.linear().col(1).z()) > 0.99;
          if (across_thickness && std::abs(side * half[axis] - c[axis]) < 0.04) found = true;
        }
        edges_with_grasps += found ? 1 : 0;
        EXPECT_TRUE(found) << "no edge grasp on side " << side << " of axis " << axis;
      }
    }
    EXPECT_EQ(edges_with_grasps, 4);
  }
}

TEST(RobotGrasps, ThetaCOfEveryGraspEqualsTheClosedForm) {
  const auto cell = test::reference_cell();
  const double capacity = cell->spec().gripper.friction_torque_capacity;
  for (const Board* board : {&shelf(), &lateral(), &back_panel()}) {
    for (const auto& g : board->grasps) {
      const Eigen::Vector3d axis = (g.contact_2 - g.contact_1).normalized();
      const Eigen::Vector3d r =
          board->analysis.mass_properties.com - 0.5 * (g.contact_1 + g.contact_2);
      EXPECT_NEAR(g.lever, (r - r.dot(axis) * axis).norm(), 1e-12);
      const double ratio = capacity / (board->mass * cell->spec().gravity * g.lever);
      const double expected =
          ratio >= 1.0 ? 90.0 : std::floor(core::rad_to_deg(std::asin(ratio)) + 1e-12);
      EXPECT_EQ(g.theta_c_deg, expected) << "lever " << g.lever;
      EXPECT_NEAR(g.friction_torque_capacity, capacity, 1e-12);
    }
  }
}

TEST(RobotGrasps, PaperRelaxationLimitsAtTheMiddleOfTheEdges) {
  // Paper §VII with the grasp axis at the rim of the board (its idealised grasp point).
  const auto cell = test::reference_cell();
  const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d com = Eigen::Vector3d::Zero();
  EXPECT_EQ(offline::grasp_theta_c(*cell, 0.8, com, {0, 0.144, 0}, z), 62.0);   // long edge
  EXPECT_EQ(offline::grasp_theta_c(*cell, 0.8, com, {0.195, 0, 0}, z), 40.0);   // short edge
  EXPECT_EQ(offline::grasp_theta_c(*cell, 1.8, com, {0, 0.1475, 0}, z), 22.0);  // lateral, long
  EXPECT_EQ(offline::grasp_theta_c(*cell, 0.22, com, {0, 0.14, 0}, z), 90.0);   // back panel
  // The planner's grasps sit inside the rim, so their levers and limits bracket these.
  double tightest = 90.0;
  for (const auto& g : lateral().grasps) tightest = std::min(tightest, g.theta_c_deg);
  EXPECT_LE(tightest, 22.0);  // short-edge grasps of the 1.8 kg board are tighter still
}

TEST(RobotGrasps, SortedByQualityAndDeterministicForASeed) {
  const auto& g = shelf().grasps;
  for (std::size_t i = 1; i < g.size(); ++i) EXPECT_GE(g[i - 1].quality, g[i].quality);
  const Board again = plan("shelf.stl", 0.8, 1);
  ASSERT_EQ(again.grasps.size(), g.size());
  for (std::size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(again.grasps[i].tcp.matrix(), g[i].tcp.matrix());
  }
  const Board other = plan("shelf.stl", 0.8, 2);
  bool differs = other.grasps.size() != g.size();
  for (std::size_t i = 0; !differs && i < g.size(); ++i) {
    differs = other.grasps[i].tcp.matrix() != g[i].tcp.matrix();
  }
  EXPECT_TRUE(differs);
}

TEST(RobotGrasps, NearDuplicatesAreMerged) {
  const auto& g = shelf().grasps;
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (std::size_t k = i + 1; k < g.size(); ++k) {
      const bool close = (g[i].tcp.translation() - g[k].tcp.translation()).norm() <= 0.01;
      const bool aligned =
          core::rotation_distance(g[i].tcp.linear(), g[k].tcp.linear()) <= core::deg_to_rad(20.0);
      EXPECT_FALSE(close && aligned) << i << " and " << k;
    }
  }
}

TEST(RobotGrasps, GripperGeometrySeparatesTheFingers) {
  const auto hand = offline::gripper_geometry(*test::reference_cell(), "left");
  EXPECT_EQ(hand.finger_pos.size(), 2u);  // finger body and pad
  EXPECT_EQ(hand.finger_neg.size(), 2u);
  EXPECT_GE(hand.fixed.size(), 2u);  // sensor and palm
  for (const auto& s : hand.finger_pos) EXPECT_GT(s.origin.translation().y(), 0.0);
  for (const auto& s : hand.finger_neg) EXPECT_LT(s.origin.translation().y(), 0.0);
}

TEST(RobotGrasps, APartWiderThanTheJawEverywhereHasNoGrasp) {
  const core::TriangleMesh cube = core::make_box_mesh({0.2, 0.2, 0.2});
  const auto analysis = offline::analyze_part("cube", cube, 1.0);
  offline::RobotGraspSettings settings;
  settings.samples = 300;
  EXPECT_TRUE(
      offline::plan_robot_grasps(cube, analysis, 1.0, *test::reference_cell(), settings).empty());
}

TEST(RobotGrasps, FingerReachIsTheFingertipsDistanceAlongTheApproach) {
  // The URDF's finger box ends 0.175 m past the palm, the palm 0.05 m past the flange (F/T
  // sensor), the TCP 0.20 m past the flange: 0.025 m.
  const auto hand = offline::gripper_geometry(*test::reference_cell(), "left");
  EXPECT_NEAR(offline::finger_reach(hand), 0.025, 1e-12);
}

TEST(RobotGrasps, ASmallBlockOnTheTableIsTakenAtTheFingertips) {
  // A 60 x 40 x 20 mm block resting on its 60 x 40 face: with the contact at the pads' centre
  // the fingers reach 25 mm past it, through the table under it (10 mm below the contact).
  Board block;
  block.mesh = core::make_box_mesh({0.06, 0.04, 0.02});
  block.mass = 0.05;
  block.analysis = offline::analyze_part("block", block.mesh, block.mass);
  offline::RobotGraspSettings settings;
  block.grasps = offline::plan_robot_grasps(block.mesh, block.analysis, block.mass,
                                            *test::reference_cell(), settings);
  ASSERT_FALSE(block.grasps.empty());
  const auto& pad = test::reference_cell()->spec().gripper.pad;
  const double max_shift = 0.5 * pad.length - settings.tip_margin;
  // The table: a slab whose top touches the block's bottom face (z = -0.01).
  const core::Pose table = core::make_pose(Eigen::Vector3d(0, 0, -0.01 - 0.05));
  const Eigen::Vector3d table_size(1.0, 1.0, 0.1 - 1e-4);
  int from_above = 0;
  int shifted = 0;
  for (const auto& g : block.grasps) {
    // The contact stays on the pads: on the approach axis, between the TCP and the fingertips.
    const Eigen::Vector3d centre = 0.5 * (g.contact_1 + g.contact_2);
    const Eigen::Vector3d z = g.tcp.linear().col(2);
    const double shift = (centre - g.tcp.translation()).dot(z);
    EXPECT_LT((centre - g.tcp.translation() - shift * z).norm(), 1e-9);
    EXPECT_GE(shift, -1e-12);
    EXPECT_LE(shift, max_shift + 1e-12);
    shifted += shift > 1e-9 ? 1 : 0;
    EXPECT_FALSE(gripper_collides_independently(block, g)) << "grasp " << g.id;
    // Straight down onto the block: the fingers end above the table wherever the pads allow
    // them to (the contact high enough on the block's side), and strike it elsewhere.
    if (z.dot(-Eigen::Vector3d::UnitZ()) > 0.99) {
      const double height = centre.z() + 0.01;  // of the contact above the table
      const double tips = height - (0.025 - shift);  // of the fingertips above the table
      EXPECT_EQ(gripper_collides_independently(block, g, table, table_size), tips < 0.0)
          << "grasp " << g.id << " at " << height << " m, set back " << shift << " m";
      if (0.025 + settings.tip_clearance - height <= max_shift) {
        ++from_above;  // the pads allow the clearance: the grasp has it
        EXPECT_NEAR(tips, settings.tip_clearance, 1e-9) << "grasp " << g.id;
      }
    }
  }
  EXPECT_GT(from_above, 0);
  EXPECT_GT(shifted, 0);
}
