#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "open_checks.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::test_data;
using namespace hila::test;
namespace fs = std::filesystem;

namespace {

// A valid database of a few hundred pages, so a page in the middle holds grasp rows.
std::string write_large(const std::string& dir) {
  Sample sample = make_sample();
  auto& grasps = sample.parts[0].robot_grasps;
  const auto base = grasps;
  for (int i = 0; i < 400; ++i) grasps.insert(grasps.end(), base.begin(), base.end());
  const std::string path = dir + "/p.db";
  write_sample(path, sample);
  return path;
}

std::string write_small(const std::string& dir) {
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  return path;
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// Database::open and content_digest must both refuse the file with these fragments.
void expect_refused(const std::string& path, std::initializer_list<std::string> fragments) {
  expect_input_error([&] { Database::open(path); }, fragments);
  expect_input_error([&] { content_digest(path); }, {path});
}

}  // namespace

TEST(OpenChecks, MissingFileIsNotCreated) {
  const std::string path = temp_dir("db_open_missing") + "/p.db";
  expect_refused(path, {path + ": (file)", "no such file", "hila build PRODUCT.yaml -o " + path});
  EXPECT_FALSE(fs::exists(path));
}

TEST(OpenChecks, Directory) {
  const std::string dir = temp_dir("db_open_directory");
  expect_refused(dir, {dir, "a directory"});
}

TEST(OpenChecks, EmptyFile) {
  const std::string path = write_file(temp_dir("db_open_empty"), "p.db", "");
  expect_refused(path, {path + ": (file)", "expected a hila database (SQLite), got an empty file",
                        "rebuild with: hila build PRODUCT.yaml -o " + path});
}

TEST(OpenChecks, TruncatedToHalf) {
  const std::string path = write_small(temp_dir("db_open_truncated"));
  fs::resize_file(path, fs::file_size(path) / 2);
  expect_refused(path, {path, "a truncated SQLite file", "its header says", "rebuild with"});
}

TEST(OpenChecks, TruncatedInsideTheHeader) {
  const std::string dir = temp_dir("db_open_truncated_header");
  const std::string path = write_small(dir);
  fs::resize_file(path, 50);
  expect_refused(path, {path, "truncated", "shorter than the 100-byte header"});
  fs::resize_file(path, 10);  // a prefix of the magic string
  expect_refused(path, {path, "a truncated SQLite file (10 bytes)"});
}

TEST(OpenChecks, TextFile) {
  const std::string path =
      write_file(temp_dir("db_open_text"), "p.db", "name: cabinet\nparts: []\n");
  expect_refused(path, {path,
                        "expected a hila database (SQLite), got a text file starting with "
                        "\"name: cabinet parts: []\"",
                        "check the path"});
}

TEST(OpenChecks, BinaryForeignFile) {
  const std::string path = temp_dir("db_open_binary") + "/p.db";
  write_bytes(path, std::string("\x7f"
                                "ELF\x02\x01\x01\x00",
                                8) +
                        std::string(200, '\0'));
  expect_refused(path, {path, "208-byte file that is not SQLite (it starts with 7f 45 4c 46 02"});
}

TEST(OpenChecks, SqliteFileWithoutHilaTables) {
  const std::string path = temp_dir("db_open_foreign_sqlite") + "/p.db";
  detail::execute_script(path, "CREATE TABLE addresses (street TEXT); CREATE TABLE b (x);");
  expect_refused(path,
                 {path + ": meta", "without it (tables: addresses, b)", "not written by hila"});
}

TEST(OpenChecks, CorruptPageInTheMiddle) {
  const std::string path = write_large(temp_dir("db_open_corrupt"));
  const auto size = fs::file_size(path);
  constexpr std::uintmax_t kPage = 4096;  // SQLite's default page size
  ASSERT_GT(size / kPage, 20u) << "need a multi-page database";
  ASSERT_NO_THROW(Database::open(path));
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>((size / kPage / 2) * kPage));
    const std::string garbage(kPage, '\xa5');
    f.write(garbage.data(), static_cast<std::streamsize>(garbage.size()));
  }
  ASSERT_EQ(fs::file_size(path), size) << "same size: only the integrity check can notice";
  expect_refused(path, {path + ": (integrity)", "expected an intact hila database (SQLite)",
                        "rebuild with: hila build"});
}

