#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "hila/core/comfort.hpp"
#include "hila/core/product.hpp"
#include "hila/core/receiving_posture.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/offline/handover.hpp"
#include "hila/offline/human_grasps.hpp"
#include "hila/offline/part_analysis.hpp"
#include "hila/offline/robot_grasps.hpp"
#include "hila/offline/suction_grasps.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

const core::ProductSpec& product() {
  static const core::ProductSpec p = core::load_product(test::product_path());
  return p;
}

// Maps with a third of the default samples: sparser, which only makes S smaller.
const std::vector<core::ComfortMap>& comfort_maps() {
  static const std::vector<core::ComfortMap> maps = [] {
    const auto cell = test::reference_cell();
    std::vector<core::ComfortMap> m;
    core::ComfortMapSettings s;
    s.samples = 1000000;
    for (const auto& arm : cell->human_arms()) m.push_back(core::ComfortMap::build(arm.chain, s));
    return m;
  }();
  return maps;
}
const offline::HumanComfort& comfort() {
  static const offline::HumanComfort c(*test::reference_cell(), comfort_maps());
  return c;
}

// `human_samples`: fewer than the build's default keeps the cabinet's tests quick.
offline::BoardGrasps board_grasps(const core::ProductSpec& of, std::size_t index,
                                  int human_samples = 400) {
  const auto cell = test::reference_cell();
  const auto& part = of.parts[index];
  const auto analysis = offline::analyze_part(part.name, part.mesh, part.mass);
  offline::BoardGrasps g;
  g.robot = offline::plan_robot_grasps(analysis.mesh, analysis, part.mass, *cell, {});
  g.suction = offline::plan_suction_grasps(analysis.mesh, analysis, part.mass, *cell, {});
  offline::HumanGraspSettings human;
  human.samples = human_samples;
  g.human = offline::plan_human_grasps(analysis.mesh, analysis, part.mass, *cell, human);
  g.com = analysis.mass_properties.com;
  return g;
}
offline::BoardGrasps board_grasps(std::size_t index) {
  return board_grasps(product(), index);
}

// Oriented box of a board (its mesh's bounding box in the part frame, placed in the world).
struct Obb {
  Eigen::Vector3d centre;
  Eigen::Matrix3d axes;
  Eigen::Vector3d half;
};

Obb board_box(const core::PartSpec& part, const core::Pose& pose) {
  const Eigen::Vector3d lo = part.mesh.min_corner(), hi = part.mesh.max_corner();
  return {pose * (0.5 * (lo + hi)), pose.linear(), 0.5 * (hi - lo)};
}

// Separating-axis test of two oriented boxes (Gottschalk), with a small tolerance so touching
// faces do not count: independent of FCL.
bool boxes_overlap(const Obb& a, const Obb& b) {
  std::vector<Eigen::Vector3d> axes;
  for (int i = 0; i < 3; ++i) {
    axes.push_back(a.axes.col(i));
    axes.push_back(b.axes.col(i));
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d c = a.axes.col(i).cross(b.axes.col(j));
      if (c.norm() > 1e-9) axes.push_back(c.normalized());
    }
  }
  const Eigen::Vector3d d = b.centre - a.centre;
  for (const auto& axis : axes) {
    double ra = 0.0, rb = 0.0;
    for (int k = 0; k < 3; ++k) {
      ra += a.half[k] * std::abs(axis.dot(a.axes.col(k)));
      rb += b.half[k] * std::abs(axis.dot(b.axes.col(k)));
    }
    if (std::abs(axis.dot(d)) > ra + rb - 1e-6) return false;
  }
  return true;
}

double angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const double dot = std::abs(Eigen::Quaterniond(a).dot(Eigen::Quaterniond(b)));
  return 2.0 * std::acos(std::min(1.0, dot));
}

