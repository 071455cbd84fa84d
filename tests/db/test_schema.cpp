#include <gtest/gtest.h>
#include <sqlite3.h>

#include <string>
#include <vector>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "schema.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::detail;
using namespace hila::test;

namespace {

// A fresh file with the current schema (and nothing else).
std::string schema_only_database(const std::string& name) {
  const std::string path = temp_dir(name) + "/schema.db";
  execute_script(path, schema_sql());
  return path;
}

// The CREATE statements in `sql` ("CREATE ... ;"), in order.
std::vector<std::string> create_statements(const std::string& sql) {
  std::vector<std::string> statements;
  for (std::size_t at = sql.find("CREATE "); at != std::string::npos;
       at = sql.find("CREATE ", at + 1)) {
    statements.push_back(sql.substr(at, sql.find(';', at) + 1 - at));
  }
  return statements;
}

}  // namespace

TEST(Schema, VersionIsTenWithStepsFromOneToNine) {
  EXPECT_EQ(current_schema_version(), 10);
  ASSERT_EQ(migration_steps().size(), 9u);
  EXPECT_EQ(migration_steps()[0].from_version, 1);
  EXPECT_EQ(migration_steps()[1].from_version, 2);
  EXPECT_EQ(migration_steps()[2].from_version, 3);
  EXPECT_EQ(migration_steps()[3].from_version, 4);
  EXPECT_EQ(migration_steps()[4].from_version, 5);
  EXPECT_EQ(migration_steps()[5].from_version, 6);
  EXPECT_EQ(migration_steps()[6].from_version, 7);
  EXPECT_EQ(migration_steps()[7].from_version, 8);
  EXPECT_EQ(migration_steps()[8].from_version, 9);
  EXPECT_TRUE(can_migrate(migration_steps(), 1, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 2, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 3, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 4, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 5, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 6, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 7, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 8, current_schema_version()));
  EXPECT_TRUE(can_migrate(migration_steps(), 9, current_schema_version()));
  EXPECT_FALSE(can_migrate(migration_steps(), 0, current_schema_version()));
  // The steps create the tables exactly as a fresh database has them.
  EXPECT_NE(migration_steps()[0].sql.find("CREATE TABLE comfort_maps ("), std::string::npos);
  EXPECT_NE(schema_sql().find(migration_steps()[0].sql), std::string::npos);
  const auto created = create_statements(migration_steps()[1].sql);
  ASSERT_EQ(created.size(), 8u) << "5 tables, 3 indexes";
  for (const std::string table : {"handover_stages", "robot_handovers", "handover_candidates",
                                  "shared_grasps", "ergonomics"}) {
    EXPECT_NE(migration_steps()[1].sql.find("CREATE TABLE " + table + " ("), std::string::npos)
        << table;
  }
  // 2 -> 3 as a fresh database has them, but for version 10's handover_candidates.bodies.
  std::string handover_candidates_v3;
  for (const auto& statement : created) {
    if (statement.rfind("CREATE TABLE handover_candidates (", 0) == 0) {
      handover_candidates_v3 = statement;
      EXPECT_EQ(statement.find("bodies"), std::string::npos) << statement;
      EXPECT_EQ(schema_sql().find(statement), std::string::npos) << "version 10 changed the table";
      continue;
    }
    EXPECT_NE(schema_sql().find(statement), std::string::npos) << statement;
  }
  {
    // Version 10's table is version 3's with the column after second_joints, before the CHECK.
    std::string with_bodies = handover_candidates_v3;
    const std::string last_column = "  second_joints BLOB NOT NULL,\n";
    ASSERT_NE(with_bodies.find(last_column), std::string::npos);
    with_bodies.insert(with_bodies.find(last_column) + last_column.size(),
                       "  bodies INTEGER NOT NULL CHECK (bodies >= 0 AND bodies < 4294967296),\n");
    EXPECT_NE(schema_sql().find(with_bodies), std::string::npos) << with_bodies;
  }
  EXPECT_NE(migration_steps()[1].sql.find(
                "INSERT OR IGNORE INTO meta (key, value) VALUES ('human_bodies', '');"),
            std::string::npos);
  // 3 -> 4: the roadmap and regrasp-graph tables, as a fresh database has them (but for version
  // 9's regrasp_edges.duration), and nothing else.
  const auto created_v4 = create_statements(migration_steps()[2].sql);
  ASSERT_EQ(created_v4.size(), 6u) << "4 tables, 2 indexes";
  for (const std::string table :
       {"roadmaps", "roadmap_filters", "regrasp_nodes", "regrasp_edges"}) {
    EXPECT_NE(migration_steps()[2].sql.find("CREATE TABLE " + table + " ("), std::string::npos)
        << table;
  }
  std::string regrasp_edges_v4;
  for (const auto& statement : created_v4) {
    if (statement.rfind("CREATE TABLE regrasp_edges (", 0) == 0) {
      regrasp_edges_v4 = statement;
      EXPECT_EQ(statement.find("duration"), std::string::npos) << statement;
      EXPECT_EQ(schema_sql().find(statement), std::string::npos) << "version 9 changed the table";
      continue;
    }
    EXPECT_NE(schema_sql().find(statement), std::string::npos) << statement;
  }
  {
    // Version 9's table is version 4's with the column after path and its CHECK last.
    std::string with_duration = regrasp_edges_v4;
    const std::string path = "  path BLOB NOT NULL,\n";
    const std::string last = "  CHECK ((via = '') = (path_waypoints = 0))\n";
    ASSERT_NE(with_duration.find(path), std::string::npos);
    with_duration.insert(with_duration.find(path) + path.size(),
                         "  duration REAL NOT NULL CHECK (duration >= 0),\n");
    ASSERT_NE(with_duration.find(last), std::string::npos);
    with_duration.replace(with_duration.find(last), last.size(),
                          "  CHECK ((via = '') = (path_waypoints = 0)),\n"
                          "  CHECK (path_waypoints <> 0 OR duration = 0)\n");
    EXPECT_NE(schema_sql().find(with_duration), std::string::npos) << with_duration;
  }
  EXPECT_EQ(migration_steps()[2].sql.find("INSERT"), std::string::npos);
  // 4 -> 5: the direct_grasps table and its index, as a fresh database has them, and nothing else.
  const auto created_v5 = create_statements(migration_steps()[3].sql);
  ASSERT_EQ(created_v5.size(), 2u) << "1 table, 1 index";
  EXPECT_EQ(created_v5[0].rfind("CREATE TABLE direct_grasps (", 0), 0u) << created_v5[0];
  EXPECT_EQ(created_v5[1],
            "CREATE INDEX direct_grasps_candidate_id ON direct_grasps(candidate_id);");
  for (const auto& statement : created_v5) {
    EXPECT_NE(schema_sql().find(statement), std::string::npos) << statement;
  }
  EXPECT_EQ(migration_steps()[3].sql.find("INSERT"), std::string::npos);
  // 5 -> 6: the table_regrasps table and its index as version 6 declared them (the table a fresh
  // database has but for version 8's repick_arm), and nothing else.
  const auto created_v6 = create_statements(migration_steps()[4].sql);
  ASSERT_EQ(created_v6.size(), 2u) << "1 table, 1 index";
  EXPECT_EQ(created_v6[0].rfind("CREATE TABLE table_regrasps (", 0), 0u) << created_v6[0];
  EXPECT_EQ(created_v6[0].find("repick_arm"), std::string::npos) << created_v6[0];
  EXPECT_EQ(schema_sql().find(created_v6[0]), std::string::npos) << "version 8 changed the table";
  {
    std::string with_repick_arm = created_v6[0];
    const std::string arm = "  arm TEXT NOT NULL,\n";
    ASSERT_NE(with_repick_arm.find(arm), std::string::npos);
    with_repick_arm.insert(with_repick_arm.find(arm) + arm.size(), "  repick_arm TEXT NOT NULL,\n");
    EXPECT_NE(schema_sql().find(with_repick_arm), std::string::npos) << with_repick_arm;
  }
  EXPECT_EQ(created_v6[1],
            "CREATE INDEX table_regrasps_candidate_id ON table_regrasps(candidate_id);");
  EXPECT_NE(schema_sql().find(created_v6[1]), std::string::npos);
  EXPECT_EQ(migration_steps()[4].sql.find("INSERT"), std::string::npos);
  // 6 -> 7: no table changes; the migration writes the per-table digests after its last step, the
  // step only drops digests a file may already have.
  EXPECT_TRUE(create_statements(migration_steps()[5].sql).empty());
  EXPECT_EQ(migration_steps()[5].sql, "DELETE FROM meta WHERE key GLOB 'digest.*';\n");
  EXPECT_EQ(kTableDigestsSince, 7);
  // 7 -> 8: the suction_deliveries table and its index, and table_regrasps rebuilt with repick_arm
  // (and its index again), as a fresh database has them, and nothing else.
  const std::string& step_v8 = migration_steps()[6].sql;
  const auto created_v8 = create_statements(step_v8);
  ASSERT_EQ(created_v8.size(), 4u) << "2 tables, 2 indexes";
  EXPECT_EQ(created_v8[0].rfind("CREATE TABLE suction_deliveries (", 0), 0u) << created_v8[0];
  EXPECT_EQ(created_v8[1],
            "CREATE INDEX suction_deliveries_candidate_id ON suction_deliveries(candidate_id);");
  EXPECT_EQ(created_v8[2].rfind("CREATE TABLE table_regrasps (", 0), 0u) << created_v8[2];
  EXPECT_NE(created_v8[2].find("  repick_arm TEXT NOT NULL,\n"), std::string::npos);
  EXPECT_EQ(created_v8[3],
            "CREATE INDEX table_regrasps_candidate_id ON table_regrasps(candidate_id);");
  for (const auto& statement : created_v8) {
    EXPECT_NE(schema_sql().find(statement), std::string::npos) << statement;
  }
  // The old table's rows go over with repick_arm = arm, then the old table goes.
  const std::size_t moved = step_v8.find("ALTER TABLE table_regrasps RENAME TO table_regrasps_v7;");
  const std::size_t copied = step_v8.find("INSERT INTO table_regrasps (");
  const std::size_t dropped = step_v8.find("DROP TABLE table_regrasps_v7;");
  ASSERT_NE(moved, std::string::npos) << step_v8;
  ASSERT_NE(copied, std::string::npos) << step_v8;
  ASSERT_NE(dropped, std::string::npos) << step_v8;
  EXPECT_LT(step_v8.find("DROP INDEX table_regrasps_candidate_id;"), moved);
  EXPECT_LT(moved, step_v8.find("CREATE TABLE table_regrasps ("));
  EXPECT_LT(step_v8.find("CREATE TABLE table_regrasps ("), copied);
  EXPECT_LT(copied, dropped);
  EXPECT_NE(step_v8.find("robot_grasp_id, arm, repick_arm, placement_x,", copied),
            std::string::npos);
  EXPECT_NE(step_v8.find("SELECT id, candidate_id, pick_grasp_id, robot_grasp_id, arm, arm, "
                         "placement_x,",
                         copied),
            std::string::npos)
      << step_v8;
  EXPECT_EQ(step_v8.find("INSERT", copied + 1), std::string::npos) << "one INSERT";
  EXPECT_EQ(step_v8.find("INSERT"), copied);
  EXPECT_EQ(migration_steps()[6].sql.find("digest"), std::string::npos)
      << "the migration, not the step, writes the digests";
  // 8 -> 9: regrasp_edges rebuilt with duration (and its index again), as a fresh database has
  // them, and nothing else: the column added (failing on a table that has it), the old table out
  // of the way, the new one created, the rows copied, the old table dropped.
  const std::string& step_v9 = migration_steps()[7].sql;
  const auto created_v9 = create_statements(step_v9);
  ASSERT_EQ(created_v9.size(), 2u) << "1 table, 1 index";
  EXPECT_EQ(created_v9[0].rfind("CREATE TABLE regrasp_edges (", 0), 0u) << created_v9[0];
  EXPECT_NE(created_v9[0].find("  duration REAL NOT NULL CHECK (duration >= 0),\n"),
            std::string::npos);
  EXPECT_EQ(created_v9[1], "CREATE INDEX regrasp_edges_part_id ON regrasp_edges(part_id);");
  for (const auto& statement : created_v9) {
    EXPECT_NE(schema_sql().find(statement), std::string::npos) << statement;
  }
  const std::size_t added =
      step_v9.find("ALTER TABLE regrasp_edges ADD COLUMN duration REAL NOT NULL DEFAULT 0.0;");
  const std::size_t moved_v9 =
      step_v9.find("ALTER TABLE regrasp_edges RENAME TO regrasp_edges_v8;");
  const std::size_t copied_v9 = step_v9.find("INSERT INTO regrasp_edges (");
  const std::size_t dropped_v9 = step_v9.find("DROP TABLE regrasp_edges_v8;");
  ASSERT_NE(added, std::string::npos) << step_v9;
  ASSERT_NE(moved_v9, std::string::npos) << step_v9;
  ASSERT_NE(copied_v9, std::string::npos) << step_v9;
  ASSERT_NE(dropped_v9, std::string::npos) << step_v9;
  EXPECT_EQ(added, 0u) << "first, so that a table with the column fails before anything moves";
  EXPECT_LT(added, step_v9.find("DROP INDEX regrasp_edges_part_id;"));
  EXPECT_LT(step_v9.find("DROP INDEX regrasp_edges_part_id;"), moved_v9);
  EXPECT_LT(moved_v9, step_v9.find("CREATE TABLE regrasp_edges ("));
  EXPECT_LT(step_v9.find("CREATE TABLE regrasp_edges ("), copied_v9);
  EXPECT_LT(copied_v9, dropped_v9);
  EXPECT_NE(step_v9.find("INSERT INTO regrasp_edges (id, part_id, kind, arm, from_node, to_node, "
                         "filter_id, connected, cost, path_nodes, via, path_dof, path_waypoints, "
                         "path, duration)\n  SELECT id, part_id, kind, arm, from_node, to_node, "
                         "filter_id, connected, cost, path_nodes, via, path_dof, path_waypoints, "
                         "path, duration FROM regrasp_edges_v8 ORDER BY id;"),
            std::string::npos)
      << step_v9;
  EXPECT_EQ(step_v9.find("INSERT", copied_v9 + 1), std::string::npos) << "one INSERT";
  EXPECT_EQ(step_v9.find("INSERT"), copied_v9);
  EXPECT_EQ(step_v9.find("digest"), std::string::npos)
      << "the migration, not the step, writes the digests";
  // 9 -> 10: handover_candidates rebuilt with bodies (and its index again), as a fresh database
  // has them, and nothing else: the column added (failing on a table that has it), the old table
  // out of the way without touching the references to it, the new one created, the rows copied,
  // the old table dropped.
  const std::string& step_v10 = migration_steps()[8].sql;
  const auto created_v10 = create_statements(step_v10);
  ASSERT_EQ(created_v10.size(), 2u) << "1 table, 1 index";
  EXPECT_EQ(created_v10[0].rfind("CREATE TABLE handover_candidates (", 0), 0u) << created_v10[0];
  EXPECT_NE(created_v10[0].find(
                "  bodies INTEGER NOT NULL CHECK (bodies >= 0 AND bodies < 4294967296),\n"),
            std::string::npos);
  EXPECT_EQ(created_v10[1],
            "CREATE INDEX handover_candidates_part_id ON handover_candidates(part_id);");
  for (const auto& statement : created_v10) {
    EXPECT_NE(schema_sql().find(statement), std::string::npos) << statement;
  }
  const std::size_t added_v10 = step_v10.find(
      "ALTER TABLE handover_candidates ADD COLUMN bodies INTEGER NOT NULL DEFAULT 0;");
  const std::size_t legacy_on = step_v10.find("PRAGMA legacy_alter_table = ON;");
  const std::size_t moved_v10 =
      step_v10.find("ALTER TABLE handover_candidates RENAME TO handover_candidates_v9;");
  const std::size_t legacy_off = step_v10.find("PRAGMA legacy_alter_table = OFF;");
  const std::size_t copied_v10 = step_v10.find("INSERT INTO handover_candidates (");
  const std::size_t dropped_v10 = step_v10.find("DROP TABLE handover_candidates_v9;");
  ASSERT_NE(added_v10, std::string::npos) << step_v10;
  ASSERT_NE(legacy_on, std::string::npos) << step_v10;
  ASSERT_NE(moved_v10, std::string::npos) << step_v10;
  ASSERT_NE(legacy_off, std::string::npos) << step_v10;
  ASSERT_NE(copied_v10, std::string::npos) << step_v10;
  ASSERT_NE(dropped_v10, std::string::npos) << step_v10;
  EXPECT_EQ(added_v10, 0u) << "first, so that a table with the column fails before anything moves";
  EXPECT_LT(added_v10, step_v10.find("DROP INDEX handover_candidates_part_id;"));
  EXPECT_LT(step_v10.find("DROP INDEX handover_candidates_part_id;"), legacy_on);
  EXPECT_LT(legacy_on, moved_v10);
  EXPECT_LT(moved_v10, legacy_off);
  EXPECT_LT(legacy_off, step_v10.find("CREATE TABLE handover_candidates ("));
  EXPECT_LT(step_v10.find("CREATE TABLE handover_candidates ("), copied_v10);
  EXPECT_LT(copied_v10, dropped_v10);
  const std::string columns =
      "id, part_id, sample, board_x, board_y, board_z, board_qw, board_qx, board_qy, board_qz, "
      "distance, quality, status, rank, human_arm, human_grasp_id, human_quality, second_arm, "
      "second_grasp_id, second_quality, human_joints, second_joints, bodies";
  EXPECT_NE(step_v10.find("INSERT INTO handover_candidates (" + columns + ")\n  SELECT " + columns +
                          " FROM handover_candidates_v9 ORDER BY id;"),
            std::string::npos)
      << step_v10;
  EXPECT_EQ(step_v10.find("INSERT", copied_v10 + 1), std::string::npos) << "one INSERT";
  EXPECT_EQ(step_v10.find("INSERT"), copied_v10);
  EXPECT_EQ(step_v10.find("digest"), std::string::npos)
      << "the migration, not the step, writes the digests";
}

