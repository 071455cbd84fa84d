#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <thread>

#include "hila/core/error.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;
namespace fs = std::filesystem;

namespace {

// Smaller sampling keeps the suite quick; the bundled defaults are exercised by the demo/bench.
offline::BuildSettings quick_settings(std::uint64_t seed = 7, int jobs = 1) {
  return test::quick_build_settings(seed, jobs);
}

std::string build(const std::string& dir, const std::string& name,
                  const offline::BuildSettings& s) {
  const std::string out = dir + "/" + name;
  offline::build_database(test::product_path(), test::cell_path(), out, s);
  return out;
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A copy of the cabinet product in `dir` with one line replaced (meshes referenced absolutely).
std::string product_variant(const std::string& dir, const std::string& from,
                            const std::string& to) {
  std::string text = test::read_file(test::product_path());
  for (const char* mesh : {"shelf.stl", "lateral.stl", "back_panel.stl"}) {
    const std::string rel = std::string("mesh: ") + mesh;
    for (auto at = text.find(rel); at != std::string::npos; at = text.find(rel, at + 1)) {
      text.replace(at, rel.size(), "mesh: " + test::data_path(std::string("cabinet/") + mesh));
    }
  }
  if (!from.empty()) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  return test::write_file(dir, "product.yaml", text);
}

}  // namespace

TEST(Build, CabinetDatabaseHoldsEveryBoardWithGraspsOfEachKind) {
  const std::string dir = test::temp_dir("build_cabinet");
  const std::string out = build(dir, "cabinet.hila", quick_settings());
  const auto database = db::Database::open(out);
  ASSERT_EQ(database.parts().size(), 7u);
  EXPECT_EQ(database.meta().product_name, "cabinet");
  EXPECT_EQ(database.meta().seed, 7u);
  for (const auto& part : database.parts()) {
    EXPECT_FALSE(database.robot_grasps(part.id).empty()) << part.name;
    EXPECT_EQ(database.suction_grasps(part.id).size(), 24u) << part.name;
    EXPECT_FALSE(database.human_grasps(part.id).empty()) << part.name;
    EXPECT_FALSE(database.placements(part.id).empty()) << part.name;
    EXPECT_NEAR(part.mass_properties.volume, part.extent.prod(), 1e-12) << part.name;
  }
  EXPECT_EQ(database.meta().cell_hash, offline::cell_hash(core::load_cell_spec(test::cell_path())));
  // One comfort map per human arm, equal to one built directly with the same settings and seed.
  ASSERT_EQ(database.comfort_maps().size(), 2u);
  const auto cell = test::reference_cell();
  core::ComfortMapSettings comfort = quick_settings().comfort;
  comfort.seed = offline::part_seed(7, "comfort:right", 3);
  const auto direct = core::ComfortMap::build(cell->human_arms()[1].chain, comfort);
  EXPECT_EQ(database.comfort_map("right").values, direct.values());
  EXPECT_EQ(database.comfort_map("right").dims, direct.dims());
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"cabinet.hila"}));  // no temporary left
}

TEST(Build, HandoverStagesGoalsAndErgonomicsAreStoredForEveryBoard) {
  const std::string dir = test::temp_dir("build_handover");
  offline::BuildSettings settings = quick_settings();
  settings.comfort.spacing = 0.03;
  settings.comfort.orientations = 128;
  settings.comfort.samples = 400000;
  settings.human_bodies = {{1.60, core::Sex::Female}, {1.80, core::Sex::Male}};
  settings.handover.body_candidates = 30;
  const auto summary =
      offline::build_database(test::product_path(), test::cell_path(), dir + "/c.hila", settings);
  const auto database = db::Database::open(dir + "/c.hila");
  EXPECT_EQ(database.meta().human_bodies, "1.6 female; 1.8 male");
  int with_goals = 0;
  int goals_for_body[2] = {0, 0};  // goals each body of the set takes comfortably
  for (std::size_t i = 0; i < database.parts().size(); ++i) {
    const auto& part = database.parts()[i];
    const db::HandoverStageRecord* stage = database.handover_stage(part.id);
    ASSERT_NE(stage, nullptr) << part.name;
    EXPECT_EQ(stage->finished_parts.size(), i) << part.name;  // the boards before it
    // The cell human's 60 and each body's 30, and any natural band's or thin board's more.
    EXPECT_GE(stage->candidates, 60 + 2 * 30);
    EXPECT_LE(stage->comfortable, stage->candidates);
    const auto candidates = database.handover_candidates(part.id);
    EXPECT_EQ(static_cast<int>(candidates.size()), stage->candidates);
    const auto goals = database.handover_goals(part.id);
    EXPECT_EQ(static_cast<int>(goals.size()), stage->goals);
    EXPECT_EQ(stage->failure.empty(), stage->goals > 0) << stage->failure;
    EXPECT_EQ(summary.parts[i].handover_failure, stage->failure);
    for (std::size_t r = 0; r < goals.size(); ++r) {
      EXPECT_EQ(goals[r].rank, static_cast<int>(r));
      EXPECT_LT(goals[r].bodies, 4U);  // bits of the two bodies only
      for (int b = 0; b < 2; ++b)
        goals_for_body[b] += static_cast<int>((goals[r].bodies >> b) & 1U);
      const auto id = goals[r].id;
      EXPECT_TRUE(!database.shared_grasps(id).empty() || !database.direct_grasps(id).empty() ||
                  !database.table_regrasps(id).empty() || !database.suction_deliveries(id).empty())
          << "goal " << r << " has no way";
    }
    with_goals += stage->goals > 0 ? 1 : 0;
    const auto ergonomics = database.ergonomics(part.id);
    ASSERT_EQ(ergonomics.size(), stage->goals > 0 ? 3u : 2u);
    EXPECT_EQ(ergonomics.back().method, "alone");
  }
  EXPECT_GT(with_goals, 0);
  EXPECT_GT(goals_for_body[0], 0);
  EXPECT_GT(goals_for_body[1], 0);
  EXPECT_EQ(static_cast<int>(summary.failed_parts().size()), 7 - with_goals);
}

