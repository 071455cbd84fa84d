#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sample_records.hpp"
#include "sqlite_handle.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::detail;
using namespace hila::db::test_data;
using namespace hila::test;
namespace fs = std::filesystem;

namespace {

// A "version 0" database: what schema 1 would look like if robot_grasps had no theta_c_deg yet
// (and, as in schema 1, there were no comfort maps, handover, ergonomics, roadmap, regrasp,
// direct grasp, table regrasp or suction delivery tables).
std::string write_v0(const std::string& dir) {
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path,
                 "DROP TABLE suction_deliveries;"
                 "DROP TABLE table_regrasps;"
                 "DROP TABLE direct_grasps;"
                 "DROP TABLE regrasp_edges;"
                 "DROP TABLE regrasp_nodes;"
                 "DROP TABLE roadmap_filters;"
                 "DROP TABLE roadmaps;"
                 "DROP TABLE comfort_maps;"
                 "DROP TABLE shared_grasps;"
                 "DROP TABLE handover_candidates;"
                 "DROP TABLE robot_handovers;"
                 "DROP TABLE handover_stages;"
                 "DROP TABLE ergonomics;"
                 "DELETE FROM meta WHERE key = 'human_bodies';"
                 "ALTER TABLE robot_grasps DROP COLUMN theta_c_deg;"
                 "UPDATE meta SET value = '0' WHERE key = 'schema_version';");
  return path;
}

// The synthetic 0 -> 1 step: add the column with its "no constraint" default.
const std::vector<MigrationStep> kSteps = {
    {0, "ALTER TABLE robot_grasps ADD COLUMN theta_c_deg REAL NOT NULL DEFAULT 90.0;"}};

// kSteps followed by the real steps (1 -> 2, 2 -> 3, ...): a version 0 file to the current version.
std::vector<MigrationStep> steps_from_v0() {
  std::vector<MigrationStep> steps = kSteps;
  steps.insert(steps.end(), migration_steps().begin(), migration_steps().end());
  return steps;
}

// The CREATE statements sqlite_master holds for `table` and its index (and for any table left
// over by a step, named after it), in name order: how the file itself declares the table.
std::vector<std::string> declared_sql(const std::string& path, const std::string& table) {
  const ErrorContext context{"(sqlite_master)", "a readable schema", ""};
  Connection connection(path, SQLITE_OPEN_READONLY, path);
  std::vector<std::string> statements;
  {
    Statement select(connection, "SELECT sql FROM sqlite_master WHERE name GLOB ? ORDER BY name",
                     context);
    select.bind_next(table + "*");
    while (select.step()) statements.push_back(select.column_text(0));
  }
  connection.close();
  return statements;
}

std::vector<std::string> table_regrasps_sql(const std::string& path) {
  return declared_sql(path, "table_regrasps");
}

std::vector<std::string> regrasp_edges_sql(const std::string& path) {
  return declared_sql(path, "regrasp_edges");
}

std::vector<std::string> handover_candidates_sql(const std::string& path) {
  return declared_sql(path, "handover_candidates");
}

// Every CREATE statement sqlite_master holds, name -> statement: how the file declares all its
// tables and indexes.
std::map<std::string, std::string> all_declared_sql(const std::string& path) {
  const ErrorContext context{"(sqlite_master)", "a readable schema", ""};
  Connection connection(path, SQLITE_OPEN_READONLY, path);
  std::map<std::string, std::string> statements;
  {
    Statement select(connection, "SELECT name, sql FROM sqlite_master WHERE sql IS NOT NULL",
                     context);
    while (select.step()) statements[select.column_text(0)] = select.column_text(1);
  }
  connection.close();
  return statements;
}

// handover_candidates as the 2 -> 3 step declares it (versions 3 to 9), as sqlite_master holds a
// CREATE statement: without the ';'.
std::string handover_candidates_v3_sql() {
  const std::string& step_v3 = migration_steps().at(1).sql;
  const std::size_t begin = step_v3.find("CREATE TABLE handover_candidates (");
  return step_v3.substr(begin, step_v3.find("\n);", begin) + 2 - begin);
}

// The meta table's digest.* rows, key -> value.
std::map<std::string, std::string> stored_digests(const std::string& path) {
  const ErrorContext context{"(meta)", "a readable meta table", ""};
  Connection connection(path, SQLITE_OPEN_READONLY, path);
  std::map<std::string, std::string> digests;
  {
    Statement select(connection, "SELECT key, value FROM meta WHERE key GLOB 'digest.*'", context);
    while (select.step()) digests[select.column_text(0)] = select.column_text(1);
  }
  connection.close();
  return digests;
}

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

// Schema version 1 exactly as hila 0.1 (schema 1) wrote it, frozen here: the migration from 1 must
// keep working on such files whatever the current schema looks like.
const char* const kSchemaV1 = R"sql(
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
)sql";

// What schema version 2 added to version 1, exactly as hila (schema 2) wrote it, frozen here like
// kSchemaV1.
const char* const kSchemaV2Additions = R"sql(
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

// What schema version 3 added to version 2, exactly as hila (schema 3) wrote it, frozen here like
// kSchemaV1.
const char* const kSchemaV3Additions = R"sql(
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

// What schema version 4 added to version 3, exactly as hila (schema 4) wrote it, frozen here like
// kSchemaV1.
const char* const kSchemaV4Additions = R"sql(
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

// What schema version 5 added to version 4, exactly as hila (schema 5) wrote it, frozen here like
// kSchemaV1.
const char* const kSchemaV5Additions = R"sql(
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

// What schema version 6 added to version 5, exactly as hila (schema 6) wrote it, frozen here like
// kSchemaV1. (Version 7 added no table, only the digests in meta.)
const char* const kSchemaV6Additions = R"sql(
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

// Meta and one part with a placement and one grasp of each kind, as rows of the version 1 tables
// (meta without schema_version). Values are exact in binary so the writer would store the same
// bits.
const char* const kV1Rows = R"sql(
INSERT INTO meta (key, value) VALUES
  ('hila_version', '0.1.0'), ('product_name', 'cabinet'),
  ('cell_hash', 'cccc'), ('product_hash', 'aaaa'), ('settings_hash', '5555'),
  ('seed', '18446744073709551615'), ('created_at', '2024-06-11T10:00:00Z'),
  ('cell_file', 'cell.yaml'), ('product_file', 'product.yaml');
INSERT INTO parts VALUES (1, 'bracket', 3, 'bracket.stl', 'eeee', 0.5, 0.25,
  0.125, 0.0, -0.5,  1.0, 2.0, 3.0, 0.5, 0.25, 0.125,  0.5, 0.25, 0.125,  12,
  1.0, 2.0, 3.0, 1.0, 0.0, 0.0, 0.0,  0.5, -0.5, 0.0, 1.0, 0.0, 0.0, 0.0);
INSERT INTO placements VALUES (1, 1, 0.0, 0.0, 0.0625, 1.0, 0.0, 0.0, 0.0, 0.03125);
INSERT INTO robot_grasps VALUES (1, 1, 0.0, 0.0, 0.25, 1.0, 0.0, 0.0, 0.0, 0.5,
  0.25, 0.0, 0.0, 1.0, 0.0, 0.0, -0.25, 0.0, 0.0, -1.0, 0.0, 0.0, 0.75, 2.0, 0.125, 45.0);
INSERT INTO suction_grasps VALUES (1, 1, 0.0, 0.125, 0.0, 1.0, 0.0, 0.0, 0.0, -90.0, 4.5, 0.5);
INSERT INTO human_grasps VALUES (1, 1, 0.0, 0.0, 0.5, 1.0, 0.0, 0.0, 0.0, 0.0625,
  0.03125, 0.0, 0.0, -0.03125, 0.0, 0.0, 0.5, 1);
)sql";

// A version 1 file made by hand (no DatabaseWriter involved): kV1Rows.
std::string write_v1(const std::string& dir) {
  const std::string path = dir + "/v1.db";
  execute_script(path, std::string(kSchemaV1) + kV1Rows +
                           "INSERT INTO meta (key, value) VALUES ('schema_version', '1');");
  return path;
}

// A version 2 file made by hand: kV1Rows and one comfort map (1 x 1 x 1 nodes, no orientations,
// so no values: the zlib stream of nothing, as compress2 at level 6 writes it).
std::string write_v2(const std::string& dir) {
  const std::string path = dir + "/v2.db";
  execute_script(path, std::string(kSchemaV1) + kSchemaV2Additions + kV1Rows + R"sql(
INSERT INTO meta (key, value) VALUES ('schema_version', '2');
INSERT INTO comfort_maps VALUES (1, 'right', 0.25, -0.5, 1.0, 0.03125, 1, 1, 1, 0, x'', 0,
  x'789c030000000001', 2000000, -1, 0.375);
)sql");
  return path;
}

// The comfort map of write_v2 and one record of every version 3 table, as rows. Joint vectors are
// (0.5, 1.0) = x'000000000000e03f000000000000f03f' and (-2.0) = x'00000000000000c0'.
const char* const kV3Rows = R"sql(
INSERT INTO meta (key, value) VALUES ('schema_version', '3'), ('human_bodies', '1.75 male');
INSERT INTO comfort_maps VALUES (1, 'right', 0.25, -0.5, 1.0, 0.03125, 1, 1, 1, 0, x'', 0,
  x'789c030000000001', 2000000, -1, 0.375);
INSERT INTO handover_stages VALUES (1, 1, '', 812, 6, 5, 6, 1, 1, 0, '');
INSERT INTO robot_handovers VALUES (1, 1, 0.5, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 1, 'right',
  x'000000000000e03f000000000000f03f');
