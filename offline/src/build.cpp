#include "hila/offline/build.hpp"

#include <atomic>
#include <chrono>
#include <ctime>
#include <exception>
#include <fstream>
#include <functional>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "hila/core/error.hpp"
#include "hila/core/mesh_symmetry.hpp"
#include "hila/db/database.hpp"
#include "hila/offline/human_comfort.hpp"
#include "hila/offline/part_analysis.hpp"

#ifndef HILA_VERSION
#define HILA_VERSION "unknown"
#endif

namespace hila::offline {

namespace {

// The database record of a human arm's comfort map (the build's sample count and seed with it).
db::ComfortMapRecord comfort_map_record(const core::ComfortMap& map, const std::string& arm,
                                        const core::ComfortMapSettings& settings) {
  db::ComfortMapRecord record;
  record.arm = arm;
  record.origin = map.origin();
  record.spacing = map.spacing();
  record.dims = map.dims();
  record.orientations = map.orientations();
  record.values = map.values();
  record.samples = settings.samples;
  record.seed = settings.seed;
  record.coverage = map.coverage();
  return record;
}

}  // namespace

std::string mesh_hash(const core::TriangleMesh& mesh) {
  std::string bytes;
  bytes.reserve(mesh.vertices.size() * 24 + mesh.triangles.size() * 12);
  for (const auto& v : mesh.vertices) {
    bytes.append(reinterpret_cast<const char*>(v.data()), 3 * sizeof(double));
  }
  for (const auto& t : mesh.triangles) {
    bytes.append(reinterpret_cast<const char*>(t.data()), 3 * sizeof(int));
  }
  return db::sha256_hex(bytes);
}

namespace {

std::string utc_now() {
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buffer;
}

struct PartResult {
  HandoverResult handover;
  RegraspResult regrasp;
  std::vector<db::ErgonomicsRecord> ergonomics;
  db::PartRecord record;
  std::vector<db::PlacementRecord> placements;
  std::vector<db::RobotGraspRecord> robot;
  std::vector<db::SuctionGraspRecord> suction;
  std::vector<db::HumanGraspRecord> human;
  PartBuildSummary summary;
  bool roles_swapped = false;  // the receiving arm picks by suction (swap_roles)
};

PartResult build_part(const core::ProductSpec& product, std::size_t index, const core::Cell& cell,
                      const BuildSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  const core::PartSpec& part = product.parts[index];
  const std::string field = "parts[" + part.name + "]";
  PartResult r;
  const PartAnalysis analysis = analyze_part(part.name, part.mesh, part.mass);

  r.record.name = part.name;
  r.record.assembly_order = part.order;
  r.record.mesh_file = part.mesh_file.substr(part.mesh_file.find_last_of('/') + 1);
  r.record.mesh_hash = mesh_hash(part.mesh);
  r.record.mass = part.mass;
  r.record.mass_properties = analysis.mass_properties;
  r.record.extent = part.mesh.max_corner() - part.mesh.min_corner();
  r.record.triangle_count = static_cast<int>(part.mesh.triangles.size());
  r.record.target = product.target_in_world(part);
  r.record.initial = part.initial;
  r.placements = analysis.placements;

  RobotGraspSettings robot = settings.robot;
  robot.seed = part_seed(settings.seed, part.name, 1);
  r.robot = plan_robot_grasps(analysis.mesh, analysis, part.mass, cell, robot);
  if (r.robot.empty()) {
    throw core::InputError(product.file, field,
                           "a part the gripper can hold (somewhere no wider than the " +
                               core::format_number(cell.spec().gripper.jaw_max) + " m jaw)",
                           "no collision-free antipodal grasp on '" + part.name + "'");
  }
  r.suction = plan_suction_grasps(analysis.mesh, analysis, part.mass, cell, settings.suction);
  HumanGraspSettings human = settings.human;
  human.seed = part_seed(settings.seed, part.name, 2);
  r.human = plan_human_grasps(analysis.mesh, analysis, part.mass, cell, human);

  auto& s = r.summary;
  s.name = part.name;
  s.order = part.order;
  s.mass = part.mass;
  s.placements = static_cast<int>(r.placements.size());
  s.robot_grasps = static_cast<int>(r.robot.size());
  s.suction_grasps = static_cast<int>(r.suction.size());
  s.human_grasps = static_cast<int>(r.human.size());
  for (const auto& g : r.human) s.one_hand_grasps += g.one_hand_stable ? 1 : 0;
  s.theta_c_min_deg = 90.0;
  s.theta_c_max_deg = 0.0;
  for (const auto& g : r.robot) {
    s.theta_c_min_deg = std::min(s.theta_c_min_deg, g.theta_c_deg);
    s.theta_c_max_deg = std::max(s.theta_c_max_deg, g.theta_c_deg);
  }
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return r;
}

// Runs task(0..count-1) on `jobs` threads; rethrows the failure of the lowest task index.
void run_tasks(int jobs, std::size_t count, const std::function<void(std::size_t)>& task) {
  std::vector<std::exception_ptr> errors(count);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t t = next++; t < count; t = next++) {
      try {
        task(t);
      } catch (...) {
        errors[t] = std::current_exception();
      }
    }
  };
  const int threads = std::min<int>(jobs, static_cast<int>(count));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
  for (const auto& e : errors) {
    if (e) std::rethrow_exception(e);
  }
}

