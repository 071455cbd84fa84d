// `hila report ergonomics` per worker, end to end (the hila command as a process): hila's column is
// what `hila plan` returns for the scene naming that worker, the table drop and the human alone are
// each body's own postures, checked against the body's model, and bad input exits 2.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/product.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/offline/ergonomics.hpp"
#include "hila/online/scene.hpp"
#include "util/quick_build.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

using test::CommandRun;

CommandRun run(const std::string& args) {
  return test::run_command(std::string(HILA_EXE) + " " + args);
}

nlohmann::json json_of(const CommandRun& r) {
  return nlohmann::json::parse(r.out.substr(r.out.find('{')));
}

// The workers the report is run for: the smallest and the tallest tested bodies, and the cell's
// own human as a body (1.722 m man).
const std::vector<core::HumanBodySpec> kWorkers = {
    {1.50, core::Sex::Female}, {1.722, core::Sex::Male}, {1.95, core::Sex::Male}};
constexpr const char* kWorkersOption = "1.50:female,1.722:male,1.95:male";

// The bundled scene with its files made absolute and `worker: {stature, sex}` added, as
// tools/dev/plan_workers writes it.
std::string scene_for(const std::string& dir, const core::HumanBodySpec& worker) {
  std::string text = test::read_file(test::data_path("cabinet/scene.yaml"));
  const std::string files = "files: {cell: ../cell/cell.yaml, product: product.yaml}";
  const auto at = text.find(files);
  EXPECT_NE(at, std::string::npos) << "the bundled scene names its files otherwise";
  text.replace(at, files.size(),
               "files: {cell: " + test::cell_path() + ", product: " + test::product_path() + "}");
  const std::string sex = worker.sex == core::Sex::Male ? "male" : "female";
  text += "\nworker: {stature: " + core::format_number(worker.stature) + ", sex: " + sex + "}\n";
  return test::write_file(dir, "scene_" + core::format_number(worker.stature) + "_" + sex + ".yaml",
                          text);
}

class ReportErgonomics : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = test::temp_dir("report_ergonomics_" + std::to_string(::getpid()));
    // A prebuilt cabinet database (HILA_TEST_DATABASE, as tools/test builds it), else a quick
    // build with maps dense enough that the boards have goals, as test_db_scenes'.
    if (const char* given = std::getenv("HILA_TEST_DATABASE")) {
      path_ = given;
    } else {
      path_ = dir_ + "/cabinet.hila";
      offline::BuildSettings settings = test::quick_build_settings(7, 2);
      settings.comfort.samples = 400000;
      settings.handover.candidates = 200;
      settings.handover.max_candidates = 400;
      // The report searches the table and stack postures with the default settings: the stored
      // ones are the report's only for a build with those.
      settings.ergonomics = offline::ErgonomicsSettings{};
      offline::build_database(test::product_path(), test::cell_path(), path_, settings);
    }
  }
  static void TearDownTestSuite() { report_.reset(); }

  // The report for kWorkers, made once per process when first asked for.
  static const nlohmann::json& report() {
    if (report_ == nullptr) {
      const CommandRun r =
          run("report ergonomics " + path_ + " --workers " + kWorkersOption + " --json");
      EXPECT_EQ(r.status, 0) << r.out;
      report_ = std::make_unique<nlohmann::json>(json_of(r));
    }
    return *report_;
  }

  // The report's entry for the worker of `spec`.
  static const nlohmann::json& worker(const core::HumanBodySpec& spec) {
    for (const auto& w : report()["workers"]) {
      if (w["worker"]["label"] == core::human_body_label(spec)) return w;
    }
    ADD_FAILURE() << "no worker " << core::human_body_label(spec);
    static const nlohmann::json none;
    return none;
  }

  static inline std::string dir_;
  static inline std::string path_;
  static inline std::unique_ptr<nlohmann::json> report_;
};

}  // namespace

