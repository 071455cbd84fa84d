// End-to-end tests of the `hila` command: real process, real files, exit codes and JSON.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

using test::CommandRun;

CommandRun run(const std::string& args) {
  return test::run_command(std::string(HILA_EXE) + " " + args);
}

std::string json_part(const std::string& out) {
  return out.substr(out.find('{'));
}

// `inspect graph`'s stored regrasp-graph edges against the database as hila::db reads it: every
// connected `regrasp` / `transit` of the JSON's edges has the cost_rad and duration_s (both rounded
// to 1e-4) of a connected regrasp_edges row of the part, and every "C rad T s VIA" of the text
// (`text`: `inspect graph` of the same part) the cost, duration and via of one, as the text rounds
// them. Returns {JSON blocks, text mentions} checked, and counts the JSON durations above 0 into
// `estimated`.
std::pair<int, int> expect_stored_durations(const nlohmann::json& graph, const std::string& text,
                                            const db::Database& database, std::int64_t part_id,
                                            int& estimated) {
  const auto rounded = [](double v) { return std::round(v / 1e-4) * 1e-4; };
  const auto edges = database.regrasp_edges(part_id);
  std::set<std::string> shown;  // the text's "C rad T s VIA" of every connected edge with a time
  for (const auto& e : edges) {
    if (!e.connected || (e.duration == 0.0 && e.cost != 0.0)) continue;  // as the text shows them
    char buffer[96];
    std::snprintf(buffer, sizeof(buffer), "%.2f rad %.1f s %s", e.cost, e.duration, e.via.c_str());
    shown.insert(buffer);
  }
  int blocks = 0;
  for (const auto& edge : graph["edges"]) {
    for (const char* key : {"regrasp", "transit"}) {
      const auto& stored = edge[key];
      if (stored.is_null()) continue;
      if (!stored["connected"].get<bool>()) {
        EXPECT_TRUE(stored["duration_s"].is_null()) << edge.dump();
        continue;
      }
      ++blocks;
      const double cost = stored["cost_rad"].get<double>();
      const double duration = stored["duration_s"].get<double>();
      estimated += duration > 0.0 ? 1 : 0;
      bool found = false;
      for (const auto& e : edges) {
        found = found || (e.connected && std::abs(rounded(e.cost) - cost) < 1e-9 &&
                          std::abs(rounded(e.duration) - duration) < 1e-9);
      }
      EXPECT_TRUE(found) << "no regrasp_edges row of part " << part_id << " has " << key << " "
                         << stored.dump();
    }
  }
  int mentions = 0;
  const std::regex timed(R"((\d+\.\d\d rad \d+\.\d s (roadmap|bridge)))");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), timed);
       it != std::sregex_iterator(); ++it) {
    ++mentions;
    EXPECT_TRUE(shown.count((*it)[1].str()))
        << "'" << (*it)[1].str() << "' is no edge of part " << part_id << "'s regrasp_edges";
  }
  return {blocks, mentions};
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
  EXPECT_TRUE(j["pose_errors"].empty()) << r.out;
  EXPECT_TRUE(j["pose_warnings"].empty()) << r.out;
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
    // Each stored edge's cost and estimated time are the database's.
    const db::Database database = db::Database::open(out);
    const CommandRun graph_text = run("inspect " + out + " graph --part " + board + " --goals 99");
    ASSERT_EQ(graph_text.status, 0) << graph_text.out;
    int estimated = 0;
    const auto [blocks, mentions] =
        expect_stored_durations(gr, graph_text.out, database, database.part(board).id, estimated);
    EXPECT_GT(blocks, 0) << board;
    EXPECT_GT(mentions, 0) << board << "\n" << graph_text.out;
    EXPECT_GT(estimated, 0) << board;
  }
  const CommandRun graph_text = run("inspect " + out + " graph --part base --goals 2");
  ASSERT_EQ(graph_text.status, 0) << graph_text.out;
  EXPECT_NE(graph_text.out.find("goals in rank order (2 of "), std::string::npos) << graph_text.out;
  EXPECT_NE(graph_text.out.find("  rank 1 "), std::string::npos) << graph_text.out;
  EXPECT_EQ(graph_text.out.find("  rank 2 "), std::string::npos) << graph_text.out;
  EXPECT_NE(build.out.find("|𝕊|"), std::string::npos) << build.out;
  // The ergonomics report (the cell's human: the database has no worker set): hila's planned
  // handover needs no forward bend wherever the human alone does.
  const CommandRun report = run("report ergonomics " + out + " --json");
  ASSERT_EQ(report.status, 0) << report.out;
  const auto e = nlohmann::json::parse(json_part(report.out));
  ASSERT_EQ(e["workers"].size(), 1u);
  const auto& w = e["workers"][0];
  EXPECT_EQ(w["worker"]["from"], "cell");
  ASSERT_EQ(w["boards"].size(), 7u);
  int alone_bent = 0, planned = 0;
  for (const auto& b : w["boards"]) {
    if (b["alone"]["scored"].get<bool>() && b["alone"]["bent_forward"].get<bool>()) ++alone_bent;
    if (!b["hila"]["scored"].get<bool>()) continue;
    ++planned;
    EXPECT_FALSE(b["hila"]["bent_forward"].get<bool>()) << b["board"];
    // Eq. 1's goals within 45 degrees of fitted, the band's within natural_max_rotation_deg
    // (HandoverSettings, default 90).
    EXPECT_LE(b["hila"]["reorientation_deg"].get<double>(), 90.0 + 1e-6);
  }
  EXPECT_GT(planned, 0);
  EXPECT_GT(alone_bent, 0);
  EXPECT_EQ(w["verdicts_hila_vs"]["alone"]["bent_forward"], "eliminated");
  // RULA and REBA of each way's posture, and their distributions adding up to the boards scored.
  std::map<std::string, int> scored;
  for (const auto& b : w["boards"]) {
    for (const char* method : {"hila", "table", "alone"}) {
      const auto& m = b[method];
      if (!m["scored"].get<bool>()) continue;
      SCOPED_TRACE(b["board"].get<std::string>() + " " + method);
      ++scored[method];
      EXPECT_GE(m["rula_grand"].get<int>(), 1);
      EXPECT_LE(m["rula_grand"].get<int>(), 7);
      EXPECT_GE(m["reba"].get<int>(), 1);
      EXPECT_LE(m["reba"].get<int>(), 15);
      EXPECT_GT(m["load_kg"].get<double>(), 0.0);
    }
  }
  for (const char* method : {"hila", "table", "alone"}) {
    SCOPED_TRACE(method);
    const auto& s = w["summary"][method];
    EXPECT_EQ(s["scored"].get<int>(), scored[method]);
    for (const char* distribution :
         {"rula_grand", "rula_action_level", "reba_score", "reba_risk"}) {
      int sum = 0;
      for (const auto& [key, n] : s[distribution].items()) sum += n.get<int>();
      EXPECT_EQ(sum, scored[method]) << distribution << ": " << s[distribution].dump();
    }
    double mean = 0.0;
    for (const auto& [key, n] : s["rula_grand"].items()) mean += std::stoi(key) * n.get<int>();
    EXPECT_NEAR(s["mean_rula_grand"].get<double>(), mean / scored[method], 1e-12);
  }
  EXPECT_GT(scored["hila"], 0);
  const CommandRun report_text = run("report ergonomics " + out);
  EXPECT_NE(report_text.out.find("bent forward eliminated"), std::string::npos) << report_text.out;
  EXPECT_NE(report_text.out.find("  hila  RULA grand (boards by score) "), std::string::npos)
      << report_text.out;
  // The plan file: each solved board's receiving posture scored, a hand per arm of
  // human_posture_rad, the board's RULA and REBA the worse hand's.
  const CommandRun plan = run("plan --db " + out + " --scene " +
                              test::data_path("cabinet/scene.yaml") + " --all --json");
  const auto p = nlohmann::json::parse(json_part(plan.out));
  int two_hand = 0, solved = 0;
  for (const auto& b : p["boards"]) {
    if (b["status"] != "solved") continue;
    ++solved;
    SCOPED_TRACE(b["board"].get<std::string>());
    const auto& ergonomics = b["ergonomics"];
    ASSERT_TRUE(ergonomics.contains("hands")) << ergonomics.dump();
    ASSERT_EQ(ergonomics["hands"].size(), b["human_posture_rad"].size());
    EXPECT_EQ(ergonomics["two_hands"].get<bool>(), ergonomics["hands"].size() == 2);
    two_hand += ergonomics["two_hands"].get<bool>() ? 1 : 0;
    int grand = 0, reba = 0;
    for (const auto& h : ergonomics["hands"]) {
      EXPECT_TRUE(b["human_posture_rad"].contains(h["side"].get<std::string>()));
      grand = std::max(grand, h["rula"]["grand"].get<int>());
      reba = std::max(reba, h["reba"]["score"].get<int>());
      EXPECT_DOUBLE_EQ(h["reba"]["load_kg"].get<double>(), ergonomics["load_kg"].get<double>());
      EXPECT_DOUBLE_EQ(
          h["rula"]["load_kg"].get<double>(),
          ergonomics["load_kg"].get<double>() / static_cast<double>(ergonomics["hands"].size()));
    }
    EXPECT_EQ(ergonomics["rula"]["grand"].get<int>(), grand);
    EXPECT_EQ(ergonomics["reba"]["score"].get<int>(), reba);
    EXPECT_GE(grand, 1);
    EXPECT_LE(grand, 7);
    EXPECT_GE(ergonomics["rula"]["action_level"].get<int>(), 1);
    EXPECT_FALSE(ergonomics["reba"]["risk"].get<std::string>().empty());
  }
  EXPECT_GT(solved, 0) << plan.out;
  EXPECT_GT(two_hand, 0);

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

