#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "hila/core/collision.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/mesh_symmetry.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/product.hpp"
#include "hila/offline/ergonomics.hpp"
#include "hila/offline/handover.hpp"
#include "hila/offline/human_grasps.hpp"
#include "hila/offline/part_analysis.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// Maps with fewer samples than the default: sparse, but the posture search confirms every
// candidate by direct IK, so they only steer it.
const offline::HumanComfort& comfort() {
  static const offline::HumanComfort c = [] {
    const auto cell = test::reference_cell();
    std::vector<core::ComfortMap> maps;
    core::ComfortMapSettings s;
    s.samples = 300000;
    for (const auto& arm : cell->human_arms())
      maps.push_back(core::ComfortMap::build(arm.chain, s));
    return offline::HumanComfort(*cell, maps);
  }();
  return c;
}

struct Board {
  core::PartSpec spec;
  offline::PartAnalysis analysis;
  std::vector<db::HumanGraspRecord> grasps;
  std::vector<int> one_hand;
};

Board shelf_board() {
  static const core::ProductSpec product = core::load_product(test::product_path());
  Board b;
  b.spec = product.part("back_lower");  // 0.22 kg: one hand holds it
  b.analysis = offline::analyze_part(b.spec.name, b.spec.mesh, b.spec.mass);
  offline::HumanGraspSettings s;
  s.samples = 300;
  b.grasps = offline::plan_human_grasps(b.analysis.mesh, b.analysis, b.spec.mass,
                                        *test::reference_cell(), s);
  for (std::size_t g = 0; g < b.grasps.size(); ++g) {
    if (b.grasps[g].one_hand_stable) b.one_hand.push_back(static_cast<int>(g));
  }
  return b;
}

// The shelf board taken a quarter turn about `axis` (world) off its fitted orientation, the worker
// at the cell's stance: what the turn tests turn back.
struct QuarterTurned {
  Board b;
  std::vector<Eigen::Matrix3d> symmetries;
  core::Pose stance;
  Eigen::Matrix3d target;
  core::Pose taken;
};

QuarterTurned quarter_turned(const core::Cell& cell, const Eigen::Vector3d& axis) {
  QuarterTurned q{shelf_board(),
                  {},
                  cell.spec().human_stance,
                  Eigen::Matrix3d::Identity(),
                  core::Pose::Identity()};
  q.symmetries = core::mesh_symmetries(q.b.spec.mesh);
  q.target = q.b.spec.target.linear();
  q.taken = q.b.spec.target;
  q.taken.linear() = Eigen::AngleAxisd(0.5 * M_PI, axis) * q.target;
  return q;
}

// The board at its target and in the stack, laid on its first stable placement, with its human
// grasps: the inputs evaluate_ergonomics takes (the cell's human at the cell's stance).
offline::ErgonomicsInputs inputs_of(const Board& b) {
  offline::ErgonomicsInputs in;
  in.target = b.spec.target;
  in.initial = b.spec.initial;
  in.has_placement = true;
  in.table_placement = b.analysis.placements.front().part_in_plane;
  in.human_grasps = &b.grasps;
  return in;
}

// Shoulder of the human arm in the world, by the human model's own FK at the neutral posture
// bent by `flexion_deg` (an independent path from the posture search's).
Eigen::Vector3d shoulder_in_world(const core::Cell& cell, int arm, double flexion_deg) {
  Eigen::VectorXd q = cell.human_neutral();
  q[cell.human()
        .joints()[static_cast<std::size_t>(cell.human().joint_index("torso_flexion"))]
        .variable] = core::deg_to_rad(flexion_deg);
  std::vector<core::Pose> links;
  cell.human().link_poses(q, links);
  const auto& chain = cell.human_arms()[static_cast<std::size_t>(arm)].chain;
  const auto torso = links[static_cast<std::size_t>(cell.human().link_index(chain.base_link()))];
  return cell.spec().human_stance * torso * chain.first_joint_position();
}

}  // namespace