TEST(OpenChecks, OlderSchemaVersionWithoutAMigrationPath) {
  const std::string path = write_small(temp_dir("db_open_older"));
  detail::execute_script(path, "UPDATE meta SET value = '0' WHERE key = 'schema_version'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.schema_version", "this hila reads (schema version 10)",
                      "written by schema version 0 (an older hila)",
                      "rebuild with: hila build meshes/cabinet/product.yaml -o " + path});
  // There is no step from version 0, so the message must not offer one.
  try {
    Database::open(path);
  } catch (const DatabaseError& e) {
    EXPECT_EQ(std::string(e.what()).find("migrate"), std::string::npos) << e.what();
  }
}

// SQL that drops the tables schema versions 8, 6 and 5 added and the ones version 4 added
// (regrasp_edges first: it refers to the others); suction_deliveries, table_regrasps and
// direct_grasps go before handover_candidates, which they refer to. Version 8 also added
// table_regrasps.repick_arm (kDropVersion8Columns, for a file that keeps the table), version 9
// regrasp_edges.duration (kDropVersion9Columns, likewise: the table as versions 4 to 8 had it),
// version 10 handover_candidates.bodies (kDropVersion10Columns: the table as versions 3 to 9 had
// it).
const std::string kDropVersion10Columns = handover_candidates_before_v10_sql();
const std::string kDropVersion9Columns = regrasp_edges_before_v9_sql();
const char* const kDropVersion8Tables = "DROP TABLE suction_deliveries;";
const char* const kDropVersion8Columns = "ALTER TABLE table_regrasps DROP COLUMN repick_arm;";
const char* const kDropVersion6Tables = "DROP TABLE table_regrasps;";
const char* const kDropVersion5Tables = "DROP TABLE direct_grasps;";
const char* const kDropVersion4Tables =
    "DROP TABLE regrasp_edges; DROP TABLE regrasp_nodes; DROP TABLE roadmap_filters;"
    "DROP TABLE roadmaps;";