TEST(Build, AHumanStanceInsideTheTableIsRejectedBeforeAnyWork) {
  const std::string dir = test::temp_dir("build_stance");
  const std::string path =
      test::cell_variant(dir, "stance: {xyz: [1.15, 0.0, 0.1]", "stance: {xyz: [0.70, 0.0, 0.1]");
  test::expect_input_error(
      [&] {
        offline::build_database(test::product_path(), path, dir + "/x.hila", quick_settings());
      },
      {"human.stance", "table"});
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));
}

// With the UR3's datasheet payload (3.0 kg, the reference cell's allowance of 3.5 kg taken out),
// the 1.8 kg laterals on the suction tool are over it on either arm: the build gives them no goals
// and says why for both roles; the lighter boards are unaffected.
TEST(Build, APartOverThePayloadGetsNoGoalAndTheReason) {
  const std::string dir = test::temp_dir("build_payload");
  const std::string path = test::cell_variant(dir, "        allowed_kg: 3.5\n", "");
  const offline::BuildSummary summary =
      offline::build_database(test::product_path(), path, dir + "/x.hila", quick_settings());
  for (const auto& part : summary.parts) {
    SCOPED_TRACE(part.name);
    if (part.mass > 1.45) {
      EXPECT_EQ(part.goals, 0);
      // Both roles are tried, and each arm's payload is named.
      EXPECT_EQ(part.handover_failure,
                "over the payload: part 1.80 kg + tooling 1.30 kg + suction tool 0.25 kg = 3.35 kg "
                "> 3.00 kg allowed at arm 'right'; with the roles swapped (the left arm picking by "
                "suction, the right arm receiving): over the payload: part 1.80 kg + tooling "
                "1.30 kg + suction tool 0.25 kg = 3.35 kg > 3.00 kg allowed at arm 'left'");
    } else {
      EXPECT_EQ(part.handover_failure.find("payload"), std::string::npos);
    }
  }
}

// A part laid out in front of the left arm, out of the suction arm's reach: the build's reason
// names the arm, the check and the pose, and what to change.
TEST(Build, APartOutOfTheSuctionArmsReachIsNamedWithItsPose) {
  const std::string dir = test::temp_dir("build_reach");
  const std::string product = product_variant(dir, "initial: {xyz: [0.30, -0.30, 1.0965]",
                                              "initial: {xyz: [0.30, 0.55, 1.0965]");
  // Eq. 1's candidates only (no natural band's): where the stack stood, no way serves them.
  offline::BuildSettings settings = quick_settings();
  settings.handover.natural_candidates = 0;
  const offline::BuildSummary summary =
      offline::build_database(product, test::cell_path(), dir + "/x.hila", settings);
  const auto& last = summary.parts.back();
  EXPECT_EQ(last.goals, 0);
  EXPECT_EQ(last.handover_failure.rfind(
                "the right arm cannot pick the part by suction at its initial pose (0.3, 0.55, "
                "1.0965) m with any of its ",
                0),
            0u)
      << last.handover_failure;
  EXPECT_NE(last.handover_failure.find("place the part within the right arm's reach"),
            std::string::npos);
  // The direct picks' reason names each arm and how far its grasps got.
  EXPECT_NE(last.handover_failure.find("no arm's gripper takes the part where it lies (0.3, 0.55, "
                                       "1.0965) m"),
            std::string::npos);
  EXPECT_NE(last.handover_failure.find("(the left arm: "), std::string::npos);
  EXPECT_NE(last.handover_failure.find("; the right arm: "), std::string::npos);
}

