#include <algorithm>
#include <charconv>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <optional>

#include "comfort_codec.hpp"
#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "list_codec.hpp"
#include "open_checks.hpp"
#include "pose_codec.hpp"
#include "schema.hpp"
#include "sqlite_handle.hpp"

namespace hila::db {

namespace {

using detail::pose_columns;
using detail::vector_columns;

// Reads rows of `table` in id order; `read_row` gets the row's id and consumes `columns`.
template <typename Record>
std::vector<Record> load_rows(
    detail::Connection& connection, const std::string& table, const std::string& columns,
    const std::string& fix,
    const std::function<void(detail::Statement&, std::int64_t id, Record&)>& read_row) {
  detail::Statement select(connection, "SELECT id, " + columns + " FROM " + table + " ORDER BY id",
                           {table, "a readable hila table", fix});
  std::vector<Record> records;
  while (select.step()) {
    Record record;
    const std::int64_t id = select.next_int64();
    read_row(select, id, record);
    records.push_back(std::move(record));
  }
  return records;
}

// Reads rows of `table` in id order; `read_row` consumes the columns after id and part_id.
template <typename Record>
std::vector<Record> load_table(detail::Connection& connection, const std::string& table,
                               const std::string& columns, const std::string& fix,
                               const std::function<void(detail::Statement&, Record&)>& read_row) {
  return load_rows<Record>(connection, table, "part_id, " + columns, fix,
                           [&](detail::Statement& s, std::int64_t id, Record& record) {
                             record.id = id;
                             record.part_id = s.next_int64();
                             read_row(s, record);
                           });
}

Eigen::Vector3d read_vector(detail::Statement& s) {
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) v[i] = s.next_double();
  return v;
}

// A pose whose quaternion is not a unit one can only come from damage or hand edits.
core::Pose read_pose(detail::Statement& s, const std::string& path, const std::string& table,
                     const std::string& prefix, std::int64_t id, const std::string& fix) {
  detail::PoseColumns columns;
  for (double& value : columns) value = s.next_double();
  const auto pose = detail::decode_pose(columns);
  if (!pose) {
    throw DatabaseError(path, table + "." + prefix + " (id " + std::to_string(id) + ")",
                        "finite values and a unit quaternion", "something else", fix);
  }
  return *pose;
}

// A joint vector BLOB: a whole number of little-endian doubles, all finite (the writer refuses
// anything else, so a bad one is damage).
Eigen::VectorXd read_joints(detail::Statement& s, const std::string& path, const std::string& table,
                            const std::string& column, std::int64_t id, const std::string& fix) {
  const std::string bytes = s.next_blob();
  Eigen::VectorXd joints;
  if (!detail::decode_doubles(bytes, joints) || !joints.allFinite()) {
    throw DatabaseError(path, table + "." + column + " (id " + std::to_string(id) + ")",
                        "finite joint values as little-endian doubles (8 bytes each)",
                        bytes.size() % 8 != 0 ? std::to_string(bytes.size()) + " bytes"
                                              : std::string("a value that is not finite"),
                        fix);
  }
  return joints;
}

std::string short_hash(const std::string& hash) {
  return hash.size() > 12 ? hash.substr(0, 12) + "..." : hash;
}

void check_hash(const std::string& path, const std::string& what, const std::string& key,
                const std::string& stored, const std::optional<std::string>& expected,
                const std::string& fix) {
  if (!expected || *expected == stored) return;
  throw DatabaseError(
      path, "meta." + key, short_hash(*expected) + " (the " + what + " as it is now)",
      short_hash(stored) + " (the " + what + " this database was built from): the " + what +
          " changed since this database was built",
      fix);
}

Meta parse_meta(const std::string& path, const std::map<std::string, std::string>& map,
                int schema_version) {
  const std::string fix = detail::rebuild_hint(path, map);
  for (const char* key : detail::kMetaKeys) {
    if (!map.count(key)) {
      throw DatabaseError(path, std::string("meta.") + key, "a value", "no such key", fix);
    }
  }
  Meta meta;
  meta.schema_version = schema_version;
  meta.hila_version = map.at("hila_version");
  meta.product_name = map.at("product_name");
  meta.cell_hash = map.at("cell_hash");
  meta.product_hash = map.at("product_hash");
  meta.settings_hash = map.at("settings_hash");
  meta.created_at = map.at("created_at");
  meta.cell_file = map.at("cell_file");
  meta.product_file = map.at("product_file");
  // Added in version 3: a file without it (hand-made) reads as "the cell's human only".
  const auto bodies = map.find("human_bodies");
  meta.human_bodies = bodies == map.end() ? std::string() : bodies->second;
  const std::string& seed = map.at("seed");
  const auto [end, error] = std::from_chars(seed.data(), seed.data() + seed.size(), meta.seed);
  if (seed.empty() || error != std::errc() || end != seed.data() + seed.size()) {
    throw DatabaseError(path, "meta.seed", "an unsigned 64-bit integer", "'" + seed + "'", fix);
  }
  return meta;
}

// The comfort_maps table. Every size is checked against the others before anything is trusted: a
// damaged row is a DatabaseError, never a map whose lookups read out of bounds.
std::vector<ComfortMapRecord> load_comfort_maps(detail::Connection& connection,
                                                const std::string& path, const std::string& fix) {
  detail::Statement select(connection,
                           "SELECT id, arm, " + vector_columns("origin") +
                               ", spacing, dim_x, dim_y, dim_z, orientation_count, orientations, "
                               "value_bytes, values_deflate, samples, seed, coverage "
                               "FROM comfort_maps ORDER BY id",
                           {"comfort_maps", "a readable hila table", fix});
  std::vector<ComfortMapRecord> maps;
  while (select.step()) {
    ComfortMapRecord map;
    const std::int64_t id = select.next_int64();
    map.arm = select.next_text();
    const std::string row = "(arm '" + map.arm + "', id " + std::to_string(id) + ")";
    const auto corrupt = [&](const std::string& column, const std::string& expected,
                             const std::string& got) {
      return DatabaseError(path, "comfort_maps." + column + " " + row, expected, got, fix);
    };
    map.origin = read_vector(select);
    map.spacing = select.next_double();
    if (!map.origin.allFinite()) throw corrupt("origin", "finite values", "something else");
    if (!(map.spacing > 0.0) || !std::isfinite(map.spacing)) {
      throw corrupt("spacing", "a finite value > 0", std::to_string(map.spacing));
    }
    std::int64_t dims[3];
    for (std::int64_t& d : dims) d = select.next_int64();
    for (int i = 0; i < 3; ++i) {
      if (dims[i] <= 0 || dims[i] > std::numeric_limits<int>::max()) {
        throw corrupt("dim_x/y/z", "node counts > 0",
                      std::to_string(dims[0]) + " x " + std::to_string(dims[1]) + " x " +
                          std::to_string(dims[2]));
      }
      map.dims[i] = static_cast<int>(dims[i]);
    }
    const std::int64_t orientation_count = select.next_int64();
    const std::string orientation_bytes = select.next_blob();
    if (!detail::decode_orientations(orientation_bytes, orientation_count, map.orientations)) {
      throw corrupt("orientations",
                    "orientation_count = " + std::to_string(orientation_count) +
                        " orientations (32 bytes each)",
                    std::to_string(orientation_bytes.size()) + " bytes");
    }
    for (std::size_t o = 0; o < map.orientations.size(); ++o) {
      const double norm = map.orientations[o].coeffs().norm();
      if (!(std::abs(norm - 1.0) <= detail::kUnitQuaternionTolerance)) {
        throw corrupt("orientations", "unit quaternions",
                      "orientation " + std::to_string(o) + " of norm " + std::to_string(norm));
      }
    }
    const std::int64_t value_bytes = select.next_int64();
    const std::int64_t count =
        detail::comfort_value_count(dims[0], dims[1], dims[2], orientation_count);
    if (count < 0 || value_bytes != count) {
      throw corrupt("value_bytes",
                    "dim_x * dim_y * dim_z * orientation_count = " + std::to_string(count),
                    std::to_string(value_bytes));
    }
    const std::string compressed = select.next_blob();
    const std::string problem = detail::inflate_values(compressed, value_bytes, map.values);
    if (!problem.empty()) {
      throw corrupt("values_deflate",
                    "zlib-compressed values that inflate to value_bytes = " +
                        std::to_string(value_bytes) + " bytes",
                    problem);
    }
    map.samples = select.next_int64();
    map.seed = static_cast<std::uint64_t>(select.next_int64());
    map.coverage = select.next_double();
    maps.push_back(std::move(map));
  }
  return maps;
}

template <typename Record>
std::vector<Record> for_part(const std::vector<Record>& records, std::int64_t part_id) {
  std::vector<Record> selected;
  std::copy_if(records.begin(), records.end(), std::back_inserter(selected),
               [&](const Record& r) { return r.part_id == part_id; });
  return selected;
}

}  // namespace