TEST(Ergonomics, BoardHeldInFrontAtWaistHeightNeedsNoBendAndReachIsShoulderToHand) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  // Flat, 35 cm in front of the human, 10 cm above the table.
  core::Pose board = core::Pose::Identity();
  board.translation() = cell->spec().human_stance * Eigen::Vector3d(0.35, 0.0, 1.10);
  const offline::ErgonomicsSettings settings;
  const auto p = offline::receiving_posture(*cell, comfort(), cell->spec().human_stance, board,
                                            b.grasps, b.one_hand, -1, settings);
  ASSERT_TRUE(p.reachable);
  EXPECT_EQ(p.torso_flexion_deg, 0.0);
  EXPECT_FALSE(p.shoulder_elevated);
  const Eigen::Vector3d hand =
      (board * b.grasps[static_cast<std::size_t>(p.grasp)].hand).translation();
  EXPECT_NEAR(p.reach, (hand - shoulder_in_world(*cell, p.arm, 0.0)).norm(), 1e-9);
  EXPECT_LT(p.reach, 0.8);
  EXPECT_GT(p.quality, 0.0);
  // The posture's joints put the hand on the grasp (direct FK of the arm).
  const auto& arm = cell->human_arms()[static_cast<std::size_t>(p.arm)];
  const core::Pose base = comfort().arm_base(p.arm);
  EXPECT_LT(((base * arm.chain.fk(p.arm_joints)).translation() - hand).norm(), 1e-4);
}

TEST(Ergonomics, BoardOnTheStackFarAcrossTheTableNeedsABend) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  core::Pose stance = cell->spec().human_stance;
  stance.translation().y() = b.spec.initial.translation().y();
  const auto p = offline::receiving_posture(*cell, comfort(), stance, b.spec.initial, b.grasps,
                                            b.one_hand, -1, offline::ErgonomicsSettings{});
  if (p.reachable) {
    EXPECT_GE(p.torso_flexion_deg, 20.0);
  }
  // Upright, the board on the stack is out of reach: no grasp's hand pose has an IK solution.
  offline::ErgonomicsSettings upright;
  upright.flexion_step_deg = 1000.0;  // only 0 degrees
  EXPECT_FALSE(offline::receiving_posture(*cell, comfort(), stance, b.spec.initial, b.grasps,
                                          b.one_hand, -1, upright)
                   .reachable);
}

TEST(Ergonomics, TableDropPoseLiesFlatOnTheTableAtTheSpot) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  const offline::ErgonomicsSettings settings;
  const core::Pose pose =
      offline::table_drop_pose(*cell, b.analysis.placements.front().part_in_plane, settings);
  // The lowest vertex touches the table top (z = 1.094) and the longest side runs along y.
  double lowest = 1e9;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const auto& v : b.analysis.mesh.vertices) {
    const Eigen::Vector3d w = pose * v;
    lowest = std::min(lowest, w.z());
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  EXPECT_NEAR(lowest, 1.094, 1e-6);
  EXPECT_GT(hi.y() - lo.y(), hi.x() - lo.x());
  EXPECT_NEAR(0.5 * (lo.x() + hi.x()), settings.table_spot_x, 1e-6);
  EXPECT_NEAR(0.5 * (lo.y() + hi.y()), settings.table_spot_y, 1e-6);
}