// The manipulation graph of a part served by a regrasp on the table (an L bracket no cup holds,
// whose grasps where it lies leave the human no room): `inspect graph` lists that way, its
// set-downs and their edges as `inspect handover` lists the goals' regrasp records.
TEST(Cli, InspectGraphShowsTheRegraspsOnTheTable) {
  const std::string dir = test::temp_dir("cli_graph_regrasp");
  const std::string product = test::bracket_product(dir);
  const std::string db = dir + "/bracket.hila";
  const CommandRun built = run(
      "build " + product + " --cell " + test::cell_path() +
      " --comfort-samples 20000 --handover-candidates 400 --roadmap-nodes 300 --jobs 2 -o " + db);
  ASSERT_EQ(built.status, 0) << built.out;
  const CommandRun handover = run("inspect " + db + " handover --part bracket --json");
  ASSERT_EQ(handover.status, 0) << handover.out;
  const auto h = nlohmann::json::parse(json_part(handover.out));
  std::map<std::int64_t, nlohmann::json> set_downs;  // regrasp id -> its set-down pose
  int goals_regrasp = 0;
  for (const auto& goal : h["ranked_goals"]) {
    goals_regrasp += goal["table_regrasps"].empty() ? 0 : 1;
    for (const auto& r : goal["table_regrasps"]) set_downs[r["id"]] = r["set_down"];
  }
  ASSERT_GT(goals_regrasp, 0) << handover.out;

  const CommandRun graph = run("inspect " + db + " graph --part bracket --json");
  ASSERT_EQ(graph.status, 0) << graph.out;
  const auto g = nlohmann::json::parse(json_part(graph.out));
  EXPECT_EQ(g["summary"]["goals_regrasp"], goals_regrasp);
  std::size_t way_set_downs = 0;
  for (const auto& way : g["summary"]["ways"]) {
    if (way["way"] == "regrasp") way_set_downs += way["set_downs"].size();
  }
  EXPECT_EQ(way_set_downs, set_downs.size());
  std::set<std::string> nodes;
  int set_down_nodes = 0;
  for (const auto& n : g["nodes"]) {
    nodes.insert(n["id"].get<std::string>());
    if (n["kind"] != "set_down") continue;
    ++set_down_nodes;
    const auto& pose = set_downs.at(n["regrasp"].get<std::int64_t>());
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(n["position"][k].get<double>(), pose["xyz"][k].get<double>(), 2e-5);
    }
  }
  EXPECT_EQ(static_cast<std::size_t>(set_down_nodes), set_downs.size());
  int set_down_edges = 0;
  for (const auto& e : g["edges"]) {
    EXPECT_TRUE(nodes.count(e["from"].get<std::string>()) &&
                nodes.count(e["to"].get<std::string>()))
        << e.dump();
    set_down_edges += e["kind"] == "set_down" ? 1 : 0;
  }
  EXPECT_EQ(static_cast<std::size_t>(set_down_edges), set_downs.size());
  // The text names each way as the JSON does ("regrasp on table by left", or for a relay to the
  // other arm "relay on table left -> right").
  const CommandRun text = run("inspect " + db + " graph --part bracket");
  int regrasp_ways = 0;
  for (const auto& way : g["summary"]["ways"]) {
    if (way["way"] != "regrasp") continue;
    ++regrasp_ways;
    EXPECT_NE(text.out.find(way["name"].get<std::string>()), std::string::npos) << text.out;
  }
  EXPECT_GT(regrasp_ways, 0);
}