void check_stage(std::size_t index) {
  const auto cell = test::reference_cell();
  const auto& part = product().parts[index];
  const auto grasps = board_grasps(index);
  const offline::HandoverSettings settings;
  const auto result =
      offline::plan_handover_goals(*cell, product(), index, grasps, comfort(), settings);
  const auto& stage = result.stage;
  ASSERT_EQ(stage.failure, "") << part.name;
  ASSERT_GT(stage.goals, 0);
  const core::Pose target = product().target_in_world(part);

  // Every candidate satisfies Eq. 1, checked independently (quaternion angle, SAT boxes), but
  // for the band candidates drawn after them for a human without a natural goal: the part's
  // centre in the human's band, within natural_max_rotation_deg.
  EXPECT_GE(stage.candidates, settings.candidates);
  EXPECT_EQ(static_cast<int>(result.candidates.size()), stage.candidates);
  const core::HeightBand band =
      core::natural_height_band(*cell, nullptr, cell->spec().human_stance);
  int comfortable = 0, goals = 0;
  for (const auto& c : result.candidates) {
    const double angle = angle_between(c.board.linear(), target.linear());
    if (c.sample < settings.candidates) {
      EXPECT_LT(angle, core::deg_to_rad(settings.max_rotation_deg));
      EXPECT_LT((c.board.translation() - target.translation()).norm(), settings.max_offset);
    } else {
      EXPECT_LT(angle, core::deg_to_rad(settings.natural_max_rotation_deg));
      EXPECT_TRUE(band.contains((c.board * grasps.com).z())) << "candidate " << c.sample;
    }
    for (std::size_t f = 0; f < index; ++f) {
      const auto& other = product().parts[f];
      EXPECT_FALSE(boxes_overlap(board_box(part, c.board),
                                 board_box(other, product().target_in_world(other))))
          << "candidate " << c.sample << " overlaps " << other.name;
    }
    comfortable += c.status != "uncomfortable" ? 1 : 0;
    goals += c.status == "goal" ? 1 : 0;
    // A copy of an earlier candidate (the same pose) at the grasps the human takes it naturally
    // at is in S down to comfort_floor.
    const bool copy = std::any_of(result.candidates.begin(), result.candidates.begin() + c.sample,
                                  [&](const auto& o) { return o.board.isApprox(c.board, 0.0); });
    if (c.status != "uncomfortable") {
      EXPECT_GT(c.quality, copy ? settings.comfort_floor : settings.comfort_threshold);
    }
  }
  EXPECT_EQ(comfortable, stage.comfortable);
  EXPECT_EQ(goals, stage.goals);

  // Eq. 8: goals ranked by the distance, recomputed independently.
  std::vector<const db::HandoverCandidateRecord*> ranked;
  for (const auto& c : result.candidates) {
    if (c.status == "goal") ranked.push_back(&c);
  }
  std::sort(ranked.begin(), ranked.end(), [](auto* a, auto* b) { return a->rank < b->rank; });
  for (std::size_t r = 0; r < ranked.size(); ++r) {
    const auto& c = *ranked[r];
    EXPECT_EQ(c.rank, static_cast<int>(r));
    const double d = (c.board.translation() - target.translation()).norm() +
                     settings.rotation_weight * angle_between(c.board.linear(), target.linear());
    EXPECT_NEAR(c.distance, d, 1e-9);
    if (r > 0) {
      EXPECT_LE(ranked[r - 1]->distance, c.distance);
    }
  }

  // Every member of 𝕊 re-verified: FK (not IK) of the stored joints, joint limits, the slip
  // torque from the board's geometry, and a brute-force collision check of the whole scene.
  const core::Arm& receiving = cell->arm(settings.receiving_arm);
  const core::Arm& suction_arm = cell->arm(settings.suction_arm);
  const core::Pose receiving_base = core::arm_base_in_world(*cell, receiving);
  const core::Pose suction_base = core::arm_base_in_world(*cell, suction_arm);
  std::vector<core::PlacedPart> finished;
  for (std::size_t f = 0; f < index; ++f) {
    const auto& p = product().parts[f];
    finished.push_back({p.name, &p.mesh, product().target_in_world(p)});
  }
  core::StageScene scene =
      core::build_stage_scene(*cell, part.mesh, finished, settings.suction_arm);
  core::CollisionData data(scene.cell.model);
  const double weight = part.mass * cell->spec().gravity;
  auto slip_ok = [&](const core::Pose& board, const db::RobotGraspRecord& g) {
    const Eigen::Vector3d axis =
        board.linear() * g.tcp.linear() * cell->spec().gripper.opening_axis.normalized();
    const Eigen::Vector3d centre = board * (0.5 * (g.contact_1 + g.contact_2));
    const Eigen::Vector3d com = board * grasps.com;
    const double torque = std::abs(axis.dot((com - centre).cross(Eigen::Vector3d(0, 0, -weight))));
    return torque <= weight * g.lever * std::sin(core::deg_to_rad(g.theta_c_deg)) + 1e-9;
  };
  int checked = 0;
  for (const auto& s : result.shared) {
    const auto& c = result.candidates[static_cast<std::size_t>(s.candidate_id)];
    ASSERT_EQ(c.status, "goal");
    const auto& g = grasps.robot[static_cast<std::size_t>(s.robot_grasp_id)];
    const auto& rr = result.robot_handovers[static_cast<std::size_t>(s.robot_handover_id)];
    for (const auto* joints : {&s.joints_rr, &s.joints_rh}) {
      EXPECT_TRUE(receiving.chain.within_limits(*joints, 1e-9));
    }
    EXPECT_TRUE(suction_arm.chain.within_limits(rr.joints, 1e-9));
    const core::Pose tcp_rr = receiving_base * receiving.chain.fk(s.joints_rr);
    const core::Pose tcp_rh = receiving_base * receiving.chain.fk(s.joints_rh);
    EXPECT_LT((tcp_rr.matrix() - (rr.board * g.tcp).matrix()).norm(), 1e-6);
    EXPECT_LT((tcp_rh.matrix() - (c.board * g.tcp).matrix()).norm(), 1e-6);
    const core::Pose suction_tcp = suction_base * suction_arm.chain.fk(rr.joints);
    const auto& cup = grasps.suction[static_cast<std::size_t>(rr.suction_grasp_id)].cup;
    EXPECT_LT(((suction_tcp * scene.cup_in_tcp).matrix() - (rr.board * cup).matrix()).norm(), 1e-6);
    EXPECT_TRUE(slip_ok(rr.board, g));
    EXPECT_TRUE(slip_ok(c.board, g));

    // Robot-robot pose: both arms at their solutions, the tool held, the board on the cup.
    Eigen::VectorXd q = cell->home_configuration();
    cell->set_arm(q, receiving, s.joints_rr);
    cell->set_jaw(q, receiving, std::min(0.085, g.jaw_width + 0.005));
    cell->set_arm(q, suction_arm, rr.joints);
    core::set_cell_state(*cell, scene.cell, data, q, cell->human_neutral());
    core::set_tool_held(*cell, scene, data, suction_tcp);
    data.set_body_pose(scene.board, rr.board);
    core::CollisionPair pair;
    EXPECT_FALSE(core::in_collision_brute_force(scene.cell.model, data, &pair))
        << "rr: " << core::describe_pair(scene.cell.model, pair);
    // After the exchange the suction arm goes home with the tool, the board still held here by
    // the receiving arm: the exchange must not trap it.
    cell->set_arm(q, suction_arm, suction_arm.spec.home);
    core::set_cell_state(*cell, scene.cell, data, q, cell->human_neutral());
    core::set_tool_held(*cell, scene, data,
                        suction_base * suction_arm.chain.fk(suction_arm.spec.home));
    EXPECT_FALSE(core::in_collision_brute_force(scene.cell.model, data, &pair))
        << "suction arm home after the exchange: " << core::describe_pair(scene.cell.model, pair);
    // Robot-human pose: the suction arm back home with the tool.
    q = cell->home_configuration();
    cell->set_arm(q, receiving, s.joints_rh);
    cell->set_jaw(q, receiving, std::min(0.085, g.jaw_width + 0.005));
    core::set_cell_state(*cell, scene.cell, data, q, cell->human_neutral());
    core::set_tool_held(*cell, scene, data,
                        suction_base * suction_arm.chain.fk(suction_arm.spec.home));
    data.set_body_pose(scene.board, c.board);
    EXPECT_FALSE(core::in_collision_brute_force(scene.cell.model, data, &pair))
        << "rh: " << core::describe_pair(scene.cell.model, pair);
    ++checked;
  }
  EXPECT_GT(checked, 0);

  // Every direct grasp re-verified: FK of the stored joints at the part's initial pose and at the
  // goal, the slip there, and a brute-force collision check at the goal (the other arm home, the
  // tool in the suction arm's hand or, when the suction arm delivers, on the table).
  for (const auto& d : result.direct) {
    const auto& c = result.candidates[static_cast<std::size_t>(d.candidate_id)];
    ASSERT_EQ(c.status, "goal");
    const auto& g = grasps.robot[static_cast<std::size_t>(d.robot_grasp_id)];
    const core::Arm& arm = cell->arm(d.arm);
    const core::Pose base = core::arm_base_in_world(*cell, arm);
    EXPECT_LT(
        ((base * arm.chain.fk(d.joints_pick)).matrix() - (part.initial * g.tcp).matrix()).norm(),
        1e-6);
    EXPECT_LT(((base * arm.chain.fk(d.joints_rh)).matrix() - (c.board * g.tcp).matrix()).norm(),
              1e-6);
    EXPECT_TRUE(slip_ok(part.initial, g));
    EXPECT_TRUE(slip_ok(c.board, g));
    Eigen::VectorXd q = cell->home_configuration();
    cell->set_arm(q, arm, d.joints_rh);
    cell->set_jaw(q, arm, std::min(0.085, g.jaw_width + 0.005));
    core::set_cell_state(*cell, scene.cell, data, q, cell->human_neutral());
    if (&arm == &suction_arm) {
      core::set_robot_pose(data, scene.tool, scene.tool_links_in_handle,
                           product().suction_tool_pose);
    } else {
      core::set_tool_held(*cell, scene, data,
                          suction_base * suction_arm.chain.fk(suction_arm.spec.home));
    }
    data.set_body_pose(scene.board, c.board);
    core::CollisionPair pair;
    EXPECT_FALSE(core::in_collision_brute_force(scene.cell.model, data, &pair))
        << "direct rh: " << core::describe_pair(scene.cell.model, pair);
  }

  // Goals with a solved human posture: the hand is on the chosen grasp.
  for (const auto* c : ranked) {
    if (c->human_joints.size() == 0) continue;
    int arm = 0;
    while (comfort().arm_name(arm) != c->human_arm) ++arm;
    const auto& chain = cell->human_arms()[static_cast<std::size_t>(arm)].chain;
    const core::Pose hand = comfort().arm_base(arm) * chain.fk(c->human_joints);
    const core::Pose want =
        c->board * grasps.human[static_cast<std::size_t>(c->human_grasp_id)].hand;
    EXPECT_LT((hand.translation() - want.translation()).norm(), 1e-4);
  }
}

}  // namespace

