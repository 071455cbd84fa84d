#pragma once

// OMPL set-up shared by the bridge and the LazyPRM baseline: an arm's joint box with a seeded
// sampler, so that planning is deterministic whatever ran before in the process.

#include <ompl/base/StateSampler.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "hila/core/cell.hpp"

namespace hila::core::detail {

// Where part of the samples are drawn: around given configurations (a Gaussian per joint),
// for a tree rooted where few straight steps toward uniform samples are free.
struct SamplerFocus {
  std::vector<Eigen::VectorXd> around;  // each of the space's dimension
  double fraction = 0.0;                // of the samples
  double sigma = 0.5;                   // rad, per joint
};

// Uniform joint samples from a seeded generator (OMPL's own samplers draw from a process-wide
// seed, which would make plans depend on what ran before); a `focus` share of them around given
// configurations instead.
class SeededSampler : public ompl::base::StateSampler {
 public:
  // `project` (optional) moves each uniform sample onto a constraint, or rejects it (false):
  // the sample is then drawn again, a few times at most (the last one is kept as drawn).
  using Projection = std::function<bool(Eigen::VectorXd&)>;
  SeededSampler(const ompl::base::StateSpace* space, std::uint64_t seed,
                Projection project = nullptr, SamplerFocus focus = {});
  void sampleUniform(ompl::base::State* state) override;
  void sampleUniformNear(ompl::base::State* state, const ompl::base::State* near,
                         double distance) override;
  void sampleGaussian(ompl::base::State* state, const ompl::base::State* mean,
                      double stddev) override;

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  void draw(ompl::base::State* state);
  double gaussian();
  std::mt19937_64 rng_;
  Projection project_;
  SamplerFocus focus_;
  Eigen::VectorXd scratch_;
};

// The arm's joints in core::joint_box(arm, joint_range), widened to include
// `include_a` and `include_b` (valid ends, hence within the limits) when given; its uniform
// samples go through `project` when given (SeededSampler).
std::shared_ptr<ompl::base::RealVectorStateSpace> joint_space(
    const Arm& arm, double joint_range, std::uint64_t seed, const Eigen::VectorXd* include_a,
    const Eigen::VectorXd* include_b, SeededSampler::Projection project = nullptr,
    SamplerFocus focus = {});

}  // namespace hila::core::detail
