#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <random>
#include <string>

#include "hila/core/human_body.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/receiving_scores.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// One arm's angles measured independently of the score mapping, from the human model's link
// frames at the whole configuration: the upper arm (shoulder to elbow) against the torso's
// downward axis, the elbow from the upper and lower arm (elbow to wrist) directions, the wrist's
// position across the body.
struct FkAngles {
  double upper_arm = 0.0;  // deg, negative behind the torso's frontal plane below the shoulder
  double abduction = 0.0;  // deg out of the sagittal plane, away from the body positive
  double elbow = 0.0;      // deg, 0 straight
  bool across_or_out = false;
};

FkAngles fk_angles(const core::Cell& cell, const Eigen::VectorXd& q, const std::string& side) {
  const core::RobotModel& human = cell.human();
  std::vector<core::Pose> poses;
  human.link_poses(q, poses);
  const core::Pose& torso = poses[human.link_index("torso")];
  auto at = [&](const std::string& link) {
    return torso.inverse() * poses[human.link_index(side + "_" + link)].translation();
  };
  const Eigen::Vector3d shoulder = at("shoulder_flexion_link");
  const Eigen::Vector3d elbow = at("elbow_link");
  const Eigen::Vector3d wrist = at("wrist_link");
  const Eigen::Vector3d upper = (elbow - shoulder).normalized();
  const Eigen::Vector3d lower = (wrist - elbow).normalized();
  const double outward = side == "left" ? 1.0 : -1.0;  // the torso's y toward this side
  FkAngles a;
  a.upper_arm = core::rad_to_deg(std::acos(std::clamp(-upper.z(), -1.0, 1.0)));
  if (upper.x() < 0.0 && upper.z() < 0.0) a.upper_arm = -a.upper_arm;
  a.abduction = core::rad_to_deg(std::asin(std::clamp(outward * upper.y(), -1.0, 1.0)));
  a.elbow = core::rad_to_deg(std::acos(std::clamp(upper.dot(lower), -1.0, 1.0)));
  const double wrist_out = outward * wrist.y(), shoulder_out = outward * shoulder.y();
  a.across_or_out = wrist_out < 0.0 || wrist_out - shoulder_out > 0.5 * shoulder_out;
  return a;
}

// Whether `x` lies within 1e-6 deg of a band edge (the closed form and FK differ by rounding).
bool near_edge(double x, std::initializer_list<double> edges) {
  return std::any_of(edges.begin(), edges.end(), [&](double e) { return std::abs(x - e) < 1e-6; });
}

// Checks one hand's reported scores against the angles from forward kinematics: RULA's upper arm
// (+-20, 45, 90 deg, +1 abducted beyond 20 deg) and lower arm (60-100 deg, +1 across the body or
// out to the side), REBA's upper and lower arm likewise, and the grand and REBA scores those of
// core::rula and core::reba on the reported inputs. Returns false when an angle is on a band's
// edge (nothing checked).
bool expect_hand_follows_fk(const core::Cell& cell, const Eigen::VectorXd& q,
                            const online::HandScores& h) {
  const FkAngles fk = fk_angles(cell, q, h.arm);
  if (near_edge(fk.upper_arm, {-20, 20, 45, 90}) || near_edge(fk.elbow, {60, 100}) ||
      near_edge(fk.abduction, {core::kAbductedDeg})) {
    return false;
  }
  SCOPED_TRACE(h.arm + ": upper arm " + std::to_string(fk.upper_arm) + " deg, elbow " +
               std::to_string(fk.elbow) + " deg");
  const int band = fk.upper_arm < -20   ? 2
                   : fk.upper_arm <= 20 ? 1
                   : fk.upper_arm <= 45 ? 2
                   : fk.upper_arm <= 90 ? 3
                                        : 4;
  const bool abducted = fk.abduction > core::kAbductedDeg;
  EXPECT_EQ(h.rula.upper_arm, band + (abducted ? 1 : 0));
  const int elbow_band = fk.elbow >= 60 && fk.elbow <= 100 ? 1 : 2;
  EXPECT_EQ(h.rula.lower_arm, elbow_band + (fk.across_or_out ? 1 : 0));
  EXPECT_EQ(h.reba.lower_arm, elbow_band);
  // REBA: +1 abducted or rotated (the shoulder's rotation joint beyond kArmRotatedDeg).
  const core::RobotModel& human = cell.human();
  const double rotation =
      core::rad_to_deg(q[human.joints()[human.joint_index(h.arm + "_shoulder_rotation")].variable]);
  const bool rotated = abducted || std::abs(rotation) > core::kArmRotatedDeg;
  EXPECT_EQ(h.reba.upper_arm, band + (rotated ? 1 : 0));
  EXPECT_NEAR(h.rula_inputs.upper_arm_flexion_deg, fk.upper_arm, 1e-6);
  EXPECT_NEAR(h.rula_inputs.lower_arm_flexion_deg, fk.elbow, 1e-6);
  EXPECT_EQ(h.rula.grand, core::rula(h.rula_inputs).grand);
  EXPECT_EQ(h.reba.reba, core::reba(h.reba_inputs).reba);
  return true;
}