TEST(Handover, OneHandBoardWithTwoFinishedBoards) {
  check_stage(2);  // back_lower: 0.22 kg, one hand; base and lateral_right finished
}

TEST(Handover, TwoHandLateralBesideTheBase) {
  check_stage(1);  // lateral_right: 1.8 kg, two hands, a tight slip limit
}

// The top of the generated product gen1_p12 (tests/data/wide_top): a 0.73 kg board one hand
// holds at a single grasp, where the human's own IK rejects every candidate a way serves. It is
// handed over for two hands, at grasps the human's IK reaches comfortably: each goal's stored
// postures put both hands on their grasps (forward kinematics), at least two_hand_separation
// apart, and their Q recomputed from the joints is the stored one, above the threshold.
TEST(Handover, AWideBoardOneHandHoldsOnlyAtAnEdgeIsHandedOverForTwoHands) {
  const auto cell = test::reference_cell();
  const core::ProductSpec wide =
      core::load_product(std::string(HILA_TEST_DATA_DIR) + "/wide_top/product.yaml");
  std::size_t index = 0;
  while (wide.parts[index].name != "top") ++index;
  const auto grasps = board_grasps(wide, index, offline::HumanGraspSettings{}.samples);
  const auto one_hand = std::count_if(grasps.human.begin(), grasps.human.end(),
                                      [](const auto& g) { return g.one_hand_stable; });
  ASSERT_GT(one_hand, 0);  // one hand holds it: not a two-hand part by the soft-finger check
  const offline::HandoverSettings settings;
  const auto result = offline::plan_handover_goals(*cell, wide, index, grasps, comfort(), settings);
  ASSERT_EQ(result.stage.failure, "");
  ASSERT_GT(result.stage.goals, 0);
  EXPECT_FALSE(result.stage.two_hands);
  int confirmed = 0;
  for (const auto& c : result.candidates) {
    if (c.status != "goal" || c.human_joints.size() == 0) continue;
    ++confirmed;
    ASSERT_GE(c.second_grasp_id, 0) << "goal " << c.rank << " is taken with one hand";
    const auto& g0 = grasps.human[static_cast<std::size_t>(c.human_grasp_id)];
    const auto& g1 = grasps.human[static_cast<std::size_t>(c.second_grasp_id)];
    EXPECT_GE((g0.hand.translation() - g1.hand.translation()).norm(), settings.two_hand_separation);
    const std::pair<std::string, std::pair<const Eigen::VectorXd*, const core::Pose*>> hands[2] = {
        {c.human_arm, {&c.human_joints, &g0.hand}}, {c.second_arm, {&c.second_joints, &g1.hand}}};
    const double stored_q[2] = {c.human_quality, c.second_quality};
    for (int k = 0; k < 2; ++k) {
      int arm = 0;
      while (comfort().arm_name(arm) != hands[k].first) ++arm;
      const auto& chain = cell->human_arms()[static_cast<std::size_t>(arm)].chain;
      const Eigen::VectorXd& q = *hands[k].second.first;
      const core::Pose hand = comfort().arm_base(arm) * chain.fk(q);
      const core::Pose want = c.board * *hands[k].second.second;
      EXPECT_LT((hand.translation() - want.translation()).norm(), 1e-4);
      EXPECT_LT(Eigen::AngleAxisd(hand.linear().transpose() * want.linear()).angle(), 1e-4);
      const double recomputed =
          core::comfort_index(chain.jacobian(q), core::characteristic_length(chain));
      EXPECT_NEAR(recomputed, stored_q[k], 1e-9);
      EXPECT_GT(recomputed, settings.comfort_threshold);
    }
  }
  EXPECT_GT(confirmed, 0);
}

