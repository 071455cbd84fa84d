// `hila export grasps` and `hila export goals` end to end (tools/hila/db_scenes.cpp): the command
// run on a cabinet database, its .glb read back with tinygltf and compared with the records the
// database stores, read here with hila::db.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>

#include "gltf_reading.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/receiving_scores.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

using test::CommandRun;

CommandRun run(const std::string& args) {
  return test::run_command(std::string(HILA_EXE) + " " + args);
}

class DatabaseExports : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    // A prebuilt cabinet database (HILA_TEST_DATABASE, as tools/test builds it), else a quick
    // build with maps dense enough that the boards have goals, as test_worker_comfort's.
    dir_ = temp_dir("db_scenes_" + std::to_string(::getpid()));
    if (const char* given = std::getenv("HILA_TEST_DATABASE")) {
      path_ = given;
    } else {
      path_ = dir_ + "/cabinet.hila";
      offline::BuildSettings settings = quick_build_settings(7, 2);
      settings.comfort.samples = 400000;
      settings.handover.candidates = 200;
      settings.handover.max_candidates = 400;
      offline::build_database(product_path(), cell_path(), path_, settings);
    }
    db::OpenOptions options;
    options.comfort_maps = false;
    database_ = std::make_unique<db::Database>(db::Database::open(path_, options));
  }
  static void TearDownTestSuite() { database_.reset(); }

  static std::string export_args(const std::string& what, const std::string& part,
                                 const std::string& out) {
    return "export " + what + " --db " + path_ + " --part " + part + " --cell " + cell_path() +
           " --product " + product_path() + " -o " + out;
  }

  static inline std::string dir_;
  static inline std::string path_;
  static inline std::unique_ptr<db::Database> database_;
};

TEST_F(DatabaseExports, GraspsOneNodePerStoredGraspAtItsPose) {
  const auto cell = reference_cell();
  int parts_with_suction = 0;
  for (const db::PartRecord& part : database_->parts()) {
    SCOPED_TRACE(part.name);
    const std::string out = dir_ + "/grasps_" + part.name + ".glb";
    const CommandRun r = run(export_args("grasps", part.name, out));
    ASSERT_EQ(r.status, 0) << r.out;
    const tinygltf::Model gltf = load_glb(read_file(out));
    const NodeState state = node_states(gltf);
    const auto nodes = nodes_by_name(gltf);
    int grasp_nodes = 0, suction_nodes = 0;
    for (const auto& [name, n] : nodes) {
      if (name.find('/') != std::string::npos) continue;
      grasp_nodes += name.rfind("grasp:", 0) == 0 ? 1 : 0;
      suction_nodes += name.rfind("suction:", 0) == 0 ? 1 : 0;
    }
    const auto grasps = database_->robot_grasps(part.id);
    const auto cups = database_->suction_grasps(part.id);
    ASSERT_FALSE(grasps.empty());
    EXPECT_EQ(grasp_nodes, static_cast<int>(grasps.size()));
    EXPECT_EQ(suction_nodes, static_cast<int>(cups.size()));
    parts_with_suction += cups.empty() ? 0 : 1;
    // The part in its own frame: a grasp's node at its stored TCP, a cup's at its stored frame,
    // and the gripper's TCP link and the tool's cup link there too.
    const std::string tcp_link = cell->arms().front().spec.tip_link;
    for (const auto& g : grasps) {
      const std::string name = "grasp:" + std::to_string(g.id);
      EXPECT_LT(pose_error(state.world.at(static_cast<std::size_t>(nodes.at(name))), g.tcp), 1e-9);
      EXPECT_LT(
          pose_error(state.world.at(static_cast<std::size_t>(nodes.at(name + "/" + tcp_link))),
                     g.tcp),
          1e-9);
    }
    for (const auto& c : cups) {
      const std::string name = "suction:" + std::to_string(c.id);
      EXPECT_LT(pose_error(state.world.at(static_cast<std::size_t>(nodes.at(name))), c.cup), 1e-9);
      EXPECT_LT(pose_error(state.world.at(static_cast<std::size_t>(
                               nodes.at(name + "/" + cell->spec().suction.cup_link))),
                           c.cup),
                1e-9);
    }
  }
  EXPECT_GT(parts_with_suction, 0);
}

