#include "schema.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sqlite_handle.hpp"

#ifndef HILA_VERSION
#error "HILA_VERSION (the project version) must be defined: db/CMakeLists.txt sets it"
#endif

namespace hila::db {

std::string hila_version() {
  return HILA_VERSION;
}

std::vector<std::string> human_body_labels(const std::string& human_bodies) {
  static const std::string kSeparator = "; ";
  std::vector<std::string> labels;
  std::size_t begin = 0;
  while (begin <= human_bodies.size()) {
    std::size_t end = human_bodies.find(kSeparator, begin);
    if (end == std::string::npos) end = human_bodies.size();
    if (end > begin) labels.push_back(human_bodies.substr(begin, end - begin));
    begin = end + kSeparator.size();
  }
  return labels;
}

// Bump together with a new entry in migration_steps() and a schema_sql() change.
int current_schema_version() {
  return 10;
}

namespace detail {

namespace {

// The comfort_maps table as schema version 2 defines it. Both the current schema and the 1 -> 2
// migration step create it from this text. If a later version changes the table, write the new
// definition into schema_sql() and leave this one to the 1 -> 2 step (a step must keep producing
// the version it upgrades to).
//
// values_deflate is zlib (compress2, level 6) of value_bytes bytes, one per bin, Q * 255, bin
// ((x * dim_y + y) * dim_z + z) * orientation_count + o; orientations holds orientation_count
// quaternions as little-endian doubles w, x, y, z; seed is the uint64 seed's bit pattern.
constexpr const char* kCreateComfortMapsV2 = R"sql(
CREATE TABLE comfort_maps (
  id INTEGER PRIMARY KEY,
  arm TEXT UNIQUE NOT NULL,
  origin_x REAL NOT NULL, origin_y REAL NOT NULL, origin_z REAL NOT NULL,
  spacing REAL NOT NULL,
  dim_x INTEGER NOT NULL, dim_y INTEGER NOT NULL, dim_z INTEGER NOT NULL,
  orientation_count INTEGER NOT NULL,
  orientations BLOB NOT NULL,
  value_bytes INTEGER NOT NULL,
  values_deflate BLOB NOT NULL,
  samples INTEGER NOT NULL,
  seed INTEGER NOT NULL,
  coverage REAL NOT NULL
);
)sql";

// The handover and ergonomics tables as schema version 3 defines them, one constant per table
// (with its indexes). Both the current schema and the 2 -> 3 migration step create them from this
// text, but for handover_candidates, which version 10 changed (kCreateHandoverCandidatesV10): like
// kCreateComfortMapsV2, a later change goes into a constant of its own and leaves these to the
// step.
//
// handover_stages.finished_parts is the part names joined by "\n" ("" for none); joint vectors
// (robot_handovers.joints, handover_candidates.human_joints/second_joints, shared_grasps.joints_rr
// and joints_rh) are BLOBs of little-endian IEEE doubles, 8 bytes per joint (empty: no joints).
constexpr const char* kCreateHandoverStagesV3 = R"sql(
CREATE TABLE handover_stages (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL UNIQUE REFERENCES parts(id),
  finished_parts TEXT NOT NULL,
  draws INTEGER NOT NULL,
  candidates INTEGER NOT NULL,
  comfortable INTEGER NOT NULL,
  comfortable_default_body INTEGER NOT NULL,
  goals INTEGER NOT NULL,
  robot_handovers INTEGER NOT NULL,
  two_hands INTEGER NOT NULL CHECK (two_hands IN (0, 1)),
  failure TEXT NOT NULL
);
)sql";

constexpr const char* kCreateRobotHandoversV3 = R"sql(
CREATE TABLE robot_handovers (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  board_x REAL NOT NULL, board_y REAL NOT NULL, board_z REAL NOT NULL,
  board_qw REAL NOT NULL, board_qx REAL NOT NULL, board_qy REAL NOT NULL, board_qz REAL NOT NULL,
  suction_grasp_id INTEGER NOT NULL REFERENCES suction_grasps(id),
  arm TEXT NOT NULL,
  joints BLOB NOT NULL
);
CREATE INDEX robot_handovers_part_id ON robot_handovers(part_id);
)sql";

constexpr const char* kCreateHandoverCandidatesV3 = R"sql(
CREATE TABLE handover_candidates (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  sample INTEGER NOT NULL,
  board_x REAL NOT NULL, board_y REAL NOT NULL, board_z REAL NOT NULL,
  board_qw REAL NOT NULL, board_qx REAL NOT NULL, board_qy REAL NOT NULL, board_qz REAL NOT NULL,
  distance REAL NOT NULL,
  quality REAL NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('uncomfortable', 'no_shared_grasp', 'goal')),
  rank INTEGER NOT NULL,
  human_arm TEXT NOT NULL,
  human_grasp_id INTEGER NOT NULL,
  human_quality REAL NOT NULL,
  second_arm TEXT NOT NULL,
  second_grasp_id INTEGER NOT NULL,
  second_quality REAL NOT NULL,
  human_joints BLOB NOT NULL,
  second_joints BLOB NOT NULL,
  CHECK ((status = 'goal' AND rank >= 0) OR (status <> 'goal' AND rank = -1))
);
CREATE INDEX handover_candidates_part_id ON handover_candidates(part_id);
)sql";

