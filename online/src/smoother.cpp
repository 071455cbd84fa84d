#include "hila/online/smoother.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>

#include "hila/core/time_parameterization.hpp"

namespace hila::online {

using core::resample_path;

SmoothResult smooth_path(
    const std::vector<Eigen::VectorXd>& path,
    const std::function<bool(const Eigen::VectorXd&, const Eigen::VectorXd&)>& segment_valid,
    const SmootherSettings& settings) {
  SmoothResult result;
  result.path = path;
  if (path.size() < 3 || !(settings.spacing > 0.0)) return result;
  const std::vector<Eigen::VectorXd> original = resample_path(path, settings.spacing);
  const int points = static_cast<int>(original.size());
  const int inner = points - 2;  // the unknowns: every point but the ends
  if (inner < 1) return result;
  const int dof = static_cast<int>(original.front().size());

  // Second differences over all points; the normal matrix splits into the inner block and its
  // coupling to the two fixed ends.
  using Sparse = Eigen::SparseMatrix<double>;
  std::vector<Eigen::Triplet<double>> d2;
  for (int r = 0; r + 2 < points; ++r) {
    d2.emplace_back(r, r, 1.0);
    d2.emplace_back(r, r + 1, -2.0);
    d2.emplace_back(r, r + 2, 1.0);
  }
  Sparse second(points - 2, points);
  second.setFromTriplets(d2.begin(), d2.end());
  const Sparse normal = Sparse(second.transpose()) * second;
  const Sparse inner_block = normal.block(1, 1, inner, inner);
  const Sparse to_ends = normal.block(1, 0, inner, points);

  Eigen::MatrixXd x0(points, dof);
  for (int i = 0; i < points; ++i) x0.row(i) = original[static_cast<std::size_t>(i)].transpose();
  Eigen::MatrixXd ends = Eigen::MatrixXd::Zero(points, dof);
  ends.row(0) = x0.row(0);
  ends.row(points - 1) = x0.row(points - 1);
  const Eigen::MatrixXd coupling = to_ends * ends;

  const double fidelity =
      std::pow(settings.spacing / std::max(settings.length, settings.spacing), 4);
  Eigen::VectorXd weight = Eigen::VectorXd::Constant(inner, fidelity);
  Eigen::CholmodSimplicialLLT<Sparse> cholesky;
  for (int round = 0; round < settings.max_rounds; ++round) {
    Sparse system = inner_block;
    for (int i = 0; i < inner; ++i) system.coeffRef(i, i) += weight[i];
    cholesky.compute(system);
    ++result.rounds;
    if (cholesky.info() != Eigen::Success) return result;  // SPD by construction: not expected
    const Eigen::MatrixXd rhs = weight.asDiagonal() * x0.middleRows(1, inner) - coupling;
    const Eigen::MatrixXd solved = cholesky.solve(rhs);
    if (cholesky.info() != Eigen::Success || !solved.allFinite()) return result;

    std::vector<Eigen::VectorXd> candidate;
    candidate.reserve(static_cast<std::size_t>(points));
    candidate.push_back(original.front());
    for (int i = 0; i < inner; ++i) candidate.emplace_back(solved.row(i).transpose());
    candidate.push_back(original.back());
    bool all_valid = true;
    for (int s = 0; s + 1 < points; ++s) {
      ++result.segments_checked;
      if (segment_valid(candidate[static_cast<std::size_t>(s)],
                        candidate[static_cast<std::size_t>(s + 1)])) {
        continue;
      }
      all_valid = false;
      // Inner indices of the points around segment s (points s and s + 1).
      for (int p = s - settings.pin_reach; p <= s + 1 + settings.pin_reach; ++p) {
        if (p >= 1 && p <= inner) {
          weight[p - 1] = std::max(weight[p - 1], 1.0) * settings.pin_growth;
        }
      }
    }
    if (all_valid) {
      result.path = std::move(candidate);
      result.smoothed = true;
      return result;
    }
  }
  return result;
}

}  // namespace hila::online