// The column specs the checks at open compare values with come from schema_sql() itself.
TEST(Schema, ColumnSpecsFollowTheSql) {
  for (const auto& table : kTables) {
    EXPECT_FALSE(schema_columns(table.name).empty()) << table.name;
    if (std::string(table.name) != "meta") {
      EXPECT_EQ(schema_columns(table.name).front().name, "id") << table.name;
      EXPECT_FALSE(schema_columns(table.name).front().nullable) << table.name;
    }
  }
  EXPECT_TRUE(schema_columns("no_such_table").empty());
  const auto& meta = schema_columns("meta");
  ASSERT_EQ(meta.size(), 2u);
  EXPECT_EQ(meta[1].name, "value");
  EXPECT_EQ(meta[1].storage_class, SQLITE_TEXT);
  EXPECT_FALSE(meta[1].nullable);
  const auto find = [](const std::string& table, const std::string& column) {
    for (const auto& c : schema_columns(table)) {
      if (c.name == column) return c;
    }
    return ColumnSpec{};
  };
  EXPECT_EQ(find("parts", "mass").storage_class, SQLITE_FLOAT);
  EXPECT_EQ(find("parts", "name").storage_class, SQLITE_TEXT);
  EXPECT_EQ(find("parts", "triangle_count").storage_class, SQLITE_INTEGER);
  EXPECT_EQ(find("roadmaps", "edge_nodes").storage_class, SQLITE_BLOB);
  EXPECT_EQ(schema_columns("robot_grasps").size(), 26u);
  // Only the optional references of version 4 may be NULL.
  std::vector<std::string> nullable;
  for (const auto& table : kTables) {
    for (const auto& c : schema_columns(table.name)) {
      if (c.nullable) nullable.push_back(std::string(table.name) + "." + c.name);
    }
  }
  EXPECT_EQ(nullable,
            (std::vector<std::string>{"regrasp_nodes.robot_handover_id",
                                      "regrasp_nodes.candidate_id", "regrasp_edges.filter_id"}));
  EXPECT_EQ(digest_key("robot_grasps"), "digest.robot_grasps");
}