constexpr const char* kCreateSharedGraspsV3 = R"sql(
CREATE TABLE shared_grasps (
  id INTEGER PRIMARY KEY,
  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),
  robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),
  robot_handover_id INTEGER NOT NULL REFERENCES robot_handovers(id),
  arm TEXT NOT NULL,
  joints_rr BLOB NOT NULL,
  joints_rh BLOB NOT NULL,
  inclination_rr_deg REAL NOT NULL,
  inclination_rh_deg REAL NOT NULL
);
CREATE INDEX shared_grasps_candidate_id ON shared_grasps(candidate_id);
)sql";

constexpr const char* kCreateErgonomicsV3 = R"sql(
CREATE TABLE ergonomics (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  method TEXT NOT NULL CHECK (method IN ('hila', 'table', 'alone')),
  reachable INTEGER NOT NULL CHECK (reachable IN (0, 1)),
  torso_flexion_deg REAL NOT NULL,
  shoulder_elevated INTEGER NOT NULL CHECK (shoulder_elevated IN (0, 1)),
  reach REAL NOT NULL,
  reorientation_deg REAL NOT NULL,
  quality REAL NOT NULL,
  arm TEXT NOT NULL,
  UNIQUE (part_id, method)
);
)sql";

// Every table schema version 3 adds, in schema order, as version 3 declared them (the 2 -> 3
// step; schema_sql() has the version 10 handover_candidates, create_tables_v10()).
std::string create_tables_v3() {
  return std::string(kCreateHandoverStagesV3) + kCreateRobotHandoversV3 +
         kCreateHandoverCandidatesV3 + kCreateSharedGraspsV3 + kCreateErgonomicsV3;
}

// The handover_candidates table as schema version 10 defines it (with its index): version 3's
// with bodies, the bodies of meta.human_bodies (the build's worker set) that take the candidate
// above the comfort threshold at its stored grasps, bit i for body i in stored order
// (records::HandoverCandidateRecord::bodies, an unsigned 32-bit mask; 0 without a body set, and on
// every row migrated from version 9 or earlier: not computed). Created by schema_sql() and by the
// 9 -> 10 step (rebuild_handover_candidates_v10) from this text; kCreateHandoverCandidatesV3 stays
// for the 2 -> 3 step.
constexpr const char* kCreateHandoverCandidatesV10 = R"sql(
CREATE TABLE handover_candidates (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  sample INTEGER NOT NULL,
  board_x REAL NOT NULL, board_y REAL NOT NULL, board_z REAL NOT NULL,
  board_qw REAL NOT NULL, board_qx REAL NOT NULL, board_qy REAL NOT NULL, board_qz REAL NOT NULL,
  distance REAL NOT NULL,
  quality REAL NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('uncomfortable', 'no_shared_grasp', 'goal')),
  rank INTEGER NOT NULL,
  human_arm TEXT NOT NULL,
  human_grasp_id INTEGER NOT NULL,
  human_quality REAL NOT NULL,
  second_arm TEXT NOT NULL,
  second_grasp_id INTEGER NOT NULL,
  second_quality REAL NOT NULL,
  human_joints BLOB NOT NULL,
  second_joints BLOB NOT NULL,
  bodies INTEGER NOT NULL CHECK (bodies >= 0 AND bodies < 4294967296),
  CHECK ((status = 'goal' AND rank >= 0) OR (status <> 'goal' AND rank = -1))
);
CREATE INDEX handover_candidates_part_id ON handover_candidates(part_id);
)sql";

// The 9 -> 10 step: the version 10 handover_candidates in place of the version 9 one (which is
// version 3's), every row kept with bodies 0 (not computed). The column is first added as ALTER
// TABLE adds one, at the end, every row's its DEFAULT 0 (and the step fails, leaving the file as it
// was, on a table that has the column already: a version 10 file whose version was set back). Then
// the table is rebuilt, as the 8 -> 9 step rebuilt regrasp_edges, so that the file declares it
// exactly as a fresh one does (an added column keeps its DEFAULT): the old table renamed out of the
// way (its index dropped, so the name is free), the version 10 one created, the rows copied with
// their ids, the old one dropped. Unlike regrasp_edges, handover_candidates is referred to by
// shared_grasps, direct_grasps, table_regrasps, suction_deliveries and regrasp_nodes: the rename
// runs with legacy_alter_table on (and the migration's connection has foreign_keys off), so that
// their REFERENCES handover_candidates(id) are left as they are, naming the new table once it is
// created, rather than rewritten to the old one's new name.
constexpr const char* kHandoverCandidatesColumnsV10 =
    "id, part_id, sample, board_x, board_y, board_z, board_qw, board_qx, board_qy, board_qz, "
    "distance, quality, status, rank, human_arm, human_grasp_id, human_quality, second_arm, "
    "second_grasp_id, second_quality, human_joints, second_joints, bodies";