// hila's column for a worker is the plan `hila plan --all` returns for the scene naming that
// worker: the same status and goal per board, and for a planned board the same `ergonomics`
// block (RULA, REBA, every hand's sub-scores, the posture check), which the report's own figures
// repeat.
TEST_F(ReportErgonomics, HilaIsWhatHilaPlanReturnsForTheWorkersScene) {
  ASSERT_EQ(report()["workers"].size(), kWorkers.size());
  int solved = 0;
  for (const core::HumanBodySpec& spec : {kWorkers.front(), kWorkers.back()}) {
    SCOPED_TRACE(core::human_body_label(spec));
    // The plan file (stdout also carries the note on boards not planned, exit status 1).
    const std::string plan_file = dir_ + "/plan_" + core::format_number(spec.stature) + ".json";
    const CommandRun plan =
        run("plan --db " + path_ + " --scene " + scene_for(dir_, spec) + " --all -o " + plan_file);
    ASSERT_TRUE(plan.status == 0 || plan.status == 1) << plan.out;
    const nlohmann::json p = nlohmann::json::parse(test::read_file(plan_file));
    EXPECT_EQ(p["worker"]["stature"].get<double>(), spec.stature);
    const auto& boards = worker(spec)["boards"];
    ASSERT_EQ(boards.size(), p["boards"].size());
    for (std::size_t i = 0; i < boards.size(); ++i) {
      const auto& planned = p["boards"][i];
      const auto& hila = boards[i]["hila"];
      SCOPED_TRACE(planned["board"].get<std::string>());
      ASSERT_EQ(boards[i]["board"], planned["board"]);
      ASSERT_EQ(hila["status"], planned["status"]);
      if (planned["status"] != "solved") {
        EXPECT_FALSE(hila["scored"].get<bool>());
        continue;
      }
      ++solved;
      ASSERT_TRUE(hila["scored"].get<bool>()) << hila.dump();
      EXPECT_EQ(hila["goal_rank"], planned["goal_rank"]);
      EXPECT_EQ(hila["natural_posture"], planned["natural_posture"]);
      const auto& e = planned["ergonomics"];
      EXPECT_EQ(hila["ergonomics"], e);
      EXPECT_EQ(hila["rula_grand"], e["rula"]["grand"]);
      EXPECT_EQ(hila["reba"], e["reba"]["score"]);
      EXPECT_EQ(hila["elbow_below_shoulder"], e["posture"]["elbow_below_shoulder"]);
      EXPECT_EQ(hila["part_centre_z"], e["posture"]["part_centre_z"]);
      EXPECT_EQ(hila["hip_z"], e["posture"]["hip_z"]);
      EXPECT_EQ(hila["shoulder_z"], e["posture"]["shoulder_z"]);
      EXPECT_EQ(hila["torso_flexion_deg"], e["posture"]["trunk_flexion_deg"]);
      EXPECT_EQ(hila["natural"], e["posture"]["natural"]);
      std::vector<std::string> arms;
      for (const auto& [arm, joints] : hila["joints_rad"].items()) {
        EXPECT_EQ(joints, planned["human_posture_rad"][arm]) << arm;
        arms.push_back(arm);
      }
      EXPECT_EQ(arms.size(), planned["human_posture_rad"].size());
    }
  }
  EXPECT_GT(solved, 0);
}

