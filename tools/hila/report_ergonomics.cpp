#include "report_ergonomics.hpp"

#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/human_comfort.hpp"
#include "plan_sequence.hpp"
#include "worker_postures.hpp"

namespace hila::tools {

namespace {

// EAWS (the paper's Table 2): the torso counts as bent forward from 20 degrees.
constexpr double kBentForwardDeg = 20.0;
// RULA grand scores of action levels 1 and 2 ("acceptable", "investigate further"): what the
// issue asks of every handover (BoardPlanSettings::natural_max_rula).
const int kAcceptableRula = online::BoardPlanSettings{}.natural_max_rula;

// The scene of the database's product bundled with hila (meshes/PRODUCT/scene.yaml), as the
// cabinet's; refused where there is none.
std::string bundled_scene(const std::string& database) {
  db::OpenOptions options;
  options.comfort_maps = false;
  const std::string product = db::Database::open(database, options).meta().product_name;
  const std::string path = default_scene_path(product);
  std::error_code error;
  if (path.empty() || !std::filesystem::is_regular_file(path, error)) {
    throw core::InputError("command line", "--scene",
                           "a scene file (docs/scene.md) for the database's product '" + product +
                               "' (hila bundles none" + (path.empty() ? "" : ": no " + path) + ")",
                           "none");
  }
  return path;
}

// The workers asked for, else the database's worker set, else the scene's worker, else the
// cell's own human.
std::vector<ReportWorker> report_workers(const ReportErgonomicsOptions& opt,
                                         const ErgonomicsContext& context) {
  const core::Cell& cell = context.model->cell();
  std::vector<ReportWorker> workers;
  auto add = [&](const std::vector<core::HumanBodySpec>& bodies, const std::string& from,
                 const std::string& where, const std::string& field) {
    for (const auto& spec : bodies) {
      workers.push_back({core::human_body_label(spec), from,
                         std::make_shared<const core::HumanBody>(cell, spec, where, field)});
    }
  };
  if (opt.workers_given) {
    add(offline::parse_human_bodies(opt.workers, "--workers"), "--workers", "command line",
        "--workers");
  } else if (const std::string& stored = context.model->database().meta().human_bodies;
             !stored.empty()) {
    add(offline::parse_stored_human_bodies(stored, opt.database), "database", opt.database,
        "meta.human_bodies");
  } else if (context.scene.worker != nullptr) {
    workers.push_back({context.scene.worker->label(), "scene", context.scene.worker});
  } else {
    workers.push_back({"cell human", "cell", nullptr});
  }
  return workers;
}

// Where the part's centre is against the worker's hip and shoulder heights.
std::string centre_band(const online::PostureCheck& c) {
  if (c.part_centre_z > c.shoulder_z) return "above the shoulder";
  if (c.part_centre_z < c.hip_z) return "below the hip";
  return "in band";
}

// The elbow at or above the shoulder taking the board or turning it to its fitted orientation
// (EAWS shoulder work), for a scored posture.
bool elbow_up_turning(const TakenPosture& t) {
  return t.turn && t.turn->elevated_steps > 0;
}
bool does_shoulder_work(const TakenPosture& t) {
  return t.scored && (!t.ergonomics.check.elbow_below_shoulder || elbow_up_turning(t));
}

nlohmann::json taken_json(const TakenPosture& t, bool planned) {
  nlohmann::json m = {{"status", t.status}, {"scored", t.scored}};
  if (planned && t.status == "solved") {
    m.update({{"goal_rank", t.goal_rank},
              {"candidate", t.candidate},
              {"way", t.way},
              {"natural_posture", t.natural_posture}});
  }
  if (!t.scored) {
    m["why"] = t.why;
    return m;
  }
  const online::PostureCheck& c = t.ergonomics.check;
  const online::ReceivingScores& s = t.ergonomics.scores;
  nlohmann::json joints = nlohmann::json::object();
  for (const auto& [arm, q] : t.joints)
    joints[arm] = std::vector<double>(q.data(), q.data() + q.size());
  m.update({{"arm", t.arm},
            {"joints_rad", joints},
            {"torso_flexion_deg", t.torso_flexion_deg},
            {"bent_forward", t.torso_flexion_deg >= kBentForwardDeg},
            {"elbow_below_shoulder", c.elbow_below_shoulder},
            {"part_centre_z", c.part_centre_z},
            {"hip_z", c.hip_z},
            {"shoulder_z", c.shoulder_z},
            {"centre", centre_band(c)},
            {"upright", c.upright()},
            {"natural", c.natural(kAcceptableRula)},
            {"rula_grand", s.rula().grand},
            {"reba", s.reba().reba},
            {"reach", t.reach},
            {"reorientation_deg", t.reorientation_deg},
            {"quality", t.quality},
            {"two_hands", s.two_hands},
            {"load_kg", s.load_kg},
            {"ergonomics", receiving_ergonomics_json(t.ergonomics)}});
  if (t.turn) {
    const offline::Turn& turn = *t.turn;
    m["turn"] = {{"turned_deg", turn.turned_deg},
                 {"steps", turn.postures.size()},
                 {"reachable", turn.reachable},
                 {"blocked_steps", turn.blocked_steps},
                 {"elbow_up_steps", turn.elevated_steps},
                 {"max_torso_flexion_deg", turn.max_flexion_deg},
                 {"point", {turn.point.x(), turn.point.y(), turn.point.z()}}};
  }
  m["shoulder_work"] = does_shoulder_work(t);
  return m;
}

// A method's figures over a set of boards (its scored postures).
struct Totals {
  int boards = 0;
  int scored = 0;
  int bent = 0;
  int elbow_up = 0;       // an elbow at or above its shoulder at the take
  int turn_elbow_up = 0;  // ... while turning the board to its fitted orientation
  int shoulder_work = 0;  // either
  int in_band = 0;
  int upright = 0;
  int natural = 0;
  int rula_acceptable = 0;
  double reach = 0.0;
  double reorientation = 0.0;
  double quality = 0.0;
  double rula_sum = 0.0;
  double reba_sum = 0.0;
  std::map<int, int> rula, reba;                      // boards by RULA grand score, by REBA score
  std::map<std::string, int> rula_action, reba_risk;  // by action level, by risk level