INSERT INTO handover_candidates VALUES (1, 1, 3, 0.25, 0.5, 1.0, 1.0, 0.0, 0.0, 0.0, 0.125, 0.75,
  'goal', 0, 'right', 1, 0.875, '', 0, 0.0, x'00000000000000c0', x'');
INSERT INTO shared_grasps VALUES (1, 1, 1, 1, 'left', x'000000000000e03f000000000000f03f',
  x'00000000000000c0', 12.5, 45.0);
INSERT INTO ergonomics VALUES (1, 1, 'hila', 1, 17.25, 0, 0.625, 0.0, 0.5, 'right');
)sql";

// A version 3 file made by hand: kV1Rows and kV3Rows.
std::string write_v3(const std::string& dir) {
  const std::string path = dir + "/v3.db";
  execute_script(
      path, std::string(kSchemaV1) + kSchemaV2Additions + kSchemaV3Additions + kV1Rows + kV3Rows);
  return path;
}

// One roadmap without nodes or edges, a human_handover regrasp node at the goal of kV3Rows (the
// one solution (0.5, 1.0), as in the kV3Rows blobs) and a connected transit edge from that node to
// itself via the roadmap, its path the solution twice, as rows of the version 4 tables (the edge
// has no duration before version 9); the version set to 4.
const char* const kV4Rows = R"sql(
UPDATE meta SET value = '4' WHERE key = 'schema_version';
INSERT INTO roadmaps VALUES (1, 'left', 6, 0.0625, 0, 0, x'', x'', x'', x'', x'', x'');
INSERT INTO regrasp_nodes VALUES (1, 1, 'human_handover', 'left', 'gripper', 1, NULL, 1,
  0.25, 0.5, 1.0, 1.0, 0.0, 0.0, 0.0, 2, 1, x'000000000000e03f000000000000f03f');
INSERT INTO regrasp_edges VALUES (1, 1, 'transit', 'left', 1, 1, NULL, 1, 0.375, 3, 'roadmap',
  2, 2, x'000000000000e03f000000000000f03f000000000000e03f000000000000f03f');
)sql";

// A version 4 file made by hand: kV1Rows, kV3Rows and kV4Rows.
std::string write_v4(const std::string& dir) {
  const std::string path = dir + "/v4.db";
  execute_script(path, std::string(kSchemaV1) + kSchemaV2Additions + kSchemaV3Additions +
                           kSchemaV4Additions + kV1Rows + kV3Rows + kV4Rows);
  return path;
}

// One direct grasp of the goal of kV3Rows (joints_pick (0.5, 1.0) and joints_rh (-2.0), as in the
// kV3Rows blobs), as a row of the version 5 table; the version set to 5.
const char* const kV5Rows = R"sql(
UPDATE meta SET value = '5' WHERE key = 'schema_version';
INSERT INTO direct_grasps VALUES (1, 1, 1, 'right', x'000000000000e03f000000000000f03f',
  x'00000000000000c0', 22.5, 67.5);
)sql";

// A version 5 file made by hand: kV1Rows, kV3Rows, kV4Rows and kV5Rows.
std::string write_v5(const std::string& dir) {
  const std::string path = dir + "/v5.db";
  execute_script(path, std::string(kSchemaV1) + kSchemaV2Additions + kSchemaV3Additions +
                           kSchemaV4Additions + kSchemaV5Additions + kV1Rows + kV3Rows + kV4Rows +
                           kV5Rows);
  return path;
}

// One table regrasp of the goal of kV3Rows (set down at (0.5, -0.25, 0.75) unturned; joints_pick
// (0.5), no joints_place, joints_repick (-2.0) and joints_rh (0.5, 1.0), as in the kV3Rows blobs),
// as a row of the version 6 table; the version set to 6.
const char* const kV6Rows = R"sql(
UPDATE meta SET value = '6' WHERE key = 'schema_version';
INSERT INTO table_regrasps VALUES (1, 1, 1, 1, 'left', 0.5, -0.25, 0.75, 1.0, 0.0, 0.0, 0.0,
  x'000000000000e03f', x'', x'00000000000000c0', x'000000000000e03f000000000000f03f',
  10.5, 20.5, 30.5, 40.5);
)sql";

// A version 6 file made by hand: kV1Rows, kV3Rows, kV4Rows, kV5Rows and kV6Rows.
std::string write_v6(const std::string& dir) {
  const std::string path = dir + "/v6.db";
  execute_script(path, std::string(kSchemaV1) + kSchemaV2Additions + kSchemaV3Additions +
                           kSchemaV4Additions + kSchemaV5Additions + kSchemaV6Additions + kV1Rows +
                           kV3Rows + kV4Rows + kV5Rows + kV6Rows);
  return path;
}

// The same content written by this hila's DatabaseWriter (no handover or ergonomics records, an
// empty meta.human_bodies), with the comfort map of write_v2 when `with_comfort_map`, with the
// version 3 records (and meta.human_bodies) of write_v3 when `with_handover_records`, with the
// version 4 records of write_v4 when `with_roadmap_records` (which needs the version 3 ones), with
// the version 5 record of write_v5 when `with_direct_grasp_records` (which needs the version 3
// ones), and with the version 6 record of write_v6 when `with_table_regrasp_records` (likewise),
// taken again by `table_regrasp_repick_arm` (the arm that set it down, as a migrated version 6 row
// says, unless told otherwise). The regrasp edge of write_v4 takes `regrasp_edge_duration` (0, not
// estimated, as in a file migrated from version 8 or earlier, unless told otherwise).
void write_reference_content(const std::string& path, bool with_comfort_map,
                             bool with_handover_records = false, bool with_roadmap_records = false,
                             bool with_direct_grasp_records = false,
                             bool with_table_regrasp_records = false,
                             const std::string& table_regrasp_repick_arm = "left",
                             double regrasp_edge_duration = 0.0) {
  Meta meta;
  meta.hila_version = "0.1.0";
  meta.product_name = "cabinet";
  meta.cell_hash = "cccc";
  meta.product_hash = "aaaa";
  meta.settings_hash = "5555";
  meta.seed = 18446744073709551615ull;
  meta.created_at = "2031-01-01T00:00:00Z";  // ignored by the digest
  meta.cell_file = "cell.yaml";
  meta.product_file = "product.yaml";
  PartRecord part;
  part.name = "bracket";
  part.assembly_order = 3;
  part.mesh_file = "bracket.stl";
  part.mesh_hash = "eeee";
  part.mass = 0.5;
  part.mass_properties.volume = 0.25;
  part.mass_properties.com = {0.125, 0.0, -0.5};
  part.mass_properties.inertia << 1.0, 0.5, 0.25, 0.5, 2.0, 0.125, 0.25, 0.125, 3.0;
  part.extent = {0.5, 0.25, 0.125};
  part.triangle_count = 12;
  part.target.translation() = Eigen::Vector3d(1.0, 2.0, 3.0);
  part.initial.translation() = Eigen::Vector3d(0.5, -0.5, 0.0);
  PlacementRecord placement;
  placement.part_in_plane.translation() = Eigen::Vector3d(0.0, 0.0, 0.0625);
  placement.stability = 0.03125;
  RobotGraspRecord robot;
  robot.tcp.translation() = Eigen::Vector3d(0.0, 0.0, 0.25);
  robot.jaw_width = 0.5;
  robot.contact_1 = {0.25, 0.0, 0.0};
  robot.normal_1 = {1.0, 0.0, 0.0};
  robot.contact_2 = {-0.25, 0.0, 0.0};
  robot.normal_2 = {-1.0, 0.0, 0.0};
  robot.quality = 0.75;
  robot.friction_torque_capacity = 2.0;
  robot.lever = 0.125;
  robot.theta_c_deg = 45.0;
  SuctionGraspRecord suction;
  suction.cup.translation() = Eigen::Vector3d(0.0, 0.125, 0.0);
  suction.rotation_deg = -90.0;
  suction.force_margin = 4.5;
  suction.moment_margin = 0.5;
  HumanGraspRecord human;
  human.hand.translation() = Eigen::Vector3d(0.0, 0.0, 0.5);
  human.aperture = 0.0625;
  human.contact_1 = {0.03125, 0.0, 0.0};
  human.contact_2 = {-0.03125, 0.0, 0.0};
  human.quality = 0.5;
  human.one_hand_stable = true;
  ComfortMapRecord map;
  map.arm = "right";
  map.origin = {0.25, -0.5, 1.0};
  map.spacing = 0.03125;
  map.dims = {1, 1, 1};
  map.samples = 2000000;
  map.seed = 18446744073709551615ull;  // stored as -1
  map.coverage = 0.375;

  if (with_handover_records) meta.human_bodies = "1.75 male";

  DatabaseWriter writer(path);
  writer.write_meta(meta);
  const auto id = writer.add_part(part);
  writer.add_placements(id, {placement});
  writer.add_robot_grasps(id, {robot});
  writer.add_suction_grasps(id, {suction});
  writer.add_human_grasps(id, {human});
  if (with_comfort_map) writer.add_comfort_map(map);
  if (with_handover_records) {
    HandoverStageRecord stage;
    stage.part_id = id;
    stage.draws = 812;
    stage.candidates = 6;
    stage.comfortable = 5;
    stage.comfortable_default_body = 6;
    stage.goals = 1;
    stage.robot_handovers = 1;
    writer.add_handover_stage(stage);
    RobotHandoverRecord handover;
    handover.board.translation() = Eigen::Vector3d(0.5, 0.0, 1.0);
    handover.suction_grasp_id = 1;
    handover.arm = "right";
    handover.joints = Eigen::Vector2d(0.5, 1.0);
    writer.add_robot_handovers(id, {handover});
    HandoverCandidateRecord candidate;
    candidate.sample = 3;
    candidate.board.translation() = Eigen::Vector3d(0.25, 0.5, 1.0);
    candidate.distance = 0.125;
    candidate.quality = 0.75;
    candidate.status = "goal";
    candidate.rank = 0;
    candidate.human_arm = "right";
    candidate.human_grasp_id = 1;
    candidate.human_quality = 0.875;
    candidate.human_joints = Eigen::VectorXd::Constant(1, -2.0);
    writer.add_handover_candidates(id, {candidate});
    SharedGraspRecord shared;
    shared.candidate_id = 1;
    shared.robot_grasp_id = 1;
    shared.robot_handover_id = 1;
    shared.arm = "left";
    shared.joints_rr = Eigen::Vector2d(0.5, 1.0);
    shared.joints_rh = Eigen::VectorXd::Constant(1, -2.0);
    shared.inclination_rr_deg = 12.5;
    shared.inclination_rh_deg = 45.0;
    writer.add_shared_grasps({shared});
    ErgonomicsRecord ergonomics;
    ergonomics.method = "hila";
    ergonomics.reachable = true;
    ergonomics.torso_flexion_deg = 17.25;
    ergonomics.reach = 0.625;
    ergonomics.quality = 0.5;
    ergonomics.arm = "right";
    writer.add_ergonomics(id, {ergonomics});
  }
  if (with_roadmap_records) {
    RoadmapRecord roadmap;
    roadmap.arm = "left";
    roadmap.dof = 6;
    roadmap.resolution = 0.0625;
    writer.add_roadmap(roadmap);
    RegraspNodeRecord node;
    node.part_id = id;
    node.kind = "human_handover";
    node.arm = "left";
    node.grasp_kind = "gripper";
    node.grasp_id = 1;
    node.candidate_id = 1;
    node.board.translation() = Eigen::Vector3d(0.25, 0.5, 1.0);
    node.solutions = {Eigen::Vector2d(0.5, 1.0)};
    writer.add_regrasp_nodes({node});
    RegraspEdgeRecord edge;
    edge.part_id = id;
    edge.kind = "transit";
    edge.arm = "left";
    edge.from_node = 1;
    edge.to_node = 1;
    edge.connected = true;
    edge.cost = 0.375;
    edge.path_nodes = 3;
    edge.via = "roadmap";
    edge.path = {Eigen::Vector2d(0.5, 1.0), Eigen::Vector2d(0.5, 1.0)};
    edge.duration = regrasp_edge_duration;
    writer.add_regrasp_edges({edge});
  }
  if (with_direct_grasp_records) {
    DirectGraspRecord direct;
    direct.candidate_id = 1;
    direct.robot_grasp_id = 1;
    direct.arm = "right";
    direct.joints_pick = Eigen::Vector2d(0.5, 1.0);
    direct.joints_rh = Eigen::VectorXd::Constant(1, -2.0);
    direct.inclination_pick_deg = 22.5;
    direct.inclination_rh_deg = 67.5;
    writer.add_direct_grasps({direct});
  }
  if (with_table_regrasp_records) {
    TableRegraspRecord regrasp;
    regrasp.candidate_id = 1;
    regrasp.pick_grasp_id = 1;
    regrasp.robot_grasp_id = 1;
    regrasp.arm = "left";
    regrasp.repick_arm = table_regrasp_repick_arm;
    regrasp.placement.translation() = Eigen::Vector3d(0.5, -0.25, 0.75);
    regrasp.joints_pick = Eigen::VectorXd::Constant(1, 0.5);
    regrasp.joints_repick = Eigen::VectorXd::Constant(1, -2.0);
    regrasp.joints_rh = Eigen::Vector2d(0.5, 1.0);
    regrasp.inclination_pick_deg = 10.5;
    regrasp.inclination_place_deg = 20.5;
    regrasp.inclination_repick_deg = 30.5;
    regrasp.inclination_rh_deg = 40.5;
    writer.add_table_regrasps({regrasp});
  }
  writer.commit();
}