struct HandoverIds {
  std::vector<std::int64_t> robot_handovers;
  std::vector<std::int64_t> candidates;
};

std::int64_t id_of(const std::vector<std::int64_t>& ids, std::int64_t index) {
  return index < 0 ? 0 : ids[static_cast<std::size_t>(index)];
}

// Turns the result's 0-based indices into database ids and writes it.
HandoverIds write_handover(db::DatabaseWriter& writer, std::int64_t part_id,
                           const HandoverResult& h, const std::vector<std::int64_t>& robot_ids,
                           const std::vector<std::int64_t>& suction_ids,
                           const std::vector<std::int64_t>& human_ids) {
  db::HandoverStageRecord stage = h.stage;
  stage.part_id = part_id;
  writer.add_handover_stage(stage);
  std::vector<db::RobotHandoverRecord> rr = h.robot_handovers;
  for (auto& r : rr) r.suction_grasp_id = id_of(suction_ids, r.suction_grasp_id);
  const auto rr_ids = writer.add_robot_handovers(part_id, rr);
  std::vector<db::HandoverCandidateRecord> candidates = h.candidates;
  for (auto& c : candidates) {
    c.human_grasp_id = id_of(human_ids, c.human_grasp_id);
    c.second_grasp_id = id_of(human_ids, c.second_grasp_id);
  }
  const auto candidate_ids = writer.add_handover_candidates(part_id, candidates);
  std::vector<db::SharedGraspRecord> shared = h.shared;
  for (auto& s : shared) {
    s.candidate_id = id_of(candidate_ids, s.candidate_id);
    s.robot_grasp_id = id_of(robot_ids, s.robot_grasp_id);
    s.robot_handover_id = id_of(rr_ids, s.robot_handover_id);
  }
  writer.add_shared_grasps(shared);
  std::vector<db::DirectGraspRecord> direct = h.direct;
  for (auto& d : direct) {
    d.candidate_id = id_of(candidate_ids, d.candidate_id);
    d.robot_grasp_id = id_of(robot_ids, d.robot_grasp_id);
  }
  writer.add_direct_grasps(direct);
  std::vector<db::TableRegraspRecord> regrasps = h.regrasps;
  for (auto& r : regrasps) {
    r.candidate_id = id_of(candidate_ids, r.candidate_id);
    r.pick_grasp_id = id_of(robot_ids, r.pick_grasp_id);
    r.robot_grasp_id = id_of(robot_ids, r.robot_grasp_id);
  }
  writer.add_table_regrasps(regrasps);
  std::vector<db::SuctionDeliveryRecord> deliveries = h.suction_deliveries;
  for (auto& d : deliveries) {
    d.candidate_id = id_of(candidate_ids, d.candidate_id);
    d.suction_grasp_id = id_of(suction_ids, d.suction_grasp_id);
  }
  writer.add_suction_deliveries(deliveries);
  return {rr_ids, candidate_ids};
}