TEST(Schema, ColumnListHelpers) {
  EXPECT_EQ(pose_columns("tcp"), "tcp_x, tcp_y, tcp_z, tcp_qw, tcp_qx, tcp_qy, tcp_qz");
  EXPECT_EQ(vector_columns("contact_1"), "contact_1_x, contact_1_y, contact_1_z");
}

TEST(Schema, TablesInDigestOrderAllExistInTheSql) {
  ASSERT_EQ(kTables.size(), 19u);
  EXPECT_STREQ(kTables[0].name, "meta");
  EXPECT_STREQ(kTables[1].name, "parts");
  EXPECT_STREQ(kTables[6].name, "comfort_maps");
  EXPECT_EQ(kTables[6].since_version, 2);
  EXPECT_STREQ(kTables[7].name, "handover_stages");
  EXPECT_STREQ(kTables[8].name, "robot_handovers");
  EXPECT_STREQ(kTables[9].name, "handover_candidates");
  EXPECT_STREQ(kTables[10].name, "shared_grasps");
  EXPECT_STREQ(kTables[11].name, "ergonomics");
  for (std::size_t i = 7; i < 12; ++i) EXPECT_EQ(kTables[i].since_version, 3);
  EXPECT_STREQ(kTables[12].name, "roadmaps");
  EXPECT_STREQ(kTables[13].name, "roadmap_filters");
  EXPECT_STREQ(kTables[14].name, "regrasp_nodes");
  EXPECT_STREQ(kTables[15].name, "regrasp_edges");
  for (std::size_t i = 12; i < 16; ++i) EXPECT_EQ(kTables[i].since_version, 4);
  // Appended last, so the digest of an older file hashes its tables as it always did.
  EXPECT_STREQ(kTables[16].name, "direct_grasps");
  EXPECT_EQ(kTables[16].since_version, 5);
  EXPECT_STREQ(kTables[17].name, "table_regrasps");
  EXPECT_EQ(kTables[17].since_version, 6);
  EXPECT_STREQ(kTables[18].name, "suction_deliveries");
  EXPECT_EQ(kTables[18].since_version, 8) << "version 7 added no table";
  for (const auto& table : kTables) {
    EXPECT_NE(schema_sql().find(std::string("CREATE TABLE ") + table.name + " ("),
              std::string::npos)
        << table.name;
    EXPECT_GE(table.since_version, 1);
    EXPECT_LE(table.since_version, current_schema_version());
  }
  // And the SQL has no table the digest would miss.
  std::size_t tables = 0;
  for (const auto& statement : create_statements(schema_sql())) {
    tables += statement.rfind("CREATE TABLE ", 0) == 0 ? 1 : 0;
  }
  EXPECT_EQ(tables, kTables.size());
}

