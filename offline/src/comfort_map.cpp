#include "hila/offline/comfort_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>

#include "hila/core/generic_ik.hpp"
#include "hila/offline/comfort.hpp"

namespace hila::offline {

std::vector<Eigen::Quaterniond> spread_orientations(int count) {
  constexpr double kPhi = 1.4142135623730951;    // sqrt(2)
  constexpr double kPsi = 1.533751168755204288;  // root of x^4 = x + 4
  std::vector<Eigen::Quaterniond> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const double s = i + 0.5;
    const double r = std::sqrt(s / count);
    const double big_r = std::sqrt(1.0 - s / count);
    const double alpha = 2.0 * core::kPi * s / kPhi;
    const double beta = 2.0 * core::kPi * s / kPsi;
    out.emplace_back(big_r * std::cos(beta), r * std::sin(alpha), r * std::cos(alpha),
                     big_r * std::sin(beta));
    out.back().normalize();
  }
  return out;
}

int nearest_orientation(const std::vector<Eigen::Quaterniond>& set, const Eigen::Quaterniond& q) {
  int best = 0;
  double best_dot = -1.0;
  for (int i = 0; i < static_cast<int>(set.size()); ++i) {
    const double d = std::abs(set[static_cast<std::size_t>(i)].dot(q));
    if (d > best_dot) {
      best_dot = d;
      best = i;
    }
  }
  return best;
}

double comfort_index_fast(const core::Jacobian& jacobian, double characteristic_length) {
  if (jacobian.cols() < 6) return 0.0;
  core::Jacobian scaled = jacobian;
  scaled.topRows<3>() /= characteristic_length;
  const Eigen::Matrix<double, 6, 6> jjt = scaled * scaled.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(jjt, Eigen::EigenvaluesOnly);
  const auto& l = eig.eigenvalues();  // ascending
  if (l[5] <= 0.0) return 0.0;
  return std::sqrt(std::max(0.0, l[0]) / l[5]);
}

std::size_t ComfortMap::index(const Eigen::Vector3i& node, int orientation) const {
  const std::size_t cell =
      (static_cast<std::size_t>(node.x()) * static_cast<std::size_t>(dims_.y()) +
       static_cast<std::size_t>(node.y())) *
          static_cast<std::size_t>(dims_.z()) +
      static_cast<std::size_t>(node.z());
  return cell * orientations_.size() + static_cast<std::size_t>(orientation);
}

Eigen::Vector3i ComfortMap::nearest_node(const Eigen::Vector3d& position) const {
  Eigen::Vector3i node;
  for (int k = 0; k < 3; ++k) {
    const long n = std::lround((position[k] - origin_[k]) / spacing_);
    node[k] = static_cast<int>(std::clamp<long>(n, 0, dims_[k] - 1));
  }
  return node;
}

Eigen::Vector3d ComfortMap::node_position(const Eigen::Vector3i& node) const {
  return origin_ + spacing_ * node.cast<double>();
}

double ComfortMap::bin(const Eigen::Vector3i& node, int orientation) const {
  return values_[index(node, orientation)] / 255.0;
}

double ComfortMap::lookup(const core::Pose& hand) const {
  const int o = nearest_orientation(orientations_, Eigen::Quaterniond(hand.linear()));
  const Eigen::Vector3d g = (hand.translation() - origin_) / spacing_;
  Eigen::Vector3i base;
  Eigen::Vector3d t;
  for (int k = 0; k < 3; ++k) {
    if (g[k] < 0.0 || g[k] > dims_[k] - 1) return 0.0;  // outside the grid: out of reach
    base[k] = std::min(static_cast<int>(std::floor(g[k])), dims_[k] - 2);
    t[k] = g[k] - base[k];
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    double w = 1.0;
    Eigen::Vector3i node = base;
    for (int k = 0; k < 3; ++k) {
      const bool upper = (corner >> k) & 1;
      node[k] += upper ? 1 : 0;
      w *= upper ? t[k] : 1.0 - t[k];
    }
    value += w * bin(node, o);
  }
  return value;
}

ComfortMap ComfortMap::from_record(const db::ComfortMapRecord& record) {
  ComfortMap map;
  map.origin_ = record.origin;
  map.spacing_ = record.spacing;
  map.dims_ = record.dims;
  map.orientations_ = record.orientations;
  map.values_ = record.values;
  map.coverage_ = record.coverage;
  return map;
}

db::ComfortMapRecord ComfortMap::to_record(const std::string& arm,
                                           const ComfortMapSettings& settings) const {
  db::ComfortMapRecord record;
  record.arm = arm;
  record.origin = origin_;
  record.spacing = spacing_;
  record.dims = dims_;
  record.orientations = orientations_;
  record.values = values_;
  record.samples = settings.samples;
  record.seed = settings.seed;
  record.coverage = coverage_;
  return record;
}

ComfortMap ComfortMap::build(const core::KinematicChain& arm, const ComfortMapSettings& settings) {
  ComfortMap map;
  map.spacing_ = settings.spacing;
  map.orientations_ = spread_orientations(settings.orientations);
  const double reach = characteristic_length(arm);
  const Eigen::Vector3d shoulder = arm.first_joint_position();
  const int half = static_cast<int>(std::ceil(reach / settings.spacing)) + 1;
  map.origin_ = shoulder - settings.spacing * Eigen::Vector3d::Constant(half);
  map.dims_ = Eigen::Vector3i::Constant(2 * half + 1);
  map.values_.assign(static_cast<std::size_t>(map.dims_.prod()) * map.orientations_.size(), 0);

  std::mt19937_64 rng(settings.seed);
  core::Pose tip;
  core::Jacobian jac;
  for (long s = 0; s < settings.samples; ++s) {
    const Eigen::VectorXd q = core::random_configuration(arm, rng);
    arm.fk_and_jacobian(q, tip, jac);
    const double quality = comfort_index_fast(jac, reach);
    const auto value =
        static_cast<std::uint8_t>(std::lround(std::clamp(quality, 0.0, 1.0) * 255.0));
    const int o = nearest_orientation(map.orientations_, Eigen::Quaterniond(tip.linear()));
    std::uint8_t& slot = map.values_[map.index(map.nearest_node(tip.translation()), o)];
    slot = std::max(slot, value);
  }
  // Coverage over the bins whose node lies within reach of the shoulder.
  long inside = 0, filled = 0;
  for (int x = 0; x < map.dims_.x(); ++x) {
    for (int y = 0; y < map.dims_.y(); ++y) {
      for (int z = 0; z < map.dims_.z(); ++z) {
        const Eigen::Vector3i node(x, y, z);
        if ((map.node_position(node) - shoulder).norm() > reach) continue;
        for (int o = 0; o < static_cast<int>(map.orientations_.size()); ++o) {
          ++inside;
          filled += map.values_[map.index(node, o)] > 0 ? 1 : 0;
        }
      }
    }
  }
  map.coverage_ = inside ? static_cast<double>(filled) / static_cast<double>(inside) : 0.0;
  return map;
}

}  // namespace hila::offline
