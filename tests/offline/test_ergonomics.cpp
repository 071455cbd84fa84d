#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>

#include "hila/core/human_body.hpp"
#include "hila/core/mesh_symmetry.hpp"
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