TEST(Handover, SameSeedSameGoals) {
  const auto cell = test::reference_cell();
  const auto grasps = board_grasps(0);
  offline::HandoverSettings settings;
  settings.candidates = 120;
  const auto a = offline::plan_handover_goals(*cell, product(), 0, grasps, comfort(), settings);
  const auto b = offline::plan_handover_goals(*cell, product(), 0, grasps, comfort(), settings);
  ASSERT_EQ(a.candidates.size(), b.candidates.size());
  for (std::size_t i = 0; i < a.candidates.size(); ++i) {
    EXPECT_TRUE(a.candidates[i].board.isApprox(b.candidates[i].board, 0.0));
    EXPECT_EQ(a.candidates[i].status, b.candidates[i].status);
    EXPECT_EQ(a.candidates[i].rank, b.candidates[i].rank);
  }
  EXPECT_EQ(a.shared.size(), b.shared.size());
}

TEST(Handover, UnreachableTargetFailsWithAReason) {
  // The same board with its target 1.5 m behind the robot: no human can reach it.
  const auto cell = test::reference_cell();
  core::ProductSpec moved = product();
  moved.parts[0].target.translation() += Eigen::Vector3d(-1.8, 0.0, 0.0);
  offline::HandoverSettings settings;
  settings.candidates = 60;
  const auto r =
      offline::plan_handover_goals(*cell, moved, 0, board_grasps(0), comfort(), settings);
  EXPECT_EQ(r.stage.goals, 0);
  EXPECT_NE(r.stage.failure.find("reaches none"), std::string::npos) << r.stage.failure;
}

TEST(Handover, NoRobotRobotPoseFailsWithAReason) {
  // Robot-robot poses out of both arms' reach: S exists, 𝕊 cannot.
  const auto cell = test::reference_cell();
  offline::HandoverSettings settings;
  settings.candidates = 60;
  settings.max_candidates = 60;
  settings.rr_positions = {{2.0, 0.0, 2.5}};
  settings.suction_delivery = false;  // the right arm could present the board on its cup
  const auto r =
      offline::plan_handover_goals(*cell, product(), 0, board_grasps(0), comfort(), settings);
  EXPECT_EQ(r.stage.goals, 0);
  EXPECT_EQ(r.stage.robot_handovers, 0);
  EXPECT_NE(r.stage.failure.find("no robot-robot handover pose"), std::string::npos)
      << r.stage.failure;
  for (const auto& c : r.candidates) EXPECT_NE(c.status, "goal");
  // The arms do reach the part where the human takes it: the way from the stack is missing.
  EXPECT_NE(r.stage.failure.find("the left arm's gripper would hold it at"), std::string::npos)
      << r.stage.failure;
  EXPECT_EQ(r.stage.failure.find("out of both arms' reach"), std::string::npos) << r.stage.failure;

  // With suction deliveries the right arm presents it on its cup: goals, each served by them
  // alone, every stored IK holding the cup where its grasp meets the board at the goal (FK).
  settings.suction_delivery = true;
  const auto on_cup =
      offline::plan_handover_goals(*cell, product(), 0, board_grasps(0), comfort(), settings);
  ASSERT_GT(on_cup.stage.goals, 0) << on_cup.stage.failure;
  EXPECT_TRUE(on_cup.shared.empty());
  ASSERT_FALSE(on_cup.suction_deliveries.empty());
  const core::Arm& right = cell->arm("right");
  const core::Pose cup_in_tcp =
      core::build_stage_scene(*cell, product().parts[0].mesh, {}, "right").cup_in_tcp;
  for (const auto& d : on_cup.suction_deliveries) {
    const auto& goal = on_cup.candidates[static_cast<std::size_t>(d.candidate_id)];
    EXPECT_EQ(goal.status, "goal");
    const core::Pose cup =
        core::arm_base_in_world(*cell, right) * right.chain.fk(d.joints_rh) * cup_in_tcp;
    const core::Pose want =
        goal.board * board_grasps(0).suction[static_cast<std::size_t>(d.suction_grasp_id)].cup;
    EXPECT_LT((cup.translation() - want.translation()).norm(), 1e-6);
    EXPECT_TRUE(cup.linear().isApprox(want.linear(), 1e-6));
  }
}

