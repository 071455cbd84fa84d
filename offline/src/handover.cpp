#include "hila/offline/handover.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <tuple>

#include "hila/core/collision.hpp"
#include "hila/core/comfort.hpp"
#include "hila/core/comfort_map.hpp"
#include "hila/core/error.hpp"
#include "hila/core/pre_grasp.hpp"
#include "hila/core/receiving_posture.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/offline/arm_workspace.hpp"
#include "hila/offline/gripper_pick.hpp"
#include "hila/offline/human_grasps.hpp"
#include "hila/offline/suction_pick.hpp"

namespace hila::offline {

namespace {

const core::Pose kParked = core::Pose(Eigen::Translation3d(100.0, 100.0, 100.0));
// Candidates (the nearest by Eq. 8) a part with no goal is checked at for either arm's reach.
constexpr std::size_t kReachCensus = 200;
// The human's fingers open this much wider than the grasp's aperture around the board.
constexpr double kHandOpeningMargin = 0.01;
// m: a natural band's candidates keep the part's centre this far inside the band's ends.
constexpr double kBandMargin = 0.03;
// Grasps per arm, best first by the maps' Q, judged for a natural posture by the worker's IK.
constexpr int kNaturalGrasps = 24;
const Eigen::Vector3d kDown(0.0, 0.0, -1.0);

double uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// Fisher-Yates with the raw generator: the same order on every standard library.
void shuffle(std::vector<int>& v, std::mt19937_64& rng) {
  for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[rng() % i]);
}

// A rotation drawn uniformly (Haar measure) from the ball of angle < max_angle about identity:
// axis uniform on the sphere, angle with density proportional to 1 - cos(angle).
Eigen::Matrix3d random_rotation_within(double max_angle, std::mt19937_64& rng) {
  Eigen::Vector3d axis;
  do {
    axis = Eigen::Vector3d(2 * uniform01(rng) - 1, 2 * uniform01(rng) - 1, 2 * uniform01(rng) - 1);
  } while (axis.squaredNorm() > 1.0 || axis.squaredNorm() < 1e-6);
  axis.normalize();
  const double u = uniform01(rng) * (max_angle - std::sin(max_angle));
  double lo = 0.0, hi = max_angle;
  for (int i = 0; i < 60; ++i) {  // inverse of F(t) = t - sin t
    const double mid = 0.5 * (lo + hi);
    (mid - std::sin(mid) < u ? lo : hi) = mid;
  }
  return Eigen::AngleAxisd(0.5 * (lo + hi), axis).toRotationMatrix();
}

Eigen::Vector3d random_in_ball(double radius, std::mt19937_64& rng) {
  Eigen::Vector3d u;
  do {
    u = Eigen::Vector3d(2 * uniform01(rng) - 1, 2 * uniform01(rng) - 1, 2 * uniform01(rng) - 1);
  } while (u.squaredNorm() >= 1.0);
  return radius * u;
}

// A human hand as three bodies (palm, two fingers) in a collision model.
struct HandBodies {
  int fixed = -1, finger_pos = -1, finger_neg = -1;
  std::vector<int> all() const { return {fixed, finger_pos, finger_neg}; }
};

HandBodies add_hand(core::CollisionModel& model, const HandGeometry& hand, const std::string& name,
                    int board) {
  HandBodies h;
  h.fixed = model.add_body(name + "/palm", hand.fixed, false, kParked);
  h.finger_pos = model.add_body(name + "/finger+", hand.finger_pos, false, kParked);
  h.finger_neg = model.add_body(name + "/finger-", hand.finger_neg, false, kParked);
  for (const int b : h.all()) {
    model.allow(b, board);  // the hand holds the board
    for (const int c : h.all()) {
      if (b != c) model.allow(b, c);
    }
  }
  return h;
}

void place_hand(core::CollisionData& data, const HandBodies& h, const core::Pose& grasp_world,
                double opening) {
  data.set_body_pose(h.fixed, grasp_world);
  data.set_body_pose(h.finger_pos, grasp_world * Eigen::Translation3d(0.0, 0.5 * opening, 0.0));
  data.set_body_pose(h.finger_neg, grasp_world * Eigen::Translation3d(0.0, -0.5 * opening, 0.0));
}

void park_hand(core::CollisionData& data, const HandBodies& h) {
  for (const int b : h.all()) data.set_body_pose(b, kParked);
}

// The human's choice at one candidate pose.
struct HumanChoice {
  int body = -1;         // the worker chosen for: -1 the cell's human, else a body of the set
  double quality = 0.0;  // that worker's (weaker hand for two hands)
  double default_quality = 0.0;  // the cell's human alone
  int arm = -1, grasp = -1;
  double arm_quality = 0.0;
  int second_arm = -1, second_grasp = -1;
  double second_quality = 0.0;
};

struct ScoredGrasp {
  double quality;
  double default_quality;
  int grasp;
};

// Grasps of `arm` at `board`, best first by the Q of worker `body` (-1: the cell's human, else a
// body of the set), with positive Q.
std::vector<ScoredGrasp> score_grasps(const HumanComfort& comfort, int body, int arm,
                                      const core::Pose& board,
                                      const std::vector<db::HumanGraspRecord>& grasps,
                                      const std::vector<int>& eligible) {
  std::vector<ScoredGrasp> out;
  for (const int g : eligible) {
    const core::Pose hand = board * grasps[static_cast<std::size_t>(g)].hand;
    const double q0 = comfort.quality(arm, hand);
    const double q = body < 0 ? q0 : comfort.body_quality(body, arm, hand);
    if (q > 0.0 || q0 > 0.0) out.push_back({q, q0, g});
  }
  std::stable_sort(out.begin(), out.end(), [](const ScoredGrasp& a, const ScoredGrasp& b) {
    return a.quality > b.quality;
  });
  return out;
}

struct Receiving {
  int grasp = -1;
  Eigen::VectorXd joints;
  double slip_deg = 0.0;
};

}  // namespace

double rotation_angle_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return core::rad_to_deg(Eigen::AngleAxisd(a.transpose() * b).angle());
}

