// bench/plan_check.cpp, the benches' independent re-check of a solved plan: its human part. A
// plan the board planner returns passes; the same plan with the receiving hand's joints moved, or
// one of them past its limit, fails it with the hand named.

#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/scene.hpp"
#include "plan_check.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

class PlanCheck : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string out =
        test::cabinet_database("plan_check", test::dense_quick_build_settings());
    model_ = online::PlannerModel::load(out, test::cell_path(), test::product_path());
    scene_ = online::load_scene(test::data_path("cabinet/scene.yaml"), model_->cell(),
                                model_->product());
    // Stepped 5 cm aside: the planner solves the human's arms for this stance.
    scene_.human_stance.translation().y() += 0.05;
    plan_ = online::BoardPlanner(*model_, settings_)
                .plan(scene_, "base", std::chrono::steady_clock::now() + std::chrono::seconds(60));
  }
  static void TearDownTestSuite() { model_.reset(); }

  static bool names_the_hand(const bench::PlanCheck& check, const std::string& what) {
    for (const auto& p : check.problems) {
      if (p.find("the human's") != std::string::npos && p.find(what) != std::string::npos) {
        return true;
      }
    }
    return false;
  }

  static inline std::shared_ptr<const online::PlannerModel> model_;
  static inline online::Scene scene_;
  static inline online::BoardPlanSettings settings_;
  static inline online::BoardPlan plan_;
};

TEST_F(PlanCheck, APlannedHandoverPassesWithTheHumanTakingTheBoard) {
  ASSERT_TRUE(plan_.solved()) << plan_.reason;
  ASSERT_GT(plan_.human_joints.size(), 0);
  const bench::PlanCheck check = bench::check_plan(*model_, scene_, plan_, settings_);
  for (const auto& p : check.problems) ADD_FAILURE() << p;
}

TEST_F(PlanCheck, AReceivingPostureThatMissesTheGraspFails) {
  ASSERT_TRUE(plan_.solved()) << plan_.reason;
  online::BoardPlan moved = plan_;
  moved.human_joints[0] += 0.2;  // rad at the shoulder: the hand is centimetres off
  EXPECT_TRUE(names_the_hand(bench::check_plan(*model_, scene_, moved, settings_),
                             "its grasp on the presented board"));
  // The same joints, checked for a human standing 10 cm further back: off again.
  online::Scene back = scene_;
  back.human_stance.translation().x() += 0.10;
  EXPECT_TRUE(names_the_hand(bench::check_plan(*model_, back, plan_, settings_),
                             "its grasp on the presented board"));
}

TEST_F(PlanCheck, AReceivingPostureOutsideTheJointLimitsFails) {
  ASSERT_TRUE(plan_.solved()) << plan_.reason;
  online::BoardPlan bent = plan_;
  bent.human_joints[3] += 10.0;  // rad: past any elbow's range
  EXPECT_TRUE(
      names_the_hand(bench::check_plan(*model_, scene_, bent, settings_), "outside their limits"));
}

}  // namespace
