#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/arm_poser.hpp"
#include "hila/core/bridge.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/lazy_prm.hpp"
#include "hila/core/roadmap_graph.hpp"
#include "hila/db/records.hpp"
#include "hila/online/world.hpp"

namespace hila::online {

// One arm's stored roadmap as the planner searches it. Const after construction: shared.
struct ArmRoadmap {
  explicit ArmRoadmap(db::RoadmapRecord stored);
  db::RoadmapRecord record;
  core::RoadmapGraph graph;
  Eigen::MatrixXd node_matrix;  // the nodes as columns, for the nearest-node scans
};

// The board in the moving arm's hand, if any.
struct HeldBoard {
  bool held = false;
  core::Pose board_in_tcp = core::Pose::Identity();
  double jaw = 0.085;  // the gripper's opening while it holds (ignored for the suction arm)
  // Slip: the opening axis and the unit lever to the centre of mass in the TCP frame, and the
  // grasp's limit (90: none).
  Eigen::Vector3d axis_tcp = Eigen::Vector3d::UnitY();
  Eigen::Vector3d lever_tcp = Eigen::Vector3d::Zero();
  double theta_c_deg = 90.0;
};

struct MotionRequest {
  Eigen::VectorXd start;
  Eigen::VectorXd goal;
  // Roadmap edges the held board's grasp may use (the stored filter); nullptr: every edge. The
  // planner keys what it learns of the filtered roadmap on this address: a filter must not
  // change while the planner is used (the database's are fixed while it is loaded).
  const std::vector<bool>* filter = nullptr;
  HeldBoard held;
  Eigen::VectorXd robot_q;                          // the whole robot while this arm moves
  bool tool_in_hand = true;                         // the suction arm holds the tool
  core::Pose tool_world = core::Pose::Identity();   // the tool's handle when not in hand
  core::Pose board_world = core::Pose::Identity();  // the board when not held
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  // The start touches by design (a lift: the picked board or the grasped tool still rests on
  // the table): its own collisions are not checked, every later sample is.
  bool start_in_contact = false;
  // The goal touches by design (the tool set down on the table): the same for the last sample.
  bool end_in_contact = false;
  // Paths stored offline for this motion (the regrasp graph's, for the nominal scene), tried in
  // order before the roadmap: each is joined to the start and goal by straight segments within
  // its first and last few waypoints and re-validated against the scene as it is. A repair of
  // one that failed is remembered by the path's address (ArmMotionPlanner::failed_bridges_):
  // a path must not change while the planner that was given it lives (the database's do not).
  std::vector<const std::vector<Eigen::VectorXd>*> hints;
  // Whether the hints are followed whole before the roadmap is searched; false keeps them for
  // leading a wedged end into the roadmap only (a hint that seldom holds whole).
  bool follow_hints = true;
  // Stored paths known only when asked for (the way an arm came, while that motion's smoothing
  // is still queued): fetched once, the first time a wedged end needs a way into the roadmap,
  // and used there as `hints` are with follow_hints false (set when this is). Must stay callable
  // while plan() runs.
  std::function<std::vector<const std::vector<Eigen::VectorXd>*>()> late_hints;
  bool allow_bridge = true;  // false: roadmap (and stored paths) only, e.g. for a staging try
  // Every segment at MotionSettings::fine_resolution (the validator's): a retry after the
  // validator found a thin collision between the planner's coarser samples.
  bool fine_checks = false;
  // The path the validator rejected (hila's planner, with fine_checks): re-checked segment by
  // segment, each blocked stretch bridged locally (MotionSettings::fine_repair_checks each, at
  // most fine_repairs), before the motion is planned again from scratch.
  const std::vector<Eigen::VectorXd>* rejected = nullptr;
  // A* runs allowed (0: MotionSettings::max_searches), e.g. fewer for a staging try, where a
  // bridge is the better tool once the roadmap around the goal proves this blocked.
  int max_searches = 0;
};

enum class MotionStatus { kSolved, kInvalidStart, kInvalidGoal, kNoPath, kTimeout };
const char* to_string(MotionStatus status);

// How a motion was found: kDirect (the straight segment), kStored (an offline path
// re-validated), kRoadmap, kStoredRoadmap (the roadmap entered or left along the part of a stored
// path that holds), kStoredRepair (a stored path bridged around what blocks it), kBridge,
// kRepaired (a rejected path mended where it was blocked, MotionRequest::rejected); the
// baselines' kRrtConnect or kLazyPrm. kNone: not found.
enum class MotionVia {
  kNone,
  kDirect,
  kStored,
  kRoadmap,
  kStoredRoadmap,
  kStoredRepair,
  kBridge,
  kRepaired,
  kRrtConnect,
  kLazyPrm
};
// "direct", "stored", "roadmap", "stored+roadmap", "stored+repair", "bridge", "repaired",
// "rrt_connect", "lazy_prm"; "" for kNone.
const char* to_string(MotionVia via);

struct MotionResult {
  MotionStatus status = MotionStatus::kNoPath;
  std::string reason;                 // why not solved, naming what is in the way
  std::vector<Eigen::VectorXd> path;  // start ... goal, straight segments between waypoints
  MotionVia via = MotionVia::kNone;
  // Found to a staging pose near the goal, the last segment straight from there (the board
  // planner's stagings: a gripper's way in along its approach).
  bool staged = false;
  // Set once the roadmap search is over: an end attached to no roadmap node, directly or along
  // a stored path (a failure then is a wedge, not a cut roadmap).
  bool wedged = false;
  int searches = 0;           // A* runs (one more after each invalidated edge)
  int nodes_expanded = 0;     // by those runs (none for a search its ends' components rule out)
  int edges_checked = 0;      // roadmap edges validated against the scene
  int edges_invalidated = 0;  // of those, blocked in the scene
  double seconds = 0.0;
  bool solved() const { return status == MotionStatus::kSolved; }
};

// What plans a motion: the stored roadmap (hila's planner), or a baseline it is measured
// against: OMPL RRT-Connect from scratch, OMPL LazyPRM with a roadmap kept between queries.
// Every one checks the same validity (collisions, held board, slip) at the same resolution.
enum class MotionPlannerKind { kRoadmap, kRrtConnect, kLazyPrm };
const char* to_string(MotionPlannerKind kind);

struct MotionSettings {
  MotionPlannerKind planner = MotionPlannerKind::kRoadmap;
  // Roadmap nodes tried per end, nearest first, until `attachments` valid ones: where the scene
  // crowds an end (a staging pose beside the board at the exchange), its nearest valid nodes can
  // lie well past the first few dozen.
  int attach_neighbours = 150;
  int attachments = 6;  // valid attachments kept per end
  // The same where the joins are checked (an end whose unchecked joins failed, a stored path's
  // end): each kept node costs a whole segment's checks, and past the second they rarely
  // shorten the path.
  int checked_attachments = 2;
  int max_searches = 200;
  int staging_searches = 20;  // per staging try (MotionRequest::max_searches)
  // Segment checks while holding a board (rad): finer than the roadmap's 0.05, since a long
  // board sweeps far between those samples; the empty arm uses the roadmap's. The validator's
  // 0.01 pass catches what falls between samples (a step it rejects is planned again at 0.01,
  // fine_checks). 0.04: finer finds the same plans more slowly; at the roadmap's 0.05 some
  // held-board motions are no longer found.
  double held_resolution = 0.04;
  // A fine retry's (MotionRequest::fine_checks): the validator's 0.01.
  double fine_resolution = 0.01;
  // A bridge's validity-check budget (also bounded by the deadline): enough for the receiving
  // arm's way home from beside the human's hands, where a failed bridge gives up the whole goal
  // after every other motion of it is planned.
  long bridge_checks = 10000;
  // A bridge for an end wedged in by the scene (no straight join reaches a roadmap node): a
  // `wedged_focus` share of its samples drawn around that end (a Gaussian of `focus_sigma` rad
  // per joint, core::BridgeSettings::focus), within `wedged_bridge_checks` (and bridge_checks)
  // until the larger bridges' round. Uniform samples alone seldom grow the wedged end's tree
  // past its root; drawn around the end, a bridge that gets through at all does so within a few
  // thousand checks, so the smaller cap costs the hopeless ones less and loses little.
  long wedged_bridge_checks = 3000;
  double wedged_focus = 0.6;
  double focus_sigma = 0.5;  // rad
  // A stored path the scene blocks, repaired around each blocked stretch (at most
  // `max_repairs`) by a bridge to one of the next `repair_targets` valid waypoints, when the
  // roadmap fails and before a bridge across the whole motion: with `repair_checks` per
  // repair (0: off), and `wedged_repair_checks` when an end attaches to no roadmap node. A board
  // whose every goal failed gets `escalated_repair_checks` with the larger bridges. Where a
  // stored transfer under a tight slip limit threads between finished boards and a box blocks
  // it further on, the repair gets through where a whole-motion bridge needs luck; repairs
  // before every whole-motion bridge cost more than they save, so repair_checks is 0 (off).
  // A wedged repair gets the larger round's budget from the start: otherwise the motions that
  // need it get it only after every goal has failed once.
  // Wedged repairs first go over every stored path at `wedged_first_repair_checks` each, then
  // at the full budget: one stored path may need several times the checks another needs round
  // the same box. 0: the full budget only.
  long repair_checks = 0;
  long wedged_repair_checks = 20000;
  long wedged_first_repair_checks = 3000;
  long escalated_repair_checks = 20000;
  int max_repairs = 2;
  int repair_targets = 12;
  // A repair's samples drawn around the waypoint it leaves from, as for a wedged end: the stored
  // path is blocked right after it, so it is usually up against what blocks it.
  double repair_focus = 0.6;
  // A path the validator rejected, mended stretch by stretch at its resolution
  // (MotionRequest::rejected): each blocked stretch's bridge budget, and how many stretches.
  long fine_repair_checks = 10000;
  int fine_repairs = 4;
  // A board whose every goal failed within bridge_checks is tried once more, time permitting,
  // with bridges this large (the baselines' from-scratch budget).
  long escalated_bridge_checks = 200000;
  // A held board's bridges sample on its slip limit (core::SlipProjection) rather than by
  // rejection alone (the baselines keep rejection, as the issue specifies).
  bool project_slip = true;
  long baseline_checks = 200000;  // the baselines' budget per motion (and the deadline)
  int join_waypoints = 4;         // a stored path's first / last waypoints tried for the joins
  long shortcut_checks = 1500;    // validity checks spent shortening a found path
  std::uint64_t seed = 1;
};

// Plans one arm's motion through its stored roadmap for the scene as it is: both ends attached
// to nearby nodes, A* over the allowed edges, the path's edges validated lazily against the
// whole world (the held board and the tool included) and blocked edges dropped before searching
// again; where the roadmap is cut, an RRT-Connect bridge under the same checks. Holds the
// per-thread state (collision data, search workspace, edge verdicts): one per thread. Never
// throws on the planning path: failures are statuses with reasons.
class ArmMotionPlanner {
 public:
  // `lazy_prm`: the persistent baseline planner for this arm (kLazyPrm only; not owned).
  ArmMotionPlanner(const World& world, const ArmRoadmap& roadmap, const std::string& arm,
                   const MotionSettings& settings = {}, core::LazyPrmPlanner* lazy_prm = nullptr);

