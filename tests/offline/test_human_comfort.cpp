#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "hila/core/comfort.hpp"
#include "hila/core/generic_ik.hpp"
#include "hila/core/robot_model.hpp"
#include "hila/offline/human_comfort.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

std::vector<core::ComfortMap> maps(long samples) {
  std::vector<core::ComfortMap> out;
  core::ComfortMapSettings s;
  s.samples = samples;
  for (const auto& arm : test::reference_cell()->human_arms()) {
    out.push_back(core::ComfortMap::build(arm.chain, s));
  }
  return out;
}

}  // namespace

TEST(HumanComfort, CellHumanLookupEqualsTheMapInTheArmBaseFrame) {
  const auto cell = test::reference_cell();
  const offline::HumanComfort comfort(*cell, maps(20000));
  std::mt19937_64 rng(5);
  for (int arm = 0; arm < comfort.arm_count(); ++arm) {
    const auto& chain = cell->human_arms()[static_cast<std::size_t>(arm)].chain;
    for (int i = 0; i < 50; ++i) {
      const core::Pose local = chain.fk(core::random_configuration(chain, rng));
      const core::Pose world = comfort.arm_base(arm) * local;
      EXPECT_NEAR(comfort.quality(arm, world), comfort.map(arm).lookup(local), 1e-9);
    }
  }
}

// Another stature served by the cell human's map (scaled about the shoulder) against direct IK
// of that body's own arm, generated independently: the same error bound as the map itself.
TEST(HumanComfort, OtherBodiesMatchDirectIkOfTheirOwnArms) {
  const auto cell = test::reference_cell();
  const std::vector<core::HumanBodySpec> bodies = {{1.50, core::Sex::Female},
                                                   {1.88, core::Sex::Male}};
  const offline::HumanComfort comfort(*cell, maps(3000000), bodies);
  std::mt19937_64 rng(8);
  for (int b = 0; b < 2; ++b) {
    const auto model = core::RobotModel::load_urdf_string(
        core::generate_human_urdf(bodies[static_cast<std::size_t>(b)]), "body");
    std::vector<core::Pose> links;
    model.link_poses(cell->human_neutral(), links);
    const int arm = 1;  // right
    const auto& spec = cell->human_arms()[arm].spec;
    const core::KinematicChain chain(model, spec.base_link, spec.tip_link);
    const core::Pose base = cell->spec().human_stance *
                            links[static_cast<std::size_t>(model.link_index(spec.base_link))];
    double error = 0.0;
    const int n = 60;
    for (int i = 0; i < n; ++i) {
      const Eigen::VectorXd q = core::random_configuration(chain, rng);
      const core::Pose hand = base * chain.fk(q);
      const auto direct = core::best_comfort(chain, base.inverse() * hand, q);
      ASSERT_TRUE(direct.reachable);
      error += std::abs(comfort.body_quality(b, arm, hand) - direct.quality);
    }
    EXPECT_LE(error / n, 0.05) << "body " << b;
  }
  // A short body cannot reach where a tall one can: 1.88 m at full stretch forward and up.
  const auto& chain = cell->human_arms()[1].chain;
  Eigen::VectorXd stretched = Eigen::VectorXd::Zero(chain.dof());
  stretched[0] = core::deg_to_rad(150.0);  // arm raised forward
  const core::Pose tall_base = [&] {
    const auto model =
        core::RobotModel::load_urdf_string(core::generate_human_urdf(bodies[1]), "b");
    std::vector<core::Pose> links;
    model.link_poses(cell->human_neutral(), links);
    return cell->spec().human_stance *
           links[static_cast<std::size_t>(model.link_index(cell->human_arms()[1].spec.base_link))];
  }();
  const auto tall_model =
      core::RobotModel::load_urdf_string(core::generate_human_urdf(bodies[1]), "tall");
  const core::KinematicChain tall(tall_model, cell->human_arms()[1].spec.base_link,
                                  cell->human_arms()[1].spec.tip_link);
  const core::Pose far_up = tall_base * tall.fk(stretched);
  EXPECT_EQ(comfort.body_quality(0, 1, far_up), 0.0);
  EXPECT_GT(comfort.body_quality(1, 1, far_up), 0.0);  // the tall body's own reach
}

TEST(HumanComfort, BodySetsParseAndRejectBadItems) {
  const auto bodies = offline::parse_human_bodies("1.50:female,1.722,1.88:male", "--bodies");
  ASSERT_EQ(bodies.size(), 3u);
  EXPECT_EQ(bodies[0].sex, core::Sex::Female);
  EXPECT_DOUBLE_EQ(bodies[1].stature, 1.722);
  EXPECT_EQ(offline::format_human_bodies(bodies), "1.5 female; 1.722 male; 1.88 male");
  test::expect_input_error([] { offline::parse_human_bodies("1.7:robot", "--bodies"); },
                           {"--bodies", "sex", "robot"});
  test::expect_input_error([] { offline::parse_human_bodies("1722", "--bodies"); },
                           {"command line: --bodies:", "stature", "[1.3, 2.2]", "'1722'",
                            "got 1722 (millimetres given as metres?)"});
  test::expect_input_error([] { offline::parse_human_bodies("1.5:female,1.29", "--workers"); },
                           {"--workers", "stature", "'1.29'", "got 1.29"});
  test::expect_input_error([] { offline::parse_human_bodies("1.5:female,,1.8", "--workers"); },
                           {"--workers", "STATURE[:SEX]", "got ''"});
  test::expect_input_error([] { offline::parse_human_bodies("tall", "--bodies"); },
                           {"--bodies", "tall"});
  // A goal's bodies are bits of a 32-bit mask: 32 bodies, not 33.
  std::string many;
  for (int i = 0; i < 33; ++i) many += i == 0 ? "1.7" : ",1.7";
  test::expect_input_error([&] { offline::parse_human_bodies(many, "--bodies"); },
                           {"--bodies", "at most 32 bodies", "33"});
  EXPECT_EQ(offline::parse_human_bodies(many.substr(4), "--bodies").size(), 32u);
}

// The stored form (meta.human_bodies) reads back as the set it was written from; an item that is
// not "STATURE SEX" names the database and the field.
TEST(HumanComfort, StoredBodySetsReadBack) {
  const auto bodies = offline::parse_human_bodies("1.50:female,1.722,1.95:male", "--bodies");
  const std::string stored = offline::format_human_bodies(bodies);
  const auto back = offline::parse_stored_human_bodies(stored, "cab.hila");
  ASSERT_EQ(back.size(), bodies.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].stature, bodies[i].stature) << i;
    EXPECT_EQ(back[i].sex, bodies[i].sex) << i;
  }
  EXPECT_EQ(offline::format_human_bodies(back), stored);
  test::expect_input_error(
      [] { offline::parse_stored_human_bodies("1.5 female; 1.8", "cab.hila"); },
      {"cab.hila: meta.human_bodies:", "sex", "got ''"});
  test::expect_input_error([] { offline::parse_stored_human_bodies("1.5:female", "cab.hila"); },
                           {"cab.hila: meta.human_bodies:", "'1.5:female'"});
  test::expect_input_error([] { offline::parse_stored_human_bodies("", "cab.hila"); },
                           {"meta.human_bodies", "at least one"});
}