// The stored regrasp-graph edges `inspect graph` shows are the database's: each one's joint-space
// cost and the robot's estimated time along its path (regrasp_edges.duration, schema 9), beside
// each other in the text ("8.74 rad 6.9 s roadmap") and as cost_rad and duration_s in --json, as
// hila::db reads them. (The bracket above has no regrasp graph: no cup holds it.) A quick cabinet
// build, every board's graph.
TEST(Cli, InspectGraphShowsEachStoredEdgesCostAndEstimatedTime) {
  const std::string dir = test::temp_dir("cli_graph_durations");
  const std::string db_path = dir + "/cabinet.hila";
  const CommandRun built =
      run("build " + test::product_path() + " --cell " + test::cell_path() +
          " --seed 3 --comfort-samples 20000 --handover-candidates 60 --roadmap-nodes 300 "
          "--jobs 2 -o " +
          db_path);
  ASSERT_LE(built.status, 1) << built.out;  // a board without a goal is part of the content
  const db::Database database = db::Database::open(db_path);
  int boards = 0, blocks = 0, mentions = 0, estimated = 0;
  for (const auto& part : database.parts()) {
    SCOPED_TRACE(part.name);
    const CommandRun graph = run("inspect " + db_path + " graph --part " + part.name + " --json");
    ASSERT_EQ(graph.status, 0) << graph.out;
    const CommandRun text =
        run("inspect " + db_path + " graph --part " + part.name + " --goals 99");
    ASSERT_EQ(text.status, 0) << text.out;
    const auto [b, m] = expect_stored_durations(nlohmann::json::parse(json_part(graph.out)),
                                                text.out, database, part.id, estimated);
    boards += b > 0 ? 1 : 0;
    blocks += b;
    mentions += m;
  }
  EXPECT_GE(boards, 5) << "most boards have a stored regrasp graph";
  EXPECT_GT(mentions, 0);
  EXPECT_GT(estimated, 0) << "a fresh build estimates the paths' times";
  EXPECT_LT(estimated, blocks) << "handover edges have no path, so no time";

  // A file migrated from schema 8 (made from this one: regrasp_edges as versions 4 to 8 declared
  // it, the 3 -> 4 step's text, handover_candidates without its schema 10 column, then migrated),
  // whose durations were never estimated: the text
  // shows the cost without a time, the JSON 0.
  const std::string& step_v4 = db::detail::migration_steps().at(2).sql;
  const std::string to_v8 =
      "DROP INDEX regrasp_edges_part_id; ALTER TABLE regrasp_edges RENAME TO regrasp_edges_v9;" +
      step_v4.substr(step_v4.find("CREATE TABLE regrasp_edges (")) +
      "INSERT INTO regrasp_edges SELECT id, part_id, kind, arm, from_node, to_node, filter_id, "
      "connected, cost, path_nodes, via, path_dof, path_waypoints, path FROM regrasp_edges_v9;"
      "DROP TABLE regrasp_edges_v9;"
      "ALTER TABLE handover_candidates DROP COLUMN bodies;"  // schema 10's, as in schema 8 to 9
      "UPDATE meta SET value = '8' WHERE key = 'schema_version';";
  sqlite3* handle = nullptr;
  ASSERT_EQ(sqlite3_open(db_path.c_str(), &handle), SQLITE_OK);
  char* error = nullptr;
  EXPECT_EQ(sqlite3_exec(handle, to_v8.c_str(), nullptr, nullptr, &error), SQLITE_OK)
      << (error ? error : "");
  sqlite3_free(error);
  sqlite3_close(handle);
  EXPECT_EQ(run("inspect " + db_path + " graph --part base").status, 2) << "schema 8: refused";
  db::migrate_in_place(db_path);
  const CommandRun old_json = run("inspect " + db_path + " graph --part base --json");
  ASSERT_EQ(old_json.status, 0) << old_json.out;
  int not_estimated = 0;
  const auto old_graph = nlohmann::json::parse(json_part(old_json.out));
  for (const auto& edge : old_graph["edges"]) {
    for (const char* key : {"regrasp", "transit"}) {
      if (edge[key].is_null() || !edge[key]["connected"].get<bool>()) continue;
      EXPECT_EQ(edge[key]["duration_s"].get<double>(), 0.0) << edge.dump();
      ++not_estimated;
    }
  }
  EXPECT_GT(not_estimated, 0);
  const CommandRun old_text = run("inspect " + db_path + " graph --part base --goals 99");
  ASSERT_EQ(old_text.status, 0) << old_text.out;
  EXPECT_FALSE(std::regex_search(old_text.out, std::regex(R"(rad \d+\.\d s )"))) << old_text.out;
  EXPECT_TRUE(std::regex_search(old_text.out, std::regex(R"(\d+\.\d\d rad (roadmap|bridge))")))
      << old_text.out;
}

namespace {

// A one-board database written through hila::db: meta.human_bodies `human_bodies`, the board's
// stage and its candidates with these masks (handover_candidates.bodies), goals of ranks 0, 1, ...
// in order, and one uncomfortable candidate (mask `other`) that `inspect handover` does not list.
std::string write_goals_with_bodies(const std::string& path, const std::string& human_bodies,
                                    const std::vector<std::uint32_t>& goal_bodies,
                                    std::uint32_t other) {
  db::DatabaseWriter writer(path);
  db::Meta meta;
  meta.product_name = "one board";
  meta.cell_hash = std::string(64, 'c');
  meta.product_hash = std::string(64, 'a');
  meta.settings_hash = std::string(64, '5');
  meta.cell_file = "cell.yaml";
  meta.product_file = "product.yaml";
  meta.human_bodies = human_bodies;
  writer.write_meta(meta);
  db::PartRecord part;
  part.name = "board";
  part.mass = 1.0;
  const std::int64_t id = writer.add_part(part);
  db::HandoverStageRecord stage;
  stage.part_id = id;
  stage.candidates = static_cast<int>(goal_bodies.size()) + 1;
  stage.comfortable = static_cast<int>(goal_bodies.size());
  stage.goals = static_cast<int>(goal_bodies.size());
  writer.add_handover_stage(stage);
  std::vector<db::HandoverCandidateRecord> candidates;
  db::HandoverCandidateRecord uncomfortable;
  uncomfortable.status = "uncomfortable";
  uncomfortable.bodies = other;
  candidates.push_back(uncomfortable);
  for (std::size_t i = 0; i < goal_bodies.size(); ++i) {
    db::HandoverCandidateRecord goal;
    goal.sample = static_cast<int>(i + 1);
    goal.board.translation() = Eigen::Vector3d(0.5, 0.1 * static_cast<double>(i), 1.0);
    goal.distance = 0.125 * static_cast<double>(i + 1);
    goal.quality = 0.5;
    goal.status = "goal";
    goal.rank = static_cast<int>(i);
    goal.human_arm = "right";
    goal.human_grasp_id = 1;
    goal.human_quality = 0.5;
    goal.bodies = goal_bodies[i];
    candidates.push_back(goal);
  }
  writer.add_handover_candidates(id, candidates);
  writer.commit();
  return path;
}

}  // namespace

