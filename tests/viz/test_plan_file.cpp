#include <gtest/gtest.h>

#include "hila/viz/plan_file.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

// A plan file as `hila plan -o` writes it, cut to what the export reads.
std::string plan_text(const std::string& second_time = "0.5", const std::string& version = "1",
                      const std::string& second_joints = "[0.1, 0, 0, 0, 0, 0.2]") {
  return R"({"hila_plan": )" + version + R"(, "database": "out/cabinet.hila",
  "scene": "meshes/cabinet/scene.yaml", "product": "cabinet", "boards": [
  {"board": "base", "status": "solved", "reason": "", "duration_s": 1.5,
   "robot_handover": {"xyz": [0.1, 0.2, 0.3], "quat_wxyz": [1, 0, 0, 0]},
   "human_handover": {"xyz": [0.4, 0.5, 0.6], "quat_wxyz": [0, 1, 0, 0]},
   "steps": [
    {"name": "suction_pick", "arm": "right", "events": "suction_on", "time_s": [0, )" +
         second_time + R"(],
     "joints_rad": [[0, 0, 0, 0, 0, 0], )" +
         second_joints + R"(]},
    {"name": "suction_retreat", "arm": "right", "events": "suction_off,gripper_open",
     "time_s": [0.5, 1.5], "joints_rad": [[0.1, 0, 0, 0, 0, 0.2], [0, 0, 0, 0, 0, 0]]}]},
  {"board": "top", "status": "no goal", "reason": "no goal"}]})";
}

TEST(PlanFile, ReadsBoardsStepsAndPoses) {
  const viz::PlanFile plan = viz::parse_plan_file(plan_text(), "plan.json");
  EXPECT_EQ(plan.product, "cabinet");
  EXPECT_EQ(plan.scene, "meshes/cabinet/scene.yaml");
  ASSERT_EQ(plan.boards.size(), 2u);
  const viz::PlanFileBoard& base = plan.boards[0];
  EXPECT_TRUE(base.solved());
  EXPECT_FALSE(plan.boards[1].solved());
  EXPECT_EQ(plan.duration(), 1.5);
  ASSERT_EQ(base.steps.size(), 2u);
  EXPECT_EQ(base.steps[1].events, (std::vector<std::string>{"suction_off", "gripper_open"}));
  EXPECT_EQ(base.steps[0].time, (std::vector<double>{0.0, 0.5}));
  EXPECT_EQ(base.steps[0].joints[1][5], 0.2);
  ASSERT_TRUE(base.robot_handover && base.human_handover);
  EXPECT_EQ(base.robot_handover->translation(), Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_NEAR(
      (base.human_handover->linear() - Eigen::Vector3d(1, -1, -1).asDiagonal().toDenseMatrix())
          .norm(),
      0.0, 1e-15);
}

TEST(PlanFile, BadFilesNameTheField) {
  expect_input_error([] { viz::parse_plan_file(plan_text("0.5", "2"), "plan.json"); },
                     {"plan.json", "hila_plan"});
  expect_input_error([] { viz::parse_plan_file("{", "plan.json"); }, {"plan.json", "JSON"});
  // Times that go back, a step past the board's duration, a joint vector of another size.
  expect_input_error([] { viz::parse_plan_file(plan_text("-0.5"), "plan.json"); },
                     {"boards[0].steps[0].time_s[1]", "do not decrease"});
  expect_input_error([] { viz::parse_plan_file(plan_text("2.0"), "plan.json"); },
                     {"boards[0].steps", "time_s"});
  expect_input_error([] { viz::parse_plan_file(plan_text("0.5", "1", "[0, 0]"), "plan.json"); },
                     {"boards[0].steps[0].joints_rad[1]"});
  expect_input_error([] { viz::read_plan_file(temp_dir("plan_file") + "/none.json"); },
                     {"none.json", "cannot open"});
}

}  // namespace
}  // namespace hila::test