TEST(Schema, HandoverAndErgonomicsColumnsAreDeclared) {
  const std::string& sql = schema_sql();
  for (const std::string column : {
           "part_id INTEGER NOT NULL UNIQUE REFERENCES parts(id)",
           "finished_parts TEXT NOT NULL",
           "draws INTEGER NOT NULL",
           "comfortable_default_body INTEGER NOT NULL",
           "two_hands INTEGER NOT NULL CHECK (two_hands IN (0, 1))",
           "failure TEXT NOT NULL",
           "suction_grasp_id INTEGER NOT NULL REFERENCES suction_grasps(id)",
           "joints BLOB NOT NULL",
           "sample INTEGER NOT NULL",
           "distance REAL NOT NULL",
           "status TEXT NOT NULL CHECK (status IN ('uncomfortable', 'no_shared_grasp', 'goal'))",
           "rank INTEGER NOT NULL",
           "human_arm TEXT NOT NULL",
           "human_grasp_id INTEGER NOT NULL",
           "second_quality REAL NOT NULL",
           "human_joints BLOB NOT NULL",
           "second_joints BLOB NOT NULL",
           "bodies INTEGER NOT NULL CHECK (bodies >= 0 AND bodies < 4294967296)",
           "candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id)",
           "robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id)",
           "robot_handover_id INTEGER NOT NULL REFERENCES robot_handovers(id)",
           "joints_rr BLOB NOT NULL",
           "joints_rh BLOB NOT NULL",
           "inclination_rr_deg REAL NOT NULL",
           "method TEXT NOT NULL CHECK (method IN ('hila', 'table', 'alone'))",
           "reachable INTEGER NOT NULL CHECK (reachable IN (0, 1))",
           "shoulder_elevated INTEGER NOT NULL CHECK (shoulder_elevated IN (0, 1))",
           "reorientation_deg REAL NOT NULL",
           "UNIQUE (part_id, method)",
       }) {
    EXPECT_NE(sql.find(column), std::string::npos) << column;
  }
  // The column specs the checks at open use: bodies last, an INTEGER, after second_joints, as the
  // writer and reader name them.
  const auto& columns = schema_columns("handover_candidates");
  ASSERT_EQ(columns.size(), 23u);
  EXPECT_EQ(columns[21].name, "second_joints");
  EXPECT_EQ(columns[22].name, "bodies");
  EXPECT_EQ(columns[22].storage_class, SQLITE_INTEGER);
  EXPECT_FALSE(columns[22].nullable);
}