double handover_distance(const core::Pose& a, const core::Pose& b, double rotation_weight) {
  return (a.translation() - b.translation()).norm() +
         rotation_weight * Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

HandoverResult plan_handover_goals(const core::Cell& cell, const core::ProductSpec& product,
                                   std::size_t index, const BoardGrasps& grasps,
                                   const HumanComfort& comfort, const HandoverSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const core::PartSpec& part = product.parts[index];
  const core::Pose target = product.target_in_world(part);
  HandoverResult result;
  auto& stage = result.stage;
  const std::vector<core::PlacedPart> finished = core::parts_before(product, index);
  for (const auto& p : finished) stage.finished_parts.push_back(p.name);

  // --- Scenes -----------------------------------------------------------------------------
  // Screening (Eq. 1 and the human's hands): finished parts, the table taken as solid down to
  // the floor (a board under the table top is no handover), the human's body.
  const HandGeometry hand_geometry = human_hand_geometry(cell.spec().human_hand);
  core::CollisionModel screen;
  const core::RobotBodies screen_human = core::add_robot(screen, cell.human(), "human/", true);
  const double floor_z = cell.spec().human_stance.translation().z();
  for (const auto& o : cell.spec().obstacles) {
    const double top = o.pose.translation().z() + 0.5 * o.size.z();
    core::GeometrySpec box;
    box.box_size = Eigen::Vector3d(o.size.x(), o.size.y(), top - floor_z);
    core::Pose pose = o.pose;
    pose.translation().z() = 0.5 * (top + floor_z);
    screen.add_body(o.name, {box}, true, pose);
  }
  for (const auto& f : finished) screen.add_mesh_body("finished/" + f.name, *f.mesh, true, f.pose);
  const int screen_board = screen.add_mesh_body("board", part.mesh, false, kParked);
  const HandBodies screen_hands[2] = {add_hand(screen, hand_geometry, "hand0", screen_board),
                                      add_hand(screen, hand_geometry, "hand1", screen_board)};
  for (const int h0 : screen_hands[0].all()) {
    for (const int h1 : screen_hands[1].all()) screen.allow(h0, h1);  // two hands may touch
  }
  core::CollisionData screen_data(screen);
  {
    std::vector<core::Pose> poses;
    cell.human().link_poses(cell.human_neutral(), poses);
    core::set_robot_pose(screen_data, screen_human, poses, cell.spec().human_stance);
  }

  // Robot checks: the stage scene (the stack under the board included) with the human's hands
  // at the receiving grasp.
  core::StageScene scene = core::build_stage_scene(cell, part.mesh, finished, settings.suction_arm,
                                                   core::parts_after(product, index));
  const HandBodies robot_hands[2] = {
      add_hand(scene.cell.model, hand_geometry, "hand0", scene.board),
      add_hand(scene.cell.model, hand_geometry, "hand1", scene.board)};
  core::CollisionData data(scene.cell.model);
  const core::Arm& suction_arm = cell.arms()[static_cast<std::size_t>(scene.suction_arm)];
  const core::Arm& receiving_arm = cell.arm(settings.receiving_arm);
  for (const core::Arm* a : {&suction_arm, &receiving_arm}) {
    if (!a->ur_ik) {
      throw core::InputError(cell.spec().file, "robot.arms." + a->spec.name + ".kinematics",
                             "UR DH parameters (handover goals search the arms' analytic IK)",
                             "none");
    }
  }
  int receiving_index = 0;
  while (&cell.arms()[static_cast<std::size_t>(receiving_index)] != &receiving_arm)
    ++receiving_index;
  const std::vector<int>& receiving_bodies =
      scene.cell.arm_bodies[static_cast<std::size_t>(receiving_index)];
  std::vector<int> suction_bodies =
      scene.cell.arm_bodies[static_cast<std::size_t>(scene.suction_arm)];
  suction_bodies.insert(suction_bodies.end(), scene.tool_bodies.begin(), scene.tool_bodies.end());
  suction_bodies.push_back(scene.board);
  const core::Pose suction_base_inv = core::arm_base_in_world(cell, suction_arm).inverse();
  const core::Pose receiving_base_inv = core::arm_base_in_world(cell, receiving_arm).inverse();
  const Eigen::VectorXd home_q = cell.home_configuration();
  const core::Pose suction_home_tcp =
      core::arm_base_in_world(cell, suction_arm) * suction_arm.chain.fk(suction_arm.spec.home);
  Eigen::VectorXd robot_q = home_q;
  const Eigen::VectorXd human_q = cell.human_neutral();
  auto reset_state = [&] {
    robot_q = home_q;
    core::set_cell_state(cell, scene.cell, data, robot_q, human_q);
    core::set_tool_held(cell, scene, data, suction_home_tcp);
    data.set_body_pose(scene.board, kParked);
    park_hand(data, robot_hands[0]);
    park_hand(data, robot_hands[1]);
  };
  reset_state();

  // --- Human grasps usable for this board -------------------------------------------------
  // One hand holds the part at its one-hand-stable grasps; two hands at any pair of grasps far
  // enough apart. The human takes it with one hand where that is comfortable, else with two.
  std::vector<int> eligible, both_hands;
  for (std::size_t g = 0; g < grasps.human.size(); ++g) {
    if (grasps.human[g].one_hand_stable) eligible.push_back(static_cast<int>(g));
    both_hands.push_back(static_cast<int>(g));
  }
  stage.two_hands = eligible.empty();
  auto human_hand_clear = [&](const core::Pose& board, int hand_slot, int grasp) {
    const auto& g = grasps.human[static_cast<std::size_t>(grasp)];
    place_hand(screen_data, screen_hands[hand_slot], board * g.hand,
               g.aperture + kHandOpeningMargin);
    const bool clear = !core::in_collision(screen, screen_data, screen_hands[hand_slot].all());
    return clear;
  };

  // The best pair of `lists` (one grasp per arm, best first, each hand clear alone) for two
  // hands: far enough apart and clear together, Q the weaker hand's; `best` improved in place.
  auto choose_pair = [&](const core::Pose& board, const std::vector<ScoredGrasp>(&lists)[2],
                         HumanChoice& best) {
    for (const auto& s0 : lists[0]) {
      for (const auto& s1 : lists[1]) {
        const double q = std::min(s0.quality, s1.quality);
        const double q0 = std::min(s0.default_quality, s1.default_quality);
        if (q <= best.quality && q0 <= best.default_quality) continue;
        const auto& g0 = grasps.human[static_cast<std::size_t>(s0.grasp)];
        const auto& g1 = grasps.human[static_cast<std::size_t>(s1.grasp)];
        if ((g0.hand.translation() - g1.hand.translation()).norm() < settings.two_hand_separation) {
          continue;
        }
        place_hand(screen_data, screen_hands[0], board * g0.hand, g0.aperture + kHandOpeningMargin);
        place_hand(screen_data, screen_hands[1], board * g1.hand, g1.aperture + kHandOpeningMargin);
        if (core::in_collision(screen, screen_data, screen_hands[0].all())) continue;
        best.default_quality = std::max(best.default_quality, q0);
        if (q > best.quality) {
          best.quality = q;
          best.arm = 0;
          best.grasp = s0.grasp;
          best.arm_quality = s0.quality;
          best.second_arm = 1;
          best.second_grasp = s1.grasp;
          best.second_quality = s1.quality;
        }
      }
    }
    park_hand(screen_data, screen_hands[0]);
    park_hand(screen_data, screen_hands[1]);
  };
  // The worker the human's grasps are chosen for (choose_human, rechoose_human): -1 the cell's
  // human, else a body of the set.
  int choosing_for = -1;
  auto choose_human = [&](const core::Pose& board) {
    HumanChoice best;
    best.body = choosing_for;
    screen_data.set_body_pose(screen_board, board);
    const int arms = comfort.arm_count();
    if (!stage.two_hands) {
      for (int a = 0; a < arms; ++a) {
        int tried = 0;
        for (const auto& s :
             score_grasps(comfort, choosing_for, a, board, grasps.human, eligible)) {
          if (s.quality <= best.quality && s.default_quality <= best.default_quality) break;
          if (++tried > 12) break;
          if (!human_hand_clear(board, 0, s.grasp)) continue;
          best.default_quality = std::max(best.default_quality, s.default_quality);
          if (s.quality > best.quality) {
            best.quality = s.quality;
            best.arm = a;
            best.grasp = s.grasp;
            best.arm_quality = s.quality;
          }
        }
      }
      park_hand(screen_data, screen_hands[0]);
      if (best.quality > settings.comfort_threshold) return best;
    }
    // Two hands: one grasp per arm, far enough apart, both clear.
    if (arms < 2) return best;
    std::vector<ScoredGrasp> lists[2];
    for (int a = 0; a < 2; ++a) {
      for (const auto& s :
           score_grasps(comfort, choosing_for, a, board, grasps.human, both_hands)) {
        if (lists[a].size() >= 10) break;
        if (human_hand_clear(board, a, s.grasp)) lists[a].push_back(s);
      }
    }
    choose_pair(board, lists, best);
    return best;
  };

  // The comfort of the human's choice h at candidate c for each worker: the cell human's Q
  // (weaker hand) as the candidate's quality, what the online planner reads for the cell's
  // human, and the bodies of the set that take it above comfort_threshold (c.bodies).
  auto worker_quality = [&](const db::HandoverCandidateRecord& c, const HumanChoice& h, int body) {
    auto one = [&](int arm, int grasp) {
      const core::Pose hand = c.board * grasps.human[static_cast<std::size_t>(grasp)].hand;
      return body < 0 ? comfort.quality(arm, hand) : comfort.body_quality(body, arm, hand);
    };
    const double q = one(h.arm, h.grasp);
    return h.second_grasp >= 0 ? std::min(q, one(h.second_arm, h.second_grasp)) : q;
  };
  // `comfort_of_cell`: also the cell human's Q by the maps as the candidate's quality and each
  // hand's (false where the cell human's own IK has just given them).
  auto record_worker_set = [&](db::HandoverCandidateRecord& c, const HumanChoice& h,
                               bool comfort_of_cell = true) {
    c.bodies = 0;
    if (h.grasp < 0) return;
    if (comfort_of_cell) {
      c.human_quality =
          comfort.quality(h.arm, c.board * grasps.human[static_cast<std::size_t>(h.grasp)].hand);
      if (h.second_grasp >= 0) {
        c.second_quality = comfort.quality(
            h.second_arm, c.board * grasps.human[static_cast<std::size_t>(h.second_grasp)].hand);
      }
      c.quality = worker_quality(c, h, -1);
    }
    for (int b = 0; b < comfort.body_count(); ++b) {
      if (worker_quality(c, h, b) > settings.comfort_threshold) c.bodies |= 1U << b;
    }
  };

  // Candidate c takes the human's choice h (its grasps, each hand's Q and the worker set's).
  auto set_human = [&](db::HandoverCandidateRecord& c, const HumanChoice& h) {
    c.human_arm.clear();
    c.human_grasp_id = -1;
    c.second_arm.clear();
    c.second_grasp_id = -1;
    if (h.grasp >= 0) {
      c.human_arm = comfort.arm_name(h.arm);
      c.human_grasp_id = h.grasp;
      c.human_quality = h.arm_quality;
    }
    if (h.second_grasp >= 0) {
      c.second_arm = comfort.arm_name(h.second_arm);
      c.second_grasp_id = h.second_grasp;
      c.second_quality = h.second_quality;
    }
    if (comfort.body_count() > 0) record_worker_set(c, h);
  };

  // --- Eq. 1 candidates and S ----------------------------------------------------------------
  // The cell human's Eq. 1 candidates and the robot-robot search draw from `rng`; each body of a
  // worker set and each natural band from a stream of its own, so that adding a worker or a band
  // changes none of the other draws.
  std::mt19937_64 rng(settings.seed);
  auto stream = [&](std::uint64_t k) {
    std::seed_seq seq{static_cast<std::uint32_t>(settings.seed),
                      static_cast<std::uint32_t>(settings.seed >> 32),
                      static_cast<std::uint32_t>(k)};
    return std::mt19937_64(seq);
  };
  // Per worker (index body + 1); body_rng[0] unused (the cell human draws from rng).
  std::vector<std::mt19937_64> body_rng, band_rng;
  for (int w = 0; w <= comfort.body_count(); ++w) {
    body_rng.push_back(stream(2 * static_cast<std::uint64_t>(w) + 1));
    band_rng.push_back(stream(2 * static_cast<std::uint64_t>(w) + 2));
  }
  const double max_rotation = core::deg_to_rad(settings.max_rotation_deg);
  const double natural_max_rotation = core::deg_to_rad(settings.natural_max_rotation_deg);
  std::vector<HumanChoice> choices;
  double best_q = 0.0;
  // S's threshold: comfort_threshold, lowered towards comfort_floor for a part with no goal.
  double threshold = settings.comfort_threshold;
  // The human's grasps as worker `choosing_for` takes the part at `board` naturally, as the
  // online planner judges it (core::reach_hand from zero; core::check_receiving_posture natural
  // at natural_max_rula): of the grasps the maps rank first per arm (kNaturalGrasps, clear of
  // the cell, the maps' Q above `floor`) those whose hand alone is natural, the best by the maps'
  // Q, one hand where the part allows one, else a pair far enough apart and clear together; no
  // grasp where none is. A hand's RULA, its elbow and the part's centre do not depend on the
  // other hand (each carries half the load), so a pair of natural hands is natural. The maps'
  // best grasps can need a bent wrist or a raised upper arm that the maps' Q (Eq. 4) weighs less
  // than RULA does.
  auto choose_natural = [&](const core::Pose& board, double floor) {
    const core::HumanBody* body = choosing_for < 0 ? nullptr : &comfort.body(choosing_for);
    const core::Pose& stance = cell.spec().human_stance;
    const Eigen::Vector3d centre = board * grasps.com;
    // The hand of `arm` at `grasp` natural alone, carrying `load` kg.
    auto natural_hand = [&](int arm, int grasp, double load) {
      const std::string name = comfort.arm_name(arm);
      const core::ComfortResult r = core::reach_hand(
          cell, body, stance, name, board * grasps.human[static_cast<std::size_t>(grasp)].hand, {});
      return r.reachable &&
             core::check_receiving_posture(cell, body, stance, {{name, r.joints}}, centre, load)
                 .natural(settings.natural_max_rula);
    };
    // Of `from`, the grasps of `arm` the maps rank first (kNaturalGrasps with Q above `above`)
    // whose hand, put in screen slot `slot`, is clear and natural carrying `load` kg: up to
    // `want`, best first.
    auto natural_grasps = [&](int arm, const std::vector<int>& from, int slot, double load,
                              double above, std::size_t want) {
      std::vector<ScoredGrasp> out;
      int tried = 0;
      for (const auto& s : score_grasps(comfort, choosing_for, arm, board, grasps.human, from)) {
        if (out.size() >= want || s.quality <= above || ++tried > kNaturalGrasps) break;
        if (human_hand_clear(board, slot, s.grasp) && natural_hand(arm, s.grasp, load)) {
          out.push_back(s);
        }
      }
      park_hand(screen_data, screen_hands[slot]);
      return out;
    };
    HumanChoice best;
    best.body = choosing_for;
    screen_data.set_body_pose(screen_board, board);
    const int arms = comfort.arm_count();
    if (!stage.two_hands) {  // one hand: the best natural grasp of either arm
      for (int a = 0; a < arms; ++a) {
        for (const auto& s :
             natural_grasps(a, eligible, 0, part.mass, std::max(best.quality, floor), 1)) {
          best.quality = best.arm_quality = s.quality;
          best.default_quality = s.default_quality;
          best.arm = a;
          best.grasp = s.grasp;
        }
      }
    }
    if (best.grasp < 0 && arms >= 2) {
      const auto all = static_cast<std::size_t>(kNaturalGrasps);
      std::vector<ScoredGrasp> lists[2] = {
          natural_grasps(0, both_hands, 0, 0.5 * part.mass, floor, all),
          natural_grasps(1, both_hands, 1, 0.5 * part.mass, floor, all)};
      choose_pair(board, lists, best);
    }
    screen_data.set_body_pose(screen_board, kParked);
    return best;
  };
  // Eq. 1: within max_rotation of the target's orientation and max_offset of its position.
  auto draw_eq1 = [&](std::mt19937_64& from) {
    core::Pose pose = core::Pose::Identity();
    pose.linear() = target.linear() * random_rotation_within(max_rotation, from);
    pose.translation() = target.translation() + random_in_ball(settings.max_offset, from);
    return pose;
  };
  // A natural band's: the orientation within max_rotation_deg (natural_max_rotation_deg where that
  // finds the worker no goal in the band) and the horizontal position of the part's centre within
  // max_offset of the target's, its height within the band
  // (kept kBandMargin inside its ends): the target lowered or raised to where the worker holds
  // it in front of the chest.
  const Eigen::Vector3d target_centre = target * grasps.com;
  // `w`: the worker whose band it is (index body + 1), whose band stream it draws from.
  // `rotation`: the orientation's limit (rad).
  auto draw_in_band = [&](const core::HeightBand& band, int w, double rotation) {
    return [&, band, w, rotation](std::mt19937_64& /*worker's*/) {
      std::mt19937_64& from = band_rng[static_cast<std::size_t>(w)];
      core::Pose pose = core::Pose::Identity();
      pose.linear() = target.linear() * random_rotation_within(rotation, from);
      Eigen::Vector3d centre = target_centre + random_in_ball(settings.max_offset, from);
      centre.z() = band.hip_z + kBandMargin +
                   uniform01(from) * std::max(0.0, band.shoulder_z - band.hip_z - 2 * kBandMargin);
      pose.translation() = centre - pose.linear() * grasps.com;
      return pose;
    };
  };
  // Candidates until there are `until`, drawn by `draw`, the human's grasps chosen for worker
  // `body` (-1: the cell's human, else a body of the set).
  std::vector<int> drawn_for;           // Eq. 1 and band candidates per worker (index body + 1)
  int draw_limit = settings.max_draws;  // stage.draws stop here (the wider band batches: more)
  auto sample_candidates = [&](int until, const auto& draw, int body) {
    // The worker's own stream (the cell human's: `rng`); a band's draw brings its own.
    std::mt19937_64& from = body < 0 ? rng : body_rng[static_cast<std::size_t>(body + 1)];
    choosing_for = body;
    drawn_for.resize(static_cast<std::size_t>(comfort.body_count() + 1), 0);
    const int before = static_cast<int>(result.candidates.size());
    while (static_cast<int>(result.candidates.size()) < until && stage.draws < draw_limit) {
      ++stage.draws;
      const core::Pose pose = draw(from);
      screen_data.set_body_pose(screen_board, pose);
      if (core::in_collision(screen, screen_data, {screen_board})) continue;
      db::HandoverCandidateRecord c;
      c.sample = static_cast<int>(result.candidates.size());
      c.board = pose;
      c.distance = handover_distance(pose, target, settings.rotation_weight);
      const HumanChoice h = choose_human(pose);
      c.quality = h.quality;
      best_q = std::max(best_q, h.quality);
      c.status = "uncomfortable";
      set_human(c, h);
      if (h.default_quality > settings.comfort_threshold) ++stage.comfortable_default_body;
      if (h.quality > settings.comfort_threshold) ++stage.comfortable;
      if (h.quality > threshold) c.status = "no_shared_grasp";
      result.candidates.push_back(c);
      choices.push_back(h);
    }
    screen_data.set_body_pose(screen_board, kParked);
    stage.candidates = static_cast<int>(result.candidates.size());
    drawn_for[static_cast<std::size_t>(body + 1)] += stage.candidates - before;
  };
  auto finish = [&](const std::string& failure) {
    stage.failure = failure;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  auto no_candidate_reason = [&]() -> std::string {
    if (stage.candidates == 0) {
      return "no pose within " + core::format_number(settings.max_rotation_deg) + " deg and " +
             core::format_number(settings.max_offset) +
             " m of the target is clear of the finished parts, the table and the human (" +
             std::to_string(stage.draws) + " draws)";
    }
    if (stage.comfortable == 0) {
      if (best_q <= 0.0) {
        return "the human reaches none of the " + std::to_string(stage.candidates) +
               " candidates around the target (is the target within reach of the stance?)";
      }
      return "no candidate is comfortable: the best human Q is " + core::format_number(best_q) +
             ", the threshold " + core::format_number(settings.comfort_threshold);
    }
    return "";
  };
  // Payload. The exchange: the suction arm carries the part on the tool, the receiving arm in its
  // jaws. A direct pick: the picking arm in its jaws. A way whose arm would be over its payload
  // is not searched; with none left the part has no goal.
  std::string exchange_failure, over_payload;
  // The suction delivery carries the part on the tool alone.
  const bool suction_within_payload =
      core::check_payload(settings.suction_arm, cell.arm(settings.suction_arm).spec.payload,
                          part.mass, core::CarryMode::kSuction, cell.spec().suction.mass)
          .within_allowed();
  for (const auto& check :
       {core::check_payload(settings.suction_arm, cell.arm(settings.suction_arm).spec.payload,
                            part.mass, core::CarryMode::kSuction, cell.spec().suction.mass),
        core::check_payload(settings.receiving_arm, cell.arm(settings.receiving_arm).spec.payload,
                            part.mass, core::CarryMode::kGripper, cell.spec().suction.mass)}) {
    if (!check.within_allowed() && exchange_failure.empty()) {
      exchange_failure = "over the payload: " + check.describe();
      if (over_payload.empty()) over_payload = exchange_failure;
    }
  }
  std::vector<const core::Arm*> direct_candidates;  // arms that may pick the part directly
  if (settings.direct) {
    for (const std::string& name : {settings.receiving_arm, settings.suction_arm}) {
      const core::Arm& a = cell.arm(name);
      const auto check = core::check_payload(name, a.spec.payload, part.mass,
                                             core::CarryMode::kGripper, cell.spec().suction.mass);
      if (check.within_allowed()) {
        direct_candidates.push_back(&a);
      } else if (over_payload.empty()) {
        over_payload = "over the payload: " + check.describe();
      }
    }
  }
  if (!exchange_failure.empty() && direct_candidates.empty() &&
      !(settings.suction_delivery && suction_within_payload)) {
    return finish(over_payload);
  }
  // Each worker's candidates: the cell's human's, then each body's of the set, each with the
  // human's grasps chosen for that worker; then those of the workers' natural bands.
  const int workers = comfort.body_count() + 1;  // worker w: body w - 1 (-1 the cell's human)
  for (int w = 0; w < workers; ++w) {
    sample_candidates(stage.candidates + (w == 0 ? settings.candidates : settings.body_candidates),
                      draw_eq1, w - 1);
  }
  // Each worker's natural band (index body + 1); band candidates at once for a worker outside
  // whose band the part's fitted centre lies.
  std::vector<core::HeightBand> band_of;
  for (int w = 0; w < workers; ++w) {
    const core::HeightBand band = core::natural_height_band(
        cell, w == 0 ? nullptr : &comfort.body(w - 1), cell.spec().human_stance);
    band_of.push_back(band);
    if (settings.natural_candidates > 0 && !band.contains(target_centre.z())) {
      sample_candidates(stage.candidates + settings.natural_candidates,
                        draw_in_band(band, w, max_rotation), w - 1);
    }
  }
  // Nothing to search for: no candidate, or none the human takes even at the comfort floor.
  if (!no_candidate_reason().empty() && settings.max_candidates <= settings.candidates &&
      (stage.candidates == 0 || best_q <= std::min(settings.comfort_floor, threshold))) {
    return finish(no_candidate_reason());
  }

  // --- Robot grasp geometry: opening axis and lever direction in the part frame ---------------
  const Eigen::Vector3d opening_tcp = cell.spec().gripper.opening_axis.normalized();
  const double jaw_margin = 0.005;
  std::vector<Eigen::Vector3d> axis_part, lever_part;
  for (const auto& g : grasps.robot) {
    const Eigen::Vector3d a = g.tcp.linear() * opening_tcp;
    axis_part.push_back(a);
    lever_part.push_back(core::lever_direction(a, 0.5 * (g.contact_1 + g.contact_2), grasps.com));
  }
  auto slip_at = [&](const core::Pose& board, int g) {
    const auto gi = static_cast<std::size_t>(g);
    return core::slip_angle_deg(board.linear() * axis_part[gi], board.linear() * lever_part[gi],
                                kDown);
  };
  // Receiving-arm IK for grasp g with the board at `board`: the first collision-free solution
  // (nearest to home first) of the receiving arm's bodies against everything else as posed.
  core::UrIkSolutions ik;
  // `arm` holding the board at `board` with robot grasp g: its first collision-free IK solution
  // (nearest home first) of `bodies` against everything else as posed, the slip within θc.
  // `way_in`: the gripper must also have a way in (the robot-robot exchange); at the human's
  // pose the online planner finds its way out or falls back to the next goal.
  auto reach_with = [&](const core::Arm& arm, const core::Pose& base_inv, const core::Pose& board,
                        int g, const std::vector<int>& bodies, bool way_in, Receiving& out) {
    const auto& grasp = grasps.robot[static_cast<std::size_t>(g)];
    const double slip = slip_at(board, g);
    if (slip > grasp.theta_c_deg) return false;
    const core::Pose tcp = base_inv * board * grasp.tcp;
    const int n = arm.ur_ik->solve(tcp, arm.spec.home, ik);
    cell.set_jaw(robot_q, arm, std::min(cell.spec().gripper.jaw_max, grasp.jaw_width + jaw_margin));
    // The arm (the rest of the robot and the board as posed) clear at q.
    auto clear = [&](const Eigen::VectorXd& q) {
      cell.set_arm(robot_q, arm, q);
      core::set_robot_state(cell, scene.cell, data, robot_q);
      return !core::in_collision(scene.cell.model, data, bodies);
    };
    auto within = [&](const Eigen::VectorXd& q) {
      return arm.chain.within_limits(q, 1e-9) && clear(q);
    };
    for (int s = 0; s < n; ++s) {
      const Eigen::VectorXd q = ik.q[static_cast<std::size_t>(s)];
      if (clear(q) && (!way_in || core::find_pre_grasp(cell, arm, q, settings.exchange_approach,
                                                       settings.exchange_resolution, within))) {
        out.grasp = g;
        out.joints = q;
        out.slip_deg = slip;
        return true;
      }
    }
    return false;
  };
  auto receive = [&](const core::Pose& board, int g, const std::vector<int>& bodies, bool way_in,
                     Receiving& out) {
    return reach_with(receiving_arm, receiving_base_inv, board, g, bodies, way_in, out);
  };
  auto restore_arm = [&](const core::Arm& arm) {
    cell.set_arm(robot_q, arm, arm.spec.home);
    cell.set_jaw(robot_q, arm, cell.spec().gripper.jaw_max);
  };
  auto restore_receiving = [&] { restore_arm(receiving_arm); };

  // --- Direct picks: an arm's gripper takes the part where it lies --------------------------
  // The suction arm's gripper is free only with the tool on the table (at the product's tool
  // pose); the receiving arm's always (the suction arm at home with the tool).
  struct DirectArm {
    const core::Arm* arm = nullptr;
    core::Pose base_inv = core::Pose::Identity();
    bool tool_on_table = false;
    std::vector<int> bodies;       // the arm's and the board's: checked at the robot-human pose
    std::vector<Receiving> picks;  // the grasps it picks the part with, grasp order
    std::unique_ptr<ArmWorkspace> workspace;  // the part standing, for picks and set-downs
    GripperPickSettings pick_settings;
    // Regrasps on the table, found when a goal first needs them: where the part is set down
    // with a pick grasp and which grasps take it again there.
    struct SetDown {
      core::Pose board;
      Receiving pick;                  // a pick grasp at the part's initial pose
      Receiving place;                 // the same grasp, its IK at the set-down pose
      std::vector<Receiving> repicks;  // the grasps that take it again there
    };
    std::optional<std::vector<SetDown>> set_downs;
  };
  std::vector<DirectArm> direct_arms;
  // Arms whose gripper picks nothing where the part lies: they may still take it where the other
  // arm sets it down (a relay).
  std::vector<DirectArm> relay_only_arms;
  std::string direct_checks;  // per arm that picks nothing: how far its grasps got
  for (const core::Arm* a : direct_candidates) {
    if (!a->ur_ik) continue;
    DirectArm d;
    d.arm = a;
    d.base_inv = core::arm_base_in_world(cell, *a).inverse();
    d.tool_on_table = a == &suction_arm;
    for (std::size_t k = 0; k < cell.arms().size(); ++k) {
      if (&cell.arms()[k] == a) d.bodies = scene.cell.arm_bodies[k];
    }
    d.bodies.push_back(scene.board);
    d.workspace = std::make_unique<ArmWorkspace>(
        cell, a->spec.name, suction_arm.spec.name, &part.mesh, finished,
        core::parts_after(product, index), d.tool_on_table ? &product.suction_tool_pose : nullptr);
    ArmWorkspace& pick = *d.workspace;
    GripperPickSettings& ps = d.pick_settings;
    ps.approach = settings.exchange_approach;
    ps.approach_resolution = settings.exchange_resolution;
    ps.lift = settings.pick_lift;
    ps.resolution = settings.exchange_resolution;
    ps.jaw_margin = jaw_margin;
    std::map<GripperPickCheck, int> stopped;  // grasps by the check they failed
    int slipping = 0;
    for (int g = 0; g < static_cast<int>(grasps.robot.size()); ++g) {
      const auto& grasp = grasps.robot[static_cast<std::size_t>(g)];
      const double slip = slip_at(part.initial, g);
      if (slip > grasp.theta_c_deg) {
        ++slipping;
        continue;
      }
      const GripperPick p = plan_gripper_pick(pick, part.initial, grasp, ps);
      if (!p.ok()) {
        ++stopped[p.failed];
        continue;
      }
      Receiving r;
      r.grasp = g;
      r.joints = p.grasp;
      r.slip_deg = slip;
      d.picks.push_back(r);
    }
    if (!d.picks.empty()) {
      direct_arms.push_back(std::move(d));
      continue;
    }
    std::string counts;
    for (const auto& [check, count] : stopped) {
      counts += (counts.empty() ? "" : ", ") + std::to_string(count) + " " + to_string(check);
    }
    if (slipping > 0) {
      counts += (counts.empty() ? "" : ", ") + std::to_string(slipping) +
                " would slip (the slip angle over θc as the part lies)";
    }
    if (!direct_checks.empty()) direct_checks += "; ";
    direct_checks += "the " + a->spec.name + " arm: " + (counts.empty() ? "no grasp" : counts);
    relay_only_arms.push_back(std::move(d));
  }
  // Regrasps on the table. Arm d's set-downs, found once when a goal first needs them: the poses
  // where one of its pick grasps sets the part down (plan_gripper_pick's way in and lift, run
  // backwards) and the other grasps take it again (plan_gripper_pick), each within θc there.
  const std::vector<core::Pose> set_down_poses =
      settings.direct ? table_set_down_poses(cell, part.mesh, grasps.com, part.initial,
                                             grasps.placements, settings.table_regrasp)
                      : std::vector<core::Pose>{};
  // Arm `by`'s gripper takes the part standing at `board` with grasp g (its way in and lift).
  auto taken_by = [&](DirectArm& by, const core::Pose& board, int g, Receiving& out) {
    const auto& grasp = grasps.robot[static_cast<std::size_t>(g)];
    const double slip = slip_at(board, g);
    if (slip > grasp.theta_c_deg) return false;
    const GripperPick p = plan_gripper_pick(*by.workspace, board, grasp, by.pick_settings);
    if (!p.ok()) return false;
    out = {g, p.grasp, slip};
    return true;
  };
  // The set-downs at `poses` where d sets the part down with one of its pick grasps and `again`
  // takes it with other grasps (d itself: another grasp than the one it let go of).
  auto find_set_downs = [&](DirectArm& d, DirectArm& again, const std::vector<core::Pose>& poses) {
    std::vector<DirectArm::SetDown> downs;
    for (const core::Pose& board : poses) {
      DirectArm::SetDown down;
      down.board = board;
      for (const Receiving& at_pick : d.picks) {
        if (!taken_by(d, board, at_pick.grasp, down.place)) continue;
        down.pick = at_pick;
        break;
      }
      if (down.place.grasp < 0) continue;
      for (int g = 0; g < static_cast<int>(grasps.robot.size()); ++g) {
        Receiving r;
        if ((&again != &d || g != down.place.grasp) && taken_by(again, board, g, r)) {
          down.repicks.push_back(r);
        }
      }
      if (!down.repicks.empty()) downs.push_back(std::move(down));
    }
    return downs;
  };
  auto set_downs_of = [&](DirectArm& d) -> const std::vector<DirectArm::SetDown>& {
    if (!d.set_downs) d.set_downs = find_set_downs(d, d, set_down_poses);
    return *d.set_downs;
  };
  // Relays from d to the other arm `to`, found once per pair when a goal first needs them.
  const std::vector<core::Pose> relay_poses =
      settings.direct ? relay_set_down_poses(cell, part.mesh, grasps.com, part.initial,
                                             grasps.placements, settings.table_regrasp)
                      : std::vector<core::Pose>{};
  std::map<std::pair<const DirectArm*, const DirectArm*>, std::vector<DirectArm::SetDown>> relays;
  auto relays_of = [&](DirectArm& d, DirectArm& to) -> const std::vector<DirectArm::SetDown>& {
    const auto key = std::make_pair(&d, &to);
    auto it = relays.find(key);
    if (it == relays.end()) it = relays.emplace(key, find_set_downs(d, to, relay_poses)).first;
    return it->second;
  };

  std::string direct_failure;
  if (!settings.direct) {
    direct_failure = "direct picks are off";
  } else if (direct_candidates.empty()) {
    direct_failure = "no arm's gripper lifts it: " + over_payload;
  } else if (direct_arms.empty()) {
    const Eigen::Vector3d at = part.initial.translation();
    direct_failure =
        "no arm's gripper takes the part where it lies (" + core::format_number(at.x()) + ", " +
        core::format_number(at.y()) + ", " + core::format_number(at.z()) + ") m with any of its " +
        std::to_string(grasps.robot.size()) + " robot grasps (" + direct_checks +
        "); lay the part within an arm's reach with room for the open gripper around it";
  }

  // --- Robot-robot handover poses ----------------------------------------------------------
  // Board orientations: first those a transfer to the goals favours (the target orientation
  // turned about the vertical, and the board lying flat, where every grasp's axis is vertical),
  // then an even spread over SO(3). Each group is tried in a seeded random order.
  std::vector<Eigen::Matrix3d> orientations;
  for (int k = 0; k < 8; ++k) {
    orientations.push_back(Eigen::AngleAxisd(k * core::kPi / 4, Eigen::Vector3d::UnitZ()) *
                           target.linear());
  }
  {
    // Flat: the part's thinnest axis vertical (up and down).
    const Eigen::Vector3d extent = part.mesh.max_corner() - part.mesh.min_corner();
    Eigen::Index thin = 0;
    extent.minCoeff(&thin);
    const Eigen::Matrix3d to_up =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::Unit(thin), Eigen::Vector3d::UnitZ())
            .toRotationMatrix();
    for (int flip = 0; flip < 2; ++flip) {
      const Eigen::Matrix3d r =
          flip ? Eigen::Matrix3d(Eigen::AngleAxisd(core::kPi, Eigen::Vector3d::UnitX()) * to_up)
               : to_up;
      for (int k = 0; k < 4; ++k) {
        orientations.push_back(Eigen::AngleAxisd(k * core::kPi / 2, Eigen::Vector3d::UnitZ()) * r);
      }
    }
  }
  const int n_favoured = static_cast<int>(orientations.size());
  for (const auto& q : core::spread_orientations(settings.rr_orientations)) {
    orientations.push_back(q.toRotationMatrix());
  }
  const int n_pos = static_cast<int>(settings.rr_positions.size());
  const int n_orient = static_cast<int>(orientations.size());
  const int n_suction = static_cast<int>(grasps.suction.size());
  // Suction grasps usable from the stack: a robot-robot pose with any other is unreachable.
  std::vector<char> pickable(static_cast<std::size_t>(n_suction), 0);
  {
    ArmWorkspace pick(cell, suction_arm.spec.name, suction_arm.spec.name, &part.mesh, finished,
                      core::parts_after(product, index));
    for (int s = 0; s < n_suction; ++s) {
      pickable[static_cast<std::size_t>(s)] =
          plan_suction_pick(pick, part.initial, grasps.suction[static_cast<std::size_t>(s)],
                            settings.pick_lift, settings.pick_resolution)
              .ok();
    }
  }
  if (!exchange_failure.empty()) {
    // over the payload: no exchange searched
  } else if (n_suction == 0) {
    exchange_failure = "no suction grasp: no flat face of the part takes the " +
                       core::format_number(cell.spec().suction.cup_radius) +
                       " m cup with the weight and its moment within the cup's limits";
  } else if (std::count(pickable.begin(), pickable.end(), 1) == 0) {
    const Eigen::Vector3d at = part.initial.translation();
    exchange_failure = "the " + suction_arm.spec.name +
                       " arm cannot pick the part by suction at its initial pose (" +
                       core::format_number(at.x()) + ", " + core::format_number(at.y()) + ", " +
                       core::format_number(at.z()) + ") m with any of its " +
                       std::to_string(n_suction) +
                       " suction grasps: out of the arm's reach there, in collision at the pick "
                       "or the approach, or the lift blocked; place the part within the " +
                       suction_arm.spec.name + " arm's reach, clear of the parts around it";
  }
  // Suction deliveries need a suction grasp the arm picks the part with where it lies.
  const bool suction_deliverable = settings.suction_delivery && suction_within_payload &&
                                   std::count(pickable.begin(), pickable.end(), 1) > 0;
  if (!exchange_failure.empty() && direct_arms.empty() && !suction_deliverable) {
    return finish(exchange_failure + "; " + direct_failure);
  }
  std::vector<int> favoured, spread;
  for (int i = 0; i < n_pos * n_orient * n_suction; ++i) {
    ((i / n_suction) % n_orient < n_favoured ? favoured : spread).push_back(i);
  }
  shuffle(favoured, rng);
  shuffle(spread, rng);
  std::vector<int> order = favoured;
  order.insert(order.end(), spread.begin(), spread.end());
  std::vector<std::vector<Receiving>> rr_grasps;  // per kept robot-robot pose
  // The first rr_per_grasp rr poses receiving each grasp, in search order.
  std::vector<std::vector<int>> rr_of_grasp(grasps.robot.size());
  int examined = 0;
  int trapping = 0;  // held poses where the board would stand in the suction arm's home
  std::vector<int> suction_arm_and_tool =
      scene.cell.arm_bodies[static_cast<std::size_t>(scene.suction_arm)];
  suction_arm_and_tool.insert(suction_arm_and_tool.end(), scene.tool_bodies.begin(),
                              scene.tool_bodies.end());
  // The suction arm holds the board at `board` on suction grasp s, clear of the cell, and its home
  // (with the tool) is clear of the board there: an exchange here must not trap the suction arm,
  // which goes home once the receiving arm holds the board. Leaves the arm and the tool posed at
  // the hold.
  auto hold_on_cup = [&](const core::Pose& board, int s, Eigen::VectorXd& suction_q) {
    const core::Pose tcp =
        board * grasps.suction[static_cast<std::size_t>(s)].cup * scene.cup_in_tcp.inverse();
    const int n = suction_arm.ur_ik->solve(suction_base_inv * tcp, suction_arm.spec.home, ik);
    if (n == 0) return false;
    data.set_body_pose(scene.board, board);
    core::set_tool_held(cell, scene, data, tcp);
    bool held = false;
    for (int k = 0; k < n && !held; ++k) {
      cell.set_arm(robot_q, suction_arm, ik.q[static_cast<std::size_t>(k)]);
      core::set_robot_state(cell, scene.cell, data, robot_q);
      if (!core::in_collision(scene.cell.model, data, suction_bodies)) {
        held = true;
        suction_q = ik.q[static_cast<std::size_t>(k)];
      }
    }
    if (!held) return false;
    cell.set_arm(robot_q, suction_arm, suction_arm.spec.home);
    core::set_robot_state(cell, scene.cell, data, robot_q);
    core::set_tool_held(cell, scene, data, suction_home_tcp);
    if (core::in_collision(scene.cell.model, data, suction_arm_and_tool)) {
      ++trapping;
      return false;
    }
    cell.set_arm(robot_q, suction_arm, suction_q);
    core::set_robot_state(cell, scene.cell, data, robot_q);
    core::set_tool_held(cell, scene, data, tcp);
    return true;
  };
  // The receiving arm takes the board held at `board` (suction grasp s, the suction arm at
  // suction_q) with each robot grasp that has fewer than rr_per_grasp poses yet (its way in
  // included); a robot-robot pose is kept when any does.
  auto receive_held = [&](const core::Pose& board, int s, const Eigen::VectorXd& suction_q) {
    std::vector<Receiving> received;
    for (int g = 0; g < static_cast<int>(grasps.robot.size()); ++g) {
      // A grasp with its rr_per_grasp poses already is not looked at again (only those are
      // stored): the way-in check makes each look costly.
      if (static_cast<int>(rr_of_grasp[static_cast<std::size_t>(g)].size()) >=
          settings.rr_per_grasp) {
        continue;
      }
      Receiving r;
      if (receive(board, g, receiving_bodies, true, r)) received.push_back(r);
    }
    restore_receiving();
    if (received.empty()) return;
    db::RobotHandoverRecord rr;
    rr.board = board;
    rr.suction_grasp_id = s;
    rr.arm = suction_arm.spec.name;
    rr.joints = suction_q;
    for (const auto& r : received) {
      auto& poses = rr_of_grasp[static_cast<std::size_t>(r.grasp)];
      if (static_cast<int>(poses.size()) < settings.rr_per_grasp) {
        poses.push_back(static_cast<int>(result.robot_handovers.size()));
      }
    }
    result.robot_handovers.push_back(rr);
    rr_grasps.push_back(std::move(received));
  };
  for (const int combo : order) {
    if (examined >= settings.rr_poses || !exchange_failure.empty()) break;
    const int s = combo % n_suction;
    if (!pickable[static_cast<std::size_t>(s)]) continue;
    const int o = (combo / n_suction) % n_orient;
    const int p = combo / (n_suction * n_orient);
    core::Pose board = core::Pose::Identity();
    board.linear() = orientations[static_cast<std::size_t>(o)];
    board.translation() = settings.rr_positions[static_cast<std::size_t>(p)];
    Eigen::VectorXd suction_q;
    if (hold_on_cup(board, s, suction_q)) {
      ++examined;
      receive_held(board, s, suction_q);
    }
    reset_state();
  }
  reset_state();
  stage.robot_handovers = static_cast<int>(result.robot_handovers.size());
  if (stage.robot_handovers == 0 && exchange_failure.empty()) {
    exchange_failure = examined == 0
                           ? "no robot-robot handover pose: the " + suction_arm.spec.name +
                                 " arm cannot hold the board by suction clear of the cell at any "
                                 "of the shared-workspace poses"
                           : "no robot-robot handover pose: the " + receiving_arm.spec.name +
                                 " arm reaches no grasp within its slip limit at the " +
                                 std::to_string(examined) + " poses the " + suction_arm.spec.name +
                                 " arm can hold";
    if (trapping > 0) {
      exchange_failure += " (" + std::to_string(trapping) +
                          " more held poses left out: the board there would stand where the " +
                          suction_arm.spec.name + " arm goes home)";
    }
  }
  // Whether either arm's gripper could hold the part at the candidates the human takes
  // comfortably at all, however it got there ("; ..." for a failure): where neither can, no way
  // from where the part lies would help (out of both arms' reach).
  // The board at candidate c with the human's hands at the grasps of their choice h.
  auto place_at_candidate = [&](const db::HandoverCandidateRecord& c, const HumanChoice& h) {
    data.set_body_pose(scene.board, c.board);
    const auto& g0 = grasps.human[static_cast<std::size_t>(h.grasp)];
    place_hand(data, robot_hands[0], c.board * g0.hand, g0.aperture + kHandOpeningMargin);
    if (h.second_grasp >= 0) {
      const auto& g1 = grasps.human[static_cast<std::size_t>(h.second_grasp)];
      place_hand(data, robot_hands[1], c.board * g1.hand, g1.aperture + kHandOpeningMargin);
    }
  };
  auto reach_census = [&]() -> std::string {
    std::vector<int> census;
    for (std::size_t i = 0; i < result.candidates.size(); ++i) {
      if (choices[i].grasp >= 0 && choices[i].quality > threshold)
        census.push_back(static_cast<int>(i));
    }
    std::stable_sort(census.begin(), census.end(), [&](int a, int b) {
      return result.candidates[static_cast<std::size_t>(a)].distance <
             result.candidates[static_cast<std::size_t>(b)].distance;
    });
    census.resize(std::min<std::size_t>(census.size(), kReachCensus));
    std::map<const core::Arm*, int> held_at;  // census candidates each arm's gripper holds it at
    for (const core::Arm* a : {&receiving_arm, &suction_arm}) {
      int& count = held_at[a];
      std::vector<int> bodies;
      for (std::size_t k = 0; k < cell.arms().size(); ++k) {
        if (&cell.arms()[k] == a) bodies = scene.cell.arm_bodies[k];
      }
      bodies.push_back(scene.board);
      const core::Pose base_inv = core::arm_base_in_world(cell, *a).inverse();
      for (const int ci : census) {
        const auto& c = result.candidates[static_cast<std::size_t>(ci)];
        const HumanChoice& h = choices[static_cast<std::size_t>(ci)];
        reset_state();
        // The suction arm's gripper holds parts only with the tool on its stand.
        if (a == &suction_arm) {
          core::set_robot_pose(data, scene.tool, scene.tool_links_in_handle,
                               product.suction_tool_pose);
        }
        place_at_candidate(c, h);
        for (int g = 0; g < static_cast<int>(grasps.robot.size()); ++g) {
          Receiving r;
          if (reach_with(*a, base_inv, c.board, g, bodies, false, r)) {
            ++count;
            break;
          }
        }
        restore_arm(*a);
      }
    }
    reset_state();
    std::string why;
    if (!census.empty()) {
      const std::string n = std::to_string(census.size());
      if (held_at[&receiving_arm] == 0 && held_at[&suction_arm] == 0) {
        why +=
            "; out of both arms' reach: neither arm's gripper holds the part (within its "
            "slip limit, clear of the human's hands) at any of the " +
            n + " nearest candidates the human takes comfortably";
      } else {
        why += "; the " + receiving_arm.spec.name + " arm's gripper would hold it at " +
               std::to_string(held_at[&receiving_arm]) + " of the " + n +
               " nearest candidates the human takes comfortably, the " + suction_arm.spec.name +
               " arm's at " + std::to_string(held_at[&suction_arm]);
      }
    }
    return why;
  };
  if (!exchange_failure.empty() && direct_arms.empty() && !suction_deliverable) {
    return finish(exchange_failure + "; " + direct_failure + reach_census());
  }

  // --- 𝕊: members of S sharing a grasp with a robot-robot pose, in Eq. 8 order -------------
  core::ComfortSettings ik_settings;
  ik_settings.ik_attempts = 12;
  ik_settings.seed = settings.seed;
  // `body` -1: the cell's human; else that body of the set, its own arm.
  auto solve_human = [&](const core::Pose& board, int arm, int grasp, int body = -1) {
    const auto a = static_cast<std::size_t>(arm);
    const auto& chain = body < 0 ? cell.human_arms()[a].chain : comfort.body(body).arms()[a].chain;
    const core::Pose base = body < 0
                                ? comfort.arm_base(arm)
                                : cell.spec().human_stance * comfort.body(body).base_in_stance(arm);
    const core::Pose hand =
        base.inverse() * board * grasps.human[static_cast<std::size_t>(grasp)].hand;
    const Eigen::VectorXd seed = Eigen::VectorXd::Zero(chain.dof())
                                     .cwiseMax(chain.lower_limits())
                                     .cwiseMin(chain.upper_limits());
    return core::best_comfort(chain, hand, seed, ik_settings);
  };
  // A candidate the human's own IK finds uncomfortable at the grasps the maps chose may be
  // comfortable at others: a map bin holds the best Q of hand orientations up to ~35 degrees
  // apart (ComfortMapSettings::orientations), which the wrist may not all reach. The human's
  // grasps by the maps' Q (up to 12 per arm, as choose_human, clear of the cell) confirmed by the
  // arm's IK above the threshold: one hand where one does, else the best pair far enough apart and
  // clear together. The candidate takes the best by the IK's Q; false when none is confirmed.
  auto rechoose_human = [&](int ci) {
    auto& c = result.candidates[static_cast<std::size_t>(ci)];
    HumanChoice& h = choices[static_cast<std::size_t>(ci)];
    const int arms = std::min(comfort.arm_count(), 2);
    choosing_for = h.body;  // chosen again for the worker the candidate was drawn for
    // Per arm, the grasps of `from` the IK confirms (that worker's arm), with the IK's Q.
    auto confirm = [&](const std::vector<int>& from, std::vector<ScoredGrasp>(&out)[2]) {
      for (int a = 0; a < arms; ++a) {
        int tried = 0;
        for (const auto& sg : score_grasps(comfort, choosing_for, a, c.board, grasps.human, from)) {
          if (++tried > 12) break;
          if (!human_hand_clear(c.board, a, sg.grasp)) continue;
          const core::ComfortResult r = solve_human(c.board, a, sg.grasp, h.body);
          if (r.reachable && r.quality > threshold) out[a].push_back({r.quality, 0.0, sg.grasp});
        }
        park_hand(screen_data, screen_hands[a]);
      }
    };
    screen_data.set_body_pose(screen_board, c.board);
    HumanChoice best;
    best.body = h.body;
    if (!eligible.empty()) {
      std::vector<ScoredGrasp> one[2];
      confirm(eligible, one);
      for (int a = 0; a < arms; ++a) {
        for (const ScoredGrasp& k : one[a]) {
          if (k.quality <= best.quality) continue;
          best.quality = best.arm_quality = k.quality;
          best.arm = a;
          best.grasp = k.grasp;
        }
      }
    }
    if (best.grasp < 0 && arms == 2) {
      std::vector<ScoredGrasp> two[2];
      confirm(both_hands, two);
      choose_pair(c.board, two, best);
    }
    screen_data.set_body_pose(screen_board, kParked);
    if (best.grasp < 0) return false;
    best.default_quality = h.default_quality;
    h = best;
    c.quality = best.quality;
    c.human_arm = comfort.arm_name(best.arm);
    c.human_grasp_id = best.grasp;
    c.human_quality = best.arm_quality;
    c.second_grasp_id = best.second_grasp;
    if (best.second_grasp >= 0) {
      c.second_arm = comfort.arm_name(best.second_arm);
      c.second_quality = best.second_quality;
    }
    if (comfort.body_count() > 0) record_worker_set(c, h, h.body >= 0);
    return true;
  };
  // Goals per worker (index body + 1).
  std::vector<int> goals_of(static_cast<std::size_t>(comfort.body_count() + 1), 0);
  // Goals confirmed by the human's IK, per worker (index body + 1).
  std::vector<int> verified(static_cast<std::size_t>(comfort.body_count() + 1), 0);
  int human_ik_rejected = 0;  // candidates a way served that the human's own IK then rejected
  // At the robot-human pose the receiving arm and the board it holds move against the rest.
  std::vector<int> rh_bodies = receiving_bodies;
  rh_bodies.push_back(scene.board);
  std::size_t searched = 0;  // candidates before this index have been searched
  // Relays are searched only for a part no other way serves at any candidate: they take two arms
  // and two more stages, and a relay goal ranked before a goal one arm serves would be tried first.
  bool relays_allowed = false;
  // The relay pass: the candidates searched before for every other way, which found none.
  bool relays_only = false;
  // The human's grasps are chosen again by IK (rechoose_human) only for a part no way serves at
  // any candidate the maps' grasps pass: where it has goals, they are kept as the maps rank them.
  bool rechoose_allowed = false;
  std::vector<int> ik_rejected;  // candidates the human's IK rejected at the maps' grasps
  // Copies of goals at the grasps a worker takes them naturally at (after the wider band
  // batches' natural check): in S down to the floor each was chosen at.
  std::map<int, double> natural_copies;  // candidate index: the floor of its Q
  // `only`: these candidates alone (those still unserved), else those from `searched` on.
  auto search_shared = [&](const std::vector<int>* only = nullptr) {
    std::vector<int> comfortable;
    for (std::size_t i = only ? 0 : searched; i < result.candidates.size(); ++i) {
      if (result.candidates[i].status == "no_shared_grasp" &&
          (!only || std::find(only->begin(), only->end(), static_cast<int>(i)) != only->end())) {
        comfortable.push_back(static_cast<int>(i));
      }
    }
    if (!only) searched = result.candidates.size();
    std::stable_sort(comfortable.begin(), comfortable.end(), [&](int a, int b) {
      return result.candidates[static_cast<std::size_t>(a)].distance <
             result.candidates[static_cast<std::size_t>(b)].distance;
    });
    for (const int ci : comfortable) {
      bool rechosen = false;  // the human's grasps chosen again by their IK (rechoose_human)
      for (bool search_again = true; search_again;) {
        search_again = false;
        auto& c = result.candidates[static_cast<std::size_t>(ci)];
        const HumanChoice& h = choices[static_cast<std::size_t>(ci)];
        // The board at the candidate with the human's hands at their grasps (again after an arm's
        // checks reset the scene).
        const auto at_candidate = [&] { place_at_candidate(c, h); };
        at_candidate();
        int shared = 0;
        for (int g = 0; g < static_cast<int>(grasps.robot.size()) && !relays_only; ++g) {
          const auto& poses = rr_of_grasp[static_cast<std::size_t>(g)];
          if (poses.empty()) continue;
          Receiving at_rh;
          if (!receive(c.board, g, rh_bodies, false, at_rh)) continue;
          ++shared;
          // One record per rr pose: the regrasp graph takes the next when a pose's suction
          // transfer is cut in the roadmap.
          for (const int rr : poses) {
            const auto& at_rr = rr_grasps[static_cast<std::size_t>(rr)];
            const auto it = std::find_if(at_rr.begin(), at_rr.end(),
                                         [&](const Receiving& r) { return r.grasp == g; });
            db::SharedGraspRecord s;
            s.candidate_id = ci;
            s.robot_grasp_id = g;
            s.robot_handover_id = rr;
            s.arm = receiving_arm.spec.name;
            s.joints_rr = it->joints;
            s.joints_rh = at_rh.joints;
            s.inclination_rr_deg = it->slip_deg;
            s.inclination_rh_deg = at_rh.slip_deg;
            result.shared.push_back(s);
          }
          if (shared >= settings.shared_stored) break;  // membership in 𝕊 is settled
        }
        restore_receiving();
        int direct = 0;
        for (const DirectArm& d : direct_arms) {
          if (relays_only) break;
          if (d.tool_on_table) {
            core::set_robot_pose(data, scene.tool, scene.tool_links_in_handle,
                                 product.suction_tool_pose);
          }
          int stored = 0;
          for (const Receiving& at_pick : d.picks) {
            Receiving at_rh;
            if (!reach_with(*d.arm, d.base_inv, c.board, at_pick.grasp, d.bodies, false, at_rh)) {
              continue;
            }
            db::DirectGraspRecord r;
            r.candidate_id = ci;
            r.robot_grasp_id = at_pick.grasp;
            r.arm = d.arm->spec.name;
            r.joints_pick = at_pick.joints;
            r.joints_rh = at_rh.joints;
            r.inclination_pick_deg = at_pick.slip_deg;
            r.inclination_rh_deg = at_rh.slip_deg;
            result.direct.push_back(r);
            ++direct;
            if (++stored >= settings.direct_stored) break;
          }
          restore_arm(*d.arm);
          reset_state();
          at_candidate();
        }
        reset_state();
        // Table regrasps of this candidate from `d`'s set-downs `downs`, taken again by `to` (d
        // itself, or the other arm for a relay): up to direct_stored whose delivering grasp `to`
        // also holds at the candidate.
        int regrasps = 0;
        auto store_set_downs = [&](const DirectArm& d, DirectArm& to,
                                   const std::vector<DirectArm::SetDown>& downs) {
          if (downs.empty()) return;
          if (to.tool_on_table) {
            core::set_robot_pose(data, scene.tool, scene.tool_links_in_handle,
                                 product.suction_tool_pose);
          }
          int stored = 0;
          for (const auto& down : downs) {
            for (const Receiving& again : down.repicks) {
              Receiving at_rh;
              if (!reach_with(*to.arm, to.base_inv, c.board, again.grasp, to.bodies, false,
                              at_rh)) {
                continue;
              }
              db::TableRegraspRecord r;
              r.candidate_id = ci;
              r.pick_grasp_id = down.pick.grasp;
              r.robot_grasp_id = again.grasp;
              r.arm = d.arm->spec.name;
              r.repick_arm = to.arm->spec.name;
              r.placement = down.board;
              r.joints_pick = down.pick.joints;
              r.joints_place = down.place.joints;
              r.joints_repick = again.joints;
              r.joints_rh = at_rh.joints;
              r.inclination_pick_deg = down.pick.slip_deg;
              r.inclination_place_deg = down.place.slip_deg;
              r.inclination_repick_deg = again.slip_deg;
              r.inclination_rh_deg = at_rh.slip_deg;
              result.regrasps.push_back(r);
              ++regrasps;
              if (++stored >= settings.direct_stored) break;
            }
            if (stored >= settings.direct_stored) break;
          }
          restore_arm(*to.arm);
          reset_state();
          at_candidate();
        };
        if (shared == 0 && direct == 0 && settings.table_regrasp.enabled && !relays_only) {
          for (DirectArm& d : direct_arms) store_set_downs(d, d, set_downs_of(d));
          reset_state();
        }
        // Relays: an arm that picks the part sets it down where the other arm takes it again.
        if (shared == 0 && direct == 0 && regrasps == 0 && settings.table_regrasp.enabled &&
            settings.table_regrasp.relay && relays_allowed) {
          for (DirectArm& d : direct_arms) {
            for (auto* group : {&direct_arms, &relay_only_arms}) {
              for (DirectArm& to : *group) {
                if (to.arm != d.arm) store_set_downs(d, to, relays_of(d, to));
              }
            }
          }
          reset_state();
        }
        int on_cup = 0;
        if (shared == 0 && direct == 0 && regrasps == 0 && suction_deliverable && !relays_only) {
          at_candidate();
          for (int s = 0; s < n_suction && on_cup < settings.direct_stored; ++s) {
            if (!pickable[static_cast<std::size_t>(s)]) continue;
            const core::Pose tcp = c.board * grasps.suction[static_cast<std::size_t>(s)].cup *
                                   scene.cup_in_tcp.inverse();
            const int n =
                suction_arm.ur_ik->solve(suction_base_inv * tcp, suction_arm.spec.home, ik);
            for (int k = 0; k < n; ++k) {
              cell.set_arm(robot_q, suction_arm, ik.q[static_cast<std::size_t>(k)]);
              core::set_robot_state(cell, scene.cell, data, robot_q);
              core::set_tool_held(cell, scene, data, tcp);
              if (core::in_collision(scene.cell.model, data, suction_bodies)) continue;
              db::SuctionDeliveryRecord r;
              r.candidate_id = ci;
              r.suction_grasp_id = s;
              r.arm = suction_arm.spec.name;
              r.joints_rh = ik.q[static_cast<std::size_t>(k)];
              result.suction_deliveries.push_back(r);
              ++on_cup;
              break;
            }
          }
          reset_state();
        }
        if (shared == 0 && direct == 0 && regrasps == 0 && on_cup == 0) continue;
        // The first goals are confirmed by direct IK of the human arm(s): the map's orientation
        // bins are coarse, so a bin's Q may come from a neighbouring hand orientation.
        int& confirmed = verified[static_cast<std::size_t>(h.body + 1)];
        if (confirmed < settings.human_ik_goals) {
          // The worker it was drawn for confirms it: a goal for a body other than the cell's
          // human keeps no posture (the online planner solves the worker's own).
          // A copy at a worker's natural grasps is confirmed at the posture that is natural (as
          // choose_natural reached it, and the online planner reaches it), not at the best Q.
          const int who = h.body;
          const auto copy_floor = natural_copies.find(ci);
          const bool natural_copy = copy_floor != natural_copies.end();
          auto confirm = [&](int arm, int grasp) {
            if (!natural_copy) return solve_human(c.board, arm, grasp, who);
            return core::reach_hand(cell, who < 0 ? nullptr : &comfort.body(who),
                                    cell.spec().human_stance, comfort.arm_name(arm),
                                    c.board * grasps.human[static_cast<std::size_t>(grasp)].hand,
                                    {});
          };
          const core::ComfortResult first = confirm(h.arm, h.grasp);
          core::ComfortResult second;
          if (h.second_grasp >= 0) second = confirm(h.second_arm, h.second_grasp);
          const double q =
              h.second_grasp >= 0 ? std::min(first.quality, second.quality) : first.quality;
          const double floor = natural_copy ? copy_floor->second : threshold;
          if (!first.reachable || (h.second_grasp >= 0 && !second.reachable) || q <= floor) {
            // The ways were found with the human's hands at the maps' grasps: they go.
            std::erase_if(result.shared,
                          [&](const db::SharedGraspRecord& r) { return r.candidate_id == ci; });
            std::erase_if(result.direct,
                          [&](const db::DirectGraspRecord& r) { return r.candidate_id == ci; });
            std::erase_if(result.regrasps,
                          [&](const db::TableRegraspRecord& r) { return r.candidate_id == ci; });
            std::erase_if(result.suction_deliveries,
                          [&](const db::SuctionDeliveryRecord& r) { return r.candidate_id == ci; });
            // Comfortable at grasps the human's IK confirms: the ways are searched again with the
            // hands there.
            if (rechoose_allowed && !rechosen && rechoose_human(ci)) {
              rechosen = true;
              search_again = true;
              continue;
            }
            // Not comfortable after all: out of S.
            c.status = "uncomfortable";
            if (who < 0) c.quality = q;  // the cell human's own IK; a body's leaves the maps' Q
            ++human_ik_rejected;
            if (threshold == settings.comfort_threshold) --stage.comfortable;
            if (!rechoose_allowed) ik_rejected.push_back(ci);
            continue;
          }
          ++confirmed;
          if (who < 0) {
            // Below the stated threshold the goal says how comfortable the human's own IK found
            // it where that is less than the maps' Q: the plan reports it as delivered below.
            if (threshold < settings.comfort_threshold) c.quality = std::min(c.quality, q);
            c.human_joints = first.joints;
            c.human_quality = first.quality;
            if (h.second_grasp >= 0) {
              c.second_joints = second.joints;
              c.second_quality = second.quality;
            }
          }
        }
        c.status = "goal";
        ++stage.goals;
        ++goals_of[static_cast<std::size_t>(h.body + 1)];
      }
    }
    reset_state();
  };
  search_shared();
  // Thin boards (a worker with few goals after the first batches) get more candidates for each
  // such worker, batch by batch, up to max_candidates drawn for that worker.
  for (bool thin = true; thin && stage.draws < settings.max_draws;) {
    thin = false;
    for (int w = 0; w < workers; ++w) {
      const auto wi = static_cast<std::size_t>(w);
      if (goals_of[wi] >= settings.min_goals || drawn_for[wi] >= settings.max_candidates) continue;
      thin = true;
      const int batch = std::min(w == 0 ? settings.candidates : settings.body_candidates,
                                 settings.max_candidates - drawn_for[wi]);
      sample_candidates(stage.candidates + batch, draw_eq1, w - 1);
    }
    if (thin) search_shared();
  }
  // No goal: the candidates the human's IK rejected, with the human's grasps chosen again by IK.
  rechoose_allowed = true;
  if (stage.goals == 0 && !ik_rejected.empty()) {
    for (const int ci : ik_rejected) {
      auto& c = result.candidates[static_cast<std::size_t>(ci)];
      c.status = "no_shared_grasp";
      c.quality = choices[static_cast<std::size_t>(ci)].quality;
      --human_ik_rejected;
      if (threshold == settings.comfort_threshold) ++stage.comfortable;
    }
    search_shared(&ik_rejected);
  }
  if (stage.goals == 0 && settings.direct && settings.table_regrasp.enabled &&
      settings.table_regrasp.relay && !relay_poses.empty() && !direct_arms.empty()) {
    relays_allowed = true;
    relays_only = true;
    searched = 0;
    search_shared();
    relays_only = false;
  }
  // No goal: the candidates down to comfort_floor, in two steps, the human's IK confirming each
  // as before (a candidate it found below the old threshold may pass the new one).
  for (const double relaxed :
       {0.5 * (settings.comfort_threshold + settings.comfort_floor), settings.comfort_floor}) {
    if (stage.goals > 0 || relaxed >= threshold) break;
    threshold = relaxed;
    for (std::size_t i = 0; i < result.candidates.size(); ++i) {
      auto& c = result.candidates[i];
      const HumanChoice& h = choices[i];
      if (c.status == "uncomfortable" && h.grasp >= 0 && h.quality > threshold) {
        c.status = "no_shared_grasp";
        c.quality = comfort.body_count() > 0 ? worker_quality(c, h, -1) : h.quality;
      }
    }
    searched = 0;
    search_shared();
  }
  // A worker none of whose goals the online planner would find natural for them (BoardPlanner:
  // the goal's centre in their band, their arm reached as core::reach_hand does from the goal's
  // stored posture, else from zero, upright with RULA at most natural_max_rula): batches of
  // natural_candidates more in their band, within natural_max_rotation_deg of the target's
  // orientation, up to max_candidates, until one is. Whether the part is fitted inside their band
  // or not: a panel too tall to stand within max_rotation_deg below a short worker's shoulder
  // above the table lies further over; the goals Eq. 1 found for a part fitted in the band may all
  // be held high (the exchanges that reach them). Before each batch, a goal in their band that
  // they would take naturally at other grasps (choose_natural) with a Q in S gets a copy at those
  // grasps; after the batches, one with a Q down to comfort_floor. Last, after every other batch
  // and fallback: they add goals and take none away. They draw on a budget of max_draws of their
  // own.
  draw_limit = stage.draws + settings.max_draws;
  std::vector<int> wider_for(static_cast<std::size_t>(workers), 0);
  // Goals judged not natural for a worker (index body + 1): judged once.
  std::vector<std::set<int>> not_natural(static_cast<std::size_t>(workers));
  auto natural_for = [&](int ci, int w, const core::HeightBand& band) {
    const auto& c = result.candidates[static_cast<std::size_t>(ci)];
    const Eigen::Vector3d centre = c.board * grasps.com;
    if (c.status != "goal" || !band.contains(centre.z())) return false;
    if (not_natural[static_cast<std::size_t>(w)].count(ci) > 0) return false;
    const HumanChoice& h = choices[static_cast<std::size_t>(ci)];
    const core::HumanBody* body = w == 0 ? nullptr : &comfort.body(w - 1);
    std::vector<std::pair<std::string, Eigen::VectorXd>> held;
    // The cell's human at a goal that stores the posture: the planner takes it as stored.
    if (w == 0 && c.human_joints.size() > 0 && (h.second_grasp < 0 || c.second_joints.size() > 0)) {
      held.emplace_back(comfort.arm_name(h.arm), c.human_joints);
      if (h.second_grasp >= 0) held.emplace_back(comfort.arm_name(h.second_arm), c.second_joints);
    } else {
      for (const auto& [arm, grasp, seed] :
           {std::tuple{h.arm, h.grasp, &c.human_joints},
            std::tuple{h.second_arm, h.second_grasp, &c.second_joints}}) {
        if (grasp < 0) continue;
        const core::ComfortResult r =
            core::reach_hand(cell, body, cell.spec().human_stance, comfort.arm_name(arm),
                             c.board * grasps.human[static_cast<std::size_t>(grasp)].hand, *seed);
        if (!r.reachable) break;
        held.emplace_back(comfort.arm_name(arm), r.joints);
      }
    }
    const bool natural =
        held.size() == (h.second_grasp >= 0 ? 2U : 1U) &&
        core::check_receiving_posture(cell, body, cell.spec().human_stance, held, centre, part.mass)
            .natural(settings.natural_max_rula);
    if (!natural) not_natural[static_cast<std::size_t>(w)].insert(ci);
    return natural;
  };
  auto has_natural_goal = [&](int w) {
    for (int ci = 0; ci < static_cast<int>(result.candidates.size()); ++ci) {
      if (natural_for(ci, w, band_of[static_cast<std::size_t>(w)])) return true;
    }
    return false;
  };
  // Copies for worker w of the goals in their band (those not yet in `looked_at`) that they take
  // naturally at other grasps (choose_natural, the maps' Q above `floor`), searched for their
  // ways as new candidates: true when one was made.
  auto copy_natural = [&](int w, double floor, std::set<std::size_t>& looked_at) {
    const core::HeightBand& band = band_of[static_cast<std::size_t>(w)];
    bool copied = false;
    choosing_for = w - 1;
    for (std::size_t ci = 0, n = result.candidates.size(); ci < n; ++ci) {
      const auto& c = result.candidates[ci];
      if (c.status != "goal" || !band.contains((c.board * grasps.com).z()) ||
          !looked_at.insert(ci).second) {
        continue;
      }
      const HumanChoice h = choose_natural(c.board, floor);
      if (h.grasp < 0 ||
          (h.grasp == choices[ci].grasp && h.second_grasp == choices[ci].second_grasp)) {
        continue;
      }
      db::HandoverCandidateRecord copy;
      copy.sample = static_cast<int>(result.candidates.size());
      copy.board = c.board;
      copy.distance = c.distance;
      copy.quality = h.quality;
      copy.status = "no_shared_grasp";
      set_human(copy, h);
      natural_copies[copy.sample] = floor;
      result.candidates.push_back(copy);
      choices.push_back(h);
      if (threshold == settings.comfort_threshold) ++stage.comfortable;  // in S (at its floor)
      copied = true;
    }
    stage.candidates = static_cast<int>(result.candidates.size());
    return copied;
  };
  // Per worker (index body + 1): the goals looked at for copies above the threshold, and below.
  std::vector<std::set<std::size_t>> copied_above(static_cast<std::size_t>(workers));
  std::vector<std::set<std::size_t>> copied_below(static_cast<std::size_t>(workers));
  for (bool wider = settings.natural_candidates > 0; wider && stage.draws < draw_limit;) {
    wider = false;
    for (int w = 0; w < workers; ++w) {
      const auto wi = static_cast<std::size_t>(w);
      if (has_natural_goal(w)) continue;
      // Copies in S first, before more are drawn.
      if (copy_natural(w, threshold, copied_above[wi])) {
        wider = true;
        continue;
      }
      if (natural_max_rotation <= max_rotation || wider_for[wi] >= settings.max_candidates) {
        continue;
      }
      const int batch =
          std::min(settings.natural_candidates, settings.max_candidates - wider_for[wi]);
      sample_candidates(stage.candidates + batch,
                        draw_in_band(band_of[wi], w, natural_max_rotation), w - 1);
      wider_for[wi] += batch;
      wider = true;
    }
    if (wider) search_shared();
  }
  // Last, for a worker the batches found no natural goal for: copies below the threshold, down
  // to comfort_floor (a natural posture, by RULA, weighing above Eq. 4's Q there).
  if (settings.natural_candidates > 0 && settings.comfort_floor < threshold) {
    bool copied = false;
    for (int w = 0; w < workers; ++w) {
      if (has_natural_goal(w)) continue;
      copied = copy_natural(w, settings.comfort_floor, copied_below[static_cast<std::size_t>(w)]) ||
               copied;
    }
    if (copied) search_shared();
  }
  // Eq. 8 ranks over every batch.
  std::vector<db::HandoverCandidateRecord*> goals;
  for (auto& c : result.candidates) {
    if (c.status == "goal") goals.push_back(&c);
  }
  std::stable_sort(goals.begin(), goals.end(),
                   [](const auto* a, const auto* b) { return a->distance < b->distance; });
  for (std::size_t r = 0; r < goals.size(); ++r) goals[r]->rank = static_cast<int>(r);

  if (stage.goals == 0 && !no_candidate_reason().empty()) {
    return finish(no_candidate_reason() +
                  (threshold < settings.comfort_threshold
                       ? "; none either down to comfort Q " + core::format_number(threshold)
                       : std::string()));
  }
  if (stage.goals == 0) {
    std::string why = "no comfortable candidate (|S| = " + std::to_string(stage.comfortable) + ")";
    why += exchange_failure.empty()
               ? " shares a grasp with a robot-robot handover pose (" +
                     std::to_string(stage.robot_handovers) + " robot-robot poses)"
               : " is reached through an exchange (" + exchange_failure + ")";
    if (!direct_arms.empty()) {
      std::string arms;
      for (const DirectArm& d : direct_arms) {
        arms += (arms.empty() ? "" : " or ") + d.arm->spec.name;
      }
      why += " or by the " + arms + " arm's gripper from where the part lies";
      if (settings.table_regrasp.enabled) {
        why += set_down_poses.empty()
                   ? " (no regrasp on the table: the part does not lie on it)"
                   : " (nor after a regrasp on the table, at " +
                         std::to_string(set_down_poses.size()) + " set-down poses" +
                         (relay_poses.empty() ? std::string()
                                              : ", or a relay to the other arm there, at " +
                                                    std::to_string(relay_poses.size()) + " poses") +
                         ")";
      }
    } else {
      why += "; " + direct_failure;
    }
    if (suction_deliverable) {
      why += "; nor presented on the " + suction_arm.spec.name +
             " arm's suction cup (its IK at the candidates in collision or out of reach)";
    }
    if (threshold < settings.comfort_threshold) {
      why += "; none either down to comfort Q " + core::format_number(threshold);
    }
    if (human_ik_rejected > 0) {
      why += "; the human's arm IK found the " + std::to_string(human_ik_rejected) +
             " candidates a way served uncomfortable after all (the comfort maps' Q too high "
             "there)";
    }
    why += reach_census();
    return finish(why);
  }
  // Shared grasps by goal rank.
  std::stable_sort(result.shared.begin(), result.shared.end(),
                   [&](const db::SharedGraspRecord& a, const db::SharedGraspRecord& b) {
                     return result.candidates[static_cast<std::size_t>(a.candidate_id)].rank <
                            result.candidates[static_cast<std::size_t>(b.candidate_id)].rank;
                   });
  std::stable_sort(result.direct.begin(), result.direct.end(),
                   [&](const db::DirectGraspRecord& a, const db::DirectGraspRecord& b) {
                     return result.candidates[static_cast<std::size_t>(a.candidate_id)].rank <
                            result.candidates[static_cast<std::size_t>(b.candidate_id)].rank;
                   });
  std::stable_sort(result.regrasps.begin(), result.regrasps.end(),
                   [&](const db::TableRegraspRecord& a, const db::TableRegraspRecord& b) {
                     return result.candidates[static_cast<std::size_t>(a.candidate_id)].rank <
                            result.candidates[static_cast<std::size_t>(b.candidate_id)].rank;
                   });
  std::stable_sort(result.suction_deliveries.begin(), result.suction_deliveries.end(),
                   [&](const db::SuctionDeliveryRecord& a, const db::SuctionDeliveryRecord& b) {
                     return result.candidates[static_cast<std::size_t>(a.candidate_id)].rank <
                            result.candidates[static_cast<std::size_t>(b.candidate_id)].rank;
                   });
  return finish("");
}

}  // namespace hila::offline
