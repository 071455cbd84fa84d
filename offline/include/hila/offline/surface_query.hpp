#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "hila/core/mesh.hpp"

namespace hila::offline {

struct SurfacePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // outward face normal, unit
  int triangle = -1;
};

// Ray shooting and surface sampling on a closed part mesh (CGAL AABB tree over its triangles).
// Const after construction: safe to share between threads. Normals come from the triangles'
// winding, so build it from an outward-oriented mesh (PartAnalysis::mesh). Throws
// std::invalid_argument for non-finite vertices or vertex indices out of range; an empty mesh
// gives no hits, no samples and no inside points.
class SurfaceQuery {
 public:
  explicit SurfaceQuery(const core::TriangleMesh& mesh);
  ~SurfaceQuery();
  SurfaceQuery(SurfaceQuery&&) noexcept;
  SurfaceQuery& operator=(SurfaceQuery&&) noexcept;

  // The first surface point hit by the ray origin + t * direction, t > min_distance (a triangle
  // containing origin + min_distance * direction exactly is skipped). nullopt for a miss, a zero
  // or non-finite direction.
  std::optional<SurfacePoint> first_hit(const Eigen::Vector3d& origin,
                                        const Eigen::Vector3d& direction,
                                        double min_distance = 0.0) const;

  // `count` points uniformly distributed by area, deterministic for a given seed (the same on
  // every platform: std::mt19937_64 and no std distributions). Empty for count <= 0.
  std::vector<SurfacePoint> sample_uniform(int count, std::uint64_t seed) const;

  // Signed distance sign: is the point inside the closed mesh? Points on the surface are not.
  bool inside(const Eigen::Vector3d& point) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hila::offline