// evaluate_ergonomics with `postures`: each record's posture beside it, in the same order, and
// the same records as without; evaluated again with the same inputs and seed, the same records
// (what `hila report ergonomics` relies on to find the stored postures' joints).
TEST(Ergonomics, EvaluateReturnsEachRecordsPostureAndRepeatsItself) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  offline::ErgonomicsInputs in = inputs_of(b);
  offline::ErgonomicsSettings settings;
  settings.seed = 11;
  std::vector<offline::Posture> postures{offline::Posture{}};  // cleared first
  const auto with = offline::evaluate_ergonomics(*cell, comfort(), in, settings, &postures);
  const auto without = offline::evaluate_ergonomics(*cell, comfort(), in, settings);
  ASSERT_EQ(with.size(), 2u);  // table and alone (no goal)
  ASSERT_EQ(postures.size(), with.size());
  ASSERT_EQ(without.size(), with.size());
  for (std::size_t i = 0; i < with.size(); ++i) {
    SCOPED_TRACE(with[i].method);
    const offline::Posture& p = postures[i];
    EXPECT_EQ(p.reachable, with[i].reachable);
    ASSERT_TRUE(p.reachable);
    EXPECT_EQ(comfort().arm_name(p.arm), with[i].arm);
    EXPECT_EQ(p.torso_flexion_deg, with[i].torso_flexion_deg);
    EXPECT_EQ(p.quality, with[i].quality);
    EXPECT_EQ(p.arm_joints.size(), cell->human_arms()[static_cast<std::size_t>(p.arm)].chain.dof());
    EXPECT_EQ(without[i].method, with[i].method);
    EXPECT_EQ(without[i].arm, with[i].arm);
    EXPECT_EQ(without[i].torso_flexion_deg, with[i].torso_flexion_deg);
    EXPECT_EQ(without[i].quality, with[i].quality);
  }
  EXPECT_EQ(with[0].method, "table");
  EXPECT_EQ(with[1].method, "alone");
}

// The re-orientation left counts the part's symmetries: the shelf (a box) whose target is its
// initial pose turned by a half turn about its normal needs none, with its symmetries; without
// them (an asymmetric part) the whole half turn.
TEST(Ergonomics, ReorientationIsModuloThePartsSymmetries) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  offline::ErgonomicsInputs in;
  in.initial = b.spec.initial;
  in.target = b.spec.initial;
  in.target.linear() = b.spec.initial.linear() *
                       Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  in.human_grasps = &b.grasps;
  const auto plain = offline::evaluate_ergonomics(*cell, comfort(), in, {});
  in.symmetries = core::mesh_symmetries(b.spec.mesh);
  ASSERT_EQ(in.symmetries.size(), 4u);
  const auto modulo = offline::evaluate_ergonomics(*cell, comfort(), in, {});
  ASSERT_EQ(plain.back().method, "alone");  // the board taken where it lies: only the turn left
  EXPECT_NEAR(plain.back().reorientation_deg, 180.0, 1e-6);
  EXPECT_NEAR(modulo.back().reorientation_deg, 0.0, 1e-6);
}

