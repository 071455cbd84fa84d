#include <gtest/gtest.h>

#include "hila/core/mesh.hpp"
#include "hila/offline/suction_grasps.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {
std::vector<db::SuctionGraspRecord> plan(const core::TriangleMesh& mesh, double mass,
                                         offline::PartAnalysis* out = nullptr) {
  const auto analysis = offline::analyze_part("part", mesh, mass);
  if (out) *out = analysis;
  return offline::plan_suction_grasps(mesh, analysis, mass, *test::reference_cell(), {});
}
}  // namespace

TEST(SuctionGrasps, CupAtTheCentreOfMassOnBothLargeFacesOfABoard) {
  const auto mesh = core::load_mesh(test::data_path("cabinet/lateral.stl"), 0.001);
  offline::PartAnalysis analysis;
  const auto grasps = plan(mesh, 1.8, &analysis);
  ASSERT_EQ(grasps.size(), 2u * 12u);  // two large faces x 12 tool rotations
  const auto& suction = test::reference_cell()->spec().suction;
  for (const auto& g : grasps) {
    // On a face (z = +-5 mm), right above/below the CoM, pressing into the part.
    EXPECT_NEAR(std::abs(g.cup.translation().z()), 0.005, 1e-9);
    EXPECT_NEAR(g.cup.translation().head<2>().norm(), 0.0, 1e-9);
    EXPECT_NEAR(g.cup.linear().col(2).dot(-g.cup.translation().normalized()), 1.0, 1e-9);
    EXPECT_TRUE(core::is_valid_pose(g.cup, 1e-9));
    // Margins as the holding check defines them.
    EXPECT_NEAR(g.force_margin, suction.max_force - 1.8 * 9.81, 1e-9);
    EXPECT_NEAR(g.moment_margin, suction.max_moment - 1.8 * 9.81 * 0.005, 1e-9);
  }
  // Rotations in 30 degree steps about the normal.
  EXPECT_NEAR(grasps[1].rotation_deg - grasps[0].rotation_deg, 30.0, 1e-9);
}

TEST(SuctionGrasps, TooHeavyForTheCupHasNoGrasp) {
  // 5 kg pulls 49 N on a 40 N cup.
  EXPECT_TRUE(plan(core::make_box_mesh({0.4, 0.3, 0.01}), 5.0).empty());
}

TEST(SuctionGrasps, NoFaceLargeEnoughForTheCup) {
  // A 30 mm cube: every face is smaller than the 40 mm cup.
  EXPECT_TRUE(plan(core::make_box_mesh({0.03, 0.03, 0.03}), 0.05).empty());
}

TEST(SuctionGrasps, MomentLimitRejectsAThickBlock) {
  // CoM 0.2 m behind the face of a 0.4 m cube of 1 kg: 1.96 N m > 0.8 N m.
  EXPECT_TRUE(plan(core::make_box_mesh({0.4, 0.4, 0.4}), 1.0).empty());
}
