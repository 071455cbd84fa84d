#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

#include "atomic_file.hpp"
#include "comfort_codec.hpp"
#include "digest.hpp"
#include "hila/db/database.hpp"
#include "list_codec.hpp"
#include "pose_codec.hpp"
#include "schema.hpp"
#include "sqlite_handle.hpp"

namespace hila::db {

namespace {

std::string utc_now_iso8601() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buffer[32];
  std::strftime(buffer, sizeof(buffer), "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buffer;
}

void bind_pose(detail::Statement& statement, const core::Pose& pose) {
  for (double value : detail::encode_pose(pose)) statement.bind_next(value);
}

void bind_vector(detail::Statement& statement, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) statement.bind_next(v[i]);
}

void bind_joints(detail::Statement& statement, const Eigen::VectorXd& joints) {
  statement.bind_blob(detail::encode_doubles(joints));
}

// Refuses non-finite values of the tables since version 3 before anything is written (SQLite
// would turn NaN into NULL and a BLOB would keep it silently): std::invalid_argument naming the
// call, the table's column and the record, e.g. "DatabaseWriter::add_robot_handovers:
// robot_handovers.joints[2] (record 0 of 3, part id 1) must be finite, got nan".
class FiniteCheck {
 public:
  FiniteCheck(std::string call, std::string table)
      : call_(std::move(call)), table_(std::move(table)) {}

  // What identifies the record being checked, e.g. "record 0 of 3, part id 1".
  void set_record(std::string record) { record_ = std::move(record); }

  void value(const std::string& column, double v) const {
    if (!std::isfinite(v)) {
      throw std::invalid_argument("DatabaseWriter::" + call_ + ": " + table_ + "." + column + " (" +
                                  record_ + ") must be finite, got " + std::to_string(v));
    }
  }
  void pose(const std::string& prefix, const core::Pose& pose) const {
    static constexpr const char* kSuffixes[] = {"_x", "_y", "_z", "_qw", "_qx", "_qy", "_qz"};
    const detail::PoseColumns columns = detail::encode_pose(pose);
    for (std::size_t i = 0; i < columns.size(); ++i) value(prefix + kSuffixes[i], columns[i]);
  }
  void joints(const std::string& column, const Eigen::VectorXd& joints) const {
    for (Eigen::Index i = 0; i < joints.size(); ++i) {
      value(column + "[" + std::to_string(i) + "]", joints[i]);
    }
  }
  void vector(const std::string& column, const Eigen::Vector3d& v) const {
    for (int i = 0; i < 3; ++i) value(column + "[" + std::to_string(i) + "]", v[i]);
  }

 private:
  std::string call_;
  std::string table_;
  std::string record_;
};

// A double as SQLite stores it (17 significant digits), for "is ..." in a refusal.
std::string exact(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

std::string record_label(std::size_t index, std::size_t count, const std::string& owner) {
  return "record " + std::to_string(index) + " of " + std::to_string(count) + ", " + owner;
}

// Refuses a record of the tables since version 4 before anything of the call is written:
// std::invalid_argument "DatabaseWriter::CALL: TABLE.COLUMN (RECORD): WHAT".
[[noreturn]] void refuse(const std::string& call, const std::string& column,
                         const std::string& record, const std::string& what) {
  throw std::invalid_argument("DatabaseWriter::" + call + ": " + column + " (" + record +
                              "): " + what);
}

std::string quoted(const std::string& text) {
  return "'" + text + "'";
}

// "a, b or c" of quoted names.
std::string one_of(std::initializer_list<const char*> names) {
  std::string text;
  std::size_t i = 0;
  for (const char* name : names) {
    if (i) text += i + 1 == names.size() ? " or " : ", ";
    text += quoted(name);
    ++i;
  }
  return text;
}

bool is_one_of(const std::string& value, std::initializer_list<const char*> names) {
  return std::any_of(names.begin(), names.end(), [&](const char* name) { return value == name; });
}

// An optional reference of the version 4 tables: 0 in the record, NULL in the row.
void bind_reference(detail::Statement& statement, std::int64_t id) {
  if (id == 0) {
    statement.bind_null();
  } else {
    statement.bind_next(id);
  }
}

// What add_roadmap_filters needs to know of a roadmap this writer wrote.
struct RoadmapShape {
  std::size_t node_count = 0;
  std::vector<std::pair<int, int>> edges;
};

// "INSERT INTO table (a, b) VALUES (?, ?)" for a comma-separated column list.
std::string insert_sql(const std::string& table, const std::string& columns) {
  std::string placeholders = "?";
  for (char c : columns) {
    if (c == ',') placeholders += ", ?";
  }
  return "INSERT INTO " + table + " (" + columns + ") VALUES (" + placeholders + ")";
}

}  // namespace

struct DatabaseWriter::Impl {
  std::string target;
  std::string temp;
  std::unique_ptr<detail::Connection> connection;
  // Prepared once, reused for every row; destroyed before the connection closes.
  std::optional<detail::Statement> insert_meta, insert_part, insert_placement, insert_robot,
      insert_suction, insert_human, insert_comfort, insert_stage, insert_robot_handover,
      insert_candidate, insert_shared, insert_direct, insert_regrasp, insert_suction_delivery,
      insert_ergonomics, insert_roadmap, insert_filter, insert_regrasp_node, insert_regrasp_edge,
      select_robot_grasp, select_suction_grasp;
  std::map<std::int64_t, RoadmapShape> roadmaps;  // by id
  bool meta_written = false;
  std::string human_bodies;  // meta.human_bodies as written (the bodies a candidate's mask names)
  std::uint32_t bodies_written = 0;  // every bit any written candidate's bodies sets
  bool committed = false;
  std::string failure;  // the first error: a writer that failed never commits

  detail::ErrorContext context(const std::string& field) const {
    return {field, "a successful write of the new database (temporary file " + temp + ")", ""};
  }

  void require_usable(const char* call) const {
    if (committed) {
      throw std::logic_error(std::string("DatabaseWriter::") + call + " after commit() for " +
                             target);
    }
    if (!failure.empty()) {
      throw std::logic_error(std::string("DatabaseWriter::") + call + " after a failed write to " +
                             target + ": " + failure);
    }
  }

  // Runs a write; on error remembers it (so commit() refuses) and rethrows.
  template <typename Fn>
  auto guarded(const char* call, Fn&& fn) {
    require_usable(call);
    try {
      return fn();
    } catch (const std::exception& e) {
      failure = e.what();
      throw;
    }
  }

  void finalize_statements() {
    insert_meta.reset();
    insert_part.reset();
    insert_placement.reset();
    insert_robot.reset();
    insert_suction.reset();
    insert_human.reset();
    insert_comfort.reset();
    insert_stage.reset();
    insert_robot_handover.reset();
    insert_candidate.reset();
    insert_shared.reset();
    insert_direct.reset();
    insert_regrasp.reset();
    insert_suction_delivery.reset();
    insert_ergonomics.reset();
    insert_roadmap.reset();
    insert_filter.reset();
    insert_regrasp_node.reset();
    insert_regrasp_edge.reset();
    select_robot_grasp.reset();
    select_suction_grasp.reset();
  }