TEST(Schema, RoadmapAndRegraspColumnsAreDeclared) {
  const std::string& sql = schema_sql();
  for (const std::string column : {
           "arm TEXT UNIQUE NOT NULL",
           "dof INTEGER NOT NULL",
           "resolution REAL NOT NULL",
           "node_count INTEGER NOT NULL",
           "edge_count INTEGER NOT NULL",
           "node_joints BLOB NOT NULL",
           "node_gravity BLOB NOT NULL",
           "node_inclination_deg BLOB NOT NULL",
           "edge_nodes BLOB NOT NULL",
           "edge_length BLOB NOT NULL",
           "edge_max_inclination_deg BLOB NOT NULL",
           "roadmap_id INTEGER NOT NULL REFERENCES roadmaps(id)",
           "grasp_kind TEXT NOT NULL CHECK (grasp_kind IN ('gripper', 'suction'))",
           "grasp_id INTEGER NOT NULL",
           "theta_c_deg REAL NOT NULL",
           "valid_edges INTEGER NOT NULL",
           "components INTEGER NOT NULL",
           "largest_component INTEGER NOT NULL",
           "edge_bits BLOB NOT NULL",
           "node_component BLOB NOT NULL",
           "UNIQUE (part_id, roadmap_id, grasp_kind, grasp_id)",
           "kind TEXT NOT NULL CHECK (kind IN ('home', 'pick', 'robot_handover', "
           "'human_handover'))",
           "grasp_kind TEXT NOT NULL CHECK (grasp_kind IN ('', 'gripper', 'suction'))",
           "robot_handover_id INTEGER REFERENCES robot_handovers(id),",
           "candidate_id INTEGER REFERENCES handover_candidates(id),",
           "solution_count INTEGER NOT NULL",
           "solutions BLOB NOT NULL",
           "CHECK ((kind = 'home') = (grasp_kind = ''))",
           "CHECK ((grasp_kind = '') = (grasp_id = 0))",
           "CHECK ((kind = 'robot_handover') = (robot_handover_id IS NOT NULL))",
           "CHECK ((kind = 'human_handover') = (candidate_id IS NOT NULL))",
           "kind TEXT NOT NULL CHECK (kind IN ('transit', 'transfer', 'handover'))",
           "from_node INTEGER NOT NULL REFERENCES regrasp_nodes(id)",
           "to_node INTEGER NOT NULL REFERENCES regrasp_nodes(id)",
           "filter_id INTEGER REFERENCES roadmap_filters(id),",
           "connected INTEGER NOT NULL CHECK (connected IN (0, 1))",
           "cost REAL NOT NULL",
           "path_nodes INTEGER NOT NULL",
           "CHECK ((kind = 'transfer') = (filter_id IS NOT NULL))",
           "CHECK (connected = 1 OR (cost = 0 AND path_nodes = 0))",
           "via TEXT NOT NULL CHECK (via IN ('', 'roadmap', 'bridge'))",
           "path_dof INTEGER NOT NULL",
           "path_waypoints INTEGER NOT NULL",
           "path BLOB NOT NULL",
           "CHECK ((connected = 1 AND kind IN ('transit', 'transfer')) = (via <> ''))",
           "CHECK ((via = '') = (path_waypoints = 0))",
           "duration REAL NOT NULL CHECK (duration >= 0)",
           "CHECK (path_waypoints <> 0 OR duration = 0)",
       }) {
    EXPECT_NE(sql.find(column), std::string::npos) << column;
  }
  // The column specs the checks at open use: duration last, a REAL, after path, as the writer
  // and reader name them.
  const auto& columns = schema_columns("regrasp_edges");
  ASSERT_EQ(columns.size(), 15u);
  EXPECT_EQ(columns[13].name, "path");
  EXPECT_EQ(columns[13].storage_class, SQLITE_BLOB);
  EXPECT_EQ(columns[14].name, "duration");
  EXPECT_EQ(columns[14].storage_class, SQLITE_FLOAT);
  EXPECT_FALSE(columns[14].nullable);
}

