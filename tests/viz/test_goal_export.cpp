#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "gltf_reading.hpp"
#include "hila/core/error.hpp"
#include "hila/core/product.hpp"
#include "hila/viz/goal_export.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

Eigen::VectorXd random_joints(const core::KinematicChain& chain, std::mt19937_64& rng) {
  Eigen::VectorXd q(chain.dof());
  for (int k = 0; k < q.size(); ++k) {
    q[k] = std::uniform_real_distribution<double>(std::max(chain.lower_limits()[k], -3.0),
                                                  std::min(chain.upper_limits()[k], 3.0))(rng);
  }
  return q;
}

// The test's own goals: seeded random goal poses and Q, postures of one human arm or of both (a
// two-hand part), an exchange for most goals, ranks as a database stores them (not the index).
viz::GoalsView random_goals(const core::Cell& cell, const core::ProductSpec& product, int count,
                            std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  viz::GoalsView view;
  view.part = product.parts.at(1).name;
  view.mesh = &product.parts.at(1).mesh;
  view.human_stance = random_pose(rng);
  for (int i = 0; i < count; ++i) {
    viz::GoalView g;
    g.rank = 2 * i + 1;
    g.board = random_pose(rng);
    g.quality = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
    const auto& arms = cell.human_arms();
    g.human_arms[arms.front().spec.name] = random_joints(arms.front().chain, rng);
    if (i % 2) g.human_arms[arms.back().spec.name] = random_joints(arms.back().chain, rng);
    if (i % 3 != 2) {
      const core::Arm& suction = cell.arms().at(static_cast<std::size_t>(i % 2));
      const core::Arm& receiving = cell.arms().at(static_cast<std::size_t>(1 - i % 2));
      g.exchange = viz::ExchangeView{random_pose(rng),
                                     suction.spec.name,
                                     random_joints(suction.chain, rng),
                                     receiving.spec.name,
                                     random_joints(receiving.chain, rng),
                                     0.01 + 0.005 * i};
    }
    view.goals.push_back(g);
  }
  return view;
}

class GoalExport : public ::testing::Test {
 protected:
  void SetUp() override {
    cell_ = reference_cell();
    product_ = core::load_product(product_path());
    view_ = random_goals(*cell_, product_, 7, 34);
    gltf_ = load_glb(viz::goals_glb(*cell_, view_));
    state_ = node_states(gltf_);
    nodes_ = nodes_by_name(gltf_);
  }
  // A node's pose in its goal's frame (the goal's node), as the database's world.
  core::Pose in_goal(const std::string& goal, const std::string& name) const {
    return state_.world.at(static_cast<std::size_t>(nodes_.at(goal))).inverse() *
           state_.world.at(static_cast<std::size_t>(nodes_.at(goal + "/" + name)));
  }

  std::shared_ptr<const core::Cell> cell_;
  core::ProductSpec product_;
  viz::GoalsView view_;
  tinygltf::Model gltf_;
  NodeState state_;
  std::map<std::string, int> nodes_;
};

