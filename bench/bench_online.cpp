// The online planner side by side with the OMPL baselines (issue 6), in one process on the same
// problems with the same collision and slip checks. Run from the repository root:
//   build/release/bench/bench_online [--db out/cabinet.hila] [--variations 20] [--boards a,b]
//       [--deadline 10] [--planners hila,rrt_connect,lazy_prm] [--seed 1] [--json FILE]
// The database: --db, else $HILA_BENCH_DATABASE, else out/cabinet.hila (tools/demo builds it).
//
// Problems: each cabinet board in assembly order, its base scene the nominal one
// (meshes/cabinet/scene.yaml) with the boards before it finished, the tool in hand and the arms
// home after the first (as `hila plan --all` goes), times --variations seeded variations
// (bench/scene_variation.hpp: the board's detected pose moved and yawed, the human's stance
// moved, an extra box on the table). Every planner plans every problem with the same board
// deadline through BoardPlanner, which differs only in the motion planner
// (BoardPlanSettings::motion.planner): hila's stored roadmap, OMPL RRT-Connect from scratch, OMPL
// LazyPRM whose roadmaps persist between problems (one BoardPlanner per planner, reused). Every
// solved plan is re-checked independently (bench/plan_check.hpp); an invalid plan is reported
// loudly and makes the exit status 1.
//
// Output: markdown tables on stdout (per planner: success, median and p95 full-board plan time,
// median path length and motion duration; ratios to hila; per board; why plans failed),
// progress on stderr, and with --json every problem's figures.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hila/core/error.hpp"
#include "hila/online/board_planner.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/scene.hpp"
#include "plan_check.hpp"
#include "scene_variation.hpp"

using namespace hila;