// The part of write_v1 as a migrated file holds it.
void expect_v1_records(const Database& db) {
  ASSERT_EQ(db.parts().size(), 1u);
  const PartRecord& part = db.part("bracket");
  EXPECT_EQ(part.id, 1);
  EXPECT_EQ(part.assembly_order, 3);
  EXPECT_EQ(part.mass_properties.inertia(1, 2), 0.125);
  EXPECT_EQ(part.target.translation(), Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(db.placements(1).size(), 1u);
  ASSERT_EQ(db.robot_grasps(1).size(), 1u);
  EXPECT_EQ(db.robot_grasps(1)[0].theta_c_deg, 45.0);
  EXPECT_EQ(db.robot_grasps(1)[0].normal_2, Eigen::Vector3d(-1.0, 0.0, 0.0));
  ASSERT_EQ(db.suction_grasps(1).size(), 1u);
  EXPECT_EQ(db.suction_grasps(1)[0].force_margin, 4.5);
  ASSERT_EQ(db.human_grasps(1).size(), 1u);
  EXPECT_TRUE(db.human_grasps(1)[0].one_hand_stable);
}

// A migrated file has the version 3 tables, empty, and an empty meta.human_bodies.
void expect_no_handover_records(const Database& db) {
  EXPECT_EQ(db.meta().human_bodies, "");
  EXPECT_TRUE(db.handover_stages().empty());
  EXPECT_EQ(db.handover_stage(1), nullptr);
  EXPECT_TRUE(db.robot_handovers(1).empty());
  EXPECT_TRUE(db.handover_candidates(1).empty());
  EXPECT_TRUE(db.handover_goals(1).empty());
  EXPECT_TRUE(db.shared_grasps(1).empty());
  EXPECT_TRUE(db.ergonomics(1).empty());
}

// A migrated file has the version 4 tables, empty.
void expect_no_roadmap_records(const Database& db) {
  EXPECT_TRUE(db.roadmaps().empty());
  EXPECT_EQ(db.roadmap("left"), nullptr);
  EXPECT_TRUE(db.roadmap_filters(1).empty());
  EXPECT_EQ(db.roadmap_filter(1), nullptr);
  EXPECT_TRUE(db.regrasp_nodes(1).empty());
  EXPECT_TRUE(db.regrasp_edges(1).empty());
}

// A migrated file has the version 5 table, empty (the by-hand files' goal is candidate 1).
void expect_no_direct_grasps(const Database& db) {
  EXPECT_TRUE(db.direct_grasps(1).empty());
}

// The by-hand files say hila 0.1.0 built them, and a migration keeps that: Database::open refuses
// them by default, as `hila build --if-outdated` would rebuild them, and reads them when told to
// accept any hila version.
Database open_migrated(const std::string& path) {
  OpenOptions options;
  options.expected_hila_version = std::nullopt;
  return Database::open(path, options);
}

// After rows were added by SQL, the per-table digests of the file as it now is, written the only
// way outside the writer, by a migration: set back to version `version` - 1, a step to `version`
// that changes no table (the real one would add handover_candidates.bodies again), after which the
// migration writes them, for the tables of `version`.
void reseal(const std::string& path, int version = current_schema_version()) {
  execute_script(path, "UPDATE meta SET value = '" + std::to_string(version - 1) +
                           "' WHERE key = 'schema_version'");
  migrate_with_steps(path, {{version - 1, "DELETE FROM meta WHERE key GLOB 'digest.*';"}}, version);
}

// A migrated file has the version 6 table, empty.
void expect_no_table_regrasps(const Database& db) {
  EXPECT_TRUE(db.table_regrasps(1).empty());
}

// A migrated file has the version 8 table, empty.
void expect_no_suction_deliveries(const Database& db) {
  EXPECT_TRUE(db.suction_deliveries(1).empty());
}

}  // namespace

TEST(Migration, Version1FileIsUpgradedToTheCurrentVersion) {
  const std::string dir = temp_dir("db_migration_v1");
  const std::string path = write_v1(dir);
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.schema_version", "written by schema version 1 (an older hila)",
                      "rebuild with: hila build product.yaml -o " + path,
                      "(or migrate it in place with hila::db::migrate_in_place)"});
  const std::string digest_v1 = content_digest(path);  // an old file still has a digest

  migrate_in_place(path);  // 1 -> 2 -> 3 -> 4 -> 5 -> 6 -> 7 -> 8 -> 9 -> 10

  // Readable now, but still what hila 0.1.0 built: refused unless any hila version is accepted.
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.hila_version: expected a database built by this hila (" +
                          hila_version() + "), got one built by hila 0.1.0 (an older hila",
                      "rebuild with: hila build product.yaml -o " + path});
  const Database db = open_migrated(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().product_name, "cabinet");
  EXPECT_EQ(db.meta().seed, 18446744073709551615ull);
  EXPECT_EQ(db.meta().created_at, "2024-06-11T10:00:00Z") << "meta kept as it was";
  expect_v1_records(db);
  EXPECT_TRUE(db.comfort_maps().empty()) << "a migrated file has no maps until it is rebuilt";
  expect_input_error([&] { db.comfort_map("right"); },
                     {path + ": comfort_maps", "a comfort map for arm 'right' (arms: none)"});
  expect_no_handover_records(db);
  expect_no_roadmap_records(db);
  expect_no_direct_grasps(db);
  expect_no_table_regrasps(db);
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"v1.db"}) << "no temporary copy left";

  // The migrated file holds exactly what this hila writes for the same records: same tables,
  // columns, types and values.
  const std::string fresh = dir + "/fresh.db";
  write_reference_content(fresh, false);
  EXPECT_EQ(content_digest(path), content_digest(fresh));
  EXPECT_NE(content_digest(path), digest_v1);

  // Migrating again is a no-op.
  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after);
}

