#include <algorithm>
#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cmd_report_html.hpp"
#include "commands.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/comfort_map.hpp"
#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/error.hpp"
#include "hila/core/mesh_symmetry.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/product.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/build.hpp"
#include "hila/offline/ergonomics.hpp"

namespace hila::tools {

namespace {

// EAWS (the paper's Table 2): the torso counts as bent forward from 20 degrees.
constexpr double kBentForwardDeg = 20.0;
constexpr const char* kMethods[] = {"hila", "table", "alone"};

// How close a posture evaluated again must come to the stored record to be the build's.
constexpr double kSameAngleDeg = 1e-6;
constexpr double kSameQuality = 1e-9;

struct ReportOptions {
  std::string what = "ergonomics";
  std::string database;
  bool json = false;
  ReportHtmlOptions html;  // `report html`
};

// RULA and REBA of one way's receiving posture.
struct PostureScores {
  // The re-orientation left (deg), modulo the part's symmetries where they are known; negative
  // when the way was not evaluated again (the stored value stands).
  double reorientation_deg = -1.0;
  bool scored = false;
  std::string why;  // not scored: why
  bool two_hands = false;
  double load_kg = 0.0;
  core::RulaScore rula;
  core::RebaScore reba;
};

// The database stores each way's posture by its summary (torso flexion, arm, Q), not its
// joints: the postures are evaluated again as the build evaluated them (its default
// ErgonomicsSettings, the database's seed, the stored comfort maps, grasps, placements and first
// goal), kept only where they are the stored ones (the same arm, torso flexion and Q), and
// scored: the arm's joints on the cell's human at that torso flexion, the rest neutral, holding
// the part's mass (two hands where the part has no one-hand grasp, or hila's goal is a two-hand
// one: the one arm's posture stands for both, as in the build). By method.
std::map<std::string, PostureScores> score_postures(
    const core::Cell& cell, const offline::HumanComfort& comfort, const db::Database& database,
    const db::PartRecord& part, const std::vector<Eigen::Matrix3d>& symmetries) {
  std::map<std::string, PostureScores> out;
  const auto grasps = database.human_grasps(part.id);
  offline::ErgonomicsInputs in;
  in.target = part.target;
  in.initial = part.initial;
  const auto placements = database.placements(part.id);
  if (!placements.empty()) {
    in.has_placement = true;
    in.table_placement = placements.front().part_in_plane;
  }
  in.human_grasps = &grasps;
  in.symmetries = symmetries;
  bool goal_two_hands = false;
  for (const auto& goal : database.handover_goals(part.id)) {
    if (goal.rank != 0) continue;
    for (std::size_t g = 0; g < grasps.size(); ++g) {
      if (grasps[g].id == goal.human_grasp_id) in.goal_grasp = static_cast<int>(g);
    }
    for (int a = 0; a < comfort.arm_count(); ++a) {
      if (comfort.arm_name(a) == goal.human_arm) in.goal_arm = a;
    }
    in.has_goal = in.goal_grasp >= 0 && in.goal_arm >= 0;
    in.goal = goal.board;
    goal_two_hands = !goal.second_arm.empty();
  }
  const bool one_hand_grasp =
      std::any_of(grasps.begin(), grasps.end(), [](const auto& g) { return g.one_hand_stable; });
  offline::ErgonomicsSettings settings;
  settings.seed = offline::part_seed(database.meta().seed, part.name, 5);
  std::vector<offline::Posture> postures;
  const auto again = offline::evaluate_ergonomics(cell, comfort, in, settings, &postures);
  const auto stored = database.ergonomics(part.id);
  const core::RobotModel& human = cell.human();
  const int torso = human.joints()[human.joint_index("torso_flexion")].variable;
  for (const auto& e : stored) {
    PostureScores& s = out[e.method];
    const auto it = std::find_if(again.begin(), again.end(),
                                 [&](const auto& r) { return r.method == e.method; });
    if (it != again.end()) s.reorientation_deg = it->reorientation_deg;
    if (!e.reachable) {
      s.why = "unreachable";
      continue;
    }
    const std::size_t k = static_cast<std::size_t>(it - again.begin());
    if (it == again.end() || !it->reachable || it->arm != e.arm ||
        std::abs(it->torso_flexion_deg - e.torso_flexion_deg) > kSameAngleDeg ||
        std::abs(it->quality - e.quality) > kSameQuality) {
      s.why = "posture not reproduced (the database was built with other settings or cell)";
      continue;
    }
    Eigen::VectorXd q = core::human_posture(cell, {{e.arm, postures[k].arm_joints}});
    q[torso] = core::deg_to_rad(postures[k].torso_flexion_deg);
    s.two_hands = e.method == "hila" ? goal_two_hands : !one_hand_grasp;
    s.load_kg = part.mass;
    s.rula = core::rula(core::rula_inputs_from_posture(human, q, e.arm, part.mass, s.two_hands));
    s.reba = core::reba(core::reba_inputs_from_posture(human, q, e.arm, part.mass));
    s.scored = true;
  }
  return out;
}

// The human's comfort maps as the database stores them, in the cell's human arm order.
offline::HumanComfort stored_comfort(const core::Cell& cell, const db::Database& database) {
  const auto records = database.read_comfort_maps();
  std::vector<core::ComfortMap> maps;
  for (const auto& arm : cell.human_arms()) {
    const auto it = std::find_if(records.begin(), records.end(),
                                 [&](const auto& m) { return m.arm == arm.spec.name; });
    if (it == records.end()) {
      throw core::InputError(database.path(), "comfort_maps",
                             "a comfort map for the human arm '" + arm.spec.name + "'", "none");
    }
    maps.push_back(core::ComfortMap::from_grid(it->origin, it->spacing, it->dims, it->orientations,
                                               it->values, it->coverage));
  }
  return offline::HumanComfort(cell, std::move(maps));
}

struct Totals {
  int boards = 0;
  int unreachable = 0;
  int bent = 0;
  int shoulder = 0;
  double reach = 0.0;
  double reorientation = 0.0;
  double quality = 0.0;
  int scored = 0;                                     // postures with RULA and REBA
  std::map<int, int> rula, reba;                      // boards by RULA grand score, by REBA score
  std::map<std::string, int> rula_action, reba_risk;  // by action level, by risk level
};

// Compares a count where fewer is better.
std::string fewer(int ours, int theirs, const char* none_left) {
  if (ours == 0 && theirs > 0) return none_left;
  if (ours < theirs) return "decreased";
  if (ours > theirs) return "increased";
  return "the same";
}

std::string compare(double ours, double theirs, double tolerance, const char* better,
                    const char* worse) {
  if (ours < theirs - tolerance) return better;
  if (ours > theirs + tolerance) return worse;
  return "the same";
}

// The part's symmetries by part name, from the product file's meshes where they are the meshes
// the database was built from (the same hash); a part without is charged the plain angle.
using Symmetries = std::map<std::string, std::vector<Eigen::Matrix3d>>;

nlohmann::json ergonomics_json(const db::Database& database, const core::Cell& cell,
                               const Symmetries& symmetries) {
  nlohmann::json boards = nlohmann::json::array();
  std::map<std::string, Totals> totals;
  // Without comfort maps, or with a human model the scores cannot read, every board says why.
  std::optional<offline::HumanComfort> comfort;
  std::string no_scores;
  try {
    comfort.emplace(stored_comfort(cell, database));
  } catch (const core::InputError& e) {
    no_scores = e.what();
  }
  for (const auto& part : database.parts()) {
    nlohmann::json row = {{"part", part.name}, {"order", part.assembly_order}};
    std::map<std::string, PostureScores> scores;
    const auto sym = symmetries.find(part.name);
    row["symmetries"] =
        sym != symmetries.end() ? nlohmann::json(sym->second.size()) : nlohmann::json(nullptr);
    if (comfort) {
      try {
        scores =
            score_postures(cell, *comfort, database, part,
                           sym != symmetries.end() ? sym->second : std::vector<Eigen::Matrix3d>{});
      } catch (const core::InputError& e) {
        no_scores = e.what();
      }
    }
    for (const char* method : kMethods) {
      if (!no_scores.empty() && !scores.count(method)) scores[method].why = no_scores;
    }
    for (const auto& e : database.ergonomics(part.id)) {
      Totals& t = totals[e.method];
      ++t.boards;
      nlohmann::json m = {{"reachable", e.reachable}};
      if (e.reachable) {
        const bool bent = e.torso_flexion_deg >= kBentForwardDeg;
        t.bent += bent ? 1 : 0;
        t.shoulder += e.shoulder_elevated ? 1 : 0;
        t.reach += e.reach;
        t.quality += e.quality;
        m.update({{"torso_flexion_deg", e.torso_flexion_deg},
                  {"bent_forward", bent},
                  {"shoulder_elevated", e.shoulder_elevated},
                  {"reach", e.reach},
                  {"quality", e.quality},
                  {"arm", e.arm}});
      } else {
        ++t.unreachable;
      }
      const auto sc = scores.find(e.method);
      const double reorientation = sc != scores.end() && sc->second.reorientation_deg >= 0.0
                                       ? sc->second.reorientation_deg
                                       : e.reorientation_deg;
      t.reorientation += reorientation;
      m["reorientation_deg"] = reorientation;
      if (sc != scores.end() && sc->second.scored) {
        const PostureScores& p = sc->second;
        ++t.scored;
        ++t.rula[p.rula.grand];
        ++t.reba[p.reba.reba];
        ++t.rula_action[std::to_string(core::rula_action_level(p.rula.grand))];
        ++t.reba_risk[core::reba_risk_level(p.reba.reba)];
        m["rula"] = {{"grand", p.rula.grand},
                     {"action_level", core::rula_action_level(p.rula.grand)},
                     {"upper_arm", p.rula.upper_arm},
                     {"lower_arm", p.rula.lower_arm},
                     {"wrist", p.rula.wrist},
                     {"trunk", p.rula.trunk},
                     {"force_load", p.rula.force_load}};
        m["reba"] = {{"score", p.reba.reba},           {"risk", core::reba_risk_level(p.reba.reba)},
                     {"trunk", p.reba.trunk},          {"upper_arm", p.reba.upper_arm},
                     {"lower_arm", p.reba.lower_arm},  {"wrist", p.reba.wrist},
                     {"load_force", p.reba.load_force}};
        m["load_kg"] = p.load_kg;
        m["two_hands"] = p.two_hands;
      } else {
        m["scores_missing"] = sc == scores.end() ? "not evaluated" : sc->second.why;
      }
      row[e.method] = m;
    }
    boards.push_back(row);
  }
  nlohmann::json summary = nlohmann::json::object();
  for (const char* method : kMethods) {
    const Totals& t = totals[method];
    const int reached = t.boards - t.unreachable;
    summary[method] = {{"boards", t.boards},
                       {"unreachable", t.unreachable},
                       {"bent_forward", t.bent},
                       {"shoulder_elevated", t.shoulder},
                       {"mean_reach", reached ? t.reach / reached : 0.0},
                       {"mean_reorientation_deg", t.boards ? t.reorientation / t.boards : 0.0},
                       {"mean_quality", reached ? t.quality / reached : 0.0},
                       {"scored", t.scored}};
    // Boards by score (keys the score, as strings: JSON keys), then by level.
    nlohmann::json rula = nlohmann::json::object(), reba = nlohmann::json::object();
    double rula_sum = 0.0, reba_sum = 0.0;
    for (const auto& [score, n] : t.rula) {
      rula[std::to_string(score)] = n;
      rula_sum += score * n;
    }
    for (const auto& [score, n] : t.reba) {
      reba[std::to_string(score)] = n;
      reba_sum += score * n;
    }
    summary[method]["rula_grand"] = rula;
    summary[method]["rula_action_level"] = t.rula_action;
    summary[method]["mean_rula_grand"] = t.scored ? rula_sum / t.scored : 0.0;
    summary[method]["reba_score"] = reba;
    summary[method]["reba_risk"] = t.reba_risk;
    summary[method]["mean_reba"] = t.scored ? reba_sum / t.scored : 0.0;
  }
  nlohmann::json verdicts = nlohmann::json::object();
  for (const char* baseline : {"alone", "table"}) {
    const auto& a = summary["hila"];
    const auto& b = summary[baseline];
    verdicts[baseline] = {
        {"bent_forward",
         fewer(a["bent_forward"].get<int>(), b["bent_forward"].get<int>(), "eliminated")},
        {"shoulder_work",
         fewer(a["shoulder_elevated"].get<int>(), b["shoulder_elevated"].get<int>(), "eliminated")},
        {"reaching", compare(a["mean_reach"].get<double>(), b["mean_reach"].get<double>(), 0.02,
                             "shorter", "longer")},
        {"reorientation",
         compare(a["mean_reorientation_deg"].get<double>(),
                 b["mean_reorientation_deg"].get<double>(), 2.0, "decreased", "increased")},
        {"comfort", compare(-a["mean_quality"].get<double>(), -b["mean_quality"].get<double>(),
                            0.005, "more comfortable", "less comfortable")},
        {"rula", compare(a["mean_rula_grand"].get<double>(), b["mean_rula_grand"].get<double>(),
                         0.05, "lower", "higher")},
        {"reba", compare(a["mean_reba"].get<double>(), b["mean_reba"].get<double>(), 0.05, "lower",
                         "higher")}};
  }
  return {{"database", database.path()},
          {"product", database.meta().product_name},
          {"bent_forward_from_deg", kBentForwardDeg},
          {"human", cell.spec().file},
          {"boards", boards},
          {"summary", summary},
          {"verdicts_hila_vs", verdicts}};
}

std::string cell_text(const nlohmann::json& m) {
  if (m.is_null()) return "-";  // not evaluated (no goal, no placement)
  if (!m["reachable"].get<bool>()) return "unreachable";
  std::ostringstream s;
  s << std::fixed << std::setprecision(0) << m["torso_flexion_deg"].get<double>() << "/"
    << (m["shoulder_elevated"].get<bool>() ? "up" : "--") << "/" << std::setprecision(2)
    << m["reach"].get<double>() << "/" << std::setprecision(0)
    << m["reorientation_deg"].get<double>() << "/" << std::setprecision(3)
    << m["quality"].get<double>() << "/";
  if (m.contains("rula")) {
    s << m["rula"]["grand"].get<int>() << "/" << m["reba"]["score"].get<int>();
  } else {
    s << "?/?";
  }
  return s.str();
}

int run_report(ReportOptions opt) {
  if (opt.what == "html") {
    if (opt.html.output.empty()) {
      throw core::InputError("command line", "report html", "-o report.html", "none");
    }
    opt.html.database = opt.database;
    return run_report_html(opt.html);
  }
  if (opt.what != "ergonomics") {
    throw core::InputError("command line", "report", "ergonomics or html", "'" + opt.what + "'");
  }
  const db::Database database = db::Database::open(opt.database);
  const auto cell =
      core::Cell::load(opt.html.cell_file.empty() ? default_cell_path() : opt.html.cell_file);
  // The parts' symmetries, from the product file where its meshes are the database's.
  Symmetries symmetries;
  try {
    const core::ProductSpec product = core::load_product(
        opt.html.product_file.empty() ? default_product_path() : opt.html.product_file);
    for (const auto& part : database.parts()) {
      for (const auto& p : product.parts) {
        if (p.name == part.name && offline::mesh_hash(p.mesh) == part.mesh_hash) {
          symmetries[part.name] = core::mesh_symmetries(p.mesh);
        }
      }
    }
  } catch (const core::InputError&) {
    // No product file at hand: the stored re-orientation (the build's, modulo the symmetries
    // where it knew them) stands.
  }
  const auto j = ergonomics_json(database, *cell, symmetries);
  if (opt.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "ergonomics of " << j["product"].get<std::string>()
            << ": (a) hila's handover, (b) laid flat on the table in front of the human, "
               "(c) the human alone from the stack\n"
            << "  per method: torso flexion deg / elbow at or above the shoulder / reach m / "
               "re-orientation left deg / comfort Q / RULA grand / REBA\n";
  std::cout << "  #  board          " << std::left << std::setw(32) << "(a) hila" << std::setw(32)
            << "(b) table"
            << "(c) alone" << std::right << "\n";
  for (const auto& b : j["boards"]) {
    std::cout << "  " << b["order"].get<int>() << "  " << std::left << std::setw(15)
              << b["part"].get<std::string>() << std::setw(32)
              << cell_text(b.value("hila", nlohmann::json())) << std::setw(32)
              << cell_text(b.value("table", nlohmann::json()))
              << cell_text(b.value("alone", nlohmann::json())) << std::right << "\n";
  }
  std::cout << "  boards bent forward (>= " << kBentForwardDeg << " deg): hila "
            << j["summary"]["hila"]["bent_forward"].get<int>() << ", table "
            << j["summary"]["table"]["bent_forward"].get<int>() << ", alone "
            << j["summary"]["alone"]["bent_forward"].get<int>() << "\n";
  // The scores' distributions: boards per RULA grand score and per REBA risk level.
  auto distribution = [](const nlohmann::json& counts) {
    std::ostringstream s;
    for (const auto& [key, n] : counts.items()) {
      s << (s.tellp() > 0 ? ", " : "") << key << ": " << n.get<int>();
    }
    return s.tellp() > 0 ? s.str() : std::string("none");
  };
  for (const char* method : kMethods) {
    const auto& m = j["summary"][method];
    std::cout << "  " << std::left << std::setw(6) << method << std::right
              << "RULA grand (boards by score) " << distribution(m["rula_grand"]) << "; mean "
              << std::setprecision(2) << m["mean_rula_grand"].get<double>()
              << "; REBA (boards by risk) " << distribution(m["reba_risk"]) << "; mean "
              << m["mean_reba"].get<double>() << "; scored " << m["scored"].get<int>() << " of "
              << m["boards"].get<int>() << "\n";
  }
  for (const char* baseline : {"alone", "table"}) {
    const auto& v = j["verdicts_hila_vs"][baseline];
    std::cout << "  hila vs " << baseline << ": bent forward "
              << v["bent_forward"].get<std::string>() << "; shoulder work "
              << v["shoulder_work"].get<std::string>() << "; reaching "
              << v["reaching"].get<std::string>() << "; re-orientation "
              << v["reorientation"].get<std::string>() << "; comfort "
              << v["comfort"].get<std::string>() << "; RULA " << v["rula"].get<std::string>()
              << "; REBA " << v["reba"].get<std::string>() << "\n";
  }
  return 0;
}

}  // namespace

void add_report_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<ReportOptions>();
  auto* report = app.add_subcommand("report", "Reports computed from a product database");
  report
      ->add_option("what", opt->what,
                   "ergonomics (a table), or html (a page with a 3D viewer and charts, -o)")
      ->required();
  report->add_option("database", opt->database, "database file")->required();
  report->add_flag("--json", opt->json, "print JSON (ergonomics)");
  report->add_option("--plan", opt->html.plan_file, "html: a plan file (hila plan -o) to animate");
  report->add_option("--scene", opt->html.scene, "html: the plan's scene (default: the plan's)");
  report->add_option("--cell", opt->html.cell_file,
                     "ergonomics, html without --plan: the database's cell YAML (default: the "
                     "bundled)");
  report->add_option("--product", opt->html.product_file,
                     "ergonomics (the parts' symmetries), html without --plan: the database's "
                     "product YAML (default: the cabinet)");
  report->add_option("-o,--output", opt->html.output, "html: the page to write");
  report->add_option("--three-js", opt->html.three_dir, "html: three.js folder (libjs-three)")
      ->capture_default_str();
  report->callback([opt, &action] { action = [opt] { return run_report(*opt); }; });
}

}  // namespace hila::tools
