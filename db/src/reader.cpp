#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <optional>

#include "comfort_codec.hpp"
#include "digest.hpp"
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

// What the loaders verify besides their own checks, in the same pass over the rows: each row's
// storage classes before it is read, and each table's content digest, kept to be compared with
// the stored ones once everything is loaded (so that damage a loader can name is reported by it).
struct Verification {
  std::string path;
  std::string fix;
  std::map<std::string, std::string> digests;  // table -> computed content digest
};

// Starts verifying `table` as read by `select`, which must select all its columns in the schema's
// order (all the loaders do).
std::unique_ptr<detail::TableDigest> begin_verifying(Verification& verify,
                                                     detail::Connection& connection,
                                                     const std::string& table,
                                                     const detail::Statement& select) {
  auto digest = std::make_unique<detail::TableDigest>(verify.path, table, verify.fix, true);
  digest->begin(connection, select);
  return digest;
}

// Reads rows of `table` in id order; `read_row` gets the row's id and consumes `columns` (all the
// table's columns after id, in the schema's order).
template <typename Record>
std::vector<Record> load_rows(
    detail::Connection& connection, const std::string& table, const std::string& columns,
    const std::string& fix, Verification& verify,
    const std::function<void(detail::Statement&, std::int64_t id, Record&)>& read_row) {
  detail::Statement select(connection, "SELECT id, " + columns + " FROM " + table + " ORDER BY id",
                           {table, "a readable hila table", fix});
  const auto digest = begin_verifying(verify, connection, table, select);
  std::vector<Record> records;
  while (select.step()) {
    digest->check_row(select);
    digest->hash_row(select);
    Record record;
    const std::int64_t id = select.next_int64();
    read_row(select, id, record);
    records.push_back(std::move(record));
  }
  verify.digests[table] = digest->finish();
  return records;
}

