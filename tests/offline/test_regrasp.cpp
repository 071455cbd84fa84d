#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <tuple>

#include "hila/core/collision.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/product.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/offline/roadmap.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

// Independent references: FK through the whole robot model (not the chain), a brute-force
// collision check of the whole cell (every pair through FCL's narrow phase), the slip angle
// from the grasp's contacts and the board's centre of mass.
struct Reference {
  std::shared_ptr<const core::Cell> cell = test::reference_cell();
  core::CellScene scene = core::build_cell_scene(*cell);
  core::CollisionData data{scene.model};

  core::Pose tcp(const core::Arm& arm, const Eigen::VectorXd& q) const {
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, arm, q);
    std::vector<core::Pose> poses;
    cell->robot().link_poses(robot_q, poses);
    return poses[static_cast<std::size_t>(cell->robot().link_index(arm.spec.tip_link))];
  }
  // `jaw`: the gripper's opening (m) when it holds something, home's otherwise.
  bool arm_colliding(const core::Arm& arm, const Eigen::VectorXd& q, double jaw = -1.0) {
    return arms_colliding(arm, q, arm, q, jaw);
  }
  // Two arms posed at once (the other at home when both are the same arm).
  bool arms_colliding(const core::Arm& a, const Eigen::VectorXd& qa, const core::Arm& b,
                      const Eigen::VectorXd& qb, double jaw_a = -1.0) {
    Eigen::VectorXd robot_q = cell->home_configuration();
    cell->set_arm(robot_q, b, qb);
    cell->set_arm(robot_q, a, qa);
    if (jaw_a >= 0.0) cell->set_jaw(robot_q, a, jaw_a);
    core::set_cell_state(*cell, scene, data, robot_q, cell->human_neutral());
    return core::in_collision_brute_force(scene.model, data);
  }
  // Slip angle of a gripper grasp with the TCP at `tcp`: asin |g . (axis x lever)|.
  double slip_deg(const core::Pose& tcp, const db::RobotGraspRecord& g,
                  const Eigen::Vector3d& com) const {
    const core::Pose board = tcp * g.tcp.inverse();
    const Eigen::Vector3d axis = (g.contact_2 - g.contact_1).normalized();
    const Eigen::Vector3d centre = 0.5 * (g.contact_1 + g.contact_2);
    Eigen::Vector3d lever = com - centre;
    lever -= axis * axis.dot(lever);
    if (lever.norm() < 1e-12) return 0.0;
    const Eigen::Vector3d n = board.linear() * axis.cross(lever.normalized());
    return core::rad_to_deg(std::asin(std::min(1.0, std::abs(n.z()))));
  }
};

const core::TriangleMesh& part_mesh(const core::ProductSpec& product, const std::string& name) {
  for (const auto& p : product.parts) {
    if (p.name == name) return p.mesh;
  }
  ADD_FAILURE() << "no part " << name;
  return product.parts.front().mesh;
}

double path_length(const std::vector<Eigen::VectorXd>& path) {
  double l = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) l += (path[i] - path[i - 1]).norm();
  return l;
}

// The parts assembled before one board at their nominal targets, with that board as a moving
// body: whether the board, posed in the world, touches any of them (FCL narrow phase, pair by
// pair). Built independently of the stage scene the build uses.
class Assembly {
 public:
  Assembly(const core::ProductSpec& product, const std::string& board) {
    for (const auto& p : product.parts) {
      if (p.name == board) {
        board_ = model_.add_mesh_body("board", p.mesh, false);
        break;
      }
      model_.add_mesh_body(p.name, p.mesh, true, product.target_in_world(p));
    }
    data_ = std::make_unique<core::CollisionData>(model_);
  }
  bool touches(const core::Pose& board_world) {
    data_->set_body_pose(board_, board_world);
    return core::in_collision_brute_force(model_, *data_);
  }

 private:
  core::CollisionModel model_;
  int board_ = -1;
  std::unique_ptr<core::CollisionData> data_;
};