TEST(OpenChecks, Version1OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v1"));
  detail::execute_script(path, std::string(kDropVersion8Tables) + kDropVersion6Tables +
                                   kDropVersion5Tables + kDropVersion4Tables +
                                   "DROP TABLE shared_grasps; DROP TABLE handover_candidates;"
                                   "DROP TABLE robot_handovers; DROP TABLE handover_stages;"
                                   "DROP TABLE ergonomics; DROP TABLE comfort_maps;"
                                   "UPDATE meta SET value = '1' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 1 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
}

TEST(OpenChecks, Version2OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v2"));
  detail::execute_script(
      path, std::string(kDropVersion8Tables) + kDropVersion6Tables + kDropVersion5Tables +
                kDropVersion4Tables +
                "DROP TABLE shared_grasps; DROP TABLE handover_candidates;"
                "DROP TABLE robot_handovers; DROP TABLE handover_stages;"
                "DROP TABLE ergonomics; DELETE FROM meta WHERE key = 'human_bodies';"
                "UPDATE meta SET value = '2' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 2 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 2 file has no version 3 tables to hash).
  EXPECT_EQ(content_digest(path).size(), 64u);
}

TEST(OpenChecks, Version3OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v3"));
  const std::string digest_current = content_digest(path);
  detail::execute_script(path, kDropVersion10Columns + kDropVersion8Tables + kDropVersion6Tables +
                                   kDropVersion5Tables + kDropVersion4Tables +
                                   "UPDATE meta SET value = '3' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 3 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 3 file has no version 4 tables to hash), and differs.
  const std::string digest_v3 = content_digest(path);
  EXPECT_EQ(digest_v3.size(), 64u);
  EXPECT_NE(digest_v3, digest_current);
}

TEST(OpenChecks, Version4OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v4"));
  const std::string digest_current = content_digest(path);
  detail::execute_script(path, kDropVersion10Columns + kDropVersion9Columns + kDropVersion8Tables +
                                   kDropVersion6Tables + kDropVersion5Tables +
                                   "UPDATE meta SET value = '4' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 4 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 4 file has no direct_grasps table to hash), and differs.
  const std::string digest_v4 = content_digest(path);
  EXPECT_EQ(digest_v4.size(), 64u);
  EXPECT_NE(digest_v4, digest_current);
}

TEST(OpenChecks, Version5OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v5"));
  const std::string digest_current = content_digest(path);
  detail::execute_script(path, kDropVersion10Columns + kDropVersion9Columns + kDropVersion8Tables +
                                   kDropVersion6Tables +
                                   "UPDATE meta SET value = '5' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 5 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 5 file has no table_regrasps table to hash), and differs.
  const std::string digest_v5 = content_digest(path);
  EXPECT_EQ(digest_v5.size(), 64u);
  EXPECT_NE(digest_v5, digest_current);
}

TEST(OpenChecks, Version7OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v7"));
  const std::string digest_current = content_digest(path);
  detail::execute_script(path, kDropVersion10Columns + kDropVersion9Columns + kDropVersion8Tables +
                                   kDropVersion8Columns +
                                   "DELETE FROM meta WHERE key = 'digest.suction_deliveries';"
                                   "UPDATE meta SET value = '7' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 7 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 7 file has no suction_deliveries table to hash, and no
  // table_regrasps.repick_arm), and differs.
  const std::string digest_v7 = content_digest(path);
  EXPECT_EQ(digest_v7.size(), 64u);
  EXPECT_NE(digest_v7, digest_current);
  // Migrated, it opens with every check (its digests rewritten), each regrasp taken again by the
  // arm that set it down, no edge's duration estimated, no candidate's bodies.
  migrate_in_place(path);
  const Database db = Database::open(path);
  std::size_t regrasps = 0;
  for (const auto& c : db.handover_candidates(1)) {
    for (const auto& r : db.table_regrasps(c.id)) {
      ++regrasps;
      EXPECT_EQ(r.repick_arm, r.arm) << r.id;
    }
  }
  EXPECT_EQ(regrasps, 5u);
  ASSERT_EQ(db.regrasp_edges(1).size(), 6u);
  for (const auto& e : db.regrasp_edges(1)) EXPECT_EQ(e.duration, 0.0) << e.id;
  for (const auto& c : db.handover_candidates(1)) EXPECT_EQ(c.bodies, 0u) << c.id;
}

TEST(OpenChecks, Version8OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v8"));
  const std::string digest_current = content_digest(path);
  detail::execute_script(path, kDropVersion10Columns + kDropVersion9Columns +
                                   "UPDATE meta SET value = '8' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 8 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 8 file has no regrasp_edges.duration), and differs.
  const std::string digest_v8 = content_digest(path);
  EXPECT_EQ(digest_v8.size(), 64u);
  EXPECT_NE(digest_v8, digest_current);
  // Migrated, it opens with every check (its digests rewritten), no edge's duration estimated, no
  // candidate's bodies.
  migrate_in_place(path);
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  std::size_t edges = 0;
  for (const std::int64_t part : {1, 2}) {
    for (const auto& e : db.regrasp_edges(part)) {
      ++edges;
      EXPECT_EQ(e.duration, 0.0) << e.id;
    }
  }
  EXPECT_EQ(edges, 8u);
  // The migration's digests differ from the writer's only where the durations and masks do: the
  // same sample with none estimated and none taking a body has the same content.
  const std::string dir = temp_dir("db_open_v8_written");
  Sample sample = make_sample();
  clear_durations(sample);
  clear_bodies(sample);
  write_sample(dir + "/p.db", sample);
  EXPECT_EQ(content_digest(path), content_digest(dir + "/p.db"));
}

TEST(OpenChecks, Version9OffersMigration) {
  const std::string path = write_small(temp_dir("db_open_v9"));
  const std::string digest_current = content_digest(path);
  detail::execute_script(
      path, kDropVersion10Columns + "UPDATE meta SET value = '9' WHERE key = 'schema_version'");
  expect_input_error(
      [&] { Database::open(path); },
      {path +
       ": meta.schema_version: expected a database this hila reads (schema version 10), "
       "got one written by schema version 9 (an older hila); rebuild with: hila build "
       "meshes/cabinet/product.yaml -o " +
       path + " (or migrate it in place with hila::db::migrate_in_place)"});
  // The digest still reads it (a version 9 file has no handover_candidates.bodies), and differs.
  const std::string digest_v9 = content_digest(path);
  EXPECT_EQ(digest_v9.size(), 64u);
  EXPECT_NE(digest_v9, digest_current);
  // Migrated, it opens with every check (its digests rewritten), no candidate taking a body.
  migrate_in_place(path);
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);
  std::size_t candidates = 0;
  for (const std::int64_t part : {1, 2}) {
    for (const auto& c : db.handover_candidates(part)) {
      ++candidates;
      EXPECT_EQ(c.bodies, 0u) << c.id;
    }
  }
  EXPECT_EQ(candidates, 9u);
  // The migration's digests differ from the writer's only where the masks do.
  const std::string dir = temp_dir("db_open_v9_written");
  Sample sample = make_sample();
  clear_bodies(sample);
  write_sample(dir + "/p.db", sample);
  EXPECT_EQ(content_digest(path), content_digest(dir + "/p.db"));
}

TEST(OpenChecks, NewerSchemaVersion) {
  const std::string path = write_small(temp_dir("db_open_newer"));
  detail::execute_script(path, "UPDATE meta SET value = '11' WHERE key = 'schema_version'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.schema_version", "written by schema version 11 (a newer hila)",
                      "upgrade hila, or rebuild with: hila build"});
}

TEST(OpenChecks, OlderVersionWithAMigrationPathSaysSo) {
  expect_input_error([] { detail::check_schema_version("p.db", 0, 1, true, "rebuild with: X"); },
                     {"p.db: meta.schema_version",
                      "rebuild with: X (or migrate it in place with hila::db::migrate_in_place)"});
  EXPECT_NO_THROW(detail::check_schema_version("p.db", 4, 4, false, ""));
}

TEST(OpenChecks, BadMetaValues) {
  const std::string dir = temp_dir("db_open_meta");
  const std::string path = write_small(dir);
  const std::string pristine = read_file(path);
  const auto reset = [&] { write_bytes(path, pristine); };

  detail::execute_script(path, "UPDATE meta SET value = '1x' WHERE key = 'schema_version'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.schema_version", "expected an integer", "'1x'"});
  reset();
  detail::execute_script(path, "DELETE FROM meta WHERE key = 'schema_version'");
  expect_input_error([&] { Database::open(path); }, {"meta.schema_version", "no such key"});
  reset();
  detail::execute_script(path, "DELETE FROM meta WHERE key = 'product_hash'");
  expect_input_error([&] { Database::open(path); }, {"meta.product_hash", "no such key"});
  reset();
  detail::execute_script(path, "UPDATE meta SET value = '-1' WHERE key = 'seed'");
  expect_input_error([&] { Database::open(path); },
                     {"meta.seed", "an unsigned 64-bit integer", "'-1'"});
  reset();
  EXPECT_NO_THROW(Database::open(path));
}

TEST(OpenChecks, MissingTable) {
  const std::string path = write_small(temp_dir("db_open_missing_table"));
  detail::execute_script(path, "DROP TABLE human_grasps");
  expect_refused(path, {path + ": human_grasps", "no such table: human_grasps", "rebuild with"});
}

TEST(OpenChecks, DamagedQuaternion) {
  const std::string path = write_small(temp_dir("db_open_quaternion"));
  detail::execute_script(path, "UPDATE robot_grasps SET tcp_qw = 0.5 WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path + ": robot_grasps.tcp (id 2)", "a unit quaternion"});
}

TEST(OpenChecks, CorruptComfortValues) {
  const std::string dir = temp_dir("db_open_comfort_deflate");
  const std::string path = write_small(dir);
  const std::string pristine = read_file(path);
  const auto reset = [&] { write_bytes(path, pristine); };
  const std::string field = path + ": comfort_maps.values_deflate (arm 'right', id 1)";

  // Four bytes in the middle of the zlib stream overwritten (zlib's checksum sees any change).
  detail::execute_script(
      path,
      "UPDATE comfort_maps SET values_deflate = CAST(substr(values_deflate, 1, 8) || "
      "x'a5a5a5a5' || substr(values_deflate, 13) AS BLOB) WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); },
                     {field,
                      "expected zlib-compressed values that inflate to value_bytes = 240 "
                      "bytes, got data that is not a valid zlib stream",
                      "rebuild with: hila build meshes/cabinet/product.yaml -o " + path});
  expect_input_error([&] { content_digest(path); }, {path, "comfort_maps.values_deflate"});
  reset();
  // Cut short.
  detail::execute_script(
      path,
      "UPDATE comfort_maps SET values_deflate = "
      "substr(values_deflate, 1, length(values_deflate) - 6) WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); }, {field, "a cut-off zlib stream"});
  reset();
  // Not zlib at all.
  detail::execute_script(
      path, "UPDATE comfort_maps SET values_deflate = x'0102030405' WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); },
                     {field, "not a valid zlib stream (incorrect header check)"});
  reset();
  // A valid stream followed by garbage.
  detail::execute_script(
      path,
      "UPDATE comfort_maps SET values_deflate = CAST(values_deflate || x'00' AS BLOB) "
      "WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); }, {field, "followed by extra bytes"});
  reset();
  // The streams of the two maps (240 and 210 bytes) swapped.
  detail::execute_script(path,
                         "UPDATE comfort_maps SET values_deflate = (SELECT values_deflate FROM "
                         "comfort_maps WHERE arm = 'left') WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); }, {field, "got a zlib stream of 210 bytes"});
  reset();
  detail::execute_script(path,
                         "UPDATE comfort_maps SET values_deflate = (SELECT values_deflate FROM "
                         "comfort_maps WHERE arm = 'right') WHERE arm = 'left'");
  expect_input_error([&] { Database::open(path); },
                     {"comfort_maps.values_deflate (arm 'left', id 2)",
                      "got a zlib stream of more than 210 bytes"});
  reset();
  EXPECT_NO_THROW(Database::open(path));
}

TEST(OpenChecks, InconsistentComfortMapSizes) {
  const std::string dir = temp_dir("db_open_comfort_sizes");
  const std::string path = write_small(dir);
  const std::string pristine = read_file(path);
  const auto reset = [&] { write_bytes(path, pristine); };
  const std::string row = "(arm 'right', id 1)";

  // value_bytes must be dims * orientation_count: a changed dimension is seen before inflating.
  detail::execute_script(path, "UPDATE comfort_maps SET dim_x = 5 WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": comfort_maps.value_bytes " + row,
                      "expected dim_x * dim_y * dim_z * orientation_count = 300, got 240"});
  reset();
  detail::execute_script(path, "UPDATE comfort_maps SET dim_z = 0 WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); },
                     {"comfort_maps.dim_x/y/z " + row, "node counts > 0", "4 x 3 x 0"});
  reset();
  // A huge value_bytes must not become a huge allocation.
  detail::execute_script(path,
                         "UPDATE comfort_maps SET dim_x = 100000, dim_y = 100000, "
                         "value_bytes = 100000 * 100000 * 2 * 10 WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); },
                     {"comfort_maps.values_deflate " + row, "too short to inflate"});
  reset();
  detail::execute_script(path,
                         "UPDATE comfort_maps SET orientation_count = 11 WHERE arm = 'right'");
  expect_input_error(
      [&] { Database::open(path); },
      {"comfort_maps.orientations " + row,
       "expected orientation_count = 11 orientations (32 bytes each), got 320 bytes"});
  reset();
  // The first orientation's w set to 0: no longer a unit quaternion.
  detail::execute_script(path,
                         "UPDATE comfort_maps SET orientations = CAST(zeroblob(8) || "
                         "substr(orientations, 9) AS BLOB) WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); },
                     {"comfort_maps.orientations " + row, "unit quaternions", "orientation 0"});
  reset();
  detail::execute_script(path, "UPDATE comfort_maps SET spacing = -0.03 WHERE arm = 'right'");
  expect_input_error([&] { Database::open(path); }, {"comfort_maps.spacing " + row, "> 0"});
  reset();
  EXPECT_NO_THROW(Database::open(path));
}

TEST(OpenChecks, OpeningChangesNothingOnDisk) {
  const std::string dir = temp_dir("db_open_readonly");
  const std::string path = write_small(dir);
  const std::string before = read_file(path);
  Database::open(path);
  content_digest(path);
  EXPECT_EQ(read_file(path), before);
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  EXPECT_EQ(names, std::vector<std::string>{"p.db"}) << "no journal or lock files";
}

TEST(OpenChecks, CheckSqliteFileAcceptsAValidDatabase) {
  const std::string path = write_small(temp_dir("db_open_valid"));
  EXPECT_NO_THROW(detail::check_sqlite_file(path));
  EXPECT_EQ(detail::rebuild_hint("x.db"), "rebuild with: hila build PRODUCT.yaml -o x.db");
  EXPECT_EQ(detail::rebuild_hint("x.db", {{"product_file", "p.yaml"}}),
            "rebuild with: hila build p.yaml -o x.db");
  EXPECT_EQ(detail::rebuild_hint("x.db", {{"product_file", "p.yaml"}, {"cell_file", "c.yaml"}}),
            "rebuild with: hila build p.yaml -o x.db");
}