TEST(Schema, DirectGraspColumnsAreDeclared) {
  // The table's own text, so a column of another table cannot stand in for one of these.
  const std::string& sql = schema_sql();
  const std::size_t start = sql.find("CREATE TABLE direct_grasps (");
  ASSERT_NE(start, std::string::npos);
  const std::string table = sql.substr(start, sql.find(");", start) + 2 - start);
  EXPECT_EQ(table,
            "CREATE TABLE direct_grasps (\n"
            "  id INTEGER PRIMARY KEY,\n"
            "  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),\n"
            "  robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),\n"
            "  arm TEXT NOT NULL,\n"
            "  joints_pick BLOB NOT NULL,\n"
            "  joints_rh BLOB NOT NULL,\n"
            "  inclination_pick_deg REAL NOT NULL,\n"
            "  inclination_rh_deg REAL NOT NULL\n"
            ");");
}

TEST(Schema, TableRegraspColumnsAreDeclared) {
  // The table's own text, so a column of another table cannot stand in for one of these.
  const std::string& sql = schema_sql();
  const std::size_t start = sql.find("CREATE TABLE table_regrasps (");
  ASSERT_NE(start, std::string::npos);
  const std::string table = sql.substr(start, sql.find(");", start) + 2 - start);
  EXPECT_EQ(table,
            "CREATE TABLE table_regrasps (\n"
            "  id INTEGER PRIMARY KEY,\n"
            "  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),\n"
            "  pick_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),\n"
            "  robot_grasp_id INTEGER NOT NULL REFERENCES robot_grasps(id),\n"
            "  arm TEXT NOT NULL,\n"
            "  repick_arm TEXT NOT NULL,\n"
            "  placement_x REAL NOT NULL, placement_y REAL NOT NULL, placement_z REAL NOT NULL,\n"
            "  placement_qw REAL NOT NULL, placement_qx REAL NOT NULL, placement_qy REAL NOT "
            "NULL,\n"
            "  placement_qz REAL NOT NULL,\n"
            "  joints_pick BLOB NOT NULL,\n"
            "  joints_place BLOB NOT NULL,\n"
            "  joints_repick BLOB NOT NULL,\n"
            "  joints_rh BLOB NOT NULL,\n"
            "  inclination_pick_deg REAL NOT NULL,\n"
            "  inclination_place_deg REAL NOT NULL,\n"
            "  inclination_repick_deg REAL NOT NULL,\n"
            "  inclination_rh_deg REAL NOT NULL\n"
            ");");
  // And the column specs the checks at open use say the same: repick_arm right after arm, as the
  // writer and reader name them.
  const auto& columns = schema_columns("table_regrasps");
  ASSERT_EQ(columns.size(), 21u);
  EXPECT_EQ(columns[4].name, "arm");
  EXPECT_EQ(columns[4].storage_class, SQLITE_TEXT);
  EXPECT_EQ(columns[5].name, "repick_arm");
  EXPECT_EQ(columns[5].storage_class, SQLITE_TEXT);
  EXPECT_FALSE(columns[5].nullable);
  EXPECT_EQ(columns[6].name, "placement_x");
  EXPECT_EQ(columns[20].name, "inclination_rh_deg");
}

