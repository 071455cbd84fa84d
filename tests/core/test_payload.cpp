#include <gtest/gtest.h>

#include <string>

#include "hila/core/cell.hpp"
#include "hila/core/payload.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

core::PayloadSpec ur3(double allowed) {
  core::PayloadSpec p;
  p.stated = true;
  p.rated = 3.0;
  p.allowed = allowed;
  p.tooling = {{"ft300", 0.300, Eigen::Vector3d::Zero()},
               {"coupling", 0.075, Eigen::Vector3d::Zero()},
               {"robotiq_2f85", 0.925, Eigen::Vector3d::Zero()}};
  return p;
}

}  // namespace

// The reference cell states the UR3's rated 3.0 kg, the 1.30 kg of tooling of the FT300, its
// coupling and the 2F-85 (their datasheets), the suction tool's 0.25 kg, and allows 3.5 kg.
TEST(Payload, TheReferenceCellStatesItsArmsPayloads) {
  const auto cell = test::reference_cell();
  for (const auto& arm : cell->arms()) {
    SCOPED_TRACE(arm.spec.name);
    EXPECT_TRUE(arm.spec.payload.stated);
    EXPECT_DOUBLE_EQ(arm.spec.payload.rated, 3.0);
    EXPECT_DOUBLE_EQ(arm.spec.payload.allowed, 3.5);
    EXPECT_NEAR(arm.spec.payload.tooling_mass(), 0.300 + 0.075 + 0.925, 1e-12);
  }
  EXPECT_DOUBLE_EQ(cell->spec().suction.mass, 0.25);
}

// Sums by hand: a 2.4 kg panel on the suction tool and in the jaws, a 1.8 kg cabinet lateral,
// a 0.15 kg bracket.
TEST(Payload, SumsThePartTheToolingAndTheTool) {
  const auto panel_cup =
      core::check_payload("right", ur3(3.0), 2.4, core::CarryMode::kSuction, 0.25);
  EXPECT_NEAR(panel_cup.total(), 2.4 + 1.3 + 0.25, 1e-12);
  EXPECT_FALSE(panel_cup.within_allowed());
  EXPECT_EQ(panel_cup.describe(),
            "part 2.40 kg + tooling 1.30 kg + suction tool 0.25 kg = 3.95 kg > 3.00 kg allowed at "
            "arm 'right'");
  const auto panel_jaws =
      core::check_payload("left", ur3(3.0), 2.4, core::CarryMode::kGripper, 0.25);
  EXPECT_NEAR(panel_jaws.total(), 3.7, 1e-12);
  EXPECT_FALSE(panel_jaws.within_allowed());
  EXPECT_EQ(panel_jaws.describe(),
            "part 2.40 kg + tooling 1.30 kg = 3.70 kg > 3.00 kg allowed at arm 'left'");

  // The paper's lateral: over the rated 3.0 kg either way, within the reference cell's 3.5 kg.
  const auto lateral = core::check_payload("right", ur3(3.5), 1.8, core::CarryMode::kSuction, 0.25);
  EXPECT_TRUE(lateral.within_allowed());
  EXPECT_FALSE(lateral.within_rated());
  EXPECT_EQ(lateral.describe(),
            "part 1.80 kg + tooling 1.30 kg + suction tool 0.25 kg = 3.35 kg <= 3.50 kg allowed at "
            "arm 'right' (rated 3.00 kg)");
  const auto bracket = core::check_payload("left", ur3(3.0), 0.15, core::CarryMode::kGripper, 0.25);
  EXPECT_TRUE(bracket.within_rated());
  EXPECT_TRUE(bracket.within_allowed());

  // Exactly at the limit is within it.
  EXPECT_TRUE(
      core::check_payload("left", ur3(3.0), 1.7, core::CarryMode::kGripper, 0.25).within_allowed());
  // No payload stated: nothing is checked.
  const auto unstated =
      core::check_payload("left", core::PayloadSpec{}, 50.0, core::CarryMode::kGripper, 0.25);
  EXPECT_TRUE(unstated.within_allowed());
  EXPECT_EQ(unstated.describe(), "no payload stated for arm 'left'");
}
