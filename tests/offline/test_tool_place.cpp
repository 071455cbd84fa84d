// The suction tool's relay: a place on the table both arms take the tool from and set it down at,
// for a product whose stand one arm reaches alone (the cabinet's, at y = -0.72 m, the right
// arm's).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "hila/core/collision.hpp"
#include "hila/core/generic_ik.hpp"
#include "hila/core/product.hpp"
#include "hila/offline/tool_place.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

offline::ToolRelaySettings relay_settings() {
  offline::ToolRelaySettings s;
  s.approach = 0.05;
  s.lift = 0.05;
  return s;
}

}  // namespace

// The cabinet's stand is the right arm's alone; the relay serves both arms, stands where the stand
// does (height and tilt; turned about the vertical by a quarter turn at most), and is the same on
// every call.
TEST(ToolPlace, TheCabinetsRelayServesBothArmsWhereTheStandServesOne) {
  const auto cell = test::reference_cell();
  const core::ProductSpec product = core::load_product(test::product_path());
  ASSERT_TRUE(offline::reaches_tool_stand(*cell, product, 0, "right", 0.05, 0.05));
  ASSERT_FALSE(offline::reaches_tool_stand(*cell, product, 0, "left", 0.05, 0.05));

  const offline::ToolRelay relay = offline::find_tool_relay(*cell, product, relay_settings());
  ASSERT_TRUE(relay.handle);
  EXPECT_GT(relay.places, relay.clear);
  EXPECT_GT(relay.clear, 0);
  const core::Pose& at = *relay.handle;
  EXPECT_NEAR(at.translation().z(), product.suction_tool_pose.translation().z(), 1e-12);
  // The same tilt: the handle's z axis as the stand's.
  EXPECT_TRUE(at.linear().col(2).isApprox(product.suction_tool_pose.linear().col(2), 1e-12));
  for (std::size_t i = 0; i < product.parts.size(); ++i) {
    for (const char* arm : {"left", "right"}) {
      EXPECT_TRUE(offline::reaches_tool_at(*cell, arm, at, core::parts_before(product, i),
                                           core::parts_after(product, i), 0.05, 0.05))
          << arm << " at the stage of " << product.parts[i].name;
    }
  }
  const offline::ToolRelay again = offline::find_tool_relay(*cell, product, relay_settings());
  ASSERT_TRUE(again.handle);
  EXPECT_TRUE(again.handle->isApprox(at, 0.0));
}

// Checked another way: each arm's gripper reaches the relay's handle by the numeric
// (Levenberg-Marquardt) IK of its chain, as the closed-form IK said; and the standing tool is
// clear of every part, initial and target, by FCL's narrow phase on every pair.
TEST(ToolPlace, TheRelayIsReachedByNumericIkAndClearByBruteForce) {
  const auto cell = test::reference_cell();
  const core::ProductSpec product = core::load_product(test::product_path());
  const offline::ToolRelay relay = offline::find_tool_relay(*cell, product, relay_settings());
  ASSERT_TRUE(relay.handle);
  const core::Pose tcp = *relay.handle * cell->spec().suction.handle_in_tcp.inverse();
  std::mt19937_64 rng(3);
  for (const auto& arm : cell->arms()) {
    const core::Pose target = core::arm_base_in_world(*cell, arm).inverse() * tcp;
    const core::GenericIkResult ik = core::solve_ik(arm.chain, target, arm.spec.home, rng);
    ASSERT_TRUE(ik.success) << arm.spec.name;
    EXPECT_TRUE(arm.chain.fk(ik.q).isApprox(target, 1e-8)) << arm.spec.name;
  }

  core::CollisionModel model;
  for (const auto& p : product.parts) {
    model.add_mesh_body("initial/" + p.name, p.mesh, true, p.initial);
    model.add_mesh_body("target/" + p.name, p.mesh, true, product.target_in_world(p));
  }
  const core::RobotModel& tool = cell->suction_tool();
  const core::RobotBodies bodies = core::add_robot(model, tool, "tool/");
  for (const int a : bodies.link_to_body) {
    for (const int b : bodies.link_to_body) {
      if (a >= 0 && b > a) model.allow(a, b);
    }
  }
  core::CollisionData data(model);
  std::vector<core::Pose> links;
  tool.link_poses(tool.neutral_configuration(), links);
  const core::Pose handle =
      links[static_cast<std::size_t>(tool.link_index(cell->spec().suction.handle_link))];
  core::set_robot_pose(data, bodies, links, *relay.handle * handle.inverse());
  core::CollisionPair pair;
  EXPECT_FALSE(core::in_collision_brute_force(model, data, &pair))
      << core::describe_pair(model, pair);
  // And the same tool over a part's initial pose is refused by the relay's own check: standing
  // there it touches the part.
  core::Pose on_part = *relay.handle;
  on_part.translation().head<2>() = product.parts.front().initial.translation().head<2>();
  core::set_robot_pose(data, bodies, links, on_part * handle.inverse());
  EXPECT_TRUE(core::in_collision_brute_force(model, data));
}

// A stand on no obstacle of the cell has no table to relay on: none, and nothing tried.
TEST(ToolPlace, AStandOffTheTableHasNoRelay) {
  const auto cell = test::reference_cell();
  core::ProductSpec product = core::load_product(test::product_path());
  product.suction_tool_pose.translation().x() = 5.0;
  const offline::ToolRelay relay = offline::find_tool_relay(*cell, product, relay_settings());
  EXPECT_FALSE(relay.handle);
  EXPECT_EQ(relay.places, 0);
}

// A generated product (tools/dev/gen_products --seed 1, product 19, copied to tests/data) whose
// rail, a dowel-like prism, touches the standing tool at some grid places: FCL's distance query on
// touching shapes runs its penetration code, which asserted (and aborted the build) there. Contact
// is tested first; the search completes and finds a relay clear of every part.
TEST(ToolPlace, PlacesWhereTheToolTouchesAPartAreLeftOutBeforeTheDistance) {
  const auto cell = test::reference_cell();
  const core::ProductSpec product =
      core::load_product(std::string(HILA_TEST_DATA_DIR) + "/gen1_p19_stand/product.yaml");
  const offline::ToolRelay relay = offline::find_tool_relay(*cell, product, relay_settings());
  ASSERT_TRUE(relay.handle);
  EXPECT_LT(relay.clear, relay.places);
}
