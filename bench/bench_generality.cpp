// How general the planner is (issue 37, item 8): products nobody tuned for, built and planned
// end to end, and the cabinet's stack moved over the pick region. Run from the repository root:
//
//   tools/dev/gen_products --seed 1 --count 20 --out /tmp/gen1
//   build/release/bench/bench_generality --products /tmp/gen1 [--jobs 2] [--seed 1] [--quick]
//       [--only p00,p03] [--deadline 30] [--keep-db] [--reuse-db] [--json FILE]
//       [--meta KEY=VALUE ...]
//   build/release/bench/bench_generality --pick-region 50 --db /tmp/cabinet.hila
//       [--scene meshes/cabinet/scene.yaml] [--region 0.10] [--seed 1] [--deadline 10]
//       [--stack-pose DX,DY,YAW_DEG]... [--json FILE]
//
// Products (--products DIR: every DIR/pNN/ with a product.yaml and a scene.yaml, in name
// order): each product's database is built with offline::build_database (default BuildSettings
// with --seed and --jobs; --quick: the small settings of tests/util/quick_build.hpp, for smoke
// runs) into a temporary directory (--keep-db: DIR/pNN/product.hila; --reuse-db: use that file
// when it is there, no build), then every part is planned in assembly order from the product's
// scene exactly as `hila plan --all` does (tools/hila/cmd_plan.cpp): one BoardPlanner, each
// scene the last one with the part finished, the tool in hand and the arms home, whether or not
// the part was planned. Every solved plan is re-checked independently (bench/plan_check.hpp).
// Reported per product and overall: parts delivered / parts, every undelivered part's reason
// (the planner's status with its most frequent attempt outcome, and the build's
// handover_failure when the build found no goal), the build time, the plan time median and p95
// over the delivered parts, and whether each delivered plan validated. A part whose start pose
// touches something (the robot at home, the tool, a finished part: a generator bug) is flagged.
//
// Pick region (--pick-region N): the cabinet (--db, --scene) with its whole stack, every board
// not yet finished and the board to plan together, moved by a seeded offset in
// [-region, region]^2 m and a yaw in [-180, 180) deg about the stack's centre (the centre of the
// boards' footprint in the scene); N such stack poses, each planned board by board in assembly
// order as above. A pose where a board would touch something at its stage (the tool, the robot,
// the finished boards) is not a detection a camera could make: it is drawn again, and the
// redraws are counted. Reported: boards planned / boards, per board, and the reasons.
//
// Output: markdown tables on stdout, progress on stderr, with --json every figure. Recorded
// runs: bench/results/generality_*.json, rendered into docs/bench.md by tools/dev/render_bench
// (the raw --json output in bench/results/raw/).
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/offline/build.hpp"
#include "hila/online/board_planner.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/receiving_scores.hpp"
#include "hila/online/scene.hpp"
#include "hila/online/world.hpp"
#include "plan_check.hpp"

using namespace hila;
namespace fs = std::filesystem;