Database Database::open(const std::string& path, const OpenOptions& options) {
  const auto connection = detail::open_hila_database(path);
  const auto meta_map = detail::read_meta_table(*connection);
  const int version = detail::stored_schema_version(path, meta_map);
  const std::string fix = detail::rebuild_hint(path, meta_map);
  detail::check_schema_version(
      path, version, current_schema_version(),
      detail::can_migrate(detail::migration_steps(), version, current_schema_version()), fix);

  Database db;
  db.path_ = path;
  db.meta_ = parse_meta(path, meta_map, version);
  check_hash(path, "cell", "cell_hash", db.meta_.cell_hash, options.expected_cell_hash, fix);
  check_hash(path, "product", "product_hash", db.meta_.product_hash, options.expected_product_hash,
             fix);

  {
    detail::Statement select(
        *connection,
        "SELECT id, name, assembly_order, mesh_file, mesh_hash, mass, volume, " +
            vector_columns("com") + ", ixx, iyy, izz, ixy, ixz, iyz, " + vector_columns("extent") +
            ", triangle_count, " + pose_columns("target") + ", " + pose_columns("initial") +
            " FROM parts ORDER BY id",
        {"parts", "a readable hila table", fix});
    while (select.step()) {
      PartRecord part;
      part.id = select.next_int64();
      part.name = select.next_text();
      part.assembly_order = static_cast<int>(select.next_int64());
      part.mesh_file = select.next_text();
      part.mesh_hash = select.next_text();
      part.mass = select.next_double();
      part.mass_properties.volume = select.next_double();
      part.mass_properties.com = read_vector(select);
      Eigen::Matrix3d& inertia = part.mass_properties.inertia;
      inertia(0, 0) = select.next_double();
      inertia(1, 1) = select.next_double();
      inertia(2, 2) = select.next_double();
      inertia(0, 1) = inertia(1, 0) = select.next_double();
      inertia(0, 2) = inertia(2, 0) = select.next_double();
      inertia(1, 2) = inertia(2, 1) = select.next_double();
      part.extent = read_vector(select);
      part.triangle_count = static_cast<int>(select.next_int64());
      part.target = read_pose(select, path, "parts", "target", part.id, fix);
      part.initial = read_pose(select, path, "parts", "initial", part.id, fix);
      db.parts_.push_back(std::move(part));
    }
  }

  db.placements_ = load_table<PlacementRecord>(
      *connection, "placements", pose_columns("part_in_plane") + ", stability", fix,
      [&](detail::Statement& s, PlacementRecord& r) {
        r.part_in_plane = read_pose(s, path, "placements", "part_in_plane", r.id, fix);
        r.stability = s.next_double();
      });
  db.robot_grasps_ = load_table<RobotGraspRecord>(
      *connection, "robot_grasps",
      pose_columns("tcp") + ", jaw_width, " + vector_columns("contact_1") + ", " +
          vector_columns("normal_1") + ", " + vector_columns("contact_2") + ", " +
          vector_columns("normal_2") + ", quality, friction_torque_capacity, lever, theta_c_deg",
      fix, [&](detail::Statement& s, RobotGraspRecord& r) {
        r.tcp = read_pose(s, path, "robot_grasps", "tcp", r.id, fix);
        r.jaw_width = s.next_double();
        r.contact_1 = read_vector(s);
        r.normal_1 = read_vector(s);
        r.contact_2 = read_vector(s);
        r.normal_2 = read_vector(s);
        r.quality = s.next_double();
        r.friction_torque_capacity = s.next_double();
        r.lever = s.next_double();
        r.theta_c_deg = s.next_double();
      });
  db.suction_grasps_ = load_table<SuctionGraspRecord>(
      *connection, "suction_grasps",
      pose_columns("cup") + ", rotation_deg, force_margin, moment_margin", fix,
      [&](detail::Statement& s, SuctionGraspRecord& r) {
        r.cup = read_pose(s, path, "suction_grasps", "cup", r.id, fix);
        r.rotation_deg = s.next_double();
        r.force_margin = s.next_double();
        r.moment_margin = s.next_double();
      });
  db.human_grasps_ = load_table<HumanGraspRecord>(
      *connection, "human_grasps",
      pose_columns("hand") + ", aperture, " + vector_columns("contact_1") + ", " +
          vector_columns("contact_2") + ", quality, one_hand_stable",
      fix, [&](detail::Statement& s, HumanGraspRecord& r) {
        r.hand = read_pose(s, path, "human_grasps", "hand", r.id, fix);
        r.aperture = s.next_double();
        r.contact_1 = read_vector(s);
        r.contact_2 = read_vector(s);
        r.quality = s.next_double();
        r.one_hand_stable = s.next_int64() != 0;
      });
  db.comfort_maps_ = load_comfort_maps(*connection, path, fix);

  db.handover_stages_ = load_rows<HandoverStageRecord>(
      *connection, "handover_stages",
      "part_id, finished_parts, draws, candidates, comfortable, comfortable_default_body, goals, "
      "robot_handovers, two_hands, failure",
      fix, [&](detail::Statement& s, std::int64_t, HandoverStageRecord& r) {
        r.part_id = s.next_int64();
        r.finished_parts = detail::decode_names(s.next_text());
        r.draws = static_cast<int>(s.next_int64());
        r.candidates = static_cast<int>(s.next_int64());
        r.comfortable = static_cast<int>(s.next_int64());
        r.comfortable_default_body = static_cast<int>(s.next_int64());
        r.goals = static_cast<int>(s.next_int64());
        r.robot_handovers = static_cast<int>(s.next_int64());
        r.two_hands = s.next_int64() != 0;
        r.failure = s.next_text();
      });
  db.robot_handovers_ = load_table<RobotHandoverRecord>(
      *connection, "robot_handovers", pose_columns("board") + ", suction_grasp_id, arm, joints",
      fix, [&](detail::Statement& s, RobotHandoverRecord& r) {
        r.board = read_pose(s, path, "robot_handovers", "board", r.id, fix);
        r.suction_grasp_id = s.next_int64();
        r.arm = s.next_text();
        r.joints = read_joints(s, path, "robot_handovers", "joints", r.id, fix);
      });
  db.handover_candidates_ = load_table<HandoverCandidateRecord>(
      *connection, "handover_candidates",
      "sample, " + pose_columns("board") +
          ", distance, quality, status, rank, human_arm, human_grasp_id, human_quality, "
          "second_arm, second_grasp_id, second_quality, human_joints, second_joints",
      fix, [&](detail::Statement& s, HandoverCandidateRecord& r) {
        r.sample = static_cast<int>(s.next_int64());
        r.board = read_pose(s, path, "handover_candidates", "board", r.id, fix);
        r.distance = s.next_double();
        r.quality = s.next_double();
        r.status = s.next_text();
        r.rank = static_cast<int>(s.next_int64());
        r.human_arm = s.next_text();
        r.human_grasp_id = s.next_int64();
        r.human_quality = s.next_double();
        r.second_arm = s.next_text();
        r.second_grasp_id = s.next_int64();
        r.second_quality = s.next_double();
        r.human_joints = read_joints(s, path, "handover_candidates", "human_joints", r.id, fix);
        r.second_joints = read_joints(s, path, "handover_candidates", "second_joints", r.id, fix);
      });
  db.shared_grasps_ = load_rows<SharedGraspRecord>(
      *connection, "shared_grasps",
      "candidate_id, robot_grasp_id, robot_handover_id, arm, joints_rr, joints_rh, "
      "inclination_rr_deg, inclination_rh_deg",
      fix, [&](detail::Statement& s, std::int64_t id, SharedGraspRecord& r) {
        r.id = id;
        r.candidate_id = s.next_int64();
        r.robot_grasp_id = s.next_int64();
        r.robot_handover_id = s.next_int64();
        r.arm = s.next_text();
        r.joints_rr = read_joints(s, path, "shared_grasps", "joints_rr", id, fix);
        r.joints_rh = read_joints(s, path, "shared_grasps", "joints_rh", id, fix);
        r.inclination_rr_deg = s.next_double();
        r.inclination_rh_deg = s.next_double();
      });
  db.ergonomics_ = load_rows<ErgonomicsRecord>(
      *connection, "ergonomics",
      "part_id, method, reachable, torso_flexion_deg, shoulder_elevated, reach, "
      "reorientation_deg, quality, arm",
      fix, [&](detail::Statement& s, std::int64_t, ErgonomicsRecord& r) {
        r.part_id = s.next_int64();
        r.method = s.next_text();
        r.reachable = s.next_int64() != 0;
        r.torso_flexion_deg = s.next_double();
        r.shoulder_elevated = s.next_int64() != 0;
        r.reach = s.next_double();
        r.reorientation_deg = s.next_double();
        r.quality = s.next_double();
        r.arm = s.next_text();
      });
  return db;
}