TEST(Handover, APartWithNoGoalAboveTheThresholdGetsTheMostComfortableBelowIt) {
  // back_lower's goals at the default threshold; then the threshold raised above any Q of the
  // human's arm (it peaks near 0.15): without the floor no goal, with it goals come back from
  // below, at candidates the default run drew (the same draws: screening does not read Q).
  const auto cell = test::reference_cell();
  const auto grasps = board_grasps(2);
  offline::HandoverSettings settings;
  settings.candidates = 200;
  settings.max_candidates = 200;
  settings.comfort_floor = settings.comfort_threshold;  // off
  const auto plain = offline::plan_handover_goals(*cell, product(), 2, grasps, comfort(), settings);
  ASSERT_GT(plain.stage.goals, 0) << plain.stage.failure;
  double best = 0.0;
  for (const auto& c : plain.candidates) {
    if (c.status != "goal") continue;
    best = std::max(best, c.quality);
  }
  offline::HandoverSettings high = settings;
  ASSERT_LT(best, 0.3);
  high.comfort_threshold = 0.3;
  high.comfort_floor = high.comfort_threshold;
  const auto none = offline::plan_handover_goals(*cell, product(), 2, grasps, comfort(), high);
  EXPECT_EQ(none.stage.goals, 0);
  EXPECT_EQ(none.stage.failure.find("none either down to comfort Q"), std::string::npos);

  high.comfort_floor = settings.comfort_threshold;
  const auto relaxed = offline::plan_handover_goals(*cell, product(), 2, grasps, comfort(), high);
  ASSERT_GT(relaxed.stage.goals, 0) << relaxed.stage.failure;
  EXPECT_EQ(relaxed.stage.failure, "");
  EXPECT_EQ(relaxed.stage.comfortable, none.stage.comfortable);  // |S| at the stated threshold
  int ranked = 0;
  for (const auto& c : relaxed.candidates) {
    if (c.status != "goal") continue;
    ASSERT_LT(static_cast<std::size_t>(c.sample), plain.candidates.size());
    EXPECT_TRUE(plain.candidates[static_cast<std::size_t>(c.sample)].board.isApprox(c.board, 0.0))
        << "goal " << c.sample << " is not a candidate of the default run";
    EXPECT_GT(c.quality, settings.comfort_threshold);
    EXPECT_LE(c.quality, high.comfort_threshold);
    EXPECT_GE(c.rank, 0);
    ++ranked;
  }
  EXPECT_EQ(ranked, relaxed.stage.goals);
}

TEST(Handover, ACellWithoutAnalyticIkIsAClearError) {
  // The same cell without the arms' UR kinematics: handover goals need the analytic IK.
  const std::string dir = test::temp_dir("handover_no_ik");
  std::string text = test::read_file(test::cell_path());
  for (auto at = text.find("      kinematics: {"); at != std::string::npos;
       at = text.find("      kinematics: {")) {
    text.erase(at, text.find('\n', at) - at + 1);
  }
  for (const char* f : {"dual_ur3.urdf", "suction_tool.urdf", "human.urdf"}) {
    test::write_file(dir, f, test::read_file(test::data_path(std::string("cell/") + f)));
  }
  const auto cell = core::Cell::load(test::write_file(dir, "cell.yaml", text));
  offline::HandoverSettings settings;
  settings.candidates = 10;
  settings.max_candidates = 10;
  test::expect_input_error(
      [&] {
        offline::plan_handover_goals(*cell, product(), 0, board_grasps(0), comfort(), settings);
      },
      {"cell.yaml", "kinematics", "UR DH parameters"});
}