// The same part with the suction tool standing where both arms reach it: the left arm takes the
// tool and picks the part by suction, the right arm receives it (the roles swapped).
// back_upper laid on the left, where only the left arm picks it by suction. The left arm does not
// reach the tool's stand: with no relay (its search off) the part keeps no goal and the reason
// says what the swap needed; with the relay, or with the stand where both arms reach, the left arm
// picks it by suction.
TEST(Build, APartOnlyTheLeftArmReachesIsPickedByItsSuctionWhenItGetsTheTool) {
  const std::string dir = test::temp_dir("build_swap");
  // More candidates than the quick build's: the left arm's side has few comfortable ones.
  offline::BuildSettings settings = quick_settings();
  settings.handover.candidates = 500;
  settings.handover.max_candidates = 500;
  const std::string moved = product_variant(dir, "initial: {xyz: [0.30, -0.30, 1.0965]",
                                            "initial: {xyz: [0.30, 0.30, 1.0965]");
  {
    offline::BuildSettings no_relay = settings;
    no_relay.tool_relay.spacing = 0.0;  // no grid: no relay
    const offline::BuildSummary summary =
        offline::build_database(moved, test::cell_path(), dir + "/rack.hila", no_relay);
    EXPECT_FALSE(summary.tool_relay.handle);
    const auto& last = summary.parts.back();
    EXPECT_EQ(last.goals, 0);
    EXPECT_NE(last.handover_failure.find("with the left arm picking by suction it would have "),
              std::string::npos)
        << last.handover_failure;
    EXPECT_NE(last.handover_failure.find("but the left arm does not reach the suction tool on its "
                                         "stand at (0.3, -0.72, 1.229) m, and no place on the "
                                         "table serves both arms as a relay"),
              std::string::npos)
        << last.handover_failure;
  }
  {
    const offline::BuildSummary summary =
        offline::build_database(moved, test::cell_path(), dir + "/relay.hila", settings);
    ASSERT_TRUE(summary.tool_relay.handle);
    const auto& last = summary.parts.back();
    EXPECT_GT(last.goals, 0) << last.handover_failure;
    EXPECT_EQ(last.suction_arm, "left");
    const auto database = db::Database::open(dir + "/relay.hila");
    ASSERT_TRUE(database.meta().tool_relay);
    EXPECT_TRUE(database.meta().tool_relay->isApprox(*summary.tool_relay.handle, 1e-12));
  }
  std::string text = test::read_file(moved);
  const std::string rack = "suction_tool_pose: {xyz: [0.30, -0.72, 1.229]";
  ASSERT_NE(text.find(rack), std::string::npos);
  text.replace(text.find(rack), rack.size(), "suction_tool_pose: {xyz: [0.25, 0.05, 1.229]");
  const std::string product = test::write_file(dir, "product.yaml", text);
  const std::string out = dir + "/both.hila";
  const offline::BuildSummary summary =
      offline::build_database(product, test::cell_path(), out, settings);
  const auto& last = summary.parts.back();
  EXPECT_GT(last.goals, 0) << last.handover_failure;
  EXPECT_EQ(last.suction_arm, "left");
  EXPECT_EQ(summary.parts.front().suction_arm, "right");
  // Stored: the part's exchange poses hold it on the left arm's cup.
  const auto database = db::Database::open(out);
  const auto handovers = database.robot_handovers(database.part(last.name).id);
  ASSERT_FALSE(handovers.empty());
  for (const auto& h : handovers) EXPECT_EQ(h.arm, "left");
}

TEST(Build, SameSeedSameDigestForAnyNumberOfJobs) {
  const std::string dir = test::temp_dir("build_digest");
  const std::string a = build(dir, "a.hila", quick_settings(7, 1));
  const std::string b = build(dir, "b.hila", quick_settings(7, 2));
  const std::string c = build(dir, "c.hila", quick_settings(8, 2));
  EXPECT_EQ(db::content_digest(a), db::content_digest(b));
  EXPECT_NE(db::content_digest(a), db::content_digest(c));
}

TEST(Build, AFailedBuildLeavesThePreviousDatabaseUntouched) {
  const std::string dir = test::temp_dir("build_failure");
  const std::string out = build(dir, "cabinet.hila", quick_settings());
  const std::string before = db::content_digest(out);
  const std::string bad = product_variant(dir, "mass: 0.22", "mass: 0");
  test::expect_input_error(
      [&] { offline::build_database(bad, test::cell_path(), out, quick_settings()); },
      {bad, "mass", "[0.001, 25]"});
  EXPECT_EQ(db::content_digest(out), before);
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"cabinet.hila", "product.yaml"}));
}