std::string rebuild_handover_candidates_v10() {
  return std::string(
             "ALTER TABLE handover_candidates ADD COLUMN bodies INTEGER NOT NULL DEFAULT 0;\n"
             "DROP INDEX handover_candidates_part_id;\n"
             "PRAGMA legacy_alter_table = ON;\n"
             "ALTER TABLE handover_candidates RENAME TO handover_candidates_v9;\n"
             "PRAGMA legacy_alter_table = OFF;\n") +
         kCreateHandoverCandidatesV10 + "INSERT INTO handover_candidates (" +
         kHandoverCandidatesColumnsV10 + ")\n  SELECT " + kHandoverCandidatesColumnsV10 +
         " FROM handover_candidates_v9 ORDER BY id;\n" + "DROP TABLE handover_candidates_v9;\n";
}

// The handover and ergonomics tables as schema version 10 has them: version 3's with
// kCreateHandoverCandidatesV10. What schema_sql() creates.
std::string create_tables_v10() {
  return std::string(kCreateHandoverStagesV3) + kCreateRobotHandoversV3 +
         kCreateHandoverCandidatesV10 + kCreateSharedGraspsV3 + kCreateErgonomicsV3;
}

// The roadmap and regrasp-graph tables as schema version 4 defines them, one constant per table
// (with its indexes). Both the current schema and the 3 -> 4 migration step create them from this
// text, but for regrasp_edges, which version 9 changed (kCreateRegraspEdgesV9): like the constants
// above, a later change goes into a constant of its own and leaves these to the step.
//
// Arrays are BLOBs, little-endian: roadmaps.node_joints node_count * dof doubles (node-major),
// node_gravity node_count * 3 doubles (x, y, z), node_inclination_deg, edge_length and
// edge_max_inclination_deg one double per node or edge, edge_nodes edge_count * 2 int32s (first,
// second); roadmap_filters.edge_bits ceil(edge_count / 8) bytes (edge e: bit e % 8 of byte e / 8,
// least significant first; unused bits 0), node_component node_count int32s;
// regrasp_nodes.solutions solution_count * dof doubles (solution-major), regrasp_edges.path
// path_waypoints * path_dof doubles (waypoint-major; empty, with both counts 0, for an edge without
// a path: not connected, or a handover). The optional references
// (regrasp_nodes.robot_handover_id and candidate_id, regrasp_edges.filter_id) are NULL when they
// do not apply, so they can be foreign keys; the records hold 0 for NULL.
constexpr const char* kCreateRoadmapsV4 = R"sql(
CREATE TABLE roadmaps (
  id INTEGER PRIMARY KEY,
  arm TEXT UNIQUE NOT NULL,
  dof INTEGER NOT NULL,
  resolution REAL NOT NULL,
  node_count INTEGER NOT NULL,
  edge_count INTEGER NOT NULL,
  node_joints BLOB NOT NULL,
  node_gravity BLOB NOT NULL,
  node_inclination_deg BLOB NOT NULL,
  edge_nodes BLOB NOT NULL,
  edge_length BLOB NOT NULL,
  edge_max_inclination_deg BLOB NOT NULL
);
)sql";

constexpr const char* kCreateRoadmapFiltersV4 = R"sql(
CREATE TABLE roadmap_filters (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  roadmap_id INTEGER NOT NULL REFERENCES roadmaps(id),
  grasp_kind TEXT NOT NULL CHECK (grasp_kind IN ('gripper', 'suction')),
  grasp_id INTEGER NOT NULL,
  theta_c_deg REAL NOT NULL,
  valid_edges INTEGER NOT NULL,
  components INTEGER NOT NULL,
  largest_component INTEGER NOT NULL,
  edge_bits BLOB NOT NULL,
  node_component BLOB NOT NULL,
  UNIQUE (part_id, roadmap_id, grasp_kind, grasp_id)
);
)sql";