// The cell with one board standing still (static): where the suction arm holds it at an
// exchange, or the human at a goal. Whether the moving arm, the other arm posed too, touches
// anything. Built from the cell and the board's mesh, not from the stage scene the build checks
// in.
class BoardStanding {
 public:
  BoardStanding(const core::Cell& cell, const core::TriangleMesh& mesh, const core::Pose& board,
                const core::Arm& moving)
      : cell_(cell), scene_(core::build_cell_scene(cell)) {
    scene_.model.add_mesh_body("board_standing", mesh, true, board);
    for (std::size_t i = 0; i < cell.arms().size(); ++i) {
      if (&cell.arms()[i] == &moving) moving_bodies_ = scene_.arm_bodies[i];
    }
    data_ = std::make_unique<core::CollisionData>(scene_.model);
  }
  // The first contact of the moving arm at `q`, the other at `other_q` ("" if none).
  std::string contact(const core::Arm& moving, const Eigen::VectorXd& q, const core::Arm& other,
                      const Eigen::VectorXd& other_q) {
    Eigen::VectorXd robot_q = cell_.home_configuration();
    cell_.set_arm(robot_q, other, other_q);
    cell_.set_arm(robot_q, moving, q);
    core::set_cell_state(cell_, scene_, *data_, robot_q, cell_.human_neutral());
    core::CollisionPair pair;
    if (!core::in_collision(scene_.model, *data_, moving_bodies_, &pair)) return "";
    return core::describe_pair(scene_.model, pair);
  }
  // The first contact along `path`, every `resolution` rad.
  std::string contact_along(const core::Arm& moving, const std::vector<Eigen::VectorXd>& path,
                            double resolution, const core::Arm& other,
                            const Eigen::VectorXd& other_q) {
    for (std::size_t i = 1; i < path.size(); ++i) {
      const auto& a = path[i - 1];
      const auto& b = path[i];
      const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / resolution)));
      for (int k = 0; k <= steps; ++k) {
        std::string c =
            contact(moving, a + (b - a) * (static_cast<double>(k) / steps), other, other_q);
        if (!c.empty()) return c;
      }
    }
    return "";
  }

 private:
  const core::Cell& cell_;
  core::CellScene scene_;
  std::vector<int> moving_bodies_;
  std::unique_ptr<core::CollisionData> data_;
};

}  // namespace

