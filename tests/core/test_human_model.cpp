#include <gtest/gtest.h>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/robot_model.hpp"
#include "util/test_util.hpp"

using namespace hila;

TEST(HumanModel, DimensionsFollowTheStatureRatios) {
  const auto d = core::human_dimensions({1.722, core::Sex::Male});
  EXPECT_NEAR(d.upper_arm, 0.186 * 1.722, 1e-12);
  EXPECT_NEAR(d.forearm, 0.146 * 1.722, 1e-12);
  EXPECT_NEAR(d.hand, 0.108 * 1.722, 1e-12);
  EXPECT_NEAR(d.shoulder_height, 0.818 * 1.722, 1e-12);
  const auto f = core::human_dimensions({1.595, core::Sex::Female});
  EXPECT_LT(f.shoulder_half_width / f.stature, d.shoulder_half_width / d.stature);
}

TEST(HumanModel, GeneratedUrdfHasTwoSevenDofArmsWithTheRightLengths) {
  for (const double stature : {1.50, 1.722, 1.90}) {
    const core::HumanBodySpec spec{stature, core::Sex::Male};
    const auto d = core::human_dimensions(spec);
    const auto model = core::RobotModel::load_urdf_string(core::generate_human_urdf(spec), "human");
    EXPECT_EQ(model.num_variables(), 1 + 2 * 7);  // torso flexion + two arms
    for (const std::string side : {"left", "right"}) {
      const core::KinematicChain chain(model, core::kHumanArmBase, core::human_grasp_link(side));
      ASSERT_EQ(chain.dof(), 7);
      // Arm hanging straight down at zero: grasp point below the shoulder by the arm length.
      const core::Pose grasp = chain.fk(Eigen::VectorXd::Zero(7));
      const double torso_height = d.shoulder_height - d.hip_height;
      EXPECT_NEAR(grasp.translation().z(), torso_height - d.upper_arm - d.forearm - 0.4 * d.hand,
                  1e-9);
      EXPECT_NEAR(grasp.translation().y(), (side == "left" ? 1 : -1) * d.shoulder_half_width, 1e-9);
      // Shoulder flexion of 90 degrees points the straight arm forward (+x).
      Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
      q[0] = core::deg_to_rad(90);
      EXPECT_GT(chain.fk(q).translation().x(), 0.9 * (d.upper_arm + d.forearm));
      // Abduction of 90 degrees points it sideways, away from the body.
      q.setZero();
      q[1] = core::deg_to_rad(90);
      EXPECT_GT((side == "left" ? 1 : -1) * chain.fk(q).translation().y(),
                d.shoulder_half_width + 0.9 * (d.upper_arm + d.forearm));
      // Elbow flexion brings the hand forward, never backward.
      q.setZero();
      q[3] = core::deg_to_rad(90);
      EXPECT_GT(chain.fk(q).translation().x(), 0.9 * d.forearm);
    }
  }
}

TEST(HumanModel, JointLimitsComeFromTheRangeOfMotionTable) {
  const auto model = core::RobotModel::load_urdf_string(core::generate_human_urdf({}), "human");
  const auto& elbow = model.joints()[model.joint_index("right_elbow_flexion")];
  EXPECT_NEAR(elbow.lower, 0.0, 1e-6);
  EXPECT_NEAR(elbow.upper, core::deg_to_rad(145), 1e-6);
  const auto& flexion = model.joints()[model.joint_index("left_shoulder_flexion")];
  EXPECT_NEAR(flexion.lower, core::deg_to_rad(-50), 1e-6);
  EXPECT_NEAR(flexion.upper, core::deg_to_rad(180), 1e-6);
}

TEST(HumanModel, CommittedDefaultHumanMatchesTheGenerator) {
  EXPECT_EQ(test::read_file(test::data_path("cell/human.urdf")), core::generate_human_urdf({}))
      << "regenerate with: hila human -o meshes/cell/human.urdf";
}