constexpr const char* kCreateRegraspNodesV4 = R"sql(
CREATE TABLE regrasp_nodes (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  kind TEXT NOT NULL CHECK (kind IN ('home', 'pick', 'robot_handover', 'human_handover')),
  arm TEXT NOT NULL,
  grasp_kind TEXT NOT NULL CHECK (grasp_kind IN ('', 'gripper', 'suction')),
  grasp_id INTEGER NOT NULL,
  robot_handover_id INTEGER REFERENCES robot_handovers(id),
  candidate_id INTEGER REFERENCES handover_candidates(id),
  board_x REAL NOT NULL, board_y REAL NOT NULL, board_z REAL NOT NULL,
  board_qw REAL NOT NULL, board_qx REAL NOT NULL, board_qy REAL NOT NULL, board_qz REAL NOT NULL,
  dof INTEGER NOT NULL,
  solution_count INTEGER NOT NULL,
  solutions BLOB NOT NULL,
  CHECK ((kind = 'home') = (grasp_kind = '')),
  CHECK ((grasp_kind = '') = (grasp_id = 0)),
  CHECK ((kind = 'robot_handover') = (robot_handover_id IS NOT NULL)),
  CHECK ((kind = 'human_handover') = (candidate_id IS NOT NULL))
);
CREATE INDEX regrasp_nodes_part_id ON regrasp_nodes(part_id);
)sql";

constexpr const char* kCreateRegraspEdgesV4 = R"sql(
CREATE TABLE regrasp_edges (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  kind TEXT NOT NULL CHECK (kind IN ('transit', 'transfer', 'handover')),
  arm TEXT NOT NULL,
  from_node INTEGER NOT NULL REFERENCES regrasp_nodes(id),
  to_node INTEGER NOT NULL REFERENCES regrasp_nodes(id),
  filter_id INTEGER REFERENCES roadmap_filters(id),
  connected INTEGER NOT NULL CHECK (connected IN (0, 1)),
  cost REAL NOT NULL,
  path_nodes INTEGER NOT NULL,
  via TEXT NOT NULL CHECK (via IN ('', 'roadmap', 'bridge')),
  path_dof INTEGER NOT NULL,
  path_waypoints INTEGER NOT NULL,
  path BLOB NOT NULL,
  CHECK ((kind = 'transfer') = (filter_id IS NOT NULL)),
  CHECK (connected = 1 OR (cost = 0 AND path_nodes = 0)),
  CHECK ((connected = 1 AND kind IN ('transit', 'transfer')) = (via <> '')),
  CHECK ((via = '') = (path_waypoints = 0))
);
CREATE INDEX regrasp_edges_part_id ON regrasp_edges(part_id);
)sql";

// The regrasp_edges table as schema version 9 defines it (with its index): version 4's with
// duration, the estimated robot time along the stored path in seconds (records::RegraspEdgeRecord::
// duration): >= 0, and 0 without a path. 0 with a path means "not estimated" (a row migrated from
// version 8 or earlier: the online planner times the path itself). Created by schema_sql() and by
// the 8 -> 9 step (rebuild_regrasp_edges_v9) from this text; kCreateRegraspEdgesV4 stays for the
// 3 -> 4 step.
constexpr const char* kCreateRegraspEdgesV9 = R"sql(
CREATE TABLE regrasp_edges (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  kind TEXT NOT NULL CHECK (kind IN ('transit', 'transfer', 'handover')),
  arm TEXT NOT NULL,
  from_node INTEGER NOT NULL REFERENCES regrasp_nodes(id),
  to_node INTEGER NOT NULL REFERENCES regrasp_nodes(id),
  filter_id INTEGER REFERENCES roadmap_filters(id),
  connected INTEGER NOT NULL CHECK (connected IN (0, 1)),
  cost REAL NOT NULL,
  path_nodes INTEGER NOT NULL,
  via TEXT NOT NULL CHECK (via IN ('', 'roadmap', 'bridge')),
  path_dof INTEGER NOT NULL,
  path_waypoints INTEGER NOT NULL,
  path BLOB NOT NULL,
  duration REAL NOT NULL CHECK (duration >= 0),
  CHECK ((kind = 'transfer') = (filter_id IS NOT NULL)),
  CHECK (connected = 1 OR (cost = 0 AND path_nodes = 0)),
  CHECK ((connected = 1 AND kind IN ('transit', 'transfer')) = (via <> '')),
  CHECK ((via = '') = (path_waypoints = 0)),
  CHECK (path_waypoints <> 0 OR duration = 0)
);
CREATE INDEX regrasp_edges_part_id ON regrasp_edges(part_id);
)sql";

