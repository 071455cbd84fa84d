#include <gtest/gtest.h>

#include <set>

#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

const core::ProductSpec& cabinet() {
  static const core::ProductSpec product = core::load_product(test::product_path());
  return product;
}

}  // namespace

// Every part but the one handled is either finished (at its target) or still stacked (at its
// initial pose), whatever the stage.
TEST(StageScene, EveryOtherPartIsFinishedOrStillStacked) {
  const auto& product = cabinet();
  for (std::size_t k = 0; k < product.parts.size(); ++k) {
    std::set<std::string> seen;
    for (const auto& p : core::parts_before(product, k)) {
      EXPECT_TRUE(p.pose.isApprox(product.target_in_world(product.part(p.name))));
      EXPECT_TRUE(seen.insert(p.name).second) << p.name;
    }
    for (const auto& p : core::parts_after(product, k)) {
      EXPECT_TRUE(p.pose.isApprox(product.part(p.name).initial));
      EXPECT_TRUE(seen.insert(p.name).second) << p.name;
    }
    EXPECT_EQ(seen.count(product.parts[k].name), 0u);
    EXPECT_EQ(seen.size() + 1, product.parts.size()) << "stage " << k;
  }
}

// The stack is in the stage's collision scene: the board being handled, put where the next
// board down lies, meets it there (and only where the stack is given).
TEST(StageScene, TheStackUnderTheBoardIsAnObstacle) {
  const auto cell = test::reference_cell();
  const auto& product = cabinet();
  const core::PartSpec& base = product.parts.front();
  const core::PartSpec& next = product.parts[1];
  const auto check = [&](const std::vector<core::PlacedPart>& stacked, core::CollisionPair& pair) {
    core::StageScene scene = core::build_stage_scene(*cell, base.mesh, {}, "right", stacked);
    core::CollisionData data(scene.cell.model);
    data.set_body_pose(scene.board, next.initial);
    return core::in_collision(scene.cell.model, data, {scene.board}, &pair);
  };
  core::CollisionPair pair;
  const auto stacked = core::parts_after(product, 0);
  ASSERT_TRUE(check(stacked, pair));
  const core::StageScene scene = core::build_stage_scene(*cell, base.mesh, {}, "right", stacked);
  ASSERT_EQ(scene.stacked.size(), product.parts.size() - 1);
  const std::string other =
      scene.cell.model.body_name(pair.body_a == scene.board ? pair.body_b : pair.body_a);
  EXPECT_EQ(other.rfind("stack/", 0), 0u) << other;
  for (const int b : scene.stacked) EXPECT_TRUE(scene.cell.model.is_static(b));
  // Without the stack the same pose is clear (above the table).
  EXPECT_FALSE(check({}, pair)) << scene.cell.model.body_name(pair.body_a) << " vs "
                                << scene.cell.model.body_name(pair.body_b);
}