  void add(const TakenPosture& t) {
    ++boards;
    if (!t.scored) return;
    const online::PostureCheck& c = t.ergonomics.check;
    const int grand = t.ergonomics.scores.rula().grand;
    const int score = t.ergonomics.scores.reba().reba;
    ++scored;
    bent += t.torso_flexion_deg >= kBentForwardDeg ? 1 : 0;
    elbow_up += c.elbow_below_shoulder ? 0 : 1;
    turn_elbow_up += elbow_up_turning(t) ? 1 : 0;
    shoulder_work += does_shoulder_work(t) ? 1 : 0;
    in_band += c.part_centre_z >= c.hip_z && c.part_centre_z <= c.shoulder_z ? 1 : 0;
    upright += c.upright() ? 1 : 0;
    natural += c.natural(kAcceptableRula) ? 1 : 0;
    rula_acceptable += grand <= kAcceptableRula ? 1 : 0;
    reach += t.reach;
    reorientation += t.reorientation_deg;
    quality += t.quality;
    rula_sum += grand;
    reba_sum += score;
    ++rula[grand];
    ++reba[score];
    ++rula_action[std::to_string(core::rula_action_level(grand))];
    ++reba_risk[core::reba_risk_level(score)];
  }
  double mean(double sum) const { return scored > 0 ? sum / scored : 0.0; }