namespace {

constexpr const char* kUsage =
    "usage: bench_generality --products DIR [--jobs N] [--seed N] [--quick] [--only p00,p01]\n"
    "                        [--deadline S] [--keep-db] [--reuse-db] [--json FILE]\n"
    "                        [--way-order time|fixed|cheapest] [--meta KEY=VALUE]...\n"
    "       bench_generality --pick-region N --db FILE [--scene FILE] [--region M] [--seed N]\n"
    "                        [--stack-pose DX,DY,YAW_DEG]...\n"
    "                        [--deadline S] [--json FILE] [--meta KEY=VALUE]...\n"
    "  --products    a directory of products (tools/dev/gen_products): DIR/pNN/product.yaml\n"
    "                and DIR/pNN/scene.yaml\n"
    "  --jobs        build threads (default 2)\n"
    "  --seed        the build seed (default 1); with --pick-region, the stack poses' seed\n"
    "  --quick       small build settings (tests/util/quick_build.hpp): a smoke run\n"
    "  --only        only these product directories\n"
    "  --deadline    seconds per part plan (default 30 as `hila plan`; 10 with --pick-region)\n"
    "  --keep-db     build into DIR/pNN/product.hila (default: a temporary directory)\n"
    "  --reuse-db    plan with DIR/pNN/product.hila where it exists instead of building\n"
    "  --pick-region N stack poses of the cabinet (--db, --scene)\n"
    "  --db          the cabinet database for --pick-region\n"
    "  --scene       its nominal scene (default: meshes/cabinet/scene.yaml)\n"
    "  --region      m, the stack's offset in x and y is uniform in +-this (default 0.10)\n"
    "  --stack-pose  DX,DY,YAW_DEG: plan this stack pose (m, m, deg; repeatable) instead of\n"
    "                drawn ones, touching or not\n"
    "  --way-order   each goal's ways by estimated robot time (time, the default), in the\n"
    "                fixed order direct, regrasp, suction, exchange (fixed), or every goal's\n"
    "                ways by estimate alone (cheapest) (BoardPlanSettings::way_order)\n"
    "  --json        also write every figure to FILE\n"
    "  --meta        KEY=VALUE recorded in the JSON (commit, machine, ...)\n";

struct Options {
  std::string products;
  int jobs = 2;
  std::uint64_t seed = 1;
  bool quick = false;
  std::vector<std::string> only;
  double deadline = -1.0;  // per mode default
  bool keep_db = false;
  bool reuse_db = false;
  int pick_region = 0;
  std::string db;
  std::string scene = HILA_DATA_DIR "/cabinet/scene.yaml";
  double region = 0.10;
  std::vector<Eigen::Vector3d> stack_poses;  // given (dx m, dy m, yaw deg) instead of drawn
  std::string json;
  std::map<std::string, std::string> meta;
  std::string command;
  online::WayOrder way_order = online::WayOrder::kEstimatedTime;
};

[[noreturn]] void usage_error(const std::string& what) {
  std::cerr << "bench_generality: " << what << "\n" << kUsage;
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
  for (int i = 0; i < argc; ++i) opt.command += (i ? " " : "") + std::string(argv[i]);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      std::exit(0);
    }
    if (arg == "--quick") {
      opt.quick = true;
      continue;
    }
    if (arg == "--keep-db") {
      opt.keep_db = true;
      continue;
    }
    if (arg == "--reuse-db") {
      opt.reuse_db = true;
      continue;
    }
    if (i + 1 >= argc) usage_error(arg + ": expected a value or an option, got the end");
    const std::string value = argv[++i];
    try {
      if (arg == "--products") {
        opt.products = value;
      } else if (arg == "--jobs") {
        opt.jobs = std::stoi(value);
        if (opt.jobs < 1) usage_error("--jobs: expected at least 1, got " + value);
      } else if (arg == "--seed") {
        opt.seed = std::stoull(value);
      } else if (arg == "--only") {
        opt.only = split_list(value);
      } else if (arg == "--deadline") {
        opt.deadline = std::stod(value);
        if (!(opt.deadline > 0.0)) usage_error("--deadline: expected seconds > 0, got " + value);
      } else if (arg == "--pick-region") {
        opt.pick_region = std::stoi(value);
        if (opt.pick_region < 1) usage_error("--pick-region: expected at least 1, got " + value);
      } else if (arg == "--db") {
        opt.db = value;
      } else if (arg == "--scene") {
        opt.scene = value;
      } else if (arg == "--region") {
        opt.region = std::stod(value);
        if (!(opt.region >= 0.0 && opt.region <= 0.5)) {
          usage_error("--region: expected metres in [0, 0.5], got " + value);
        }
      } else if (arg == "--stack-pose") {
        const auto v = split_list(value);
        if (v.size() != 3) usage_error("--stack-pose: expected DX,DY,YAW_DEG, got '" + value + "'");
        opt.stack_poses.emplace_back(std::stod(v[0]), std::stod(v[1]), std::stod(v[2]));
      } else if (arg == "--way-order") {
        if (value == "time") {
          opt.way_order = online::WayOrder::kEstimatedTime;
        } else if (value == "fixed") {
          opt.way_order = online::WayOrder::kFixed;
        } else if (value == "cheapest") {
          opt.way_order = online::WayOrder::kCheapestFirst;
        } else {
          usage_error("--way-order: expected time, fixed or cheapest, got '" + value + "'");
        }
      } else if (arg == "--json") {
        opt.json = value;
      } else if (arg == "--meta") {
        const auto eq = value.find('=');
        if (eq == std::string::npos || eq == 0) {
          usage_error("--meta: expected KEY=VALUE, got '" + value + "'");
        }
        opt.meta[value.substr(0, eq)] = value.substr(eq + 1);
      } else {
        usage_error("unknown option '" + arg + "'");
      }
    } catch (const std::logic_error&) {  // stoi and friends: not a number, out of range
      usage_error(arg + ": expected a number, got '" + value + "'");
    }
  }
  if (!opt.stack_poses.empty()) opt.pick_region = static_cast<int>(opt.stack_poses.size());
  if ((opt.pick_region > 0) == !opt.products.empty()) {
    usage_error("expected exactly one of --products DIR or --pick-region N (or --stack-pose)");
  }
  if (opt.pick_region > 0 && opt.db.empty()) usage_error("--pick-region: expected --db FILE");
  if (opt.deadline < 0.0) opt.deadline = opt.pick_region > 0 ? 10.0 : 30.0;
  return opt;
}