// The 8 -> 9 step: the version 9 regrasp_edges in place of the version 8 one (which is version
// 4's), every row kept with duration 0 (not estimated). The column is first added as ALTER TABLE
// adds one, at the end, every row's its DEFAULT 0 (and the step fails, leaving the file as it was,
// on a table that has the column already: a version 9 file whose version was set back). Then the
// table is rebuilt, as the 7 -> 8 step rebuilt table_regrasps: an added column keeps its DEFAULT
// and cannot take the table's CHECK tying it to the path, so the old table is renamed out of the
// way (its index dropped, so the name is free), the version 9 one created, the rows copied with
// their ids and the old one dropped, which leaves the file declaring the table exactly as a fresh
// one does. Nothing in a version 8 file refers to regrasp_edges, so the rename rewrites no other
// table; the foreign keys the table holds (parts, regrasp_nodes, roadmap_filters) name tables that
// stay.
constexpr const char* kRegraspEdgesColumnsV9 =
    "id, part_id, kind, arm, from_node, to_node, filter_id, connected, cost, path_nodes, via, "
    "path_dof, path_waypoints, path, duration";

std::string rebuild_regrasp_edges_v9() {
  return std::string(
             "ALTER TABLE regrasp_edges ADD COLUMN duration REAL NOT NULL DEFAULT 0.0;\n"
             "DROP INDEX regrasp_edges_part_id;\n"
             "ALTER TABLE regrasp_edges RENAME TO regrasp_edges_v8;\n") +
         kCreateRegraspEdgesV9 + "INSERT INTO regrasp_edges (" + kRegraspEdgesColumnsV9 +
         ")\n  SELECT " + kRegraspEdgesColumnsV9 + " FROM regrasp_edges_v8 ORDER BY id;\n" +
         "DROP TABLE regrasp_edges_v8;\n";
}

// Every table schema version 4 adds, in schema order, as version 4 declared them (the 3 -> 4
// step; schema_sql() has the version 9 regrasp_edges, create_tables_v9()).
std::string create_tables_v4() {
  return std::string(kCreateRoadmapsV4) + kCreateRoadmapFiltersV4 + kCreateRegraspNodesV4 +
         kCreateRegraspEdgesV4;
}

// The roadmap and regrasp-graph tables as schema version 9 has them: version 4's with
// kCreateRegraspEdgesV9. What schema_sql() creates.
std::string create_tables_v9() {
  return std::string(kCreateRoadmapsV4) + kCreateRoadmapFiltersV4 + kCreateRegraspNodesV4 +
         kCreateRegraspEdgesV9;
}

// The direct_grasps table as schema version 5 defines it (with its index): robot grasps with which
// one arm's gripper picks the part where it lies and holds it at a goal's robot-human pose, no
// robot-robot exchange. Both the current schema and the 4 -> 5 migration step create it from this
// text; like the constants above, a later change goes into schema_sql() and leaves this to the
// step. joints_pick (the arm's IK at the part's initial pose) and joints_rh (at the robot-human
// pose) are joint vectors as in the version 3 tables: little-endian doubles, 8 bytes per joint.
constexpr const char* kCreateDirectGraspsV5 = R"sql(
CREATE TABLE direct_grasps (
  id INTEGER PRIMARY KEY,
  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),
  robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),
  arm TEXT NOT NULL,
  joints_pick BLOB NOT NULL,
  joints_rh BLOB NOT NULL,
  inclination_pick_deg REAL NOT NULL,
  inclination_rh_deg REAL NOT NULL
);
CREATE INDEX direct_grasps_candidate_id ON direct_grasps(candidate_id);
)sql";

// The table_regrasps table as schema version 6 defines it (with its index): regrasps on the table
// by one arm's gripper (records::TableRegraspRecord). Created by the 5 -> 6 step from this text
// (schema_sql() has the version 8 table, kCreateTableRegraspsV8). The placement is a pose; the
// joints are joint vectors as in the version 3 tables.
constexpr const char* kCreateTableRegraspsV6 = R"sql(
CREATE TABLE table_regrasps (
  id INTEGER PRIMARY KEY,
  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),
  pick_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),
  robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),
  arm TEXT NOT NULL,
  placement_x REAL NOT NULL, placement_y REAL NOT NULL, placement_z REAL NOT NULL,
  placement_qw REAL NOT NULL, placement_qx REAL NOT NULL, placement_qy REAL NOT NULL,
  placement_qz REAL NOT NULL,
  joints_pick BLOB NOT NULL,
  joints_place BLOB NOT NULL,
  joints_repick BLOB NOT NULL,
  joints_rh BLOB NOT NULL,
  inclination_pick_deg REAL NOT NULL,
  inclination_place_deg REAL NOT NULL,
  inclination_repick_deg REAL NOT NULL,
  inclination_rh_deg REAL NOT NULL
);
CREATE INDEX table_regrasps_candidate_id ON table_regrasps(candidate_id);
)sql";