// `inspect handover` says which bodies of the build's worker set (meta.human_bodies) take each
// goal comfortably (handover_candidates.bodies, schema 10): their labels in --json ("bodies", an
// empty list for none and without a body set) and after each goal's line in the text ("bodies:
// 1.5 female, 1.82 male", "bodies: none"), nothing of it without a body set.
TEST(Cli, InspectHandoverNamesTheBodiesOfTheWorkerSetEachGoalSuits) {
  const std::string dir = test::temp_dir("cli_handover_bodies");
  const std::string with_set =
      write_goals_with_bodies(dir + "/set.hila", "1.5 female; 1.82 male", {3, 0, 2, 1}, 3);
  const CommandRun json = run("inspect " + with_set + " handover --part board --json");
  ASSERT_EQ(json.status, 0) << json.out;
  const auto j = nlohmann::json::parse(json_part(json.out));
  EXPECT_EQ(j["human_bodies"], "1.5 female; 1.82 male");
  ASSERT_EQ(j["ranked_goals"].size(), 4u) << "the goals only";
  using Labels = std::vector<std::string>;
  EXPECT_EQ(j["ranked_goals"][0]["bodies"].get<Labels>(), (Labels{"1.5 female", "1.82 male"}));
  EXPECT_TRUE(j["ranked_goals"][1]["bodies"].is_array());
  EXPECT_EQ(j["ranked_goals"][1]["bodies"].get<Labels>(), Labels{});
  EXPECT_EQ(j["ranked_goals"][2]["bodies"].get<Labels>(), Labels{"1.82 male"});
  EXPECT_EQ(j["ranked_goals"][3]["bodies"].get<Labels>(), Labels{"1.5 female"});
  const CommandRun text = run("inspect " + with_set + " handover --part board");
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("  worker set: 1.5 female; 1.82 male\n"), std::string::npos) << text.out;
  // Each goal's line, by rank, ends with its bodies.
  const std::vector<std::string> expected = {"bodies: 1.5 female, 1.82 male", "bodies: none",
                                             "bodies: 1.82 male", "bodies: 1.5 female"};
  std::map<int, std::string> lines;
  std::istringstream in(text.out);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_match(line, m, std::regex(R"(\s+(\d+)\s+\d+\.\d{3}\s+.*)"))) {
      lines[std::stoi(m[1].str())] = line;
    }
  }
  ASSERT_EQ(lines.size(), expected.size()) << text.out;
  for (int rank = 0; rank < static_cast<int>(expected.size()); ++rank) {
    const std::string& line = lines.at(rank);
    const std::string& tail = expected[static_cast<std::size_t>(rank)];
    EXPECT_TRUE(line.size() >= tail.size() &&
                line.compare(line.size() - tail.size(), tail.size(), tail) == 0)
        << "rank " << rank << ": " << line;
  }

  // Without a body set: an empty list per goal, and the text says nothing of bodies.
  const std::string without_set = write_goals_with_bodies(dir + "/none.hila", "", {0, 0}, 0);
  const CommandRun none_json = run("inspect " + without_set + " handover --part board --json");
  ASSERT_EQ(none_json.status, 0) << none_json.out;
  const auto n = nlohmann::json::parse(json_part(none_json.out));
  ASSERT_EQ(n["ranked_goals"].size(), 2u);
  for (const auto& goal : n["ranked_goals"]) {
    ASSERT_TRUE(goal["bodies"].is_array()) << goal.dump();
    EXPECT_TRUE(goal["bodies"].empty()) << goal.dump();
  }
  const CommandRun none_text = run("inspect " + without_set + " handover --part board");
  ASSERT_EQ(none_text.status, 0) << none_text.out;
  EXPECT_EQ(none_text.out.find("bodies"), std::string::npos) << none_text.out;
  EXPECT_EQ(none_text.out.find("worker set"), std::string::npos) << none_text.out;
}