TEST(Migration, Version2FileIsUpgradedToTheCurrentVersion) {
  const std::string dir = temp_dir("db_migration_v2");
  const std::string path = write_v2(dir);
  // Unmigrated, the file is refused as outdated, with the way out.
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 2 (an older hila); rebuild with: hila build product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  EXPECT_THROW(Database::open(path), DatabaseError);
  const std::string digest_v2 = content_digest(path);

  migrate_in_place(path);  // 2 -> 3 -> 4 -> 5 -> 6 -> 7 -> 8 -> 9 -> 10

  const Database db = open_migrated(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().created_at, "2024-06-11T10:00:00Z") << "meta kept as it was";
  expect_v1_records(db);
  ASSERT_EQ(db.comfort_maps().size(), 1u) << "the comfort map is kept";
  EXPECT_EQ(db.comfort_map("right").origin, Eigen::Vector3d(0.25, -0.5, 1.0));
  EXPECT_EQ(db.comfort_map("right").seed, 18446744073709551615ull);
  EXPECT_TRUE(db.comfort_map("right").values.empty());
  expect_no_handover_records(db);
  expect_no_roadmap_records(db);
  expect_no_direct_grasps(db);
  expect_no_table_regrasps(db);
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"v2.db"}) << "no temporary copy left";

  // Same content as this hila writes: the new tables (empty) and meta.human_bodies ("") included.
  const std::string fresh = dir + "/fresh.db";
  write_reference_content(fresh, true);
  EXPECT_EQ(content_digest(path), content_digest(fresh));
  EXPECT_NE(content_digest(path), digest_v2);

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after);
}

TEST(Migration, Version3FileIsUpgradedToTheCurrentVersion) {
  const std::string dir = temp_dir("db_migration_v3");
  const std::string path = write_v3(dir);
  // Unmigrated, the file is refused as outdated, with the way out.
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 3 (an older hila); rebuild with: hila build product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  const std::string digest_v3 = content_digest(path);

  migrate_in_place(path);  // 3 -> 4 -> 5 -> 6 -> 7 -> 8 -> 9 -> 10

  const Database db = open_migrated(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().created_at, "2024-06-11T10:00:00Z") << "meta kept as it was";
  EXPECT_EQ(db.meta().human_bodies, "1.75 male") << "meta kept as it was";
  expect_v1_records(db);
  ASSERT_EQ(db.comfort_maps().size(), 1u) << "the comfort map is kept";
  EXPECT_EQ(db.comfort_map("right").coverage, 0.375);
  // Every version 3 record is kept.
  ASSERT_NE(db.handover_stage(1), nullptr);
  EXPECT_EQ(db.handover_stage(1)->draws, 812);
  EXPECT_EQ(db.handover_stage(1)->goals, 1);
  ASSERT_EQ(db.robot_handovers(1).size(), 1u);
  EXPECT_EQ(db.robot_handovers(1)[0].joints, Eigen::Vector2d(0.5, 1.0));
  EXPECT_EQ(db.robot_handovers(1)[0].board.translation(), Eigen::Vector3d(0.5, 0.0, 1.0));
  const auto goals = db.handover_goals(1);
  ASSERT_EQ(goals.size(), 1u);
  EXPECT_EQ(goals[0].human_quality, 0.875);
  EXPECT_EQ(goals[0].human_joints, Eigen::VectorXd::Constant(1, -2.0));
  EXPECT_EQ(goals[0].bodies, 0u) << "the 9 -> 10 step: no body";
  ASSERT_EQ(db.shared_grasps(1).size(), 1u);
  EXPECT_EQ(db.shared_grasps(1)[0].inclination_rh_deg, 45.0);
  ASSERT_EQ(db.ergonomics(1).size(), 1u);
  EXPECT_EQ(db.ergonomics(1)[0].torso_flexion_deg, 17.25);
  // The version 4, 5, 6 and 8 tables exist, empty.
  expect_no_roadmap_records(db);
  expect_no_direct_grasps(db);
  expect_no_table_regrasps(db);
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"v3.db"}) << "no temporary copy left";

  // Same content as this hila writes for the same records: the new tables (empty) included.
  const std::string fresh = dir + "/fresh.db";
  write_reference_content(fresh, true, true);
  EXPECT_EQ(content_digest(path), content_digest(fresh));
  EXPECT_NE(content_digest(path), digest_v3);

  // The migrated file takes version 4 records like a fresh one (the tables and their constraints
  // are there): a roadmap row by SQL, then a filter of it that breaks its foreign key.
  execute_script(path,
                 "INSERT INTO roadmaps VALUES (1, 'left', 6, 0.05, 0, 0, x'', x'', x'', x'', x'', "
                 "x'');");
  // An edit after the migration is refused like any other.
  expect_input_error([&] { open_migrated(path); },
                     {path + ": roadmaps: expected the content digest stored when it was written"});
  reseal(path);
  EXPECT_EQ(open_migrated(path).roadmaps().size(), 1u);
  // The regrasp edges as a fresh file has them: how each was connected and its path.
  execute_script(path,
                 "CREATE TEMP TABLE probe AS SELECT via, path_dof, path_waypoints, path, "
                 "duration FROM regrasp_edges;");
  expect_input_error(
      [&] {
        execute_script(path,
                       "INSERT INTO roadmap_filters VALUES (1, 1, 2, 'gripper', 1, 90.0, 0, 0, 0, "
                       "x'', x'');");
      },
      {"FOREIGN KEY constraint failed"});

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after) << "migrating a current file is a no-op";
}

TEST(Migration, Version3FileThatAlreadyHasTheNewTablesFailsCleanly) {
  // Version 4 content with the version number set back: the 3 -> 4 step's CREATE TABLE fails and
  // the file is left as it was.
  const std::string dir = temp_dir("db_migration_v3_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '3' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 3 -> 4", "table roadmaps already exists"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version4FileIsUpgradedToTheCurrentVersion) {
  const std::string dir = temp_dir("db_migration_v4");
  const std::string path = write_v4(dir);
  // Unmigrated, the file is refused as outdated, with the way out.
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 4 (an older hila); rebuild with: hila build product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  const std::string digest_v4 = content_digest(path);

  migrate_in_place(path);  // 4 -> 5 -> 6 -> 7 -> 8 -> 9 -> 10

  const Database db = open_migrated(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().created_at, "2024-06-11T10:00:00Z") << "meta kept as it was";
  EXPECT_EQ(db.meta().human_bodies, "1.75 male") << "meta kept as it was";
  expect_v1_records(db);
  ASSERT_EQ(db.comfort_maps().size(), 1u) << "the comfort map is kept";
  // The version 3 and 4 records are kept.
  ASSERT_EQ(db.handover_goals(1).size(), 1u);
  ASSERT_EQ(db.shared_grasps(1).size(), 1u);
  EXPECT_EQ(db.shared_grasps(1)[0].joints_rr, Eigen::Vector2d(0.5, 1.0));
  ASSERT_EQ(db.ergonomics(1).size(), 1u);
  ASSERT_NE(db.roadmap("left"), nullptr);
  EXPECT_EQ(db.roadmap("left")->resolution, 0.0625);
  ASSERT_EQ(db.regrasp_nodes(1).size(), 1u);
  EXPECT_EQ(db.regrasp_nodes(1)[0].candidate_id, 1);
  ASSERT_EQ(db.regrasp_nodes(1)[0].solutions.size(), 1u);
  EXPECT_EQ(db.regrasp_nodes(1)[0].solutions[0], Eigen::Vector2d(0.5, 1.0));
  // The regrasp edge is kept, every field, and has the column of version 9: 0, not estimated.
  const auto edges = db.regrasp_edges(1);
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].id, 1);
  EXPECT_EQ(edges[0].kind, "transit");
  EXPECT_EQ(edges[0].from_node, 1);
  EXPECT_EQ(edges[0].filter_id, 0);
  EXPECT_TRUE(edges[0].connected);
  EXPECT_EQ(edges[0].cost, 0.375);
  EXPECT_EQ(edges[0].path_nodes, 3);
  EXPECT_EQ(edges[0].via, "roadmap");
  ASSERT_EQ(edges[0].path.size(), 2u);
  EXPECT_EQ(edges[0].path[1], Eigen::Vector2d(0.5, 1.0));
  EXPECT_EQ(edges[0].duration, 0.0) << "the 8 -> 9 step: not estimated";
  // The version 5, 6 and 8 tables exist, empty.
  expect_no_direct_grasps(db);
  expect_no_table_regrasps(db);
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"v4.db"}) << "no temporary copy left";

  // Same content as this hila writes for the same records: the new tables (empty) included.
  const std::string fresh = dir + "/fresh.db";
  write_reference_content(fresh, true, true, true);
  EXPECT_EQ(content_digest(path), content_digest(fresh));
  EXPECT_NE(content_digest(path), digest_v4);
  // With the edge's duration estimated the content differs: the comparison sees the column.
  const std::string estimated = dir + "/estimated.db";
  write_reference_content(estimated, true, true, true, false, false, "left", 1.5);
  EXPECT_NE(content_digest(path), content_digest(estimated));
  // regrasp_edges (and its index) declared as a fresh file declares them, nothing left over.
  EXPECT_EQ(regrasp_edges_sql(path), regrasp_edges_sql(fresh));
  EXPECT_EQ(regrasp_edges_sql(path).size(), 2u);

  // The migrated file takes direct grasps like a fresh one (the table and its foreign keys are
  // there): a row by SQL, read back, then one of a candidate that does not exist.
  execute_script(path,
                 "INSERT INTO direct_grasps VALUES (1, 1, 1, 'left', x'000000000000e03f', x'', "
                 "22.5, 45.0);");
  reseal(path);
  const auto direct = open_migrated(path).direct_grasps(1);
  ASSERT_EQ(direct.size(), 1u);
  EXPECT_EQ(direct[0].robot_grasp_id, 1);
  EXPECT_EQ(direct[0].arm, "left");
  EXPECT_EQ(direct[0].joints_pick, Eigen::VectorXd::Constant(1, 0.5));
  EXPECT_EQ(direct[0].joints_rh.size(), 0);
  EXPECT_EQ(direct[0].inclination_pick_deg, 22.5);
  EXPECT_EQ(direct[0].inclination_rh_deg, 45.0);
  expect_input_error(
      [&] {
        execute_script(path,
                       "INSERT INTO direct_grasps VALUES (2, 2, 1, 'left', x'', x'', 0.0, 0.0);");
      },
      {"FOREIGN KEY constraint failed"});

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after) << "migrating a current file is a no-op";
}

