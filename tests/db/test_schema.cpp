#include <gtest/gtest.h>

#include <string>

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

}  // namespace

TEST(Schema, VersionIsOneAndHasNoMigrationsYet) {
  EXPECT_EQ(current_schema_version(), 1);
  EXPECT_TRUE(migration_steps().empty());
}

TEST(Schema, ColumnListHelpers) {
  EXPECT_EQ(pose_columns("tcp"), "tcp_x, tcp_y, tcp_z, tcp_qw, tcp_qx, tcp_qy, tcp_qz");
  EXPECT_EQ(vector_columns("contact_1"), "contact_1_x, contact_1_y, contact_1_z");
}

TEST(Schema, TablesInDigestOrderAllExistInTheSql) {
  ASSERT_EQ(kTables.size(), 6u);
  EXPECT_STREQ(kTables[0], "meta");
  EXPECT_STREQ(kTables[1], "parts");
  for (const char* table : kTables) {
    EXPECT_NE(schema_sql().find(std::string("CREATE TABLE ") + table + " ("), std::string::npos)
        << table;
  }
}

TEST(Schema, EveryPoseAndVectorColumnIsDeclared) {
  const std::string& sql = schema_sql();
  for (const std::string prefix : {"target", "initial", "part_in_plane", "tcp", "cup", "hand"}) {
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
  for (const std::string table : {"placements", "robot_grasps", "suction_grasps", "human_grasps"}) {
    expect_input_error(
        [&] {
          execute_script(path, "CREATE INDEX " + table + "_part_id ON " + table + "(part_id)");
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
