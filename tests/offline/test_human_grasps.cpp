#include <gtest/gtest.h>

#include "hila/core/mesh.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/offline/human_grasps.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {
std::vector<db::HumanGraspRecord> plan(const std::string& file, double mass) {
  const auto mesh = core::load_mesh(test::data_path("cabinet/" + file), 0.001);
  const auto analysis = offline::analyze_part(file, mesh, mass);
  return offline::plan_human_grasps(mesh, analysis, mass, *test::reference_cell(), {});
}
}  // namespace

TEST(HumanGrasps, BoardsGetEdgePinchesInsideTheHandsAperture) {
  const auto& hand = test::reference_cell()->spec().human_hand;
  for (const auto& [file, mass] :
       {std::pair{"shelf.stl", 0.8}, std::pair{"back_panel.stl", 0.22}}) {
    const auto grasps = plan(file, mass);
    ASSERT_FALSE(grasps.empty()) << file;
    for (const auto& g : grasps) {
      EXPECT_LE(g.aperture, hand.aperture_max);
      EXPECT_NEAR((g.contact_2 - g.contact_1).norm(), g.aperture, 1e-9);
      EXPECT_TRUE(core::is_valid_pose(g.hand, 1e-9));
    }
  }
}

TEST(HumanGrasps, HeavyBoardsNeedTwoHandsLightOnesDoNot) {
  // The 1.8 kg lateral: no one-hand grasp; the 0.22 kg back panel: most grasps hold one-handed.
  int heavy_one_hand = 0;
  for (const auto& g : plan("lateral.stl", 1.8)) heavy_one_hand += g.one_hand_stable;
  EXPECT_EQ(heavy_one_hand, 0);
  const auto light = plan("back_panel.stl", 0.22);
  int light_one_hand = 0;
  for (const auto& g : light) light_one_hand += g.one_hand_stable;
  EXPECT_GT(light_one_hand, static_cast<int>(light.size()) / 2);
}

TEST(HumanGrasps, OneHandPredicateAgainstHandWorkedSoftFingerNumbers) {
  const auto& hand = test::reference_cell()->spec().human_hand;
  const core::SoftFingerPad skin{hand.pad.friction, hand.pad.elastic_modulus, hand.pad.thickness,
                                 hand.pad.radius_1, hand.pad.radius_2};
  const double e = core::winkler_eccentricity(skin, hand.grip_force);
  // Largest lever one hand holds for mass m: (m g/2)^2 + (m g r/2)^2/e^2 = (mu P)^2.
  const double m = 0.5, g = 9.81;
  const double mu_p = hand.pad.friction * hand.grip_force;
  const double r_max = e * std::sqrt(mu_p * mu_p - 0.25 * m * g * m * g) / (0.5 * m * g);
  EXPECT_TRUE(offline::one_hand_holds(hand, m, g, 0.999 * r_max));
  EXPECT_FALSE(offline::one_hand_holds(hand, m, g, 1.001 * r_max));
}