// The table_regrasps table as schema version 8 defines it (with its index): version 6's with
// repick_arm, the arm that takes the part again and delivers it (arm for a regrasp by one arm, the
// other arm for a relay). Created by schema_sql() and by the 7 -> 8 step (kRebuildTableRegraspsV8)
// from this text.
constexpr const char* kCreateTableRegraspsV8 = R"sql(
CREATE TABLE table_regrasps (
  id INTEGER PRIMARY KEY,
  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),
  pick_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),
  robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),
  arm TEXT NOT NULL,
  repick_arm TEXT NOT NULL,
  placement_x REAL NOT NULL, placement_y REAL NOT NULL, placement_z REAL NOT NULL,
  placement_qw REAL NOT NULL, placement_qx REAL NOT NULL, placement_qy REAL NOT NULL,
  placement_qz REAL NOT NULL,
  joints_pick BLOB NOT NULL,
  joints_place BLOB NOT NULL,
  joints_repick BLOB NOT NULL,
  joints_rh BLOB NOT NULL,
  inclination_pick_deg REAL NOT NULL,
  inclination_place_deg REAL NOT NULL,
  inclination_repick_deg REAL NOT NULL,
  inclination_rh_deg REAL NOT NULL
);
CREATE INDEX table_regrasps_candidate_id ON table_regrasps(candidate_id);
)sql";

// The 7 -> 8 step's change to table_regrasps: the version 8 table in place of the version 7 one
// (which is version 6's), every row kept, repick_arm its arm. Rebuilt rather than ALTER TABLE ...
// ADD COLUMN, which can only append (the checks at open want the schema's column order) and would
// need a DEFAULT. The old table is renamed out of the way first (its index dropped, so the name is
// free), which leaves the new table's CREATE text exactly kCreateTableRegraspsV8's; nothing in a
// version 7 file refers to table_regrasps, so the rename rewrites no other table.
constexpr const char* kTableRegraspsCopiedColumns =
    "placement_x, placement_y, placement_z, placement_qw, placement_qx, placement_qy, "
    "placement_qz, joints_pick, joints_place, joints_repick, joints_rh, inclination_pick_deg, "
    "inclination_place_deg, inclination_repick_deg, inclination_rh_deg";

std::string rebuild_table_regrasps_v8() {
  return std::string(
             "DROP INDEX table_regrasps_candidate_id;\n"
             "ALTER TABLE table_regrasps RENAME TO table_regrasps_v7;\n") +
         kCreateTableRegraspsV8 +
         "INSERT INTO table_regrasps (id, candidate_id, pick_grasp_id, robot_grasp_id, arm, "
         "repick_arm, " +
         kTableRegraspsCopiedColumns +
         ")\n  SELECT id, candidate_id, pick_grasp_id, robot_grasp_id, arm, arm, " +
         kTableRegraspsCopiedColumns + " FROM table_regrasps_v7 ORDER BY id;\n" +
         "DROP TABLE table_regrasps_v7;\n";
}

// The suction_deliveries table as schema version 8 defines it (with its index): deliveries by the
// arm holding the suction tool, the board on its cup (records::SuctionDeliveryRecord). Created by
// schema_sql() and by the 7 -> 8 step from this text. joints_rh is a joint vector as in the
// version 3 tables.
constexpr const char* kCreateSuctionDeliveriesV8 = R"sql(
CREATE TABLE suction_deliveries (
  id INTEGER PRIMARY KEY,
  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),
  suction_grasp_id INTEGER NOT NULL REFERENCES suction_grasps(id),
  arm TEXT NOT NULL,
  joints_rh BLOB NOT NULL
);
CREATE INDEX suction_deliveries_candidate_id ON suction_deliveries(candidate_id);
)sql";

}  // namespace