// The bundled cabinet with the default settings (as tools/demo builds it): every regrasp node
// re-verified by FK, every connected path re-checked densely and independently, and all boards
// but one with the left-arm robot-robot -> robot-human transfer connected within its filter.
TEST(Regrasp, CabinetGraphReverifiedAndEveryGoalChainChecked) {
  const std::string out = test::temp_dir("regrasp") + "/cabinet.hila";
  offline::BuildSettings settings;
  settings.jobs = 2;
  const auto summary =
      offline::build_database(test::product_path(), test::cell_path(), out, settings);
  const db::Database database = db::Database::open(out);
  Reference ref;
  const core::Arm& left = ref.cell->arm("left");
  const core::Arm& right = ref.cell->arm("right");
  ASSERT_NE(database.roadmap("left"), nullptr);
  ASSERT_NE(database.roadmap("right"), nullptr);
  const core::ProductSpec product = core::load_product(test::product_path());
  const core::Pose cup_in_tcp =
      core::build_stage_scene(*ref.cell, product.parts.front().mesh, {}, "right").cup_in_tcp;

  std::vector<std::string> connected_boards, unconnected_boards;
  int alternatives = 0;
  // The cell human's hip and shoulder heights at the stance, from the anthropometric ratios
  // (not core::natural_height_band, which the build uses).
  const core::HumanDimensions dims = core::human_dimensions(core::HumanBodySpec{});
  const core::Pose stance = ref.cell->spec().human_stance;
  const double hip_z = (stance * Eigen::Vector3d(0, 0, dims.hip_height)).z();
  const double shoulder_z = (stance * Eigen::Vector3d(0, 0, dims.shoulder_height)).z();
  int band_goals_examined = 0;  // boards whose first in-band goal is not among the Eq. 8 served
  for (const auto& part : database.parts()) {
    SCOPED_TRACE(part.name);
    const auto robot = database.robot_grasps(part.id);
    const auto suction = database.suction_grasps(part.id);
    std::map<std::int64_t, const db::RobotGraspRecord*> robot_by_id;
    for (const auto& g : robot) robot_by_id[g.id] = &g;
    std::map<std::int64_t, const db::SuctionGraspRecord*> suction_by_id;
    for (const auto& g : suction) suction_by_id[g.id] = &g;
    std::map<std::int64_t, db::RobotHandoverRecord> rr_by_id;
    for (const auto& r : database.robot_handovers(part.id)) rr_by_id[r.id] = r;
    std::map<std::int64_t, db::HandoverCandidateRecord> candidate_by_id;
    for (const auto& c : database.handover_candidates(part.id)) candidate_by_id[c.id] = c;
    const Eigen::Vector3d com = part.mass_properties.com;
    Assembly assembly(product, part.name);

    // Nodes: FK of the first solution puts the grasp where the record says.
    const auto nodes = database.regrasp_nodes(part.id);
    ASSERT_FALSE(nodes.empty());
    std::map<std::int64_t, const db::RegraspNodeRecord*> node_by_id;
    for (const auto& n : nodes) {
      node_by_id[n.id] = &n;
      const core::Arm& arm = n.arm == "left" ? left : right;
      for (const auto& q : n.solutions) EXPECT_TRUE(arm.chain.within_limits(q, 1e-9));
      const core::Pose tcp = ref.tcp(arm, n.solutions.front());
      if (n.kind == "home") {
        EXPECT_TRUE(n.solutions.front().isApprox(arm.spec.home, 0.0));
      } else if (n.grasp_kind == "gripper") {
        const auto& g = *robot_by_id.at(n.grasp_id);
        const core::Pose board = n.kind == "robot_handover"
                                     ? rr_by_id.at(n.robot_handover_id).board
                                     : candidate_by_id.at(n.candidate_id).board;
        EXPECT_TRUE(tcp.isApprox(board * g.tcp, 1e-6)) << n.kind << " node " << n.id;
        EXPECT_LE(ref.slip_deg(tcp, g, com), g.theta_c_deg + 1e-6) << "node " << n.id;
        EXPECT_FALSE(ref.arm_colliding(arm, n.solutions.front())) << "node " << n.id;
      } else if (n.kind == "pick") {
        // The cup on the suction grasp's face with the board at its initial pose.
        const core::Pose cup = tcp * cup_in_tcp;
        EXPECT_TRUE(cup.isApprox(part.initial * suction_by_id.at(n.grasp_id)->cup, 1e-6))
            << "pick node " << n.id;
      }
    }

    // The first goal in Eq. 8 order whose part centre lies between the cell human's hip and
    // shoulder height is examined by the build (RegraspSettings::served_natural): a chain to
    // it, or the suction arm at each of its robot-robot poses.
    {
      std::set<std::int64_t> suction_at, human_at;
      for (const auto& n : nodes) {
        if (n.kind == "robot_handover" && n.arm == "right") suction_at.insert(n.robot_handover_id);
        if (n.kind == "human_handover") human_at.insert(n.candidate_id);
      }
      std::vector<db::HandoverCandidateRecord> goals;
      for (const auto& [id, c] : candidate_by_id) {
        if (c.status == "goal") goals.push_back(c);
      }
      std::sort(goals.begin(), goals.end(),
                [](const auto& a, const auto& b) { return a.rank < b.rank; });
      for (const auto& goal : goals) {
        const double z = (goal.board * com).z();
        if (z < hip_z || z > shoulder_z) continue;
        bool examined = human_at.count(goal.id) > 0;
        bool every_pose = true, any_pose = false;
        for (const auto& s : database.shared_grasps(goal.id)) {
          any_pose = true;
          every_pose = every_pose && suction_at.count(s.robot_handover_id) > 0;
        }
        examined = examined || (any_pose && every_pose);
        EXPECT_TRUE(examined) << "first in-band goal, rank " << goal.rank;
        band_goals_examined += goal.rank >= 3 ? 1 : 0;
        break;
      }
    }

    // Edges: every connected path runs from the from-node to the to-node with the stated
    // cost; the receiving arm's transfers keep the grasp's slip limit and the arm clear of the
    // cell at 4x the roadmap's resolution.
    bool transfer_connected = false;
    // The suction arm's node at each exchange node of the receiving arm (the handover edges).
    std::map<std::int64_t, std::int64_t> suction_node_at;
    for (const auto& e : database.regrasp_edges(part.id)) {
      if (e.kind == "handover") suction_node_at[e.to_node] = e.from_node;
    }
    int ways_in = 0;
    // Parallel transfer edges are other bridges of the first (RegraspSettings::
    // bridge_alternatives): only where the first is a bridge, in its filter, and another path.
    std::map<std::tuple<std::string, std::int64_t, std::int64_t>, db::RegraspEdgeRecord> first;
    for (const auto& e : database.regrasp_edges(part.id)) {
      if (!e.connected) continue;
      const auto key = std::make_tuple(e.kind, e.from_node, e.to_node);
      if (const auto it = first.find(key); it != first.end()) {
        EXPECT_EQ(e.kind, "transfer") << "edge " << e.id;
        EXPECT_EQ(it->second.via, "bridge") << "edge " << e.id << " is another way than a bridge";
        EXPECT_EQ(e.via, "bridge") << "edge " << e.id;
        EXPECT_EQ(e.filter_id, it->second.filter_id) << "edge " << e.id;
        EXPECT_NE(e.path, it->second.path) << "edge " << e.id << " repeats edge " << it->second.id;
        ++alternatives;
      } else {
        first.emplace(key, e);
      }
      const auto& from = *node_by_id.at(e.from_node);
      const auto& to = *node_by_id.at(e.to_node);
      if (e.kind == "handover") {
        // Both arms at the exchange, each in the branch its own edges use, clear of each other
        // and the cell (the suction arm may hold the board in another branch than the
        // handover search's).
        EXPECT_FALSE(ref.arms_colliding(right, from.solutions.front(), left, to.solutions.front()))
            << "handover edge " << e.id;
        continue;
      }
      ASSERT_GE(e.path.size(), 2u);
      EXPECT_TRUE(e.path.front().isApprox(from.solutions.front(), 1e-12)) << "edge " << e.id;
      EXPECT_TRUE(e.path.back().isApprox(to.solutions.front(), 1e-12)) << "edge " << e.id;
      EXPECT_NEAR(e.cost, path_length(e.path), 1e-9) << "edge " << e.id;
      // The receiving arm's transit to the exchange ends with its way in: home ->
      // pre-grasp -> grasp, the last segment a straight approach of at most 5 cm, and the whole
      // path clear of the board standing there in the suction arm's hand, at the empty arm's
      // resolution (the online planner follows it as it is).
      if (e.kind == "transit" && e.arm == "left" && to.kind == "robot_handover") {
        ++ways_in;
        const auto& suction_q = node_by_id.at(suction_node_at.at(e.to_node))->solutions.front();
        const std::size_t n = e.path.size();
        const double approach = (ref.tcp(left, e.path[n - 2]).translation() -
                                 ref.tcp(left, e.path[n - 1]).translation())
                                    .norm();
        const double empty_resolution = database.roadmap("left")->resolution;
        EXPECT_GT(approach, 0.0) << "edge " << e.id << " has no approach";
        EXPECT_LE(approach, 0.05 + 1e-9) << "edge " << e.id;
        BoardStanding exchange(*ref.cell, part_mesh(product, part.name),
                               rr_by_id.at(to.robot_handover_id).board, left);
        EXPECT_EQ(exchange.contact_along(left, e.path, empty_resolution, right, suction_q), "")
            << "transit edge " << e.id << " into the exchange";
      }
      // The chains are planned at the board's stage: a held board never passes
      // through the boards assembled before it, checked every 0.01 rad as online.
      if (e.kind == "transfer") {
        const core::Arm& arm = e.arm == "left" ? left : right;
        const core::Pose board_in_tcp =
            to.grasp_kind == "gripper" ? robot_by_id.at(to.grasp_id)->tcp.inverse()
                                       : cup_in_tcp * suction_by_id.at(to.grasp_id)->cup.inverse();
        int touching = 0;
        for (std::size_t i = 1; i < e.path.size(); ++i) {
          const auto& a = e.path[i - 1];
          const auto& b = e.path[i];
          const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / 0.01)));
          for (int k = 0; k <= steps; ++k) {
            const Eigen::VectorXd q = a + (b - a) * (static_cast<double>(k) / steps);
            touching += assembly.touches(ref.tcp(arm, q) * board_in_tcp) ? 1 : 0;
          }
        }
        EXPECT_EQ(touching, 0) << e.arm << " transfer edge " << e.id;
      }
      if (!(e.kind == "transfer" && e.arm == "left")) continue;
      transfer_connected = transfer_connected || to.kind == "human_handover";
      const auto& g = *robot_by_id.at(to.grasp_id);
      const core::Arm& arm = left;
      const double resolution = database.roadmap("left")->resolution / 4.0;
      double worst = 0.0;
      for (std::size_t i = 1; i < e.path.size(); ++i) {
        const auto& a = e.path[i - 1];
        const auto& b = e.path[i];
        const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / resolution)));
        for (int k = 0; k <= steps; ++k) {
          const Eigen::VectorXd q = a + (b - a) * (static_cast<double>(k) / steps);
          worst = std::max(worst, ref.slip_deg(ref.tcp(arm, q), g, com));
          if (k % 4 == 0) {
            // The jaw closed on the board: the fingers where they are during the transfer.
            EXPECT_FALSE(ref.arm_colliding(arm, q, g.jaw_width)) << "edge " << e.id;
          }
        }
      }
      // Between two checked samples (0.05 rad of joint motion) the slip angle moves little.
      EXPECT_LE(worst, g.theta_c_deg + 1.5) << "edge " << e.id;
    }
    EXPECT_GT(ways_in, 0) << "no connected transit into an exchange";
    (transfer_connected ? connected_boards : unconnected_boards).push_back(part.name);

    // Filters: bits only on edges whose both ends keep the grasp's slip limit (FK).
    const auto& left_map = *database.roadmap("left");
    for (const auto& f : database.roadmap_filters(part.id)) {
      ASSERT_EQ(f.component.size(), f.roadmap_id == left_map.id
                                        ? left_map.nodes.size()
                                        : database.roadmap("right")->nodes.size());
      if (f.grasp_kind != "gripper") continue;
      const auto& g = *robot_by_id.at(f.grasp_id);
      int checked = 0;
      for (std::size_t e = 0; e < f.edges.size() && checked < 200; e += 37) {
        if (!f.edges[e]) continue;
        ++checked;
        for (const int n : {left_map.edges[e].first, left_map.edges[e].second}) {
          const auto& q = left_map.nodes[static_cast<std::size_t>(n)];
          EXPECT_LE(ref.slip_deg(ref.tcp(left, q), g, com), g.theta_c_deg + 1e-6);
        }
        EXPECT_EQ(f.component[static_cast<std::size_t>(left_map.edges[e].first)],
                  f.component[static_cast<std::size_t>(left_map.edges[e].second)]);
      }
    }
  }
  std::string missing;
  for (const auto& n : unconnected_boards) missing += n + " ";
  // Every board: the roadmaps span the elbow's whole +-pi (core::joint_box), which
  // reaches lateral_left's exchange from home.
  EXPECT_EQ(connected_boards.size(), database.parts().size())
      << "boards without a connected transfer: " << missing;
  EXPECT_EQ(summary.unconnected_parts(), unconnected_boards);
  // lateral_left's transfer to the human is a bridge under a 17 deg slip limit; it and others
  // have alternatives.
  EXPECT_GT(alternatives, 0);
  EXPECT_TRUE(summary.failed_parts().empty());
  // back_upper's and top's first in-band goals lie beyond the three goals served in Eq. 8 order.
  EXPECT_GE(band_goals_examined, 2);
}