// The same for the regrasp graph (filters, nodes, edges).
void write_regrasp(db::DatabaseWriter& writer, std::int64_t part_id, const RegraspResult& r,
                   const std::vector<std::int64_t>& roadmap_ids,
                   const std::vector<std::int64_t>& robot_ids,
                   const std::vector<std::int64_t>& suction_ids, const HandoverIds& handover) {
  auto grasp_id = [&](const std::string& kind, std::int64_t index) {
    return id_of(kind == "suction" ? suction_ids : robot_ids, index);
  };
  std::vector<db::RoadmapFilterRecord> filters = r.filters;
  for (auto& f : filters) {
    f.part_id = part_id;
    f.roadmap_id = roadmap_ids[static_cast<std::size_t>(f.roadmap_id)];
    f.grasp_id = grasp_id(f.grasp_kind, f.grasp_id);
  }
  const auto filter_ids = writer.add_roadmap_filters(filters);
  std::vector<db::RegraspNodeRecord> nodes = r.nodes;
  for (auto& n : nodes) {
    n.part_id = part_id;
    n.grasp_id = grasp_id(n.grasp_kind, n.grasp_id);
    n.robot_handover_id = id_of(handover.robot_handovers, n.robot_handover_id);
    n.candidate_id = id_of(handover.candidates, n.candidate_id);
  }
  const auto node_ids = writer.add_regrasp_nodes(nodes);
  std::vector<db::RegraspEdgeRecord> edges = r.edges;
  for (auto& e : edges) {
    e.part_id = part_id;
    e.from_node = id_of(node_ids, e.from_node);
    e.to_node = id_of(node_ids, e.to_node);
    e.filter_id = id_of(filter_ids, e.filter_id);
  }
  writer.add_regrasp_edges(edges);
}

}  // namespace

std::vector<std::string> BuildSummary::failed_parts() const {
  std::vector<std::string> out;
  for (const auto& p : parts) {
    if (!p.handover_failure.empty()) out.push_back(p.name);
  }
  return out;
}

std::vector<std::string> BuildSummary::unconnected_parts() const {
  std::vector<std::string> out;
  for (const auto& p : parts) {
    if (!p.regrasp_failure.empty()) out.push_back(p.name);
  }
  return out;
}

