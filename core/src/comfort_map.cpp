#include "hila/core/comfort_map.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "hila/core/comfort.hpp"
#include "hila/core/generic_ik.hpp"

namespace hila::core {

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

namespace {

// Face (largest |component|) and cell of a quaternion in the cube-face grid; the quaternion is
// folded so that component is positive.
int orientation_cell(const Eigen::Vector4d& q, int n) {
  // Branch-free argmax of |q_k|: a query's face is unpredictable.
  const Eigen::Vector4d a = q.cwiseAbs();
  const int f01 = a[1] > a[0] ? 1 : 0;
  const int f23 = a[3] > a[2] ? 3 : 2;
  const int face = a[f23] > a[f01] ? f23 : f01;
  const double inv = 0.5 * n / q[face];  // the sign fold: divides by the signed component
  int cell = face;
  for (int k = 0; k < 4; ++k) {
    if (k == face) continue;
    const int c = static_cast<int>(q[k] * inv + 0.5 * n);  // u = q_k / q_face in [-1, 1]
    cell = cell * n + std::min(std::max(c, 0), n - 1);
  }
  return cell;
}

double rotation_metric(const Eigen::Vector4d& a, const Eigen::Vector4d& b) {
  return std::acos(std::min(1.0, std::abs(a.dot(b))));
}

}  // namespace

OrientationIndex::OrientationIndex(const std::vector<Eigen::Quaterniond>& set, int n) : n_(n) {
  for (const auto& q : set) set_.emplace_back(q.w(), q.x(), q.y(), q.z());
  const int cells = 4 * n * n * n;
  offsets_.assign(static_cast<std::size_t>(cells) + 1, 0);
  std::vector<std::vector<int>> lists(static_cast<std::size_t>(cells));
  for (int face = 0; face < 4; ++face) {
    for (int c = 0; c < n * n * n; ++c) {
      // The cell's box in the face's coordinates, its centre and its angular radius (the
      // farthest point of a gnomonic cell from its centre is a corner).
      const int idx[3] = {c / (n * n), (c / n) % n, c % n};
      auto point = [&](const double* u) {
        Eigen::Vector4d q;
        int j = 0;
        for (int k = 0; k < 4; ++k) q[k] = k == face ? 1.0 : u[j++];
        return Eigen::Vector4d(q.normalized());
      };
      double centre_u[3];
      for (int k = 0; k < 3; ++k) centre_u[k] = -1.0 + (2.0 * idx[k] + 1.0) / n;
      const Eigen::Vector4d centre = point(centre_u);
      double radius = 0.0;
      for (int corner = 0; corner < 8; ++corner) {
        double u[3];
        for (int k = 0; k < 3; ++k) u[k] = -1.0 + 2.0 * (idx[k] + ((corner >> k) & 1)) / n;
        radius = std::max(radius, rotation_metric(centre, point(u)));
      }
      std::vector<double> d(set_.size());
      double nearest = 10.0;
      for (std::size_t i = 0; i < set_.size(); ++i) {
        d[i] = rotation_metric(centre, set_[i]);
        nearest = std::min(nearest, d[i]);
      }
      auto& list = lists[static_cast<std::size_t>(face * n * n * n + c)];
      for (std::size_t i = 0; i < set_.size(); ++i) {
        if (d[i] <= nearest + 2.0 * radius + 1e-9) list.push_back(static_cast<int>(i));
      }
    }
  }
  unique_.assign(static_cast<std::size_t>(cells), -1);
  for (int cell = 0; cell < cells; ++cell) {
    const auto& list = lists[static_cast<std::size_t>(cell)];
    if (list.size() == 1) unique_[static_cast<std::size_t>(cell)] = list.front();
    offsets_[static_cast<std::size_t>(cell) + 1] =
        offsets_[static_cast<std::size_t>(cell)] + static_cast<int>(list.size());
    candidates_.insert(candidates_.end(), list.begin(), list.end());
  }
}

int OrientationIndex::nearest(const Eigen::Quaterniond& rotation) const {
  const Eigen::Vector4d q(rotation.w(), rotation.x(), rotation.y(), rotation.z());
  const int cell = orientation_cell(q, n_);
  const int unique = unique_[static_cast<std::size_t>(cell)];
  if (unique >= 0) return unique;  // most cells: one possible answer, no dot product
  int best = 0;
  double best_dot = -1.0;
  const int end = offsets_[static_cast<std::size_t>(cell) + 1];
  for (int k = offsets_[static_cast<std::size_t>(cell)]; k < end; ++k) {
    const int i = candidates_[static_cast<std::size_t>(k)];
    const double d = std::abs(set_[static_cast<std::size_t>(i)].dot(q));
    best = d > best_dot ? i : best;  // strictly greater: the lowest index wins ties
    best_dot = std::max(best_dot, d);
  }
  return best;
}

double OrientationIndex::mean_candidates() const {
  return offsets_.size() > 1
             ? static_cast<double>(candidates_.size()) / static_cast<double>(offsets_.size() - 1)
             : 0.0;
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
  return ((static_cast<std::size_t>(orientation) * static_cast<std::size_t>(dims_.x()) +
           static_cast<std::size_t>(node.x())) *
              static_cast<std::size_t>(dims_.y()) +
          static_cast<std::size_t>(node.y())) *
             static_cast<std::size_t>(dims_.z()) +
         static_cast<std::size_t>(node.z());
}

namespace {

// Node-major (database) index of bin (cell, o) <-> orientation-major (memory) index.
template <typename Fn>
void for_each_bin(const Eigen::Vector3i& dims, std::size_t orientations, Fn&& fn) {
  const auto cells = static_cast<std::size_t>(dims.prod());
  for (std::size_t cell = 0; cell < cells; ++cell) {
    for (std::size_t o = 0; o < orientations; ++o) fn(cell * orientations + o, o * cells + cell);
  }
}

}  // namespace

std::vector<std::uint8_t> ComfortMap::values() const {
  std::vector<std::uint8_t> out(values_.size());
  for_each_bin(dims_, orientations_.size(),
               [&](std::size_t db, std::size_t mem) { out[db] = values_[mem]; });
  return out;
}

long ComfortMap::filled_bins() const {
  long n = 0;
  for (const auto v : values_) n += v > 0 ? 1 : 0;
  return n;
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
  const int o = orientation_index_.nearest(Eigen::Quaterniond(hand.linear()));
  const Eigen::Vector3d g = (hand.translation() - origin_) / spacing_;
  Eigen::Vector3i base;
  Eigen::Vector3d t;
  for (int k = 0; k < 3; ++k) {
    if (!(g[k] >= 0.0 && g[k] <= dims_[k] - 1)) return 0.0;  // outside the grid: out of reach
    base[k] = std::min(static_cast<int>(g[k]), dims_[k] - 2);
    t[k] = g[k] - base[k];
  }
  // Orientation-major layout: z neighbours adjacent, then y, then x.
  const std::size_t sz = 1;
  const auto sy = static_cast<std::size_t>(dims_.z());
  const std::size_t sx = sy * static_cast<std::size_t>(dims_.y());
  const std::uint8_t* p = values_.data() + index(base, o);
  const double x0 = (1.0 - t.z()) * p[0] + t.z() * p[sz];
  const double x1 = (1.0 - t.z()) * p[sy] + t.z() * p[sy + sz];
  const double x2 = (1.0 - t.z()) * p[sx] + t.z() * p[sx + sz];
  const double x3 = (1.0 - t.z()) * p[sx + sy] + t.z() * p[sx + sy + sz];
  const double y0 = (1.0 - t.y()) * x0 + t.y() * x1;
  const double y1 = (1.0 - t.y()) * x2 + t.y() * x3;
  return ((1.0 - t.x()) * y0 + t.x() * y1) * (1.0 / 255.0);
}

ComfortMap ComfortMap::from_grid(const Eigen::Vector3d& origin, double spacing,
                                 const Eigen::Vector3i& dims,
                                 std::vector<Eigen::Quaterniond> orientations,
                                 const std::vector<std::uint8_t>& node_major_values,
                                 double coverage) {
  if (dims.minCoeff() < 2 || !(spacing > 0.0) || orientations.empty() ||
      node_major_values.size() !=
          static_cast<std::size_t>(dims.prod()) * orientations.size()) {
    throw std::invalid_argument(
        "ComfortMap::from_grid: expected at least 2 nodes per axis, a positive spacing and "
        "dims.prod() * orientations bins");
  }
  ComfortMap map;
  map.origin_ = origin;
  map.spacing_ = spacing;
  map.dims_ = dims;
  map.orientations_ = std::move(orientations);
  map.orientation_index_ = OrientationIndex(map.orientations_);
  map.values_.assign(node_major_values.size(), 0);
  for_each_bin(map.dims_, map.orientations_.size(),
               [&](std::size_t db, std::size_t mem) { map.values_[mem] = node_major_values[db]; });
  map.coverage_ = coverage;
  return map;
}

ComfortMap ComfortMap::build(const core::KinematicChain& arm, const ComfortMapSettings& settings) {
  ComfortMap map;
  map.spacing_ = settings.spacing;
  map.orientations_ = spread_orientations(settings.orientations);
  map.orientation_index_ = OrientationIndex(map.orientations_);
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
    const int o = map.orientation_index_.nearest(Eigen::Quaterniond(tip.linear()));
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

}  // namespace hila::core
