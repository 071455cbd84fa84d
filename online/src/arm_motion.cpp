#include "hila/online/arm_motion.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "hila/core/bridge.hpp"
#include "hila/core/slip_projection.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"

namespace hila::online {

namespace {

int arm_index_of(const core::Cell& cell, const core::Arm& arm) {
  int i = 0;
  while (&cell.arms()[static_cast<std::size_t>(i)] != &arm) ++i;
  return i;
}

}  // namespace

const char* to_string(MotionVia via) {
  switch (via) {
    case MotionVia::kNone:
      return "";
    case MotionVia::kDirect:
      return "direct";
    case MotionVia::kStored:
      return "stored";
    case MotionVia::kRoadmap:
      return "roadmap";
    case MotionVia::kStoredRoadmap:
      return "stored+roadmap";
    case MotionVia::kStoredRepair:
      return "stored+repair";
    case MotionVia::kBridge:
      return "bridge";
    case MotionVia::kRepaired:
      return "repaired";
    case MotionVia::kRrtConnect:
      return "rrt_connect";
    case MotionVia::kLazyPrm:
      return "lazy_prm";
  }
  return "?";
}

const char* to_string(MotionStatus status) {
  switch (status) {
    case MotionStatus::kSolved:
      return "solved";
    case MotionStatus::kInvalidStart:
      return "invalid start";
    case MotionStatus::kInvalidGoal:
      return "invalid goal";
    case MotionStatus::kNoPath:
      return "no path";
    case MotionStatus::kTimeout:
      return "timeout";
  }
  return "unknown";
}

const char* to_string(MotionPlannerKind kind) {
  switch (kind) {
    case MotionPlannerKind::kRoadmap:
      return "hila";
    case MotionPlannerKind::kRrtConnect:
      return "rrt_connect";
    case MotionPlannerKind::kLazyPrm:
      return "lazy_prm";
  }
  return "unknown";
}

ArmRoadmap::ArmRoadmap(db::RoadmapRecord stored)
    : record(std::move(stored)), graph(record.nodes, record.edges) {
  const Eigen::Index dof = record.nodes.empty() ? 0 : record.nodes.front().size();
  node_matrix.resize(dof, static_cast<Eigen::Index>(record.nodes.size()));
  for (std::size_t i = 0; i < record.nodes.size(); ++i) {
    node_matrix.col(static_cast<Eigen::Index>(i)) = record.nodes[i];
  }
}

ArmMotionPlanner::ArmMotionPlanner(const World& world, const ArmRoadmap& roadmap,
                                   const std::string& arm, const MotionSettings& settings,
                                   core::LazyPrmPlanner* lazy_prm)
    : world_(world),
      roadmap_(roadmap),
      arm_(world.cell().arm(arm)),
      arm_index_(arm_index_of(world.cell(), arm_)),
      settings_(settings),
      lazy_prm_(lazy_prm),
      data_(world.make_data()),
      poser_(world.cell(), world.stage().cell, arm_),
      base_(core::arm_base_in_world(world.cell(), arm_)),
      tip_link_(world.cell().robot().link_index(arm_.spec.tip_link)),
      rigid_arm_(
          core::rigid_tip_bodies(world.cell().robot(), world.stage().cell.robot, tip_link_)) {
  // The LazyPRM baseline keeps its roadmap outside the planner: without one it cannot run.
  assert(settings_.planner != MotionPlannerKind::kLazyPrm || lazy_prm_ != nullptr);
}

void ArmMotionPlanner::prepare(const MotionRequest& request) {
  const core::Cell& cell = world_.cell();
  const core::StageScene& stage = world_.stage();
  robot_q_ = request.robot_q.size() == 0 ? cell.home_configuration() : request.robot_q;
  held_ = request.held;
  resolution_ = std::min(request.fine_checks ? settings_.fine_resolution
                         : held_.held        ? settings_.held_resolution
                                             : roadmap_.record.resolution,
                         roadmap_.record.resolution);
  // A held board is on the cup of the arm holding the tool, else in the gripper's jaws.
  if (held_.held && !(request.tool_in_hand && arm_index_ == stage.suction_arm)) {
    cell.set_jaw(robot_q_, arm_, held_.jaw);
  }
  moves_tool_ = request.tool_in_hand && arm_index_ == stage.suction_arm;
  moving_ = stage.cell.arm_bodies[static_cast<std::size_t>(arm_index_)];
  if (moves_tool_)
    moving_.insert(moving_.end(), stage.tool_bodies.begin(), stage.tool_bodies.end());
  if (held_.held) moving_.push_back(stage.board);
  poser_.pose_robot(data_, robot_q_);
  world_.place_tool(data_, robot_q_, request.tool_in_hand, request.tool_world);
  if (!held_.held) data_.set_body_pose(stage.board, request.board_world);
  // The arm's last link, gripper, tool in hand and held board keep their relative poses through
  // the motion: their pairs are checked once, here, and left out of every sample's query.
  rigid_ = rigid_arm_;
  if (moves_tool_) rigid_.insert(rigid_.end(), stage.tool_bodies.begin(), stage.tool_bodies.end());
  if (held_.held) rigid_.push_back(stage.board);
  {
    const core::Pose& tcp = poser_.link_pose(tip_link_);
    if (moves_tool_) core::set_tool_held(cell, stage, data_, tcp);
    if (held_.held) data_.set_body_pose(stage.board, tcp * held_.board_in_tcp);
    rigid_pair_ = {};
    rigid_collides_ = core::in_collision_among(stage.cell.model, data_, rigid_, &rigid_pair_);
  }
  // The verdicts found so far hold while everything validity depends on is posed the same: the
  // rest of the robot (not this arm's joints, which every check sets), what is held, the tool,
  // the board, the resolution.
  Eigen::VectorXd rest = robot_q_;
  cell.set_arm(rest, arm_, Eigen::VectorXd::Zero(arm_.chain.dof()));
  std::vector<double> context(rest.data(), rest.data() + rest.size());
  auto append_pose = [&context](const core::Pose& p) {
    context.insert(context.end(), p.matrix().data(), p.matrix().data() + 16);
  };
  context.insert(context.end(), {held_.held ? 1.0 : 0.0, moves_tool_ ? 1.0 : 0.0, resolution_});
  if (held_.held) {
    append_pose(held_.board_in_tcp);
    context.insert(context.end(), {held_.jaw, held_.theta_c_deg});
    context.insert(context.end(), held_.axis_tcp.data(), held_.axis_tcp.data() + 3);
    context.insert(context.end(), held_.lever_tcp.data(), held_.lever_tcp.data() + 3);
  } else {
    append_pose(request.board_world);
  }
  context.push_back(request.tool_in_hand ? 1.0 : 0.0);
  if (!request.tool_in_hand) append_pose(request.tool_world);
  const std::size_t edges = roadmap_.record.edges.size();
  if (context != context_ || edge_state_.size() != edges) {
    context_ = std::move(context);
    node_state_.assign(roadmap_.record.nodes.size(), -1);
    edge_state_.assign(edges, -1);
    blocked_edges_.clear();
    components_.clear();
  }
  filter_ = request.filter;
  // No filter: every edge (a held board's slip and clearance are then checked lazily, as all).
  assert(request.filter == nullptr || request.filter->size() == edges);
  if (request.filter != nullptr) {
    allowed_ = *request.filter;
  } else {
    allowed_.assign(edges, true);
  }
  for (const int e : blocked_edges_) allowed_[static_cast<std::size_t>(e)] = false;
  checked_ = 0;
  invalidated_ = 0;
  blocked_segments_.clear();
}

core::BridgeSettings ArmMotionPlanner::bridge_settings(
    long checks, std::chrono::steady_clock::time_point deadline) const {
  core::BridgeSettings bridge;
  bridge.max_checks = checks;
  bridge.resolution = resolution_;
  bridge.seed = settings_.seed;
  bridge.deadline = deadline;
  bridge.focus_sigma = settings_.focus_sigma;
  if (settings_.project_slip && held_.held && held_.theta_c_deg < 90.0) {
    const core::SlipProjection slip(arm_, base_, held_.axis_tcp, held_.lever_tcp,
                                    held_.theta_c_deg);
    if (slip.active()) bridge.project = slip;
  }
  return bridge;
}

bool ArmMotionPlanner::valid(const Eigen::VectorXd& q) {
  return check(q, nullptr) == Verdict::kValid;
}

// The hot path: no strings are built unless a reason is asked for.
ArmMotionPlanner::Verdict ArmMotionPlanner::check(const Eigen::VectorXd& q,
                                                  core::CollisionPair* pair) {
  ++checks_;
  if (q.size() != arm_.chain.dof() || !arm_.chain.within_limits(q, 1e-9)) {
    return Verdict::kOutsideLimits;
  }
  // Under a slip limit the TCP comes first (a slipping sample is rejected before the arm is
  // posed); otherwise it is read off the posed arm.
  const bool slip_checked = held_.held && held_.theta_c_deg < 90.0;
  core::Pose tcp;
  if (slip_checked) {
    tcp = base_ * arm_.chain.fk(q);
    const double slip =
        core::slip_angle_deg(tcp.linear() * held_.axis_tcp, tcp.linear() * held_.lever_tcp,
                             Eigen::Vector3d(0.0, 0.0, -1.0));
    if (slip > held_.theta_c_deg) return Verdict::kSlips;
  }
  if (rigid_collides_) {
    if (pair != nullptr) *pair = rigid_pair_;
    return Verdict::kCollides;
  }
  const core::Cell& cell = world_.cell();
  const core::StageScene& stage = world_.stage();
  cell.set_arm(robot_q_, arm_, q);
  poser_.pose_arm(data_, robot_q_);
  if (!slip_checked) tcp = poser_.link_pose(tip_link_);
  if (moves_tool_) core::set_tool_held(cell, stage, data_, tcp);
  if (held_.held) data_.set_body_pose(stage.board, tcp * held_.board_in_tcp);
  return core::in_collision(stage.cell.model, data_, moving_, pair, rigid_) ? Verdict::kCollides
                                                                            : Verdict::kValid;
}

std::string ArmMotionPlanner::why_invalid(const Eigen::VectorXd& q) {
  core::CollisionPair pair;
  switch (check(q, &pair)) {
    case Verdict::kValid:
      return "";
    case Verdict::kOutsideLimits:
      return "outside the joint limits";
    case Verdict::kSlips:
      return "the held board would slip";
    case Verdict::kCollides:
      break;
  }
  const auto& model = world_.stage().cell.model;
  return model.body_name(pair.body_a) + " vs " + model.body_name(pair.body_b);
}

bool ArmMotionPlanner::segment_valid(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  // A request asks some segments more than once (the straight motion, then again as the first
  // shortcut of whatever path is found): the ones found blocked are remembered until the next
  // prepare(). Exact ends in the same direction: the very same samples.
  for (const auto& [from, to] : blocked_segments_) {
    if (from.size() == a.size() && from == a && to == b) return false;
  }
  if (core::all_samples_coarse_to_fine(a, b, resolution_,
                                       [this](const Eigen::VectorXd& q) { return valid(q); })) {
    return true;
  }
  if (blocked_segments_.size() == kBlockedSegmentsKept) {
    blocked_segments_.erase(blocked_segments_.begin());
  }
  blocked_segments_.emplace_back(a, b);
  return false;
}

void ArmMotionPlanner::remember_failure(const FailedBridge& failure) {
  if (failed_bridges_.size() == kFailedBridgesKept) failed_bridges_.erase(failed_bridges_.begin());
  failed_bridges_.push_back(failure);
}

bool ArmMotionPlanner::node_valid(int node) {
  auto& state = node_state_[static_cast<std::size_t>(node)];
  if (state >= 0) return state == 1;
  state = valid(roadmap_.record.nodes[static_cast<std::size_t>(node)]) ? 1 : 0;
  if (state == 1) return true;
  // Every edge of a blocked node is blocked: dropped at once, not one per search.
  for (auto it = roadmap_.graph.neighbours_begin(node); it != roadmap_.graph.neighbours_end(node);
       ++it) {
    const auto e = static_cast<std::size_t>(it->edge);
    if (edge_state_[e] == 0) continue;
    edge_state_[e] = 0;
    blocked_edges_.push_back(it->edge);
    if (allowed_[e]) {
      allowed_[e] = false;
      ++invalidated_;
    }
  }
  return false;
}

const std::vector<int>* ArmMotionPlanner::components() const {
  for (const auto& c : components_) {
    if (c.filter == filter_) return &c.label;
  }
  return nullptr;
}

void ArmMotionPlanner::learn_components() {
  if (components() != nullptr) return;
  components_.push_back({filter_, core::connected_components(roadmap_.graph.node_count(),
                                                             roadmap_.record.edges, allowed_)});
}

bool ArmMotionPlanner::ends_apart(const std::vector<core::GraphEndpoint>& entries,
                                  const std::vector<core::GraphEndpoint>& exits) const {
  const std::vector<int>* label = components();
  if (label == nullptr) return false;
  const auto n = static_cast<int>(label->size());
  for (const auto& a : entries) {
    if (a.node < 0 || a.node >= n) continue;
    for (const auto& b : exits) {
      if (b.node >= 0 && b.node < n &&
          (*label)[static_cast<std::size_t>(a.node)] ==
              (*label)[static_cast<std::size_t>(b.node)]) {
        return false;
      }
    }
  }
  return true;
}

bool ArmMotionPlanner::edge_valid(int edge) {
  auto& verdict = edge_state_[static_cast<std::size_t>(edge)];
  if (verdict >= 0) return verdict == 1;
  const auto [u, v] = roadmap_.record.edges[static_cast<std::size_t>(edge)];
  if (!node_valid(u) || !node_valid(v)) return false;  // blocked with the node's edges
  verdict = 0;
  ++checked_;
  verdict = segment_valid(roadmap_.record.nodes[static_cast<std::size_t>(u)],
                          roadmap_.record.nodes[static_cast<std::size_t>(v)])
                ? 1
                : 0;
  if (verdict == 0) blocked_edges_.push_back(edge);
  return verdict == 1;
}

bool ArmMotionPlanner::join_ends(const std::vector<Eigen::VectorXd>& hint,
                                 const Eigen::VectorXd& start, const Eigen::VectorXd& goal,
                                 int& first, int& last) {
  const int n = static_cast<int>(hint.size());
  const auto at = [&](int i) -> const Eigen::VectorXd& {
    return hint[static_cast<std::size_t>(i)];
  };
  const int tries = std::max(1, settings_.join_waypoints);
  first = -1;
  for (int i = 0; i < std::min(n, tries) && first < 0; ++i) {
    if (valid(at(i)) && segment_valid(start, at(i))) first = i;
  }
  if (first < 0) return false;
  last = -1;
  for (int j = n - 1; j >= std::max(first, n - tries) && last < 0; --j) {
    if ((j == first || valid(at(j))) && segment_valid(at(j), goal)) last = j;
  }
  return last >= 0;
}

// The stored path re-validated for the scene, joined to the start and goal by straight segments
// (the stored ends are the offline scene's: the board's nominal pose, a neighbouring IK
// solution). The goal join is tried before the path is walked: where the scene moved the goal,
// that fails after a few checks. A stretch the scene blocks is repaired when `repair_checks` > 0
// (else the path is empty).
std::vector<Eigen::VectorXd> ArmMotionPlanner::follow(
    const std::vector<Eigen::VectorXd>& hint, const Eigen::VectorXd& start,
    const Eigen::VectorXd& goal, long repair_checks,
    const std::function<bool(const Eigen::VectorXd&)>& valid_here,
    std::chrono::steady_clock::time_point deadline, int max_repairs) {
  const int n = static_cast<int>(hint.size());
  if (n < 2 || hint.front().size() != start.size()) return {};
  const auto at = [&](int i) -> const Eigen::VectorXd& {
    return hint[static_cast<std::size_t>(i)];
  };
  int first = -1;
  int last = -1;
  if (!join_ends(hint, start, goal, first, last)) return {};
  std::vector<Eigen::VectorXd> path{start, at(first)};
  int repairs = 0;
  for (int i = first; i < last;) {
    if ((i + 1 == last || valid(at(i + 1))) && segment_valid(at(i), at(i + 1))) {
      path.push_back(at(++i));
      continue;
    }
    // Blocked after waypoint i: a bridge from it to whichever of the next valid waypoints it
    // reaches, and the stored path again from there.
    if (repair_checks <= 0 || ++repairs > max_repairs) return {};
    std::vector<Eigen::VectorXd> targets;
    std::vector<int> index;
    for (int k = i + 1; k <= last && static_cast<int>(targets.size()) < settings_.repair_targets;
         ++k) {
      if (k == last || valid(at(k))) {
        targets.push_back(at(k));
        index.push_back(k);
      }
    }
    core::BridgeSettings bridge = bridge_settings(repair_checks, deadline);
    bridge.focus = {at(i)};
    bridge.focus_fraction = settings_.repair_focus;
    const auto around = core::plan_bridge_to_any(arm_, valid_here, at(i), targets, bridge);
    if (around.empty()) return {};
    path.insert(path.end(), around.begin() + 1, around.end());
    // The bridge ends exactly at the target it joined (core::plan_bridge_to_any).
    const auto reached = std::find(targets.begin(), targets.end(), around.back());
    assert(reached != targets.end());
    i = index[static_cast<std::size_t>(reached - targets.begin())];
  }
  path.push_back(goal);
  return path;
}

// For an end no straight segment joins to the roadmap (looked up only then): the start joined
// to the longest valid beginning of a stored path (start first), or the longest valid end of
// one joined to the goal (goal last); a single point when no stored path joins.
std::vector<Eigen::VectorXd> ArmMotionPlanner::stored_lead(const Hints& hints,
                                                           const Eigen::VectorXd& start) {
  std::vector<Eigen::VectorXd> best{start};
  for (const auto* hint : hints) {
    const auto& h = *hint;
    const int n = static_cast<int>(h.size());
    if (n < 2 || h.front().size() != start.size()) continue;
    const auto at = [&](int i) -> const Eigen::VectorXd& { return h[static_cast<std::size_t>(i)]; };
    int first = -1;
    for (int i = 0; i < std::min(n, std::max(1, settings_.join_waypoints)) && first < 0; ++i) {
      if (valid(at(i)) && segment_valid(start, at(i))) first = i;
    }
    if (first < 0) continue;
    int reach = first;
    while (reach + 1 < n && valid(at(reach + 1)) && segment_valid(at(reach), at(reach + 1))) {
      ++reach;
    }
    if (reach - first + 2 <= static_cast<int>(best.size())) continue;
    best.assign(1, start);
    for (int i = first; i <= reach; ++i) best.push_back(at(i));
  }
  return best;
}

std::vector<Eigen::VectorXd> ArmMotionPlanner::stored_tail(const Hints& hints,
                                                           const Eigen::VectorXd& goal) {
  std::vector<Eigen::VectorXd> best{goal};
  for (const auto* hint : hints) {
    const auto& h = *hint;
    const int n = static_cast<int>(h.size());
    if (n < 2 || h.front().size() != goal.size()) continue;
    const auto at = [&](int i) -> const Eigen::VectorXd& { return h[static_cast<std::size_t>(i)]; };
    int last = -1;
    for (int j = n - 1; j >= std::max(0, n - std::max(1, settings_.join_waypoints)) && last < 0;
         --j) {
      if (valid(at(j)) && segment_valid(at(j), goal)) last = j;
    }
    if (last < 0) continue;
    int back = last;
    while (back > 0 && valid(at(back - 1)) && segment_valid(at(back - 1), at(back))) --back;
    if (last - back + 2 <= static_cast<int>(best.size())) continue;
    best.assign(h.begin() + back, h.begin() + last + 1);
    best.push_back(goal);
  }
  return best;
}

// Greedy shortcuts within a check budget: from each kept waypoint, the farthest later one a
// straight segment reaches. Drops repeated waypoints first.
void ArmMotionPlanner::shorten(std::vector<Eigen::VectorXd>& path) {
  std::vector<Eigen::VectorXd> unique;
  for (auto& q : path) {
    if (unique.empty() || (q - unique.back()).norm() > 1e-9) unique.push_back(std::move(q));
  }
  if (unique.size() == 1) unique.push_back(unique.front());  // a motion has two ends
  path = std::move(unique);
  long budget = settings_.shortcut_checks;
  path = core::shortcut_path(
      path, [this](const Eigen::VectorXd& q) { return valid(q); }, resolution_, &budget);
}

std::vector<core::GraphEndpoint> ArmMotionPlanner::attach(const Eigen::VectorXd& q,
                                                          bool check_joins) {
  const auto& nodes = roadmap_.record.nodes;
  std::vector<std::pair<double, int>>& near = near_scratch_;
  near.clear();
  near.reserve(nodes.size());
  for (Eigen::Index i = 0; i < roadmap_.node_matrix.cols(); ++i) {
    near.emplace_back((roadmap_.node_matrix.col(i) - q).norm(), static_cast<int>(i));
  }
  const auto take =
      std::min<std::size_t>(near.size(), static_cast<std::size_t>(settings_.attach_neighbours));
  // Nearest first, sorted in growing chunks as far as the walk below goes: it usually stops
  // after the first few (a full sort of the attach_neighbours nearest of thousands costs more
  // than the checks).
  std::size_t sorted = 0;
  const auto sort_up_to = [&](std::size_t j) {
    if (j < sorted) return;
    const std::size_t end = std::min(take, std::max<std::size_t>(2 * sorted, 16));
    const auto first = near.begin() + static_cast<std::ptrdiff_t>(sorted);
    const auto last = near.begin() + static_cast<std::ptrdiff_t>(end);
    if (last != near.end()) std::nth_element(first, last, near.end());
    std::sort(first, last);
    sorted = end;
  };
  std::vector<core::GraphEndpoint> out;
  for (std::size_t j = 0; j < take; ++j) {
    if (static_cast<int>(out.size()) >=
        (check_joins ? settings_.checked_attachments : settings_.attachments)) {
      break;
    }
    sort_up_to(j);
    const int n = near[j].second;
    if (node_valid(n) && (!check_joins || segment_valid(q, nodes[static_cast<std::size_t>(n)]))) {
      out.push_back({n, near[j].first});
    }
  }
  return out;
}

std::vector<core::GraphEndpoint> ArmMotionPlanner::attach_along_stored(
    const Hints& hints, const Eigen::VectorXd& q, bool is_start,
    std::vector<Eigen::VectorXd>& via) {
  if (hints.empty()) return {};
  auto stored = is_start ? stored_lead(hints, q) : stored_tail(hints, q);
  std::vector<core::GraphEndpoint> out;
  if (stored.size() > 1) out = attach(is_start ? stored.back() : stored.front(), true);
  if (!out.empty()) via = std::move(stored);
  return out;
}

MotionResult ArmMotionPlanner::plan(const MotionRequest& request) {
  assert(!request.late_hints || !request.follow_hints);  // late paths only lead wedged ends in
  const auto started = std::chrono::steady_clock::now();
  MotionResult r;
  auto finish = [&](MotionStatus status, std::string reason) {
    r.status = status;
    r.reason = std::move(reason);
    r.edges_checked = checked_;
    r.edges_invalidated = invalidated_;
    if (status != MotionStatus::kSolved) {
      r.path.clear();
    } else if (r.via != MotionVia::kDirect) {
      shorten(r.path);
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    return r;
  };
  auto late = [&] { return std::chrono::steady_clock::now() >= request.deadline; };
  prepare(request);
  if (const std::string why = why_invalid(request.start);
      !why.empty() &&
      !(request.start_in_contact && check(request.start, nullptr) == Verdict::kCollides)) {
    return finish(MotionStatus::kInvalidStart, "the start is invalid: " + why);
  }
  if (const std::string why = why_invalid(request.goal);
      !why.empty() &&
      !(request.end_in_contact && check(request.goal, nullptr) == Verdict::kCollides)) {
    return finish(MotionStatus::kInvalidGoal, "the goal is invalid: " + why);
  }
  if (segment_valid(request.start, request.goal)) {
    r.path = {request.start, request.goal};
    r.via = MotionVia::kDirect;
    return finish(MotionStatus::kSolved, "");
  }
  // The start or goal in contact is valid by design (the lift's first state, the tool set
  // down).
  const auto valid_here = [&](const Eigen::VectorXd& q) {
    return (request.start_in_contact && q == request.start) ||
           (request.end_in_contact && q == request.goal) || valid(q);
  };
  if (settings_.planner != MotionPlannerKind::kRoadmap) {
    if (settings_.planner == MotionPlannerKind::kRrtConnect) {
      core::BridgeSettings scratch;
      scratch.max_checks = settings_.baseline_checks;
      scratch.resolution = resolution_;
      scratch.seed = settings_.seed;
      scratch.deadline = request.deadline;
      r.path = core::plan_bridge(arm_, valid_here, request.start, request.goal, scratch);
    } else {
      r.path = lazy_prm_->plan(valid_here, request.start, request.goal, settings_.baseline_checks,
                               request.deadline);
    }
    if (!r.path.empty()) {
      r.via = settings_.planner == MotionPlannerKind::kRrtConnect ? MotionVia::kRrtConnect
                                                                  : MotionVia::kLazyPrm;
      return finish(MotionStatus::kSolved, "");
    }
    return finish(late() ? MotionStatus::kTimeout : MotionStatus::kNoPath,
                  std::string(to_string(settings_.planner)) + " found no path within its budget");
  }
  // A rejected path is mostly sound: mended where the validator's resolution finds it blocked.
  if (request.rejected != nullptr && settings_.fine_repair_checks > 0) {
    r.path = follow(*request.rejected, request.start, request.goal, settings_.fine_repair_checks,
                    valid_here, request.deadline, settings_.fine_repairs);
    if (!r.path.empty()) {
      r.via = MotionVia::kRepaired;
      return finish(MotionStatus::kSolved, "");
    }
  }
  for (const auto* hint : request.hints) {
    if (!request.follow_hints) break;  // kept for leading a wedged end in (below)
    if (late()) return finish(MotionStatus::kTimeout, "the deadline passed on a stored path");
    r.path = follow(*hint, request.start, request.goal, 0, valid_here, request.deadline, 0);
    if (!r.path.empty()) {
      r.via = MotionVia::kStored;
      return finish(MotionStatus::kSolved, "");
    }
  }
  // What stops the straight motion, for the reason when everything fails (looked up then only:
  // a successful search would have spent these checks for nothing).
  const auto direct_blocker = [&] {
    for (const auto& q :
         core::edge_samples(request.start, request.goal, roadmap_.record.resolution)) {
      if (std::string why = why_invalid(q); !why.empty()) return why;
    }
    return std::string("nothing at the roadmap's resolution");
  };
  // Through the roadmap, lazily validated. Each end first joins its nearest valid nodes with the
  // straight joins unchecked, checked only when a found path uses them (as the roadmap's edges
  // are): most first picks hold, and an end's six checked joins cost as much as the rest of the
  // search. Once a join fails, or no path is found, that end is joined as before: its nearest
  // nodes with joins that hold and, where none does, a stored path's beginning or end.
  std::vector<Eigen::VectorXd> lead{request.start};
  std::vector<Eigen::VectorXd> tail{request.goal};
  bool entries_checked = false;
  bool exits_checked = false;
  std::vector<core::GraphEndpoint> entries;
  std::vector<core::GraphEndpoint> exits;
  // The stored paths that lead a wedged end in: the request's, or its late ones, fetched once.
  Hints fetched;
  bool was_fetched = false;
  const auto hints = [&]() -> const Hints& {
    if (!request.late_hints) return request.hints;
    if (!was_fetched) {
      fetched = request.late_hints();
      was_fetched = true;
    }
    return fetched;
  };
  // An end wedged where no straight segment reaches a roadmap node (a held board out where the
  // slip-filtered roadmap does not go, say) enters it where a stored path that held leads: the
  // lead becomes the start and the stored path's valid beginning, the tail its valid end and
  // the goal.
  const auto check_entries = [&] {
    entries_checked = true;
    entries = attach(request.start, true);
    if (entries.empty()) entries = attach_along_stored(hints(), request.start, true, lead);
  };
  const auto check_exits = [&] {
    exits_checked = true;
    exits = attach(request.goal, true);
    if (exits.empty()) exits = attach_along_stored(hints(), request.goal, false, tail);
  };
  // A start in contact leaves straight up first (its lift is the request's goal, in practice):
  // the roadmap is entered from the goal side only when the direct segment failed.
  entries = attach(request.start, false);
  if (entries.empty()) check_entries();
  if (!entries.empty()) {
    exits = attach(request.goal, false);
    if (exits.empty()) check_exits();
  }
  std::vector<int> entries_joined;  // unchecked joins found to hold
  std::vector<int> exits_joined;
  const auto joins = [this](std::vector<int>& held, const Eigen::VectorXd& q, int node) {
    if (std::find(held.begin(), held.end(), node) != held.end()) return true;
    if (!segment_valid(q, roadmap_.record.nodes[static_cast<std::size_t>(node)])) return false;
    held.push_back(node);
    return true;
  };
  const int max_searches = request.max_searches > 0 ? request.max_searches : settings_.max_searches;
  // A* over the allowed edges, lazily validated, until a path holds (r.path) or the ends part.
  const auto search = [&] {
    while (!entries.empty() && !exits.empty() && r.searches < max_searches) {
      if (late()) return false;
      ++r.searches;
      const bool apart = ends_apart(entries, exits);
      const core::GraphPath path =
          apart ? core::GraphPath{}
                : core::shortest_path(roadmap_.graph, allowed_, entries, exits, search_);
      r.nodes_expanded += path.expanded;
      if (!path.found) {
        if (!apart) learn_components();
        // Unchecked joins may stand in for nodes whose joins hold into another part of the roadmap.
        if (!entries_checked) {
          check_entries();
        } else if (!exits_checked) {
          check_exits();
        } else {
          break;
        }
        continue;
      }
      if (!entries_checked && !joins(entries_joined, request.start, path.nodes.front())) {
        check_entries();
        continue;
      }
      if (!exits_checked && !joins(exits_joined, request.goal, path.nodes.back())) {
        check_exits();
        continue;
      }
      // The path's nodes first (a check each, against a segment's dozens): a path through a
      // blocked node is dropped with all the node's edges before any of its segments is checked.
      bool clear = true;
      for (const int n : path.nodes) clear = node_valid(n) && clear;
      for (std::size_t i = 1; i < path.nodes.size() && clear; ++i) {
        const int a = path.nodes[i - 1];
        const int b = path.nodes[i];
        for (auto it = roadmap_.graph.neighbours_begin(a); it != roadmap_.graph.neighbours_end(a);
             ++it) {
          if (it->node != b || !allowed_[static_cast<std::size_t>(it->edge)]) continue;
          if (!edge_valid(it->edge)) {
            if (allowed_[static_cast<std::size_t>(it->edge)]) {  // else dropped with its node
              allowed_[static_cast<std::size_t>(it->edge)] = false;
              ++invalidated_;
            }
            clear = false;
          }
          break;
        }
      }
      if (!clear) continue;
      r.path = lead;
      for (const int n : path.nodes)
        r.path.push_back(roadmap_.record.nodes[static_cast<std::size_t>(n)]);
      r.path.insert(r.path.end(), tail.begin(), tail.end());
      r.via = lead.size() > 1 || tail.size() > 1 ? MotionVia::kStoredRoadmap : MotionVia::kRoadmap;
      return true;
    }
    return false;
  };
  if (search()) return finish(MotionStatus::kSolved, "");
  // Both ends attach but the roadmap is cut between their nodes: where a stored path's valid
  // beginning (or end) leads into another part of it (the way the arm came, say), the search
  // starts there before any bridge. The moved end's joins are checked; the other's stay as
  // they were.
  if (!entries.empty() && !exits.empty() && (request.late_hints || !request.hints.empty()) &&
      !late()) {
    const auto reenter = [&](const Eigen::VectorXd& q, bool is_start,
                             std::vector<Eigen::VectorXd>& along,
                             std::vector<core::GraphEndpoint>& ends, bool& checked) {
      if (along.size() != 1) return false;  // already along a stored path
      std::vector<Eigen::VectorXd> via;
      auto e = attach_along_stored(hints(), q, is_start, via);
      if (e.empty()) return false;
      along = std::move(via);
      ends = std::move(e);
      checked = true;
      return true;
    };
    const bool moved_start = reenter(request.start, true, lead, entries, entries_checked);
    const bool moved = reenter(request.goal, false, tail, exits, exits_checked) || moved_start;
    if (moved && search()) return finish(MotionStatus::kSolved, "");
  }
  if (late())
    return finish(MotionStatus::kTimeout,
                  "the deadline passed during the search, before any bridge");
  const char* wedge = entries.empty() ? "the start attaches to no roadmap node"
                      : exits.empty() ? "the goal attaches to no roadmap node"
                                      : nullptr;
  r.wedged = wedge != nullptr;
  if (!request.allow_bridge) {
    return finish(MotionStatus::kNoPath, "the roadmap does not connect start and goal");
  }
  // A stored path the scene blocks, repaired around what is in the way (local bridges), before
  // a bridge across the whole motion; in the first round only when an end attaches to no
  // roadmap node (the whole-motion bridge then has to find the way out of a wedge by chance).
  const long repair_budget = r.wedged
                                 ? std::max(settings_.repair_checks, settings_.wedged_repair_checks)
                                 : settings_.repair_checks;
  // A wedged motion's stored paths are each tried cheaply before any is tried at full budget.
  // (With one stored path the cheap try would be the full one's first checks, spent twice.)
  std::vector<long> repair_budgets{repair_budget};
  if (r.wedged && request.hints.size() > 1 && settings_.wedged_first_repair_checks > 0 &&
      settings_.wedged_first_repair_checks < repair_budget) {
    repair_budgets.insert(repair_budgets.begin(), settings_.wedged_first_repair_checks);
  }
  // A repair is as deterministic as a bridge: one that failed within its budget is not run again
  // (the larger bridges' round repeats a wedged motion's repairs at the same budgets).
  for (const long budget : repair_budgets) {
    for (const auto* hint : request.hints) {
      if (!request.follow_hints || budget <= 0 || late()) break;
      const FailedBridge repair{request.start, request.goal, budget, request.start_in_contact,
                                hint,          context_};
      if (std::find(failed_bridges_.begin(), failed_bridges_.end(), repair) !=
          failed_bridges_.end()) {
        continue;
      }
      r.path = follow(*hint, request.start, request.goal, budget, valid_here, request.deadline,
                      settings_.max_repairs);
      if (!r.path.empty()) {
        r.via = MotionVia::kStoredRepair;
        return finish(MotionStatus::kSolved, "");
      }
      if (!late()) remember_failure(repair);
    }
  }
  // The roadmap is cut here: a bridge under the same checks, within the deadline.
  core::BridgeSettings bridge =
      bridge_settings(r.wedged ? std::min(settings_.bridge_checks, settings_.wedged_bridge_checks)
                               : settings_.bridge_checks,
                      request.deadline);
  if (r.wedged) {
    bridge.focus = {entries.empty() ? request.start : request.goal};
    bridge.focus_fraction = settings_.wedged_focus;
  }
  // The bridge is deterministic: the same ends under the same checks and budget fail again.
  const FailedBridge asked{request.start, request.goal, bridge.max_checks, request.start_in_contact,
                           nullptr,       context_};
  const bool failed_before =
      std::find(failed_bridges_.begin(), failed_bridges_.end(), asked) != failed_bridges_.end();
  if (!failed_before) {
    r.path = core::plan_bridge(arm_, valid_here, request.start, request.goal, bridge);
  }
  if (!r.path.empty()) {
    r.via = MotionVia::kBridge;
    return finish(MotionStatus::kSolved, "");
  }
  if (late()) return finish(MotionStatus::kTimeout, "the deadline passed during the bridge");
  if (!failed_before) remember_failure(asked);
  return finish(
      MotionStatus::kNoPath,
      r.wedged
          ? std::string(wedge) + " and no bridge was found"
          : "the roadmap is cut between start and goal (" + std::to_string(invalidated_) +
                " edges blocked in the scene) and no bridge was found; the straight motion meets " +
                direct_blocker());
}

}  // namespace hila::online
