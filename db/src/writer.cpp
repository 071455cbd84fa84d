#include <chrono>
#include <ctime>
#include <optional>
#include <stdexcept>

#include "atomic_file.hpp"
#include "comfort_codec.hpp"
#include "hila/db/database.hpp"
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
      insert_suction, insert_human, insert_comfort;
  bool meta_written = false;
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
    put("schema_version", std::to_string(current_schema_version()));
    put("hila_version", meta.hila_version);
    put("product_name", meta.product_name);
    put("cell_hash", meta.cell_hash);
    put("product_hash", meta.product_hash);
    put("settings_hash", meta.settings_hash);
    put("seed", std::to_string(meta.seed));  // text: SQLite integers are signed 64-bit
    put("created_at", meta.created_at.empty() ? utc_now_iso8601() : meta.created_at);
    put("cell_file", meta.cell_file);
    put("product_file", meta.product_file);
    m.meta_written = true;
  });
}

std::int64_t DatabaseWriter::add_part(const PartRecord& part) {
  Impl& m = *impl_;
  return m.guarded("add_part", [&] {
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
    return static_cast<std::int64_t>(sqlite3_last_insert_rowid(m.connection->get()));
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

void DatabaseWriter::add_robot_grasps(std::int64_t part_id,
                                      const std::vector<RobotGraspRecord>& grasps) {
  Impl& m = *impl_;
  m.guarded("add_robot_grasps", [&] {
    detail::Statement& s = *m.insert_robot;
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
    }
  });
}

void DatabaseWriter::add_suction_grasps(std::int64_t part_id,
                                        const std::vector<SuctionGraspRecord>& grasps) {
  Impl& m = *impl_;
  m.guarded("add_suction_grasps", [&] {
    detail::Statement& s = *m.insert_suction;
    s.set_context(m.context("suction_grasps (part id " + std::to_string(part_id) + ")"));
    for (const auto& g : grasps) {
      s.bind_next(part_id);
      bind_pose(s, g.cup);
      s.bind_next(g.rotation_deg);
      s.bind_next(g.force_margin);
      s.bind_next(g.moment_margin);
      s.run();
    }
  });
}

void DatabaseWriter::add_human_grasps(std::int64_t part_id,
                                      const std::vector<HumanGraspRecord>& grasps) {
  Impl& m = *impl_;
  m.guarded("add_human_grasps", [&] {
    detail::Statement& s = *m.insert_human;
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
    }
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

void DatabaseWriter::commit() {
  Impl& m = *impl_;
  m.require_usable("commit");
  if (!m.meta_written) {
    throw std::logic_error("DatabaseWriter::commit() without write_meta() for " + m.target +
                           ": the database could not be opened");
  }
  m.guarded("commit", [&] {
    m.finalize_statements();
    m.connection->exec("COMMIT", m.context("(commit)"));
    m.connection->close();
    m.connection.reset();
    detail::fsync_path(m.temp, m.target);
    detail::rename_into_place(m.temp, m.target);
    m.committed = true;
  });
}

}  // namespace hila::db