// The cabinet's top is fitted with its centre above the cell human's shoulder. Besides Eq. 1's
// candidates the build draws natural_candidates with the centre between the human's hip and
// shoulder height (core::natural_height_band), checked here independently of how they are drawn:
// the orientation within 45 degrees of the target's, the centre within 0.5 m of the target's
// horizontally and inside the band (recomputed from the human's link poses). The comfortable
// ones are searched for ways (the full build keeps some as goals: 3 of 200 for the cabinet's
// top); with the band off fewer comfortable candidates and no goal have their centre there.
TEST(Handover, APartFittedAboveTheShoulderGetsGoalsBetweenHipAndShoulder) {
  const auto cell = test::reference_cell();
  std::size_t index = 0;
  while (product().parts[index].name != "top") ++index;
  const auto& part = product().parts[index];
  const auto grasps = board_grasps(index);
  const core::Pose target = product().target_in_world(part);
  const Eigen::Vector3d target_centre = target * grasps.com;
  // The band from the human's link poses: the torso (arm base) to the higher shoulder joint.
  std::vector<core::Pose> links;
  cell->human().link_poses(cell->human_neutral(), links);
  double hip = 1e9, shoulder = -1e9;
  for (const auto& arm : cell->human_arms()) {
    const core::Pose base =
        cell->spec().human_stance *
        links[static_cast<std::size_t>(cell->human().link_index(arm.spec.base_link))];
    hip = std::min(hip, base.translation().z());
    shoulder = std::max(shoulder, (base * arm.chain.first_joint_position()).z());
  }
  ASSERT_GT(target_centre.z(), shoulder) << "the top is no longer fitted above the shoulder";
  offline::HandoverSettings settings;
  // The band within Eq. 1's orientation limit alone (the wider draw: the next test).
  settings.natural_max_rotation_deg = settings.max_rotation_deg;
  const auto result =
      offline::plan_handover_goals(*cell, product(), index, grasps, comfort(), settings);
  ASSERT_EQ(result.stage.failure, "");
  int band = 0, band_comfortable = 0;
  for (const auto& c : result.candidates) {
    if (c.sample < settings.candidates) continue;  // Eq. 1's
    ++band;
    const Eigen::Vector3d centre = c.board * grasps.com;
    EXPECT_LT(angle_between(c.board.linear(), target.linear()), core::deg_to_rad(45.0));
    EXPECT_LT((centre - target_centre).head<2>().norm(), 0.5);
    EXPECT_GE(centre.z(), hip);
    EXPECT_LE(centre.z(), shoulder);
    band_comfortable += c.status != "uncomfortable" ? 1 : 0;
  }
  EXPECT_GE(band, settings.natural_candidates);
  // Comfortable in the band, searched for ways (goals or not, as the robot's reach decides).
  auto in_band_comfortable = [&](const offline::HandoverResult& r) {
    int n = 0;
    for (const auto& c : r.candidates) {
      const double z = (c.board * grasps.com).z();
      n += c.status != "uncomfortable" && z >= hip && z <= shoulder ? 1 : 0;
    }
    return n;
  };
  EXPECT_GT(band_comfortable, 0);

  settings.natural_candidates = 0;
  const auto without =
      offline::plan_handover_goals(*cell, product(), index, grasps, comfort(), settings);
  EXPECT_LT(in_band_comfortable(without), in_band_comfortable(result));
  for (const auto& c : without.candidates) {
    if (c.status != "goal") continue;
    const double z = (c.board * grasps.com).z();
    EXPECT_FALSE(z >= hip && z <= shoulder) << "goal " << c.sample << " in the band without it";
  }
}

// A worker set (the cell's human, a 1.50 m woman and a 1.95 m man): each goal records the bodies
// that take it comfortably, checked against each body's own comfort lookup at the stored grasps;
// its quality is the cell human's (by the maps); and the woman, who has her own candidates and
// grasps, takes more goals comfortably than in a build for the cell's human alone.
TEST(Handover, AWorkerSetBuildsGoalsForEachBodyAndRecordsWhoTakesThem) {
  const auto cell = test::reference_cell();
  const std::vector<core::HumanBodySpec> bodies = {{1.50, core::Sex::Female},
                                                   {1.95, core::Sex::Male}};
  const offline::HumanComfort set(*cell, comfort_maps(), bodies);
  const std::size_t index = 2;  // back_lower: one hand
  const auto grasps = board_grasps(index);
  offline::HandoverSettings settings;
  const auto result = offline::plan_handover_goals(*cell, product(), index, grasps, set, settings);
  ASSERT_EQ(result.stage.failure, "");
  EXPECT_GE(result.stage.candidates, settings.candidates + 2 * settings.body_candidates);
  auto arm_of = [&](const std::string& name) {
    int a = 0;
    while (set.arm_name(a) != name) ++a;
    return a;
  };
  // Q of worker `body` (-1: the cell's human) at c's stored grasps, the weaker hand.
  auto q_of = [&](const db::HandoverCandidateRecord& c, int body) {
    auto one = [&](const std::string& arm, std::int64_t grasp) {
      const core::Pose hand = c.board * grasps.human[static_cast<std::size_t>(grasp)].hand;
      return body < 0 ? set.quality(arm_of(arm), hand) : set.body_quality(body, arm_of(arm), hand);
    };
    const double q = one(c.human_arm, c.human_grasp_id);
    return c.second_arm.empty() ? q : std::min(q, one(c.second_arm, c.second_grasp_id));
  };
  int goals_for[2] = {0, 0};
  for (const auto& c : result.candidates) {
    if (c.human_grasp_id < 0) continue;
    // (A candidate the cell human's own IK found uncomfortable keeps the IK's lower Q.)
    if (c.status == "uncomfortable") {
      EXPECT_LE(c.quality, q_of(c, -1) + 1e-12) << "candidate " << c.sample;
    } else {
      EXPECT_NEAR(c.quality, q_of(c, -1), 1e-12) << "candidate " << c.sample;
    }
    for (int b = 0; b < 2; ++b) {
      const bool takes = q_of(c, b) > settings.comfort_threshold;
      EXPECT_EQ((c.bodies >> b) & 1U, takes ? 1U : 0U) << "candidate " << c.sample << " body " << b;
      if (takes && c.status == "goal") ++goals_for[b];
    }
  }
  EXPECT_GT(goals_for[1], 0);
  // The cell's human alone, the same maps: goals the woman takes comfortably.
  const offline::HumanComfort woman_only(*cell, comfort_maps(), {bodies[0]});
  const auto alone =
      offline::plan_handover_goals(*cell, product(), index, grasps, comfort(), settings);
  int hers_alone = 0;
  for (const auto& c : alone.candidates) {
    if (c.status == "goal" && c.human_grasp_id >= 0) {
      const core::Pose hand =
          c.board * grasps.human[static_cast<std::size_t>(c.human_grasp_id)].hand;
      double q = woman_only.body_quality(0, arm_of(c.human_arm), hand);
      if (!c.second_arm.empty()) {
        q = std::min(q,
                     woman_only.body_quality(
                         0, arm_of(c.second_arm),
                         c.board * grasps.human[static_cast<std::size_t>(c.second_grasp_id)].hand));
      }
      hers_alone += q > settings.comfort_threshold ? 1 : 0;
    }
  }
  EXPECT_GT(goals_for[0], hers_alone);
}