TEST(Migration, Version4FileThatAlreadyHasTheNewTableFailsCleanly) {
  // Version 5 content with the version number set back: the 4 -> 5 step's CREATE TABLE fails and
  // the file is left as it was.
  const std::string dir = temp_dir("db_migration_v4_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '4' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 4 -> 5", "table direct_grasps already exists"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version5FileIsUpgradedToTheCurrentVersion) {
  const std::string dir = temp_dir("db_migration_v5");
  const std::string path = write_v5(dir);
  // Unmigrated, the file is refused as outdated, with the way out.
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 5 (an older hila); rebuild with: hila build product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  const std::string digest_v5 = content_digest(path);

  migrate_in_place(path);  // 5 -> 6 -> 7 -> 8 -> 9 -> 10

  const Database db = open_migrated(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().created_at, "2024-06-11T10:00:00Z") << "meta kept as it was";
  EXPECT_EQ(db.meta().human_bodies, "1.75 male") << "meta kept as it was";
  expect_v1_records(db);
  ASSERT_EQ(db.comfort_maps().size(), 1u) << "the comfort map is kept";
  EXPECT_EQ(db.comfort_map("right").coverage, 0.375);
  // The version 3 and 4 records are kept.
  ASSERT_NE(db.handover_stage(1), nullptr);
  EXPECT_EQ(db.handover_stage(1)->draws, 812);
  ASSERT_EQ(db.robot_handovers(1).size(), 1u);
  EXPECT_EQ(db.robot_handovers(1)[0].joints, Eigen::Vector2d(0.5, 1.0));
  ASSERT_EQ(db.handover_goals(1).size(), 1u);
  EXPECT_EQ(db.handover_goals(1)[0].human_joints, Eigen::VectorXd::Constant(1, -2.0));
  ASSERT_EQ(db.shared_grasps(1).size(), 1u);
  EXPECT_EQ(db.shared_grasps(1)[0].joints_rr, Eigen::Vector2d(0.5, 1.0));
  ASSERT_EQ(db.ergonomics(1).size(), 1u);
  EXPECT_EQ(db.ergonomics(1)[0].torso_flexion_deg, 17.25);
  ASSERT_NE(db.roadmap("left"), nullptr);
  EXPECT_EQ(db.roadmap("left")->resolution, 0.0625);
  ASSERT_EQ(db.regrasp_nodes(1).size(), 1u);
  ASSERT_EQ(db.regrasp_nodes(1)[0].solutions.size(), 1u);
  EXPECT_EQ(db.regrasp_nodes(1)[0].solutions[0], Eigen::Vector2d(0.5, 1.0));
  // The version 5 record is kept, every field.
  const auto direct = db.direct_grasps(1);
  ASSERT_EQ(direct.size(), 1u);
  EXPECT_EQ(direct[0].id, 1);
  EXPECT_EQ(direct[0].candidate_id, 1);
  EXPECT_EQ(direct[0].robot_grasp_id, 1);
  EXPECT_EQ(direct[0].arm, "right");
  ASSERT_EQ(direct[0].joints_pick.size(), 2);
  EXPECT_EQ(direct[0].joints_pick, Eigen::Vector2d(0.5, 1.0));
  ASSERT_EQ(direct[0].joints_rh.size(), 1);
  EXPECT_EQ(direct[0].joints_rh[0], -2.0);
  EXPECT_EQ(direct[0].inclination_pick_deg, 22.5);
  EXPECT_EQ(direct[0].inclination_rh_deg, 67.5);
  // The version 6 and 8 tables exist, empty.
  expect_no_table_regrasps(db);
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"v5.db"}) << "no temporary copy left";

  // Same content as this hila writes for the same records: the new table (empty) included.
  const std::string fresh = dir + "/fresh.db";
  write_reference_content(fresh, true, true, true, true);
  EXPECT_EQ(content_digest(path), content_digest(fresh));
  EXPECT_NE(content_digest(path), digest_v5);
  // Without the direct grasp the content differs: the comparison sees the version 5 rows.
  const std::string without = dir + "/without.db";
  write_reference_content(without, true, true, true, false);
  EXPECT_NE(content_digest(path), content_digest(without));

  // The migrated file takes table regrasps like a fresh one (the version 8 table, repick_arm
  // included, and its foreign keys are there): a relay row by SQL, read back, then one whose pick
  // grasp does not exist.
  execute_script(
      path,
      "INSERT INTO table_regrasps VALUES (1, 1, 1, 1, 'left', 'right', 0.5, -0.25, 0.75, "
      "0.0, 0.0, 0.0, 1.0, x'000000000000e03f', x'', x'00000000000000c0', "
      "x'000000000000e03f000000000000f03f', 10.5, 20.5, 30.5, 40.5);");
  reseal(path);
  const auto regrasps = open_migrated(path).table_regrasps(1);
  ASSERT_EQ(regrasps.size(), 1u);
  EXPECT_EQ(regrasps[0].id, 1);
  EXPECT_EQ(regrasps[0].pick_grasp_id, 1);
  EXPECT_EQ(regrasps[0].robot_grasp_id, 1);
  EXPECT_EQ(regrasps[0].arm, "left");
  EXPECT_EQ(regrasps[0].repick_arm, "right");
  EXPECT_EQ(regrasps[0].placement.translation(), Eigen::Vector3d(0.5, -0.25, 0.75));
  EXPECT_EQ(regrasps[0].placement.linear(),
            Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal().toDenseMatrix())
      << "a half turn about z";
  ASSERT_EQ(regrasps[0].joints_pick.size(), 1);
  EXPECT_EQ(regrasps[0].joints_pick[0], 0.5);
  EXPECT_EQ(regrasps[0].joints_place.size(), 0);
  ASSERT_EQ(regrasps[0].joints_repick.size(), 1);
  EXPECT_EQ(regrasps[0].joints_repick[0], -2.0);
  ASSERT_EQ(regrasps[0].joints_rh.size(), 2);
  EXPECT_EQ(regrasps[0].joints_rh, Eigen::Vector2d(0.5, 1.0));
  EXPECT_EQ(regrasps[0].inclination_pick_deg, 10.5);
  EXPECT_EQ(regrasps[0].inclination_place_deg, 20.5);
  EXPECT_EQ(regrasps[0].inclination_repick_deg, 30.5);
  EXPECT_EQ(regrasps[0].inclination_rh_deg, 40.5);
  EXPECT_EQ(open_migrated(path).direct_grasps(1).size(), 1u) << "a table of its own";
  expect_input_error(
      [&] {
        execute_script(
            path,
            "INSERT INTO table_regrasps VALUES (2, 1, 2, 1, 'left', 'left', 0.0, 0.0, 0.0, "
            "1.0, 0.0, 0.0, 0.0, x'', x'', x'', x'', 0.0, 0.0, 0.0, 0.0);");
      },
      {"FOREIGN KEY constraint failed"});

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after) << "migrating a current file is a no-op";
}