std::uint64_t part_seed(std::uint64_t seed, const std::string& part_name, std::uint64_t stream) {
  // FNV-1a over the name, mixed with the seed and stream by SplitMix64.
  std::uint64_t h = 1469598103934665603ULL;
  for (const unsigned char c : part_name) {
    h ^= c;
    h *= 1099511628211ULL;
  }
  std::uint64_t z = h ^ (seed * 0x9E3779B97F4A7C15ULL) ^ (stream << 32);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

std::string settings_hash(const BuildSettings& s) {
  std::ostringstream text;
  text.precision(17);
  text << "robot " << s.robot.samples << ' ' << s.robot.approach_rotations << ' '
       << s.robot.opening_margin << ' ' << s.robot.merge_distance << ' ' << s.robot.merge_angle_deg
       << ' ' << s.robot.tip_clearance << ' ' << s.robot.tip_margin << "\nsuction "
       << s.suction.rotations << ' ' << s.suction.min_area_fraction << "\nhuman " << s.human.samples
       << ' ' << s.human.approach_rotations << ' ' << s.human.opening_margin << ' '
       << s.human.merge_distance << ' ' << s.human.merge_angle_deg << "\ncomfort "
       << s.comfort.spacing << ' ' << s.comfort.orientations << ' ' << s.comfort.samples << '\n';
  const auto& h = s.handover;
  text << "handover " << h.candidates << ' ' << h.max_draws << ' ' << h.max_rotation_deg << ' '
       << h.max_offset << ' ' << h.comfort_threshold << ' ' << h.comfort_floor << ' '
       << h.two_hand_separation << ' ' << h.rotation_weight << ' ' << h.suction_arm << ' '
       << h.receiving_arm << ' ' << h.rr_orientations << ' ' << h.rr_poses << ' ' << h.shared_stored
       << ' ' << h.rr_per_grasp << ' ' << h.human_ik_goals << ' ' << h.direct << ' '
       << h.direct_stored << ' ' << h.pick_lift << ' ' << h.pick_resolution << ' '
       << h.exchange_approach << ' ' << h.exchange_resolution << ' ' << h.table_regrasp.enabled
       << ' ' << h.table_regrasp.placements << ' ' << h.table_regrasp.yaws << ' '
       << h.table_regrasp.support_tolerance << ' ' << h.swap_roles << ' ' << h.suction_delivery
       << ' ' << h.table_regrasp.relay << ' ' << h.table_regrasp.relay_spots << ' '
       << h.table_regrasp.relay_spacing << ' ' << h.natural_candidates << ' ' << h.body_candidates
       << ' ' << h.natural_max_rotation_deg << ' ' << h.natural_max_rula;
  for (const auto& p : h.rr_positions) text << ' ' << p.x() << ' ' << p.y() << ' ' << p.z();
  const auto& t = s.tool_relay;
  text << "\ntool_relay " << t.spacing << ' ' << t.yaw_steps << ' ' << t.clearance;
  const auto& e = s.ergonomics;
  text << "\nergonomics " << e.table_spot_x << ' ' << e.table_spot_y << ' ' << e.flexion_step_deg
       << ' ' << e.candidates_per_step << ' ' << e.ik_attempts << "\nbodies "
       << format_human_bodies(s.human_bodies) << '\n';
  const auto& m = s.roadmap;
  text << "roadmap " << m.nodes << ' ' << m.neighbours << ' ' << m.slip_bias << ' '
       << m.vertical_cone_deg << ' ' << m.resolution << ' ' << m.joint_range << '\n';
  const auto& g = s.regrasp;
  text << "regrasp " << g.goals << ' ' << g.served_goals << ' ' << g.attach_neighbours << ' '
       << g.bridge.max_checks << ' ' << g.transfer_bridges << ' ' << g.bridge_alternatives << ' '
       << g.alternative_checks << ' ' << g.timing_speed_scale << ' ' << g.timing_step << ' '
       << g.served_natural << ' ' << g.considered_natural << ' ' << g.online_held_resolution
       << '\n';
  return db::sha256_hex(text.str());
}

namespace {

// For a part without goals in the default roles: its goals with the arms' roles swapped. Kept
// (and `handover` swapped with them) when there are some and the new suction arm can get the
// tool: from its stand, or from the relay (`relay`) where the other arm, which reaches the stand,
// sets it down; otherwise the default roles' reason gains what the swap would have needed.
void swap_roles(const core::Cell& cell, const core::ProductSpec& product, std::size_t i,
                const BoardGrasps& grasps, const HumanComfort& comfort,
                const std::optional<core::Pose>& relay, HandoverSettings& handover, PartResult& r) {
  HandoverSettings swapped = handover;
  std::swap(swapped.suction_arm, swapped.receiving_arm);
  HandoverResult other = plan_handover_goals(cell, product, i, grasps, comfort, swapped);
  if (other.stage.goals == 0) {
    // Why the swap serves no goal either: the other arm's checks, in its own words.
    r.handover.stage.failure += "; with the roles swapped (the " + swapped.suction_arm +
                                " arm picking by suction, the " + swapped.receiving_arm +
                                " arm receiving): " + other.stage.failure;
    return;
  }
  const double approach = handover.exchange_approach, lift = handover.pick_lift;
  const bool at_stand = reaches_tool_stand(cell, product, i, swapped.suction_arm, approach, lift);
  const bool by_relay =
      !at_stand && relay &&
      reaches_tool_stand(cell, product, i, handover.suction_arm, approach, lift) &&
      reaches_tool_at(cell, swapped.suction_arm, *relay, core::parts_before(product, i),
                      core::parts_after(product, i), approach, lift);
  if (!at_stand && !by_relay) {
    const Eigen::Vector3d at = product.suction_tool_pose.translation();
    r.handover.stage.failure +=
        "; with the " + swapped.suction_arm + " arm picking by suction it would have " +
        std::to_string(other.stage.goals) + " goals, but the " + swapped.suction_arm +
        " arm does not reach the suction tool on its stand at (" + core::format_number(at.x()) +
        ", " + core::format_number(at.y()) + ", " + core::format_number(at.z()) + ") m" +
        (relay ? ", nor at the relay where the other arm would set it down"
               : ", and no place on the table serves both arms as a relay") +
        ": stand the tool where both arms reach it";
    return;
  }
  other.seconds += r.handover.seconds;
  r.handover = std::move(other);
  r.roles_swapped = true;
  handover = swapped;
}

}  // namespace

BuildSummary build_database(const std::string& product_path, const std::string& cell_path,
                            const std::string& output_path, const BuildSettings& settings,
                            const BuildProgress& progress) {
  const auto start = std::chrono::steady_clock::now();
  if (settings.jobs < 1) {
    throw core::InputError("command line", "--jobs", "a positive number of jobs",
                           std::to_string(settings.jobs));
  }
  const auto cell = core::Cell::load(cell_path);
  core::check_human_stance(*cell);
  const core::ProductSpec product = core::load_product(product_path);
  // Open the writer first: an unwritable destination fails before minutes of work.
  db::DatabaseWriter writer(output_path);

  // Phase 1: one task per human arm's comfort map and one per part's grasps. Phase 2 (needs the
  // maps and every part's grasps): one task per board's handover goals and ergonomics. Results
  // go to fixed slots, so the content does not depend on which thread ran what.
  const std::size_t n = product.parts.size();
  const std::size_t arms = cell->human_arms().size();
  const std::vector<std::string> robot_arms{settings.handover.suction_arm,
                                            settings.handover.receiving_arm};
  const std::size_t roadmap_count = robot_arms.size();
  const int total = static_cast<int>(roadmap_count + arms + 2 * n);
  std::vector<PartResult> results(n);
  std::vector<core::ComfortMap> maps(arms);
  std::vector<ComfortMapSummary> map_summaries(arms);
  std::vector<Roadmap> roadmaps(roadmap_count);
  std::mutex progress_mutex;
  int done = 0;
  auto report = [&](const std::string& label) {
    std::lock_guard<std::mutex> lock(progress_mutex);
    ++done;
    if (progress) progress(label, done, total);
  };
  auto report_partial = [&](const std::string& label) {
    std::lock_guard<std::mutex> lock(progress_mutex);
    if (progress) progress(label, done, total);
  };
  auto comfort_seed = [&](std::size_t a) {
    core::ComfortMapSettings comfort = settings.comfort;
    comfort.seed = part_seed(settings.seed, "comfort:" + cell->human_arms()[a].spec.name, 3);
    return comfort;
  };
  run_tasks(settings.jobs, roadmap_count + arms + n, [&](std::size_t t) {
    // Longest first: the robot roadmaps, then the comfort maps, then the parts.
    if (t < roadmap_count) {
      RoadmapSettings roadmap = settings.roadmap;
      roadmap.suction_arm = settings.handover.suction_arm;
      roadmap.seed = part_seed(settings.seed, "roadmap:" + robot_arms[t], 6);
      const std::string label = "roadmap, " + robot_arms[t] + " arm";
      roadmaps[t] = build_roadmap(*cell, robot_arms[t], roadmap, [&](int milestones) {
        report_partial(label + ": " + std::to_string(milestones) + "/" +
                       std::to_string(roadmap.nodes) + " milestones");
      });
      report(label + " (" + std::to_string(roadmaps[t].nodes.size()) + " nodes, " +
             std::to_string(roadmaps[t].edges.size()) + " edges)");
    } else if (t < roadmap_count + arms) {
      const std::size_t a = t - roadmap_count;
      const auto start_map = std::chrono::steady_clock::now();
      const core::HumanArm& arm = cell->human_arms()[a];
      maps[a] = core::ComfortMap::build(arm.chain, comfort_seed(a));
      auto& s = map_summaries[a];
      s.arm = arm.spec.name;
      s.filled_bins = maps[a].filled_bins();
      s.coverage = maps[a].coverage();
      s.seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_map).count();
      report("comfort map, " + arm.spec.name + " arm");
    } else {
      const std::size_t i = t - roadmap_count - arms;
      results[i] = build_part(product, i, *cell, settings);
      report(product.parts[i].name);
    }
  });

  const HumanComfort comfort(*cell, maps, settings.human_bodies);
  // The tool's relay, for parts whose swapped suction arm does not reach the stand.
  ToolRelay relay;
  if (settings.handover.swap_roles) {
    ToolRelaySettings relay_settings = settings.tool_relay;
    relay_settings.approach = settings.handover.exchange_approach;
    relay_settings.lift = settings.handover.pick_lift;
    relay = find_tool_relay(*cell, product, relay_settings);
  }
  run_tasks(settings.jobs, n, [&](std::size_t i) {
    PartResult& r = results[i];
    BoardGrasps grasps{r.robot, r.suction, r.human, r.record.mass_properties.com, r.placements};
    HandoverSettings handover = settings.handover;
    handover.pick_resolution = settings.roadmap.resolution;
    handover.seed = part_seed(settings.seed, product.parts[i].name, 4);
    r.handover = plan_handover_goals(*cell, product, i, grasps, comfort, handover);
    if (r.handover.stage.goals == 0 && handover.swap_roles)
      swap_roles(*cell, product, i, grasps, comfort, relay.handle, handover, r);
    ErgonomicsInputs in;
    in.target = r.record.target;
    in.initial = r.record.initial;
    if (!r.placements.empty()) {
      in.has_placement = true;
      in.table_placement = r.placements.front().part_in_plane;
    }
    in.human_grasps = &r.human;
    for (const auto& c : r.handover.candidates) {
      if (c.rank == 0) {
        in.has_goal = true;
        in.goal = c.board;
        for (int a = 0; a < comfort.arm_count(); ++a) {
          if (comfort.arm_name(a) == c.human_arm) in.goal_arm = a;
        }
        in.goal_grasp = static_cast<int>(c.human_grasp_id);
      }
    }
    in.symmetries = core::mesh_symmetries(product.parts[i].mesh);
    ErgonomicsSettings ergonomics = settings.ergonomics;
    ergonomics.seed = part_seed(settings.seed, product.parts[i].name, 5);
    r.ergonomics = evaluate_ergonomics(*cell, comfort, in, ergonomics);

    auto& s = r.summary;
    const auto& st = r.handover.stage;
    s.handover_draws = st.draws;
    s.handover_candidates = st.candidates;
    s.comfortable = st.comfortable;
    s.comfortable_default_body = st.comfortable_default_body;
    s.goals = st.goals;
    s.goals_per_body.assign(settings.human_bodies.size(), 0);
    for (const auto& c : r.handover.candidates) {
      if (c.status != "goal") continue;
      for (std::size_t b = 0; b < s.goals_per_body.size(); ++b) {
        if ((c.bodies >> b) & 1U) ++s.goals_per_body[b];
      }
    }
    s.robot_handovers = st.robot_handovers;
    s.two_hands = st.two_hands;
    s.handover_failure = st.failure;
    s.handover_seconds = r.handover.seconds;
    if (in.has_goal) {
      s.goal_distance = handover_distance(in.goal, in.target, settings.handover.rotation_weight);
      for (const auto& c : r.handover.candidates) {
        if (c.rank == 0) s.goal_quality = c.quality;
      }
    }
    RegraspSettings regrasp = settings.regrasp;
    regrasp.suction_arm = handover.suction_arm;
    regrasp.receiving_arm = handover.receiving_arm;
    s.suction_arm = handover.suction_arm;
    regrasp.lift = settings.handover.pick_lift;
    regrasp.approach = settings.handover.exchange_approach;
    regrasp.approach_resolution = settings.handover.exchange_resolution;
    regrasp.held_resolution = settings.handover.exchange_resolution;
    regrasp.seed = part_seed(settings.seed, product.parts[i].name, 7);
    r.regrasp =
        plan_regrasp(*cell, product, i, grasps, r.handover, roadmaps[r.roles_swapped ? 1 : 0],
                     roadmaps[r.roles_swapped ? 0 : 1], regrasp);
    const auto& g = r.regrasp;
    s.regrasp_filters = static_cast<int>(g.filters.size());
    s.regrasp_nodes = static_cast<int>(g.nodes.size());
    s.regrasp_edges = static_cast<int>(g.edges.size());
    s.transfers = g.transfers;
    s.transfers_connected = g.transfers_connected;
    s.bridges = g.bridges;
    s.goals_considered = g.goals_considered;
    s.goals_served = g.goals_served;
    s.first_served_rank = g.first_served_rank;
    s.exchanges_examined = g.exchanges_examined;
    s.exchanges_connected = g.exchanges_connected;
    // A board without goals already says why; the regrasp failure adds only a new reason.
    if (s.handover_failure.empty()) s.regrasp_failure = g.failure;
    s.regrasp_seconds = g.seconds;
    report(product.parts[i].name + " handover and regrasp graph");
  });

  db::Meta meta;
  meta.hila_version = HILA_VERSION;
  meta.product_name = product.name;
  meta.cell_hash = cell_hash(cell->spec());
  meta.product_hash = product_hash(product);
  meta.settings_hash = settings_hash(settings);
  meta.seed = settings.seed;
  meta.created_at = utc_now();
  meta.cell_file = cell_path.substr(cell_path.find_last_of('/') + 1);
  meta.product_file = product_path.substr(product_path.find_last_of('/') + 1);
  meta.human_bodies = format_human_bodies(settings.human_bodies);
  meta.tool_relay = relay.handle;
  writer.write_meta(meta);
  BuildSummary summary;
  summary.tool_relay = relay;
  summary.output = output_path;
  std::vector<std::int64_t> roadmap_ids;
  for (const auto& m : roadmaps) {
    roadmap_ids.push_back(writer.add_roadmap(to_record(m)));
    summary.roadmaps.push_back(
        {m.arm, static_cast<int>(m.nodes.size()), static_cast<int>(m.edges.size()), m.seconds});
  }
  for (auto& r : results) {
    const std::int64_t id = writer.add_part(r.record);
    writer.add_placements(id, r.placements);
    const auto robot_ids = writer.add_robot_grasps(id, r.robot);
    const auto suction_ids = writer.add_suction_grasps(id, r.suction);
    const auto human_ids = writer.add_human_grasps(id, r.human);
    const HandoverIds handover_ids =
        write_handover(writer, id, r.handover, robot_ids, suction_ids, human_ids);
    // The regrasp graph numbers the roadmaps by role: 0 the suction arm's, 1 the receiving arm's.
    const std::vector<std::int64_t> by_role =
        r.roles_swapped ? std::vector<std::int64_t>{roadmap_ids[1], roadmap_ids[0]} : roadmap_ids;
    write_regrasp(writer, id, r.regrasp, by_role, robot_ids, suction_ids, handover_ids);
    writer.add_ergonomics(id, r.ergonomics);
    summary.parts.push_back(r.summary);
  }
  for (std::size_t a = 0; a < arms; ++a) {
    writer.add_comfort_map(
        comfort_map_record(maps[a], cell->human_arms()[a].spec.name, comfort_seed(a)));
  }
  summary.comfort_maps = map_summaries;
  writer.commit();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace hila::offline