// natural_max_rotation_deg is for a worker none of whose goals the online planner would find
// natural (core::reach_hand from the goal's stored posture, else from zero, as BoardPlanner reaches
// a goal; core::PostureCheck::natural with RULA at most 3). For a 1.50 m woman, the 700 mm
// lateral and back_upper are fitted with their centres above her shoulder and have no goal she
// takes naturally within 45 degrees. With the wider limit she has one for both, and every
// candidate beyond 45 degrees lies in her band or the cell human's (he too gets them where he
// has no natural goal). For back_upper, goals that the comfort maps give her with the centre in
// her band are not natural (the elbow or RULA): what the maps alone could not judge.
TEST(Handover, AWorkerWithoutANaturalGoalGetsBandCandidatesTurnedFurther) {
  const auto cell = test::reference_cell();
  const offline::HandoverSettings settings;
  ASSERT_GT(settings.natural_max_rotation_deg, settings.max_rotation_deg);
  auto angle_deg = [](const db::HandoverCandidateRecord& c, const core::Pose& target) {
    return core::rad_to_deg(angle_between(c.board.linear(), target.linear()));
  };
  const core::HumanBodySpec woman{1.50, core::Sex::Female};
  const offline::HumanComfort set(*cell, comfort_maps(), {woman});
  const core::HumanBody& her = set.body(0);
  const core::Pose stance = cell->spec().human_stance;
  const core::HeightBand band = core::natural_height_band(*cell, &her, stance);
  const core::HeightBand his_band = core::natural_height_band(*cell, nullptr, stance);
  for (const std::string name : {"lateral_right", "back_upper"}) {
    SCOPED_TRACE(name);
    std::size_t index = 0;
    while (product().parts[index].name != name) ++index;
    const core::PartSpec& part = product().parts[index];
    const core::Pose target = product().target_in_world(part);
    const auto grasps = board_grasps(index);
    ASSERT_FALSE(band.contains((target * grasps.com).z()));
    // Goals she takes by the maps with the part's centre in her band, and those of all goals
    // with the centre in her band whose posture, reached as the planner reaches it, is natural.
    auto hers = [&](const offline::HandoverResult& r, int& maps_only, int& natural) {
      maps_only = natural = 0;
      for (const auto& c : r.candidates) {
        const Eigen::Vector3d centre = c.board * grasps.com;
        if (c.status != "goal" || !band.contains(centre.z())) continue;
        std::vector<std::pair<std::string, Eigen::VectorXd>> held;
        for (const auto& [arm, grasp, seed] :
             {std::tuple{c.human_arm, c.human_grasp_id, c.human_joints},
              std::tuple{c.second_arm, c.second_grasp_id, c.second_joints}}) {
          if (arm.empty()) continue;
          const auto reached =
              core::reach_hand(*cell, &her, stance, arm,
                               c.board * grasps.human[static_cast<std::size_t>(grasp)].hand, seed);
          if (reached.reachable) held.emplace_back(arm, reached.joints);
        }
        const bool is_natural =
            held.size() == (c.second_arm.empty() ? 1U : 2U) &&
            core::check_receiving_posture(*cell, &her, stance, held, centre, part.mass)
                .natural(settings.natural_max_rula);
        natural += is_natural ? 1 : 0;
        maps_only += !is_natural && (c.bodies & 1U) != 0 ? 1 : 0;
      }
    };
    offline::HandoverSettings narrow = settings;
    narrow.natural_max_rotation_deg = narrow.max_rotation_deg;
    int maps_only = 0, natural = 0;
    const auto within = offline::plan_handover_goals(*cell, product(), index, grasps, set, narrow);
    hers(within, maps_only, natural);
    EXPECT_EQ(natural, 0);
    const auto wider = offline::plan_handover_goals(*cell, product(), index, grasps, set, settings);
    hers(wider, maps_only, natural);
    EXPECT_GT(natural, 0);
    if (name == "back_upper") {
      EXPECT_GT(maps_only, 0);
    }
    int beyond = 0;
    for (const auto& c : wider.candidates) {
      const double angle = angle_deg(c, target);
      EXPECT_LT(angle, settings.natural_max_rotation_deg + 1e-9);
      if (angle <= settings.max_rotation_deg) continue;
      ++beyond;
      const double z = (c.board * grasps.com).z();
      EXPECT_TRUE(band.contains(z) || his_band.contains(z)) << "candidate " << c.sample;
    }
    EXPECT_GT(beyond, settings.natural_candidates / 2);  // most of the turns within 90 degrees
  }
}