// A worker's own body (core::HumanBody): the posture at the table drop and at the stack is
// searched on that body's model. Its whole configuration puts the body's hand on the grasp (the
// body's forward kinematics from the stance), the reach is the body's shoulder to that hand, the
// torso joint holds the flexion found; a short woman and a tall man take the same boards with
// different postures, and the cell's own human as a body (same_as_cell) gets the cell human's.
TEST(Ergonomics, EachBodyTakesTheBoardWithItsOwnArms) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  offline::ErgonomicsInputs in = inputs_of(b);
  offline::ErgonomicsSettings settings;
  settings.seed = 11;
  std::vector<offline::Posture> cell_postures;
  const auto cell_records =
      offline::evaluate_ergonomics(*cell, comfort(), in, settings, &cell_postures);
  std::map<std::string, std::vector<offline::Posture>> by_body;
  for (const core::HumanBodySpec spec :
       {core::HumanBodySpec{core::kFemaleStatureP5, core::Sex::Female},
        core::HumanBodySpec{core::kTallStature, core::Sex::Male}}) {
    const core::HumanBody body(*cell, spec);
    SCOPED_TRACE(body.label());
    in.body = &body;
    std::vector<offline::Posture>& postures = by_body[body.label()];
    const auto records = offline::evaluate_ergonomics(*cell, comfort(), in, settings, &postures);
    ASSERT_EQ(records.size(), 2u);  // table and alone
    const int torso =
        body.model()
            .joints()[static_cast<std::size_t>(body.model().joint_index("torso_flexion"))]
            .variable;
    for (std::size_t k = 0; k < records.size(); ++k) {
      SCOPED_TRACE(records[k].method);
      const offline::Posture& p = postures[k];
      ASSERT_TRUE(p.reachable);
      ASSERT_EQ(p.q.size(), body.model().num_variables());
      EXPECT_NEAR(p.q[torso], core::deg_to_rad(p.torso_flexion_deg), 1e-12);
      const auto& arm = body.arms()[static_cast<std::size_t>(p.arm)];
      std::vector<core::Pose> links;
      body.model().link_poses(p.q, links);
      const core::Pose base =
          p.stance * links[static_cast<std::size_t>(body.model().link_index(arm.spec.base_link))];
      const Eigen::Vector3d hand = (base * arm.chain.fk(p.arm_joints)).translation();
      const Eigen::Vector3d grasp =
          (p.board * b.grasps[static_cast<std::size_t>(p.grasp)].hand).translation();
      EXPECT_LT((hand - grasp).norm(), 1e-4);
      EXPECT_NEAR(p.reach, (grasp - base * arm.chain.first_joint_position()).norm(), 1e-9);
    }
    // Alone, the body steps sideways to the stack; at the table it stands at the stance.
    EXPECT_TRUE(postures[0].stance.isApprox(cell->spec().human_stance, 1e-12));
    EXPECT_DOUBLE_EQ(postures[1].stance.translation().y(), b.spec.initial.translation().y());
  }
  // The two bodies' arms differ: so do their postures (reach and joints) at the same board.
  const auto& small = by_body.at("1.5 female");
  const auto& tall = by_body.at("1.95 male");
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_GT(std::abs(small[k].reach - tall[k].reach), 0.01) << k;
  }
  // The cell's own human as a body: the cell human's postures, exactly.
  const core::HumanBody cell_body(*cell, core::HumanBodySpec{});
  ASSERT_TRUE(cell_body.same_as_cell());
  in.body = &cell_body;
  std::vector<offline::Posture> same;
  const auto same_records = offline::evaluate_ergonomics(*cell, comfort(), in, settings, &same);
  ASSERT_EQ(same_records.size(), cell_records.size());
  for (std::size_t k = 0; k < same.size(); ++k) {
    EXPECT_EQ(same[k].arm_joints, cell_postures[k].arm_joints);
    EXPECT_EQ(same_records[k].torso_flexion_deg, cell_records[k].torso_flexion_deg);
    EXPECT_EQ(same_records[k].quality, cell_records[k].quality);
  }
}