// Written out in full (not generated) so this file is the readable reference of the schema (the
// comfort_maps table is kCreateComfortMapsV2 above, the handover and ergonomics tables the
// kCreate...V3 constants but for handover_candidates, kCreateHandoverCandidatesV10, the roadmap and
// regrasp-graph tables the kCreate...V4 ones but for regrasp_edges, kCreateRegraspEdgesV9, the
// direct_grasps table kCreateDirectGraspsV5, the table_regrasps table kCreateTableRegraspsV8, the
// suction_deliveries table kCreateSuctionDeliveriesV8). Poses are (x, y, z) in metres and a unit
// quaternion (qw, qx, qy, qz) with qw >= 0.
const std::string& schema_sql() {
  static const std::string sql = R"sql(
CREATE TABLE meta (
  key TEXT PRIMARY KEY,
  value TEXT NOT NULL
);

CREATE TABLE parts (
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  assembly_order INTEGER NOT NULL,
  mesh_file TEXT NOT NULL,
  mesh_hash TEXT NOT NULL,
  mass REAL NOT NULL,
  volume REAL NOT NULL,
  com_x REAL NOT NULL, com_y REAL NOT NULL, com_z REAL NOT NULL,
  ixx REAL NOT NULL, iyy REAL NOT NULL, izz REAL NOT NULL,
  ixy REAL NOT NULL, ixz REAL NOT NULL, iyz REAL NOT NULL,
  extent_x REAL NOT NULL, extent_y REAL NOT NULL, extent_z REAL NOT NULL,
  triangle_count INTEGER NOT NULL,
  target_x REAL NOT NULL, target_y REAL NOT NULL, target_z REAL NOT NULL,
  target_qw REAL NOT NULL, target_qx REAL NOT NULL, target_qy REAL NOT NULL,
  target_qz REAL NOT NULL,
  initial_x REAL NOT NULL, initial_y REAL NOT NULL, initial_z REAL NOT NULL,
  initial_qw REAL NOT NULL, initial_qx REAL NOT NULL, initial_qy REAL NOT NULL,
  initial_qz REAL NOT NULL
);

CREATE TABLE placements (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  part_in_plane_x REAL NOT NULL, part_in_plane_y REAL NOT NULL, part_in_plane_z REAL NOT NULL,
  part_in_plane_qw REAL NOT NULL, part_in_plane_qx REAL NOT NULL,
  part_in_plane_qy REAL NOT NULL, part_in_plane_qz REAL NOT NULL,
  stability REAL NOT NULL
);
CREATE INDEX placements_part_id ON placements(part_id);

CREATE TABLE robot_grasps (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  tcp_x REAL NOT NULL, tcp_y REAL NOT NULL, tcp_z REAL NOT NULL,
  tcp_qw REAL NOT NULL, tcp_qx REAL NOT NULL, tcp_qy REAL NOT NULL, tcp_qz REAL NOT NULL,
  jaw_width REAL NOT NULL,
  contact_1_x REAL NOT NULL, contact_1_y REAL NOT NULL, contact_1_z REAL NOT NULL,
  normal_1_x REAL NOT NULL, normal_1_y REAL NOT NULL, normal_1_z REAL NOT NULL,
  contact_2_x REAL NOT NULL, contact_2_y REAL NOT NULL, contact_2_z REAL NOT NULL,
  normal_2_x REAL NOT NULL, normal_2_y REAL NOT NULL, normal_2_z REAL NOT NULL,
  quality REAL NOT NULL,
  friction_torque_capacity REAL NOT NULL,
  lever REAL NOT NULL,
  theta_c_deg REAL NOT NULL
);
CREATE INDEX robot_grasps_part_id ON robot_grasps(part_id);

CREATE TABLE suction_grasps (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  cup_x REAL NOT NULL, cup_y REAL NOT NULL, cup_z REAL NOT NULL,
  cup_qw REAL NOT NULL, cup_qx REAL NOT NULL, cup_qy REAL NOT NULL, cup_qz REAL NOT NULL,
  rotation_deg REAL NOT NULL,
  force_margin REAL NOT NULL,
  moment_margin REAL NOT NULL
);
CREATE INDEX suction_grasps_part_id ON suction_grasps(part_id);

CREATE TABLE human_grasps (
  id INTEGER PRIMARY KEY,
  part_id INTEGER NOT NULL REFERENCES parts(id),
  hand_x REAL NOT NULL, hand_y REAL NOT NULL, hand_z REAL NOT NULL,
  hand_qw REAL NOT NULL, hand_qx REAL NOT NULL, hand_qy REAL NOT NULL, hand_qz REAL NOT NULL,
  aperture REAL NOT NULL,
  contact_1_x REAL NOT NULL, contact_1_y REAL NOT NULL, contact_1_z REAL NOT NULL,
  contact_2_x REAL NOT NULL, contact_2_y REAL NOT NULL, contact_2_z REAL NOT NULL,
  quality REAL NOT NULL,
  one_hand_stable INTEGER NOT NULL CHECK (one_hand_stable IN (0, 1))
);
CREATE INDEX human_grasps_part_id ON human_grasps(part_id);
)sql" + std::string(kCreateComfortMapsV2) +
                                 create_tables_v10() + create_tables_v9() + kCreateDirectGraspsV5 +
                                 kCreateTableRegraspsV8 + kCreateSuctionDeliveriesV8;
  return sql;
}