const PartRecord& Database::part(const std::string& name) const {
  for (const auto& p : parts_) {
    if (p.name == name) return p;
  }
  std::string known;
  for (const auto& p : parts_) known += (known.empty() ? "" : ", ") + p.name;
  throw core::InputError(
      path_, "parts",
      "a part named '" + name + "' (parts: " + (known.empty() ? std::string("none") : known) + ")",
      "no such part");
}

const ComfortMapRecord& Database::comfort_map(const std::string& arm) const {
  for (const auto& map : comfort_maps_) {
    if (map.arm == arm) return map;
  }
  std::string known;
  for (const auto& map : comfort_maps_) known += (known.empty() ? "" : ", ") + map.arm;
  throw core::InputError(path_, "comfort_maps",
                         "a comfort map for arm '" + arm +
                             "' (arms: " + (known.empty() ? std::string("none") : known) + ")",
                         "no such arm");
}

std::vector<PlacementRecord> Database::placements(std::int64_t part_id) const {
  return for_part(placements_, part_id);
}

std::vector<RobotGraspRecord> Database::robot_grasps(std::int64_t part_id) const {
  return for_part(robot_grasps_, part_id);
}

std::vector<SuctionGraspRecord> Database::suction_grasps(std::int64_t part_id) const {
  return for_part(suction_grasps_, part_id);
}