// A goal in a worker's band that they would take naturally at other grasps than the maps chose
// gets a copy at those grasps (the wider batches, before drawing more). The 1.50 m woman and
// the cabinet's lateral_left: its goals in her band are held, at the maps' grasps, with the
// upper arm above 45 degrees and a bent wrist (RULA 4). Each copy is natural for one of the two
// workers (the cell's human or her) and is checked for that worker against a brute force over
// every pair of their grasps (reached and judged as the online planner does, far enough apart):
// its pair is one of the natural pairs, the goal it copies (the same pose, other grasps, in their
// band) is not natural for them, and a copy that is a goal has ways of its own (searched with
// the hands at its grasps). With the copies she has a natural goal.
TEST(Handover, AGoalAWorkerTakesNaturallyAtOtherGraspsIsCopiedAtThem) {
  const auto cell = test::reference_cell();
  const offline::HandoverSettings settings;
  const offline::HumanComfort set(*cell, comfort_maps(), {{1.50, core::Sex::Female}});
  const core::HumanBody* workers[2] = {nullptr, &set.body(0)};  // the cell's human, her
  const core::Pose stance = cell->spec().human_stance;
  std::size_t index = 0;
  while (product().parts[index].name != "lateral_left") ++index;
  const core::PartSpec& part = product().parts[index];
  const auto grasps = board_grasps(index);
  const auto r = offline::plan_handover_goals(*cell, product(), index, grasps, set, settings);
  using Hands = std::vector<std::tuple<std::string, std::int64_t, Eigen::VectorXd>>;
  // The worker's posture at candidate c's `hands` (reached from their seeds) natural.
  auto natural = [&](const core::HumanBody* body, const db::HandoverCandidateRecord& c,
                     const Hands& hands) {
    std::vector<std::pair<std::string, Eigen::VectorXd>> held;
    for (const auto& [arm, grasp, seed] : hands) {
      const auto reached =
          core::reach_hand(*cell, body, stance, arm,
                           c.board * grasps.human[static_cast<std::size_t>(grasp)].hand, seed);
      if (!reached.reachable) return false;
      held.emplace_back(arm, reached.joints);
    }
    return core::check_receiving_posture(*cell, body, stance, held, c.board * grasps.com, part.mass)
        .natural(settings.natural_max_rula);
  };
  auto hands_of = [](const db::HandoverCandidateRecord& c) {
    Hands hands{{c.human_arm, c.human_grasp_id, c.human_joints}};
    if (!c.second_arm.empty()) hands.emplace_back(c.second_arm, c.second_grasp_id, c.second_joints);
    return hands;
  };
  std::map<int, int> ways;  // per candidate index
  for (const auto& w : r.shared) ++ways[static_cast<int>(w.candidate_id)];
  for (const auto& w : r.suction_deliveries) ++ways[static_cast<int>(w.candidate_id)];
  for (const auto& w : r.direct) ++ways[static_cast<int>(w.candidate_id)];
  for (const auto& w : r.regrasps) ++ways[static_cast<int>(w.candidate_id)];
  const core::HeightBand her_band = core::natural_height_band(*cell, workers[1], stance);
  int copies[2] = {0, 0}, her_natural_goals = 0;
  for (std::size_t i = 0; i < r.candidates.size(); ++i) {
    const auto& c = r.candidates[i];
    if (c.status == "goal" && her_band.contains((c.board * grasps.com).z()) &&
        natural(workers[1], c, hands_of(c))) {
      ++her_natural_goals;
    }
    const auto source = std::find_if(r.candidates.begin(), r.candidates.begin() + i,
                                     [&](const auto& o) { return o.board.isApprox(c.board, 0.0); });
    if (source == r.candidates.begin() + static_cast<std::ptrdiff_t>(i)) continue;
    SCOPED_TRACE("copy " + std::to_string(i));
    ASSERT_FALSE(c.second_arm.empty());  // the lateral takes two hands
    EXPECT_EQ(source->status, "goal");
    EXPECT_TRUE(c.human_grasp_id != source->human_grasp_id ||
                c.second_grasp_id != source->second_grasp_id);
    int w = 0;
    while (w < 2 && !natural(workers[w], c, hands_of(c))) ++w;
    ASSERT_LT(w, 2) << "natural for neither worker";
    ++copies[w];
    const core::HumanBody* body = workers[w];
    EXPECT_TRUE(
        core::natural_height_band(*cell, body, stance).contains((c.board * grasps.com).z()));
    EXPECT_FALSE(natural(body, *source, hands_of(*source)));
    // Every pair of the worker's grasps, one per arm, far enough apart: the natural ones.
    std::vector<std::optional<Eigen::VectorXd>> reached[2];
    for (int a = 0; a < 2; ++a) {
      for (const auto& g : grasps.human) {
        const auto h = core::reach_hand(*cell, body, stance, a == 0 ? "left" : "right",
                                        c.board * g.hand, Eigen::VectorXd());
        reached[a].push_back(h.reachable ? std::optional(h.joints) : std::nullopt);
      }
    }
    std::set<std::pair<std::int64_t, std::int64_t>> natural_pairs;
    for (std::size_t g0 = 0; g0 < grasps.human.size(); ++g0) {
      for (std::size_t g1 = 0; g1 < grasps.human.size() && reached[0][g0]; ++g1) {
        if (!reached[1][g1] ||
            (grasps.human[g0].hand.translation() - grasps.human[g1].hand.translation()).norm() <
                settings.two_hand_separation) {
          continue;
        }
        if (core::check_receiving_posture(*cell, body, stance,
                                          {{"left", *reached[0][g0]}, {"right", *reached[1][g1]}},
                                          c.board * grasps.com, part.mass)
                .natural(settings.natural_max_rula)) {
          natural_pairs.emplace(g0, g1);
        }
      }
    }
    const auto pair = c.human_arm == "left" ? std::pair{c.human_grasp_id, c.second_grasp_id}
                                            : std::pair{c.second_grasp_id, c.human_grasp_id};
    EXPECT_EQ(natural_pairs.count(pair), 1U);
    if (c.status == "goal") {
      EXPECT_GT(ways[static_cast<int>(i)], 0);
    }
  }
  EXPECT_GT(copies[1], 0);
  EXPECT_GT(her_natural_goals, 0);
}