// `inspect digest` answers only for a database the loader opens: one another hila built (its
// meta edited as an older build would have it) is refused with exit status 2 and the rebuild
// command, as `plan` refuses it, not digested.
TEST(Cli, InspectDigestRefusesADatabaseTheLoaderRefuses) {
  const std::string dir = test::temp_dir("cli_digest_refused");
  const std::string db = dir + "/bracket.hila";
  const CommandRun built =
      run("build " + test::bracket_product(dir) + " --cell " + test::cell_path() +
          " --comfort-samples 1000 --handover-candidates 5 "
          "--roadmap-nodes 20 -o " +
          db);
  ASSERT_LE(built.status, 1) << built.out;
  ASSERT_EQ(run("inspect " + db + " digest").status, 0);
  sqlite3* handle = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &handle), SQLITE_OK);
  EXPECT_EQ(sqlite3_exec(handle, "UPDATE meta SET value = '0.6.0' WHERE key = 'hila_version'",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(handle);
  const CommandRun digest = run("inspect " + db + " digest");
  EXPECT_EQ(digest.status, 2) << digest.out;
  EXPECT_NE(digest.out.find("meta.hila_version"), std::string::npos) << digest.out;
  EXPECT_NE(digest.out.find("hila build"), std::string::npos) << digest.out;
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
  const CommandRun strict =
      run("build " + test::product_path() + " -o " + dir +
          "/ok.hila --comfort-samples 20000 --handover-candidates 40 "
          "--comfort-threshold 0.99 --comfort-floor 0.99 --roadmap-nodes 200");
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

// --- Bad input: outputs that are inputs, command-line errors, inputs refused before any work --

namespace {

// The build options that keep a build quick, should a refused build run after all.
const std::string kSmall = " --comfort-samples 1000 --handover-candidates 5 --roadmap-nodes 20";

// The bundled cabinet and cell copied into `dir` (dir/cabinet, dir/cell: the scene's relative
// paths still hold), so a command that wrongly overwrites an input damages only the copy.
void copy_bundled_data(const std::string& dir) {
  namespace fs = std::filesystem;
  for (const char* folder : {"cabinet", "cell"}) {
    fs::copy(test::data_path(folder), fs::path(dir) / folder, fs::copy_options::recursive);
  }
}

// Every file directly in `dir` whose name contains ".tmp" (a temporary left behind).
std::vector<std::string> temporaries_in(const std::string& dir) {
  std::vector<std::string> found;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name.find(".tmp") != std::string::npos) found.push_back(name);
  }
  return found;
}

// The message is one line: "hila: error: ...\n".
void expect_one_line_error(const CommandRun& r, const std::string& fragment) {
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(r.out.rfind("hila: error: ", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;
  EXPECT_NE(r.out.find(fragment), std::string::npos) << r.out;
}

}  // namespace

TEST(Cli, BuildRefusesAnOutputThatIsAnInputBeforeAnyWork) {
  const std::string dir = test::temp_dir("cli_output_is_input");
  copy_bundled_data(dir);
  const std::string product = dir + "/cabinet/product.yaml";
  const std::string cell = dir + "/cell/cell.yaml";
  const std::string product_text = test::read_file(product);
  const std::string build = "build " + product + " --cell " + cell + kSmall + " -o ";
  struct Case {
    std::string output;
    std::string role;
  };
  std::filesystem::create_symlink(product, dir + "/link.hila");
  std::filesystem::create_hard_link(dir + "/cabinet/shelf.stl", dir + "/hard.hila");
  const std::vector<Case> cases = {
      {product, "(the product file)"},
      {dir + "/cabinet/../cabinet/product.yaml", "(the product file '" + product + "')"},
      {dir + "/link.hila", "the product file"},
      {dir + "/cabinet/lateral.stl", "the mesh of part 'lateral_right'"},
      {dir + "/hard.hila", "the mesh of part 'base'"},
      {cell, "(the cell file)"},
      {dir + "/cell/dual_ur3.urdf", "the cell's robot URDF"},
      {dir + "/cell/human.urdf", "the cell's human URDF"},
  };
  for (const Case& c : cases) {
    const std::string before = test::read_file(c.output);
    const CommandRun r = run(build + c.output);
    expect_one_line_error(
        r,
        "-o: expected an output path that is not an input of the command, got '" + c.output + "'");
    EXPECT_NE(r.out.find(c.role), std::string::npos) << r.out;
    EXPECT_EQ(test::read_file(c.output), before) << c.output;
  }
  EXPECT_EQ(test::read_file(product), product_text);
  EXPECT_TRUE(temporaries_in(dir + "/cabinet").empty());
}

TEST(Cli, BuildRefusesAnUnusableOutputPathBeforeAnyWork) {
  const std::string dir = test::temp_dir("cli_output_unusable");
  const std::string build =
      "build " + test::product_path() + " --cell " + test::cell_path() + kSmall + " -o ";
  expect_one_line_error(run(build + "''"), "-o: expected an output file path, got ''");
  expect_one_line_error(run(build + dir), "(a directory)");
  const std::string long_name = dir + "/" + std::string(250, 'x') + ".hila";
  expect_one_line_error(run(build + long_name), "the write adds a temporary suffix");
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(Cli, PlanRefusesAnOutputThatIsAnInputBeforeAnyWork) {
  const std::string dir = test::temp_dir("cli_plan_output_is_input");
  copy_bundled_data(dir);
  // The check comes before the database is opened: any file stands in for it.
  const std::string database = test::write_file(dir, "cabinet.hila", "a database\n");
  const std::string scene = dir + "/cabinet/scene.yaml";
  const std::string plan = "plan --db " + database + " --scene " + scene + " --all -o ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {database, "(the database)"},
      {scene, "(the scene file)"},
      {dir + "/cabinet/product.yaml", "the product file"},
      {dir + "/cabinet/back_panel.stl", "the mesh of part"},
      {dir + "/cell/cell.yaml", "the cell file"},
      {dir + "/cell/suction_tool.urdf", "the cell's suction tool URDF"},
  };
  for (const auto& [output, role] : cases) {
    const std::string before = test::read_file(output);
    const CommandRun r = run(plan + output);
    expect_one_line_error(r, "-o: expected an output path that is not an input of the command");
    EXPECT_NE(r.out.find(role), std::string::npos) << r.out;
    EXPECT_EQ(test::read_file(output), before) << output;
  }
  expect_one_line_error(run(plan + "''"), "-o: expected an output file path, got ''");
}

// A write that fails half way (here the file size limit, as a full disk would) leaves neither
// the temporary file nor a partial output behind.
TEST(Cli, AFailedWriteRemovesItsTemporaryFile) {
  const std::string dir = test::temp_dir("cli_failed_write");
  const std::string limit = "trap '' XFSZ; ulimit -f 1; ";  // 1 KiB files, EFBIG instead of a kill
  const CommandRun human = run("human -o " + dir + "/h.urdf");  // the URDF is well over 1 KiB
  ASSERT_EQ(human.status, 0) << human.out;
  ASSERT_GT(test::read_file(dir + "/h.urdf").size(), 1024u);
  std::filesystem::remove(dir + "/h.urdf");
  const std::string command =
      "sh -c \"" + limit + std::string(HILA_EXE) + " human -o " + dir + "/h.urdf\" 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string out;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  const int raw = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 2) << out;
  EXPECT_NE(out.find("the write failed"), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/h.urdf"));
  EXPECT_TRUE(temporaries_in(dir).empty());
}

// The issue's case: `plan -o` on a full disk reported the error but left plan.json.tmp.
TEST(Cli, PlanOnAFullDiskLeavesNoTemporaryFile) {
  const std::string dir = test::temp_dir("cli_plan_full_disk");
  const std::string database = dir + "/c.hila";
  const CommandRun build = run("build " + test::product_path() + " --cell " + test::cell_path() +
                               kSmall + " --seed 1 --jobs 2 -o " + database);
  ASSERT_LE(build.status, 1) << build.out;  // boards without goals are planned as failures
  const std::string out = dir + "/out";
  std::filesystem::create_directory(out);
  const std::string plan = std::string(HILA_EXE) + " plan --db " + database + " --scene " +
                           test::data_path("cabinet/scene.yaml") + " --all -o " + out +
                           "/plan.json";
  const CommandRun whole = run(plan.substr(std::string(HILA_EXE).size() + 1));
  ASSERT_LE(whole.status, 1) << whole.out;
  ASSERT_GT(test::read_file(out + "/plan.json").size(), 1024u);
  std::filesystem::remove(out + "/plan.json");
  // 1 KiB files, EFBIG instead of a kill: a write fails half way, as on a full disk.
  const std::string command = "sh -c \"trap '' XFSZ; ulimit -f 1; " + plan + "\" 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string text;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) text.append(buffer.data(), n);
  const int raw = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 2) << text;
  EXPECT_NE(text.find("plan.json: (file): expected a writable path, got the write failed"),
            std::string::npos)
      << text;
  EXPECT_TRUE(std::filesystem::is_empty(out));
}

TEST(Cli, CommandLineErrorsExitTwoOnOneLine) {
  const std::string dir = test::temp_dir("cli_command_line");
  expect_one_line_error(run("frobnicate"),
                        "expected a subcommand (cell, human, mesh, product, "
                        "build, inspect, report, plan, export), got 'frobnicate'");
  expect_one_line_error(run(""), "A subcommand is required");
  expect_one_line_error(run("build"), "product is required (hila build --help");
  const std::string build = "build " + test::product_path() + kSmall + " -o " + dir + "/x.hila";
  expect_one_line_error(run(build + " --jobs 0"),
                        "--jobs: expected an integer in [1, 1024], got 0");
  expect_one_line_error(run(build + " --jobs two"),
                        "--jobs: expected an integer in [1, 1024], got two");
  expect_one_line_error(run("plan --db x.hila --scene s.yaml --all --no-such-option"),
                        "--no-such-option");
  EXPECT_EQ(run("--help").status, 0);
  EXPECT_EQ(run("build --help").status, 0);
}

TEST(Cli, VersionPrintsTheProjectVersion) {
  const CommandRun r = run("--version");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out, std::string("hila ") + HILA_VERSION + "\n");
}

TEST(Cli, NumericOptionsOutsideTheirRangeAreRefused) {
  const std::string dir = test::temp_dir("cli_numeric_options");
  // Quick builds but for the option under test, should a value be accepted after all.
  auto build = [&](const std::string& option, const std::string& value) {
    std::string command = "build " + test::product_path() + " -o " + dir + "/x.hila --jobs 2";
    for (const char* small :
         {"--comfort-samples 1000", "--handover-candidates 5", "--roadmap-nodes 20"}) {
      if (std::string(small).rfind(option, 0) != 0) command += std::string(" ") + small;
    }
    return run(command + " " + option + " " + value);
  };
  for (const char* seed : {"-1", "18446744073709551616", "1e3", "1.5"}) {
    expect_one_line_error(build("--seed", seed),
                          std::string("--seed: expected an integer in [0, 2^64), got ") + seed);
  }
  for (const char* threshold : {"nan", "inf", "-0.1", "1.5"}) {
    expect_one_line_error(
        build("--comfort-threshold", threshold),
        std::string("--comfort-threshold: expected a number in [0, 1], got ") + threshold);
  }
  for (const char* degrees : {"nan", "0", "-45", "181"}) {
    expect_one_line_error(
        build("--natural-max-rotation", degrees),
        std::string("--natural-max-rotation: expected a number in [1, 180], got ") + degrees);
  }
  for (const auto& [option, value] :
       std::vector<std::pair<std::string, std::string>>{{"--comfort-samples", "0"},
                                                        {"--handover-candidates", "-5"},
                                                        {"--roadmap-nodes", "1e9"},
                                                        {"--comfort-samples", "99999999999"}}) {
    expect_one_line_error(build(option, value), option + ": expected an integer in [1, ");
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));
  const std::string plan = "plan --db x.hila --scene s.yaml --all --deadline ";
  // A deadline under a millisecond ends every board before its first goal attempt.
  for (const char* deadline : {"inf", "nan", "0", "-1", "9.3e9", "86401", "1e-300", "0.0009"}) {
    expect_one_line_error(
        run(plan + deadline),
        std::string("--deadline: expected seconds in [0.001, 86400], got ") + deadline);
  }
}