std::vector<HumanGraspRecord> Database::human_grasps(std::int64_t part_id) const {
  return for_part(human_grasps_, part_id);
}

const HandoverStageRecord* Database::handover_stage(std::int64_t part_id) const {
  for (const auto& stage : handover_stages_) {
    if (stage.part_id == part_id) return &stage;
  }
  return nullptr;
}

std::vector<RobotHandoverRecord> Database::robot_handovers(std::int64_t part_id) const {
  return for_part(robot_handovers_, part_id);
}

std::vector<HandoverCandidateRecord> Database::handover_candidates(std::int64_t part_id) const {
  return for_part(handover_candidates_, part_id);
}

std::vector<HandoverCandidateRecord> Database::handover_goals(std::int64_t part_id) const {
  std::vector<HandoverCandidateRecord> goals;
  for (const auto& c : handover_candidates_) {
    if (c.part_id == part_id && c.status == "goal") goals.push_back(c);
  }
  // Stable: equal ranks (only in a hand-edited file) stay in id order.
  std::stable_sort(goals.begin(), goals.end(),
                   [](const auto& a, const auto& b) { return a.rank < b.rank; });
  return goals;
}

std::vector<SharedGraspRecord> Database::shared_grasps(std::int64_t candidate_id) const {
  std::vector<SharedGraspRecord> selected;
  std::copy_if(shared_grasps_.begin(), shared_grasps_.end(), std::back_inserter(selected),
               [&](const SharedGraspRecord& g) { return g.candidate_id == candidate_id; });
  return selected;
}

std::vector<ErgonomicsRecord> Database::ergonomics(std::int64_t part_id) const {
  return for_part(ergonomics_, part_id);
}

}  // namespace hila::db
