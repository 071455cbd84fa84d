#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "gltf_reading.hpp"
#include "hila/core/error.hpp"
#include "hila/viz/plan_export.hpp"
#include "util/test_util.hpp"

namespace hila::test {
namespace {

constexpr double kJointTolerance = 1e-6;  // rad, and m for link poses

// A hand-written plan: board 0 picked by the right arm's suction (suction_on), taken by the left
// gripper (gripper_close), let go by the suction (suction_off) and the gripper (gripper_open);
// board 1 the same with fewer steps; board 2 not solved. Seeded random walks within the limits.
struct TinyPlan {
  viz::PlanFile plan;
  viz::PlanStart start;
};

void add_step(const core::Cell& cell, viz::PlanFileBoard& board, const std::string& name,
              const std::string& arm_name, const std::string& events, Eigen::VectorXd& robot_q,
              double& time, std::mt19937_64& rng) {
  const core::Arm& arm = cell.arm(arm_name);
  viz::PlanFileStep step{name, arm_name, {}, {}, {}};
  if (!events.empty()) step.events.push_back(events);
  Eigen::VectorXd q = cell.arm_joints(robot_q, arm);
  const int samples = std::uniform_int_distribution<int>(2, 12)(rng);
  for (int i = 0; i < samples; ++i) {
    if (i > 0) {
      time += std::uniform_real_distribution<double>(0.02, 0.4)(rng);
      for (int k = 0; k < q.size(); ++k) {
        q[k] = std::clamp(q[k] + std::uniform_real_distribution<double>(-0.2, 0.2)(rng),
                          arm.chain.lower_limits()[k], arm.chain.upper_limits()[k]);
      }
    }
    step.time.push_back(time);
    step.joints.push_back(q);
  }
  cell.set_arm(robot_q, arm, q);
  board.steps.push_back(step);
}

TinyPlan tiny_plan(const core::Cell& cell, const core::ProductSpec& product) {
  TinyPlan t;
  t.plan.file = "tiny_plan.json";
  t.plan.product = product.name;
  std::mt19937_64 rng(34);
  Eigen::VectorXd robot_q = cell.home_configuration(cell.spec().gripper.jaw_max);
  for (int b = 0; b < 3; ++b) {
    viz::PlanFileBoard board;
    board.board = product.parts[static_cast<std::size_t>(b)].name;
    board.status = b < 2 ? "solved" : "no goal";
    double time = 0.0;
    if (board.solved()) {
      add_step(cell, board, "suction_approach", "right", "", robot_q, time, rng);
      add_step(cell, board, "suction_pick", "right", "suction_on", robot_q, time, rng);
      if (b == 0) add_step(cell, board, "lift", "right", "", robot_q, time, rng);
      add_step(cell, board, "receiving_grasp", "left", "gripper_close", robot_q, time, rng);
      add_step(cell, board, "suction_retreat", "right", "suction_off", robot_q, time, rng);
      add_step(cell, board, "transfer_to_human", "left", "wait_for_human", robot_q, time, rng);
      add_step(cell, board, "release_retreat", "left", "gripper_open", robot_q, time, rng);
      board.duration = time;
    }
    t.plan.boards.push_back(board);
    std::mt19937_64 pose_rng(100 + static_cast<std::uint64_t>(b));
    t.start.initial[board.board] = random_pose(pose_rng);
  }
  std::mt19937_64 pose_rng(99);
  t.start.tool = random_pose(pose_rng);
  t.start.assembly_frame = random_pose(pose_rng);
  return t;
}

// The robot's configuration the plan has at `time` (whole plan), linearly interpolated.
Eigen::VectorXd plan_configuration(const core::Cell& cell, const viz::PlanFile& plan, double time) {
  Eigen::VectorXd q = cell.home_configuration(cell.spec().gripper.jaw_max);
  double offset = 0.0;
  for (const auto& b : plan.boards) {
    for (const auto& s : b.steps) {
      const core::Arm& arm = cell.arm(s.arm);
      const double t = time - offset;
      if (t < s.time.front()) return q;
      std::size_t i = 0;
      while (i + 1 < s.time.size() && s.time[i + 1] <= t) ++i;
      if (i + 1 == s.time.size()) {
        cell.set_arm(q, arm, s.joints.back());
      } else {
        const double f = (t - s.time[i]) / (s.time[i + 1] - s.time[i]);
        cell.set_arm(q, arm, (1.0 - f) * s.joints[i] + f * s.joints[i + 1]);
      }
    }
    offset += b.duration;
  }
  return q;
}

class PlanExport : public ::testing::Test {
 protected:
  void SetUp() override {
    cell_ = reference_cell();
    product_ = core::load_product(product_path());
    tiny_ = tiny_plan(*cell_, product_);
    gltf_ = load_glb(viz::plan_glb(*cell_, product_, tiny_.start, tiny_.plan));
    tracks_ = animation_tracks(gltf_);
    nodes_ = nodes_by_name(gltf_);
  }
  core::Pose tip(const Eigen::VectorXd& q, const std::string& arm) const {
    std::vector<core::Pose> links;
    cell_->robot().link_poses(q, links);
    return links[static_cast<std::size_t>(
        cell_->robot().link_index(cell_->arm(arm).spec.tip_link))];
  }
  // The one visible copy of `board` (stack/, held/, placed/, finished/) at `time`.
  core::Pose visible_board(const NodeState& state, const std::string& board) const {
    int shown = 0;
    std::string debug;
    core::Pose pose = core::Pose::Identity();
    for (const auto& [name, n] : nodes_) {
      const auto slash = name.find('/');
      const std::string rest = name.substr(slash + 1);
      if (rest != board && rest.rfind(board + "#", 0) != 0) continue;
      const std::string kind = name.substr(0, slash);
      if (kind != "stack" && kind != "held" && kind != "placed" && kind != "finished") continue;
      if (!state.visible[static_cast<std::size_t>(n)]) continue;
      ++shown;
      debug += " " + name;
      pose = state.world[static_cast<std::size_t>(n)];
    }
    EXPECT_EQ(shown, 1) << board << debug;
    return pose;
  }