// A key given twice in a YAML input is refused (yaml-cpp would keep the first), as is a mass or
// an angle outside its documented range; exit 2, one line, file and field named.
TEST(Cli, DuplicateKeysAndFieldsOutOfRangeAreBadInput) {
  const std::string dir = test::temp_dir("cli_field_bounds");
  copy_bundled_data(dir);
  const std::string product = dir + "/cabinet/product.yaml";
  const std::string cell = dir + "/cell/cell.yaml";
  const std::string text = test::read_file(product);
  struct Case {
    std::string from, to, message;
  };
  const std::vector<Case> cases = {
      {"    mass: 0.8\n", "    mass: 0.8\n    mass: 100\n",
       product + ": parts[0].mass: expected a key that appears once in its map, got 'mass' again "
                 "on line 18 (first on line 17)"},
      {"mass: 0.8", "mass: 100",
       product + ": parts[0].mass: expected a mass in kilograms in "
                 "[0.001, 25], got 100"},
      {"mass: 0.8", "mass: 1e-300",
       product + ": parts[0].mass: expected a mass in kilograms in "
                 "[0.001, 25], got 1e-300"},
      {"rpy_deg: [0, 0, 90]", "rpy_deg: [0, 0, 1e300]",
       product + ": parts[0].target.rpy_deg[2]: expected an angle in degrees in [-360, 360], got "
                 "1e+300"},
  };
  for (const Case& c : cases) {
    std::string changed = text;
    changed.replace(changed.find(c.from), c.from.size(), c.to);
    test::write_file(dir + "/cabinet", "product.yaml", changed);
    expect_one_line_error(run("product check " + product + " --cell " + cell), c.message);
    expect_one_line_error(
        run("build " + product + " --cell " + cell + kSmall + " -o " + dir + "/x.hila"), c.message);
  }
  test::write_file(dir + "/cabinet", "product.yaml", text);
  std::string cell_text = test::read_file(cell);
  cell_text.replace(cell_text.find("  grip_force: 100\n"), 18,
                    "  grip_force: 100\n  grip_force: 235\n");
  test::write_file(dir + "/cell", "cell.yaml", cell_text);
  expect_one_line_error(run("cell check " + cell),
                        cell + ": gripper.grip_force: expected a key that appears once in its map");
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));
}

