#include "hila/core/mesh_symmetry.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "hila/core/pose.hpp"

namespace hila::core {

namespace {

// The vertices by grid cell of side `cell`: each vertex's neighbours lie in the 27 cells around.
class VertexGrid {
 public:
  VertexGrid(const std::vector<Eigen::Vector3d>& points, double cell)
      : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[key(cell_of(points[i]))].push_back(i);
  }
  bool has_near(const Eigen::Vector3d& p, double tolerance) const {
    const Eigen::Vector3i c = cell_of(p);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (const std::size_t i : it->second) {
            if ((points_[i] - p).norm() <= tolerance) return true;
          }
        }
      }
    }
    return false;
  }

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const {
    return (p / cell_).array().floor().cast<int>();
  }
  static std::int64_t key(const Eigen::Vector3i& c) {
    return (static_cast<std::int64_t>(c.x()) * 73856093) ^
           (static_cast<std::int64_t>(c.y()) * 19349663) ^
           (static_cast<std::int64_t>(c.z()) * 83492791);
  }
  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
};

}  // namespace

std::vector<Eigen::Matrix3d> mesh_symmetries(const TriangleMesh& mesh, double tolerance) {
  std::vector<Eigen::Matrix3d> out{Eigen::Matrix3d::Identity()};
  if (mesh.vertices.size() < 2 || !(tolerance > 0.0)) return out;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& v : mesh.vertices) centroid += v;
  centroid /= static_cast<double>(mesh.vertices.size());
  std::vector<Eigen::Vector3d> centred;
  centred.reserve(mesh.vertices.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& v : mesh.vertices) {
    centred.push_back(v - centroid);
    covariance += centred.back() * centred.back().transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance);
  Eigen::Matrix3d axes = eigen.eigenvectors();
  if (axes.determinant() < 0.0) axes.col(0) = -axes.col(0);
  const VertexGrid grid(centred, tolerance);
  // The signed permutations with determinant +1, in the principal frame.
  constexpr std::array<std::array<int, 3>, 6> kPermutations{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (const auto& p : kPermutations) {
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d s = Eigen::Matrix3d::Zero();
      for (int row = 0; row < 3; ++row)
        s(row, p[static_cast<std::size_t>(row)]) = (signs >> row) & 1 ? -1.0 : 1.0;
      if (s.determinant() < 0.0 || s.isIdentity()) continue;
      const Eigen::Matrix3d r = axes * s * axes.transpose();
      bool maps = true;
      for (std::size_t i = 0; maps && i < centred.size(); ++i) {
        maps = grid.has_near(r * centred[i], tolerance);
      }
      if (maps) out.push_back(r);
    }
  }
  return out;
}

double least_rotation_angle_deg(const Eigen::Matrix3d& from, const Eigen::Matrix3d& to,
                                const std::vector<Eigen::Matrix3d>& symmetries) {
  double least = rad_to_deg(Eigen::AngleAxisd(from.transpose() * to).angle());
  for (const auto& r : symmetries) {
    least = std::min(least, rad_to_deg(Eigen::AngleAxisd((from * r).transpose() * to).angle()));
  }
  return least;
}

}  // namespace hila::core
