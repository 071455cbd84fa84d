#pragma once

// Joint vectors to and from OMPL real-vector states, for the code that plans with OMPL (the
// bridge, the LazyPRM baseline, the offline roadmap's sampler). Include only where OMPL is.

#include <ompl/base/State.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>

#include <Eigen/Core>

namespace hila::core {

inline Eigen::VectorXd to_vector(const ompl::base::State* s, int dof) {
  const auto* v = s->as<ompl::base::RealVectorStateSpace::StateType>();
  Eigen::VectorXd q(dof);
  for (int i = 0; i < dof; ++i) q[i] = v->values[i];
  return q;
}

inline void from_vector(const Eigen::VectorXd& q, ompl::base::State* s) {
  auto* v = s->as<ompl::base::RealVectorStateSpace::StateType>();
  for (Eigen::Index i = 0; i < q.size(); ++i) v->values[i] = q[i];
}

}  // namespace hila::core