  MotionResult plan(const MotionRequest& request);

  // Under the request last passed to prepare() or plan().
  void prepare(const MotionRequest& request);
  bool valid(const Eigen::VectorXd& q);
  std::string why_invalid(const Eigen::VectorXd& q);
  bool segment_valid(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
  // b and the segment from a to it (a checked already): a step onto a configuration nothing has
  // checked yet, as a smoothed path's points are. segment_valid() alone samples only between
  // the ends, which a segment no longer than the resolution leaves unchecked.
  bool step_valid(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
    return valid(b) && segment_valid(a, b);
  }
  // Validity checks of single configurations since construction (every query's unit of work).
  long checks() const { return checks_; }

  // A bridge's check budget from the next request on (MotionSettings::bridge_checks).
  void set_bridge_checks(long checks) { settings_.bridge_checks = checks; }
  // A wedged end's bridge budget from the next request on (MotionSettings::wedged_bridge_checks).
  void set_wedged_bridge_checks(long checks) { settings_.wedged_bridge_checks = checks; }
  // A stored path's repair budget from the next request on (MotionSettings::repair_checks).
  void set_repair_checks(long checks) { settings_.repair_checks = checks; }

 private:
  enum class Verdict { kValid, kOutsideLimits, kSlips, kCollides };
  // A bridge's settings for the current request: its budget, the resolution, and for a held
  // board under a slip limit, samples projected onto it (core::SlipProjection).
  core::BridgeSettings bridge_settings(long checks,
                                       std::chrono::steady_clock::time_point deadline) const;
  Verdict check(const Eigen::VectorXd& q, core::CollisionPair* pair);
  // A roadmap node's verdict (kept); a blocked node's edges are all blocked with it.
  bool node_valid(int node);
  bool edge_valid(int edge);
  using Hints = std::vector<const std::vector<Eigen::VectorXd>*>;
  // The first of a stored path's first few waypoints a straight segment joins to the start, and
  // the last of its last few joined to the goal; false when either end does not join.
  bool join_ends(const std::vector<Eigen::VectorXd>& hint, const Eigen::VectorXd& start,
                 const Eigen::VectorXd& goal, int& first, int& last);
  // A stored path followed from the start to the goal, re-validated; with `repair_checks` > 0
  // each stretch the scene blocks (at most MotionSettings::max_repairs) is bridged from the
  // waypoint before it to one of the next valid waypoints. Empty when a join, a stretch or a
  // repair fails.
  std::vector<Eigen::VectorXd> follow(const std::vector<Eigen::VectorXd>& hint,
                                      const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                                      long repair_checks,
                                      const std::function<bool(const Eigen::VectorXd&)>& valid_here,
                                      std::chrono::steady_clock::time_point deadline,
                                      int max_repairs);
  std::vector<Eigen::VectorXd> stored_lead(const Hints& hints, const Eigen::VectorXd& start);
  std::vector<Eigen::VectorXd> stored_tail(const Hints& hints, const Eigen::VectorXd& goal);
  void shorten(std::vector<Eigen::VectorXd>& path);
  // The nearest valid roadmap nodes (MotionSettings::attachments of the attach_neighbours
  // nearest), with `check_joins` only those the straight segment from q reaches (and
  // MotionSettings::checked_attachments of them).
  std::vector<core::GraphEndpoint> attach(const Eigen::VectorXd& q, bool check_joins);
  // The roadmap entered (checked joins) where a stored path's longest valid beginning from q
  // (`is_start`), or end into q, takes the arm: `via` becomes that stretch. Empty when none.
  std::vector<core::GraphEndpoint> attach_along_stored(const Hints& hints, const Eigen::VectorXd& q,
                                                       bool is_start,
                                                       std::vector<Eigen::VectorXd>& via);

  const World& world_;
  const ArmRoadmap& roadmap_;
  const core::Arm& arm_;
  int arm_index_ = 0;
  MotionSettings settings_;
  core::LazyPrmPlanner* lazy_prm_ = nullptr;
  core::CollisionData data_;
  core::ArmPoser poser_;
  core::GraphSearchWorkspace search_;
  std::vector<int> moving_;
  core::Pose base_;
  int tip_link_ = -1;           // the TCP's link in the robot model
  std::vector<int> rigid_arm_;  // the arm's bodies rigid with the TCP (core::rigid_tip_bodies)
  // Those with the tool in hand and the held board: pairs among them checked in prepare() only.
  std::vector<int> rigid_;
  bool rigid_collides_ = false;
  core::CollisionPair rigid_pair_;
  Eigen::VectorXd robot_q_;
  HeldBoard held_;
  bool moves_tool_ = false;
  double resolution_ = 0.05;  // segment checks for the current request
  std::vector<bool> allowed_;
  // Verdicts of roadmap nodes and edges: -1 unknown, 0 blocked, 1 clear. They depend only on
  // what prepare() poses (the rest of the robot, what is held, the tool, the board, the
  // resolution), so they are kept across requests that pose the same: the retries of one
  // motion (stagings, other goals sharing a stage) do not re-learn the same blocked edges.
  std::vector<signed char> node_state_;
  std::vector<signed char> edge_state_;
  std::vector<int> blocked_edges_;  // the edges whose verdict is blocked, for prepare()
  std::vector<double> context_;     // what the verdicts were found under
  // Connected components of the allowed edges, per filter, made when a search first finds no
  // path and kept while the context stands. Within a context edges are only ever taken out
  // (blocked_edges_), so ends in different components stay apart for every later search under
  // that filter, and A* is not run to find that out again: a search that fails explores the
  // whole of the entries' component, and a motion whose ends the filtered roadmap does not join
  // is asked for again and again (its retries, other goals sharing its stage).
  struct Components {
    const std::vector<bool>* filter = nullptr;  // the request's (nullptr: every edge)
    std::vector<int> label;                     // per node
  };
  std::vector<Components> components_;
  const std::vector<bool>* filter_ = nullptr;  // the current request's
  const std::vector<int>* components() const;  // under filter_, if made
  void learn_components();
  // Whether no entry shares a component with an exit (false when the components are not made).
  bool ends_apart(const std::vector<core::GraphEndpoint>& entries,
                  const std::vector<core::GraphEndpoint>& exits) const;
  // Bridges across a whole motion, and repairs of a stored path, that failed within their
  // budget (not the deadline): asked again under the same context (another goal whose
  // configuration is the same, the larger bridges' round repeating a repair), they would fail
  // again, check for check, so they are not run.
  struct FailedBridge {
    Eigen::VectorXd start;
    Eigen::VectorXd goal;
    long checks = 0;
    bool start_in_contact = false;
    // The stored path a repair followed (the database's, fixed while it is loaded); nullptr for
    // a bridge across the whole motion.
    const std::vector<Eigen::VectorXd>* repaired = nullptr;
    std::vector<double> context;  // what it was checked under (context_)
    bool operator==(const FailedBridge& o) const {
      return checks == o.checks && start_in_contact == o.start_in_contact &&
             repaired == o.repaired && context == o.context && start.size() == o.start.size() &&
             goal.size() == o.goal.size() && start == o.start && goal == o.goal;
    }
  };
  // Kept across contexts (each entry names its own): the larger bridges' round comes back to
  // the contexts of the first round's attempts after others. The oldest go past this many.
  static constexpr std::size_t kFailedBridgesKept = 64;
  std::vector<FailedBridge> failed_bridges_;
  void remember_failure(const FailedBridge& failure);
  // The last segments found blocked since prepare() (segment_valid()), oldest first.
  static constexpr std::size_t kBlockedSegmentsKept = 8;
  std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> blocked_segments_;
  std::vector<std::pair<double, int>> near_scratch_;  // attach()
  int checked_ = 0;
  int invalidated_ = 0;
  long checks_ = 0;
};

}  // namespace hila::online
