// End-to-end tests of the `hila` command: real process, real files, exit codes and JSON.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>
#include <sys/wait.h>

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

std::string json_part(const std::string& out) { return out.substr(out.find('{')); }

}  // namespace

TEST(Cli, HelpListsTheSubcommands) {
  const CommandRun r = run("--help");
  EXPECT_EQ(r.status, 0);
  for (const char* sub : {"cell", "human", "mesh", "product"}) {
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
  EXPECT_NEAR(j["human_arms"][0]["reach"].get<double>(), (0.186 + 0.146 + 0.4 * 0.108) * 1.722, 2e-3);
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

  const CommandRun r = run("product check " + test::product_path() + " --cell " + test::cell_path() +
                    " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(json_part(r.out));
  EXPECT_EQ(j["parts"].size(), 7u);
  EXPECT_EQ(j["targets_collision_free"], true);
  EXPECT_EQ(j["initial_collision_free"], true);
}