TEST(Build, ABuildKilledMidwayLeavesThePreviousDatabaseUntouched) {
  const std::string dir = test::temp_dir("build_killed");
  const std::string out = build(dir, "cabinet.hila", quick_settings());
  const std::string before = db::content_digest(out);
  for (const int delay_ms : {5, 60, 250}) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      offline::BuildSettings slow = quick_settings(9, 1);
      slow.robot.samples = 3000;
      try {
        offline::build_database(test::product_path(), test::cell_path(), out, slow);
      } catch (...) {
      }
      _exit(0);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    // Whatever the moment, the target is the old database (or, had the child finished, a
    // complete new one): it opens and its digest is one of the two.
    const auto database = db::Database::open(out);
    EXPECT_EQ(database.parts().size(), 7u);
    if (WIFSIGNALED(status)) {
      EXPECT_EQ(db::content_digest(out), before) << delay_ms;
    }
  }
  // The killed writers' temporaries are swept by the next build.
  build(dir, "cabinet.hila", quick_settings());
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"cabinet.hila"}));
  EXPECT_EQ(db::content_digest(out), before);
}

TEST(Build, BadInputsAreClearErrors) {
  const std::string dir = test::temp_dir("build_bad");
  const std::string out = dir + "/out.hila";
  // Millimetre meshes declared as metres.
  const std::string metres = product_variant(dir, "mesh_unit: mm", "mesh_unit: m");
  test::expect_input_error(
      [&] { offline::build_database(metres, test::cell_path(), out, quick_settings()); },
      {metres, "mesh_unit", "mm"});
  // An open mesh: a box with one triangle missing.
  core::TriangleMesh open_box = core::make_box_mesh({0.3, 0.2, 0.01});
  open_box.triangles.pop_back();
  core::write_mesh(open_box, dir + "/open.obj", "obj");
  const std::string open_product = product_variant(dir, "", "");
  std::string text = test::read_file(open_product);
  const std::string first = "mesh: " + test::data_path("cabinet/shelf.stl");
  text.replace(text.find(first), first.size(), "mesh: " + dir + "/open.obj");
  text.replace(text.find("mesh_unit: mm"), 13, "mesh_unit: m");
  test::write_file(dir, "product.yaml", text);
  test::expect_input_error(
      [&] { offline::build_database(open_product, test::cell_path(), out, quick_settings()); },
      {"base", "closed"});
  // A destination folder that does not exist: refused before any work.
  test::expect_input_error(
      [&] {
        offline::build_database(test::product_path(), test::cell_path(),
                                dir + "/no/such/dir/x.hila", quick_settings());
      },
      {"no/such/dir"});
  EXPECT_FALSE(fs::exists(out));
  // Zero jobs.
  offline::BuildSettings zero = quick_settings();
  zero.jobs = 0;
  test::expect_input_error(
      [&] { offline::build_database(test::product_path(), test::cell_path(), out, zero); },
      {"--jobs"});
}

TEST(Build, PartSeedsDependOnNameAndSeedOnly) {
  EXPECT_EQ(offline::part_seed(1, "base", 1), offline::part_seed(1, "base", 1));
  EXPECT_NE(offline::part_seed(1, "base", 1), offline::part_seed(2, "base", 1));
  EXPECT_NE(offline::part_seed(1, "base", 1), offline::part_seed(1, "top", 1));
  EXPECT_NE(offline::part_seed(1, "base", 1), offline::part_seed(1, "base", 2));
}

TEST(Build, APartTooLargeForAnyGraspIsNamed) {
  const std::string dir = test::temp_dir("build_too_large");
  core::write_mesh(core::make_box_mesh({0.2, 0.2, 0.2}), dir + "/crate.obj", "obj");
  std::string text = test::read_file(product_variant(dir, "", ""));
  const std::string first = "mesh: " + test::data_path("cabinet/shelf.stl");
  text.replace(text.find(first), first.size(), "mesh: " + dir + "/crate.obj");
  text.replace(text.find("mesh_unit: mm"), 13, "mesh_unit: m");
  const std::string product = test::write_file(dir, "product.yaml", text);
  test::expect_input_error(
      [&] {
        offline::build_database(product, test::cell_path(), dir + "/x.hila", quick_settings());
      },
      {product, "base", "no collision-free antipodal grasp"});
  EXPECT_FALSE(fs::exists(dir + "/x.hila"));
}