// Checks the board's scores: each hand against FK, the loads (RULA each hand's share, REBA the
// whole), and the board's RULA and REBA the worse hand's.
int expect_scores_follow_fk(const core::Cell& cell, const online::BoardPlan& plan, double load) {
  const online::ReceivingScores s = online::receiving_scores(cell, plan, load);
  EXPECT_TRUE(s.scored);
  if (!s.scored) return 0;
  const bool two = !plan.second_human_arm.empty();
  EXPECT_EQ(s.two_hands, two);
  EXPECT_EQ(s.hands.size(), two ? 2u : 1u);
  EXPECT_EQ(s.hands.front().arm, plan.human_arm);
  std::vector<std::pair<std::string, Eigen::VectorXd>> arms{{plan.human_arm, plan.human_joints}};
  if (two) arms.emplace_back(plan.second_human_arm, plan.second_human_joints);
  const Eigen::VectorXd q = core::human_posture(cell, arms);
  int checked = 0;
  int grand = 0, reba = 0;
  for (const auto& h : s.hands) {
    EXPECT_DOUBLE_EQ(h.rula_inputs.load_kg, two ? 0.5 * load : load);
    EXPECT_DOUBLE_EQ(h.reba_inputs.load_kg, load);
    checked += expect_hand_follows_fk(cell, q, h) ? 1 : 0;
    grand = std::max(grand, h.rula.grand);
    reba = std::max(reba, h.reba.reba);
  }
  EXPECT_EQ(s.rula().grand, grand);
  EXPECT_EQ(s.reba().reba, reba);
  EXPECT_GE(s.rula().grand, 1);
  EXPECT_LE(s.rula().grand, 7);
  EXPECT_GE(s.reba().reba, 1);
  EXPECT_LE(s.reba().reba, 15);
  return checked;
}

}  // namespace

// Random receiving postures of one hand and of two (fixed seed): the reported sub-scores follow
// the bands of the angles from forward kinematics, and the board's score is the worse hand's.
TEST(ReceivingScores, FollowTheArmAnglesFromForwardKinematics) {
  const auto cell = test::reference_cell();
  ASSERT_EQ(cell->human_arms().size(), 2u);
  std::mt19937_64 rng(35);
  int checked = 0, worse_second = 0;
  for (int trial = 0; trial < 300; ++trial) {
    online::BoardPlan plan;
    plan.status = online::BoardPlanStatus::kSolved;
    const auto& first = cell->human_arms()[trial % 2];
    plan.human_arm = first.spec.name;
    plan.human_joints = test::random_within(first.chain, rng);
    if (trial % 3 == 0) {
      const auto& second = cell->human_arms()[(trial + 1) % 2];
      plan.second_human_arm = second.spec.name;
      plan.second_human_joints = test::random_within(second.chain, rng);
    }
    SCOPED_TRACE("trial " + std::to_string(trial));
    checked += expect_scores_follow_fk(*cell, plan, 4.0);
    const auto s = online::receiving_scores(*cell, plan, 4.0);
    if (s.hands.size() == 2 && s.worst_rula == 1) ++worse_second;
  }
  EXPECT_GT(checked, 350);     // hands checked (not on a band's edge)
  EXPECT_GT(worse_second, 5);  // the second hand is sometimes the worse one
}

// A plan without a receiving posture (not solved) is not scored; an arm the human model has not
// is an input error.
TEST(ReceivingScores, NothingScoredWithoutAPosture) {
  const auto cell = test::reference_cell();
  online::BoardPlan plan;
  EXPECT_FALSE(online::receiving_scores(*cell, plan, 2.0).scored);
  plan.human_arm = "middle";
  plan.human_joints = Eigen::VectorXd::Zero(7);
  EXPECT_THROW(online::receiving_scores(*cell, plan, 2.0), core::InputError);
}

// The postures a cabinet database stores for its goals (what the planner hands boards over at
// where the human stands as built): every goal's one or two hands scored, their sub-scores
// following the angles from forward kinematics, the load the part's mass.
TEST(ReceivingScores, CabinetGoalsStoredPostures) {
  std::string path;
  std::string dir;
  if (const char* given = std::getenv("HILA_TEST_DATABASE")) {
    path = given;
  } else {
    dir = test::temp_dir("receiving_scores_" + std::to_string(::getpid()));
    path = dir + "/cabinet.hila";
    offline::BuildSettings settings = test::quick_build_settings(7, 2);
    settings.comfort.samples = 400000;
    settings.handover.candidates = 200;
    settings.handover.max_candidates = 400;
    offline::build_database(test::product_path(), test::cell_path(), path, settings);
  }
  const auto cell = test::reference_cell();
  const db::Database database = db::Database::open(path);
  int goals = 0, two_hand = 0, checked = 0;
  for (const auto& part : database.parts()) {
    for (const auto& goal : database.handover_goals(part.id)) {
      if (goal.human_arm.empty() || goal.human_joints.size() == 0) continue;
      if (!goal.second_arm.empty() && goal.second_joints.size() == 0) continue;
      online::BoardPlan plan;
      plan.status = online::BoardPlanStatus::kSolved;
      plan.human_arm = goal.human_arm;
      plan.human_joints = goal.human_joints;
      plan.second_human_arm = goal.second_arm;
      plan.second_human_joints = goal.second_joints;
      SCOPED_TRACE(part.name + " goal " + std::to_string(goal.id));
      checked += expect_scores_follow_fk(*cell, plan, part.mass);
      ++goals;
      two_hand += goal.second_arm.empty() ? 0 : 1;
    }
  }
  EXPECT_GT(goals, 5);
  EXPECT_GT(checked, goals / 2);
  std::cout << goals << " goals (" << two_hand << " two-hand), " << checked << " hands checked\n";
  if (!dir.empty()) std::filesystem::remove_all(dir);
}
