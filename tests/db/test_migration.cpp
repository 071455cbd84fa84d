#include <gtest/gtest.h>

#include <filesystem>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::detail;
using namespace hila::db::test_data;
using namespace hila::test;
namespace fs = std::filesystem;

namespace {

// A "version 0" database: what schema 1 would look like if robot_grasps had no theta_c_deg yet.
std::string write_v0(const std::string& dir) {
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  execute_script(path,
                 "ALTER TABLE robot_grasps DROP COLUMN theta_c_deg;"
                 "UPDATE meta SET value = '0' WHERE key = 'schema_version';");
  return path;
}

// The synthetic 0 -> 1 step: add the column with its "no constraint" default.
const std::vector<MigrationStep> kSteps = {
    {0, "ALTER TABLE robot_grasps ADD COLUMN theta_c_deg REAL NOT NULL DEFAULT 90.0;"}};

std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace

TEST(Migration, SyntheticStepUpgradesAVersion0Database) {
  const std::string dir = temp_dir("db_migration_v0");
  const std::string path = write_v0(dir);
  expect_input_error([&] { Database::open(path); }, {"written by schema version 0"});

  migrate_with_steps(path, kSteps, 1);

  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 1);
  const Sample sample = make_sample();
  ASSERT_EQ(db.parts().size(), sample.parts.size());
  EXPECT_EQ(db.parts()[0].name, sample.parts[0].part.name);
  const auto grasps = db.robot_grasps(1);
  ASSERT_EQ(grasps.size(), sample.parts[0].robot_grasps.size());
  for (std::size_t i = 0; i < grasps.size(); ++i) {
    EXPECT_EQ(grasps[i].theta_c_deg, 90.0) << "the step's default";
    EXPECT_EQ(grasps[i].quality, sample.parts[0].robot_grasps[i].quality) << "data kept";
  }
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"}) << "no temporary copy left";
}

TEST(Migration, StepsRunInVersionOrderWhateverTheListOrder) {
  const std::string dir = temp_dir("db_migration_order");
  const std::string path = write_v0(dir);
  // Step 1 -> 2 needs the table step 0 -> 1 creates; listed first to prove ordering.
  const std::vector<MigrationStep> steps = {
      {1, "INSERT INTO notes (text) VALUES ('from step 1');"},
      {0,
       "CREATE TABLE notes (text TEXT NOT NULL);"
       "ALTER TABLE robot_grasps ADD COLUMN theta_c_deg REAL NOT NULL DEFAULT 90.0;"}};
  EXPECT_TRUE(can_migrate(steps, 0, 2));
  migrate_with_steps(path, steps, 2);
  // The file is now version 2: this hila (1) calls it newer.
  expect_input_error([&] { Database::open(path); }, {"written by schema version 2"});
  // Migrating to 2 again is a no-op (already there).
  const std::string after = read_file(path);
  migrate_with_steps(path, steps, 2);
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
  // The real step list of schema 1 is empty: there is nothing to migrate from 0.
  expect_input_error(
      [&] { migrate_in_place(path); },
      {path + ": meta.schema_version", "schema version 0, for which there is no migration",
       "rebuild with: hila build meshes/cabinet/product.yaml -o " + path});
  expect_input_error([&] { migrate_with_steps(path, kSteps, 2); }, {"no migration"});
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
  execute_script(path, "UPDATE meta SET value = '7' WHERE key = 'schema_version'");
  expect_input_error([&] { migrate_in_place(path); },
                     {path, "written by schema version 7 (a newer hila)", "upgrade hila"});
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
