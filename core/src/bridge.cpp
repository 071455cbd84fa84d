#include "hila/core/bridge.hpp"

#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/goals/GoalStates.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "hila/core/internal/ompl_state.hpp"
#include "ompl_joint_space.hpp"

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace hila::core {

std::vector<Eigen::VectorXd> edge_samples(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                          double resolution) {
  const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / resolution)));
  std::vector<Eigen::VectorXd> out;
  for (int i = 1; i < steps; ++i) out.push_back(a + (b - a) * (static_cast<double>(i) / steps));
  return out;
}

bool all_samples_coarse_to_fine(const Eigen::VectorXd& a, const Eigen::VectorXd& b,
                                double resolution,
                                const std::function<bool(const Eigen::VectorXd&)>& visit,
                                long* visited) {
  const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / resolution)));
  // Open index intervals (lo, hi), breadth first: each visit splits one at its middle.
  std::vector<std::pair<int, int>> queue{{0, steps}};
  const Eigen::VectorXd delta = b - a;
  for (std::size_t next = 0; next < queue.size(); ++next) {
    const auto [lo, hi] = queue[next];
    if (hi - lo < 2) continue;
    const int mid = lo + (hi - lo) / 2;
    if (visited != nullptr) ++*visited;
    if (!visit(a + delta * (static_cast<double>(mid) / steps))) return false;
    queue.emplace_back(lo, mid);
    queue.emplace_back(mid, hi);
  }
  return true;
}

bool segment_valid(const std::function<bool(const Eigen::VectorXd&)>& valid,
                   const Eigen::VectorXd& a, const Eigen::VectorXd& b, double resolution) {
  return all_samples_coarse_to_fine(a, b, resolution, valid);
}

std::vector<Eigen::VectorXd> shortcut_path(const std::vector<Eigen::VectorXd>& path,
                                           const std::function<bool(const Eigen::VectorXd&)>& valid,
                                           double resolution, long* budget, bool check_kept) {
  if (path.empty()) return {};
  std::vector<Eigen::VectorXd> out{path.front()};
  std::size_t at = 0;
  while (at + 1 < path.size()) {
    std::size_t next = at + 1;
    for (std::size_t j = path.size() - 1; j > at + 1 && (budget == nullptr || *budget > 0); --j) {
      long spent = 0;
      const bool clear = all_samples_coarse_to_fine(path[at], path[j], resolution, valid, &spent);
      if (budget != nullptr) *budget -= spent;
      if (clear) {
        next = j;
        break;
      }
    }
    if (check_kept && next == at + 1 && !segment_valid(valid, path[at], path[next], resolution)) {
      return {};
    }
    out.push_back(path[next]);
    at = next;
  }
  return out;
}

std::vector<Eigen::VectorXd> plan_bridge(const Arm& arm,
                                         const std::function<bool(const Eigen::VectorXd&)>& valid,
                                         const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                                         const BridgeSettings& settings) {
  return plan_bridge_to_any(arm, valid, from, {to}, settings);
}

std::vector<Eigen::VectorXd> plan_bridge_to_any(
    const Arm& arm, const std::function<bool(const Eigen::VectorXd&)>& valid,
    const Eigen::VectorXd& from, const std::vector<Eigen::VectorXd>& targets,
    const BridgeSettings& settings) {
  if (!valid(from)) return {};
  std::vector<const Eigen::VectorXd*> ends;
  for (const auto& t : targets) {
    if (valid(t)) ends.push_back(&t);
  }
  if (ends.empty()) return {};
  for (const auto* t : ends) {
    if (segment_valid(valid, from, *t, settings.resolution)) return {from, *t};
  }
  const int dof = arm.chain.dof();
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
  // The space's bounds take in the start and every end (joint_space widens them by two).
  Eigen::VectorXd low = from;
  Eigen::VectorXd high = from;
  for (const auto* t : ends) {
    low = low.cwiseMin(*t);
    high = high.cwiseMax(*t);
  }
  const auto space =
      detail::joint_space(arm, settings.joint_range, settings.seed, &low, &high, settings.project,
                          {settings.focus, settings.focus_fraction, settings.focus_sigma});
  auto si = std::make_shared<ob::SpaceInformation>(space);
  long checks = 0;
  si->setStateValidityChecker([&](const ob::State* s) {
    ++checks;
    return valid(to_vector(s, dof));
  });
  si->setStateValidityCheckingResolution(settings.resolution / space->getMaximumExtent());
  si->setup();
  auto pdef = std::make_shared<ob::ProblemDefinition>(si);
  ob::ScopedState<> start(space);
  for (int i = 0; i < dof; ++i) start[static_cast<unsigned>(i)] = from[i];
  pdef->addStartState(start);
  auto goals = std::make_shared<ob::GoalStates>(si);
  for (const auto* t : ends) {
    ob::ScopedState<> goal(space);
    for (int i = 0; i < dof; ++i) goal[static_cast<unsigned>(i)] = (*t)[i];
    goals->addState(goal);
  }
  pdef->setGoal(goals);
  og::RRTConnect planner(si);
  planner.setRange(settings.range);
  planner.setProblemDefinition(pdef);
  planner.setup();
  const ob::PlannerStatus status = planner.solve(ob::PlannerTerminationCondition([&] {
    return checks >= settings.max_checks ||
           (settings.deadline && std::chrono::steady_clock::now() >= *settings.deadline);
  }));
  if (status != ob::PlannerStatus::EXACT_SOLUTION) return {};
  const auto* path = pdef->getSolutionPath()->as<og::PathGeometric>();
  std::vector<Eigen::VectorXd> raw;
  for (std::size_t i = 0; i < path->getStateCount(); ++i) {
    raw.push_back(to_vector(path->getState(i), dof));
  }
  // RRT-Connect's own segments were checked by OMPL's motion validator: the kept ones are
  // checked again at exactly the documented resolution.
  return shortcut_path(raw, valid, settings.resolution, nullptr, true);
}

}  // namespace hila::core