TEST(Migration, Version5FileThatAlreadyHasTheNewTableFailsCleanly) {
  // Version 6 content with the version number set back: the 5 -> 6 step's CREATE TABLE fails and
  // the file is left as it was.
  const std::string dir = temp_dir("db_migration_v5_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '5' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 5 -> 6", "table table_regrasps already exists"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version6FileIsUpgradedToTheCurrentVersion) {
  const std::string dir = temp_dir("db_migration_v6");
  const std::string path = write_v6(dir);
  // Unmigrated, the file is refused as outdated, with the way out.
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 6 (an older hila); rebuild with: hila build product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  const std::string digest_v6 = content_digest(path);

  migrate_in_place(path);  // 6 -> 7 -> 8 -> 9 -> 10

  const Database db = open_migrated(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().created_at, "2024-06-11T10:00:00Z") << "meta kept as it was";
  EXPECT_EQ(db.meta().human_bodies, "1.75 male") << "meta kept as it was";
  expect_v1_records(db);
  ASSERT_EQ(db.comfort_maps().size(), 1u) << "the comfort map is kept";
  // The version 3, 4 and 5 records are kept.
  ASSERT_EQ(db.handover_goals(1).size(), 1u);
  ASSERT_EQ(db.shared_grasps(1).size(), 1u);
  ASSERT_NE(db.roadmap("left"), nullptr);
  ASSERT_EQ(db.regrasp_nodes(1).size(), 1u);
  ASSERT_EQ(db.direct_grasps(1).size(), 1u);
  EXPECT_EQ(db.direct_grasps(1)[0].inclination_rh_deg, 67.5);
  // The version 6 record is kept, every field.
  const auto regrasps = db.table_regrasps(1);
  ASSERT_EQ(regrasps.size(), 1u);
  EXPECT_EQ(regrasps[0].id, 1);
  EXPECT_EQ(regrasps[0].candidate_id, 1);
  EXPECT_EQ(regrasps[0].pick_grasp_id, 1);
  EXPECT_EQ(regrasps[0].robot_grasp_id, 1);
  EXPECT_EQ(regrasps[0].arm, "left");
  EXPECT_EQ(regrasps[0].repick_arm, "left") << "the 7 -> 8 step fills repick_arm with arm";
  EXPECT_EQ(regrasps[0].placement.translation(), Eigen::Vector3d(0.5, -0.25, 0.75));
  EXPECT_EQ(regrasps[0].placement.linear(), Eigen::Matrix3d::Identity());
  EXPECT_EQ(regrasps[0].joints_pick, Eigen::VectorXd::Constant(1, 0.5));
  EXPECT_EQ(regrasps[0].joints_place.size(), 0);
  EXPECT_EQ(regrasps[0].joints_repick, Eigen::VectorXd::Constant(1, -2.0));
  EXPECT_EQ(regrasps[0].joints_rh, Eigen::Vector2d(0.5, 1.0));
  EXPECT_EQ(regrasps[0].inclination_pick_deg, 10.5);
  EXPECT_EQ(regrasps[0].inclination_place_deg, 20.5);
  EXPECT_EQ(regrasps[0].inclination_repick_deg, 30.5);
  EXPECT_EQ(regrasps[0].inclination_rh_deg, 40.5);
  // The version 8 table exists, empty.
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"v6.db"}) << "no temporary copy left";

  // Same content as this hila writes for the same records: the new table (empty) included.
  const std::string fresh = dir + "/fresh.db";
  write_reference_content(fresh, true, true, true, true, true);
  EXPECT_EQ(content_digest(path), content_digest(fresh));
  EXPECT_NE(content_digest(path), digest_v6);
  // Without the table regrasp the content differs: the comparison sees the version 6 rows.
  const std::string without = dir + "/without.db";
  write_reference_content(without, true, true, true, true, false);
  EXPECT_NE(content_digest(path), content_digest(without));
  // As a relay it differs too: the comparison sees repick_arm.
  const std::string relay = dir + "/relay.db";
  write_reference_content(relay, true, true, true, true, true, "right");
  EXPECT_NE(content_digest(path), content_digest(relay));
  // The table (and its index) declared as a fresh file declares them, nothing left over.
  EXPECT_EQ(table_regrasps_sql(path), table_regrasps_sql(fresh));
  EXPECT_EQ(table_regrasps_sql(path).size(), 2u);

  // The migrated file takes suction deliveries like a fresh one (the table and its foreign keys
  // are there): a row by SQL, read back, then one whose suction grasp does not exist.
  execute_script(path,
                 "INSERT INTO suction_deliveries VALUES (1, 1, 1, 'right', "
                 "x'000000000000e03f000000000000f03f');");
  // An edit after the migration is refused like any other.
  expect_input_error([&] { open_migrated(path); },
                     {path + ": suction_deliveries: expected the content digest stored when it "
                             "was written"});
  reseal(path);
  const auto deliveries = open_migrated(path).suction_deliveries(1);
  ASSERT_EQ(deliveries.size(), 1u);
  EXPECT_EQ(deliveries[0].id, 1);
  EXPECT_EQ(deliveries[0].candidate_id, 1);
  EXPECT_EQ(deliveries[0].suction_grasp_id, 1);
  EXPECT_EQ(deliveries[0].arm, "right");
  EXPECT_EQ(deliveries[0].joints_rh, Eigen::Vector2d(0.5, 1.0));
  EXPECT_EQ(open_migrated(path).table_regrasps(1).size(), 1u) << "a table of its own";
  expect_input_error(
      [&] {
        execute_script(path, "INSERT INTO suction_deliveries VALUES (2, 1, 2, 'right', x'');");
      },
      {"FOREIGN KEY constraint failed"});

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after) << "migrating a current file is a no-op";
}

TEST(Migration, Version7FileIsUpgradedWithItsDigestsRewritten) {
  // A version 7 file as this hila's writer would have made it: no suction_deliveries table, no
  // table_regrasps.repick_arm, no regrasp_edges.duration, no handover_candidates.bodies, and a
  // stored digest for every table. The 7 -> 8 step adds the table and the column (each row's its
  // arm), the 8 -> 9 step the duration (0), the 9 -> 10 step the bodies (0), the migration the
  // digests of all of them, the new one included.
  const std::string dir = temp_dir("db_migration_v7");
  Sample sample = make_sample();
  sample.parts[0].suction_deliveries.clear();  // a version 7 file cannot hold any
  const std::string path = dir + "/v7.db";
  write_sample(path, sample);  // the sample's relays lose their repick arm with the column
  execute_script(path,
                 "DROP TABLE suction_deliveries;"
                 "DELETE FROM meta WHERE key = 'digest.suction_deliveries';"
                 "ALTER TABLE table_regrasps DROP COLUMN repick_arm;" +
                     regrasp_edges_before_v9_sql() + handover_candidates_before_v10_sql() +
                     "UPDATE meta SET value = '7' WHERE key = 'schema_version'");
  // What this hila writes for the same records: every regrasp taken again by its own arm, no
  // edge's duration estimated, no candidate's bodies.
  clear_durations(sample);
  clear_bodies(sample);
  std::size_t relays = 0;
  for (auto& r : sample.parts[0].table_regrasps) {
    relays += r.repick_arm != r.arm ? 1 : 0;
    r.repick_arm = r.arm;
  }
  ASSERT_GT(relays, 0u) << "the sample has relays, so the migration must not keep what it had";
  const std::string written = dir + "/written.db";
  write_sample(written, sample);
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.schema_version", "written by schema version 7 (an older hila)",
                      "(or migrate it in place with hila::db::migrate_in_place)"});
  const std::string digest_v7 = content_digest(path);

  migrate_in_place(path);  // 7 -> 8 -> 9 -> 10

  // Built by this hila: opens with the default options, every stored digest checked.
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  for (const auto& e : db.regrasp_edges(1)) EXPECT_EQ(e.duration, 0.0) << e.id;
  for (const auto& c : db.handover_candidates(1)) {
    EXPECT_TRUE(db.suction_deliveries(c.id).empty()) << c.id;
    EXPECT_EQ(c.bodies, 0u) << c.id;
  }
  std::size_t regrasps = 0;
  for (const auto& c : db.handover_candidates(1)) {
    for (const auto& r : db.table_regrasps(c.id)) {
      SCOPED_TRACE(r.id);
      ++regrasps;
      EXPECT_FALSE(r.arm.empty());
      EXPECT_EQ(r.repick_arm, r.arm) << "the step fills repick_arm with the row's arm";
      const auto& want = sample.parts[0].table_regrasps.at(static_cast<std::size_t>(r.id - 1));
      EXPECT_EQ(r.arm, want.arm) << "the rest of the row is kept";
      EXPECT_EQ(r.candidate_id, want.candidate_id);
      EXPECT_EQ(r.inclination_rh_deg, want.inclination_rh_deg);
    }
  }
  EXPECT_EQ(regrasps, sample.parts[0].table_regrasps.size()) << "the version 6 rows are kept";
  EXPECT_EQ(content_digest(path), content_digest(written));
  EXPECT_NE(content_digest(path), digest_v7);
  // The table and its index declared as a fresh file declares them, nothing left over.
  EXPECT_EQ(table_regrasps_sql(path), table_regrasps_sql(written));
  EXPECT_EQ(table_regrasps_sql(path).size(), 2u);
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"v7.db", "written.db"}));
}

TEST(Migration, Version7FileThatAlreadyHasTheNewTableFailsCleanly) {
  // Version 8 content with the version number set back: the 7 -> 8 step's CREATE TABLE fails and
  // the file is left as it was.
  const std::string dir = temp_dir("db_migration_v7_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '7' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 7 -> 8", "table suction_deliveries already exists"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version8FileIsUpgradedWithItsDurationsNotEstimated) {
  // A version 8 file as this hila's writer would have made it: regrasp_edges without duration
  // (version 4's table), handover_candidates without bodies (version 3's) and a stored digest for
  // every table, of that content. The 8 -> 9 step gives every edge the column, 0 (not estimated),
  // the 9 -> 10 step every candidate its bodies, 0, the migration the digests.
  const std::string dir = temp_dir("db_migration_v8");
  Sample sample = make_sample();
  const std::string path = dir + "/v8.db";
  write_sample(path, sample);  // its estimated durations go with the column
  execute_script(path, regrasp_edges_before_v9_sql() + handover_candidates_before_v10_sql());
  reseal(path, 8);  // the digests a version 8 writer stored for this content
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 8 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  ASSERT_EQ(regrasp_edges_sql(path).size(), 2u);
  EXPECT_EQ(regrasp_edges_sql(path)[0].find("duration"), std::string::npos)
      << regrasp_edges_sql(path)[0];
  const std::string digest_v8 = content_digest(path);
  const auto digests_v8 = stored_digests(path);
  // What this hila writes for the same records: no edge's duration estimated.
  std::size_t estimated = 0;
  for (const auto& p : sample.parts) {
    for (const auto& e : p.regrasp_edges) estimated += e.duration > 0.0 ? 1 : 0;
  }
  ASSERT_GT(estimated, 0u) << "the sample has durations, so the migration must not keep them";
  clear_durations(sample);
  clear_bodies(sample);
  const std::string written = dir + "/written.db";
  write_sample(written, sample);

  migrate_in_place(path);  // 8 -> 9 -> 10

  // Built by this hila: opens with the default options, every stored digest checked.
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  std::size_t edges = 0;
  for (std::size_t k = 0; k < sample.parts.size(); ++k) {
    const auto got = db.regrasp_edges(static_cast<std::int64_t>(k + 1));
    const auto& want = sample.parts[k].regrasp_edges;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(want[i].id);
      ++edges;
      EXPECT_EQ(got[i].duration, 0.0) << "the step: not estimated";
      EXPECT_EQ(got[i].id, want[i].id) << "the rest of the row is kept";
      EXPECT_EQ(got[i].kind, want[i].kind);
      EXPECT_EQ(got[i].filter_id, want[i].filter_id);
      EXPECT_EQ(got[i].cost, want[i].cost);
      EXPECT_EQ(got[i].via, want[i].via);
      EXPECT_EQ(got[i].path, want[i].path);
    }
  }
  EXPECT_EQ(edges, 8u);
  EXPECT_EQ(content_digest(path), content_digest(written));
  EXPECT_NE(content_digest(path), digest_v8);
  // The stored digests are the writer's; against the version 8 file's, only regrasp_edges' and
  // handover_candidates' (their columns) and meta's (schema_version) changed.
  const auto digests = stored_digests(path);
  EXPECT_EQ(digests, stored_digests(written));
  ASSERT_EQ(digests.size(), digests_v8.size());
  for (const auto& [key, digest] : digests) {
    if (key == "digest.regrasp_edges" || key == "digest.handover_candidates" ||
        key == "digest.meta") {
      EXPECT_NE(digest, digests_v8.at(key)) << key;
    } else {
      EXPECT_EQ(digest, digests_v8.at(key)) << key;
    }
  }
  // The table (and its index) declared as a fresh file declares them, nothing left over.
  EXPECT_EQ(regrasp_edges_sql(path), regrasp_edges_sql(written));
  EXPECT_EQ(regrasp_edges_sql(path).size(), 2u);
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"v8.db", "written.db"}));

  // The migrated table takes an estimated duration like a fresh one, and its CHECKs refuse one
  // without a path (edge 4 is not connected).
  execute_script(path, "UPDATE regrasp_edges SET duration = 2.5 WHERE id = 1");
  expect_input_error([&] { Database::open(path); },
                     {path + ": regrasp_edges: expected the content digest stored when it was "
                             "written"});
  reseal(path);
  EXPECT_EQ(Database::open(path).regrasp_edges(1)[0].duration, 2.5);
  expect_input_error(
      [&] { execute_script(path, "UPDATE regrasp_edges SET duration = 2.5 WHERE id = 4"); },
      {"CHECK constraint failed"});

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after) << "migrating a current file is a no-op";
}