TEST(Schema, SuctionDeliveryColumnsAreDeclared) {
  // The table's own text, so a column of another table cannot stand in for one of these.
  const std::string& sql = schema_sql();
  const std::size_t start = sql.find("CREATE TABLE suction_deliveries (");
  ASSERT_NE(start, std::string::npos);
  const std::string table = sql.substr(start, sql.find(");", start) + 2 - start);
  EXPECT_EQ(table,
            "CREATE TABLE suction_deliveries (\n"
            "  id INTEGER PRIMARY KEY,\n"
            "  candidate_id INTEGER NOT NULL REFERENCES handover_candidates(id),\n"
            "  suction_grasp_id INTEGER NOT NULL REFERENCES suction_grasps(id),\n"
            "  arm TEXT NOT NULL,\n"
            "  joints_rh BLOB NOT NULL\n"
            ");");
  // And the column specs the checks at open use say the same.
  const auto& columns = schema_columns("suction_deliveries");
  ASSERT_EQ(columns.size(), 5u);
  EXPECT_EQ(columns[1].name, "candidate_id");
  EXPECT_EQ(columns[1].storage_class, SQLITE_INTEGER);
  EXPECT_EQ(columns[2].name, "suction_grasp_id");
  EXPECT_EQ(columns[2].storage_class, SQLITE_INTEGER);
  EXPECT_EQ(columns[3].name, "arm");
  EXPECT_EQ(columns[3].storage_class, SQLITE_TEXT);
  EXPECT_EQ(columns[4].name, "joints_rh");
  EXPECT_EQ(columns[4].storage_class, SQLITE_BLOB);
  for (const auto& c : columns) EXPECT_FALSE(c.nullable) << c.name;
}