// The small settings of tests/util/quick_build.hpp (a complete build in seconds).
offline::BuildSettings quick_settings(offline::BuildSettings s) {
  s.robot.samples = 500;
  s.human.samples = 300;
  s.comfort.spacing = 0.06;
  s.comfort.orientations = 100;
  s.comfort.samples = 20000;
  s.handover.candidates = 60;
  s.handover.max_candidates = 60;
  s.handover.rr_poses = 6;
  s.handover.human_ik_goals = 2;
  s.ergonomics.flexion_step_deg = 15.0;
  s.roadmap.nodes = 300;
  return s;
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

nlohmann::json number(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
}

// A reason without its scene-specific numbers, so that equal causes group: every number but a
// plain 0 ("any of its 0 suction grasps" says something) becomes N.
std::string reason_key(const std::string& text, std::size_t max = 140) {
  static const std::regex numbers("[-+]?[0-9]+(\\.[0-9]+)?(e[-+]?[0-9]+)?");
  std::string key;
  auto last = text.cbegin();
  for (std::sregex_iterator it(text.begin(), text.end(), numbers), end; it != end; ++it) {
    key.append(last, text.cbegin() + it->position());
    key += it->str() == "0" ? "0" : "N";
    last = text.cbegin() + it->position() + it->length();
  }
  key.append(last, text.cend());
  if (key.size() > max) key = key.substr(0, max) + "…";
  return key;
}

// "step: status" of an attempt's outcome, as bench_online groups them.
std::string outcome_key(const std::string& outcome) {
  const auto first = outcome.find(": ");
  if (first == std::string::npos) return outcome.substr(0, 120);
  const auto second = outcome.find(": ", first + 2);
  return outcome.substr(0, std::min<std::size_t>(second, 120));
}

// One part (or cabinet board) planned.
struct PartResult {
  std::string name;
  std::string kind;  // from the generator's meta.json, when there is one
  int order = 0;
  bool delivered = false;
  std::string status;
  std::string reason;         // the planner's
  std::string top_outcome;    // the most frequent failed attempt outcome ("step: status")
  std::string build_failure;  // the build's handover_failure (no goal)
  std::string cause;          // the grouped reason of an undelivered part
  std::map<std::string, int> outcomes;
  double plan_s = 0.0;
  int attempts = 0;
  int goals = 0;
  int suction_grasps = 0;
  int robot_grasps = 0;
  bool validated = false;  // the planner's own validation of every step
  bool recheck_valid = false;
  std::vector<std::string> invalidity;
  double duration = 0.0;
  double path_length = 0.0;
  std::string start_collision;  // the part at its start pose touches this (empty: nothing)
  std::string way;              // "exchange", "direct" or "regrasp" (delivered parts)
  std::string delivering_arm;
  double quality = 0.0;            // the human's comfort Q at the goal delivered to (paper Eq. 4)
  int goal_rank = -1;              // its Eq. 8 rank
  bool natural_posture = false;    // the receiving posture natural (BoardPlan::natural_posture)
  int rula = 0;                    // its RULA grand score (the worse hand's; 0: not scored)
  std::int64_t candidate_id = 0;   // handover_candidates.id of that goal
  double estimated_seconds = 0.0;  // the chosen way's estimated robot time
  int motions_planned = 0;         // BoardPlan::motions_planned (every attempt's)
  bool tool_in_hand_after = true;  // the suction arm holds the tool after the part
  std::string tool_arm = online::kDefaultSuctionArm;  // the arm holding it then
  std::optional<core::Pose> tool_place;               // where the plan moved the tool to
};

std::string most_frequent_outcome(const online::BoardPlan& plan) {
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
  return best;
}

// What the part touches at its start pose in this scene, "" when nothing.
std::string start_collision(const online::PlannerModel& model, const online::Scene& scene,
                            const std::string& board) {
  const online::World world(model.cell(), model.product(), scene, board);
  core::CollisionData data = world.make_data();
  core::CollisionPair pair;
  if (!core::in_collision(world.stage().cell.model, data, {world.stage().board}, &pair)) return "";
  return core::describe_pair(world.stage().cell.model, pair);
}

PartResult plan_part(online::BoardPlanner& planner, const online::PlannerModel& model,
                     const online::BoardPlanSettings& settings, const online::Scene& scene,
                     const core::PartSpec& part, double deadline_s) {
  PartResult r;
  r.name = part.name;
  r.order = part.order;
  if (const auto* records = model.board_records(part.name)) {
    r.goals = static_cast<int>(records->goals.size());
    r.suction_grasps = static_cast<int>(records->suction_grasps.size());
    r.robot_grasps = static_cast<int>(records->robot_grasps.size());
    if (const auto* stage = model.database().handover_stage(records->part.id)) {
      r.build_failure = stage->failure;
    }
  }
  try {
    r.start_collision = start_collision(model, scene, part.name);
  } catch (const std::exception& e) {
    r.start_collision = std::string("(the check failed: ") + e.what() + ")";
  }
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::microseconds(static_cast<long>(deadline_s * 1e6));
  online::BoardPlan plan;
  try {
    plan = planner.plan(scene, part.name, deadline);
  } catch (const std::exception& e) {
    // The planner reports failures as statuses; an exception is a bug worth seeing.
    r.status = "error";
    r.reason = e.what();
    r.cause = std::string("error: ") + reason_key(e.what());
    return r;
  }
  r.delivered = plan.solved();
  if (r.delivered) {
    r.way = online::to_string(plan.mode);
    r.quality = plan.quality;
    r.goal_rank = plan.goal_rank;
    r.natural_posture = plan.natural_posture;
    const online::ReceivingScores scores = online::receiving_scores(model.cell(), plan, part.mass);
    r.rula = scores.scored ? scores.rula().grand : 0;
    r.candidate_id = plan.candidate_id;
    r.estimated_seconds = plan.estimated_seconds;
    r.delivering_arm = plan.delivering_arm;
    r.tool_in_hand_after = plan.tool_in_hand_after;
    r.tool_arm = plan.suction_arm;
    r.tool_place = plan.tool_place;
  } else {
    r.tool_in_hand_after = scene.tool_in_hand;
    r.tool_arm = scene.tool_arm;
  }
  r.status = online::to_string(plan.status);
  r.reason = plan.reason;
  r.plan_s = plan.planning_seconds;
  r.motions_planned = plan.motions_planned;
  r.attempts = static_cast<int>(plan.attempts.size());
  for (const auto& a : plan.attempts) ++r.outcomes[a.outcome];
  if (!r.delivered) {
    r.top_outcome = most_frequent_outcome(plan);
    if (r.goals == 0 && !r.build_failure.empty()) {
      r.cause = "no goal in the database: " + reason_key(r.build_failure);
    } else if (!r.top_outcome.empty()) {
      // The round ("(larger bridges) ") is in the JSON's outcomes; the cause groups by step.
      std::string top = r.top_outcome;
      if (top.rfind("(larger bridges) ", 0) == 0) top = top.substr(17);
      r.cause = r.status + ", mostly " + reason_key(top);
    } else {
      r.cause = r.status + ": " + reason_key(r.reason);
    }
    return r;
  }
  r.validated = plan.validated;
  r.duration = plan.duration;
  r.path_length = plan.path_length;
  try {
    const bench::PlanCheck check = bench::check_plan(model, scene, plan, settings);
    r.invalidity = check.problems;
  } catch (const std::exception& e) {
    r.invalidity.push_back(std::string("the re-check failed: ") + e.what());
  }
  r.recheck_valid = r.invalidity.empty() && r.validated;
  return r;
}

// Why a part was not delivered, in the two kinds: a physical impossibility in this cell
// (over the payload; nothing the gripper or the cup can take where it lies, out of every arm's
// reach there) or a limit of hila's planner (a way exists that hila does not try). Read from the
// build's reason, which the database keeps as text, and the planner's status.
struct Limit {
  bool physical = false;
  std::string what;
};

Limit limit_of(const PartResult& r) {
  if (r.delivered) return {};
  if (r.goals > 0 || r.build_failure.empty()) {
    return {false, "hila: goals stored, none planned in the scene (" + r.status + ")"};
  }
  const auto has = [&](const char* text) {
    return r.build_failure.find(text) != std::string::npos;
  };
  const bool no_gripper = has("no arm's gripper takes the part where it lies");
  if (has("no arm's gripper lifts it")) return {true, "physical: over every arm's payload"};
  if (no_gripper && has("over the payload")) {
    return {true, "physical: over the payload on the cup, and no gripper takes it where it lies"};
  }
  if (no_gripper && has("no suction grasp")) {
    return {true, "physical: no face for the cup, and no gripper takes it where it lies"};
  }
  if (has("out of both arms' reach")) {
    return {true, "physical: out of both arms' reach where the human takes it comfortably"};
  }
  // Both roles tried: neither arm's cup picks it where it lies (the swapped roles' reason says
  // so in its own words), and no gripper takes it there.
  const auto swapped = r.build_failure.find("with the roles swapped");
  if (no_gripper && swapped != std::string::npos &&
      r.build_failure.find("cannot pick the part by suction") < swapped &&
      r.build_failure.find("cannot pick the part by suction", swapped) != std::string::npos) {
    return {true, "physical: neither arm's cup nor any gripper takes it where it lies"};
  }
  // In the roles the build kept (the swapped roles' reason comes after theirs).
  if (no_gripper && r.build_failure.find("cannot pick the part by suction") < swapped) {
    return {false,
            "hila: the tool's arm cannot pick it by suction, no gripper takes it where it lies "
            "(the other arm would need the tool)"};
  }
  if (has("from where the part lies")) {
    return {false,
            "hila: a gripper picks it, but no comfortable goal with those grasps (an arm-to-arm "
            "handover or a regrasp on the table would be needed)"};
  }
  if (has("shares a grasp with a robot-robot handover pose")) {
    return {false, "hila: no comfortable goal shares a grasp with an exchange pose"};
  }
  return {false, "hila: " + reason_key(r.build_failure, 100)};
}

nlohmann::json part_json(const PartResult& r) {
  nlohmann::json j = {{"name", r.name},
                      {"order", r.order},
                      {"delivered", r.delivered},
                      {"status", r.status},
                      {"reason", r.reason},
                      {"plan_s", r.plan_s},
                      {"attempts", r.attempts},
                      {"goals", r.goals},
                      {"suction_grasps", r.suction_grasps},
                      {"robot_grasps", r.robot_grasps},
                      {"build_failure", r.build_failure},
                      {"start_collision", r.start_collision},
                      {"outcomes", r.outcomes},
                      {"motions_planned", r.motions_planned}};
  if (!r.kind.empty()) j["kind"] = r.kind;
  if (r.delivered) {
    j["validated"] = r.validated;
    j["recheck_valid"] = r.recheck_valid;
    j["invalidity"] = r.invalidity;
    j["duration_s"] = r.duration;
    j["path_length_rad"] = r.path_length;
    j["way"] = r.way;
    j["delivering_arm"] = r.delivering_arm;
    j["quality"] = r.quality;
    j["goal_rank"] = r.goal_rank;
    j["natural_posture"] = r.natural_posture;
    j["rula"] = r.rula;
    j["candidate"] = r.candidate_id;
    j["estimated_s"] = r.estimated_seconds;
  } else {
    const Limit limit = limit_of(r);
    j["cause"] = r.cause;
    j["top_outcome"] = r.top_outcome;
    j["limit"] = limit.what;
    j["physical"] = limit.physical;
  }
  return j;
}

// Plans every part not yet finished in assembly order, each scene following from the last as in
// `hila plan --all`.
std::vector<PartResult> plan_all(online::BoardPlanner& planner, const online::PlannerModel& model,
                                 const online::BoardPlanSettings& settings, online::Scene scene,
                                 double deadline_s, const std::string& label) {
  std::vector<PartResult> results;
  const auto& parts = model.product().parts;
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const auto& part = parts[k];
    if (scene.is_finished(part.name)) continue;
    PartResult r = plan_part(planner, model, settings, scene, part, deadline_s);
    std::cerr << "  " << label << part.name << ": " << r.status << " " << fixed(r.plan_s, 2) << " s"
              << (r.delivered ? "" : "  (" + r.cause + ")")
              << (r.delivered && !r.recheck_valid ? "  !!! INVALID" : "")
              << (r.start_collision.empty() ? "" : "  [start touches " + r.start_collision + "]")
              << std::endl;
    const bool tool_in_hand = r.tool_in_hand_after;
    const std::string tool_arm = r.tool_arm;
    const std::optional<core::Pose> tool_place = r.tool_place;
    results.push_back(std::move(r));
    scene = scene.with_finished(model.product(), part.name);
    scene.tool_in_hand = tool_in_hand;
    scene.tool_arm = tool_arm;
    if (tool_place) scene.tool = *tool_place;
    for (const auto& arm : model.cell().arms()) scene.robot[arm.spec.name] = arm.spec.home;
  }
  return results;
}