TEST(HumanModel, RejectsImplausibleStature) {
  test::expect_input_error(
      [] {
        core::human_dimensions({1722.0, core::Sex::Male});
      },
      {"stature", "millimetres"});
  test::expect_input_error(
      [] {
        core::human_dimensions({0.0, core::Sex::Female});
      },
      {"stature", "[1.30, 2.20]"});
  test::expect_input_error(
      [] {
        core::human_dimensions({std::nan(""), core::Sex::Male});
      },
      {"stature", "nan"});
}

namespace {

// The reference cell (meshes/cell/cell.yaml) with `spec`'s human in place of the default one, as
// a user gets it by `hila human --stature H --sex S -o human.urdf` in the cell's directory.
std::shared_ptr<const core::Cell> cell_with_human(const core::HumanBodySpec& spec) {
  // One directory per test and body: ctest runs the tests of this file in parallel processes.
  const std::string dir = test::temp_dir(
      std::string("human_model_cell_") +
      ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
      core::format_number(spec.stature) + (spec.sex == core::Sex::Male ? "_male" : "_female"));
  const std::string cell_file = test::cell_variant(dir, "urdf: human.urdf", "urdf: human.urdf");
  test::write_file(dir, "human.urdf", core::generate_human_urdf(spec));
  return core::Cell::load(cell_file);
}

std::string label(const core::HumanBodySpec& spec) {
  return core::format_number(spec.stature) + (spec.sex == core::Sex::Male ? " male" : " female");
}

// The human's links alone as `hila cell check` sees them (add_robot allows each link with its
// nearest ancestor that has geometry; every other pair is tested), posed at `q`.
struct SelfCheck {
  bool colliding = false;
  double clearance = 0.0;  // m, smallest distance between tested pairs (0 when colliding)
  std::string pair;
};

SelfCheck self_check(const core::RobotModel& human, const Eigen::VectorXd& q) {
  core::CollisionModel model;
  const core::RobotBodies bodies = core::add_robot(model, human, "human/");
  core::CollisionData data(model);
  std::vector<core::Pose> poses;
  human.link_poses(q, poses);
  core::set_robot_pose(data, bodies, poses);
  SelfCheck out;
  core::CollisionPair pair;
  out.colliding = core::in_collision(model, data, &pair);
  if (!out.colliding) out.clearance = core::min_distance(model, data, &pair);
  out.pair = core::describe_pair(model, pair);
  return out;
}

}  // namespace

// Both sexes over statures from below the survey's 5th-percentile woman (about 1.50 m) to above
// its 95th-percentile man (about 1.82 m): the posture every check starts from (Cell::human_neutral,
// the cell file giving no neutral_deg) leaves the human clear of itself by 3 mm or more.
TEST(HumanModel, NeutralPostureClearsItselfForBothSexesAtEveryStature) {
  constexpr double kMargin = 0.003;  // m
  for (const core::Sex sex : {core::Sex::Female, core::Sex::Male}) {
    for (int cm = 145; cm <= 195; cm += 5) {
      const core::HumanBodySpec spec{cm / 100.0, sex};
      const auto cell = cell_with_human(spec);
      const SelfCheck check = self_check(cell->human(), cell->human_neutral());
      EXPECT_FALSE(check.colliding) << label(spec) << ": " << check.pair;
      if (!check.colliding) {
        EXPECT_GE(check.clearance, kMargin) << label(spec) << ": " << check.pair;
      }
    }
  }
}

// The five bodies of issue 35 in the reference cell: the check of `hila cell check` (robot at
// home, human at the stance in the neutral posture, every body moving) finds nothing, and the
// stance check of `hila build` accepts them.
TEST(HumanModel, TheCellCheckIsCleanForFiveBodiesFromTheSmallWomanToATallMan) {
  const core::HumanBodySpec bodies[] = {
      {core::kFemaleStatureP5, core::Sex::Female}, {core::kFemaleStatureMean, core::Sex::Female},
      {core::kDefaultStature, core::Sex::Male},    {core::kMaleStatureP95, core::Sex::Male},
      {core::kTallStature, core::Sex::Male},
  };
  for (const auto& spec : bodies) {
    const auto cell = cell_with_human(spec);
    const core::CellScene scene = core::build_cell_scene(*cell, {.human_moves = true});
    core::CollisionData data(scene.model);
    core::set_cell_state(*cell, scene, data, cell->home_configuration(cell->spec().gripper.jaw_max),
                         cell->human_neutral());
    core::CollisionPair pair;
    EXPECT_FALSE(core::in_collision(scene.model, data, &pair))
        << label(spec) << ": " << core::describe_pair(scene.model, pair);
    EXPECT_NO_THROW(core::check_human_stance(*cell)) << label(spec);
  }
}