TEST(Schema, ComfortMapColumnsAreDeclaredNotNull) {
  const std::string& sql = schema_sql();
  for (const std::string column :
       {"arm TEXT UNIQUE NOT NULL", "origin_x REAL NOT NULL", "origin_y REAL NOT NULL",
        "origin_z REAL NOT NULL", "spacing REAL NOT NULL", "dim_x INTEGER NOT NULL",
        "dim_y INTEGER NOT NULL", "dim_z INTEGER NOT NULL", "orientation_count INTEGER NOT NULL",
        "orientations BLOB NOT NULL", "value_bytes INTEGER NOT NULL",
        "values_deflate BLOB NOT NULL", "samples INTEGER NOT NULL", "seed INTEGER NOT NULL",
        "coverage REAL NOT NULL"}) {
    EXPECT_NE(sql.find(column), std::string::npos) << column;
  }
}

TEST(Schema, EveryPoseAndVectorColumnIsDeclared) {
  const std::string& sql = schema_sql();
  for (const std::string prefix :
       {"target", "initial", "part_in_plane", "tcp", "cup", "hand", "board", "placement"}) {
    for (const std::string suffix : {"_x ", "_y ", "_z ", "_qw ", "_qx ", "_qy ", "_qz "}) {
      EXPECT_NE(sql.find(prefix + suffix + "REAL NOT NULL"), std::string::npos) << prefix << suffix;
    }
  }
  for (const std::string prefix :
       {"com", "extent", "contact_1", "normal_1", "contact_2", "normal_2"}) {
    for (const std::string suffix : {"_x ", "_y ", "_z "}) {
      EXPECT_NE(sql.find(prefix + suffix + "REAL NOT NULL"), std::string::npos) << prefix << suffix;
    }
  }
}

TEST(Schema, SqlRunsOnAnEmptyFileAndCreatesThePartIdIndexes) {
  const std::string path = schema_only_database("db_schema_indexes");
  // Creating an index that already exists fails: that is how the test sees the index without SQL
  // access of its own.
  for (const std::string table :
       {"placements", "robot_grasps", "suction_grasps", "human_grasps", "robot_handovers",
        "handover_candidates", "regrasp_nodes", "regrasp_edges"}) {
    expect_input_error(
        [&] {
          execute_script(path, "CREATE INDEX " + table + "_part_id ON " + table + "(part_id)");
        },
        {path, "already exists"});
  }
  for (const std::string table :
       {"shared_grasps", "direct_grasps", "table_regrasps", "suction_deliveries"}) {
    expect_input_error(
        [&] {
          execute_script(path,
                         "CREATE INDEX " + table + "_candidate_id ON " + table + "(candidate_id)");
        },
        {path, "already exists"});
  }
}

TEST(Schema, ConstraintsRejectBadRows) {
  const std::string path = schema_only_database("db_schema_constraints");
  // part_id must reference a part (execute_script turns foreign keys on, as the writer does).
  expect_input_error(
      [&] {
        execute_script(path,
                       "INSERT INTO placements (part_id, part_in_plane_x, "
                       "part_in_plane_y, part_in_plane_z, part_in_plane_qw, part_in_plane_qx, "
                       "part_in_plane_qy, part_in_plane_qz, stability) "
                       "VALUES (99, 0, 0, 0, 1, 0, 0, 0, 0)");
      },
      {"FOREIGN KEY constraint failed"});
  // Missing values are refused rather than stored as NULL.
  expect_input_error([&] { execute_script(path, "INSERT INTO meta (key) VALUES ('k')"); },
                     {"NOT NULL constraint failed: meta.value"});
  // one_hand_stable is a boolean.
  execute_script(path,
                 "INSERT INTO parts VALUES (1, 'p', 0, 'm', 'h', 1, 1, 0,0,0, 0,0,0,0,0,0, "
                 "0,0,0, 0, 0,0,0,1,0,0,0, 0,0,0,1,0,0,0)");
  expect_input_error(
      [&] {
        execute_script(path,
                       "INSERT INTO human_grasps VALUES (1, 1, 0,0,0,1,0,0,0, 0.1, 0,0,0, 0,0,0, "
                       "0.5, 2)");
      },
      {"CHECK constraint failed"});
  // Arm names are unique.
  const std::string insert_map =
      "INSERT INTO comfort_maps (arm, origin_x, origin_y, origin_z, spacing, dim_x, dim_y, dim_z, "
      "orientation_count, orientations, value_bytes, values_deflate, samples, seed, coverage) "
      "VALUES ('left', 0, 0, 0, 0.03, 1, 1, 1, 0, x'', 0, x'00', 0, 0, 0)";
  execute_script(path, insert_map);
  expect_input_error([&] { execute_script(path, insert_map); },
                     {"UNIQUE constraint failed: comfort_maps.arm"});
  // Part names are unique.
  expect_input_error(
      [&] {
        execute_script(path,
                       "INSERT INTO parts VALUES (2, 'p', 0, 'm', 'h', 1, 1, 0,0,0, 0,0,0,0,0,0, "
                       "0,0,0, 0, 0,0,0,1,0,0,0, 0,0,0,1,0,0,0)");
      },
      {"UNIQUE constraint failed: parts.name"});
}

TEST(Schema, RunningTheSchemaTwiceFails) {
  const std::string path = schema_only_database("db_schema_twice");
  expect_input_error([&] { execute_script(path, schema_sql()); }, {path, "already exists"});
}