  nlohmann::json json() const {
    nlohmann::json by_rula = nlohmann::json::object(), by_reba = nlohmann::json::object();
    for (const auto& [score, n] : rula) by_rula[std::to_string(score)] = n;
    for (const auto& [score, n] : reba) by_reba[std::to_string(score)] = n;
    return {{"boards", boards},
            {"scored", scored},
            {"bent_forward", bent},
            {"elbow_at_or_above_shoulder", elbow_up},
            {"elbow_up_turning", turn_elbow_up},
            {"shoulder_work", shoulder_work},
            {"centre_in_band", in_band},
            {"upright", upright},
            {"natural", natural},
            {"rula_acceptable", rula_acceptable},
            {"mean_reach", mean(reach)},
            {"mean_reorientation_deg", mean(reorientation)},
            {"mean_quality", mean(quality)},
            {"rula_grand", by_rula},
            {"rula_action_level", rula_action},
            {"mean_rula_grand", mean(rula_sum)},
            {"reba_score", by_reba},
            {"reba_risk", reba_risk},
            {"mean_reba", mean(reba_sum)}};
  }
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

// hila against a baseline on the boards both have a scored posture for.
nlohmann::json verdict(const WorkerPostures& w, const std::string& baseline) {
  Totals a, b;
  for (const auto& row : w.boards) {
    const TakenPosture& ours = row.by_method.at("hila");
    const TakenPosture& theirs = row.by_method.at(baseline);
    if (!ours.scored || !theirs.scored) continue;
    a.add(ours);
    b.add(theirs);
  }
  return {{"boards", a.scored},
          {"bent_forward", fewer(a.bent, b.bent, "eliminated")},
          {"shoulder_work", fewer(a.shoulder_work, b.shoulder_work, "eliminated")},
          {"upright", a.upright > b.upright   ? "more"
                      : a.upright < b.upright ? "fewer"
                                              : "the same"},
          {"reaching", compare(a.mean(a.reach), b.mean(b.reach), 0.02, "shorter", "longer")},
          {"reorientation", compare(a.mean(a.reorientation), b.mean(b.reorientation), 2.0,
                                    "decreased", "increased")},
          {"comfort", compare(-a.mean(a.quality), -b.mean(b.quality), 0.005, "more comfortable",
                              "less comfortable")},
          {"rula", compare(a.mean(a.rula_sum), b.mean(b.rula_sum), 0.05, "lower", "higher")},
          {"reba", compare(a.mean(a.reba_sum), b.mean(b.reba_sum), 0.05, "lower", "higher")}};
}

nlohmann::json worker_json(const WorkerPostures& w, std::map<std::string, Totals>& all) {
  nlohmann::json who = {{"label", w.worker.label}, {"from", w.worker.from}};
  if (w.worker.body != nullptr) {
    who["stature"] = w.worker.body->spec().stature;
    who["sex"] = w.worker.body->spec().sex == core::Sex::Male ? "male" : "female";
  } else {
    who["stature"] = nullptr;
    who["sex"] = nullptr;
  }
  nlohmann::json boards = nlohmann::json::array();
  std::map<std::string, Totals> totals;
  for (const auto& row : w.boards) {
    nlohmann::json b = {{"board", row.board}, {"order", row.order}, {"symmetries", row.symmetries}};
    for (const char* method : kErgonomicsMethods) {
      const TakenPosture& t = row.by_method.at(method);
      b[method] = taken_json(t, std::string(method) == "hila");
      totals[method].add(t);
      all[method].add(t);
    }
    boards.push_back(b);
  }
  nlohmann::json summary = nlohmann::json::object();
  for (const char* method : kErgonomicsMethods) summary[method] = totals[method].json();
  return {{"worker", who},
          {"hip_z", w.band.hip_z},
          {"shoulder_z", w.band.shoulder_z},
          {"boards", boards},
          {"summary", summary},
          {"verdicts_hila_vs", {{"alone", verdict(w, "alone")}, {"table", verdict(w, "table")}}}};
}

std::string cell_text(const nlohmann::json& m) {
  if (!m["scored"].get<bool>()) {
    const std::string status = m["status"].get<std::string>();
    if (status == "unreachable" || status == "not evaluated") return status;
    if (status == "reachable") return "not scored";
    return status == "solved" ? "not scored" : "not planned (" + status + ")";
  }
  const std::string centre = m["centre"].get<std::string>();
  std::ostringstream s;
  s << std::fixed << std::setprecision(0) << m["torso_flexion_deg"].get<double>() << "/"
    << (m["elbow_below_shoulder"].get<bool>() ? "--" : "up") << "/"
    << (centre == "in band"         ? "in"
        : centre == "below the hip" ? "low"
                                    : "high")
    << "/" << std::setprecision(2) << m["reach"].get<double>() << "/" << std::setprecision(0)
    << m["reorientation_deg"].get<double>() << "/" << std::setprecision(3)
    << m["quality"].get<double>() << "/" << m["rula_grand"].get<int>() << "/"
    << m["reba"].get<int>() << "/";
  if (!m.contains("turn")) {
    s << "--";
  } else if (!m["turn"]["reachable"].get<bool>()) {
    s << "unreachable";
  } else if (m["turn"]["blocked_steps"].get<int>() > 0) {
    s << "blocked";
  } else {
    s << (m["turn"]["steps"].get<std::size_t>() == 0   ? "--"
          : m["turn"]["elbow_up_steps"].get<int>() > 0 ? "up"
                                                       : "ok");
  }
  return s.str();
}

// `text` padded to `width` columns, and at least one space after it.
std::string column(const std::string& text, std::size_t width) {
  return text + std::string(text.size() < width ? width - text.size() : 1, ' ');
}

// "3: 2, 4: 1", or "none".
std::string distribution(const nlohmann::json& counts) {
  std::ostringstream s;
  for (const auto& [key, n] : counts.items()) {
    s << (s.tellp() > 0 ? ", " : "") << key << ": " << n.get<int>();
  }
  return s.tellp() > 0 ? s.str() : std::string("none");
}

// What a method's count of scored postures is of: planned boards, or reached ones.
const char* scored_what(const std::string& method) {
  return method == "hila" ? "planned" : "reached";
}

void print_worker(const nlohmann::json& w) {
  const auto& who = w["worker"];
  std::cout << who["label"].get<std::string>() << " (" << who["from"].get<std::string>() << "; hip "
            << std::fixed << std::setprecision(2) << w["hip_z"].get<double>() << " m, shoulder "
            << w["shoulder_z"].get<double>() << " m)\n";
  std::cout << "  #  board          " << std::left << std::setw(32) << "(a) hila" << std::setw(32)
            << "(b) table"
            << "(c) alone" << std::right << "\n";
  for (const auto& b : w["boards"]) {
    std::cout << "  " << b["order"].get<int>() << "  " << column(b["board"].get<std::string>(), 15)
              << column(cell_text(b["hila"]), 32) << column(cell_text(b["table"]), 32)
              << cell_text(b["alone"]) << "\n";
  }
  const auto& s = w["summary"];
  auto counts = [&](const char* key) {
    std::ostringstream o;
    o << "hila " << s["hila"][key].get<int>() << ", table " << s["table"][key].get<int>()
      << ", alone " << s["alone"][key].get<int>();
    return o.str();
  };
  std::cout << "  bent forward (>= " << std::setprecision(0) << kBentForwardDeg
            << " deg): " << counts("bent_forward") << "; upright: " << counts("upright")
            << "; RULA <= " << kAcceptableRula << ": " << counts("rula_acceptable")
            << "; shoulder work (elbow at or above the shoulder taking or turning it): "
            << counts("shoulder_work") << "\n";
  for (const char* method : kErgonomicsMethods) {
    const auto& m = s[method];
    std::cout << "  " << std::left << std::setw(6) << method << std::right
              << "RULA grand (boards by score) " << distribution(m["rula_grand"]) << "; mean "
              << std::setprecision(2) << m["mean_rula_grand"].get<double>()
              << "; REBA (boards by risk) " << distribution(m["reba_risk"]) << "; mean "
              << m["mean_reba"].get<double>() << "; scored " << m["scored"].get<int>() << " of "
              << m["boards"].get<int>() << "\n";
  }
  for (const char* baseline : {"alone", "table"}) {
    const auto& v = w["verdicts_hila_vs"][baseline];
    std::cout << "  hila vs " << baseline << " (" << v["boards"].get<int>()
              << " boards scored by both): bent forward " << v["bent_forward"].get<std::string>()
              << "; shoulder work " << v["shoulder_work"].get<std::string>() << "; upright "
              << v["upright"].get<std::string>() << "; reaching "
              << v["reaching"].get<std::string>() << "; re-orientation "
              << v["reorientation"].get<std::string>() << "; comfort "
              << v["comfort"].get<std::string>() << "; RULA " << v["rula"].get<std::string>()
              << "; REBA " << v["reba"].get<std::string>() << "\n";
  }
}

void print_report(const nlohmann::json& j) {
  std::cout << "ergonomics of " << j["product"].get<std::string>() << " in "
            << j["scene"].get<std::string>()
            << ": (a) hila's planned handover, (b) laid flat on the table in front of the worker, "
               "(c) the worker alone from the stack\n"
            << "  per method: torso flexion deg / elbow at or above the shoulder (up) / part "
               "centre in the hip-shoulder band (in, high, low) / reach m / re-orientation left "
               "deg / comfort Q / RULA grand / REBA / turning it to its fitted orientation in "
               "front of the worker (ok, up: an elbow at or above the shoulder, blocked: the board "
               "runs into the body at every turning point, --: nothing to turn)\n";
  for (const auto& w : j["workers"]) print_worker(w);
  const auto& all = j["all_workers"];
  std::cout << "all workers (" << j["workers"].size() << "):";
  const char* separator = " ";
  for (const char* method : kErgonomicsMethods) {
    const auto& m = all[method];
    std::cout << separator << method << " RULA <= " << kAcceptableRula << " on "
              << m["rula_acceptable"].get<int>() << " of " << m["scored"].get<int>() << " boards "
              << scored_what(method) << " (" << m["boards"].get<int>() << "), upright "
              << m["upright"].get<int>();
    separator = "; ";
  }
  std::cout << "\n";
}

}  // namespace

int run_report_ergonomics(const ReportErgonomicsOptions& opt) {
  // The workers' text first: a malformed item costs no loading.
  if (opt.workers_given) offline::parse_human_bodies(opt.workers, "--workers");
  const std::string scene = opt.scene.empty() ? bundled_scene(opt.database) : opt.scene;
  const ErgonomicsContext context = load_ergonomics_context(opt.database, scene);
  const std::vector<ReportWorker> workers = report_workers(opt, context);
  nlohmann::json per_worker = nlohmann::json::array();
  std::map<std::string, Totals> all;
  for (const ReportWorker& worker : workers) {
    per_worker.push_back(
        worker_json(worker_postures(context, worker, kDefaultBoardDeadlineSeconds), all));
  }
  nlohmann::json all_json = nlohmann::json::object();
  for (const char* method : kErgonomicsMethods) all_json[method] = all[method].json();
  const nlohmann::json j = {{"database", opt.database},
                            {"product", context.model->product().name},
                            {"scene", scene},
                            {"bent_forward_from_deg", kBentForwardDeg},
                            {"rula_acceptable_at_most", kAcceptableRula},
                            {"workers", per_worker},
                            {"all_workers", all_json}};
  if (opt.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    print_report(j);
  }
  return 0;
}

}  // namespace hila::tools