  // Requires a written grasp of that kind ("gripper": robot_grasps, "suction": suction_grasps)
  // with this id. grasp_id has no foreign key (the table depends on the kind), so the writer
  // checks it: DatabaseError naming `column` and `record` otherwise.
  void require_grasp(const std::string& column, const std::string& record, const std::string& kind,
                     std::int64_t id) {
    const bool gripper = kind == "gripper";
    detail::Statement& s = gripper ? *select_robot_grasp : *select_suction_grasp;
    s.set_context(context(column + " (" + record + ")"));
    s.bind_next(id);
    const bool found = s.step();
    s.reset();
    if (!found) {
      throw DatabaseError(target, column + " (" + record + ")",
                          std::string("the id of a written ") +
                              (gripper ? "robot_grasps" : "suction_grasps") + " row (grasp_kind '" +
                              kind + "')",
                          std::to_string(id) + ", which names none");
    }
  }

  std::int64_t last_id() const {
    return static_cast<std::int64_t>(sqlite3_last_insert_rowid(connection->get()));
  }
};

DatabaseWriter::DatabaseWriter(const std::string& target_path) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.target = target_path;
  detail::require_writable_directory(target_path);
  detail::remove_stale_temporaries(target_path);
  m.temp = detail::temporary_path_for(target_path);
  detail::remove_quietly(m.temp);  // a leftover of a killed process that had the same pid
  try {
    m.connection = std::make_unique<detail::Connection>(
        m.temp, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, target_path);
    // The file is private until the rename, so no journal and no syncs while building: commit()
    // does one fsync of the finished file. MEMORY (not OFF) keeps ROLLBACK working.
    m.connection->exec(
        "PRAGMA journal_mode = MEMORY; PRAGMA synchronous = OFF; "
        "PRAGMA foreign_keys = ON;",
        m.context("(pragmas)"));
    m.connection->exec("BEGIN", m.context("(transaction)"));
    m.connection->exec(detail::schema_sql(), m.context("(schema)"));

    using detail::pose_columns;
    using detail::vector_columns;
    m.insert_meta.emplace(*m.connection, "INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)",
                          m.context("meta"));
    m.insert_part.emplace(
        *m.connection,
        insert_sql("parts", "name, assembly_order, mesh_file, mesh_hash, mass, volume, " +
                                vector_columns("com") + ", ixx, iyy, izz, ixy, ixz, iyz, " +
                                vector_columns("extent") + ", triangle_count, " +
                                pose_columns("target") + ", " + pose_columns("initial")),
        m.context("parts"));
    m.insert_placement.emplace(
        *m.connection,
        insert_sql("placements", "part_id, " + pose_columns("part_in_plane") + ", stability"),
        m.context("placements"));
    m.insert_robot.emplace(
        *m.connection,
        insert_sql("robot_grasps",
                   "part_id, " + pose_columns("tcp") + ", jaw_width, " +
                       vector_columns("contact_1") + ", " + vector_columns("normal_1") + ", " +
                       vector_columns("contact_2") + ", " + vector_columns("normal_2") +
                       ", quality, friction_torque_capacity, lever, theta_c_deg"),
        m.context("robot_grasps"));
    m.insert_suction.emplace(
        *m.connection,
        insert_sql("suction_grasps", "part_id, " + pose_columns("cup") +
                                         ", rotation_deg, force_margin, moment_margin"),
        m.context("suction_grasps"));
    m.insert_human.emplace(
        *m.connection,
        insert_sql("human_grasps", "part_id, " + pose_columns("hand") + ", aperture, " +
                                       vector_columns("contact_1") + ", " +
                                       vector_columns("contact_2") + ", quality, one_hand_stable"),
        m.context("human_grasps"));
    m.insert_comfort.emplace(
        *m.connection,
        insert_sql("comfort_maps", "arm, " + vector_columns("origin") +
                                       ", spacing, dim_x, dim_y, dim_z, orientation_count, "
                                       "orientations, value_bytes, values_deflate, samples, seed, "
                                       "coverage"),
        m.context("comfort_maps"));
    m.insert_stage.emplace(
        *m.connection,
        insert_sql("handover_stages",
                   "part_id, finished_parts, draws, candidates, comfortable, "
                   "comfortable_default_body, goals, robot_handovers, two_hands, failure"),
        m.context("handover_stages"));
    m.insert_robot_handover.emplace(
        *m.connection,
        insert_sql("robot_handovers",
                   "part_id, " + pose_columns("board") + ", suction_grasp_id, arm, joints"),
        m.context("robot_handovers"));
    m.insert_candidate.emplace(
        *m.connection,
        insert_sql("handover_candidates",
                   "part_id, sample, " + pose_columns("board") +
                       ", distance, quality, status, rank, human_arm, human_grasp_id, "
                       "human_quality, second_arm, second_grasp_id, second_quality, human_joints, "
                       "second_joints, bodies"),
        m.context("handover_candidates"));
    m.insert_shared.emplace(
        *m.connection,
        insert_sql("shared_grasps",
                   "candidate_id, robot_grasp_id, robot_handover_id, arm, joints_rr, joints_rh, "
                   "inclination_rr_deg, inclination_rh_deg"),
        m.context("shared_grasps"));
    m.insert_direct.emplace(*m.connection,
                            insert_sql("direct_grasps",
                                       "candidate_id, robot_grasp_id, arm, joints_pick, joints_rh, "
                                       "inclination_pick_deg, inclination_rh_deg"),
                            m.context("direct_grasps"));
    m.insert_regrasp.emplace(
        *m.connection,
        insert_sql("table_regrasps",
                   "candidate_id, pick_grasp_id, robot_grasp_id, arm, repick_arm, " +
                       pose_columns("placement") +
                       ", joints_pick, joints_place, joints_repick, joints_rh, "
                       "inclination_pick_deg, inclination_place_deg, inclination_repick_deg, "
                       "inclination_rh_deg"),
        m.context("table_regrasps"));
    m.insert_suction_delivery.emplace(
        *m.connection,
        insert_sql("suction_deliveries", "candidate_id, suction_grasp_id, arm, joints_rh"),
        m.context("suction_deliveries"));
    m.insert_ergonomics.emplace(
        *m.connection,
        insert_sql("ergonomics",
                   "part_id, method, reachable, torso_flexion_deg, shoulder_elevated, reach, "
                   "reorientation_deg, quality, arm"),
        m.context("ergonomics"));
    m.insert_roadmap.emplace(
        *m.connection,
        insert_sql("roadmaps",
                   "arm, dof, resolution, node_count, edge_count, node_joints, node_gravity, "
                   "node_inclination_deg, edge_nodes, edge_length, edge_max_inclination_deg"),
        m.context("roadmaps"));
    m.insert_filter.emplace(
        *m.connection,
        insert_sql("roadmap_filters",
                   "part_id, roadmap_id, grasp_kind, grasp_id, theta_c_deg, valid_edges, "
                   "components, largest_component, edge_bits, node_component"),
        m.context("roadmap_filters"));
    m.insert_regrasp_node.emplace(
        *m.connection,
        insert_sql("regrasp_nodes",
                   "part_id, kind, arm, grasp_kind, grasp_id, robot_handover_id, candidate_id, " +
                       pose_columns("board") + ", dof, solution_count, solutions"),
        m.context("regrasp_nodes"));
    m.insert_regrasp_edge.emplace(
        *m.connection,
        insert_sql("regrasp_edges",
                   "part_id, kind, arm, from_node, to_node, filter_id, connected, cost, "
                   "path_nodes, via, path_dof, path_waypoints, path, duration"),
        m.context("regrasp_edges"));
    m.select_robot_grasp.emplace(*m.connection, "SELECT 1 FROM robot_grasps WHERE id = ?",
                                 m.context("robot_grasps"));
    m.select_suction_grasp.emplace(*m.connection, "SELECT 1 FROM suction_grasps WHERE id = ?",
                                   m.context("suction_grasps"));
  } catch (...) {
    m.finalize_statements();
    m.connection.reset();
    detail::remove_quietly(m.temp);
    throw;
  }
}