  std::shared_ptr<const core::Cell> cell_;
  core::ProductSpec product_;
  TinyPlan tiny_;
  tinygltf::Model gltf_;
  std::map<std::pair<int, std::string>, Track> tracks_;
  std::map<std::string, int> nodes_;
};

TEST_F(PlanExport, OneAnimationEndingAtThePlansDuration) {
  ASSERT_GE(gltf_.animations.size(), 1u);
  EXPECT_EQ(gltf_.animations[0].name, "plan");
  double end = 0.0;
  for (const auto& [key, track] : tracks_) end = std::max<double>(end, track.times.back());
  EXPECT_EQ(static_cast<float>(end), static_cast<float>(tiny_.plan.duration()));
  EXPECT_GT(tiny_.plan.duration(), 1.0);
}

TEST_F(PlanExport, JointAnglesAtEveryTimeStampAndBetween) {
  double offset = 0.0;
  int checked = 0;
  for (const auto& b : tiny_.plan.boards) {
    for (const auto& s : b.steps) {  // every step present: its every time stamp and midpoints
      for (std::size_t i = 0; i < s.time.size(); ++i) {
        for (double f : {0.0, 0.5}) {
          if (f > 0.0 && i + 1 == s.time.size()) continue;
          const double t_plan =
              offset + s.time[i] + (i + 1 < s.time.size() ? f * (s.time[i + 1] - s.time[i]) : 0.0);
          // glTF's times are floats: the float key times, interpolated at the same fraction.
          const float k0 = static_cast<float>(offset + s.time[i]);
          const float k1 = i + 1 < s.time.size() ? static_cast<float>(offset + s.time[i + 1]) : k0;
          const double t_gltf = k0 + f * (static_cast<double>(k1) - k0);
          const Eigen::VectorXd q = plan_configuration(*cell_, tiny_.plan, t_plan);
          for (const core::Arm& arm : cell_->arms()) {
            for (int k = 0; k < arm.chain.dof(); ++k) {
              const int variable = arm.chain.model_variables()[static_cast<std::size_t>(k)];
              const int j = cell_->robot().variable_joints()[static_cast<std::size_t>(variable)];
              const core::Joint& joint = cell_->robot().joints()[static_cast<std::size_t>(j)];
              const int node = nodes_.at(
                  "robot/" +
                  cell_->robot().links()[static_cast<std::size_t>(joint.child_link)].name);
              const auto track = tracks_.find({node, "rotation"});
              ASSERT_NE(track, tracks_.end()) << joint.name;
              const Eigen::VectorXd r = sample(track->second, t_gltf);
              const Eigen::Matrix3d relative =
                  joint.origin.linear().transpose() *
                  Eigen::Quaterniond(r[3], r[0], r[1], r[2]).normalized().toRotationMatrix();
              const Eigen::AngleAxisd aa(relative);
              const double angle = aa.axis().dot(joint.axis) >= 0.0 ? aa.angle() : -aa.angle();
              const double expected = q[variable];
              EXPECT_NEAR(std::remainder(angle - expected, 2.0 * core::kPi), 0.0, kJointTolerance)
                  << joint.name << " at " << t_plan << " s, step " << s.name;
              ++checked;
            }
          }
          // And every robot link where the plan's forward kinematics puts it.
          const NodeState state = node_states(gltf_, &tracks_, t_gltf);
          std::vector<core::Pose> links;
          cell_->robot().link_poses(q, links);
          for (std::size_t l = 0; l < links.size(); ++l) {
            const int n = nodes_.at("robot/" + cell_->robot().links()[l].name);
            ASSERT_LT(pose_error(state.world[static_cast<std::size_t>(n)], links[l]),
                      kJointTolerance)
                << cell_->robot().links()[l].name << " at " << t_plan << " s";
          }
        }
      }
    }
    offset += b.duration;
  }
  EXPECT_GT(checked, 1000);
}

TEST_F(PlanExport, BoardsFollowTheEvents) {
  double offset = 0.0;
  for (const auto& b : tiny_.plan.boards) {
    const core::PartSpec& part = product_.part(b.board);
    const core::Pose initial = tiny_.start.initial.at(b.board);
    // Expected world pose of the board, event by event.
    core::Pose world = initial;
    std::string holder;
    core::Pose in_holder = core::Pose::Identity();
    auto check_at = [&](double t_plan, const core::Pose& expected) {
      const NodeState state = node_states(gltf_, &tracks_, static_cast<float>(t_plan));
      EXPECT_LT(pose_error(visible_board(state, b.board), expected), kJointTolerance)
          << b.board << " at " << t_plan << " s";
    };
    check_at(0.0, b.solved() || offset > 0.0 ? initial : tiny_.start.assembly_frame * part.target);
    for (const auto& s : b.steps) {
      const double t0 = offset + s.time.front();
      const double t1 = offset + s.time.back();
      const bool releases =
          !s.events.empty() && (s.events[0] == "suction_off" || s.events[0] == "gripper_open");
      if (releases && holder == s.arm) {
        world = tip(plan_configuration(*cell_, tiny_.plan, t0), holder) * in_holder;
        holder.clear();
      }
      for (std::size_t i = 0; i < s.time.size(); ++i) {
        const double t = offset + s.time[i];
        if (t >= offset + b.duration) continue;  // the board's end: assembled (checked below)
        if (i + 1 == s.time.size() && !s.events.empty() &&
            (s.events[0] == "suction_on" || s.events[0] == "gripper_close")) {
          continue;  // the grasp's own instant: checked after the handover below
        }
        const core::Pose expected =
            holder.empty() ? world
                           : tip(plan_configuration(*cell_, tiny_.plan, t), holder) * in_holder;
        check_at(t, expected);
      }
      if (!s.events.empty() && (s.events[0] == "suction_on" || s.events[0] == "gripper_close")) {
        const Eigen::VectorXd q = plan_configuration(*cell_, tiny_.plan, t1);
        if (!holder.empty()) world = tip(q, holder) * in_holder;
        holder = s.arm;
        in_holder = tip(q, holder).inverse() * world;
        check_at(t1, world);
      }
    }
    offset += b.duration;
    // Assembled at its end, in the scene's assembly frame, to the plan's end.
    check_at(offset, tiny_.start.assembly_frame * part.target);
    check_at(tiny_.plan.duration(), tiny_.start.assembly_frame * part.target);
  }
}

// Besides "plan", one animation per solved board named after it, over the board's span of the
// plan file (0 to its duration): the joints at its time stamps and between are the plan's, and
// every board copy shows as in "plan" at the same moment of the whole plan.
TEST_F(PlanExport, OneAnimationPerSolvedBoardOverItsSpan) {
  std::vector<std::string> expected{"plan"};
  for (const auto& b : tiny_.plan.boards) {
    if (b.solved()) expected.push_back(b.board);
  }
  ASSERT_EQ(expected.size(), 3u);  // the tiny plan's third board is not solved
  std::vector<std::string> names;
  for (const auto& a : gltf_.animations) names.push_back(a.name);
  ASSERT_EQ(names, expected);

  double offset = 0.0;
  int animation = 0, checked = 0;
  for (const auto& b : tiny_.plan.boards) {
    if (!b.solved()) continue;
    ++animation;
    const auto tracks = animation_tracks(gltf_, animation);
    float begin = std::numeric_limits<float>::infinity(), end = -begin;
    for (const auto& [key, track] : tracks) {
      begin = std::min(begin, track.times.front());
      end = std::max(end, track.times.back());
    }
    EXPECT_EQ(begin, 0.0f) << b.board;
    EXPECT_EQ(end, static_cast<float>(b.duration)) << b.board;
    // Every arm joint and every board copy whose visibility changes in "plan" is keyed here.
    EXPECT_EQ(tracks.size(), tracks_.size()) << b.board;

    // (plan time from the board's start, glTF time): the time stamps and the midpoints between,
    // the glTF times from the float keys as in JointAnglesAtEveryTimeStampAndBetween.
    std::vector<std::pair<double, double>> times{{b.duration, static_cast<float>(b.duration)}};
    for (const auto& s : b.steps) {
      for (std::size_t i = 0; i < s.time.size(); ++i) {
        const float k0 = static_cast<float>(s.time[i]);
        times.emplace_back(s.time[i], k0);
        if (i + 1 == s.time.size()) continue;
        const float k1 = static_cast<float>(s.time[i + 1]);
        times.emplace_back(0.5 * (s.time[i] + s.time[i + 1]), k0 + 0.5 * (double{k1} - k0));
      }
    }
    for (const auto& [t, t_gltf] : times) {
      const Eigen::VectorXd q = plan_configuration(*cell_, tiny_.plan, offset + t);
      for (const core::Arm& arm : cell_->arms()) {
        for (int k = 0; k < arm.chain.dof(); ++k) {
          const int variable = arm.chain.model_variables()[static_cast<std::size_t>(k)];
          const int j = cell_->robot().variable_joints()[static_cast<std::size_t>(variable)];
          const core::Joint& joint = cell_->robot().joints()[static_cast<std::size_t>(j)];
          const int node = nodes_.at(
              "robot/" + cell_->robot().links()[static_cast<std::size_t>(joint.child_link)].name);
          const auto track = tracks.find({node, "rotation"});
          ASSERT_NE(track, tracks.end()) << joint.name;
          const Eigen::VectorXd r = sample(track->second, t_gltf);
          const Eigen::AngleAxisd aa(
              joint.origin.linear().transpose() *
              Eigen::Quaterniond(r[3], r[0], r[1], r[2]).normalized().toRotationMatrix());
          const double angle = aa.axis().dot(joint.axis) >= 0.0 ? aa.angle() : -aa.angle();
          EXPECT_NEAR(std::remainder(angle - q[variable], 2.0 * core::kPi), 0.0, kJointTolerance)
              << b.board << ": " << joint.name << " at " << t << " s";
          ++checked;
        }
      }
    }
    // At the time stamps inside the span (its ends are where "plan"'s STEP keys switch copies),
    // every board shows where "plan" shows it at the same moment of the whole plan.
    for (const auto& s : b.steps) {
      for (const double t : s.time) {
        if (!(t > 0.0 && t < b.duration)) continue;
        const NodeState here = node_states(gltf_, &tracks, static_cast<float>(t));
        const NodeState whole = node_states(gltf_, &tracks_, static_cast<float>(offset + t));
        for (const auto& other : tiny_.plan.boards) {
          EXPECT_LT(pose_error(visible_board(here, other.board), visible_board(whole, other.board)),
                    kJointTolerance)
              << other.board << " in " << b.board << "'s animation at " << t << " s";
        }
      }
    }
    offset += b.duration;
  }
  EXPECT_GT(checked, 500);
}

TEST_F(PlanExport, ToolStaysOnTheTableWithoutToolSteps) {
  const int handle = nodes_.at("tool/" + cell_->spec().suction.handle_link + "#0");
  for (double t : {0.0, 0.5 * tiny_.plan.duration(), tiny_.plan.duration()}) {
    const NodeState state = node_states(gltf_, &tracks_, t);
    EXPECT_TRUE(state.visible[static_cast<std::size_t>(handle)]);
    EXPECT_LT(pose_error(state.world[static_cast<std::size_t>(handle)], tiny_.start.tool), 1e-9);
  }
}

TEST(PlanExportInput, UnknownBoardAndWrongJointCountAreBadInput) {
  const auto cell = reference_cell();
  const core::ProductSpec product = core::load_product(product_path());
  TinyPlan t = tiny_plan(*cell, product);
  TinyPlan unknown = t;
  unknown.plan.boards[0].board = "no_such_board";
  expect_input_error([&] { viz::plan_glb(*cell, product, unknown.start, unknown.plan); },
                     {"no_such_board"});
  t.plan.boards[0].steps[0].joints[0] = Eigen::VectorXd::Zero(4);
  expect_input_error([&] { viz::plan_glb(*cell, product, t.start, t.plan); },
                     {"joints_rad", "6 joints", "got 4"});
}

}  // namespace
}  // namespace hila::test