TEST_F(GoalExport, OneNodePerGoalWithThePartAtTheGoalPose) {
  int goal_nodes = 0;
  for (const auto& [name, n] : nodes_) {
    goal_nodes += name.rfind("goal:", 0) == 0 && name.find('/') == std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(goal_nodes, static_cast<int>(view_.goals.size()));
  std::vector<Eigen::Vector3d> origins;
  for (const auto& g : view_.goals) {
    const std::string goal = "goal:" + std::to_string(g.rank);
    EXPECT_LT(pose_error(in_goal(goal, "part"), g.board), 1e-9) << goal;
    origins.push_back(state_.world.at(static_cast<std::size_t>(nodes_.at(goal))).translation());
  }
  // Side by side: no two goals' scenes at the same place.
  for (std::size_t i = 1; i < origins.size(); ++i) {
    EXPECT_GT((origins[i] - origins[i - 1]).norm(), 1.0);
  }
}

TEST_F(GoalExport, TheHumanAtTheForwardKinematicsOfTheStoredPosture) {
  const core::RobotModel& human = cell_->human();
  std::vector<core::Pose> links;
  for (const auto& g : view_.goals) {
    const std::string goal = "goal:" + std::to_string(g.rank);
    Eigen::VectorXd q = cell_->human_neutral();
    for (const core::HumanArm& arm : cell_->human_arms()) {
      const auto it = g.human_arms.find(arm.spec.name);
      if (it == g.human_arms.end()) continue;
      for (int k = 0; k < arm.chain.dof(); ++k) {
        q[arm.chain.model_variables()[static_cast<std::size_t>(k)]] = it->second[k];
      }
    }
    human.link_poses(q, links);
    for (std::size_t l = 0; l < links.size(); ++l) {
      EXPECT_LT(pose_error(in_goal(goal, "human/" + human.links()[l].name),
                           *view_.human_stance * links[l]),
                1e-9)
          << goal << " " << human.links()[l].name;
    }
    // The hand of a posed arm is where the chain's own FK puts it.
    for (const auto& [arm_name, joints] : g.human_arms) {
      const auto arm = std::find_if(cell_->human_arms().begin(), cell_->human_arms().end(),
                                    [&](const auto& a) { return a.spec.name == arm_name; });
      ASSERT_NE(arm, cell_->human_arms().end());
      const core::Pose base =
          *view_.human_stance *
          links[static_cast<std::size_t>(human.link_index(arm->spec.base_link))];
      EXPECT_LT(
          pose_error(in_goal(goal, "human/" + arm->spec.tip_link), base * arm->chain.fk(joints)),
          1e-9)
          << goal << " " << arm_name;
    }
  }
}

TEST_F(GoalExport, TheRobotAtTheExchangeHoldingTheTool) {
  const core::RobotModel& robot = cell_->robot();
  std::vector<core::Pose> links;
  int exchanges = 0;
  for (const auto& g : view_.goals) {
    const std::string goal = "goal:" + std::to_string(g.rank);
    Eigen::VectorXd q = cell_->home_configuration(cell_->spec().gripper.jaw_max);
    if (g.exchange) {
      ++exchanges;
      cell_->set_arm(q, cell_->arm(g.exchange->suction_arm), g.exchange->suction_joints);
      cell_->set_jaw(q, cell_->arm(g.exchange->suction_arm), cell_->spec().suction.handle_width);
      cell_->set_arm(q, cell_->arm(g.exchange->receiving_arm), g.exchange->receiving_joints);
      cell_->set_jaw(q, cell_->arm(g.exchange->receiving_arm), g.exchange->jaw_opening);
      EXPECT_LT(pose_error(in_goal(goal, "exchange"), g.exchange->board), 1e-9) << goal;
      robot.link_poses(q, links);
      const core::Pose tcp = links[static_cast<std::size_t>(
          robot.link_index(cell_->arm(g.exchange->suction_arm).spec.tip_link))];
      EXPECT_LT(pose_error(in_goal(goal, "tool/" + cell_->spec().suction.handle_link),
                           tcp * cell_->spec().suction.handle_in_tcp),
                1e-9)
          << goal;
    } else {
      EXPECT_EQ(nodes_.count(goal + "/exchange"), 0u);
      EXPECT_EQ(nodes_.count(goal + "/tool/" + cell_->spec().suction.handle_link), 0u);
    }
    robot.link_poses(q, links);
    for (std::size_t l = 0; l < links.size(); ++l) {
      EXPECT_LT(pose_error(in_goal(goal, "robot/" + robot.links()[l].name), links[l]), 1e-9)
          << goal << " " << robot.links()[l].name;
    }
  }
  EXPECT_GT(exchanges, 0);
}

TEST_F(GoalExport, ThePartsColourRisesWithQ) {
  std::vector<std::pair<double, std::vector<double>>> by_q;
  for (const auto& g : view_.goals) {
    const int node = nodes_.at("goal:" + std::to_string(g.rank) + "/part");
    const int mesh = gltf_.nodes[static_cast<std::size_t>(node)].mesh;
    const int material = gltf_.meshes.at(static_cast<std::size_t>(mesh)).primitives.at(0).material;
    by_q.emplace_back(g.quality, gltf_.materials.at(static_cast<std::size_t>(material))
                                     .pbrMetallicRoughness.baseColorFactor);
  }
  std::sort(by_q.begin(), by_q.end());
  for (std::size_t i = 1; i < by_q.size(); ++i) {
    EXPECT_LE(by_q[i].second[0], by_q[i - 1].second[0]);
    EXPECT_GE(by_q[i].second[1], by_q[i - 1].second[1]);
  }
  EXPECT_GT(by_q.front().second[0], by_q.back().second[0]);
}

// Coloured by RULA: green at 1 to red at 7 whatever the Q, named by the score; a goal not
// scored grey.
TEST_F(GoalExport, ByRulaThePartsColourFallsWithTheScore) {
  viz::GoalsView view = view_;
  for (std::size_t k = 0; k < view.goals.size(); ++k)
    view.goals[k].rula_grand = static_cast<int>(k);
  viz::GoalsSettings settings;
  settings.colour = viz::GoalColour::kRula;
  const tinygltf::Model gltf = load_glb(viz::goals_glb(*cell_, view, settings));
  const auto nodes = nodes_by_name(gltf);
  std::vector<std::pair<int, std::vector<double>>> by_score;
  for (const auto& g : view.goals) {
    const int node = nodes.at("goal:" + std::to_string(g.rank) + "/part");
    const int mesh = gltf.nodes[static_cast<std::size_t>(node)].mesh;
    const auto& material = gltf.materials.at(static_cast<std::size_t>(
        gltf.meshes.at(static_cast<std::size_t>(mesh)).primitives.at(0).material));
    const std::vector<double>& rgba = material.pbrMetallicRoughness.baseColorFactor;
    if (g.rula_grand == 0) {
      EXPECT_EQ(material.name, "RULA -");
      EXPECT_DOUBLE_EQ(rgba[0], rgba[1]);
      continue;
    }
    EXPECT_EQ(material.name, "RULA " + std::to_string(g.rula_grand));
    by_score.emplace_back(g.rula_grand, rgba);
  }
  ASSERT_EQ(by_score.size(), view.goals.size() - 1);
  for (std::size_t i = 1; i < by_score.size(); ++i) {
    EXPECT_GT(by_score[i].second[0], by_score[i - 1].second[0]);
    EXPECT_LT(by_score[i].second[1], by_score[i - 1].second[1]);
  }
  EXPECT_GT(by_score.front().second[1], by_score.front().second[0]);  // 1: green
  EXPECT_GT(by_score.back().second[0], by_score.back().second[1]);    // 6: red
}

TEST(GoalExportInput, JointsOfTheWrongSizeOrAnUnknownArmAreBadInput) {
  const auto cell = reference_cell();
  const core::ProductSpec product = core::load_product(product_path());
  viz::GoalsView view = random_goals(*cell, product, 2, 5);
  view.goals[0].human_arms.begin()->second = Eigen::VectorXd::Zero(2);
  expect_input_error([&] { viz::goals_glb(*cell, view); }, {"joint values", "got 2"});
  view = random_goals(*cell, product, 2, 5);
  view.goals[0].exchange->receiving_arm = "third";
  expect_input_error([&] { viz::goals_glb(*cell, view); }, {"third"});
}

}  // namespace
}  // namespace hila::test
