#include "hila/core/lazy_prm.hpp"

#include <ompl/base/PlannerData.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <ompl/util/Console.h>

#include "hila/core/bridge.hpp"
#include "hila/core/internal/ompl_state.hpp"
#include "ompl_joint_space.hpp"

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace hila::core {

namespace {

// Thrown by the validity checker once a query is out of checks or time. OMPL's LazyPRM only
// tests its termination condition between roadmap growth steps; its loop of search, lazy
// check and removal runs to the end however long that takes (far past any deadline), and it
// checks validity on every turn of that loop, so that is where it is stopped.
struct QueryBudgetSpent {};

}  // namespace

struct LazyPrmPlanner::Impl {
  int dof = 0;
  double resolution = 0.05;
  std::shared_ptr<ob::RealVectorStateSpace> space;
  ob::SpaceInformationPtr si;
  std::unique_ptr<og::LazyPRM> planner;
  // The current query's validity; the checker OMPL holds calls through it.
  const std::function<bool(const Eigen::VectorXd&)>* valid = nullptr;
  long checks = 0;
  long max_checks = 0;
  std::chrono::steady_clock::time_point deadline;
  unsigned long max_vertices = 20000;
};

LazyPrmPlanner::LazyPrmPlanner(const Arm& arm, const LazyPrmSettings& settings)
    : impl_(std::make_unique<Impl>()) {
  ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
  Impl& m = *impl_;
  m.dof = arm.chain.dof();
  m.resolution = settings.resolution;
  m.max_vertices = settings.max_vertices;
  m.space = detail::joint_space(arm, settings.joint_range, settings.seed, nullptr, nullptr);
  m.si = std::make_shared<ob::SpaceInformation>(m.space);
  Impl* self = impl_.get();
  m.si->setStateValidityChecker([self](const ob::State* s) {
    if (self->checks >= self->max_checks || std::chrono::steady_clock::now() >= self->deadline) {
      throw QueryBudgetSpent{};
    }
    ++self->checks;
    return self->valid != nullptr && (*self->valid)(to_vector(s, self->dof));
  });
  m.si->setStateValidityCheckingResolution(settings.resolution / m.space->getMaximumExtent());
  m.si->setup();
  m.planner = std::make_unique<og::LazyPRM>(m.si);
  m.planner->setRange(settings.range);
  m.planner->setProblemDefinition(std::make_shared<ob::ProblemDefinition>(m.si));
  m.planner->setup();
}

LazyPrmPlanner::~LazyPrmPlanner() = default;

std::vector<Eigen::VectorXd> LazyPrmPlanner::plan(
    const std::function<bool(const Eigen::VectorXd&)>& valid, const Eigen::VectorXd& from,
    const Eigen::VectorXd& to, long max_checks, std::chrono::steady_clock::time_point deadline) {
  Impl& m = *impl_;
  if (!valid(from) || !valid(to)) return {};
  if (segment_valid(valid, from, to, m.resolution)) return {from, to};
  ob::ScopedState<> start(m.space), goal(m.space);
  from_vector(from, start.get());
  from_vector(to, goal.get());
  if (!m.si->satisfiesBounds(start.get()) || !m.si->satisfiesBounds(goal.get())) return {};
  m.planner->clearQuery();
  m.planner->clearValidity();  // last query's scene is not this one's
  auto pdef = std::make_shared<ob::ProblemDefinition>(m.si);
  pdef->setStartAndGoalStates(start, goal);
  m.planner->setProblemDefinition(pdef);
  m.valid = &valid;
  m.checks = 0;
  m.max_checks = max_checks;
  m.deadline = deadline;
  // The cap bounds this query's growth: the roadmap persists, so a cap on its total size would
  // stop every query once it is reached.
  const unsigned long cap = m.planner->milestoneCount() + m.max_vertices;
  ob::PlannerStatus status = ob::PlannerStatus::TIMEOUT;
  try {
    status = m.planner->solve(ob::PlannerTerminationCondition([&] {
      return m.checks >= max_checks || m.planner->milestoneCount() >= cap ||
             std::chrono::steady_clock::now() >= deadline;
    }));
  } catch (const QueryBudgetSpent&) {
    // Stopped inside LazyPRM's search loop: its graph may be half-updated, so it starts over.
    m.valid = nullptr;
    m.planner->clear();
    return {};
  }
  m.valid = nullptr;
  if (status != ob::PlannerStatus::EXACT_SOLUTION) return {};
  const auto* path = pdef->getSolutionPath()->as<og::PathGeometric>();
  std::vector<Eigen::VectorXd> out;
  for (std::size_t i = 0; i < path->getStateCount(); ++i) {
    out.push_back(to_vector(path->getState(i), m.dof));
  }
  // Re-checked at exactly the documented resolution (OMPL's fraction of the extent rounds).
  for (std::size_t i = 1; i < out.size(); ++i) {
    if (!segment_valid(valid, out[i - 1], out[i], m.resolution)) return {};
  }
  return out;
}

std::size_t LazyPrmPlanner::roadmap_vertices() const {
  ob::PlannerData data(impl_->si);
  impl_->planner->getPlannerData(data);
  return data.numVertices();
}

}  // namespace hila::core
