#include <cmath>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cmd_inspect_graph.hpp"
#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/db/database.hpp"
#include "inspect_roadmap.hpp"

namespace hila::tools {

namespace {
struct InspectOptions {
  std::string database;
  std::string what = "summary";
  std::string part;
  std::string arm;
  bool json = false;
  int limit = 10;
  int goals = 10;  // goals listed by `graph` (text)
};

double round_to(double v, double unit) {
  return std::round(v / unit) * unit;
}

nlohmann::json pose_json(const core::Pose& pose);

nlohmann::json summary_json(const db::Database& database) {
  nlohmann::json out;
  const auto& m = database.meta();
  out["database"] = database.path();
  out["product"] = m.product_name;
  out["schema_version"] = m.schema_version;
  out["hila_version"] = m.hila_version;
  out["seed"] = m.seed;
  out["created_at"] = m.created_at;
  out["tool_relay"] = m.tool_relay ? pose_json(*m.tool_relay) : nlohmann::json();
  out["parts"] = nlohmann::json::array();
  for (const auto& part : database.parts()) {
    const auto robot = database.robot_grasps(part.id);
    const auto human = database.human_grasps(part.id);
    double lo = 90.0, hi = 0.0;
    for (const auto& g : robot) {
      lo = std::min(lo, g.theta_c_deg);
      hi = std::max(hi, g.theta_c_deg);
    }
    int one_hand = 0;
    for (const auto& g : human) one_hand += g.one_hand_stable ? 1 : 0;
    out["parts"].push_back({{"name", part.name},
                            {"order", part.assembly_order},
                            {"mass", part.mass},
                            {"volume", part.mass_properties.volume},
                            {"placements", database.placements(part.id).size()},
                            {"robot_grasps", robot.size()},
                            {"suction_grasps", database.suction_grasps(part.id).size()},
                            {"human_grasps", human.size()},
                            {"human_one_hand_grasps", one_hand},
                            {"theta_c_min_deg", robot.empty() ? 0.0 : lo},
                            {"theta_c_max_deg", robot.empty() ? 0.0 : hi}});
  }
  return out;
}

nlohmann::json grasps_json(const db::Database& database, const std::string& part_name) {
  const auto& part = database.part(part_name);
  nlohmann::json rows = nlohmann::json::array();
  for (const auto& g : database.robot_grasps(part.id)) {
    rows.push_back({{"id", g.id},
                    {"kind", "robot"},
                    {"width", round_to(g.jaw_width, 1e-6)},
                    {"quality", round_to(g.quality, 1e-4)},
                    {"theta_c_deg", g.theta_c_deg},
                    {"lever", round_to(g.lever, 1e-6)}});
  }
  for (const auto& g : database.suction_grasps(part.id)) {
    rows.push_back({{"id", g.id},
                    {"kind", "suction"},
                    {"width", nullptr},
                    {"quality", round_to(g.moment_margin, 1e-4)},
                    {"theta_c_deg", nullptr},
                    {"rotation_deg", g.rotation_deg}});
  }
  for (const auto& g : database.human_grasps(part.id)) {
    rows.push_back({{"id", g.id},
                    {"kind", "human"},
                    {"width", round_to(g.aperture, 1e-6)},
                    {"quality", round_to(g.quality, 1e-4)},
                    {"theta_c_deg", nullptr},
                    {"one_hand_stable", g.one_hand_stable}});
  }
  return {{"part", part_name}, {"grasps", rows}};
}

nlohmann::json comfort_json(const db::Database& database, const std::string& arm) {
  const db::ComfortMapRecord& map = database.comfort_map(arm);
  // Distribution of the stored Q over the bins that hold one.
  std::vector<long> histogram(10, 0);
  long filled = 0;
  double sum = 0.0, best = 0.0;
  for (const auto v : map.values) {
    if (v == 0) continue;
    const double q = v / 255.0;
    ++filled;
    sum += q;
    best = std::max(best, q);
    ++histogram[std::min<std::size_t>(9, static_cast<std::size_t>(q * 10.0))];
  }
  return {{"arm", map.arm},
          {"dims", {map.dims.x(), map.dims.y(), map.dims.z()}},
          {"spacing", map.spacing},
          {"orientations", map.orientations.size()},
          {"bins", map.values.size()},
          {"filled_bins", filled},
          {"coverage", map.coverage},
          {"samples", map.samples},
          {"q_max", best},
          {"q_mean", filled ? sum / static_cast<double>(filled) : 0.0},
          {"q_histogram_tenths", histogram}};
}

nlohmann::json pose_json(const core::Pose& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  return {{"xyz", {round_to(t.x(), 1e-6), round_to(t.y(), 1e-6), round_to(t.z(), 1e-6)}},
          {"quat_wxyz",
           {round_to(q.w(), 1e-9), round_to(q.x(), 1e-9), round_to(q.y(), 1e-9),
            round_to(q.z(), 1e-9)}}};
}

nlohmann::json handover_json(const db::Database& database, const std::string& part_name) {
  const auto& part = database.part(part_name);
  const db::HandoverStageRecord* stage = database.handover_stage(part.id);
  if (stage == nullptr) {
    throw core::InputError(database.path(), "handover_stages",
                           "handover goals for '" + part_name + "'",
                           "none (a database from before schema 3: rebuild it with hila build)");
  }
  std::map<std::int64_t, double> theta_c;
  for (const auto& g : database.robot_grasps(part.id)) theta_c[g.id] = g.theta_c_deg;
  // The build's worker set, in the order the goals' masks number its bodies.
  const std::vector<std::string> body_labels = db::human_body_labels(database.meta().human_bodies);
  nlohmann::json goals = nlohmann::json::array();
  for (const auto& c : database.handover_goals(part.id)) {
    nlohmann::json shared = nlohmann::json::array();
    for (const auto& s : database.shared_grasps(c.id)) {
      shared.push_back({{"robot_grasp", s.robot_grasp_id},
                        {"theta_c_deg", theta_c[s.robot_grasp_id]},
                        {"robot_handover", s.robot_handover_id},
                        {"arm", s.arm},
                        {"slip_rr_deg", round_to(s.inclination_rr_deg, 0.01)},
                        {"slip_rh_deg", round_to(s.inclination_rh_deg, 0.01)}});
    }
    // Grasps with which one arm picks the board where it lies and hands it over itself.
    nlohmann::json direct = nlohmann::json::array();
    for (const auto& d : database.direct_grasps(c.id)) {
      direct.push_back({{"robot_grasp", d.robot_grasp_id},
                        {"theta_c_deg", theta_c[d.robot_grasp_id]},
                        {"arm", d.arm},
                        {"slip_pick_deg", round_to(d.inclination_pick_deg, 0.01)},
                        {"slip_rh_deg", round_to(d.inclination_rh_deg, 0.01)}});
    }
    // Regrasps on the table: the grasp the arm picks it with, where it sets it down, the grasp it
    // (or the other arm, for a relay) takes it again with and delivers.
    nlohmann::json regrasps = nlohmann::json::array();
    for (const auto& r : database.table_regrasps(c.id)) {
      regrasps.push_back({{"id", r.id},
                          {"arm", r.arm},
                          {"taken_again_by", r.repick_arm},
                          {"pick_grasp", r.pick_grasp_id},
                          {"robot_grasp", r.robot_grasp_id},
                          {"set_down", pose_json(r.placement)}});
    }
    nlohmann::json g = {{"rank", c.rank},
                        {"candidate", c.id},
                        {"distance", round_to(c.distance, 1e-5)},
                        {"quality", round_to(c.quality, 1e-4)},
                        {"human_arm", c.human_arm},
                        {"human_grasp", c.human_grasp_id},
                        {"pose", pose_json(c.board)},
                        {"human_posture_solved", c.human_joints.size() > 0},
                        {"shared_grasps", shared},
                        {"direct_grasps", direct},
                        {"table_regrasps", regrasps}};
    nlohmann::json on_cup = nlohmann::json::array();
    for (const auto& d : database.suction_deliveries(c.id)) {
      on_cup.push_back({{"id", d.id}, {"arm", d.arm}, {"suction_grasp", d.suction_grasp_id}});
    }
    g["suction_deliveries"] = on_cup;
    // The bodies of the worker set that take this goal comfortably (bit i: body i).
    nlohmann::json bodies = nlohmann::json::array();
    for (std::size_t i = 0; i < body_labels.size() && i < 32; ++i) {
      if ((c.bodies >> i) & 1u) bodies.push_back(body_labels[i]);
    }
    g["bodies"] = bodies;
    if (!c.second_arm.empty()) {
      g["second_arm"] = c.second_arm;
      g["second_grasp"] = c.second_grasp_id;
    }
    goals.push_back(g);
  }
  nlohmann::json rr = nlohmann::json::array();
  for (const auto& r : database.robot_handovers(part.id)) {
    rr.push_back({{"id", r.id},
                  {"arm", r.arm},
                  {"suction_grasp", r.suction_grasp_id},
                  {"pose", pose_json(r.board)}});
  }
  return {{"part", part_name},
          {"finished_parts", stage->finished_parts},
          {"draws", stage->draws},
          {"candidates", stage->candidates},
          {"comfortable", stage->comfortable},
          {"comfortable_default_body", stage->comfortable_default_body},
          {"goals", stage->goals},
          {"robot_handovers", stage->robot_handovers},
          {"two_hands", stage->two_hands},
          {"failure", stage->failure},
          {"human_bodies", database.meta().human_bodies},
          {"robot_handover_poses", rr},
          {"ranked_goals", goals}};
}

int run_inspect(const InspectOptions& opt) {
  if (opt.what == "digest") {
    db::Database::open(opt.database);  // what the loader refuses is bad input here too (exit 2)
    const std::string digest = db::content_digest(opt.database);
    if (opt.json) {
      std::cout << nlohmann::json{{"database", opt.database}, {"digest", digest}}.dump(2) << "\n";
    } else {
      std::cout << digest << "\n";
    }
    return 0;
  }
  const db::Database database = db::Database::open(opt.database);
  if (opt.what == "grasps") {
    if (opt.part.empty()) {
      throw core::InputError("command line", "--part", "the name of a part", "nothing");
    }
    const auto j = grasps_json(database, opt.part);
    if (opt.json) {
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    std::cout << "grasps of " << opt.part << " (" << j["grasps"].size() << ")\n";
    std::cout << "      id  kind      width m  quality  theta_c deg\n";
    for (const auto& g : j["grasps"]) {
      std::cout << std::setw(8) << g["id"].get<std::int64_t>() << "  " << std::left << std::setw(8)
                << g["kind"].get<std::string>() << std::right;
      if (g["width"].is_null()) {
        std::cout << std::setw(9) << "-";
      } else {
        std::cout << std::setw(9) << std::fixed << std::setprecision(4) << g["width"].get<double>();
      }
      std::cout << std::setw(9) << std::setprecision(3) << g["quality"].get<double>();
      if (g["theta_c_deg"].is_null()) {
        std::cout << std::setw(13) << "-";
      } else {
        std::cout << std::setw(13) << std::setprecision(0) << g["theta_c_deg"].get<double>();
      }
      std::cout << "\n";
    }
    return 0;
  }
  if (opt.what == "comfort") {
    if (opt.arm.empty())
      throw core::InputError("command line", "--arm", "a human arm name", "nothing");
    const auto j = comfort_json(database, opt.arm);
    if (opt.json) {
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    std::cout << "comfort map of the " << opt.arm << " arm: " << j["dims"].dump() << " nodes "
              << j["spacing"].get<double>() << " m apart x " << j["orientations"].get<std::size_t>()
              << " orientations = " << j["bins"].get<std::size_t>() << " bins\n"
              << "  filled " << j["filled_bins"].get<long>() << ", coverage of the reach sphere "
              << std::fixed << std::setprecision(1) << 100.0 * j["coverage"].get<double>()
              << " %, from " << j["samples"].get<long>() << " sampled postures\n"
              << "  Q max " << std::setprecision(3) << j["q_max"].get<double>() << ", mean "
              << j["q_mean"].get<double>()
              << "\n  Q histogram (tenths): " << j["q_histogram_tenths"].dump() << "\n";
    return 0;
  }
  if (opt.what == "handover") {
    if (opt.part.empty()) {
      throw core::InputError("command line", "--part", "the name of a part", "nothing");
    }
    const auto j = handover_json(database, opt.part);
    if (opt.json) {
      std::cout << j.dump(2) << "\n";
      return 0;
    }
    std::cout << "handover goals of " << opt.part << " (finished before it: "
              << (j["finished_parts"].empty() ? std::string("none") : j["finished_parts"].dump())
              << ")\n  " << j["candidates"].get<int>() << " Eq. 1 candidates ("
              << j["draws"].get<int>() << " draws), |S| " << j["comfortable"].get<int>() << ", |𝕊| "
              << j["goals"].get<int>() << ", " << j["robot_handovers"].get<int>()
              << " robot-robot poses" << (j["two_hands"].get<bool>() ? ", two hands" : "") << "\n";
    if (!j["failure"].get<std::string>().empty()) {
      std::cout << "  no goal: " << j["failure"].get<std::string>() << "\n";
    }
    const bool with_body_set = !db::human_body_labels(database.meta().human_bodies).empty();
    if (with_body_set) {
      std::cout << "  worker set: " << database.meta().human_bodies << "\n";
    }
    std::cout << "  rank  distance m  Q      human hand (grasp)   shared grasps (theta_c deg) at "
                 "rr poses\n";
    int shown = 0;
    for (const auto& g : j["ranked_goals"]) {
      if (shown++ == opt.limit) {
        std::cout << "  ... " << j["ranked_goals"].size() - static_cast<std::size_t>(opt.limit)
                  << " more (--limit, --json)\n";
        break;
      }
      std::string hand = g["human_arm"].get<std::string>() + " (" +
                         std::to_string(g["human_grasp"].get<std::int64_t>()) + ")";
      if (g.contains("second_arm")) {
        hand += " + " + g["second_arm"].get<std::string>() + " (" +
                std::to_string(g["second_grasp"].get<std::int64_t>()) + ")";
      }
      // A grasp is stored once per robot-robot pose receiving it: "grasp (theta_c) rr a/b".
      std::string shared;
      std::int64_t last_grasp = -1;
      for (const auto& s : g["shared_grasps"]) {
        const auto grasp = s["robot_grasp"].get<std::int64_t>();
        const std::string rr = std::to_string(s["robot_handover"].get<std::int64_t>());
        if (grasp == last_grasp) {
          shared += "/" + rr;
          continue;
        }
        last_grasp = grasp;
        shared += (shared.empty() ? "" : ", ") + std::to_string(grasp) + " (" +
                  std::to_string(static_cast<int>(s["theta_c_deg"].get<double>())) + ") rr " + rr;
      }
      // Direct grasps (no exchange), when the goal has any: "grasp (theta_c) arm slip P/R", the
      // slip angles at the pick and at the robot-human pose, degrees.
      std::string direct;
      for (const auto& d : g["direct_grasps"]) {
        std::ostringstream slip;
        slip << std::fixed << std::setprecision(1) << d["slip_pick_deg"].get<double>() << "/"
             << d["slip_rh_deg"].get<double>();
        direct += (direct.empty() ? "" : ", ") +
                  std::to_string(d["robot_grasp"].get<std::int64_t>()) + " (" +
                  std::to_string(static_cast<int>(d["theta_c_deg"].get<double>())) + ") " +
                  d["arm"].get<std::string>() + " slip " + slip.str();
      }
      if (!direct.empty()) shared += (shared.empty() ? "" : "; ") + std::string("direct ") + direct;
      // With a worker set, the bodies that take the goal comfortably ("none" for none of them).
      std::string bodies;
      if (with_body_set) {
        for (const auto& b : g["bodies"]) {
          bodies += (bodies.empty() ? "" : ", ") + b.get<std::string>();
        }
        bodies = "  bodies: " + (bodies.empty() ? std::string("none") : bodies);
      }
      std::cout << std::setw(6) << g["rank"].get<int>() << std::setw(12) << std::fixed
                << std::setprecision(3) << g["distance"].get<double>() << "  " << std::setw(5)
                << std::setprecision(3) << g["quality"].get<double>() << "  " << std::left
                << std::setw(20) << hand << std::right << " " << shared << bodies << "\n";
    }
    return 0;
  }
  if (opt.what == "roadmap") return inspect_roadmap(database, opt.arm, opt.part, opt.json);
  if (opt.what == "graph") return inspect_graph(database, opt.part, opt.goals, opt.json);
  if (opt.what != "summary") {
    throw core::InputError("command line", "what",
                           "summary, grasps, comfort, handover, graph, roadmap or digest",
                           "'" + opt.what + "'");
  }
  const auto j = summary_json(database);
  if (opt.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "database " << database.path() << ": product " << j["product"].get<std::string>()
            << ", schema " << j["schema_version"].get<int>() << ", seed "
            << j["seed"].get<std::uint64_t>() << ", built " << j["created_at"].get<std::string>()
            << "\n";
  if (const auto& relay = database.meta().tool_relay) {
    const Eigen::Vector3d at = relay->translation();
    std::cout << "  suction tool relay (both arms take it there): (" << std::fixed
              << std::setprecision(3) << at.x() << ", " << at.y() << ", " << at.z() << ") m\n";
  }
  std::cout << "  #  part            mass  robot  suction  human (1-hand)  theta_c deg\n";
  for (const auto& p : j["parts"]) {
    std::cout << "  " << p["order"].get<int>() << "  " << std::left << std::setw(14)
              << p["name"].get<std::string>() << std::right << std::setw(6) << std::fixed
              << std::setprecision(2) << p["mass"].get<double>() << std::setw(7)
              << p["robot_grasps"].get<int>() << std::setw(9) << p["suction_grasps"].get<int>()
              << std::setw(7) << p["human_grasps"].get<int>() << " (" << std::setw(4)
              << p["human_one_hand_grasps"].get<int>() << ")   " << std::setprecision(0)
              << p["theta_c_min_deg"].get<double>() << "-" << p["theta_c_max_deg"].get<double>()
              << "\n";
  }
  return 0;
}
}  // namespace

void add_inspect_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<InspectOptions>();
  auto* inspect = app.add_subcommand("inspect", "Show what a product database holds");
  inspect->add_option("database", opt->database, "database file")->required();
  inspect
      ->add_option("what", opt->what,
                   "summary (default), grasps, comfort, handover, graph, roadmap or digest")
      ->capture_default_str();
  inspect->add_option("--part", opt->part, "part name (for grasps, handover, graph and roadmap)");
  inspect->add_option("--limit", opt->limit, "goals listed (handover, text)")
      ->capture_default_str();
  inspect->add_option("--goals", opt->goals, "goals listed (graph, text)")->capture_default_str();
  inspect->add_option("--arm", opt->arm, "human arm (comfort) or robot arm (roadmap) name");
  inspect->add_flag("--json", opt->json, "print JSON");
  inspect->callback([opt, &action] { action = [opt] { return run_inspect(*opt); }; });
}

}  // namespace hila::tools