std::string now_utc() {
  const std::time_t t = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return text;
}

nlohmann::json header_json(const Options& opt) {
  nlohmann::json j = {
      {"bench_generality", 1},      {"command", opt.command},
      {"date_utc", now_utc()},      {"hardware_threads", std::thread::hardware_concurrency()},
      {"deadline_s", opt.deadline}, {"seed", opt.seed}};
  for (const auto& [k, v] : opt.meta) j["meta"][k] = v;
  return j;
}

bool write_json(const std::string& path, const nlohmann::json& j) {
  std::ofstream file(path);
  file << j.dump(1) << "\n";
  if (!file) {
    std::cerr << "bench_generality: --json: could not write '" << path << "'\n";
    return false;
  }
  return true;
}

// A cause table: count x cause, most frequent first.
void print_causes(const std::map<std::string, int>& causes) {
  std::vector<std::pair<int, std::string>> sorted;
  sorted.reserve(causes.size());
  for (const auto& [cause, n] : causes) sorted.emplace_back(n, cause);
  std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
    return a.first != b.first ? a.first > b.first : a.second < b.second;
  });
  if (sorted.empty()) std::cout << "- none\n";
  for (const auto& [n, cause] : sorted) std::cout << "- " << n << " x " << cause << "\n";
}

// ------------------------------------------------------------------------------------ products