TEST(Cli, MeshBoxRefusesAbsurdSizesAndAnOutputWithoutAFormat) {
  const std::string dir = test::temp_dir("cli_mesh_bad");
  for (const char* size : {"1e300 1 1", "1 nan 1", "1 1 inf", "1 1 1e-9"}) {
    expect_one_line_error(run("mesh box --size " + std::string(size) + " -o " + dir + "/b.stl"),
                          "--size: expected a length in [1e-06, 1000000], got ");
  }
  expect_one_line_error(run("mesh box --size 1 1 1 -o " + dir + "/m"),
                        "extension names a mesh format (.stl, .obj, .ply), got '" + dir + "/m'");
  expect_one_line_error(run("mesh box --size 1 1 1 -o ''"), "-o: expected an output file path");
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  ASSERT_EQ(run("mesh box --size 10 20 30 --unit mm -o " + dir + "/b.obj").status, 0);
  EXPECT_FALSE(test::read_file(dir + "/b.obj").empty());
  EXPECT_TRUE(temporaries_in(dir).empty());
}

TEST(Cli, ADirectoryGivenAsAnInputFileIsBadInput) {
  const std::string dir = test::temp_dir("cli_directory_input");
  expect_one_line_error(run("product check " + dir + " --cell " + test::cell_path()),
                        dir + ": (file): expected a YAML file, got a directory");
  expect_one_line_error(run("product check " + test::product_path() + " --cell " + dir),
                        dir + ": (file): expected a YAML file, got a directory");
  expect_one_line_error(run("cell check " + dir), "expected a YAML file, got a directory");
  expect_one_line_error(
      run("build " + dir + " --cell " + test::cell_path() + kSmall + " -o " + dir + "/x.hila"),
      "expected a YAML file, got a directory");
  expect_one_line_error(
      run("build " + test::product_path() + " --cell " + dir + kSmall + " -o " + dir + "/x.hila"),
      "expected a YAML file, got a directory");
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

TEST(Cli, AnEmptyOrMultiLinePartNameIsRefusedByCheckAndBuild) {
  const std::string dir = test::temp_dir("cli_part_name");
  copy_bundled_data(dir);
  const std::string product = dir + "/cabinet/product.yaml";
  const std::string text = test::read_file(product);
  for (const char* name : {"''", "\"to\\np\""}) {
    std::string changed = text;
    changed.replace(changed.find("name: top"), 9, std::string("name: ") + name);
    test::write_file(dir + "/cabinet", "product.yaml", changed);
    const std::string field = "product.yaml: parts[5].name: expected a ";
    expect_one_line_error(run("product check " + product + " --cell " + dir + "/cell/cell.yaml"),
                          field);
    expect_one_line_error(run("build " + product + " --cell " + dir + "/cell/cell.yaml" + kSmall +
                              " -o " + dir + "/x.hila"),
                          field);
  }
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));
}

// A mesh the build refuses (open, degenerate, ...) is refused by `product check` too, before the
// build's work, and the message names the mesh file.
TEST(Cli, AnOpenMeshIsRefusedNamingTheMeshFile) {
  const std::string dir = test::temp_dir("cli_open_mesh");
  copy_bundled_data(dir);
  // A tetrahedron without its bottom face: 3 border edges.
  const std::string open = test::write_file(dir + "/cabinet", "open.stl",
                                            "solid open\n"
                                            "facet normal 0 -1 0\nouter loop\n"
                                            "vertex 0 0 0\nvertex 100 0 0\nvertex 0 0 100\n"
                                            "endloop\nendfacet\n"
                                            "facet normal -1 0 0\nouter loop\n"
                                            "vertex 0 0 0\nvertex 0 0 100\nvertex 0 100 0\n"
                                            "endloop\nendfacet\n"
                                            "facet normal 1 1 1\nouter loop\n"
                                            "vertex 100 0 0\nvertex 0 100 0\nvertex 0 0 100\n"
                                            "endloop\nendfacet\n"
                                            "endsolid open\n");
  const std::string product = dir + "/cabinet/product.yaml";
  std::string text = test::read_file(product);
  text.replace(text.find("mesh: shelf.stl"), 15, "mesh: open.stl");
  test::write_file(dir + "/cabinet", "product.yaml", text);
  const std::string message =
      open + ": mesh of part 'base' (" + product + "): expected a closed mesh, got 3 border edges";
  expect_one_line_error(run("product check " + product + " --cell " + dir + "/cell/cell.yaml"),
                        message);
  expect_one_line_error(run("build " + product + " --cell " + dir + "/cell/cell.yaml" + kSmall +
                            " -o " + dir + "/x.hila"),
                        message);
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));
}

TEST(Cli, AUrdfThatIsNotXmlIsNamed) {
  const std::string dir = test::temp_dir("cli_urdf_not_xml");
  copy_bundled_data(dir);
  const std::string urdf = test::write_file(dir + "/cell", "human.urdf", "human: not a urdf\n");
  expect_one_line_error(run("cell check " + dir + "/cell/cell.yaml"),
                        urdf + ": (file): expected a URDF (XML), got text that is not XML");
  expect_one_line_error(run("build " + test::product_path() + " --cell " + dir + "/cell/cell.yaml" +
                            kSmall + " -o " + dir + "/x.hila"),
                        urdf + ": (file): expected a URDF (XML)");
}