TEST(Migration, Version8FileThatAlreadyHasTheNewColumnFailsCleanly) {
  // Version 9 content with the version number set back: the 8 -> 9 step's ADD COLUMN fails and
  // the file is left as it was (its estimated durations are not replaced by 0).
  const std::string dir = temp_dir("db_migration_v8_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '8' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 8 -> 9", "duplicate column name: duration"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version9FileIsUpgradedWithItsCandidatesTakingNoBody) {
  // A version 9 file as this hila's writer would have made it: handover_candidates without bodies
  // (version 3's table, which shared_grasps, direct_grasps, table_regrasps, suction_deliveries and
  // regrasp_nodes refer to) and a stored digest for every table, of that content. The 9 -> 10 step
  // gives every candidate the column, 0 (no body: not computed), the migration the digests.
  const std::string dir = temp_dir("db_migration_v9");
  Sample sample = make_sample();
  const std::string path = dir + "/v9.db";
  write_sample(path, sample);  // its masks go with the column
  execute_script(path, handover_candidates_before_v10_sql());
  reseal(path, 9);  // the digests a version 9 writer stored for this content
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), got one "
       "written by schema version 9 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  ASSERT_EQ(handover_candidates_sql(path).size(), 2u);
  EXPECT_EQ(handover_candidates_sql(path)[0], handover_candidates_v3_sql())
      << "declared as versions 3 to 9 declared it";
  const auto declared_v9 = all_declared_sql(path);
  const std::string digest_v9 = content_digest(path);
  const auto digests_v9 = stored_digests(path);
  // What this hila writes for the same records: no candidate takes a body.
  std::size_t with_bodies = 0;
  for (const auto& p : sample.parts) {
    for (const auto& c : p.handover_candidates) with_bodies += c.bodies != 0 ? 1 : 0;
  }
  ASSERT_GT(with_bodies, 0u) << "the sample has masks, so the migration must not keep them";
  clear_bodies(sample);
  const std::string written = dir + "/written.db";
  write_sample(written, sample);

  migrate_in_place(path);  // 9 -> 10

  // Built by this hila: opens with the default options, every stored digest and reference checked.
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  EXPECT_EQ(db.meta().human_bodies, "1.75 male; 1.55 female") << "meta kept as it was";
  std::size_t candidates = 0;
  std::size_t referring = 0;
  for (std::size_t k = 0; k < sample.parts.size(); ++k) {
    const auto got = db.handover_candidates(static_cast<std::int64_t>(k + 1));
    const auto& want = sample.parts[k].handover_candidates;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(want[i].id);
      ++candidates;
      EXPECT_EQ(got[i].bodies, 0u) << "the step: no body";
      EXPECT_EQ(got[i].id, want[i].id) << "the rest of the row is kept";
      EXPECT_EQ(got[i].status, want[i].status);
      EXPECT_EQ(got[i].rank, want[i].rank);
      EXPECT_EQ(got[i].distance, want[i].distance);
      EXPECT_EQ(got[i].second_quality, want[i].second_quality);
      EXPECT_EQ(got[i].human_joints, want[i].human_joints);
      EXPECT_EQ(got[i].second_joints, want[i].second_joints);
      referring += db.shared_grasps(got[i].id).size() + db.direct_grasps(got[i].id).size() +
                   db.table_regrasps(got[i].id).size() + db.suction_deliveries(got[i].id).size();
    }
  }
  EXPECT_EQ(candidates, 9u);
  std::size_t written_referring = 0;
  for (const auto& p : sample.parts) {
    written_referring += p.shared_grasps.size() + p.direct_grasps.size() + p.table_regrasps.size() +
                         p.suction_deliveries.size();
  }
  EXPECT_GT(referring, 0u);
  EXPECT_EQ(referring, written_referring) << "the rows referring to candidates still find theirs";
  EXPECT_EQ(content_digest(path), content_digest(written));
  EXPECT_NE(content_digest(path), digest_v9);
  // The stored digests are the writer's; against the version 9 file's, only handover_candidates'
  // (its column) and meta's (schema_version) changed.
  const auto digests = stored_digests(path);
  EXPECT_EQ(digests, stored_digests(written));
  ASSERT_EQ(digests.size(), digests_v9.size());
  for (const auto& [key, digest] : digests) {
    if (key == "digest.handover_candidates" || key == "digest.meta") {
      EXPECT_NE(digest, digests_v9.at(key)) << key;
    } else {
      EXPECT_EQ(digest, digests_v9.at(key)) << key;
    }
  }
  // The table (and its index) declared as a fresh file declares them, nothing left over, and
  // every other table as it was: the tables referring to handover_candidates still name it.
  EXPECT_EQ(handover_candidates_sql(path), handover_candidates_sql(written));
  EXPECT_EQ(handover_candidates_sql(path).size(), 2u);
  const auto declared = all_declared_sql(path);
  EXPECT_EQ(declared, all_declared_sql(written));
  ASSERT_EQ(declared.size(), declared_v9.size());
  for (const auto& [name, sql] : declared) {
    if (name == "handover_candidates") continue;
    EXPECT_EQ(sql, declared_v9.at(name)) << name;
  }
  EXPECT_NE(declared.at("shared_grasps").find("REFERENCES handover_candidates(id)"),
            std::string::npos);
  EXPECT_EQ(files_in(dir), (std::vector<std::string>{"v9.db", "written.db"}));

  // The migrated table takes a mask like a fresh one, its CHECK refuses one beyond 32 bits, and
  // the foreign keys referring to it hold against it (candidate 2 has shared grasps).
  execute_script(path, "UPDATE handover_candidates SET bodies = 3 WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path + ": handover_candidates: expected the content digest stored when it "
                             "was written"});
  reseal(path);
  EXPECT_EQ(Database::open(path).handover_candidates(1)[1].bodies, 3u);
  expect_input_error(
      [&] {
        execute_script(path, "UPDATE handover_candidates SET bodies = 4294967296 WHERE id = 2");
      },
      {"CHECK constraint failed"});
  expect_input_error([&] { execute_script(path, "DELETE FROM handover_candidates WHERE id = 2"); },
                     {"FOREIGN KEY constraint failed"});

  const std::string after = read_file(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), after) << "migrating a current file is a no-op";
}