// Upgrades from older schema versions, oldest first. Schema version 1 is the first release. A
// step's SQL runs inside the migration's transaction; the framework updates schema_version.
const std::vector<MigrationStep>& migration_steps() {
  static const std::vector<MigrationStep> steps = {
      // 1 -> 2: human comfort maps (a new table; the old tables are unchanged, and a migrated file
      // has no maps until it is rebuilt).
      {1, kCreateComfortMapsV2},
      // 2 -> 3: handover goals and ergonomics (new tables, empty in a migrated file until it is
      // rebuilt) and the meta key human_bodies (empty: the cell's human only).
      {2, create_tables_v3() +
              "INSERT OR IGNORE INTO meta (key, value) VALUES ('human_bodies', '');\n"},
      // 3 -> 4: roadmaps, roadmap filters and the regrasp graph (new tables, empty in a migrated
      // file until it is rebuilt; the old tables are unchanged).
      {3, create_tables_v4()},
      // 4 -> 5: direct grasps (a new table, empty in a migrated file until it is rebuilt; the old
      // tables are unchanged).
      {4, kCreateDirectGraspsV5},
      // 5 -> 6: regrasps on the table (a new table, empty in a migrated file until it is rebuilt).
      {5, kCreateTableRegraspsV6},
      // 6 -> 7: a content digest per table in meta (digest.<table>, see kTableDigestsSince). SQL
      // cannot hash, so the migration itself writes them after its last step, for the content the
      // file then holds; the step only drops any the file already had.
      {6, "DELETE FROM meta WHERE key GLOB 'digest.*';\n"},
      // 7 -> 8: suction deliveries (a new table, empty in a migrated file until it is rebuilt) and
      // table_regrasps.repick_arm (the table rebuilt with the column, each row's its arm: version 7
      // had no relays). The migration rewrites every table's digest after its last step.
      {7, kCreateSuctionDeliveriesV8 + rebuild_table_regrasps_v8()},
      // 8 -> 9: regrasp_edges.duration (the table rebuilt with the column, every row's 0: not
      // estimated, the online planner times the stored path itself). The migration rewrites every
      // table's digest after its last step.
      {8, rebuild_regrasp_edges_v9()},
      // 9 -> 10: handover_candidates.bodies (the table rebuilt with the column, every row's 0: not
      // computed, as a file without a body set has it). The migration rewrites every table's digest
      // after its last step.
      {9, rebuild_handover_candidates_v10()},
  };
  return steps;
}

std::string digest_key(const std::string& table) {
  return "digest." + table;
}

const std::vector<ColumnSpec>& schema_columns(const std::string& table) {
  static const std::map<std::string, std::vector<ColumnSpec>> by_table = [] {
    Connection connection(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "(schema)");
    const ErrorContext context{"(schema)", "hila's own schema to run", ""};
    connection.exec(schema_sql(), context);
    std::map<std::string, std::vector<ColumnSpec>> result;
    for (const auto& t : kTables) {
      Statement info(connection,
                     std::string("SELECT name, type, \"notnull\", pk FROM pragma_table_info('") +
                         t.name + "') ORDER BY cid",
                     context);
      auto& columns = result[t.name];
      while (info.step()) {
        ColumnSpec column;
        column.name = info.next_text();
        const std::string type = info.next_text();
        const bool not_null = info.next_int64() != 0;
        const bool primary_key = info.next_int64() != 0;
        if (type == "INTEGER") {
          column.storage_class = SQLITE_INTEGER;
        } else if (type == "REAL") {
          column.storage_class = SQLITE_FLOAT;
        } else if (type == "TEXT") {
          column.storage_class = SQLITE_TEXT;
        } else if (type == "BLOB") {
          column.storage_class = SQLITE_BLOB;
        } else {
          throw std::logic_error("schema_sql(): column " + std::string(t.name) + "." + column.name +
                                 " has type '" + type + "'");
        }
        column.nullable = !not_null && !primary_key;
        columns.push_back(std::move(column));
      }
    }
    connection.close();
    return result;
  }();
  static const std::vector<ColumnSpec> none;
  const auto it = by_table.find(table);
  return it == by_table.end() ? none : it->second;
}

bool body_mask_fits(std::int64_t mask, std::size_t body_count) {
  if (mask < 0 || mask > std::int64_t{0xffffffff}) return false;
  return body_count >= 32 || (mask >> body_count) == 0;
}

std::string body_mask_expectation(const std::string& human_bodies) {
  const std::size_t count = human_body_labels(human_bodies).size();
  if (count == 0) return "0 (meta.human_bodies names no body: the cell's human only)";
  const std::int64_t largest =
      count >= 32 ? std::int64_t{0xffffffff} : (std::int64_t{1} << count) - 1;
  return "a mask of the " + std::to_string(count) + " bod" + (count == 1 ? "y" : "ies") +
         " of meta.human_bodies ('" + human_bodies + "'): bits 0 to " +
         std::to_string(std::min<std::size_t>(count, 32) - 1) + ", from 0 to " +
         std::to_string(largest);
}

std::string pose_columns(const std::string& prefix) {
  return prefix + "_x, " + prefix + "_y, " + prefix + "_z, " + prefix + "_qw, " + prefix + "_qx, " +
         prefix + "_qy, " + prefix + "_qz";
}

std::string vector_columns(const std::string& prefix) {
  return prefix + "_x, " + prefix + "_y, " + prefix + "_z";
}

}  // namespace detail
}  // namespace hila::db