// The table drop and the human alone are each body's own: the figures follow from the body's
// model (core::HumanBody) at the joints and torso flexion the report returns (RULA and REBA by
// core's functions, the reach by forward kinematics, the hip and shoulder heights of
// core::natural_height_band at the stance, the table drop's centre where offline::table_drop_pose
// lays the board), and a 1.50 m woman and a 1.95 m man take the same boards differently.
TEST_F(ReportErgonomics, TableAndAloneAreEachBodysOwnPostures) {
  const auto cell = test::reference_cell();
  const core::ProductSpec product = core::load_product(test::product_path());
  const online::Scene scene =
      online::load_scene(test::data_path("cabinet/scene.yaml"), *cell, product);
  const db::Database database = db::Database::open(path_);
  std::map<std::string, std::map<std::string, nlohmann::json>> taken;  // [label][board/method]
  int checked = 0;
  for (const core::HumanBodySpec& spec : {kWorkers.front(), kWorkers.back()}) {
    const core::HumanBody body(*cell, spec);
    SCOPED_TRACE(body.label());
    const core::HeightBand band = core::natural_height_band(*cell, &body, scene.human_stance);
    const auto& w = worker(spec);
    EXPECT_NEAR(w["hip_z"].get<double>(), band.hip_z, 1e-12);
    EXPECT_NEAR(w["shoulder_z"].get<double>(), band.shoulder_z, 1e-12);
    const int torso =
        body.model()
            .joints()[static_cast<std::size_t>(body.model().joint_index("torso_flexion"))]
            .variable;
    for (const auto& b : w["boards"]) {
      const std::string board = b["board"];
      const db::PartRecord& part = database.part(board);
      for (const char* method : {"table", "alone"}) {
        const auto& m = b[method];
        SCOPED_TRACE(board + " " + method);
        taken[body.label()][board + "/" + method] = m;
        if (!m["scored"].get<bool>()) continue;
        const std::string arm = m["arm"];
        const std::vector<double> values = m["joints_rad"][arm].get<std::vector<double>>();
        const Eigen::VectorXd joints = Eigen::Map<const Eigen::VectorXd>(
            values.data(), static_cast<Eigen::Index>(values.size()));
        Eigen::VectorXd q = body.posture({{arm, joints}});
        q[torso] = core::deg_to_rad(m["torso_flexion_deg"].get<double>());
        const double load = m["load_kg"].get<double>();
        EXPECT_DOUBLE_EQ(load, part.mass);
        const bool two_hands = m["two_hands"].get<bool>();
        EXPECT_EQ(m["rula_grand"].get<int>(),
                  core::rula(core::rula_inputs_from_posture(body.model(), q, arm, load, two_hands))
                      .grand);
        EXPECT_EQ(m["reba"].get<int>(),
                  core::reba(core::reba_inputs_from_posture(body.model(), q, arm, load)).reba);
        const double centre = m["part_centre_z"].get<double>();
        const std::string where = centre > m["shoulder_z"].get<double>() ? "above the shoulder"
                                  : centre < m["hip_z"].get<double>()    ? "below the hip"
                                                                         : "in band";
        EXPECT_EQ(m["centre"], where);
        // The turn left to the fitted orientation is the re-orientation left, in 15-degree steps
        // with both ends; shoulder work is an elbow up at the take or in the turn.
        const auto& turn = m["turn"];
        const double turned = turn["turned_deg"].get<double>();
        EXPECT_NEAR(turned, m["reorientation_deg"].get<double>(), 1e-6);
        EXPECT_EQ(turn["steps"].get<int>(),
                  turned < 1e-6 ? 0 : static_cast<int>(std::ceil(turned / 15.0 - 1e-9)) + 1);
        EXPECT_EQ(m["shoulder_work"].get<bool>(),
                  !m["elbow_below_shoulder"].get<bool>() || turn["elbow_up_steps"].get<int>() > 0);
        // Steps blocked by the body are among the steps, none without a turn.
        EXPECT_GE(turn["blocked_steps"].get<int>(), 0);
        EXPECT_LE(turn["blocked_steps"].get<int>(), turn["steps"].get<int>());
        ++checked;
        if (std::string(method) != "table") continue;
        // At the table the worker stands at the scene's stance.
        std::vector<core::Pose> links;
        body.model().link_poses(q, links);
        const auto& held = body.arms()[static_cast<std::size_t>(body.arm_index(arm))];
        const auto& chain = held.chain;
        const core::Pose base =
            scene.human_stance *
            links[static_cast<std::size_t>(body.model().link_index(held.spec.base_link))];
        EXPECT_NEAR(
            m["reach"].get<double>(),
            ((base * chain.fk(joints)).translation() - base * chain.first_joint_position()).norm(),
            1e-6);
        if (m["torso_flexion_deg"].get<double>() == 0.0) {
          EXPECT_NEAR(m["hip_z"].get<double>(), band.hip_z, 1e-9);
          EXPECT_NEAR(m["shoulder_z"].get<double>(), band.shoulder_z, 1e-9);
        }
        const auto placements = database.placements(part.id);
        ASSERT_FALSE(placements.empty());
        const core::Pose drop = offline::table_drop_pose(*cell, placements.front().part_in_plane,
                                                         offline::ErgonomicsSettings{});
        EXPECT_NEAR(centre, (drop * part.mass_properties.com).z(), 1e-9);
      }
    }
  }
  EXPECT_GT(checked, 10);
  // The same boards, two bodies: different reaches, and the board on the table is in the short
  // woman's hip-shoulder band but below the tall man's hip somewhere.
  const auto& small = taken.at("1.5 female");
  const auto& tall = taken.at("1.95 male");
  int compared = 0, band_differs = 0;
  for (const auto& [key, m] : small) {
    const auto& other = tall.at(key);
    if (!m["scored"].get<bool>() || !other["scored"].get<bool>()) continue;
    ++compared;
    EXPECT_GT(std::abs(m["reach"].get<double>() - other["reach"].get<double>()), 0.01) << key;
    band_differs += m["centre"] != other["centre"] ? 1 : 0;
  }
  EXPECT_GT(compared, 4);
  EXPECT_GT(band_differs, 0);
}

