#include "hila/offline/suction_grasps.hpp"

#include <cmath>

namespace hila::offline {

std::vector<db::SuctionGraspRecord> plan_suction_grasps(const core::TriangleMesh& mesh,
                                                        const PartAnalysis& analysis, double mass,
                                                        const core::Cell& cell,
                                                        const SuctionSettings& settings) {
  const auto& suction = cell.spec().suction;
  const double weight = mass * cell.spec().gravity;
  const Eigen::Vector3d com = analysis.mass_properties.com;
  std::vector<db::SuctionGraspRecord> grasps;
  if (analysis.facets.empty()) return grasps;
  const double largest = analysis.facets.front().area;
  const double cup_area = core::kPi * suction.cup_radius * suction.cup_radius;
  for (const PlanarFacet& facet : analysis.facets) {
    if (facet.area < settings.min_area_fraction * largest || facet.area < cup_area) continue;
    // The centre of mass projected onto the face: the paper picks every board there.
    const Eigen::Vector3d cup_point = com - (facet.normal.dot(com) - facet.offset) * facet.normal;
    if (!point_inside_facet(mesh, facet, cup_point, suction.cup_radius)) continue;
    // Worst case over orientations: the full weight pulls on the cup, and the weight's moment
    // about the cup is m g |CoM - cup| when that lever is horizontal.
    const double force_margin = suction.max_force - weight;
    const double moment_margin = suction.max_moment - weight * (com - cup_point).norm();
    if (force_margin < 0.0 || moment_margin < 0.0) continue;
    const Eigen::Vector3d z = -facet.normal;  // the cup presses into the part
    Eigen::Index least = 0;
    z.cwiseAbs().minCoeff(&least);
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(least);
    const Eigen::Vector3d x0 = (e - e.dot(z) * z).normalized();
    for (int k = 0; k < settings.rotations; ++k) {
      const double angle = 2.0 * core::kPi * k / settings.rotations;
      const Eigen::Vector3d x = Eigen::AngleAxisd(angle, z) * x0;
      db::SuctionGraspRecord g;
      g.cup.linear().col(0) = x;
      g.cup.linear().col(1) = z.cross(x);
      g.cup.linear().col(2) = z;
      g.cup.translation() = cup_point;
      g.rotation_deg = core::rad_to_deg(angle);
      g.force_margin = force_margin;
      g.moment_margin = moment_margin;
      grasps.push_back(g);
    }
  }
  return grasps;
}

}  // namespace hila::offline