struct ProductResult {
  std::string dir;
  std::string name;
  std::string style;   // meta.json
  std::string layout;  // meta.json
  bool built = false;
  bool reused = false;
  std::string error;  // the build or the load failed
  double build_s = std::nan("");
  int parts_total = 0;
  std::vector<PartResult> parts;
  int delivered() const {
    return static_cast<int>(
        std::count_if(parts.begin(), parts.end(), [](const auto& p) { return p.delivered; }));
  }
};

int run_products(const Options& opt) {
  std::vector<fs::path> dirs;
  if (!fs::is_directory(opt.products)) {
    usage_error("--products: no directory '" + opt.products + "'");
  }
  for (const auto& entry : fs::directory_iterator(opt.products)) {
    if (!entry.is_directory()) continue;
    if (!fs::exists(entry.path() / "product.yaml") || !fs::exists(entry.path() / "scene.yaml")) {
      continue;
    }
    const std::string name = entry.path().filename().string();
    if (!opt.only.empty() && std::find(opt.only.begin(), opt.only.end(), name) == opt.only.end()) {
      continue;
    }
    dirs.push_back(entry.path());
  }
  std::sort(dirs.begin(), dirs.end());
  if (dirs.empty()) usage_error("--products: no pNN/product.yaml + scene.yaml in " + opt.products);

  offline::BuildSettings build_settings;
  build_settings.seed = opt.seed;
  build_settings.jobs = opt.jobs;
  if (opt.quick) build_settings = quick_settings(build_settings);
  fs::path temp_dir;
  if (!opt.keep_db) {
    temp_dir = fs::temp_directory_path() / ("bench_generality." + std::to_string(::getpid()));
    fs::create_directories(temp_dir);
  }
  online::BoardPlanSettings plan_settings;
  plan_settings.way_order = opt.way_order;

  std::vector<ProductResult> results;
  const auto started = std::chrono::steady_clock::now();
  int invalid = 0;
  for (const auto& dir : dirs) {
    ProductResult pr;
    pr.dir = dir.filename().string();
    const std::string product_file = (dir / "product.yaml").string();
    const std::string scene_file = (dir / "scene.yaml").string();
    std::map<std::string, std::string> kinds;
    if (std::ifstream meta_in(dir / "meta.json"); meta_in) {
      try {
        const auto meta = nlohmann::json::parse(meta_in);
        pr.style = meta.value("style", "");
        pr.layout = meta.value("layout", "");
        for (const auto& p : meta.at("parts")) kinds[p.at("name")] = p.value("kind", "");
      } catch (const std::exception& e) {
        std::cerr << "bench_generality: " << (dir / "meta.json").string() << ": " << e.what()
                  << " (ignored)\n";
      }
    }
    const fs::path db_path =
        opt.keep_db || opt.reuse_db ? dir / "product.hila" : temp_dir / (pr.dir + ".hila");
    std::cerr << "[" << results.size() + 1 << "/" << dirs.size() << "] " << pr.dir << std::endl;
    try {
      const online::SceneFiles files = online::read_scene_files(scene_file);
      if (opt.reuse_db && fs::exists(db_path)) {
        pr.reused = true;
      } else {
        const auto t0 = std::chrono::steady_clock::now();
        const offline::BuildSummary summary =
            offline::build_database(files.product, files.cell, db_path.string(), build_settings);
        pr.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        pr.built = true;
        std::cerr << "  built in " << fixed(pr.build_s, 1) << " s\n";
      }
      const auto model = online::PlannerModel::load(db_path.string(), files.cell, files.product);
      pr.name = model->product().name;
      pr.parts_total = static_cast<int>(model->product().parts.size());
      const online::Scene scene = online::load_scene(scene_file, model->cell(), model->product());
      online::BoardPlanner planner(*model, plan_settings);
      pr.parts = plan_all(planner, *model, plan_settings, scene, opt.deadline, "");
      for (auto& p : pr.parts) {
        if (kinds.count(p.name)) p.kind = kinds[p.name];
        if (p.delivered && !p.recheck_valid) ++invalid;
      }
    } catch (const std::exception& e) {
      pr.error = e.what();
      std::cerr << "  ERROR: " << pr.error << "\n";
    }
    if (!opt.keep_db && !pr.reused) {
      std::error_code ignored;
      fs::remove(db_path, ignored);
    }
    results.push_back(std::move(pr));
  }
  if (!temp_dir.empty()) {
    std::error_code ignored;
    fs::remove_all(temp_dir, ignored);
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  // Overall.
  int parts = 0, delivered = 0, products_all = 0, errors = 0;
  std::vector<double> plan_s, build_s, plan_all_s;
  std::map<std::string, int> causes;
  std::map<std::string, int> limits;  // Limit::what of the undelivered parts
  int physical = 0;
  // Delivered at a goal below the build's comfort threshold (HandoverSettings::comfort_floor).
  const double threshold = offline::HandoverSettings{}.comfort_threshold;
  int below_threshold = 0;
  int natural = 0, rula_low = 0;  // delivered with a natural posture; with RULA <= 3
  std::map<std::string, std::pair<int, int>> by_kind;  // delivered, parts
  for (const auto& pr : results) {
    if (!pr.error.empty()) ++errors;
    if (std::isfinite(pr.build_s)) build_s.push_back(pr.build_s);
    parts += pr.parts_total;
    delivered += pr.delivered();
    if (pr.parts_total > 0 && pr.delivered() == pr.parts_total) ++products_all;
    for (const auto& p : pr.parts) {
      plan_all_s.push_back(p.plan_s);
      if (p.delivered) {
        plan_s.push_back(p.plan_s);
        below_threshold += p.quality <= threshold;
        natural += p.natural_posture;
        rula_low += p.rula > 0 && p.rula <= 3;
      } else {
        ++causes[p.cause];
        const Limit limit = limit_of(p);
        ++limits[limit.what];
        physical += limit.physical;
      }
      auto& k = by_kind[p.kind.empty() ? "?" : p.kind];
      k.first += p.delivered;
      ++k.second;
    }
    if (!pr.error.empty()) causes["product not planned: " + reason_key(pr.error)] += pr.parts_total;
  }
  std::cout << "## bench_generality: " << results.size() << " products from " << opt.products
            << ", " << (opt.quick ? "quick" : "default") << " build settings (seed " << opt.seed
            << ", " << opt.jobs << " jobs), deadline " << fixed(opt.deadline, 0) << " s per part, "
            << std::thread::hardware_concurrency() << " hardware threads, wall "
            << fixed(wall / 60.0, 1) << " min\n\n"
            << "| products | all parts delivered | parts delivered | share | build s median | "
               "build s max | plan s median | plan s p95 | plan s p95 (all) | invalid | errors |\n"
            << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
            << "| " << results.size() << " | " << products_all << " | " << delivered << "/" << parts
            << " | " << fixed(100.0 * delivered / std::max(1, parts), 1) << " % | "
            << fixed(quantile(build_s, 0.5), 1) << " | "
            << fixed(build_s.empty() ? std::nan("")
                                     : *std::max_element(build_s.begin(), build_s.end()),
                     1)
            << " | " << fixed(quantile(plan_s, 0.5), 3) << " | " << fixed(quantile(plan_s, 0.95), 3)
            << " | " << fixed(quantile(plan_all_s, 0.95), 3) << " | " << invalid << " | " << errors
            << " |\n";

  std::cout << "\nPer product (plan times over its delivered parts; validated: the planner's "
               "validation and the independent re-check both passed).\n\n"
            << "| product | style | layout | parts | delivered | build s | plan s median | "
               "plan s p95 | validated |\n"
            << "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& pr : results) {
    std::vector<double> t;
    int valid = 0;
    for (const auto& p : pr.parts) {
      if (!p.delivered) continue;
      t.push_back(p.plan_s);
      valid += p.recheck_valid;
    }
    std::cout << "| " << pr.dir << " " << pr.name << " | " << pr.style << " | " << pr.layout
              << " | " << pr.parts_total << " | " << pr.delivered() << " | "
              << (pr.reused ? "reused" : fixed(pr.build_s, 1)) << " | "
              << fixed(quantile(t, 0.5), 3) << " | " << fixed(quantile(t, 0.95), 3) << " | "
              << valid << "/" << t.size()
              << (pr.error.empty() ? "" : " ERROR: " + reason_key(pr.error, 100)) << " |\n";
  }

  std::cout << "\nBy kind of part (the generator's meta.json): delivered / parts.\n\n"
            << "| kind | delivered |\n| --- | --- |\n";
  for (const auto& [kind, k] : by_kind) {
    std::cout << "| " << kind << " | " << k.first << "/" << k.second << " |\n";
  }

  std::cout << "\nDelivered below the comfort threshold (Q <= " << fixed(threshold, 2)
            << ", goals from the build's fallback down to its comfort floor): " << below_threshold
            << " of " << delivered << ".\n";
  std::cout << "\nReceived by the cell's human (online::receiving_scores): a natural posture "
               "(upright, RULA <= natural_max_rula) "
            << natural << ", RULA <= 3 " << rula_low << " of " << delivered << ".\n";
  std::cout << "\nWhy parts were not delivered: " << physical << " of " << parts - delivered
            << " physically impossible in this cell, the rest limits of hila's planner.\n\n";
  print_causes(limits);
  std::cout << "\nThe reasons in detail (grouped; numbers as N):\n\n";
  print_causes(causes);

  std::cout << "\nEvery undelivered part:\n\n| product | part | kind | status | cause |\n"
            << "| --- | --- | --- | --- | --- |\n";
  for (const auto& pr : results) {
    for (const auto& p : pr.parts) {
      if (p.delivered) continue;
      std::cout << "| " << pr.dir << " | " << p.name << " | " << p.kind << " | " << p.status
                << " | " << p.cause << " |\n";
    }
  }
  int touching = 0;
  for (const auto& pr : results) {
    for (const auto& p : pr.parts) touching += !p.start_collision.empty();
  }
  if (touching > 0) {
    std::cout << "\n**" << touching << " part(s) touch something at their start pose** (a "
              << "generator bug; --json: start_collision).\n";
  }
  if (invalid > 0) {
    std::cout << "\n**INVALID PLANS: " << invalid << "** (--json: invalidity)\n";
  } else {
    std::cout << "\nInvalid plans: 0 (every delivered plan passed the planner's validation and "
                 "the independent re-check).\n";
  }

  if (!opt.json.empty()) {
    nlohmann::json out = header_json(opt);
    out["mode"] = "products";
    out["products_dir"] = opt.products;
    out["build"] = {
        {"settings", opt.quick ? "quick" : "default"}, {"seed", opt.seed}, {"jobs", opt.jobs}};
    out["wall_s"] = wall;
    out["summary"] = {{"products", results.size()},
                      {"products_all_delivered", products_all},
                      {"parts", parts},
                      {"delivered", delivered},
                      {"share", parts ? static_cast<double>(delivered) / parts : 0.0},
                      {"build_s_median", number(quantile(build_s, 0.5))},
                      {"build_s_max",
                       number(build_s.empty() ? std::nan("")
                                              : *std::max_element(build_s.begin(), build_s.end()))},
                      {"plan_s_median", number(quantile(plan_s, 0.5))},
                      {"plan_s_p95", number(quantile(plan_s, 0.95))},
                      {"plan_s_p95_all", number(quantile(plan_all_s, 0.95))},
                      {"invalid", invalid},
                      {"errors", errors},
                      {"physical", physical},
                      {"below_comfort_threshold", below_threshold},
                      {"natural_posture", natural},
                      {"rula_le_3", rula_low},
                      {"limits", limits},
                      {"causes", causes}};
    out["products"] = nlohmann::json::array();
    for (const auto& pr : results) {
      std::vector<double> t;
      for (const auto& p : pr.parts) {
        if (p.delivered) t.push_back(p.plan_s);
      }
      nlohmann::json j = {{"dir", pr.dir},
                          {"name", pr.name},
                          {"style", pr.style},
                          {"layout", pr.layout},
                          {"parts", pr.parts_total},
                          {"delivered", pr.delivered()},
                          {"build_s", number(pr.build_s)},
                          {"reused_db", pr.reused},
                          {"plan_s_median", number(quantile(t, 0.5))},
                          {"plan_s_p95", number(quantile(t, 0.95))},
                          {"error", pr.error},
                          {"part_results", nlohmann::json::array()}};
      for (const auto& p : pr.parts) j["part_results"].push_back(part_json(p));
      out["products"].push_back(j);
    }
    if (!write_json(opt.json, out)) return 2;
  }
  return invalid > 0 ? 1 : 0;
}