// The turn to the fitted orientation (turn_in_hands): a board taken as fitted, or turned by a
// symmetry of the part, has nothing to turn; one taken a quarter turn off is turned about its
// centre of mass, held at the turning point, in steps no larger than step_deg from the taken
// orientation to the fitted one, the angle the same as least_rotation_angle_deg's.
TEST(Ergonomics, TurnRunsFromTheTakenToTheFittedOrientationAboutTheCentre) {
  const auto cell = test::reference_cell();
  const Board b = shelf_board();
  const auto symmetries = core::mesh_symmetries(b.spec.mesh);
  const core::Pose stance = cell->spec().human_stance;
  const Eigen::Vector3d com = b.analysis.mass_properties.com;
  const offline::ErgonomicsSettings settings;
  offline::TurnSettings turn;
  turn.band_fractions = {0.5};
  turn.distances = {0.35};
  const Eigen::Matrix3d target = b.spec.target.linear();
  core::Pose as_fitted = b.spec.target;
  const offline::Turn none =
      offline::turn_in_hands(*cell, comfort(), stance, as_fitted, target, symmetries, com, nullptr,
                             b.grasps, b.one_hand, settings, turn);
  EXPECT_NEAR(none.turned_deg, 0.0, 1e-9);
  EXPECT_TRUE(none.postures.empty());
  core::Pose half_turned = as_fitted;
  half_turned.linear() = target * symmetries.back();  // the same part
  EXPECT_TRUE(offline::turn_in_hands(*cell, comfort(), stance, half_turned, target, symmetries, com,
                                     nullptr, b.grasps, b.one_hand, settings, turn)
                  .postures.empty());

  core::Pose quarter = as_fitted;
  quarter.linear() = Eigen::AngleAxisd(0.5 * M_PI, Eigen::Vector3d::UnitY()) * target;
  const offline::Turn t =
      offline::turn_in_hands(*cell, comfort(), stance, quarter, target, symmetries, com, nullptr,
                             b.grasps, b.one_hand, settings, turn);
  EXPECT_NEAR(t.turned_deg, core::least_rotation_angle_deg(quarter.linear(), target, symmetries),
              1e-9);
  EXPECT_NEAR(t.turned_deg, 90.0, 1e-6);
  ASSERT_EQ(t.boards.size(), 7u);  // 90 degrees in 15-degree steps, both ends
  ASSERT_EQ(t.postures.size(), t.boards.size());
  const core::HeightBand band = core::natural_height_band(*cell, nullptr, stance);
  EXPECT_NEAR(t.point.z(), 0.5 * (band.hip_z + band.shoulder_z), 1e-12);
  EXPECT_NEAR((t.point - stance.translation()).head<2>().norm(), 0.35, 1e-12);
  EXPECT_LT(core::rotation_distance(t.boards.front().linear(), quarter.linear()), 1e-9);
  EXPECT_LT(core::least_rotation_angle_deg(t.boards.back().linear(), target, symmetries), 1e-6);
  for (std::size_t k = 0; k < t.boards.size(); ++k) {
    EXPECT_LT((t.boards[k] * com - t.point).norm(), 1e-9);
    if (k > 0) {
      EXPECT_LE(
          core::rad_to_deg(core::rotation_distance(t.boards[k - 1].linear(), t.boards[k].linear())),
          turn.step_deg + 1e-6);
    }
  }
}

// The elbow-up steps of a turn are those whose posture raises an elbow to the shoulder, recomputed
// here by the human model's FK from the returned configurations; a turning point above the
// worker's shoulder raises it where one in the lower band does not.
TEST(Ergonomics, TurnCountsTheStepsWithTheElbowAtOrAboveTheShoulder) {
  const auto cell = test::reference_cell();
  const auto [b, symmetries, stance, target, taken] =
      quarter_turned(*cell, Eigen::Vector3d::UnitX());
  const core::RobotModel& human = cell->human();
  auto elbow_up_by_fk = [&](const offline::Posture& p) {
    std::vector<core::Pose> links;
    human.link_poses(p.q, links);
    const auto& names = cell->human_arms()[static_cast<std::size_t>(p.arm)].chain.joint_names();
    auto z_of = [&](const std::string& joint) {
      const auto& j = human.joints()[static_cast<std::size_t>(human.joint_index(joint))];
      return (p.stance * links[static_cast<std::size_t>(j.child_link)]).translation().z();
    };
    std::string elbow;
    for (const auto& n : names) {
      if (n.find("elbow") != std::string::npos) elbow = n;
    }
    return z_of(elbow) >= z_of(names.front());
  };
  std::map<double, int> elevated;
  for (const double fraction : {0.3, 1.5}) {
    offline::TurnSettings turn;
    turn.band_fractions = {fraction};
    turn.distances = {0.30};
    const offline::Turn t = offline::turn_in_hands(
        *cell, comfort(), stance, taken, target, symmetries, b.analysis.mass_properties.com,
        nullptr, b.grasps, b.one_hand, offline::ErgonomicsSettings{}, turn);
    ASSERT_FALSE(t.postures.empty());
    int by_fk = 0;
    for (const offline::Posture& p : t.postures) {
      if (p.reachable) by_fk += elbow_up_by_fk(p) ? 1 : 0;
    }
    EXPECT_EQ(t.elevated_steps, by_fk) << "band fraction " << fraction;
    elevated[fraction] = t.elevated_steps;
  }
  EXPECT_EQ(elevated[0.3], 0);
  EXPECT_GT(elevated[1.5], 0);
}