// Without --workers on a database without a worker set: one worker, the cell's own human, whose
// figures are the 1.722 m man's (the cell human's body), and whose table and alone postures are
// the build's stored ones (the same search, settings and seed). The summaries add up.
TEST_F(ReportErgonomics, WithoutWorkersTheCellsHuman) {
  const db::Database database = db::Database::open(path_);
  ASSERT_EQ(database.meta().human_bodies, "") << "a database without a worker set";
  const CommandRun r = run("report ergonomics " + path_ + " --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = json_of(r);
  ASSERT_EQ(j["workers"].size(), 1u);
  const auto& w = j["workers"][0];
  EXPECT_EQ(w["worker"]["from"], "cell");
  const auto& same = worker(kWorkers[1]);
  ASSERT_EQ(w["boards"].size(), same["boards"].size());
  for (std::size_t i = 0; i < w["boards"].size(); ++i) {
    const auto& b = w["boards"][i];
    SCOPED_TRACE(b["board"].get<std::string>());
    for (const char* method : {"hila", "table", "alone"}) {
      EXPECT_EQ(b[method]["status"], same["boards"][i][method]["status"]) << method;
      EXPECT_EQ(b[method].value("rula_grand", 0), same["boards"][i][method].value("rula_grand", 0))
          << method;
    }
    for (const auto& stored : database.ergonomics(database.part(b["board"]).id)) {
      if (stored.method == "hila") continue;  // the build's first goal, not the plan's
      const auto& m = b[stored.method];
      SCOPED_TRACE(stored.method);
      ASSERT_EQ(m["scored"].get<bool>(), stored.reachable);
      if (!stored.reachable) continue;
      EXPECT_EQ(m["arm"], stored.arm);
      EXPECT_EQ(m["torso_flexion_deg"].get<double>(), stored.torso_flexion_deg);
      EXPECT_NEAR(m["quality"].get<double>(), stored.quality, 1e-12);
    }
  }
  for (const char* method : {"hila", "table", "alone"}) {
    SCOPED_TRACE(method);
    const auto& s = w["summary"][method];
    int scored = 0, by_score = 0;
    for (const auto& b : w["boards"]) scored += b[method]["scored"].get<bool>() ? 1 : 0;
    for (const auto& [score, n] : s["rula_grand"].items()) by_score += n.get<int>();
    EXPECT_EQ(s["scored"].get<int>(), scored);
    EXPECT_EQ(by_score, scored);
    int shoulder = 0;
    for (const auto& b : w["boards"]) {
      shoulder += b[method].value("shoulder_work", false) ? 1 : 0;
    }
    EXPECT_EQ(s["shoulder_work"].get<int>(), shoulder);
    EXPECT_EQ(s["boards"].get<int>(), static_cast<int>(w["boards"].size()));
    EXPECT_EQ(j["all_workers"][method], s);  // one worker: the all-workers totals are its own
  }
  const CommandRun text = run("report ergonomics " + path_);
  ASSERT_EQ(text.status, 0) << text.out;
  EXPECT_NE(text.out.find("cell human (cell; hip "), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("all workers (1): hila RULA <= 3 on "), std::string::npos) << text.out;
}

// Bad input: a malformed --workers item, a stature outside the human model's range, an empty
// list, a scene that cannot be read, options of `report html` — one line naming the option or
// file, what was expected and what was got, exit status 2, no report.
TEST_F(ReportErgonomics, BadInputIsRefusedWithExitTwo) {
  const std::string report = "report ergonomics " + path_;
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {" --workers 1.50:robot",
       {"command line: --workers: expected sex 'male' or 'female' in '1.50:robot', got 'robot'"}},
      {" --workers 1500:male",
       {"--workers: expected a stature in metres within [1.3, 2.2] in '1500:male', got 1500",
        "millimetres given as metres?"}},
      {" --workers 1.5:female,1.25:male", {"--workers", "in '1.25:male', got 1.25"}},
      {" --workers tall",
       {"--workers: expected STATURE[:SEX] items such as 1.50:female, got 'tall'"}},
      {" --workers 1.5:female,,1.8", {"--workers", "got ''"}},
      {" --workers ''", {"--workers: expected at least one STATURE[:SEX] item, got nothing"}},
      {" --scene " + dir_ + "/no_such_scene.yaml",
       {dir_ + "/no_such_scene.yaml", "expected an existing YAML file"}},
      {" --cell " + test::cell_path(), {"--cell: expected no --cell with report ergonomics"}},
  };
  for (const auto& [args, fragments] : cases) {
    SCOPED_TRACE(args);
    const CommandRun r = run(report + args);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_EQ(r.out.rfind("hila: error: ", 0), 0u) << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;  // one line, nothing else printed
    for (const auto& fragment : fragments) {
      EXPECT_NE(r.out.find(fragment), std::string::npos) << fragment << "\n" << r.out;
    }
  }
  const CommandRun html =
      run("report html " + path_ + " --workers 1.5:female -o " + dir_ + "/report.html");
  EXPECT_EQ(html.status, 2) << html.out;
  EXPECT_NE(html.out.find("--workers: expected no --workers with report html"), std::string::npos)
      << html.out;
  EXPECT_FALSE(std::filesystem::exists(dir_ + "/report.html"));
}