// --------------------------------------------------------------------------------- pick region

struct StackPose {
  int index = 0;
  std::uint64_t seed = 0;
  Eigen::Vector2d offset = Eigen::Vector2d::Zero();
  double yaw_deg = 0.0;
  int redraws = 0;
  std::vector<std::string> redraw_causes;  // per redrawn pose: the first contact
  std::string touching;                    // a given pose (--stack-pose) that touches
  std::vector<PartResult> boards;
};

// Which board of the stack the suction tool, standing at its place on the table, touches in this
// scene, "" when none or when the suction arm holds it.
std::string tool_collision(const online::PlannerModel& model, const online::Scene& scene,
                           const std::string& board) {
  if (scene.tool_in_hand) return "";
  const online::World world(model.cell(), model.product(), scene, board);
  core::CollisionData data = world.make_data();
  std::vector<int> boards = world.stage().stacked;
  boards.push_back(world.stage().board);
  for (const int b : boards) {
    std::vector<int> bodies = world.stage().tool_bodies;
    bodies.push_back(b);
    core::CollisionPair pair;
    if (core::in_collision_among(world.stage().cell.model, data, bodies, &pair)) {
      return core::describe_pair(world.stage().cell.model, pair);
    }
  }
  return "";
}

// Whether a board touches something at its stage with the stack at the scene's detected poses
// (the robot at home, the tool, the finished boards), or the tool at its place touches the stack;
// the first contact, or "".
std::string stack_touches(const online::PlannerModel& model, online::Scene scene) {
  for (const auto& part : model.product().parts) {
    if (scene.is_finished(part.name)) continue;
    std::string hit = start_collision(model, scene, part.name);
    if (hit.empty()) hit = tool_collision(model, scene, part.name);
    if (!hit.empty()) return part.name + ": " + hit;
    scene = scene.with_finished(model.product(), part.name);
    scene.tool_in_hand = true;
    for (const auto& arm : model.cell().arms()) scene.robot[arm.spec.name] = arm.spec.home;
  }
  return "";
}