// The neutral posture by itself: a man's arms hang straight (the zero posture, so the default
// cell's human posture is what it always was); a woman's shoulders abduct by half a degree to a
// degree, the same on both sides, and nothing else moves.
TEST(HumanModel, NeutralPostureHangsAMansArmsAndHoldsAWomansOffTheHip) {
  const auto reference = test::reference_cell();
  EXPECT_EQ(reference->human_neutral(), reference->human().neutral_configuration());
  for (int cm = 145; cm <= 195; cm += 5) {
    const core::HumanBodySpec male{cm / 100.0, core::Sex::Male};
    const auto m = core::RobotModel::load_urdf_string(core::generate_human_urdf(male), "male");
    EXPECT_EQ(core::human_neutral_configuration(m), m.neutral_configuration()) << label(male);

    const core::HumanBodySpec female{cm / 100.0, core::Sex::Female};
    const auto f = core::RobotModel::load_urdf_string(core::generate_human_urdf(female), "female");
    const Eigen::VectorXd q = core::human_neutral_configuration(f);
    const int left = f.joints()[f.joint_index("left_shoulder_abduction")].variable;
    const int right = f.joints()[f.joint_index("right_shoulder_abduction")].variable;
    EXPECT_GT(q[left], 0.0) << label(female);
    EXPECT_LE(q[left], core::deg_to_rad(1.0) + 1e-12) << label(female);
    EXPECT_EQ(q[right], q[left]) << label(female);
    Eigen::VectorXd rest = q;
    rest[left] = rest[right] = 0.0;
    EXPECT_EQ(rest, f.neutral_configuration()) << label(female);
    EXPECT_GE(self_check(f, q).clearance, core::kHumanNeutralClearance) << label(female);
  }
}

// `human.neutral_deg` has one angle per joint of the model, in this order
// (docs/cell_and_product.md).
TEST(HumanModel, NeutralDegListsTheTorsoThenTheLeftThenTheRightArm) {
  const auto model = core::RobotModel::load_urdf_string(core::generate_human_urdf({}), "human");
  std::vector<std::string> expected{"torso_flexion"};
  for (const std::string side : {"left", "right"}) {
    for (const char* joint :
         {"shoulder_flexion", "shoulder_abduction", "shoulder_rotation", "elbow_flexion",
          "forearm_pronation", "wrist_flexion", "wrist_deviation"}) {
      expected.push_back(side + "_" + joint);
    }
  }
  std::vector<std::string> names;
  for (const int j : model.variable_joints()) names.push_back(model.joints()[j].name);
  EXPECT_EQ(names, expected);
}

// A neutral_deg that folds the arm into the body is the posture's fault, not the stance's.
TEST(HumanModel, ASelfIntersectingNeutralPostureIsBlamedOnTheNeutralPosture) {
  const std::string dir = test::temp_dir("human_model_neutral_deg");
  // Both shoulders adducted 30 degrees: the hanging arms cross into the hips.
  const std::string cell_file =
      test::cell_variant(dir, "  arms:\n    - {name: left, base_link: torso",
                         "  neutral_deg: [0, 0, -30, 0, 0, 0, 0, 0, 0, -30, 0, 0, 0, 0, 0]\n"
                         "  arms:\n    - {name: left, base_link: torso");
  const auto cell = core::Cell::load(cell_file);
  test::expect_input_error([&] { core::check_human_stance(*cell); },
                           {"human.neutral_deg", "clears itself", "human/"});
}