// `product check` checks the poses: initial poses on the table (not below its top, not
// floating), clear of the suction tool on its stand, within some arm's reach; targets not below
// the table top (errors, exit 1); targets beyond the human's reach are a warning (exit 0).
TEST(Cli, ProductCheckChecksInitialAndTargetPoses) {
  const std::string dir = test::temp_dir("cli_product_poses");
  copy_bundled_data(dir);
  const std::string product = dir + "/cabinet/product.yaml";
  const std::string check = "product check " + product + " --cell " + dir + "/cell/cell.yaml";
  const std::string text = test::read_file(product);
  const std::string base_initial = "initial: {xyz: [0.30, -0.30, 1.152]";
  struct Case {
    std::string from, to;
    int status;
    std::string line;
  };
  const std::vector<Case> cases = {
      // 9 cm below the table top, beside the stack (no overlap with the table or a part).
      {base_initial, "initial: {xyz: [0.30, 0.30, 1.009]", 1,
       "error: base: initial pose: its lowest point is 90 mm below the top of 'table'"},
      {base_initial, "initial: {xyz: [0.30, 0.30, 1.2]", 1,
       "error: base: initial pose: its lowest point floats 101 mm above the top of 'table'"},
      // Behind the human, 1.5 m beyond the table's edge.
      {base_initial, "initial: {xyz: [2.65, 0.0, 1.152]", 1,
       "error: base: initial pose: out of every robot arm's reach by "},
      {base_initial, "initial: {xyz: [2.65, 0.0, 1.152]", 1,
       "error: base: initial pose: not over the table or any obstacle"},
      // On the suction tool's stand.
      {base_initial, "initial: {xyz: [0.30, -0.72, 1.099]", 1, "base <-> tool/"},
      {"target: {xyz: [0.0035, 0.0, 0.006]", "target: {xyz: [0.0035, 0.0, -0.09]", 1,
       "error: base: target pose: its lowest point is 95 mm below the top of 'table'"},
      // The assembly at the robot's side of the table: on the table, out of the human's reach.
      {"assembly_frame: {xyz: [0.62, 0.0, 1.094]", "assembly_frame: {xyz: [0.15, 0.0, 1.094]", 0,
       "warning: back_lower: target pose: out of the human's reach from the stance by "},
  };
  for (const Case& c : cases) {
    std::string changed = text;
    changed.replace(changed.find(c.from), c.from.size(), c.to);
    test::write_file(dir + "/cabinet", "product.yaml", changed);
    const CommandRun r = run(check);
    EXPECT_EQ(r.status, c.status) << c.to << "\n" << r.out;
    EXPECT_NE(r.out.find(c.line), std::string::npos) << c.to << "\n" << r.out;
  }
  // The same in the JSON report.
  std::string changed = text;
  changed.replace(changed.find(base_initial), base_initial.size(),
                  "initial: {xyz: [0.30, 0.30, 1.009]");
  test::write_file(dir + "/cabinet", "product.yaml", changed);
  const CommandRun r = run(check + " --json");
  EXPECT_EQ(r.status, 1) << r.out;
  const auto j = nlohmann::json::parse(json_part(r.out));
  ASSERT_EQ(j["pose_errors"].size(), 1u) << r.out;
  EXPECT_EQ(j["pose_errors"][0]["part"], "base");
  EXPECT_EQ(j["pose_errors"][0]["pose"], "initial");
  EXPECT_TRUE(j["pose_warnings"].empty());
}

// `build` refuses, before the comfort maps and roadmaps and with exit 1, a product whose
// finished assembly interpenetrates and a cell whose robot home collides (they used to build
// for the whole run, then exit 0 with every board "no goal reachable").
TEST(Cli, BuildRefusesInterpenetratingTargetsAndACollidingHomeBeforeTheWork) {
  const std::string dir = test::temp_dir("cli_build_refuses");
  copy_bundled_data(dir);
  const std::string product = dir + "/cabinet/product.yaml";
  const std::string cell = dir + "/cell/cell.yaml";
  const std::string build =
      "build " + product + " --cell " + cell + kSmall + " --jobs 2 -o " + dir + "/x.hila";
  const std::string product_text = test::read_file(product);
  std::string sunk = product_text;
  // The middle shelf at the base's height: the two boards overlap.
  const std::string middle = "target: {xyz: [0.0035, 0.0, 0.2945]";
  sunk.replace(sunk.find(middle), middle.size(), "target: {xyz: [0.0035, 0.0, 0.006]");
  test::write_file(dir + "/cabinet", "product.yaml", sunk);
  const CommandRun targets = run(build);
  EXPECT_EQ(targets.status, 1) << targets.out;
  EXPECT_NE(targets.out.find("hila: " + product + ": the finished assembly interpenetrates ("),
            std::string::npos)
      << targets.out;
  EXPECT_NE(targets.out.find("shelf_middle"), std::string::npos) << targets.out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));

  test::write_file(dir + "/cabinet", "product.yaml", product_text);
  std::string cell_text = test::read_file(cell);
  const std::string home = "home_deg: [15, -60, -120, -180, -120, 0]";
  cell_text.replace(cell_text.find(home), home.size(), "home_deg: [15, 90, -120, -180, -120, 0]");
  test::write_file(dir + "/cell", "cell.yaml", cell_text);
  const CommandRun colliding = run(build);
  EXPECT_EQ(colliding.status, 1) << colliding.out;
  EXPECT_NE(colliding.out.find("hila: " + cell + ": the robot at home is in collision ("),
            std::string::npos)
      << colliding.out;
  EXPECT_FALSE(std::filesystem::exists(dir + "/x.hila"));
  EXPECT_TRUE(temporaries_in(dir).empty());
}

// A build killed while writing leaves OUT.tmp-PID-N; `--if-outdated` keeping OUT removes the
// temporaries of processes that no longer run and keeps those of a running one.
TEST(Cli, BuildIfOutdatedRemovesTheTemporariesOfDeadBuilds) {
  const std::string dir = test::temp_dir("cli_stale_temporaries");
  const std::string db = dir + "/c.hila";
  const std::string build = "build " + test::product_path() + " --cell " + test::cell_path() +
                            kSmall + " --jobs 2 --if-outdated -o " + db;
  ASSERT_LE(run(build).status, 1);
  // A process that has exited: its PID no longer runs.
  FILE* pipe = popen("sh -c 'echo $$'", "r");
  ASSERT_NE(pipe, nullptr);
  char pid_text[32] = {};
  ASSERT_NE(fgets(pid_text, sizeof pid_text, pipe), nullptr);
  pclose(pipe);
  const std::string dead = dir + "/c.hila.tmp-" + std::to_string(std::atol(pid_text)) + "-0";
  const std::string live = dir + "/c.hila.tmp-" + std::to_string(::getpid()) + "-0";
  test::write_file(dir, std::filesystem::path(dead).filename().string(), "");
  test::write_file(dir, std::filesystem::path(live).filename().string(), "");
  const CommandRun kept = run(build);
  EXPECT_EQ(kept.status, 0) << kept.out;
  EXPECT_NE(kept.out.find("is up to date"), std::string::npos) << kept.out;
  EXPECT_FALSE(std::filesystem::exists(dead));
  EXPECT_TRUE(std::filesystem::exists(live));
}