int run_pick_region(const Options& opt) {
  std::shared_ptr<const online::PlannerModel> model;
  online::Scene nominal;
  try {
    const online::SceneFiles files = online::read_scene_files(opt.scene);
    model = online::PlannerModel::load(opt.db, files.cell, files.product);
    nominal = online::load_scene(opt.scene, model->cell(), model->product());
  } catch (const core::InputError& e) {
    std::cerr << "bench_generality: " << e.what()
              << "\n(build the cabinet with `build/release/tools/hila build "
                 "meshes/cabinet/product.yaml --cell meshes/cell/cell.yaml -o /tmp/cabinet.hila "
                 "--jobs 2`)\n";
    return 2;
  }
  const core::ProductSpec& product = model->product();
  // The stack's centre: the centre of every unfinished board's footprint in the scene.
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e9), hi = Eigen::Vector2d::Constant(-1e9);
  for (const auto& part : product.parts) {
    if (nominal.is_finished(part.name)) continue;
    const core::Pose pose = nominal.initial_pose(part);
    for (const auto& v : part.mesh.vertices) {
      const Eigen::Vector3d w = pose * v;
      lo = lo.cwiseMin(w.head<2>());
      hi = hi.cwiseMax(w.head<2>());
    }
  }
  const Eigen::Vector2d centre = 0.5 * (lo + hi);
  online::BoardPlanSettings plan_settings;
  plan_settings.way_order = opt.way_order;
  online::BoardPlanner planner(*model, plan_settings);
  std::vector<StackPose> poses;
  int invalid = 0;
  constexpr int kTries = 1000;
  const auto started = std::chrono::steady_clock::now();
  for (int k = 0; k < opt.pick_region; ++k) {
    StackPose sp;
    sp.index = k;
    sp.seed = opt.seed * 1000003u + static_cast<std::uint64_t>(k);
    std::mt19937_64 rng(sp.seed);
    auto uniform = [&](double a, double b) {
      return std::uniform_real_distribution<double>(a, b)(rng);
    };
    online::Scene scene;
    const bool given = !opt.stack_poses.empty();
    for (int attempt = 0;; ++attempt) {
      if (attempt == kTries) {
        std::cerr << "bench_generality: no stack pose clear of the cell in " << kTries
                  << " draws (seed " << sp.seed << ")\n";
        return 3;
      }
      // One draw per statement: the order of draws is part of what the seed means.
      if (given) {
        const Eigen::Vector3d& g = opt.stack_poses[static_cast<std::size_t>(k)];
        sp.offset = g.head<2>();
        sp.yaw_deg = g.z();
      } else {
        sp.offset.x() = uniform(-opt.region, opt.region);
        sp.offset.y() = uniform(-opt.region, opt.region);
        sp.yaw_deg = uniform(-180.0, 180.0);
      }
      core::Pose move = core::Pose::Identity();
      move.linear() = Eigen::AngleAxisd(core::deg_to_rad(sp.yaw_deg), Eigen::Vector3d::UnitZ())
                          .toRotationMatrix();
      const Eigen::Vector3d c(centre.x(), centre.y(), 0.0);
      move.translation() =
          c + Eigen::Vector3d(sp.offset.x(), sp.offset.y(), 0.0) - move.linear() * c;
      scene = nominal;
      for (const auto& part : product.parts) {
        if (!nominal.is_finished(part.name)) {
          scene.detected[part.name] = move * nominal.initial_pose(part);
        }
      }
      sp.redraws = attempt;
      const std::string hit = stack_touches(*model, scene);
      if (hit.empty()) break;
      if (given) {
        sp.touching = hit;
        break;
      }
      sp.redraw_causes.push_back(hit);
    }
    std::cerr << "[" << k + 1 << "/" << opt.pick_region << "] stack moved ("
              << fixed(100 * sp.offset.x(), 1) << ", " << fixed(100 * sp.offset.y(), 1)
              << ") cm, yaw " << fixed(sp.yaw_deg, 1) << " deg, " << sp.redraws << " redraws"
              << (sp.touching.empty() ? "" : ", TOUCHING: " + sp.touching) << std::endl;
    sp.boards = plan_all(planner, *model, plan_settings, scene, opt.deadline, "");
    for (const auto& b : sp.boards) invalid += b.delivered && !b.recheck_valid;
    poses.push_back(std::move(sp));
  }
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  int boards = 0, planned = 0, all_planned = 0, redraws = 0;
  std::vector<double> plan_s;
  std::map<std::string, int> causes;
  std::map<std::string, std::pair<int, int>> by_board;
  std::map<std::string, int> redraw_causes;
  for (const auto& sp : poses) {
    redraws += sp.redraws;
    for (const auto& c : sp.redraw_causes) ++redraw_causes[reason_key(c)];
    int here = 0;
    for (const auto& b : sp.boards) {
      ++boards;
      ++by_board[b.name].second;
      if (b.delivered) {
        ++planned;
        ++here;
        ++by_board[b.name].first;
        plan_s.push_back(b.plan_s);
      } else {
        ++causes[b.name + ": " + b.cause];
      }
    }
    all_planned += here == static_cast<int>(sp.boards.size());
  }
  std::cout << "## bench_generality --pick-region: " << poses.size() << " stack poses of "
            << product.name << " (offset uniform in +-" << fixed(100 * opt.region, 0)
            << " cm in x and y, yaw in [-180, 180) deg about the stack's centre ("
            << fixed(centre.x(), 3) << ", " << fixed(centre.y(), 3) << ")), seed " << opt.seed
            << ", deadline " << fixed(opt.deadline, 0) << " s per board, wall "
            << fixed(wall / 60.0, 1) << " min\n\n"
            << "| stack poses | redrawn (touching) | all boards planned | boards planned | "
               "share | plan s median | plan s p95 | invalid |\n"
            << "| --- | --- | --- | --- | --- | --- | --- | --- |\n"
            << "| " << poses.size() << " | " << redraws << " | " << all_planned << " | " << planned
            << "/" << boards << " | " << fixed(100.0 * planned / std::max(1, boards), 1) << " % | "
            << fixed(quantile(plan_s, 0.5), 3) << " | " << fixed(quantile(plan_s, 0.95), 3) << " | "
            << invalid << " |\n\nPer board: planned / stack poses.\n\n| board | planned |\n"
            << "| --- | --- |\n";
  for (const auto& part : product.parts) {
    if (!by_board.count(part.name)) continue;
    const auto& [p, n] = by_board[part.name];
    std::cout << "| " << part.name << " | " << p << "/" << n << " |\n";
  }
  std::cout << "\nWhy boards were not planned (board: cause, grouped; numbers as N):\n\n";
  print_causes(causes);
  std::cout << "\nWhy drawn stack poses were drawn again (the first board, at its stage, that "
               "touches something: a pose no camera could report):\n\n";
  print_causes(redraw_causes);
  if (invalid > 0) std::cout << "\n**INVALID PLANS: " << invalid << "**\n";

  if (!opt.json.empty()) {
    nlohmann::json out = header_json(opt);
    out["mode"] = "pick_region";
    out["db"] = opt.db;
    out["scene"] = opt.scene;
    out["region_m"] = opt.region;
    out["stack_centre"] = {centre.x(), centre.y()};
    out["wall_s"] = wall;
    out["summary"] = {{"stack_poses", poses.size()},
                      {"redraws", redraws},
                      {"all_boards_planned", all_planned},
                      {"boards", boards},
                      {"planned", planned},
                      {"share", boards ? static_cast<double>(planned) / boards : 0.0},
                      {"plan_s_median", number(quantile(plan_s, 0.5))},
                      {"plan_s_p95", number(quantile(plan_s, 0.95))},
                      {"invalid", invalid},
                      {"causes", causes},
                      {"redraw_causes", redraw_causes}};
    out["stack_poses"] = nlohmann::json::array();
    for (const auto& sp : poses) {
      nlohmann::json j = {{"index", sp.index},
                          {"seed", sp.seed},
                          {"offset_m", {sp.offset.x(), sp.offset.y()}},
                          {"yaw_deg", sp.yaw_deg},
                          {"redraws", sp.redraws},
                          {"redraw_causes", sp.redraw_causes},
                          {"touching", sp.touching},
                          {"boards", nlohmann::json::array()}};
      for (const auto& b : sp.boards) j["boards"].push_back(part_json(b));
      out["stack_poses"].push_back(j);
    }
    if (!write_json(opt.json, out)) return 2;
  }
  return invalid > 0 ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  try {
    return opt.pick_region > 0 ? run_pick_region(opt) : run_products(opt);
  } catch (const std::exception& e) {
    std::cerr << "bench_generality: " << e.what() << "\n";
    return 2;
  }
}