DatabaseWriter::~DatabaseWriter() {
  if (!impl_ || impl_->committed) return;
  // Not committed: drop everything (closing rolls the transaction back) and leave the target as
  // it was. Nothing here may throw.
  impl_->finalize_statements();
  impl_->connection.reset();
  detail::remove_quietly(impl_->temp);
  detail::remove_quietly(impl_->temp + "-journal");
}

const std::string& DatabaseWriter::temporary_path() const {
  return impl_->temp;
}

void DatabaseWriter::write_meta(const Meta& meta) {
  Impl& m = *impl_;
  m.guarded("write_meta", [&] {
    const auto put = [&](const std::string& key, const std::string& value) {
      m.insert_meta->bind_next(key);
      m.insert_meta->bind_next(value);
      m.insert_meta->run();
    };
    // The candidates written before name bodies of this set (schema version 10).
    const std::size_t bodies = human_body_labels(meta.human_bodies).size();
    if (!detail::body_mask_fits(m.bodies_written, bodies)) {
      refuse("write_meta", "meta.human_bodies", "the candidates written before",
             "expected the bodies their masks name (handover_candidates.bodies: bits 0 to " +
                 std::to_string(std::bit_width(m.bodies_written) - 1) + "), got " +
                 std::to_string(bodies) + " ('" + meta.human_bodies + "')");
    }
    put("schema_version", std::to_string(current_schema_version()));
    put("hila_version", meta.hila_version.empty() ? hila_version() : meta.hila_version);
    put("product_name", meta.product_name);
    put("cell_hash", meta.cell_hash);
    put("product_hash", meta.product_hash);
    put("settings_hash", meta.settings_hash);
    put("seed", std::to_string(meta.seed));  // text: SQLite integers are signed 64-bit
    put("created_at", meta.created_at.empty() ? utc_now_iso8601() : meta.created_at);
    put("cell_file", meta.cell_file);
    put("product_file", meta.product_file);
    put("human_bodies", meta.human_bodies);
    // Only where there is one: a file without the key (as every file written before) has none.
    if (meta.tool_relay) put("tool_relay", detail::format_pose_text(*meta.tool_relay));
    m.meta_written = true;
    m.human_bodies = meta.human_bodies;
  });
}

std::int64_t DatabaseWriter::add_part(const PartRecord& part) {
  Impl& m = *impl_;
  return m.guarded("add_part", [&] {
    // Database::open refuses any other mass, so the writer refuses it first.
    if (!(part.mass > 0.0) || !std::isfinite(part.mass)) {
      char mass[32];
      std::snprintf(mass, sizeof(mass), "%.17g", part.mass);
      refuse(
          "add_part", "parts.mass", "part '" + part.name + "'",
          std::string("PartRecord::mass is ") + mass + ", expected a mass in kg, finite and > 0");
    }
    detail::Statement& s = *m.insert_part;
    s.set_context(m.context("parts (part '" + part.name + "')"));
    s.bind_next(part.name);
    s.bind_next(static_cast<std::int64_t>(part.assembly_order));
    s.bind_next(part.mesh_file);
    s.bind_next(part.mesh_hash);
    s.bind_next(part.mass);
    s.bind_next(part.mass_properties.volume);
    bind_vector(s, part.mass_properties.com);
    const Eigen::Matrix3d& inertia = part.mass_properties.inertia;
    for (double value : {inertia(0, 0), inertia(1, 1), inertia(2, 2), inertia(0, 1), inertia(0, 2),
                         inertia(1, 2)}) {
      s.bind_next(value);
    }
    bind_vector(s, part.extent);
    s.bind_next(static_cast<std::int64_t>(part.triangle_count));
    bind_pose(s, part.target);
    bind_pose(s, part.initial);
    s.run();
    return m.last_id();
  });
}

void DatabaseWriter::add_placements(std::int64_t part_id,
                                    const std::vector<PlacementRecord>& placements) {
  Impl& m = *impl_;
  m.guarded("add_placements", [&] {
    detail::Statement& s = *m.insert_placement;
    s.set_context(m.context("placements (part id " + std::to_string(part_id) + ")"));
    for (const auto& p : placements) {
      s.bind_next(part_id);
      bind_pose(s, p.part_in_plane);
      s.bind_next(p.stability);
      s.run();
    }
  });
}

