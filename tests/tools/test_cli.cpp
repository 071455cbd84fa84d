// End-to-end tests of the `hila` command: real process, real files, exit codes and JSON.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "util/test_util.hpp"

using namespace hila;

namespace {

struct CommandRun {
  int status = -1;
  std::string out;  // stdout and stderr together
};

CommandRun run(const std::string& args) {
  CommandRun r;
  const std::string command = std::string(HILA_EXE) + " " + args + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.out.append(buffer.data(), n);
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

std::string json_part(const std::string& out) {
  return out.substr(out.find('{'));
}

}  // namespace

TEST(Cli, HelpListsTheSubcommands) {
  const CommandRun r = run("--help");
  EXPECT_EQ(r.status, 0);
  for (const char* sub : {"cell", "human", "mesh", "product", "build", "inspect", "plan"}) {
    EXPECT_NE(r.out.find(sub), std::string::npos) << sub;
  }
  EXPECT_EQ(run("cell check --help").status, 0);
}

TEST(Cli, CellCheckJsonReportsArmsHumanAndHome) {
  const CommandRun r = run("cell check " + test::cell_path() + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(json_part(r.out));
  ASSERT_EQ(j["arms"].size(), 2u);
  EXPECT_EQ(j["arms"][0]["name"], "left");
  EXPECT_EQ(j["arms"][0]["dof"], 6);
  EXPECT_EQ(j["arms"][0]["home_tcp"]["xyz"].size(), 3u);
  // Mirror-symmetric home poses.
  EXPECT_NEAR(j["arms"][0]["home_tcp"]["xyz"][1].get<double>(),
              -j["arms"][1]["home_tcp"]["xyz"][1].get<double>(), 1e-6);
  ASSERT_EQ(j["human_arms"].size(), 2u);
  EXPECT_EQ(j["human_arms"][0]["dof"], 7);
  EXPECT_EQ(j["home_collision_free"], true);
  // The reach is the stretched arm: upper arm + forearm + 0.4 hand of a 1.722 m male.
  EXPECT_NEAR(j["human_arms"][0]["reach"].get<double>(), (0.186 + 0.146 + 0.4 * 0.108) * 1.722,
              2e-3);
}

TEST(Cli, CellCheckWithHomeInCollisionExitsOneAndNamesThePair) {
  const std::string dir = test::temp_dir("cli_home_collision");
  std::string yaml = test::read_file(test::cell_path());
  const std::string home = "home_deg: [15, -60, -120, -180, -120, 0]";
  yaml.replace(yaml.find(home), home.size(), "home_deg: [15, 90, -120, -180, -120, 0]");
  for (const char* file : {"dual_ur3.urdf", "suction_tool.urdf", "human.urdf"}) {
    const std::string rel = std::string(" ") + file;
    const auto at = yaml.find(rel);
    yaml.replace(at, rel.size(), " " + test::data_path(std::string("cell/") + file));
  }
  const std::string cell = test::write_file(dir, "cell.yaml", yaml);
  const CommandRun r = run("cell check " + cell + " --json");
  EXPECT_EQ(r.status, 1) << r.out;
  const auto j = nlohmann::json::parse(json_part(r.out));
  EXPECT_EQ(j["home_collision_free"], false);
  EXPECT_NE(j["home_colliding_pair"].get<std::string>().find("<->"), std::string::npos);
}

TEST(Cli, BadInputGivesAClearErrorAndExitCodeTwo) {
  const CommandRun missing = run("cell check /nonexistent/cell.yaml");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.out.find("/nonexistent/cell.yaml"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("expected"), std::string::npos) << missing.out;

  const std::string dir = test::temp_dir("cli_bad");
  const std::string broken = test::write_file(dir, "cell.yaml", "robot: [unclosed\n");
  const CommandRun malformed = run("cell check " + broken);
  EXPECT_EQ(malformed.status, 2);
  EXPECT_NE(malformed.out.find("cell.yaml"), std::string::npos) << malformed.out;

  const CommandRun stature = run("human --stature 1722");
  EXPECT_EQ(stature.status, 2);
  EXPECT_NE(stature.out.find("stature"), std::string::npos) << stature.out;

  EXPECT_NE(run("human --sex other").status, 0);
  EXPECT_NE(run("no-such-command").status, 0);
}

TEST(Cli, HumanWritesALoadableUrdfAtomically) {
  const std::string dir = test::temp_dir("cli_human");
  const CommandRun r = run("human --stature 1.595 --sex female -o " + dir + "/female.urdf");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string urdf = test::read_file(dir + "/female.urdf");
  EXPECT_NE(urdf.find("left_hand_grasp"), std::string::npos);
  // An unwritable destination fails cleanly and leaves nothing behind.
  const CommandRun bad = run("human -o /nonexistent_dir/h.urdf");
  EXPECT_EQ(bad.status, 2);
}

TEST(Cli, MeshBoxAndProductCheck) {
  const std::string dir = test::temp_dir("cli_mesh");
  ASSERT_EQ(run("mesh box --size 100 50 10 --unit mm -o " + dir + "/b.stl").status, 0);
  EXPECT_FALSE(test::read_file(dir + "/b.stl").empty());
  EXPECT_NE(run("mesh box --size 100 -5 10 -o " + dir + "/c.stl").status, 0);

  const CommandRun r =
      run("product check " + test::product_path() + " --cell " + test::cell_path() + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(json_part(r.out));
  EXPECT_EQ(j["parts"].size(), 7u);
  EXPECT_EQ(j["targets_collision_free"], true);
  EXPECT_EQ(j["initial_collision_free"], true);
}

TEST(Cli, BuildThenInspectSummaryGraspsAndDigest) {
  const std::string dir = test::temp_dir("cli_build");
  const std::string out = dir + "/cabinet.hila";
  const CommandRun build = run("build " + test::product_path() + " --cell " + test::cell_path() +
                               " -o " + out + " --jobs 2");
  ASSERT_EQ(build.status, 0) << build.out;
  // Not a terminal: no progress lines, just the summary.
  EXPECT_EQ(build.out.find("\r"), std::string::npos);
  EXPECT_NE(build.out.find("lateral_right"), std::string::npos);

  const CommandRun summary = run("inspect " + out + " --json");
  ASSERT_EQ(summary.status, 0) << summary.out;
  const auto j = nlohmann::json::parse(json_part(summary.out));
  ASSERT_EQ(j["parts"].size(), 7u);
  EXPECT_EQ(j["seed"], 1);
  for (const auto& p : j["parts"]) {
    EXPECT_GT(p["robot_grasps"].get<int>(), 0) << p["name"];
    EXPECT_LE(p["theta_c_min_deg"].get<double>(), p["theta_c_max_deg"].get<double>());
  }
  // The heavy laterals are slip-constrained, the back panels are not.
  EXPECT_LT(j["parts"][1]["theta_c_min_deg"].get<double>(), 22.0);
  EXPECT_EQ(j["parts"][2]["theta_c_min_deg"].get<double>(), 90.0);

  const CommandRun grasps = run("inspect " + out + " grasps --part top --json");
  ASSERT_EQ(grasps.status, 0) << grasps.out;
  const auto g = nlohmann::json::parse(json_part(grasps.out));
  int robot = 0;
  for (const auto& row : g["grasps"]) robot += row["kind"] == "robot";
  EXPECT_EQ(robot, j["parts"][5]["robot_grasps"].get<int>());

  const CommandRun comfort = run("inspect " + out + " comfort --arm right --json");
  ASSERT_EQ(comfort.status, 0) << comfort.out;
  const auto c = nlohmann::json::parse(json_part(comfort.out));
  EXPECT_EQ(c["orientations"], 128);
  EXPECT_GT(c["filled_bins"].get<long>(), 1000);
  EXPECT_LE(c["q_max"].get<double>(), 1.0);
  EXPECT_EQ(run("inspect " + out + " comfort --arm tail").status, 2);

  // Handover goals: every board has ranked goals with shared grasps.
  for (const char* board : {"base", "lateral_right", "back_upper"}) {
    const CommandRun handover = run("inspect " + out + " handover --part " + board + " --json");
    ASSERT_EQ(handover.status, 0) << handover.out;
    const auto h = nlohmann::json::parse(json_part(handover.out));
    EXPECT_GE(h["candidates"].get<int>(), 500);  // thin boards get further batches
    EXPECT_GT(h["goals"].get<int>(), 0) << board;
    EXPECT_EQ(h["ranked_goals"].size(), h["goals"].get<std::size_t>());
    EXPECT_EQ(h["failure"], "");
    EXPECT_FALSE(h["ranked_goals"][0]["shared_grasps"].empty());
    EXPECT_TRUE(h["ranked_goals"][0]["direct_grasps"].is_array()) << "listed, even when empty";

    // The manipulation graph serves the goals the handover stage lists, by the same ways, and
    // its edges join listed nodes.
    const CommandRun graph = run("inspect " + out + " graph --part " + board + " --json");
    ASSERT_EQ(graph.status, 0) << graph.out;
    const auto gr = nlohmann::json::parse(json_part(graph.out));
    int exchange = 0, direct = 0, first_exchange = -1;
    for (const auto& goal : h["ranked_goals"]) {
      exchange += goal["shared_grasps"].empty() ? 0 : 1;
      direct += goal["direct_grasps"].empty() ? 0 : 1;
      if (first_exchange < 0 && !goal["shared_grasps"].empty()) first_exchange = goal["rank"];
    }
    const auto& graph_summary = gr["summary"];
    EXPECT_EQ(graph_summary["goals"], h["ranked_goals"].size()) << board;
    EXPECT_EQ(graph_summary["goals_exchange"], exchange) << board;
    EXPECT_EQ(graph_summary["goals_direct"], direct) << board;
    int best_exchange = -1;
    for (const auto& way : graph_summary["ways"]) {
      EXPECT_LE(way["goals"].get<int>(), way["way"] == "direct" ? direct : exchange) << way.dump();
      const int best = way["best_rank"];
      if (way["way"] == "exchange" && (best_exchange < 0 || best < best_exchange)) {
        best_exchange = best;
      }
    }
    EXPECT_EQ(best_exchange, first_exchange) << board;
    std::set<std::string> nodes;
    int goal_nodes = 0;
    for (const auto& n : gr["nodes"]) {
      EXPECT_TRUE(nodes.insert(n["id"].get<std::string>()).second) << "listed twice: " << n["id"];
      goal_nodes += n["kind"] == "goal" ? 1 : 0;
    }
    EXPECT_GE(goal_nodes, graph_summary["goals"].get<int>()) << board;
    ASSERT_FALSE(gr["edges"].empty()) << board;
    int dangling = 0, presented = 0;
    std::string first_dangling;
    for (const auto& e : gr["edges"]) {
      if (nodes.count(e["from"].get<std::string>()) && nodes.count(e["to"].get<std::string>())) {
        presented += e["kind"] == "present" ? 1 : 0;
        continue;
      }
      if (dangling++ == 0) first_dangling = e.dump();
    }
    EXPECT_EQ(dangling, 0) << board << ", e.g. " << first_dangling;
    EXPECT_EQ(presented, goal_nodes) << board << ": each goal node is presented to the human";
    // Goals connected end to end in the stored regrasp graph, as `inspect roadmap` counts them.
    const CommandRun roadmap = run("inspect " + out + " roadmap --part " + board + " --json");
    ASSERT_EQ(roadmap.status, 0) << roadmap.out;
    const auto stored = nlohmann::json::parse(json_part(roadmap.out));
    int connected = 0;
    for (const auto& goal : stored["boards"][0]["goals"]) {
      connected += goal["connected"].get<bool>() ? 1 : 0;
    }
    EXPECT_EQ(graph_summary["goals_connected_offline"], connected) << board;
  }
  const CommandRun graph_text = run("inspect " + out + " graph --part base --goals 2");
  ASSERT_EQ(graph_text.status, 0) << graph_text.out;
  EXPECT_NE(graph_text.out.find("goals in rank order (2 of "), std::string::npos) << graph_text.out;
  EXPECT_NE(graph_text.out.find("  rank 1 "), std::string::npos) << graph_text.out;
  EXPECT_EQ(graph_text.out.find("  rank 2 "), std::string::npos) << graph_text.out;
  EXPECT_NE(build.out.find("|𝕊|"), std::string::npos) << build.out;
  // The ergonomics report: hila's handover needs no forward bend wherever the human alone does.
  const CommandRun report = run("report ergonomics " + out + " --json");
  ASSERT_EQ(report.status, 0) << report.out;
  const auto e = nlohmann::json::parse(json_part(report.out));
  ASSERT_EQ(e["boards"].size(), 7u);
  int alone_bent = 0;
  for (const auto& b : e["boards"]) {
    ASSERT_TRUE(b["hila"]["reachable"].get<bool>()) << b["part"];
    EXPECT_FALSE(b["hila"]["bent_forward"].get<bool>()) << b["part"];
    if (b["alone"]["reachable"].get<bool>() && b["alone"]["bent_forward"].get<bool>()) ++alone_bent;
    EXPECT_LT(b["hila"]["reorientation_deg"].get<double>(), 45.0);
  }
  EXPECT_GT(alone_bent, 0);
  EXPECT_EQ(e["verdicts_hila_vs"]["alone"]["bent_forward"], "eliminated");
  const CommandRun report_text = run("report ergonomics " + out);
  EXPECT_NE(report_text.out.find("bent forward eliminated"), std::string::npos) << report_text.out;

  const CommandRun digest1 = run("inspect " + out + " digest");
  ASSERT_EQ(digest1.status, 0);
  EXPECT_EQ(digest1.out.size(), 65u);  // 64 hex digits and a newline
}

TEST(Cli, SameSeedSameDigestWhateverTheJobs) {
  // Sparse maps keep this quick; boards without goals (exit 1) are part of the content too.
  const std::string dir = test::temp_dir("cli_digest");
  const std::string options =
      " --cell " + test::cell_path() +
      " --seed 3 --comfort-samples 20000 --handover-candidates 60 --roadmap-nodes 300";
  const int a =
      run("build " + test::product_path() + options + " --jobs 2 -o " + dir + "/a.hila").status;
  const int b =
      run("build " + test::product_path() + options + " --jobs 1 -o " + dir + "/b.hila").status;
  EXPECT_EQ(a, b);
  EXPECT_LE(a, 1);
  const CommandRun digest1 = run("inspect " + dir + "/a.hila digest");
  ASSERT_EQ(digest1.status, 0);
  EXPECT_EQ(run("inspect " + dir + "/b.hila digest").out, digest1.out);
}

// tools/demo's --if-outdated: a database from this hila, the same files, settings and seed is
// kept untouched; another seed or a file that is not a database is rebuilt, with the reason.
TEST(Cli, BuildIfOutdatedKeepsACurrentDatabaseAndRebuildsAStaleOne) {
  const std::string dir = test::temp_dir("cli_if_outdated");
  const std::string db = dir + "/c.hila";
  const std::string options = " --cell " + test::cell_path() +
                              " --comfort-samples 20000 --handover-candidates 60"
                              " --roadmap-nodes 300 --jobs 2 -o " +
                              db + " --if-outdated";
  const CommandRun first = run("build " + test::product_path() + options + " --seed 3");
  ASSERT_LE(first.status, 1) << first.out;
  EXPECT_NE(first.out.find("it does not exist"), std::string::npos) << first.out;
  const std::string digest = run("inspect " + db + " digest").out;
  const auto written = std::filesystem::last_write_time(db);

  const CommandRun kept = run("build " + test::product_path() + options + " --seed 3");
  EXPECT_EQ(kept.status, 0) << kept.out;
  EXPECT_NE(kept.out.find("is up to date"), std::string::npos) << kept.out;
  EXPECT_EQ(std::filesystem::last_write_time(db), written);
  EXPECT_EQ(run("inspect " + db + " digest").out, digest);

  const CommandRun reseeded = run("build " + test::product_path() + options + " --seed 4");
  EXPECT_LE(reseeded.status, 1) << reseeded.out;
  EXPECT_NE(reseeded.out.find("the seed differs"), std::string::npos) << reseeded.out;
  EXPECT_NE(run("inspect " + db + " digest").out, digest);

  {
    std::ofstream garbage(db, std::ios::trunc);
    garbage << "not a database";
  }
  const CommandRun repaired = run("build " + test::product_path() + options + " --seed 3");
  EXPECT_LE(repaired.status, 1) << repaired.out;
  EXPECT_NE(repaired.out.find("cannot be used"), std::string::npos) << repaired.out;
  EXPECT_EQ(run("inspect " + db + " digest").out, digest);  // same inputs, same content
}

TEST(Cli, BuildAndInspectBadInputs) {
  const std::string dir = test::temp_dir("cli_build_bad");
  // Unknown part, foreign file, missing database, missing output folder, bad jobs.
  const std::string text_file = test::write_file(dir, "notes.hila", "not a database\n");
  const CommandRun foreign = run("inspect " + text_file);
  EXPECT_EQ(foreign.status, 2);
  EXPECT_NE(foreign.out.find("notes.hila"), std::string::npos) << foreign.out;
  const CommandRun missing = run("inspect " + dir + "/none.hila");
  EXPECT_EQ(missing.status, 2);
  EXPECT_NE(missing.out.find("none.hila"), std::string::npos) << missing.out;
  const CommandRun no_dir = run("build " + test::product_path() + " -o " + dir + "/no/dir/x.hila");
  EXPECT_EQ(no_dir.status, 2);
  EXPECT_NE(no_dir.out.find("no/dir"), std::string::npos) << no_dir.out;
  EXPECT_NE(run("build " + test::product_path() + " -o " + dir + "/x.hila --jobs 0").status, 0);
  // No board can be comfortable at Q > 0.99: the build finishes every board, writes the database
  // with the reasons, names each failing board and exits 1.
  const CommandRun strict = run("build " + test::product_path() + " -o " + dir +
                                "/ok.hila --comfort-samples 20000 --handover-candidates 40 "
                                "--comfort-threshold 0.99 --roadmap-nodes 200");
  EXPECT_EQ(strict.status, 1) << strict.out;
  EXPECT_NE(strict.out.find("lateral_left: no handover goal: no candidate is comfortable"),
            std::string::npos)
      << strict.out;
  EXPECT_NE(strict.out.find("7 of 7 boards"), std::string::npos) << strict.out;
  const CommandRun failed = run("inspect " + dir + "/ok.hila handover --part top --json");
  ASSERT_EQ(failed.status, 0) << failed.out;
  const auto f = nlohmann::json::parse(json_part(failed.out));
  EXPECT_EQ(f["goals"], 0);
  EXPECT_NE(f["failure"].get<std::string>().find("threshold 0.99"), std::string::npos);
  EXPECT_NE(
      run("build " + test::product_path() + " -o " + dir + "/x.hila --comfort-threshold 2").status,
      0);
  const CommandRun part = run("inspect " + dir + "/ok.hila grasps --part drawer");
  EXPECT_EQ(part.status, 2);
  EXPECT_NE(part.out.find("drawer"), std::string::npos) << part.out;
  // The graph of an unknown part: the same error and exit status.
  const CommandRun graph_part = run("inspect " + dir + "/ok.hila graph --part drawer");
  EXPECT_EQ(graph_part.status, 2);
  EXPECT_EQ(graph_part.out, part.out);
  EXPECT_EQ(run("inspect " + dir + "/ok.hila graph").status, 2);  // no --part
  // A part without a goal: no way, and the stage's reason.
  const CommandRun no_goal = run("inspect " + dir + "/ok.hila graph --part top --json");
  ASSERT_EQ(no_goal.status, 0) << no_goal.out;
  const auto ng = nlohmann::json::parse(json_part(no_goal.out));
  EXPECT_EQ(ng["summary"]["goals"], 0);
  EXPECT_TRUE(ng["summary"]["ways"].empty());
  EXPECT_EQ(ng["failure"], f["failure"]);
  const CommandRun no_goal_text = run("inspect " + dir + "/ok.hila graph --part top");
  EXPECT_NE(no_goal_text.out.find("no goal: " + f["failure"].get<std::string>()), std::string::npos)
      << no_goal_text.out;
}

TEST(Cli, PlanBadInputsGiveClearErrorsAndExitCodeTwo) {
  const std::string scene = test::data_path("cabinet/scene.yaml");
  const CommandRun missing = run("plan --db /nonexistent/cabinet.hila --scene " + scene + " --all");
  EXPECT_EQ(missing.status, 2) << missing.out;
  EXPECT_NE(missing.out.find("/nonexistent/cabinet.hila"), std::string::npos) << missing.out;
  EXPECT_NE(missing.out.find("hila build"), std::string::npos) << missing.out;

  const CommandRun both = run("plan --db x.hila --scene " + scene + " --all --board base");
  EXPECT_EQ(both.status, 2) << both.out;
  EXPECT_NE(both.out.find("exactly one of --board NAME or --all"), std::string::npos) << both.out;

  const CommandRun no_scene = run("plan --db x.hila --scene /nonexistent/scene.yaml --all");
  EXPECT_EQ(no_scene.status, 2) << no_scene.out;
  EXPECT_NE(no_scene.out.find("/nonexistent/scene.yaml"), std::string::npos) << no_scene.out;

  // A scene without its cell and product files.
  const std::string dir = test::temp_dir("cli_plan");
  const std::string bare = test::write_file(dir, "scene.yaml", "product: cabinet\n");
  const CommandRun no_files = run("plan --db x.hila --scene " + bare + " --all");
  EXPECT_EQ(no_files.status, 2) << no_files.out;
  EXPECT_NE(no_files.out.find("files"), std::string::npos) << no_files.out;
}