// With the board's mesh, each step of a turn is checked against the worker's body: the board held
// at its posture, against the human model's torso and base (legs and hips) by FCL's narrow phase
// pair by pair, in a collision model built here. Turned with its centre 0.12 m in front of the
// stance (inside the torso), every step found blocked is blocked by the reference and some are;
// 0.60 m in front, none is. Without the mesh nothing is checked. Offered both points, the turn is
// scored at the clear one.
TEST(Ergonomics, TurnChecksTheBoardAgainstTheWorkersBody) {
  const auto cell = test::reference_cell();
  const auto [b, symmetries, stance, target, taken] =
      quarter_turned(*cell, Eigen::Vector3d::UnitY());
  const Eigen::Vector3d com = b.analysis.mass_properties.com;
  const offline::ErgonomicsSettings settings;
  // The reference: the board against the torso and the base alone.
  const core::RobotModel& human = cell->human();
  core::CollisionModel reference;
  const core::RobotBodies bodies = core::add_robot(reference, human, "human/");
  const int board = reference.add_mesh_body("board", b.spec.mesh, false);
  for (int body = 0; body < reference.num_bodies(); ++body) {
    const std::string& name = reference.body_name(body);
    if (body != board && name != "human/torso" && name != "human/base") {
      reference.set_enabled(body, false);
    }
  }
  core::CollisionData data(reference);
  auto in_body = [&](const offline::Posture& p, const core::Pose& pose) {
    std::vector<core::Pose> links;
    human.link_poses(p.q, links);
    core::set_robot_pose(data, bodies, links, p.stance);
    data.set_body_pose(board, pose);
    return core::in_collision_brute_force(reference, data, {board});
  };
  std::map<double, int> blocked;
  for (const double distance : {0.12, 0.60}) {
    offline::TurnSettings turn;
    turn.band_fractions = {0.6};
    turn.distances = {distance};
    const offline::Turn t =
        offline::turn_in_hands(*cell, comfort(), stance, taken, target, symmetries, com,
                               &b.spec.mesh, b.grasps, b.one_hand, settings, turn);
    ASSERT_EQ(t.blocked.size(), t.postures.size());
    int by_reference = 0;
    for (std::size_t k = 0; k < t.postures.size(); ++k) {
      const offline::Posture& p = t.postures[k];
      const bool expected = p.reachable && in_body(p, t.boards[k]);
      EXPECT_EQ(t.blocked[k], expected) << "distance " << distance << " step " << k;
      by_reference += expected ? 1 : 0;
    }
    EXPECT_EQ(t.blocked_steps, by_reference);
    EXPECT_EQ(t.feasible(), t.reachable && by_reference == 0);
    blocked[distance] = t.blocked_steps;
    if (distance < 0.5) {
      const offline::Turn unchecked =
          offline::turn_in_hands(*cell, comfort(), stance, taken, target, symmetries, com, nullptr,
                                 b.grasps, b.one_hand, settings, turn);
      EXPECT_EQ(unchecked.blocked_steps, 0);
    }
  }
  EXPECT_GT(blocked[0.12], 0);
  EXPECT_EQ(blocked[0.60], 0);
  offline::TurnSettings both;
  both.band_fractions = {0.6};
  both.distances = {0.12, 0.60};
  const offline::Turn chosen =
      offline::turn_in_hands(*cell, comfort(), stance, taken, target, symmetries, com, &b.spec.mesh,
                             b.grasps, b.one_hand, settings, both);
  EXPECT_NEAR((chosen.point - stance.translation()).head<2>().norm(), 0.60, 1e-12);
}