TEST(Migration, Version9FileThatAlreadyHasTheNewColumnFailsCleanly) {
  // Version 10 content with the version number set back: the 9 -> 10 step's ADD COLUMN fails and
  // the file is left as it was (its masks are not replaced by 0).
  const std::string dir = temp_dir("db_migration_v9_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '9' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 9 -> 10", "duplicate column name: bodies"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version2StepKeepsAnExistingHumanBodiesKey) {
  // A hand-made version 2 file that already has the key: the step does not overwrite it.
  const std::string dir = temp_dir("db_migration_v2_bodies");
  const std::string path = write_v2(dir);
  execute_script(path, "INSERT INTO meta (key, value) VALUES ('human_bodies', '1.80 male')");
  migrate_in_place(path);
  EXPECT_EQ(open_migrated(path).meta().human_bodies, "1.80 male");
}

TEST(Migration, Version2FileThatAlreadyHasTheNewTablesFailsCleanly) {
  // Version 3 content with the version number set back: the 2 -> 3 step's CREATE TABLE fails and
  // the file is left as it was.
  const std::string dir = temp_dir("db_migration_v2_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '2' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 2 -> 3", "table handover_stages already exists"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, SyntheticStepThenTheRealOneUpgradeAVersion0Database) {
  const std::string dir = temp_dir("db_migration_v0");
  const std::string path = write_v0(dir);
  expect_input_error([&] { Database::open(path); }, {"written by schema version 0"});

  migrate_with_steps(path, steps_from_v0(), current_schema_version());

  // Made from the sample, which this hila wrote: it opens with the default options.
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  const Sample sample = make_sample();
  ASSERT_EQ(db.parts().size(), sample.parts.size());
  EXPECT_EQ(db.parts()[0].name, sample.parts[0].part.name);
  const auto grasps = db.robot_grasps(1);
  ASSERT_EQ(grasps.size(), sample.parts[0].robot_grasps.size());
  for (std::size_t i = 0; i < grasps.size(); ++i) {
    EXPECT_EQ(grasps[i].theta_c_deg, 90.0) << "the step's default";
    EXPECT_EQ(grasps[i].quality, sample.parts[0].robot_grasps[i].quality) << "data kept";
  }
  EXPECT_TRUE(db.comfort_maps().empty());
  expect_no_handover_records(db);
  expect_no_roadmap_records(db);
  expect_no_direct_grasps(db);
  expect_no_table_regrasps(db);
  expect_no_suction_deliveries(db);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"}) << "no temporary copy left";
}

TEST(Migration, StepsRunInVersionOrderWhateverTheListOrder) {
  const std::string dir = temp_dir("db_migration_order");
  const std::string path = write_v0(dir);
  // Step 10 -> 11 needs the table step 0 -> 1 creates, the ones steps 1 -> 2, 2 -> 3, 3 -> 4,
  // 4 -> 5, 5 -> 6 and 7 -> 8 create and the columns 8 -> 9 and 9 -> 10 add; listed first to prove
  // ordering.
  std::vector<MigrationStep> steps = {
      {10,
       "INSERT INTO notes (text) VALUES ('from step 10');"
       "INSERT INTO notes (text) SELECT duration FROM regrasp_edges;"
       "INSERT INTO notes (text) SELECT bodies FROM handover_candidates;"
       "INSERT INTO notes (text) SELECT arm FROM comfort_maps;"
       "INSERT INTO notes (text) SELECT arm FROM ergonomics;"
       "INSERT INTO notes (text) SELECT arm FROM roadmaps;"
       "INSERT INTO notes (text) SELECT arm FROM direct_grasps;"
       "INSERT INTO notes (text) SELECT arm FROM table_regrasps;"
       "INSERT INTO notes (text) SELECT arm FROM suction_deliveries;"}};
  steps.push_back(migration_steps().at(1));
  steps.push_back(migration_steps().at(8));
  steps.push_back(migration_steps().at(7));
  steps.push_back(migration_steps().at(6));
  steps.push_back(migration_steps().at(5));
  steps.push_back(migration_steps().at(4));
  steps.push_back(migration_steps().at(3));
  steps.push_back(migration_steps().at(2));
  steps.push_back(migration_steps().at(0));
  steps.push_back({0,
                   "CREATE TABLE notes (text TEXT NOT NULL);"
                   "ALTER TABLE robot_grasps ADD COLUMN theta_c_deg REAL NOT NULL DEFAULT 90.0;"});
  EXPECT_TRUE(can_migrate(steps, 0, 11));
  migrate_with_steps(path, steps, 11);
  // The file is now version 11: this hila (10) calls it newer.
  expect_input_error([&] { Database::open(path); }, {"written by schema version 11"});
  // Migrating to 11 again is a no-op (already there).
  const std::string after = read_file(path);
  migrate_with_steps(path, steps, 11);
  EXPECT_EQ(read_file(path), after);
}

TEST(Migration, FailingStepLeavesTheOriginalByteIdentical) {
  const std::string dir = temp_dir("db_migration_failure");
  const std::string path = write_v0(dir);
  const std::string before = read_file(path);
  const std::vector<MigrationStep> steps = {
      {0,
       "ALTER TABLE robot_grasps ADD COLUMN theta_c_deg REAL NOT NULL DEFAULT 90.0;"
       "ALTER TABLE no_such_table ADD COLUMN x;"}};
  expect_input_error([&] { migrate_with_steps(path, steps, 1); },
                     {path + ": migration 0 -> 1", "no such table: no_such_table"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, MissingStepIsRefusedWithoutTouchingTheFile) {
  const std::string dir = temp_dir("db_migration_missing");
  const std::string path = write_v0(dir);
  const std::string before = read_file(path);
  EXPECT_FALSE(can_migrate({}, 0, 1));
  EXPECT_FALSE(can_migrate(kSteps, 0, 2));
  EXPECT_FALSE(can_migrate({migration_steps().at(0)}, 1, 3)) << "1 -> 2 alone does not reach 3";
  EXPECT_FALSE(can_migrate({migration_steps().at(0), migration_steps().at(1)}, 1, 4))
      << "1 -> 2 -> 3 does not reach 4";
  EXPECT_FALSE(can_migrate(
      {migration_steps().at(0), migration_steps().at(1), migration_steps().at(2)}, 1, 5))
      << "1 -> 2 -> 3 -> 4 does not reach 5";
  EXPECT_FALSE(can_migrate({migration_steps().at(0), migration_steps().at(1),
                            migration_steps().at(2), migration_steps().at(3)},
                           1, 6))
      << "1 -> 2 -> 3 -> 4 -> 5 does not reach 6";
  EXPECT_FALSE(
      can_migrate({migration_steps().at(0), migration_steps().at(1), migration_steps().at(2),
                   migration_steps().at(3), migration_steps().at(4)},
                  1, 7))
      << "1 -> 2 -> 3 -> 4 -> 5 -> 6 does not reach 7";
  EXPECT_FALSE(
      can_migrate({migration_steps().at(0), migration_steps().at(1), migration_steps().at(2),
                   migration_steps().at(3), migration_steps().at(4), migration_steps().at(5)},
                  1, 8))
      << "1 -> 2 -> 3 -> 4 -> 5 -> 6 -> 7 does not reach 8";
  EXPECT_FALSE(
      can_migrate({migration_steps().at(0), migration_steps().at(1), migration_steps().at(2),
                   migration_steps().at(3), migration_steps().at(4), migration_steps().at(5),
                   migration_steps().at(6)},
                  1, 9))
      << "1 -> 2 -> ... -> 8 does not reach 9";
  EXPECT_FALSE(
      can_migrate({migration_steps().at(0), migration_steps().at(1), migration_steps().at(2),
                   migration_steps().at(3), migration_steps().at(4), migration_steps().at(5),
                   migration_steps().at(6), migration_steps().at(7)},
                  1, 10))
      << "1 -> 2 -> ... -> 9 does not reach 10";
  // The real steps start at version 1: there is nothing to migrate from 0.
  expect_input_error(
      [&] { migrate_in_place(path); },
      {path + ": meta.schema_version", "schema version 0, for which there is no migration",
       "rebuild with: hila build meshes/cabinet/product.yaml -o " + path});
  expect_input_error([&] { migrate_with_steps(path, kSteps, 2); }, {"no migration"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, Version1FileThatAlreadyHasTheTableFailsCleanly) {
  // A damaged "version 1" file (version 2 content, version number set back): the step's CREATE
  // TABLE fails and the file is left as it was.
  const std::string dir = temp_dir("db_migration_v1_clash");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '1' WHERE key = 'schema_version'");
  const std::string before = read_file(path);
  expect_input_error([&] { migrate_in_place(path); },
                     {path + ": migration 1 -> 2", "table comfort_maps already exists"});
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Migration, DuplicateStepsAreAmbiguous) {
  EXPECT_FALSE(can_migrate({{0, "SELECT 1;"}, {0, "SELECT 2;"}}, 0, 1));
  EXPECT_TRUE(can_migrate({{0, "SELECT 1;"}, {5, "ignored"}}, 0, 1));
}

TEST(Migration, CurrentDatabaseIsLeftAlone) {
  const std::string dir = temp_dir("db_migration_current");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  const std::string before = read_file(path);
  const auto mtime = fs::last_write_time(path);
  migrate_in_place(path);
  EXPECT_EQ(read_file(path), before);
  EXPECT_EQ(fs::last_write_time(path), mtime) << "not even rewritten";
}

TEST(Migration, NewerDatabaseIsRefused) {
  const std::string dir = temp_dir("db_migration_newer");
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path, "UPDATE meta SET value = '11' WHERE key = 'schema_version'");
  expect_input_error([&] { migrate_in_place(path); },
                     {path, "written by schema version 11 (a newer hila)", "upgrade hila"});
}

TEST(Migration, ForeignFilesAreRefused) {
  const std::string dir = temp_dir("db_migration_foreign");
  expect_input_error([&] { migrate_in_place(write_file(dir, "t.db", "hello")); },
                     {"t.db", "expected a hila database (SQLite)"});
  expect_input_error([&] { migrate_in_place(dir + "/missing.db"); }, {"no such file"});
  EXPECT_FALSE(fs::exists(dir + "/missing.db"));
}

TEST(Migration, ExecuteScriptIsAllOrNothing) {
  const std::string dir = temp_dir("db_migration_script");
  const std::string path = dir + "/s.db";
  execute_script(path, "CREATE TABLE t (x INTEGER NOT NULL);");
  expect_input_error(
      [&] { execute_script(path, "INSERT INTO t VALUES (1); INSERT INTO t VALUES (NULL);"); },
      {path + ": (script)", "NOT NULL constraint failed: t.x"});
  // The first insert must have been rolled back with the second: with a unique index, inserting
  // 1 again only succeeds if the table is still empty.
  execute_script(path, "CREATE UNIQUE INDEX t_x ON t(x); INSERT INTO t VALUES (1);");
}