std::vector<std::int64_t> DatabaseWriter::add_robot_grasps(
    std::int64_t part_id, const std::vector<RobotGraspRecord>& grasps) {
  Impl& m = *impl_;
  return m.guarded("add_robot_grasps", [&] {
    detail::Statement& s = *m.insert_robot;
    std::vector<std::int64_t> ids;
    ids.reserve(grasps.size());
    s.set_context(m.context("robot_grasps (part id " + std::to_string(part_id) + ")"));
    for (const auto& g : grasps) {
      s.bind_next(part_id);
      bind_pose(s, g.tcp);
      s.bind_next(g.jaw_width);
      bind_vector(s, g.contact_1);
      bind_vector(s, g.normal_1);
      bind_vector(s, g.contact_2);
      bind_vector(s, g.normal_2);
      s.bind_next(g.quality);
      s.bind_next(g.friction_torque_capacity);
      s.bind_next(g.lever);
      s.bind_next(g.theta_c_deg);
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

std::vector<std::int64_t> DatabaseWriter::add_suction_grasps(
    std::int64_t part_id, const std::vector<SuctionGraspRecord>& grasps) {
  Impl& m = *impl_;
  return m.guarded("add_suction_grasps", [&] {
    detail::Statement& s = *m.insert_suction;
    std::vector<std::int64_t> ids;
    ids.reserve(grasps.size());
    s.set_context(m.context("suction_grasps (part id " + std::to_string(part_id) + ")"));
    for (const auto& g : grasps) {
      s.bind_next(part_id);
      bind_pose(s, g.cup);
      s.bind_next(g.rotation_deg);
      s.bind_next(g.force_margin);
      s.bind_next(g.moment_margin);
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

std::vector<std::int64_t> DatabaseWriter::add_human_grasps(
    std::int64_t part_id, const std::vector<HumanGraspRecord>& grasps) {
  Impl& m = *impl_;
  return m.guarded("add_human_grasps", [&] {
    detail::Statement& s = *m.insert_human;
    std::vector<std::int64_t> ids;
    ids.reserve(grasps.size());
    s.set_context(m.context("human_grasps (part id " + std::to_string(part_id) + ")"));
    for (const auto& g : grasps) {
      s.bind_next(part_id);
      bind_pose(s, g.hand);
      s.bind_next(g.aperture);
      bind_vector(s, g.contact_1);
      bind_vector(s, g.contact_2);
      s.bind_next(g.quality);
      s.bind_next(static_cast<std::int64_t>(g.one_hand_stable ? 1 : 0));
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

void DatabaseWriter::add_comfort_map(const ComfortMapRecord& map) {
  Impl& m = *impl_;
  m.guarded("add_comfort_map", [&] {
    detail::validate_comfort_map(map);
    detail::Statement& s = *m.insert_comfort;
    s.set_context(m.context("comfort_maps (arm '" + map.arm + "')"));
    s.bind_next(map.arm);
    bind_vector(s, map.origin);
    s.bind_next(map.spacing);
    for (int i = 0; i < 3; ++i) s.bind_next(static_cast<std::int64_t>(map.dims[i]));
    s.bind_next(static_cast<std::int64_t>(map.orientations.size()));
    s.bind_blob(detail::encode_orientations(map.orientations));
    s.bind_next(static_cast<std::int64_t>(map.values.size()));
    s.bind_blob(detail::deflate_values(map.values));
    s.bind_next(map.samples);
    s.bind_next(static_cast<std::int64_t>(map.seed));  // the bit pattern: SQLite has no uint64
    s.bind_next(map.coverage);
    s.run();
  });
}

void DatabaseWriter::add_handover_stage(const HandoverStageRecord& stage) {
  Impl& m = *impl_;
  m.guarded("add_handover_stage", [&] {
    const std::string owner = "part id " + std::to_string(stage.part_id);
    const int bad = detail::invalid_name(stage.finished_parts);
    if (bad >= 0) {
      throw std::invalid_argument(
          "DatabaseWriter::add_handover_stage: handover_stages.finished_parts (" + owner +
          "): name " + std::to_string(bad) + " is " +
          (stage.finished_parts[bad].empty() ? "empty" : "'" + stage.finished_parts[bad] + "'") +
          ", but names must be non-empty and free of newlines (they are stored newline-joined)");
    }
    detail::Statement& s = *m.insert_stage;
    s.set_context(m.context("handover_stages (" + owner + ")"));
    s.bind_next(stage.part_id);
    s.bind_next(detail::encode_names(stage.finished_parts));
    for (const int count : {stage.draws, stage.candidates, stage.comfortable,
                            stage.comfortable_default_body, stage.goals, stage.robot_handovers}) {
      s.bind_next(static_cast<std::int64_t>(count));
    }
    s.bind_next(static_cast<std::int64_t>(stage.two_hands ? 1 : 0));
    s.bind_next(stage.failure);
    s.run();
  });
}

std::vector<std::int64_t> DatabaseWriter::add_robot_handovers(
    std::int64_t part_id, const std::vector<RobotHandoverRecord>& handovers) {
  Impl& m = *impl_;
  return m.guarded("add_robot_handovers", [&] {
    const std::string owner = "part id " + std::to_string(part_id);
    FiniteCheck check("add_robot_handovers", "robot_handovers");
    for (std::size_t i = 0; i < handovers.size(); ++i) {
      check.set_record(record_label(i, handovers.size(), owner));
      check.pose("board", handovers[i].board);
      check.joints("joints", handovers[i].joints);
    }
    detail::Statement& s = *m.insert_robot_handover;
    s.set_context(m.context("robot_handovers (" + owner + ")"));
    std::vector<std::int64_t> ids;
    ids.reserve(handovers.size());
    for (const auto& h : handovers) {
      s.bind_next(part_id);
      bind_pose(s, h.board);
      s.bind_next(h.suction_grasp_id);
      s.bind_next(h.arm);
      bind_joints(s, h.joints);
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

std::vector<std::int64_t> DatabaseWriter::add_handover_candidates(
    std::int64_t part_id, const std::vector<HandoverCandidateRecord>& candidates) {
  Impl& m = *impl_;
  return m.guarded("add_handover_candidates", [&] {
    const std::string owner = "part id " + std::to_string(part_id);
    FiniteCheck check("add_handover_candidates", "handover_candidates");
    const std::size_t body_count = human_body_labels(m.human_bodies).size();
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      const auto& c = candidates[i];
      check.set_record(record_label(i, candidates.size(), owner));
      check.pose("board", c.board);
      check.value("distance", c.distance);
      check.value("quality", c.quality);
      check.value("human_quality", c.human_quality);
      check.value("second_quality", c.second_quality);
      check.joints("human_joints", c.human_joints);
      check.joints("second_joints", c.second_joints);
      // Bit i: body i of meta.human_bodies (schema version 10), so none before write_meta.
      if (!detail::body_mask_fits(c.bodies, body_count)) {
        refuse("add_handover_candidates", "handover_candidates.bodies",
               record_label(i, candidates.size(), owner),
               "expected " +
                   (m.meta_written ? detail::body_mask_expectation(m.human_bodies)
                                   : std::string("0 before write_meta (bit i: body i of "
                                                 "meta.human_bodies)")) +
                   ", got HandoverCandidateRecord::bodies = " + std::to_string(c.bodies) +
                   " (bit " + std::to_string(std::bit_width(c.bodies) - 1) + " set)");
      }
    }
    detail::Statement& s = *m.insert_candidate;
    s.set_context(m.context("handover_candidates (" + owner + ")"));
    std::vector<std::int64_t> ids;
    ids.reserve(candidates.size());
    for (const auto& c : candidates) {
      s.bind_next(part_id);
      s.bind_next(static_cast<std::int64_t>(c.sample));
      bind_pose(s, c.board);
      s.bind_next(c.distance);
      s.bind_next(c.quality);
      s.bind_next(c.status);
      s.bind_next(static_cast<std::int64_t>(c.rank));
      s.bind_next(c.human_arm);
      s.bind_next(c.human_grasp_id);
      s.bind_next(c.human_quality);
      s.bind_next(c.second_arm);
      s.bind_next(c.second_grasp_id);
      s.bind_next(c.second_quality);
      bind_joints(s, c.human_joints);
      bind_joints(s, c.second_joints);
      s.bind_next(static_cast<std::int64_t>(c.bodies));
      s.run();
      ids.push_back(m.last_id());
      m.bodies_written |= c.bodies;
    }
    return ids;
  });
}

void DatabaseWriter::add_shared_grasps(const std::vector<SharedGraspRecord>& grasps) {
  Impl& m = *impl_;
  m.guarded("add_shared_grasps", [&] {
    FiniteCheck check("add_shared_grasps", "shared_grasps");
    for (std::size_t i = 0; i < grasps.size(); ++i) {
      const auto& g = grasps[i];
      check.set_record(
          record_label(i, grasps.size(), "candidate id " + std::to_string(g.candidate_id)));
      check.joints("joints_rr", g.joints_rr);
      check.joints("joints_rh", g.joints_rh);
      check.value("inclination_rr_deg", g.inclination_rr_deg);
      check.value("inclination_rh_deg", g.inclination_rh_deg);
    }
    detail::Statement& s = *m.insert_shared;
    for (const auto& g : grasps) {
      s.set_context(m.context("shared_grasps (candidate id " + std::to_string(g.candidate_id) +
                              ", robot grasp id " + std::to_string(g.robot_grasp_id) +
                              ", robot handover id " + std::to_string(g.robot_handover_id) + ")"));
      s.bind_next(g.candidate_id);
      s.bind_next(g.robot_grasp_id);
      s.bind_next(g.robot_handover_id);
      s.bind_next(g.arm);
      bind_joints(s, g.joints_rr);
      bind_joints(s, g.joints_rh);
      s.bind_next(g.inclination_rr_deg);
      s.bind_next(g.inclination_rh_deg);
      s.run();
    }
  });
}

void DatabaseWriter::add_direct_grasps(const std::vector<DirectGraspRecord>& grasps) {
  Impl& m = *impl_;
  m.guarded("add_direct_grasps", [&] {
    FiniteCheck check("add_direct_grasps", "direct_grasps");
    for (std::size_t i = 0; i < grasps.size(); ++i) {
      const auto& g = grasps[i];
      const std::string record =
          record_label(i, grasps.size(), "candidate id " + std::to_string(g.candidate_id));
      if (g.arm.empty()) {
        refuse("add_direct_grasps", "direct_grasps.arm", record,
               "DirectGraspRecord::arm is empty, expected an arm name");
      }
      check.set_record(record);
      check.joints("joints_pick", g.joints_pick);
      check.joints("joints_rh", g.joints_rh);
      check.value("inclination_pick_deg", g.inclination_pick_deg);
      check.value("inclination_rh_deg", g.inclination_rh_deg);
    }
    detail::Statement& s = *m.insert_direct;
    for (const auto& g : grasps) {
      s.set_context(m.context("direct_grasps (candidate id " + std::to_string(g.candidate_id) +
                              ", robot grasp id " + std::to_string(g.robot_grasp_id) + ", arm '" +
                              g.arm + "')"));
      s.bind_next(g.candidate_id);
      s.bind_next(g.robot_grasp_id);
      s.bind_next(g.arm);
      bind_joints(s, g.joints_pick);
      bind_joints(s, g.joints_rh);
      s.bind_next(g.inclination_pick_deg);
      s.bind_next(g.inclination_rh_deg);
      s.run();
    }
  });
}

void DatabaseWriter::add_table_regrasps(const std::vector<TableRegraspRecord>& regrasps) {
  Impl& m = *impl_;
  m.guarded("add_table_regrasps", [&] {
    FiniteCheck check("add_table_regrasps", "table_regrasps");
    for (std::size_t i = 0; i < regrasps.size(); ++i) {
      const auto& g = regrasps[i];
      const std::string record =
          record_label(i, regrasps.size(), "candidate id " + std::to_string(g.candidate_id));
      if (g.arm.empty()) {
        refuse("add_table_regrasps", "table_regrasps.arm", record,
               "TableRegraspRecord::arm is empty, expected an arm name");
      }
      if (g.repick_arm.empty()) {
        refuse("add_table_regrasps", "table_regrasps.repick_arm", record,
               "TableRegraspRecord::repick_arm is empty, expected an arm name");
      }
      check.set_record(record);
      check.pose("placement", g.placement);
      check.joints("joints_pick", g.joints_pick);
      check.joints("joints_place", g.joints_place);
      check.joints("joints_repick", g.joints_repick);
      check.joints("joints_rh", g.joints_rh);
      check.value("inclination_pick_deg", g.inclination_pick_deg);
      check.value("inclination_place_deg", g.inclination_place_deg);
      check.value("inclination_repick_deg", g.inclination_repick_deg);
      check.value("inclination_rh_deg", g.inclination_rh_deg);
    }
    detail::Statement& s = *m.insert_regrasp;
    for (const auto& g : regrasps) {
      s.set_context(m.context("table_regrasps (candidate id " + std::to_string(g.candidate_id) +
                              ", pick grasp id " + std::to_string(g.pick_grasp_id) +
                              ", robot grasp id " + std::to_string(g.robot_grasp_id) + ", arm '" +
                              g.arm + "')"));
      s.bind_next(g.candidate_id);
      s.bind_next(g.pick_grasp_id);
      s.bind_next(g.robot_grasp_id);
      s.bind_next(g.arm);
      s.bind_next(g.repick_arm);
      bind_pose(s, g.placement);
      bind_joints(s, g.joints_pick);
      bind_joints(s, g.joints_place);
      bind_joints(s, g.joints_repick);
      bind_joints(s, g.joints_rh);
      s.bind_next(g.inclination_pick_deg);
      s.bind_next(g.inclination_place_deg);
      s.bind_next(g.inclination_repick_deg);
      s.bind_next(g.inclination_rh_deg);
      s.run();
    }
  });
}

void DatabaseWriter::add_suction_deliveries(const std::vector<SuctionDeliveryRecord>& deliveries) {
  Impl& m = *impl_;
  m.guarded("add_suction_deliveries", [&] {
    FiniteCheck check("add_suction_deliveries", "suction_deliveries");
    for (std::size_t i = 0; i < deliveries.size(); ++i) {
      const auto& d = deliveries[i];
      const std::string record =
          record_label(i, deliveries.size(), "candidate id " + std::to_string(d.candidate_id));
      if (d.arm.empty()) {
        refuse("add_suction_deliveries", "suction_deliveries.arm", record,
               "SuctionDeliveryRecord::arm is empty, expected an arm name");
      }
      check.set_record(record);
      check.joints("joints_rh", d.joints_rh);
    }
    detail::Statement& s = *m.insert_suction_delivery;
    for (const auto& d : deliveries) {
      s.set_context(m.context("suction_deliveries (candidate id " + std::to_string(d.candidate_id) +
                              ", suction grasp id " + std::to_string(d.suction_grasp_id) +
                              ", arm '" + d.arm + "')"));
      s.bind_next(d.candidate_id);
      s.bind_next(d.suction_grasp_id);
      s.bind_next(d.arm);
      bind_joints(s, d.joints_rh);
      s.run();
    }
  });
}

void DatabaseWriter::add_ergonomics(std::int64_t part_id,
                                    const std::vector<ErgonomicsRecord>& rows) {
  Impl& m = *impl_;
  m.guarded("add_ergonomics", [&] {
    const std::string owner = "part id " + std::to_string(part_id);
    FiniteCheck check("add_ergonomics", "ergonomics");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const auto& e = rows[i];
      check.set_record(record_label(i, rows.size(), owner));
      check.value("torso_flexion_deg", e.torso_flexion_deg);
      check.value("reach", e.reach);
      check.value("reorientation_deg", e.reorientation_deg);
      check.value("quality", e.quality);
    }
    detail::Statement& s = *m.insert_ergonomics;
    for (const auto& e : rows) {
      s.set_context(m.context("ergonomics (" + owner + ", method '" + e.method + "')"));
      s.bind_next(part_id);
      s.bind_next(e.method);
      s.bind_next(static_cast<std::int64_t>(e.reachable ? 1 : 0));
      s.bind_next(e.torso_flexion_deg);
      s.bind_next(static_cast<std::int64_t>(e.shoulder_elevated ? 1 : 0));
      s.bind_next(e.reach);
      s.bind_next(e.reorientation_deg);
      s.bind_next(e.quality);
      s.bind_next(e.arm);
      s.run();
    }
  });
}

std::int64_t DatabaseWriter::add_roadmap(const RoadmapRecord& roadmap) {
  Impl& m = *impl_;
  return m.guarded("add_roadmap", [&] {
    const RoadmapRecord& r = roadmap;
    const std::string owner = "arm '" + r.arm + "'";
    const auto bad = [&](const std::string& column, const std::string& what) {
      refuse("add_roadmap", "roadmaps." + column, owner, what);
    };
    if (r.arm.empty()) bad("arm", "RoadmapRecord::arm is empty, expected an arm name");
    if (r.dof <= 0) {
      bad("dof", "RoadmapRecord::dof is " + std::to_string(r.dof) + ", expected > 0");
    }
    if (!(r.resolution > 0.0) || !std::isfinite(r.resolution)) {
      bad("resolution", "RoadmapRecord::resolution is " + std::to_string(r.resolution) +
                            ", expected a finite value > 0 (rad)");
    }
    const std::size_t nodes = r.nodes.size();
    const std::size_t edges = r.edges.size();
    if (nodes > static_cast<std::size_t>(std::numeric_limits<int>::max())) {
      bad("node_count", std::to_string(nodes) + " nodes, expected at most 2^31 - 1");
    }
    const auto one_per = [&](const std::string& column, const std::string& field, std::size_t got,
                             std::size_t want, const std::string& what) {
      if (got != want) {
        bad(column, "RoadmapRecord::" + field + " holds " + std::to_string(got) +
                        " values, expected one per " + what + " (" + std::to_string(want) + ")");
      }
    };
    one_per("node_gravity", "node_gravity", r.node_gravity.size(), nodes, "node");
    one_per("node_inclination_deg", "node_inclination_deg", r.node_inclination_deg.size(), nodes,
            "node");
    one_per("edge_length", "edge_length", r.edge_length.size(), edges, "edge");
    one_per("edge_max_inclination_deg", "edge_max_inclination_deg",
            r.edge_max_inclination_deg.size(), edges, "edge");
    FiniteCheck check("add_roadmap", "roadmaps");
    for (std::size_t i = 0; i < nodes; ++i) {
      if (r.nodes[i].size() != r.dof) {
        bad("node_joints", "RoadmapRecord::nodes[" + std::to_string(i) + "] has " +
                               std::to_string(r.nodes[i].size()) +
                               " joint values, expected dof = " + std::to_string(r.dof));
      }
      check.set_record(owner + ", node " + std::to_string(i));
      check.joints("node_joints", r.nodes[i]);
      check.vector("node_gravity", r.node_gravity[i]);
      check.value("node_inclination_deg", r.node_inclination_deg[i]);
    }
    for (std::size_t e = 0; e < edges; ++e) {
      const auto [first, second] = r.edges[e];
      if (first < 0 || first >= second || static_cast<std::size_t>(second) >= nodes) {
        bad("edge_nodes", "RoadmapRecord::edges[" + std::to_string(e) + "] is (" +
                              std::to_string(first) + ", " + std::to_string(second) +
                              "), expected 0 <= first < second < " + std::to_string(nodes) +
                              " (the node count)");
      }
      check.set_record(owner + ", edge " + std::to_string(e));
      check.value("edge_length", r.edge_length[e]);
      check.value("edge_max_inclination_deg", r.edge_max_inclination_deg[e]);
    }

    detail::Statement& s = *m.insert_roadmap;
    s.set_context(m.context("roadmaps (" + owner + ")"));
    s.bind_next(r.arm);
    s.bind_next(static_cast<std::int64_t>(r.dof));
    s.bind_next(r.resolution);
    s.bind_next(static_cast<std::int64_t>(nodes));
    s.bind_next(static_cast<std::int64_t>(edges));
    s.bind_blob(detail::encode_vectors(r.nodes));
    s.bind_blob(detail::encode_vectors(r.node_gravity));
    s.bind_blob(detail::encode_double_list(r.node_inclination_deg));
    s.bind_blob(detail::encode_int32_pairs(r.edges));
    s.bind_blob(detail::encode_double_list(r.edge_length));
    s.bind_blob(detail::encode_double_list(r.edge_max_inclination_deg));
    s.run();
    const std::int64_t id = m.last_id();
    m.roadmaps[id] = RoadmapShape{nodes, r.edges};
    return id;
  });
}

std::vector<std::int64_t> DatabaseWriter::add_roadmap_filters(
    const std::vector<RoadmapFilterRecord>& filters) {
  Impl& m = *impl_;
  return m.guarded("add_roadmap_filters", [&] {
    FiniteCheck check("add_roadmap_filters", "roadmap_filters");
    for (std::size_t i = 0; i < filters.size(); ++i) {
      const RoadmapFilterRecord& f = filters[i];
      const std::string record =
          record_label(i, filters.size(), "part id " + std::to_string(f.part_id));
      const auto bad = [&](const std::string& column, const std::string& what) {
        refuse("add_roadmap_filters", "roadmap_filters." + column, record, what);
      };
      if (!is_one_of(f.grasp_kind, {"gripper", "suction"})) {
        bad("grasp_kind", "RoadmapFilterRecord::grasp_kind is " + quoted(f.grasp_kind) +
                              ", expected " + one_of({"gripper", "suction"}));
      }
      check.set_record(record);
      check.value("theta_c_deg", f.theta_c_deg);

      // The bits and ids against the roadmap (an unknown roadmap fails its foreign key below).
      const auto shape = m.roadmaps.find(f.roadmap_id);
      if (shape != m.roadmaps.end()) {
        const std::string roadmap = "roadmap id " + std::to_string(f.roadmap_id);
        if (f.edges.size() != shape->second.edges.size()) {
          bad("edge_bits", "RoadmapFilterRecord::edges holds " + std::to_string(f.edges.size()) +
                               " bits, expected one per edge of " + roadmap + " (" +
                               std::to_string(shape->second.edges.size()) + ")");
        }
        if (f.component.size() != shape->second.node_count) {
          bad("node_component", "RoadmapFilterRecord::component holds " +
                                    std::to_string(f.component.size()) +
                                    " ids, expected one per node of " + roadmap + " (" +
                                    std::to_string(shape->second.node_count) + ")");
        }
        for (std::size_t e = 0; e < f.edges.size(); ++e) {
          if (!f.edges[e]) continue;
          const auto [a, b] = shape->second.edges[e];
          if (f.component[a] != f.component[b]) {
            bad("node_component", "edge " + std::to_string(e) + " (nodes " + std::to_string(a) +
                                      ", " + std::to_string(b) + ") is set but joins components " +
                                      std::to_string(f.component[a]) + " and " +
                                      std::to_string(f.component[b]) +
                                      ", expected the ids of connected nodes to be equal");
          }
        }
      }
      std::map<int, int> sizes;  // component id -> nodes
      for (std::size_t n = 0; n < f.component.size(); ++n) {
        if (f.component[n] < 0) {
          bad("node_component", "RoadmapFilterRecord::component[" + std::to_string(n) + "] is " +
                                    std::to_string(f.component[n]) + ", expected an id >= 0");
        }
        ++sizes[f.component[n]];
      }
      const auto set = static_cast<int>(std::count(f.edges.begin(), f.edges.end(), true));
      int largest = 0;
      for (const auto& entry : sizes) largest = std::max(largest, entry.second);
      const auto count = [&](const std::string& column, int got, int want,
                             const std::string& what) {
        if (got != want) {
          bad(column, "RoadmapFilterRecord::" + column + " is " + std::to_string(got) +
                          ", expected " + what + " (" + std::to_string(want) + ")");
        }
      };
      count("valid_edges", f.valid_edges, set, "the number of set edges");
      count("components", f.components, static_cast<int>(sizes.size()),
            "the number of distinct component ids");
      count("largest_component", f.largest_component, largest, "the nodes of the largest");
      m.require_grasp("roadmap_filters.grasp_id", record, f.grasp_kind, f.grasp_id);
    }

    detail::Statement& s = *m.insert_filter;
    std::vector<std::int64_t> ids;
    ids.reserve(filters.size());
    for (const auto& f : filters) {
      s.set_context(m.context("roadmap_filters (part id " + std::to_string(f.part_id) +
                              ", roadmap id " + std::to_string(f.roadmap_id) + ", " + f.grasp_kind +
                              " grasp id " + std::to_string(f.grasp_id) + ")"));
      s.bind_next(f.part_id);
      s.bind_next(f.roadmap_id);
      s.bind_next(f.grasp_kind);
      s.bind_next(f.grasp_id);
      s.bind_next(f.theta_c_deg);
      s.bind_next(static_cast<std::int64_t>(f.valid_edges));
      s.bind_next(static_cast<std::int64_t>(f.components));
      s.bind_next(static_cast<std::int64_t>(f.largest_component));
      s.bind_blob(detail::encode_bits(f.edges));
      s.bind_blob(detail::encode_int32s(f.component));
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

std::vector<std::int64_t> DatabaseWriter::add_regrasp_nodes(
    const std::vector<RegraspNodeRecord>& nodes) {
  Impl& m = *impl_;
  return m.guarded("add_regrasp_nodes", [&] {
    FiniteCheck check("add_regrasp_nodes", "regrasp_nodes");
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const RegraspNodeRecord& n = nodes[i];
      const std::string record =
          record_label(i, nodes.size(), "part id " + std::to_string(n.part_id));
      const auto bad = [&](const std::string& column, const std::string& what) {
        refuse("add_regrasp_nodes", "regrasp_nodes." + column, record, what);
      };
      if (!is_one_of(n.kind, {"home", "pick", "robot_handover", "human_handover"})) {
        bad("kind", "RegraspNodeRecord::kind is " + quoted(n.kind) + ", expected " +
                        one_of({"home", "pick", "robot_handover", "human_handover"}));
      }
      const std::string of_kind = " for a " + quoted(n.kind) + " node";
      if (n.arm.empty()) bad("arm", "RegraspNodeRecord::arm is empty, expected an arm name");
      if (n.kind == "home") {
        if (!n.grasp_kind.empty()) {
          bad("grasp_kind", "RegraspNodeRecord::grasp_kind is " + quoted(n.grasp_kind) + of_kind +
                                ", expected ''");
        }
        if (n.grasp_id != 0) {
          bad("grasp_id", "RegraspNodeRecord::grasp_id is " + std::to_string(n.grasp_id) + of_kind +
                              ", expected 0");
        }
      } else if (!is_one_of(n.grasp_kind, {"gripper", "suction"})) {
        bad("grasp_kind", "RegraspNodeRecord::grasp_kind is " + quoted(n.grasp_kind) + of_kind +
                              ", expected " + one_of({"gripper", "suction"}));
      }
      const auto reference = [&](const std::string& column, std::int64_t id,
                                 const std::string& applies_to) {
        if ((n.kind == applies_to) != (id != 0)) {
          bad(column,
              "RegraspNodeRecord::" + column + " is " + std::to_string(id) + of_kind +
                  (id == 0 ? ", expected the id it refers to"
                           : ", expected 0 (it applies to " + quoted(applies_to) + " nodes only)"));
        }
      };
      reference("robot_handover_id", n.robot_handover_id, "robot_handover");
      reference("candidate_id", n.candidate_id, "human_handover");
      if (n.solutions.empty()) {
        bad("solutions", "RegraspNodeRecord::solutions is empty, expected at least one");
      }
      for (std::size_t j = 0; j < n.solutions.size(); ++j) {
        if (n.solutions[j].size() == 0 || n.solutions[j].size() != n.solutions[0].size()) {
          bad("solutions", "RegraspNodeRecord::solutions[" + std::to_string(j) + "] has " +
                               std::to_string(n.solutions[j].size()) + " joint values, expected " +
                               (j == 0 ? std::string("at least one")
                                       : "as many as solutions[0] (" +
                                             std::to_string(n.solutions[0].size()) + ")"));
        }
      }
      check.set_record(record);
      check.pose("board", n.board);
      for (std::size_t j = 0; j < n.solutions.size(); ++j) {
        check.set_record(record + ", solution " + std::to_string(j));
        check.joints("solutions", n.solutions[j]);
      }
      if (n.kind != "home")
        m.require_grasp("regrasp_nodes.grasp_id", record, n.grasp_kind, n.grasp_id);
    }

    detail::Statement& s = *m.insert_regrasp_node;
    std::vector<std::int64_t> ids;
    ids.reserve(nodes.size());
    for (const auto& n : nodes) {
      s.set_context(m.context("regrasp_nodes (part id " + std::to_string(n.part_id) + ", " +
                              n.kind + " node of arm '" + n.arm + "')"));
      s.bind_next(n.part_id);
      s.bind_next(n.kind);
      s.bind_next(n.arm);
      s.bind_next(n.grasp_kind);
      s.bind_next(n.grasp_id);
      bind_reference(s, n.robot_handover_id);
      bind_reference(s, n.candidate_id);
      bind_pose(s, n.board);
      s.bind_next(static_cast<std::int64_t>(n.solutions[0].size()));
      s.bind_next(static_cast<std::int64_t>(n.solutions.size()));
      s.bind_blob(detail::encode_vectors(n.solutions));
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

std::vector<std::int64_t> DatabaseWriter::add_regrasp_edges(
    const std::vector<RegraspEdgeRecord>& edges) {
  Impl& m = *impl_;
  return m.guarded("add_regrasp_edges", [&] {
    FiniteCheck check("add_regrasp_edges", "regrasp_edges");
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const RegraspEdgeRecord& e = edges[i];
      const std::string record =
          record_label(i, edges.size(), "part id " + std::to_string(e.part_id));
      const auto bad = [&](const std::string& column, const std::string& what) {
        refuse("add_regrasp_edges", "regrasp_edges." + column, record, what);
      };
      if (!is_one_of(e.kind, {"transit", "transfer", "handover"})) {
        bad("kind", "RegraspEdgeRecord::kind is " + quoted(e.kind) + ", expected " +
                        one_of({"transit", "transfer", "handover"}));
      }
      const std::string of_kind = " for a " + quoted(e.kind) + " edge";
      if (e.arm.empty()) bad("arm", "RegraspEdgeRecord::arm is empty, expected an arm name");
      if ((e.kind == "transfer") != (e.filter_id != 0)) {
        bad("filter_id", "RegraspEdgeRecord::filter_id is " + std::to_string(e.filter_id) +
                             of_kind +
                             (e.filter_id == 0 ? ", expected the roadmap filter used"
                                               : ", expected 0 (only 'transfer' edges use one)"));
      }
      check.set_record(record);
      check.value("cost", e.cost);
      if (e.cost < 0.0) {
        bad("cost", "RegraspEdgeRecord::cost is " + std::to_string(e.cost) +
                        ", expected a path length >= 0");
      }
      if (e.path_nodes < 0) {
        bad("path_nodes",
            "RegraspEdgeRecord::path_nodes is " + std::to_string(e.path_nodes) + ", expected >= 0");
      }
      if (!e.connected && (e.cost != 0.0 || e.path_nodes != 0)) {
        bad(e.cost != 0.0 ? "cost" : "path_nodes",
            "RegraspEdgeRecord::cost is " + std::to_string(e.cost) + " and path_nodes " +
                std::to_string(e.path_nodes) + " for an edge that is not connected, expected 0");
      }
      if (e.kind == "handover" && e.cost != 0.0) {
        bad("cost",
            "RegraspEdgeRecord::cost is " + std::to_string(e.cost) + of_kind + ", expected 0");
      }
      // A connected transit or transfer edge says how it was connected and holds its path; the
      // others hold neither.
      const bool has_path = e.connected && e.kind != "handover";
      const std::string without_path =
          e.kind == "handover" ? of_kind : std::string(" for an edge that is not connected");
      if (!is_one_of(e.via, {"", "roadmap", "bridge"})) {
        bad("via", "RegraspEdgeRecord::via is " + quoted(e.via) + ", expected " +
                       one_of({"roadmap", "bridge"}) + " (or '' without a path)");
      }
      if (has_path && e.via.empty()) {
        bad("via", "RegraspEdgeRecord::via is '' for a connected " + quoted(e.kind) +
                       " edge, expected " + one_of({"roadmap", "bridge"}));
      }
      if (!has_path && !e.via.empty()) {
        bad("via", "RegraspEdgeRecord::via is " + quoted(e.via) + without_path + ", expected ''");
      }
      const auto waypoints = [](std::size_t n) {
        return std::to_string(n) + (n == 1 ? " waypoint" : " waypoints");
      };
      if (has_path && e.path.size() < 2) {
        bad("path", "RegraspEdgeRecord::path has " + waypoints(e.path.size()) +
                        " for a connected " + quoted(e.kind) + " edge, expected at least 2");
      }
      if (!has_path && !e.path.empty()) {
        bad("path", "RegraspEdgeRecord::path has " + waypoints(e.path.size()) + without_path +
                        ", expected none");
      }
      for (std::size_t j = 0; j < e.path.size(); ++j) {
        if (e.path[j].size() == 0 || e.path[j].size() != e.path[0].size()) {
          bad("path",
              "RegraspEdgeRecord::path[" + std::to_string(j) + "] has " +
                  std::to_string(e.path[j].size()) + " joint values, expected " +
                  (j == 0 ? std::string("at least one")
                          : "as many as path[0] (" + std::to_string(e.path[0].size()) + ")"));
        }
      }
      // The estimated time along the path (schema version 9): finite, >= 0, and 0 without a
      // path (0 with one: not estimated).
      check.value("duration", e.duration);
      if (e.duration < 0.0) {
        bad("duration", "RegraspEdgeRecord::duration is " + exact(e.duration) +
                            ", expected a time in seconds >= 0");
      }
      if (e.path.empty() && e.duration != 0.0) {
        bad("duration", "RegraspEdgeRecord::duration is " + exact(e.duration) +
                            " for an edge without a path, expected 0");
      }
      for (std::size_t j = 0; j < e.path.size(); ++j) {
        check.set_record(record + ", waypoint " + std::to_string(j));
        check.joints("path", e.path[j]);
      }
    }

    detail::Statement& s = *m.insert_regrasp_edge;
    std::vector<std::int64_t> ids;
    ids.reserve(edges.size());
    for (const auto& e : edges) {
      s.set_context(m.context("regrasp_edges (part id " + std::to_string(e.part_id) + ", " +
                              e.kind + " edge " + std::to_string(e.from_node) + " -> " +
                              std::to_string(e.to_node) + ")"));
      s.bind_next(e.part_id);
      s.bind_next(e.kind);
      s.bind_next(e.arm);
      s.bind_next(e.from_node);
      s.bind_next(e.to_node);
      bind_reference(s, e.filter_id);
      s.bind_next(static_cast<std::int64_t>(e.connected ? 1 : 0));
      s.bind_next(e.cost);
      s.bind_next(static_cast<std::int64_t>(e.path_nodes));
      s.bind_next(e.via);
      s.bind_next(static_cast<std::int64_t>(e.path.empty() ? 0 : e.path[0].size()));
      s.bind_next(static_cast<std::int64_t>(e.path.size()));
      s.bind_blob(detail::encode_vectors(e.path));
      s.bind_next(e.duration);
      s.run();
      ids.push_back(m.last_id());
    }
    return ids;
  });
}

void DatabaseWriter::commit() {
  Impl& m = *impl_;
  m.require_usable("commit");
  if (!m.meta_written) {
    throw std::logic_error("DatabaseWriter::commit() without write_meta() for " + m.target +
                           ": the database could not be opened");
  }
  m.guarded("commit", [&] {
    m.finalize_statements();
    // Hashed inside the transaction, from the rows as stored, so the digests are of exactly what
    // Database::open will read.
    const auto digests =
        detail::table_digests(*m.connection, m.target, current_schema_version(), "");
    detail::write_table_digests(*m.connection, digests, m.context("meta (content digests)"));
    m.connection->exec("COMMIT", m.context("(commit)"));
    m.connection->close();
    m.connection.reset();
    detail::fsync_path(m.temp, m.target);
    detail::rename_into_place(m.temp, m.target);
    m.committed = true;
  });
}

}  // namespace hila::db