// Reads rows of `table` in id order; `read_row` consumes the columns after id and part_id.
template <typename Record>
std::vector<Record> load_table(detail::Connection& connection, const std::string& table,
                               const std::string& columns, const std::string& fix,
                               Verification& verify,
                               const std::function<void(detail::Statement&, Record&)>& read_row) {
  return load_rows<Record>(connection, table, "part_id, " + columns, fix, verify,
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

// A double as it is stored (17 significant digits), for "got ..." in a DatabaseError.
std::string exact(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
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
  // Added in hila 0.12: "" or the 7 pose numbers (x y z qw qx qy qz).
  const auto relay = map.find("tool_relay");
  if (relay != map.end() && !relay->second.empty()) {
    meta.tool_relay = detail::parse_pose_text(relay->second);
    if (!meta.tool_relay) {
      throw DatabaseError(path, "meta.tool_relay",
                          "'' or a pose as 7 numbers (x y z qw qx qy qz, a unit quaternion)",
                          "'" + relay->second + "'", fix);
    }
  }
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
                                                const std::string& path, const std::string& fix,
                                                Verification& verify) {
  detail::Statement select(connection,
                           "SELECT id, arm, " + vector_columns("origin") +
                               ", spacing, dim_x, dim_y, dim_z, orientation_count, orientations, "
                               "value_bytes, values_deflate, samples, seed, coverage "
                               "FROM comfort_maps ORDER BY id",
                           {"comfort_maps", "a readable hila table", fix});
  const auto digest = begin_verifying(verify, connection, "comfort_maps", select);
  std::vector<ComfortMapRecord> maps;
  while (select.step()) {
    digest->check_row(select);
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
    // Hashed with the values inflated above, rather than inflating them again.
    digest->hash_row(select, &map.values);
    maps.push_back(std::move(map));
  }
  verify.digests["comfort_maps"] = digest->finish();
  return maps;
}

// A damaged version 4 row: DatabaseError "FILE: TABLE.COLUMN (ROW): expected X, got Y; FIX".
class RowCheck {
 public:
  RowCheck(std::string path, std::string table, std::string fix)
      : path_(std::move(path)), table_(std::move(table)), fix_(std::move(fix)) {}

  void set_row(std::string row) { row_ = std::move(row); }

  [[noreturn]] void fail(const std::string& column, const std::string& expected,
                         const std::string& got) const {
    throw DatabaseError(path_, table_ + "." + column + " (" + row_ + ")", expected, got, fix_);
  }

  // A count column: 0 <= value <= 2^31 - 1 (at least `minimum`).
  int count(const std::string& column, std::int64_t value, int minimum = 0) const {
    if (value < minimum || value > std::numeric_limits<int>::max()) {
      fail(column, "an integer from " + std::to_string(minimum) + " to 2147483647",
           std::to_string(value));
    }
    return static_cast<int>(value);
  }

  // A BLOB `decode` accepts for `count` elements of `element_bytes` bytes each ("N WHAT as
  // little-endian TYPE (B bytes each) = T bytes").
  template <typename Decode>
  void blob(const std::string& column, const std::string& bytes, std::int64_t count,
            std::int64_t element_bytes, const std::string& what, Decode&& decode) const {
    if (!decode()) {
      const std::int64_t total = detail::blob_bytes(count, element_bytes);
      fail(column,
           what + " (" + std::to_string(element_bytes) + " bytes each" +
               (total >= 0 ? ", " + std::to_string(total) + " bytes" : std::string()) + ")",
           std::to_string(bytes.size()) + " bytes");
    }
  }

  // Every value finite; `label(i)` names the one that is not.
  template <typename Values, typename Label>
  void finite(const std::string& column, const Values& values, Label&& label) const {
    for (std::size_t i = 0; i < values.size(); ++i) {
      if (!finite_value(values[i])) {
        fail(column, "finite values", "a value that is not finite (" + label(i) + ")");
      }
    }
  }

 private:
  static bool finite_value(double v) { return std::isfinite(v); }
  template <typename Derived>
  static bool finite_value(const Eigen::MatrixBase<Derived>& v) {
    return v.allFinite();
  }

  std::string path_;
  std::string table_;
  std::string fix_;
  std::string row_;
};

std::string nth(const char* what, std::size_t i) {
  return std::string(what) + " " + std::to_string(i);
}

// The roadmaps table. Every array's size is checked against the row's counts, and every value
// (finite numbers, edges joining existing nodes in order) before anything is trusted.
std::vector<RoadmapRecord> load_roadmaps(detail::Connection& connection, const std::string& path,
                                         const std::string& fix, Verification& verify) {
  RowCheck check(path, "roadmaps", fix);
  return load_rows<RoadmapRecord>(
      connection, "roadmaps",
      "arm, dof, resolution, node_count, edge_count, node_joints, node_gravity, "
      "node_inclination_deg, edge_nodes, edge_length, edge_max_inclination_deg",
      fix, verify, [&](detail::Statement& s, std::int64_t id, RoadmapRecord& r) {
        r.id = id;
        r.arm = s.next_text();
        check.set_row("arm '" + r.arm + "', id " + std::to_string(id));
        r.dof = check.count("dof", s.next_int64(), 1);
        r.resolution = s.next_double();
        if (!(r.resolution > 0.0) || !std::isfinite(r.resolution)) {
          check.fail("resolution", "a finite value > 0", std::to_string(r.resolution));
        }
        const int nodes = check.count("node_count", s.next_int64());
        const int edges = check.count("edge_count", s.next_int64());
        const std::string n = std::to_string(nodes);
        const std::string e = std::to_string(edges);

        const std::string joints = s.next_blob();
        check.blob("node_joints", joints, nodes, detail::blob_bytes(r.dof, 8),
                   "node_count * dof = " + n + " * " + std::to_string(r.dof) +
                       " joint values as little-endian doubles, one node after the other",
                   [&] { return detail::decode_vectors(joints, nodes, r.dof, r.nodes); });
        check.finite("node_joints", r.nodes, [](std::size_t i) { return nth("node", i); });
        const std::string gravity = s.next_blob();
        check.blob("node_gravity", gravity, nodes, 24,
                   "node_count = " + n + " directions as little-endian doubles x, y, z",
                   [&] { return detail::decode_vectors(gravity, nodes, r.node_gravity); });
        check.finite("node_gravity", r.node_gravity, [](std::size_t i) { return nth("node", i); });
        const std::string inclination = s.next_blob();
        check.blob("node_inclination_deg", inclination, nodes, 8,
                   "node_count = " + n + " little-endian doubles", [&] {
                     return detail::decode_double_list(inclination, nodes, r.node_inclination_deg);
                   });
        check.finite("node_inclination_deg", r.node_inclination_deg,
                     [](std::size_t i) { return nth("node", i); });

        const std::string pairs = s.next_blob();
        check.blob("edge_nodes", pairs, edges, 8,
                   "edge_count = " + e + " node pairs as little-endian int32s",
                   [&] { return detail::decode_int32_pairs(pairs, edges, r.edges); });
        for (std::size_t k = 0; k < r.edges.size(); ++k) {
          const auto [first, second] = r.edges[k];
          if (first < 0 || first >= second || second >= nodes) {
            check.fail("edge_nodes", "node pairs with 0 <= first < second < node_count = " + n,
                       "edge " + std::to_string(k) + " = (" + std::to_string(first) + ", " +
                           std::to_string(second) + ")");
          }
        }
        const std::string length = s.next_blob();
        check.blob("edge_length", length, edges, 8, "edge_count = " + e + " little-endian doubles",
                   [&] { return detail::decode_double_list(length, edges, r.edge_length); });
        check.finite("edge_length", r.edge_length, [](std::size_t i) { return nth("edge", i); });
        const std::string max_inclination = s.next_blob();
        check.blob("edge_max_inclination_deg", max_inclination, edges, 8,
                   "edge_count = " + e + " little-endian doubles", [&] {
                     return detail::decode_double_list(max_inclination, edges,
                                                       r.edge_max_inclination_deg);
                   });
        check.finite("edge_max_inclination_deg", r.edge_max_inclination_deg,
                     [](std::size_t i) { return nth("edge", i); });
      });
}

// The roadmap_filters table: the bits and component ids against their roadmap, the counts
// against the bits and ids.
std::vector<RoadmapFilterRecord> load_roadmap_filters(detail::Connection& connection,
                                                      const std::string& path,
                                                      const std::string& fix, Verification& verify,
                                                      const std::vector<RoadmapRecord>& roadmaps) {
  RowCheck check(path, "roadmap_filters", fix);
  std::map<std::int64_t, const RoadmapRecord*> by_id;
  for (const auto& r : roadmaps) by_id[r.id] = &r;
  return load_table<RoadmapFilterRecord>(
      connection, "roadmap_filters",
      "roadmap_id, grasp_kind, grasp_id, theta_c_deg, valid_edges, components, largest_component, "
      "edge_bits, node_component",
      fix, verify, [&](detail::Statement& s, RoadmapFilterRecord& f) {
        check.set_row("id " + std::to_string(f.id));
        f.roadmap_id = s.next_int64();
        f.grasp_kind = s.next_text();
        f.grasp_id = s.next_int64();
        f.theta_c_deg = s.next_double();
        f.valid_edges = check.count("valid_edges", s.next_int64());
        f.components = check.count("components", s.next_int64());
        f.largest_component = check.count("largest_component", s.next_int64());
        const auto roadmap = by_id.find(f.roadmap_id);
        if (roadmap == by_id.end()) {
          check.fail("roadmap_id", "the id of a roadmap in this file",
                     std::to_string(f.roadmap_id));
        }
        const RoadmapRecord& r = *roadmap->second;
        const auto edges = static_cast<std::int64_t>(r.edges.size());
        const auto nodes = static_cast<std::int64_t>(r.nodes.size());
        const std::string of_roadmap = " of roadmap id " + std::to_string(r.id);
        const std::string bits = s.next_blob();
        if (!detail::decode_bits(bits, edges, f.edges)) {
          check.fail("edge_bits",
                     "one bit per edge" + of_roadmap + ": " + std::to_string(edges) + " bits in " +
                         std::to_string((edges + 7) / 8) + " bytes, the unused high bits 0",
                     std::to_string(bits.size()) + " bytes" +
                         (static_cast<std::int64_t>(bits.size()) == (edges + 7) / 8
                              ? std::string(" with an unused bit set")
                              : std::string()));
        }
        const std::string ids = s.next_blob();
        check.blob("node_component", ids, nodes, 4,
                   "one component id per node" + of_roadmap + " (" + std::to_string(nodes) +
                       ") as little-endian int32s",
                   [&] { return detail::decode_int32s(ids, nodes, f.component); });
        std::map<int, int> sizes;
        for (std::size_t n = 0; n < f.component.size(); ++n) {
          if (f.component[n] < 0) {
            check.fail("node_component", "component ids >= 0",
                       nth("node", n) + ": " + std::to_string(f.component[n]));
          }
          ++sizes[f.component[n]];
        }
        for (std::size_t e = 0; e < f.edges.size(); ++e) {
          const auto [a, b] = r.edges[e];
          if (f.edges[e] && f.component[a] != f.component[b]) {
            check.fail("node_component", "the same id at both ends of every set edge",
                       "edge " + std::to_string(e) + " joining components " +
                           std::to_string(f.component[a]) + " and " +
                           std::to_string(f.component[b]));
          }
        }
        int largest = 0;
        for (const auto& entry : sizes) largest = std::max(largest, entry.second);
        const auto count = [&](const char* column, int got, int want, const std::string& what) {
          if (got != want)
            check.fail(column, what + " = " + std::to_string(want), std::to_string(got));
        };
        count("valid_edges", f.valid_edges,
              static_cast<int>(std::count(f.edges.begin(), f.edges.end(), true)),
              "the set bits of edge_bits");
        count("components", f.components, static_cast<int>(sizes.size()),
              "the distinct ids of node_component");
        count("largest_component", f.largest_component, largest,
              "the nodes of the largest component");
      });
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
  if (options.expected_hila_version) {
    detail::check_hila_version(path, db.meta_.hila_version, *options.expected_hila_version, fix);
  }
  check_hash(path, "cell", "cell_hash", db.meta_.cell_hash, options.expected_cell_hash, fix);
  check_hash(path, "product", "product_hash", db.meta_.product_hash, options.expected_product_hash,
             fix);
  // While loading, each row's storage classes before its values are read (read as a number, 'abc'
  // or NULL would pass as 0) and each table's digest; then every reference; last the digests are
  // compared, so that damage a more specific check can name is reported by it.
  Verification verify{path, fix, {}};
  verify.digests["meta"] = detail::table_digest(*connection, path, "meta", fix, true);

  {
    detail::Statement select(
        *connection,
        "SELECT id, name, assembly_order, mesh_file, mesh_hash, mass, volume, " +
            vector_columns("com") + ", ixx, iyy, izz, ixy, ixz, iyz, " + vector_columns("extent") +
            ", triangle_count, " + pose_columns("target") + ", " + pose_columns("initial") +
            " FROM parts ORDER BY id",
        {"parts", "a readable hila table", fix});
    const auto digest = begin_verifying(verify, *connection, "parts", select);
    while (select.step()) {
      digest->check_row(select);
      digest->hash_row(select);
      PartRecord part;
      part.id = select.next_int64();
      part.name = select.next_text();
      part.assembly_order = static_cast<int>(select.next_int64());
      part.mesh_file = select.next_text();
      part.mesh_hash = select.next_text();
      part.mass = select.next_double();
      if (!(part.mass > 0.0) || !std::isfinite(part.mass)) {
        throw DatabaseError(
            path, "parts.mass (part '" + part.name + "', id " + std::to_string(part.id) + ")",
            "a mass in kg, finite and > 0", exact(part.mass), fix);
      }
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
    verify.digests["parts"] = digest->finish();
  }

  db.placements_ = load_table<PlacementRecord>(
      *connection, "placements", pose_columns("part_in_plane") + ", stability", fix, verify,
      [&](detail::Statement& s, PlacementRecord& r) {
        r.part_in_plane = read_pose(s, path, "placements", "part_in_plane", r.id, fix);
        r.stability = s.next_double();
      });
  db.robot_grasps_ = load_table<RobotGraspRecord>(
      *connection, "robot_grasps",
      pose_columns("tcp") + ", jaw_width, " + vector_columns("contact_1") + ", " +
          vector_columns("normal_1") + ", " + vector_columns("contact_2") + ", " +
          vector_columns("normal_2") + ", quality, friction_torque_capacity, lever, theta_c_deg",
      fix, verify, [&](detail::Statement& s, RobotGraspRecord& r) {
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
      pose_columns("cup") + ", rotation_deg, force_margin, moment_margin", fix, verify,
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
      fix, verify, [&](detail::Statement& s, HumanGraspRecord& r) {
        r.hand = read_pose(s, path, "human_grasps", "hand", r.id, fix);
        r.aperture = s.next_double();
        r.contact_1 = read_vector(s);
        r.contact_2 = read_vector(s);
        r.quality = s.next_double();
        r.one_hand_stable = s.next_int64() != 0;
      });
  db.comfort_maps_loaded_ = options.comfort_maps;
  if (options.comfort_maps) {
    db.comfort_maps_ = load_comfort_maps(*connection, path, fix, verify);
  } else {
    detail::check_table_types(*connection, path, "comfort_maps", fix);  // not hashed: not read
  }

  db.handover_stages_ = load_rows<HandoverStageRecord>(
      *connection, "handover_stages",
      "part_id, finished_parts, draws, candidates, comfortable, comfortable_default_body, goals, "
      "robot_handovers, two_hands, failure",
      fix, verify, [&](detail::Statement& s, std::int64_t, HandoverStageRecord& r) {
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
      fix, verify, [&](detail::Statement& s, RobotHandoverRecord& r) {
        r.board = read_pose(s, path, "robot_handovers", "board", r.id, fix);
        r.suction_grasp_id = s.next_int64();
        r.arm = s.next_text();
        r.joints = read_joints(s, path, "robot_handovers", "joints", r.id, fix);
      });
  const std::size_t body_count = human_body_labels(db.meta_.human_bodies).size();
  db.handover_candidates_ = load_table<HandoverCandidateRecord>(
      *connection, "handover_candidates",
      "sample, " + pose_columns("board") +
          ", distance, quality, status, rank, human_arm, human_grasp_id, human_quality, "
          "second_arm, second_grasp_id, second_quality, human_joints, second_joints, bodies",
      fix, verify, [&](detail::Statement& s, HandoverCandidateRecord& r) {
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
        // Schema version 10: bit i for body i of meta.human_bodies. The file's CHECK bounds it to
        // 32 bits (but is not verified on this read-only connection); the body count it cannot
        // know.
        const std::int64_t bodies = s.next_int64();
        if (!detail::body_mask_fits(bodies, body_count)) {
          throw DatabaseError(path, "handover_candidates.bodies (id " + std::to_string(r.id) + ")",
                              detail::body_mask_expectation(db.meta_.human_bodies),
                              std::to_string(bodies), fix);
        }
        r.bodies = static_cast<std::uint32_t>(bodies);
      });
  db.shared_grasps_ = load_rows<SharedGraspRecord>(
      *connection, "shared_grasps",
      "candidate_id, robot_grasp_id, robot_handover_id, arm, joints_rr, joints_rh, "
      "inclination_rr_deg, inclination_rh_deg",
      fix, verify, [&](detail::Statement& s, std::int64_t id, SharedGraspRecord& r) {
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
  db.direct_grasps_ = load_rows<DirectGraspRecord>(
      *connection, "direct_grasps",
      "candidate_id, robot_grasp_id, arm, joints_pick, joints_rh, inclination_pick_deg, "
      "inclination_rh_deg",
      fix, verify, [&](detail::Statement& s, std::int64_t id, DirectGraspRecord& r) {
        r.id = id;
        r.candidate_id = s.next_int64();
        r.robot_grasp_id = s.next_int64();
        r.arm = s.next_text();
        r.joints_pick = read_joints(s, path, "direct_grasps", "joints_pick", id, fix);
        r.joints_rh = read_joints(s, path, "direct_grasps", "joints_rh", id, fix);
        r.inclination_pick_deg = s.next_double();
        r.inclination_rh_deg = s.next_double();
      });
  db.table_regrasps_ = load_rows<TableRegraspRecord>(
      *connection, "table_regrasps",
      "candidate_id, pick_grasp_id, robot_grasp_id, arm, repick_arm, " + pose_columns("placement") +
          ", joints_pick, joints_place, joints_repick, joints_rh, inclination_pick_deg, "
          "inclination_place_deg, inclination_repick_deg, inclination_rh_deg",
      fix, verify, [&](detail::Statement& s, std::int64_t id, TableRegraspRecord& r) {
        r.id = id;
        r.candidate_id = s.next_int64();
        r.pick_grasp_id = s.next_int64();
        r.robot_grasp_id = s.next_int64();
        r.arm = s.next_text();
        r.repick_arm = s.next_text();
        r.placement = read_pose(s, path, "table_regrasps", "placement", id, fix);
        r.joints_pick = read_joints(s, path, "table_regrasps", "joints_pick", id, fix);
        r.joints_place = read_joints(s, path, "table_regrasps", "joints_place", id, fix);
        r.joints_repick = read_joints(s, path, "table_regrasps", "joints_repick", id, fix);
        r.joints_rh = read_joints(s, path, "table_regrasps", "joints_rh", id, fix);
        r.inclination_pick_deg = s.next_double();
        r.inclination_place_deg = s.next_double();
        r.inclination_repick_deg = s.next_double();
        r.inclination_rh_deg = s.next_double();
      });
  db.suction_deliveries_ = load_rows<SuctionDeliveryRecord>(
      *connection, "suction_deliveries", "candidate_id, suction_grasp_id, arm, joints_rh", fix,
      verify, [&](detail::Statement& s, std::int64_t id, SuctionDeliveryRecord& r) {
        r.id = id;
        r.candidate_id = s.next_int64();
        r.suction_grasp_id = s.next_int64();
        r.arm = s.next_text();
        r.joints_rh = read_joints(s, path, "suction_deliveries", "joints_rh", id, fix);
      });
  db.ergonomics_ = load_rows<ErgonomicsRecord>(
      *connection, "ergonomics",
      "part_id, method, reachable, torso_flexion_deg, shoulder_elevated, reach, "
      "reorientation_deg, quality, arm",
      fix, verify, [&](detail::Statement& s, std::int64_t, ErgonomicsRecord& r) {
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

  db.roadmaps_ = load_roadmaps(*connection, path, fix, verify);
  db.roadmap_filters_ = load_roadmap_filters(*connection, path, fix, verify, db.roadmaps_);
  db.regrasp_nodes_ = load_table<RegraspNodeRecord>(
      *connection, "regrasp_nodes",
      "kind, arm, grasp_kind, grasp_id, robot_handover_id, candidate_id, " + pose_columns("board") +
          ", dof, solution_count, solutions",
      fix, verify, [&](detail::Statement& s, RegraspNodeRecord& r) {
        RowCheck check(path, "regrasp_nodes", fix);
        check.set_row("id " + std::to_string(r.id));
        r.kind = s.next_text();
        r.arm = s.next_text();
        r.grasp_kind = s.next_text();
        r.grasp_id = s.next_int64();
        r.robot_handover_id = s.next_int64();  // NULL reads as 0
        r.candidate_id = s.next_int64();
        r.board = read_pose(s, path, "regrasp_nodes", "board", r.id, fix);
        const int dof = check.count("dof", s.next_int64(), 1);
        const int count = check.count("solution_count", s.next_int64(), 1);
        const std::string bytes = s.next_blob();
        check.blob("solutions", bytes, count, detail::blob_bytes(dof, 8),
                   "solution_count * dof = " + std::to_string(count) + " * " + std::to_string(dof) +
                       " joint values as little-endian doubles",
                   [&] { return detail::decode_vectors(bytes, count, dof, r.solutions); });
        check.finite("solutions", r.solutions, [](std::size_t i) { return nth("solution", i); });
      });
  db.regrasp_edges_ = load_table<RegraspEdgeRecord>(
      *connection, "regrasp_edges",
      "kind, arm, from_node, to_node, filter_id, connected, cost, path_nodes, via, path_dof, "
      "path_waypoints, path, duration",
      fix, verify, [&](detail::Statement& s, RegraspEdgeRecord& r) {
        RowCheck check(path, "regrasp_edges", fix);
        check.set_row("id " + std::to_string(r.id));
        r.kind = s.next_text();
        r.arm = s.next_text();
        r.from_node = s.next_int64();
        r.to_node = s.next_int64();
        r.filter_id = s.next_int64();  // NULL reads as 0
        r.connected = s.next_int64() != 0;
        r.cost = s.next_double();
        r.path_nodes = static_cast<int>(s.next_int64());
        r.via = s.next_text();
        // No path: both counts 0. A path: at least 2 waypoints of at least one joint.
        const std::int64_t stored_dof = s.next_int64();
        const int waypoints = check.count("path_waypoints", s.next_int64());
        if (waypoints == 1) {
          check.fail("path_waypoints", "0 (no path) or an integer from 2 to 2147483647", "1");
        }
        const int dof = check.count("path_dof", stored_dof, waypoints > 0 ? 1 : 0);
        if (waypoints == 0 && dof != 0) {
          check.fail("path_dof", "0 when path_waypoints is 0", std::to_string(dof));
        }
        const std::string bytes = s.next_blob();
        check.blob("path", bytes, waypoints, detail::blob_bytes(dof, 8),
                   "path_waypoints * path_dof = " + std::to_string(waypoints) + " * " +
                       std::to_string(dof) + " joint values as little-endian doubles",
                   [&] { return detail::decode_vectors(bytes, waypoints, dof, r.path); });
        check.finite("path", r.path, [](std::size_t i) { return nth("waypoint", i); });
        // Schema version 9. The file's CHECKs refuse a negative value and one without a path,
        // but not +infinity (nor a file whose schema lost them).
        r.duration = s.next_double();
        if (!std::isfinite(r.duration) || r.duration < 0.0) {
          check.fail("duration", "a time in seconds, finite and >= 0", exact(r.duration));
        }
        if (waypoints == 0 && r.duration != 0.0) {
          check.fail("duration", "0 when path_waypoints is 0 (no path)", exact(r.duration));
        }
      });
  detail::check_references(*connection, path, fix);
  detail::check_table_digests(path, meta_map, verify.digests, fix);
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

std::vector<ComfortMapRecord> Database::read_comfort_maps() const {
  const auto connection = detail::open_hila_database(path_);
  const auto meta_map = detail::read_meta_table(*connection);
  const std::string fix = detail::rebuild_hint(path_, meta_map);
  const Meta now = parse_meta(path_, meta_map, detail::stored_schema_version(path_, meta_map));
  if (now.created_at != meta_.created_at || now.settings_hash != meta_.settings_hash ||
      now.cell_hash != meta_.cell_hash || now.product_hash != meta_.product_hash ||
      now.seed != meta_.seed) {
    throw DatabaseError(path_, "meta", "the database opened (created " + meta_.created_at + ")",
                        "a file rebuilt or replaced since (created " + now.created_at + ")",
                        "open it again");
  }
  Verification verify{path_, fix, {}};
  auto maps = load_comfort_maps(*connection, path_, fix, verify);
  detail::check_table_digests(path_, meta_map, verify.digests, fix);
  return maps;
}

const ComfortMapRecord& Database::comfort_map(const std::string& arm) const {
  if (!comfort_maps_loaded_) {
    throw core::InputError(
        path_, "comfort_maps", "the comfort map for arm '" + arm + "' loaded",
        "a database opened without its comfort maps (OpenOptions::comfort_maps)");
  }
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

std::vector<DirectGraspRecord> Database::direct_grasps(std::int64_t candidate_id) const {
  std::vector<DirectGraspRecord> selected;
  std::copy_if(direct_grasps_.begin(), direct_grasps_.end(), std::back_inserter(selected),
               [&](const DirectGraspRecord& g) { return g.candidate_id == candidate_id; });
  return selected;
}

std::vector<TableRegraspRecord> Database::table_regrasps(std::int64_t candidate_id) const {
  std::vector<TableRegraspRecord> selected;
  std::copy_if(table_regrasps_.begin(), table_regrasps_.end(), std::back_inserter(selected),
               [&](const TableRegraspRecord& g) { return g.candidate_id == candidate_id; });
  return selected;
}

std::vector<SuctionDeliveryRecord> Database::suction_deliveries(std::int64_t candidate_id) const {
  std::vector<SuctionDeliveryRecord> selected;
  std::copy_if(suction_deliveries_.begin(), suction_deliveries_.end(), std::back_inserter(selected),
               [&](const SuctionDeliveryRecord& d) { return d.candidate_id == candidate_id; });
  return selected;
}

std::vector<ErgonomicsRecord> Database::ergonomics(std::int64_t part_id) const {
  return for_part(ergonomics_, part_id);
}

const RoadmapRecord* Database::roadmap(const std::string& arm) const {
  for (const auto& r : roadmaps_) {
    if (r.arm == arm) return &r;
  }
  return nullptr;
}

std::vector<RoadmapFilterRecord> Database::roadmap_filters(std::int64_t part_id) const {
  return for_part(roadmap_filters_, part_id);
}

const RoadmapFilterRecord* Database::roadmap_filter(std::int64_t id) const {
  const auto it = std::lower_bound(
      roadmap_filters_.begin(), roadmap_filters_.end(), id,
      [](const RoadmapFilterRecord& f, std::int64_t value) { return f.id < value; });
  return it != roadmap_filters_.end() && it->id == id ? &*it : nullptr;
}

std::vector<RegraspNodeRecord> Database::regrasp_nodes(std::int64_t part_id) const {
  return for_part(regrasp_nodes_, part_id);
}

std::vector<RegraspEdgeRecord> Database::regrasp_edges(std::int64_t part_id) const {
  return for_part(regrasp_edges_, part_id);
}

}  // namespace hila::db