namespace {

constexpr const char* kUsage =
    "usage: bench_online [--db FILE] [--scene FILE] [--variations N] [--boards a,b]\n"
    "                    [--deadline S] [--planners hila,rrt_connect,lazy_prm] [--seed N]\n"
    "                    [--overlap-validation yes|no] [--held-resolution RAD]\n"
    "                    [--variants fixed,cheapest,fixed+eq8] [--json FILE]\n"
    "  --db          the cabinet database (default: $HILA_BENCH_DATABASE, else\n"
    "                out/cabinet.hila)\n"
    "  --scene       the nominal scene (default: meshes/cabinet/scene.yaml)\n"
    "  --variations  seeded scene variations per board (default 20)\n"
    "  --boards      only these boards (default: all, in assembly order)\n"
    "  --deadline    seconds per board plan (default 10)\n"
    "  --planners    which planners (default: all three)\n"
    "  --seed        base seed of the variations (default 1)\n"
    "  --overlap-validation\n"
    "                validate each motion on a second thread while the next is planned\n"
    "                (BoardPlanSettings::overlap_validation, default yes)\n"
    "  --held-resolution\n"
    "                rad between the checked samples of a held board's motions, for every\n"
    "                planner (MotionSettings::held_resolution, default 0.04)\n"
    "  --variants    also hila with other settings, interleaved; each a '+'-joined list of:\n"
    "                fixed (each goal's ways in the order direct, regrasp, suction, exchange),\n"
    "                cheapest (every goal's ways by estimated robot time alone), eq8 (goals in\n"
    "                Eq. 8 order, natural receiving postures not first), inplace (a goal whose\n"
    "                exchanges the build found blocked tried in its place, not after the\n"
    "                others): fixed+eq8 is 0.14.0's\n"
    "  --json        also write every problem's figures to FILE\n";

constexpr const char* kBuildHint =
    "build it with `tools/demo`, or `build/release/tools/hila build meshes/cabinet/product.yaml "
    "--cell meshes/cell/cell.yaml -o out/cabinet.hila --jobs 2` (about a minute), or point --db or "
    "HILA_BENCH_DATABASE at one";

struct Options {
  std::string database;
  std::string scene = HILA_DATA_DIR "/cabinet/scene.yaml";
  int variations = 20;
  std::vector<std::string> boards;
  double deadline = 10.0;
  double held_resolution = online::MotionSettings{}.held_resolution;
  std::vector<online::MotionPlannerKind> planners = {online::MotionPlannerKind::kRoadmap,
                                                     online::MotionPlannerKind::kRrtConnect,
                                                     online::MotionPlannerKind::kLazyPrm};
  std::uint64_t seed = 1;
  bool overlap_validation = true;
  struct Variant {
    std::string name;
    online::WayOrder way_order = online::WayOrder::kEstimatedTime;
    bool natural_posture_first = true;
    bool blocked_exchanges_last = true;
  };
  std::vector<Variant> variants;  // extra hila variants
  std::string json;
};

[[noreturn]] void usage_error(const std::string& what) {
  std::cerr << "bench_online: " << what << "\n" << kUsage;
  std::exit(2);
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

Options parse(int argc, char** argv) {
  Options opt;
  if (const char* env = std::getenv("HILA_BENCH_DATABASE"); env != nullptr && *env != '\0') {
    opt.database = env;
  } else {
    opt.database = "out/cabinet.hila";
  }
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (i + 1 >= argc) usage_error(arg + ": expected a value or an option, got the end");
    const std::string value = argv[++i];
    try {
      if (arg == "--db") {
        opt.database = value;
      } else if (arg == "--scene") {
        opt.scene = value;
      } else if (arg == "--variations") {
        opt.variations = std::stoi(value);
        if (opt.variations < 1) usage_error("--variations: expected at least 1, got " + value);
      } else if (arg == "--boards") {
        opt.boards = split_list(value);
      } else if (arg == "--held-resolution") {
        opt.held_resolution = std::stod(value);
        if (!(opt.held_resolution > 0.0 && opt.held_resolution <= 0.05)) {
          usage_error("--held-resolution: expected rad in (0, 0.05], got " + value);
        }
      } else if (arg == "--deadline") {
        opt.deadline = std::stod(value);
        if (!(opt.deadline > 0.0)) usage_error("--deadline: expected seconds > 0, got " + value);
      } else if (arg == "--planners") {
        opt.planners.clear();
        for (const auto& name : split_list(value)) {
          bool known = false;
          for (const auto kind :
               {online::MotionPlannerKind::kRoadmap, online::MotionPlannerKind::kRrtConnect,
                online::MotionPlannerKind::kLazyPrm}) {
            if (name == online::to_string(kind)) {
              opt.planners.push_back(kind);
              known = true;
            }
          }
          if (!known) {
            usage_error("--planners: expected hila, rrt_connect or lazy_prm, got '" + name + "'");
          }
        }
        if (opt.planners.empty()) usage_error("--planners: expected at least one planner");
      } else if (arg == "--seed") {
        opt.seed = std::stoull(value);
      } else if (arg == "--overlap-validation") {
        if (value != "yes" && value != "no") {
          usage_error("--overlap-validation: expected yes or no, got '" + value + "'");
        }
        opt.overlap_validation = value == "yes";
      } else if (arg == "--variants") {
        for (const auto& name : split_list(value)) {
          Options::Variant v;
          v.name = name;
          std::stringstream parts(name);
          for (std::string part; std::getline(parts, part, '+');) {
            if (part == "fixed") {
              v.way_order = online::WayOrder::kFixed;
            } else if (part == "cheapest") {
              v.way_order = online::WayOrder::kCheapestFirst;
            } else if (part == "eq8") {
              v.natural_posture_first = false;
            } else if (part == "inplace") {
              v.blocked_exchanges_last = false;
            } else {
              usage_error(
                  "--variants: expected fixed, cheapest, eq8 or inplace joined by '+', "
                  "got '" +
                  name + "'");
            }
          }
          opt.variants.push_back(v);
        }
      } else if (arg == "--json") {
        opt.json = value;
      } else {
        usage_error("unknown option '" + arg + "'");
      }
    } catch (const std::logic_error&) {  // stoi and friends: not a number, out of range
      usage_error(arg + ": expected a number, got '" + value + "'");
    }
  }
  return opt;
}

// One planner on one problem.
struct Result {
  bool solved = false;
  std::string status;
  std::string reason;
  double seconds = 0.0;
  online::PlanTimes times;  // of seconds
  double path_length = 0.0;
  double duration = 0.0;
  int attempts = 0;
  int goal_rank = -1;
  double quality = 0.0;            // the scene's human's comfort Q at the goal
  double estimated_seconds = 0.0;  // the chosen way's estimated robot time
  double theta_c_deg = 0.0;
  std::string why_failed;               // the most frequent attempt outcome (failures)
  std::map<std::string, int> outcomes;  // every attempt's outcome in full, with its count
  std::vector<std::string> invalidity;  // solved but rejected by the re-check
  int checked_samples = 0;
  int motions_planned = 0;        // BoardPlan::motions_planned
  int human_postures_solved = 0;  // BoardPlan::human_postures_solved
  bool invalid() const { return solved && !invalidity.empty(); }
};

struct Problem {
  std::string board;
  int variation = 0;
  bench::VariedScene varied;
  std::vector<Result> results;  // per planner, in Options::planners order
};

// "step: status" of an attempt's outcome ("receiving_grasp: no path: the straight ..."), the
// part that says where and how a chain failed without the scene-specific detail.
std::string outcome_key(const std::string& outcome) {
  const auto first = outcome.find(": ");
  if (first == std::string::npos) return outcome.substr(0, 120);
  const auto second = outcome.find(": ", first + 2);
  return outcome.substr(0, std::min<std::size_t>(second, 120));
}

std::string why_failed(const online::BoardPlan& plan) {
  std::map<std::string, int> count;
  for (const auto& a : plan.attempts) {
    if (a.result == online::AttemptResult::kFailed) {
      ++count[outcome_key(a.outcome)];
    }
  }
  std::string best;
  int most = 0;
  for (const auto& [key, n] : count) {
    if (n > most) {
      best = key;
      most = n;
    }
  }
  const std::string status = online::to_string(plan.status);
  if (best.empty()) return status + (plan.attempts.empty() ? ": " + plan.reason : "");
  return status + ", mostly " + best;
}

Result run(online::BoardPlanner& planner, const online::PlannerModel& model,
           const online::BoardPlanSettings& settings, const online::Scene& scene,
           const std::string& board, double deadline_s) {
  Result r;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(static_cast<long>(deadline_s * 1e6));
  online::BoardPlan plan;
  try {
    plan = planner.plan(scene, board, deadline);
  } catch (const std::exception& e) {
    // The planner reports failures as statuses; an exception is a bug worth seeing in the table.
    r.status = "error";
    r.reason = e.what();
    r.why_failed = std::string("error: ") + e.what();
    return r;
  }
  r.solved = plan.solved();
  r.status = online::to_string(plan.status);
  r.reason = plan.reason;
  r.seconds = plan.planning_seconds;
  r.times = plan.times;
  r.attempts = static_cast<int>(plan.attempts.size());
  r.motions_planned = plan.motions_planned;
  r.human_postures_solved = plan.human_postures_solved;
  for (const auto& a : plan.attempts) ++r.outcomes[a.outcome];
  if (!r.solved) {
    r.why_failed = why_failed(plan);
    return r;
  }
  r.path_length = plan.path_length;
  r.duration = plan.duration;
  r.goal_rank = plan.goal_rank;
  r.quality = plan.quality;
  r.estimated_seconds = plan.estimated_seconds;
  r.theta_c_deg = plan.theta_c_deg;
  try {
    const bench::PlanCheck check = bench::check_plan(model, scene, plan, settings);
    r.invalidity = check.problems;
    r.checked_samples = check.samples;
  } catch (const std::exception& e) {
    r.invalidity.push_back(std::string("the re-check failed: ") + e.what());
  }
  return r;
}

// Linear interpolation between the closest ranks; NaN for no values.
double quantile(std::vector<double> v, double p) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double h = p * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(h));
  const auto hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (h - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

std::string fixed(double x, int digits) {
  if (!std::isfinite(x)) return "–";
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << x;
  return s.str();
}

struct Summary {
  int problems = 0;
  int solved = 0;
  int timeouts = 0;
  int invalid = 0;
  double median_s = 0, p95_s = 0, median_all_s = 0, p95_all_s = 0;
  double median_path = 0, median_duration = 0;
  // Medians over the solved problems of where the time went (online::PlanTimes).
  double median_motions_s = 0, median_smoothing_s = 0, median_validation_s = 0;
  double median_queued_smoothing_s = 0;
  double p95_motions_s = 0;
};

Summary summarise(const std::vector<Problem>& problems, std::size_t planner) {
  Summary s;
  std::vector<double> solved_s, all_s, path, duration, motions, smoothing, validation;
  std::vector<double> queued_smoothing;
  for (const auto& p : problems) {
    const Result& r = p.results[planner];
    ++s.problems;
    all_s.push_back(r.seconds);
    if (r.status == "timeout") ++s.timeouts;
    if (!r.solved) continue;
    ++s.solved;
    if (r.invalid()) ++s.invalid;
    solved_s.push_back(r.seconds);
    path.push_back(r.path_length);
    duration.push_back(r.duration);
    motions.push_back(r.times.motions);
    smoothing.push_back(r.times.smoothing);
    queued_smoothing.push_back(r.times.queued_smoothing);
    validation.push_back(r.times.validation);
  }
  s.median_s = quantile(solved_s, 0.5);
  s.p95_s = quantile(solved_s, 0.95);
  s.median_all_s = quantile(all_s, 0.5);
  s.p95_all_s = quantile(all_s, 0.95);
  s.median_path = quantile(path, 0.5);
  s.median_duration = quantile(duration, 0.5);
  s.median_motions_s = quantile(motions, 0.5);
  s.p95_motions_s = quantile(motions, 0.95);
  s.median_smoothing_s = quantile(smoothing, 0.5);
  s.median_queued_smoothing_s = quantile(queued_smoothing, 0.5);
  s.median_validation_s = quantile(validation, 0.5);
  return s;
}

nlohmann::json result_json(const Result& r) {
  nlohmann::json j = {{"status", r.status},
                      {"reason", r.reason},
                      {"planning_s", r.seconds},
                      {"planning_split_s",
                       {{"motions", r.times.motions},
                        {"smoothing", r.times.smoothing},
                        {"validation", r.times.validation},
                        {"queued_validation", r.times.queued_validation},
                        {"queued_smoothing", r.times.queued_smoothing}}},
                      {"attempts", r.attempts},
                      {"solved", r.solved},
                      {"why_failed", r.why_failed},
                      {"outcomes", r.outcomes}};
  if (r.solved) {
    j["path_length_rad"] = r.path_length;
    j["duration_s"] = r.duration;
    j["goal_rank"] = r.goal_rank;
    j["quality"] = r.quality;
    j["estimated_s"] = r.estimated_seconds;
    j["theta_c_deg"] = r.theta_c_deg;
    j["valid"] = !r.invalid();
    j["invalidity"] = r.invalidity;
    j["checked_samples"] = r.checked_samples;
    j["motions_planned"] = r.motions_planned;
    j["human_postures_solved"] = r.human_postures_solved;
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  if (!std::filesystem::exists(opt.database)) {
    std::cerr << "bench_online: no database at '" << opt.database << "': " << kBuildHint << "\n";
    return 2;
  }
  std::shared_ptr<const online::PlannerModel> model;
  online::Scene nominal;
  try {
    const online::SceneFiles files = online::read_scene_files(opt.scene);
    model = online::PlannerModel::load(opt.database, files.cell, files.product);
    nominal = online::load_scene(opt.scene, model->cell(), model->product());
    // The comfort maps are read on the first varied stance: at start-up here, so that the first
    // problem's first variant is not charged the file's reading (a few hundred ms).
    model->load_worker_comfort();
  } catch (const core::InputError& e) {
    std::cerr << "bench_online: " << e.what() << "\n(" << kBuildHint << ")\n";
    return 2;
  }
  const core::ProductSpec& product = model->product();

  // The boards in assembly order, each with its base scene: the boards before it finished.
  std::vector<std::pair<const core::PartSpec*, online::Scene>> boards;
  online::Scene scene = nominal;
  for (const auto& part : product.parts) {
    const bool wanted = opt.boards.empty() || std::find(opt.boards.begin(), opt.boards.end(),
                                                        part.name) != opt.boards.end();
    if (wanted) boards.emplace_back(&part, scene);
    scene = scene.with_finished(product, part.name);
    scene.tool_in_hand = true;
    for (const auto& arm : model->cell().arms()) scene.robot[arm.spec.name] = arm.spec.home;
  }
  for (const auto& name : opt.boards) {
    if (std::none_of(product.parts.begin(), product.parts.end(),
                     [&](const auto& p) { return p.name == name; })) {
      std::string known;
      for (const auto& p : product.parts) known += (known.empty() ? "" : ", ") + p.name;
      usage_error("--boards: expected boards of " + product.file + " (" + known + "), got '" +
                  name + "'");
    }
  }

  // One BoardPlanner per planner, reused for every problem: LazyPRM keeps its roadmaps.
  std::vector<online::BoardPlanSettings> settings;
  std::vector<std::unique_ptr<online::BoardPlanner>> planners;
  std::vector<std::string> names;
  for (const auto kind : opt.planners) {
    online::BoardPlanSettings s;
    s.motion.planner = kind;
    s.overlap_validation = opt.overlap_validation;
    s.motion.held_resolution = opt.held_resolution;
    settings.push_back(s);
    planners.push_back(std::make_unique<online::BoardPlanner>(*model, s));
    names.emplace_back(online::to_string(kind));
  }
  for (const auto& v : opt.variants) {  // after the planners: their indices stay
    online::BoardPlanSettings s;
    s.overlap_validation = opt.overlap_validation;
    s.motion.held_resolution = opt.held_resolution;
    s.way_order = v.way_order;
    s.natural_posture_first = v.natural_posture_first;
    s.blocked_exchanges_last = v.blocked_exchanges_last;
    settings.push_back(s);
    planners.push_back(std::make_unique<online::BoardPlanner>(*model, s));
    names.push_back("hila (" + v.name + ")");
  }

  std::vector<Problem> problems;
  const std::size_t total = boards.size() * static_cast<std::size_t>(opt.variations);
  int invalid = 0;
  const auto started = std::chrono::steady_clock::now();
  for (const auto& [part, base] : boards) {
    for (int v = 0; v < opt.variations; ++v) {
      Problem problem;
      problem.board = part->name;
      problem.variation = v;
      // Distinct per board and variation, the same for every planner and every run.
      const std::uint64_t seed = opt.seed * 1000000u +
                                 1000u * static_cast<std::uint64_t>(part->order) +
                                 static_cast<std::uint64_t>(v);
      try {
        problem.varied = bench::vary_scene(base, model->cell(), product, part->name, seed);
      } catch (const std::exception& e) {
        std::cerr << "bench_online: " << e.what() << "\n";
        return 3;
      }
      std::cerr << "[" << problems.size() + 1 << "/" << total << "] " << part->name << " v" << v
                << " (seed " << seed << "):";
      for (std::size_t k = 0; k < planners.size(); ++k) {
        Result r =
            run(*planners[k], *model, settings[k], problem.varied.scene, part->name, opt.deadline);
        std::cerr << "  " << names[k] << " " << r.status << " " << fixed(r.seconds, 2) << " s";
        if (r.invalid()) {
          ++invalid;
          std::cerr << "\n!!! INVALID PLAN: " << names[k] << " " << part->name << " v" << v << ":";
          for (const auto& why : r.invalidity) std::cerr << "\n!!!   " << why;
          std::cerr << "\n";
        }
        problem.results.push_back(std::move(r));
      }
      std::cerr << std::endl;
      problems.push_back(std::move(problem));
    }
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  // Per planner.
  std::vector<Summary> summary;
  for (std::size_t k = 0; k < planners.size(); ++k) summary.push_back(summarise(problems, k));
  std::cout << "## bench_online: " << boards.size() << " boards x " << opt.variations
            << " variations, deadline " << fixed(opt.deadline, 1) << " s per board, held-board "
            << "checks every " << fixed(opt.held_resolution, 3) << " rad, "
            << std::thread::hardware_concurrency() << " hardware threads, wall "
            << fixed(wall / 60.0, 1) << " min\n\n"
            << "Plan times are full-board BoardPlan::planning_seconds over the solved problems; "
               "\"all\" counts every problem with the time it took to succeed or give up.\n\n"
            << "| planner | solved | success | median s | p95 s | median s (all) | p95 s (all) "
               "| median path rad | median motion s | timeouts | invalid |\n"
            << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (std::size_t k = 0; k < planners.size(); ++k) {
    const Summary& s = summary[k];
    std::cout << "| " << names[k] << " | " << s.solved << "/" << s.problems << " | "
              << fixed(100.0 * s.solved / std::max(1, s.problems), 0) << " % | "
              << fixed(s.median_s, 3) << " | " << fixed(s.p95_s, 3) << " | "
              << fixed(s.median_all_s, 3) << " | " << fixed(s.p95_all_s, 3) << " | "
              << fixed(s.median_path, 2) << " | " << fixed(s.median_duration, 1) << " | "
              << s.timeouts << " | " << s.invalid << " |\n";
  }
  std::cout
      << "\nWhere the time went (medians over the solved problems, s; online::PlanTimes): the "
         "motions' planning is what the planners differ in, smoothing and the timing with "
         "the validator's re-check are the same work for all. Smoothing is on the planner's "
         "thread; queued, on the second thread (or the first, helping at the end) with the "
         "validation, mostly alongside the planning.\n\n"
      << "| planner | full board | motions | motions p95 | smoothing | smoothing (queued) | "
         "timing + validation |\n"
      << "| --- | --- | --- | --- | --- | --- | --- |\n";
  for (std::size_t k = 0; k < planners.size(); ++k) {
    const Summary& s = summary[k];
    std::cout << "| " << names[k] << " | " << fixed(s.median_s, 4) << " | "
              << fixed(s.median_motions_s, 4) << " | " << fixed(s.p95_motions_s, 4) << " | "
              << fixed(s.median_smoothing_s, 4) << " | " << fixed(s.median_queued_smoothing_s, 4)
              << " | " << fixed(s.median_validation_s, 4) << " |\n";
  }

  // Ratios to hila: over each planner's own solved problems, and over the problems both solved
  // (the fairer one when the success rates differ: the hard problems drop out of one side only).
  const auto hila =
      std::find(opt.planners.begin(), opt.planners.end(), online::MotionPlannerKind::kRoadmap);
  if (hila != opt.planners.end() && planners.size() > 1) {
    const auto h = static_cast<std::size_t>(hila - opt.planners.begin());
    std::cout << "\nRatios baseline / hila (> 1: hila is faster or shorter).\n\n"
              << "| baseline | median | p95 | both solved | median (both) | p95 (both) "
                 "| motions median (both) | motions p95 (both) | path (both) | only hila solved "
                 "| only baseline solved |\n"
              << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
    for (std::size_t k = 0; k < planners.size(); ++k) {
      if (k == h) continue;
      std::vector<double> bh, bb, ph, pb, mh, mb;
      int only_hila = 0, only_baseline = 0;
      for (const auto& p : problems) {
        const Result& rh = p.results[h];
        const Result& rb = p.results[k];
        only_hila += rh.solved && !rb.solved;
        only_baseline += !rh.solved && rb.solved;
        if (rh.solved && rb.solved) {
          bh.push_back(rh.seconds);
          bb.push_back(rb.seconds);
          ph.push_back(rh.path_length);
          pb.push_back(rb.path_length);
          mh.push_back(rh.times.motions);
          mb.push_back(rb.times.motions);
        }
      }
      std::cout << "| " << names[k] << " | " << fixed(summary[k].median_s / summary[h].median_s, 2)
                << " | " << fixed(summary[k].p95_s / summary[h].p95_s, 2) << " | " << bh.size()
                << " | " << fixed(quantile(bb, 0.5) / quantile(bh, 0.5), 2) << " | "
                << fixed(quantile(bb, 0.95) / quantile(bh, 0.95), 2) << " | "
                << fixed(quantile(mb, 0.5) / quantile(mh, 0.5), 2) << " | "
                << fixed(quantile(mb, 0.95) / quantile(mh, 0.95), 2) << " | "
                << fixed(quantile(pb, 0.5) / quantile(ph, 0.5), 2) << " | " << only_hila << " | "
                << only_baseline << " |\n";
    }
  }

  // Per board: solved and the median plan time of the solved.
  std::cout << "\nPer board: solved / problems, median plan s of the solved.\n\n| board |";
  for (const auto& n : names) std::cout << " " << n << " |";
  std::cout << "\n| --- |";
  for (std::size_t k = 0; k < names.size(); ++k) std::cout << " --- |";
  std::cout << "\n";
  for (const auto& [part, base] : boards) {
    std::cout << "| " << part->name << " |";
    for (std::size_t k = 0; k < planners.size(); ++k) {
      std::vector<double> t;
      int n = 0;
      for (const auto& p : problems) {
        if (p.board != part->name) continue;
        ++n;
        if (p.results[k].solved) t.push_back(p.results[k].seconds);
      }
      std::cout << " " << t.size() << "/" << n << ", " << fixed(quantile(t, 0.5), 2) << " |";
    }
    std::cout << "\n";
  }

  // Why plans failed: per planner and board, the failed problems by their most frequent cause.
  std::cout << "\nFailures by planner and board (count x status and the most frequent attempt "
               "outcome, deadline notes left out):\n\n";
  bool any_failure = false;
  for (std::size_t k = 0; k < planners.size(); ++k) {
    for (const auto& [part, base] : boards) {
      std::map<std::string, int> causes;
      for (const auto& p : problems) {
        if (p.board == part->name && !p.results[k].solved) ++causes[p.results[k].why_failed];
      }
      for (const auto& [cause, n] : causes) {
        std::cout << "- " << names[k] << " / " << part->name << ": " << n << " x " << cause << "\n";
        any_failure = true;
      }
    }
  }
  if (!any_failure) std::cout << "- none\n";

  if (invalid > 0) {
    std::cout << "\n**INVALID PLANS: " << invalid
              << "** (solved plans the independent re-check rejected; details on stderr and in "
                 "--json)\n";
    std::cerr << "bench_online: " << invalid << " INVALID PLAN(S)\n";
  } else {
    std::cout << "\nInvalid plans: 0 (every solved plan passed the independent re-check).\n";
  }

  if (!opt.json.empty()) {
    nlohmann::json out = {{"bench_online", 1},
                          {"database", opt.database},
                          {"scene", opt.scene},
                          {"variations", opt.variations},
                          {"deadline_s", opt.deadline},
                          {"seed", opt.seed},
                          {"held_resolution", opt.held_resolution},
                          {"overlap_validation", opt.overlap_validation},
                          {"hardware_threads", std::thread::hardware_concurrency()},
                          {"wall_s", wall},
                          {"planners", names},
                          {"problems", nlohmann::json::array()},
                          {"summary", nlohmann::json::object()}};
    for (const auto& p : problems) {
      const auto& v = p.varied;
      nlohmann::json j = {{"board", p.board},
                          {"variation", p.variation},
                          {"seed", v.seed},
                          {"board_shift_m", {v.board_shift.x(), v.board_shift.y()}},
                          {"board_yaw_deg", v.board_yaw_deg},
                          {"board_redraws", v.board_redraws},
                          {"stance_shift_m", {v.stance_shift.x(), v.stance_shift.y()}},
                          {"box",
                           {{"side_m", v.box_side},
                            {"centre", {v.box_centre.x(), v.box_centre.y(), v.box_centre.z()}},
                            {"yaw_deg", v.box_yaw_deg}}},
                          {"results", nlohmann::json::object()}};
      for (std::size_t k = 0; k < names.size(); ++k)
        j["results"][names[k]] = result_json(p.results[k]);
      out["problems"].push_back(j);
    }
    for (std::size_t k = 0; k < names.size(); ++k) {
      const Summary& s = summary[k];
      out["summary"][names[k]] = {{"problems", s.problems},
                                  {"solved", s.solved},
                                  {"timeouts", s.timeouts},
                                  {"invalid", s.invalid},
                                  {"median_s", s.median_s},
                                  {"p95_s", s.p95_s},
                                  {"median_all_s", s.median_all_s},
                                  {"p95_all_s", s.p95_all_s},
                                  {"median_path_rad", s.median_path},
                                  {"median_duration_s", s.median_duration},
                                  {"median_motions_s", s.median_motions_s},
                                  {"p95_motions_s", s.p95_motions_s},
                                  {"median_smoothing_s", s.median_smoothing_s},
                                  {"median_queued_smoothing_s", s.median_queued_smoothing_s},
                                  {"median_validation_s", s.median_validation_s}};
    }
    // NaN (no solved problem) is not JSON: written as null.
    std::ofstream file(opt.json);
    file << out.dump(1) << "\n";
    if (!file) {
      std::cerr << "bench_online: --json: could not write '" << opt.json << "'\n";
      return 2;
    }
  }
  return invalid > 0 ? 1 : 0;
}