TEST_F(DatabaseExports, GoalsAtTheStoredPosesAndPostures) {
  const auto cell = reference_cell();
  const core::RobotModel& human = cell->human();
  constexpr int kCount = 3;
  int goals_checked = 0, exchanges = 0;
  std::vector<core::Pose> links;
  for (const db::PartRecord& part : database_->parts()) {
    SCOPED_TRACE(part.name);
    std::vector<db::HandoverCandidateRecord> goals = database_->handover_goals(part.id);
    std::sort(goals.begin(), goals.end(),
              [](const auto& a, const auto& b) { return a.rank < b.rank; });
    const std::string out = dir_ + "/goals_" + part.name + ".glb";
    const CommandRun r =
        run(export_args("goals", part.name, out) + " --count " + std::to_string(kCount));
    ASSERT_EQ(r.status, 0) << r.out;
    const tinygltf::Model gltf = load_glb(read_file(out));
    const NodeState state = node_states(gltf);
    const auto nodes = nodes_by_name(gltf);
    int goal_nodes = 0;
    for (const auto& [name, n] : nodes) {
      goal_nodes += name.rfind("goal:", 0) == 0 && name.find('/') == std::string::npos ? 1 : 0;
    }
    EXPECT_EQ(goal_nodes, std::min<int>(kCount, static_cast<int>(goals.size())));
    for (std::size_t k = 0; k < goals.size() && k < static_cast<std::size_t>(kCount); ++k) {
      const db::HandoverCandidateRecord& goal = goals[k];
      const std::string prefix = "goal:" + std::to_string(goal.rank);
      const core::Pose root = state.world.at(static_cast<std::size_t>(nodes.at(prefix)));
      auto in_goal = [&](const std::string& name) {
        return root.inverse() *
               state.world.at(static_cast<std::size_t>(nodes.at(prefix + "/" + name)));
      };
      EXPECT_LT(pose_error(in_goal("part"), goal.board), 1e-9);
      // Each posed hand where the chain's FK of the stored joints puts it, from the stance.
      Eigen::VectorXd q = cell->human_neutral();
      human.link_poses(q, links);
      for (const auto& [arm_name, joints] :
           {std::pair{goal.human_arm, goal.human_joints}, {goal.second_arm, goal.second_joints}}) {
        if (arm_name.empty() || joints.size() == 0) continue;
        for (const core::HumanArm& arm : cell->human_arms()) {
          if (arm.spec.name != arm_name) continue;
          const core::Pose base =
              cell->spec().human_stance *
              links[static_cast<std::size_t>(human.link_index(arm.spec.base_link))];
          EXPECT_LT(pose_error(in_goal("human/" + arm.spec.tip_link), base * arm.chain.fk(joints)),
                    1e-9)
              << prefix << " " << arm_name;
        }
      }
      // The exchange: the first shared grasp's robot-robot pose and both arms' stored joints.
      const auto shared = database_->shared_grasps(goal.id);
      if (shared.empty()) {
        EXPECT_EQ(nodes.count(prefix + "/exchange"), 0u);
      } else {
        ++exchanges;
        db::RobotHandoverRecord rr;
        for (const auto& h : database_->robot_handovers(part.id)) {
          if (h.id == shared.front().robot_handover_id) rr = h;
        }
        EXPECT_LT(pose_error(in_goal("exchange"), rr.board), 1e-9) << prefix;
        for (const auto& [arm_name, joints] :
             {std::pair{rr.arm, rr.joints}, {shared.front().arm, shared.front().joints_rr}}) {
          const core::Arm& arm = cell->arm(arm_name);
          const core::Pose base_world = state.world.at(
              static_cast<std::size_t>(nodes.at(prefix + "/robot/" + arm.spec.base_link)));
          EXPECT_LT(pose_error(root.inverse() * state.world.at(static_cast<std::size_t>(nodes.at(
                                                    prefix + "/robot/" + arm.spec.tip_link))),
                               root.inverse() * base_world * arm.chain.fk(joints)),
                    1e-9)
              << prefix << " " << arm_name;
        }
      }
      ++goals_checked;
    }
  }
  EXPECT_GT(goals_checked, 5);
  EXPECT_GT(exchanges, 0);
}

// `--colour rula`: each goal's part named by the RULA grand score the plan file gives the same
// stored posture (online::receiving_scores), for the part's mass.
TEST_F(DatabaseExports, GoalsColouredByTheRulaOfTheStoredPosture) {
  const auto cell = reference_cell();
  const core::ProductSpec product = core::load_product(product_path());
  int scored = 0;
  for (const db::PartRecord& part : database_->parts()) {
    SCOPED_TRACE(part.name);
    std::vector<db::HandoverCandidateRecord> goals = database_->handover_goals(part.id);
    std::sort(goals.begin(), goals.end(),
              [](const auto& a, const auto& b) { return a.rank < b.rank; });
    const std::string out = dir_ + "/rula_" + part.name + ".glb";
    const CommandRun r = run(export_args("goals", part.name, out) + " --count 3 --colour rula");
    ASSERT_EQ(r.status, 0) << r.out;
    const tinygltf::Model gltf = load_glb(read_file(out));
    const auto nodes = nodes_by_name(gltf);
    for (std::size_t k = 0; k < goals.size() && k < 3; ++k) {
      const db::HandoverCandidateRecord& goal = goals[k];
      const int node = nodes.at("goal:" + std::to_string(goal.rank) + "/part");
      const int mesh = gltf.nodes[static_cast<std::size_t>(node)].mesh;
      const std::string& name =
          gltf.materials
              .at(static_cast<std::size_t>(
                  gltf.meshes.at(static_cast<std::size_t>(mesh)).primitives.at(0).material))
              .name;
      online::BoardPlan plan;
      plan.human_arm = goal.human_arm;
      plan.human_joints = goal.human_joints;
      plan.second_human_arm = goal.second_joints.size() > 0 ? goal.second_arm : "";
      plan.second_human_joints = goal.second_joints;
      const online::ReceivingScores want =
          online::receiving_scores(*cell, plan, product.part(part.name).mass);
      if (!want.scored) {
        EXPECT_EQ(name, "RULA -");
        continue;
      }
      EXPECT_EQ(name, "RULA " + std::to_string(want.rula().grand));
      ++scored;
    }
  }
  EXPECT_GT(scored, 5);
}

TEST_F(DatabaseExports, AnUnknownPartOrNoGoalCountIsBadInput) {
  CommandRun r = run(export_args("grasps", "no_such_part", dir_ + "/x.glb"));
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("no_such_part"), std::string::npos) << r.out;
  r = run(export_args("goals", database_->parts().front().name, dir_ + "/x.glb") + " --count 0");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("--count"), std::string::npos) << r.out;
  r = run(export_args("grasps", database_->parts().front().name, path_));
  EXPECT_EQ(r.status, 2) << r.out;  // never over an input
}

}  // namespace
}  // namespace hila::test
