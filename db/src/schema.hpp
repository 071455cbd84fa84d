#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hila::db::detail {

// CREATE statements of the current schema (tables and indexes; meta rows are the writer's job).
const std::string& schema_sql();

// Every table in a fixed order: the content digest hashes them in this order (those the file's
// schema version has).
struct TableInfo {
  const char* name;
  int since_version;  // the schema version that added the table
};
inline constexpr std::array<TableInfo, 19> kTables = {{{"meta", 1},
                                                       {"parts", 1},
                                                       {"placements", 1},
                                                       {"robot_grasps", 1},
                                                       {"suction_grasps", 1},
                                                       {"human_grasps", 1},
                                                       {"comfort_maps", 2},
                                                       {"handover_stages", 3},
                                                       {"robot_handovers", 3},
                                                       {"handover_candidates", 3},
                                                       {"shared_grasps", 3},
                                                       {"ergonomics", 3},
                                                       {"roadmaps", 4},
                                                       {"roadmap_filters", 4},
                                                       {"regrasp_nodes", 4},
                                                       {"regrasp_edges", 4},
                                                       {"direct_grasps", 5},
                                                       {"table_regrasps", 6},
                                                       {"suction_deliveries", 8}}};

// The meta keys every database carries. Keys added later are optional when reading: the writer
// always writes human_bodies (since version 3), the reader takes a missing one as "".
inline constexpr std::array<const char*, 10> kMetaKeys = {
    "schema_version", "hila_version", "product_name", "cell_hash", "product_hash",
    "settings_hash",  "seed",         "created_at",   "cell_file", "product_file"};

// The schema version since which every database holds a content digest per table in meta
// (digest_key(table)): the writer stores them at commit, a migration to it or later writes them
// after its last step, and Database::open compares them.
inline constexpr int kTableDigestsSince = 7;

// "digest.<table>": the meta key of a table's stored content digest.
std::string digest_key(const std::string& table);

// A column as the current schema declares it: its name, the SQLite storage class its values must
// have (SQLITE_INTEGER, SQLITE_FLOAT, SQLITE_TEXT or SQLITE_BLOB) and whether NULL is allowed (the
// optional references of version 4).
struct ColumnSpec {
  std::string name;
  int storage_class = 0;
  bool nullable = false;
};

// The columns of `table` in the current schema, in declaration order (read once from schema_sql()
// run on an in-memory database, so they cannot drift from it). Empty for an unknown table.
const std::vector<ColumnSpec>& schema_columns(const std::string& table);

// Whether `mask` (HandoverCandidateRecord::bodies, handover_candidates.bodies) sets only bits
// below `body_count`, one per body of meta.human_bodies (human_body_labels), and fits in 32 bits.
bool body_mask_fits(std::int64_t mask, std::size_t body_count);

// What a mask of `human_bodies`' bodies may be, for the "expected" of a refusal, e.g. "a mask of
// the 2 bodies of meta.human_bodies ('1.5 female; 1.82 male'): bits 0 to 1, from 0 to 3", or "0
// (meta.human_bodies names no body: the cell's human only)".
std::string body_mask_expectation(const std::string& human_bodies);

// Column lists of a pose ("p_x, p_y, p_z, p_qw, p_qx, p_qy, p_qz") and a vector ("v_x, v_y, v_z").
std::string pose_columns(const std::string& prefix);
std::string vector_columns(const std::string& prefix);

}  // namespace hila::db::detail
