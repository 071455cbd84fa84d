#include "ompl_joint_space.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "hila/core/joint_box.hpp"

namespace ob = ompl::base;

namespace hila::core::detail {

SeededSampler::SeededSampler(const ob::StateSpace* space, std::uint64_t seed, Projection project,
                             SamplerFocus focus)
    : ob::StateSampler(space), rng_(seed), project_(std::move(project)), focus_(std::move(focus)) {
  for (const auto& c : focus_.around) {
    assert(c.size() == static_cast<Eigen::Index>(space->getDimension()));
    (void)c;
  }
}

// Box-Muller from the seeded generator (std::normal_distribution's output is not specified
// across standard libraries).
double SeededSampler::gaussian() {
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
}

void SeededSampler::sampleUniform(ob::State* state) {
  if (!project_) {
    draw(state);
    return;
  }
  const auto& bounds = space_->as<ob::RealVectorStateSpace>()->getBounds();
  auto* v = state->as<ob::RealVectorStateSpace::StateType>();
  const auto dof = static_cast<Eigen::Index>(bounds.low.size());
  scratch_.resize(dof);
  constexpr int kTries = 8;
  for (int t = 0; t < kTries; ++t) {
    draw(state);
    for (Eigen::Index i = 0; i < dof; ++i) scratch_[i] = v->values[i];
    if (!project_(scratch_)) continue;
    bool inside = true;
    for (Eigen::Index i = 0; i < dof && inside; ++i) {
      inside = scratch_[i] >= bounds.low[static_cast<std::size_t>(i)] &&
               scratch_[i] <= bounds.high[static_cast<std::size_t>(i)];
    }
    if (!inside) continue;
    for (Eigen::Index i = 0; i < dof; ++i) v->values[i] = scratch_[i];
    return;
  }
}

void SeededSampler::draw(ob::State* state) {
  const auto& bounds = space_->as<ob::RealVectorStateSpace>()->getBounds();
  auto* v = state->as<ob::RealVectorStateSpace::StateType>();
  if (!focus_.around.empty() && uniform() < focus_.fraction) {
    const auto k = std::min(focus_.around.size() - 1,
                            static_cast<std::size_t>(uniform() * focus_.around.size()));
    const Eigen::VectorXd& c = focus_.around[k];
    for (std::size_t i = 0; i < bounds.low.size(); ++i) {
      v->values[i] = std::clamp(c[static_cast<Eigen::Index>(i)] + focus_.sigma * gaussian(),
                                bounds.low[i], bounds.high[i]);
    }
    return;
  }
  for (std::size_t i = 0; i < bounds.low.size(); ++i) {
    v->values[i] = bounds.low[i] + uniform() * (bounds.high[i] - bounds.low[i]);
  }
}

void SeededSampler::sampleUniformNear(ob::State* state, const ob::State* near, double distance) {
  const auto& bounds = space_->as<ob::RealVectorStateSpace>()->getBounds();
  auto* v = state->as<ob::RealVectorStateSpace::StateType>();
  const auto* c = near->as<ob::RealVectorStateSpace::StateType>();
  for (std::size_t i = 0; i < bounds.low.size(); ++i) {
    v->values[i] = std::clamp(c->values[i] + (2.0 * uniform() - 1.0) * distance, bounds.low[i],
                              bounds.high[i]);
  }
}

void SeededSampler::sampleGaussian(ob::State* state, const ob::State* mean, double stddev) {
  sampleUniformNear(state, mean, 2.0 * stddev);
}

std::shared_ptr<ob::RealVectorStateSpace> joint_space(
    const Arm& arm, double joint_range, std::uint64_t seed, const Eigen::VectorXd* include_a,
    const Eigen::VectorXd* include_b, SeededSampler::Projection project, SamplerFocus focus) {
  const int dof = arm.chain.dof();
  auto space = std::make_shared<ob::RealVectorStateSpace>(static_cast<unsigned>(dof));
  ob::RealVectorBounds bounds(static_cast<unsigned>(dof));
  const JointBox box = joint_box(arm, joint_range);
  for (int i = 0; i < dof; ++i) {
    double low = box.lower[i];
    double high = box.upper[i];
    for (const Eigen::VectorXd* q : {include_a, include_b}) {
      if (q == nullptr) continue;
      low = std::min(low, (*q)[i]);
      high = std::max(high, (*q)[i]);
    }
    bounds.setLow(static_cast<unsigned>(i), low);
    bounds.setHigh(static_cast<unsigned>(i), high);
  }
  space->setBounds(bounds);
  space->setStateSamplerAllocator(
      [seed, project = std::move(project), focus = std::move(focus)](const ob::StateSpace* s) {
        return std::make_shared<SeededSampler>(s, seed, project, focus);
      });
  return space;
}

}  // namespace hila::core::detail
