// Database::open verifies what it opens (issue 36): the hila version, every value's storage class,
// the references, part masses, and each table's content digest stored in meta when the file was
// written. Each test damages a database written by DatabaseWriter the way a hand edit, a stale
// build or a flipped bit would, and expects the open refused with a message that names the file,
// the table (and row), what was expected and found, and how to rebuild.

#include <gtest/gtest.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sample_records.hpp"
#include "schema.hpp"
#include "sqlite_handle.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::test_data;
using namespace hila::test;
namespace fs = std::filesystem;

namespace {

const detail::ErrorContext kEdit{"(edit)", "SQL that runs", ""};

std::string write_small(const std::string& dir) {
  const std::string path = dir + "/p.db";
  write_sample(path, make_sample());
  return path;
}

// "rebuild with: hila build meshes/cabinet/product.yaml -o PATH", as every refusal ends.
std::string rebuild(const std::string& path) {
  return "rebuild with: hila build meshes/cabinet/product.yaml -o " + path;
}

// Runs SQL on the file as the sqlite3 shell would: foreign keys off, so edits the writer refuses
// go through.
void edit(const std::string& path, const std::string& sql) {
  detail::Connection connection(path, SQLITE_OPEN_READWRITE, path);
  connection.exec("PRAGMA foreign_keys = OFF;", kEdit);
  connection.exec(sql, kEdit);
  connection.close();
}

// One integer of the file, by SQL.
std::int64_t query_int(const std::string& path, const std::string& sql) {
  detail::Connection connection(path, SQLITE_OPEN_READONLY, path);
  std::int64_t value = 0;
  {
    detail::Statement select(connection, sql, kEdit);
    if (!select.step()) throw std::runtime_error("no row: " + sql);
    value = select.column_int64(0);
  }
  connection.close();
  return value;
}

// The meta table's digest.* rows, key -> value.
std::vector<std::pair<std::string, std::string>> stored_digests(const std::string& path) {
  detail::Connection connection(path, SQLITE_OPEN_READONLY, path);
  std::vector<std::pair<std::string, std::string>> digests;
  {
    detail::Statement select(
        connection, "SELECT key, value FROM meta WHERE key GLOB 'digest.*' ORDER BY key", kEdit);
    while (select.step()) digests.emplace_back(select.column_text(0), select.column_text(1));
  }
  connection.close();
  return digests;
}

// The double stored in TABLE.COLUMN of row `id`, with its lowest mantissa bit flipped (one ulp).
void flip_real(const std::string& path, const std::string& table, const std::string& column,
               std::int64_t id) {
  detail::Connection connection(path, SQLITE_OPEN_READWRITE, path);
  {
    detail::Statement select(
        connection, "SELECT " + column + " FROM " + table + " WHERE id = " + std::to_string(id),
        kEdit);
    ASSERT_TRUE(select.step());
    ASSERT_EQ(select.column_type(0), SQLITE_FLOAT);
    double value = select.column_double(0);
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));
    bits ^= 1;
    std::memcpy(&value, &bits, sizeof(bits));
    detail::Statement update(
        connection, "UPDATE " + table + " SET " + column + " = ? WHERE id = " + std::to_string(id),
        kEdit);
    update.bind_next(value);
    update.run();
  }
  connection.close();
}

// The BLOB in TABLE.COLUMN of row `id`, with the lowest bit of its first byte flipped.
void flip_blob_bit(const std::string& path, const std::string& table, const std::string& column,
                   std::int64_t id) {
  detail::Connection connection(path, SQLITE_OPEN_READWRITE, path);
  {
    detail::Statement select(
        connection, "SELECT " + column + " FROM " + table + " WHERE id = " + std::to_string(id),
        kEdit);
    ASSERT_TRUE(select.step());
    std::string bytes = select.column_blob(0);
    ASSERT_FALSE(bytes.empty());
    bytes[0] = static_cast<char>(bytes[0] ^ 1);
    detail::Statement update(
        connection, "UPDATE " + table + " SET " + column + " = ? WHERE id = " + std::to_string(id),
        kEdit);
    update.bind_blob(bytes);
    update.run();
  }
  connection.close();
}

// Where `needle` occurs in `haystack`.
std::vector<std::size_t> occurrences(const std::string& haystack, const std::string& needle) {
  std::vector<std::size_t> at;
  for (std::size_t i = haystack.find(needle); i != std::string::npos;
       i = haystack.find(needle, i + 1)) {
    at.push_back(i);
  }
  return at;
}

OpenOptions any_hila_version() {
  OpenOptions options;
  options.expected_hila_version = std::nullopt;
  return options;
}

}  // namespace

TEST(OpenVerification, AnIntactDatabaseOpensWithAllItsDigests) {
  const std::string path = write_small(temp_dir("db_verify_intact"));
  EXPECT_NO_THROW(Database::open(path));
  const auto digests = stored_digests(path);
  ASSERT_EQ(digests.size(), detail::kTables.size()) << "one per table, meta included";
  for (const auto& [key, value] : digests) {
    EXPECT_EQ(key.rfind("digest.", 0), 0u) << key;
    EXPECT_EQ(value.size(), 64u) << key;
  }
  EXPECT_EQ(Database::open(path).meta().hila_version, hila_version());
}

// A stale database: another hila built it, so `hila build --if-outdated` would rebuild it.
TEST(OpenVerification, HilaVersionChangedInMeta) {
  const std::string path = write_small(temp_dir("db_verify_hila_version"));
  edit(path, "UPDATE meta SET value = '0.6.0' WHERE key = 'hila_version'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.hila_version: expected a database built by this hila (" +
                          hila_version() + "), got one built by hila 0.6.0 (an older hila",
                      "hila build --if-outdated rebuilds it); " + rebuild(path)});
  // Accepting any hila version does not accept the edit: meta's stored digest covers it.
  expect_input_error([&] { Database::open(path, any_hila_version()); },
                     {path + ": meta: expected the content digest stored when it was written "
                             "(meta.digest.meta = ",
                      "its rows changed since (a damaged or edited file); " + rebuild(path)});
  // A newer hila's database: upgrade, or rebuild.
  edit(path, "UPDATE meta SET value = '99.0.0' WHERE key = 'hila_version'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.hila_version", "got one built by hila 99.0.0 (a newer hila)",
                      "; upgrade hila, or " + rebuild(path)});
}

TEST(OpenVerification, DatabaseBuiltByAnotherHilaOpensOnlyWhenAnyVersionIsAccepted) {
  const std::string dir = temp_dir("db_verify_other_hila");
  Sample sample = make_sample();
  sample.meta.hila_version = "0.6.0";
  write_sample(dir + "/p.db", sample);
  expect_input_error([&] { Database::open(dir + "/p.db"); },
                     {dir + "/p.db: meta.hila_version", "got one built by hila 0.6.0"});
  EXPECT_EQ(Database::open(dir + "/p.db", any_hila_version()).meta().hila_version, "0.6.0");
  OpenOptions exact;
  exact.expected_hila_version = "0.6.0";
  EXPECT_NO_THROW(Database::open(dir + "/p.db", exact));
  // A version that is not dotted numbers is compared all the same, without older or newer.
  exact.expected_hila_version = "dev";
  expect_input_error([&] { Database::open(dir + "/p.db", exact); },
                     {"expected a database built by this hila (dev), got one built by hila "
                      "0.6.0; rebuild with"});
}

TEST(OpenVerification, RealValueReplacedByText) {
  const std::string path = write_small(temp_dir("db_verify_real_text"));
  edit(path, "UPDATE robot_grasps SET quality = 'abc' WHERE id = 3");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": robot_grasps.quality (id 3): expected a REAL (the column is REAL "
                      "NOT NULL), got the TEXT 'abc'; " +
                      rebuild(path)});
}

TEST(OpenVerification, RealValueReplacedByNull) {
  const std::string path = write_small(temp_dir("db_verify_real_null"));
  // SQLite keeps NOT NULL, so only a file whose schema lost it can hold the NULL: edit the
  // schema first (as a hand-made file could be), then the value.
  edit(path,
       "PRAGMA writable_schema = ON;"
       "UPDATE sqlite_master SET sql = replace(sql, 'quality REAL NOT NULL', 'quality REAL') "
       "WHERE name = 'robot_grasps';"
       "PRAGMA writable_schema = OFF;");
  edit(path, "UPDATE robot_grasps SET quality = NULL WHERE id = 2");
  ASSERT_EQ(query_int(path, "SELECT count(*) FROM robot_grasps WHERE quality IS NULL"), 1);
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": robot_grasps.quality (id 2): expected a REAL (the column is REAL "
                      "NOT NULL), got NULL; " +
                      rebuild(path)});
}

TEST(OpenVerification, MassThatIsNotAPositiveNumber) {
  const std::string dir = temp_dir("db_verify_mass");
  const std::string path = write_small(dir);
  const std::string pristine = read_file(path);
  edit(path, "UPDATE parts SET mass = 'heavy' WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": parts.mass (id 2): expected a REAL (the column is REAL NOT NULL), "
                      "got the TEXT 'heavy'; " +
                      rebuild(path)});
  // SQL value -> as the message shows it (SQLite reads -0.0 back as 0).
  const std::vector<std::pair<std::string, std::string>> masses = {
      {"-5", "-5"}, {"0", "0"}, {"-0.0", "0"}, {"-1e-300", "-1e-300"}};
  for (const auto& [stored, shown] : masses) {
    SCOPED_TRACE(stored);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    edit(path, "UPDATE parts SET mass = " + stored + " WHERE id = 2");
    expect_input_error([&] { Database::open(path); },
                       {path +
                        ": parts.mass (part 'door panel 'left'', id 2): expected a mass in "
                        "kg, finite and > 0, got " +
                        shown + "; " + rebuild(path)});
  }
  // The writer refuses such a mass in the first place.
  Sample sample = make_sample();
  sample.parts[1].part.mass = -5.0;
  try {
    write_sample(dir + "/w.db", sample);
    ADD_FAILURE() << "a mass of -5 kg was written";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "DatabaseWriter::add_part: parts.mass (part 'door panel 'left''): "
                  "PartRecord::mass is -5, expected a mass in kg, finite and > 0"),
              std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(fs::exists(dir + "/w.db"));
}

TEST(OpenVerification, HalfTheRobotGraspsDeleted) {
  const std::string path = write_small(temp_dir("db_verify_half_grasps"));
  edit(path, "DELETE FROM robot_grasps WHERE id % 2 = 0");
  // Other tables refer to some of them: their foreign keys break first.
  expect_input_error(
      [&] { Database::open(path); },
      {path + ": ", "expected the id of a robot_grasps row, got ", ", which names none (one of ",
       " references PRAGMA foreign_key_check finds "
       "broken); " +
           rebuild(path)});
}

TEST(OpenVerification, RobotGraspsNothingRefersToDeleted) {
  const std::string path = write_small(temp_dir("db_verify_unreferenced_grasps"));
  const std::string unreferenced =
      "id NOT IN (SELECT robot_grasp_id FROM shared_grasps UNION SELECT robot_grasp_id FROM "
      "direct_grasps UNION SELECT pick_grasp_id FROM table_regrasps UNION SELECT robot_grasp_id "
      "FROM table_regrasps UNION SELECT grasp_id FROM roadmap_filters WHERE grasp_kind = "
      "'gripper' UNION SELECT grasp_id FROM regrasp_nodes WHERE grasp_kind = 'gripper')";
  ASSERT_GE(query_int(path, "SELECT count(*) FROM robot_grasps WHERE " + unreferenced), 1);
  edit(path, "DELETE FROM robot_grasps WHERE " + unreferenced);
  // Every reference still holds: only the table's digest can tell.
  expect_input_error([&] { Database::open(path); },
                     {path + ": robot_grasps: expected the content digest stored when it was "
                             "written (meta.digest.robot_grasps = ",
                      "its rows changed since (a damaged or edited file); " + rebuild(path)});
}

TEST(OpenVerification, HalfTheRoadmapFiltersDeleted) {
  const std::string path = write_small(temp_dir("db_verify_half_filters"));
  ASSERT_GE(query_int(path,
                      "SELECT count(*) FROM regrasp_edges WHERE filter_id IN (SELECT id FROM "
                      "roadmap_filters WHERE id % 2 = 0)"),
            1);
  edit(path, "DELETE FROM roadmap_filters WHERE id % 2 = 0");
  expect_input_error(
      [&] { Database::open(path); },
      {path + ": regrasp_edges.filter_id (id ", "): expected the id of a roadmap_filters row, got ",
       ", which names none", rebuild(path)});
}

TEST(OpenVerification, RegraspEdgeDeleted) {
  const std::string path = write_small(temp_dir("db_verify_regrasp_edge"));
  edit(path, "DELETE FROM regrasp_edges WHERE id = 3");
  expect_input_error([&] { Database::open(path); },
                     {path + ": regrasp_edges: expected the content digest stored when it was "
                             "written (meta.digest.regrasp_edges = ",
                      rebuild(path)});
}

TEST(OpenVerification, RelayUndoneByHand) {
  // A relay turned into a regrasp by one arm (repick_arm set to arm): a valid row every other
  // check accepts; only table_regrasps' digest sees it.
  const std::string path = write_small(temp_dir("db_verify_relay"));
  ASSERT_EQ(query_int(path, "SELECT count(*) FROM table_regrasps WHERE repick_arm <> arm"), 2);
  edit(path, "UPDATE table_regrasps SET repick_arm = arm WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path + ": table_regrasps: expected the content digest stored when it was "
                             "written (meta.digest.table_regrasps = ",
                      rebuild(path)});
}

TEST(OpenVerification, DurationEditedByHand) {
  // An edge's estimated duration changed to another valid time (or to 0, not estimated): a row
  // every other check accepts; only regrasp_edges' digest sees it.
  const std::string path = write_small(temp_dir("db_verify_duration"));
  const std::string pristine = read_file(path);
  ASSERT_EQ(query_int(path, "SELECT count(*) FROM regrasp_edges WHERE duration > 0"), 4);
  for (const std::string sql : {"UPDATE regrasp_edges SET duration = 6.0 WHERE id = 1",
                                "UPDATE regrasp_edges SET duration = 0 WHERE id = 2",
                                "UPDATE regrasp_edges SET duration = 1.5 WHERE id = 3"}) {
    SCOPED_TRACE(sql);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    edit(path, sql);
    expect_input_error([&] { Database::open(path); },
                       {path + ": regrasp_edges: expected the content digest stored when it was "
                               "written (meta.digest.regrasp_edges = ",
                        rebuild(path)});
  }
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  flip_real(path, "regrasp_edges", "duration", 1);
  expect_input_error([&] { Database::open(path); },
                     {path + ": regrasp_edges: expected the content digest stored when it was "
                             "written (meta.digest.regrasp_edges = "});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  EXPECT_NO_THROW(Database::open(path));
}

TEST(OpenVerification, RoadmapEdgeDeleted) {
  // The last of the left arm's 13 roadmap edges cut from its arrays (8 bytes each), the count
  // lowered to match, and that edge's bit (bit 4 of byte 1) cleared in every filter of the
  // roadmap with its valid_edges: a roadmap with one edge less that every other check accepts.
  const std::string path = write_small(temp_dir("db_verify_roadmap_edge"));
  ASSERT_EQ(query_int(path, "SELECT edge_count FROM roadmaps WHERE id = 1"), 13);
  edit(path,
       "UPDATE roadmaps SET edge_count = 12,"
       " edge_nodes = substr(edge_nodes, 1, 96),"
       " edge_length = substr(edge_length, 1, 96),"
       " edge_max_inclination_deg = substr(edge_max_inclination_deg, 1, 96) WHERE id = 1;");
  {
    detail::Connection connection(path, SQLITE_OPEN_READWRITE, path);
    {
      detail::Statement select(
          connection, "SELECT id, edge_bits, valid_edges FROM roadmap_filters WHERE roadmap_id = 1",
          kEdit);
      detail::Statement update(
          connection, "UPDATE roadmap_filters SET edge_bits = ?, valid_edges = ? WHERE id = ?",
          kEdit);
      std::vector<std::tuple<std::int64_t, std::string, std::int64_t>> rows;
      while (select.step()) {
        rows.emplace_back(select.column_int64(0), select.column_blob(1), select.column_int64(2));
      }
      ASSERT_FALSE(rows.empty());
      for (auto& [id, bits, valid] : rows) {
        ASSERT_EQ(bits.size(), 2u);
        if (bits[1] & 0x10) --valid;
        bits[1] = static_cast<char>(bits[1] & ~0x10);
        update.bind_blob(bits);
        update.bind_next(valid);
        update.bind_next(id);
        update.run();
      }
    }
    connection.close();
  }
  ASSERT_EQ(query_int(path, "SELECT length(edge_nodes) FROM roadmaps WHERE id = 1"), 96);
  expect_input_error([&] { Database::open(path); },
                     {path + ": roadmaps: expected the content digest stored when it was written "
                             "(meta.digest.roadmaps = ",
                      rebuild(path)});
}

TEST(OpenVerification, ForeignKeyViolation) {
  const std::string path = write_small(temp_dir("db_verify_foreign_key"));
  edit(path, "UPDATE shared_grasps SET robot_handover_id = 999 WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": shared_grasps.robot_handover_id (id 2): expected the id of a "
                      "robot_handovers row, got 999, which names none (the only reference "
                      "PRAGMA foreign_key_check finds broken); " +
                      rebuild(path)});
}

TEST(OpenVerification, GraspIdThatNamesNoGrasp) {
  // grasp_id has no foreign key (its table depends on grasp_kind): checked by open all the same.
  const std::string path = write_small(temp_dir("db_verify_grasp_id"));
  edit(path,
       "UPDATE roadmap_filters SET grasp_id = 999 WHERE id = (SELECT min(id) FROM roadmap_filters "
       "WHERE grasp_kind = 'suction')");
  const std::int64_t id =
      query_int(path, "SELECT min(id) FROM roadmap_filters WHERE grasp_kind = 'suction'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": roadmap_filters.grasp_id (id " + std::to_string(id) +
                      "): expected the id of a suction_grasps row (grasp_kind 'suction'), got "
                      "999, which names none; " +
                      rebuild(path)});
}

// The suction_deliveries table (schema version 8) is verified like the others: its references,
// its storage classes and its content digest.
TEST(OpenVerification, SuctionDeliveriesAreVerified) {
  const std::string path = write_small(temp_dir("db_verify_suction_deliveries"));
  const std::string pristine = read_file(path);
  const auto reset = [&] { std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine; };
  ASSERT_EQ(query_int(path, "SELECT count(*) FROM suction_deliveries"), 5);
  edit(path, "UPDATE suction_deliveries SET suction_grasp_id = 999 WHERE id = 3");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": suction_deliveries.suction_grasp_id (id 3): expected the id of a "
                      "suction_grasps row, got 999, which names none (the only reference "
                      "PRAGMA foreign_key_check finds broken); " +
                      rebuild(path)});
  reset();
  edit(path, "UPDATE suction_deliveries SET candidate_id = 99 WHERE id IN (1, 4)");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": suction_deliveries.candidate_id (id 1): expected the id of a "
                      "handover_candidates row, got 99, which names none (one of 2 references "
                      "PRAGMA foreign_key_check finds broken); " +
                      rebuild(path)});
  reset();
  edit(path, "UPDATE suction_deliveries SET joints_rh = 0.5 WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": suction_deliveries.joints_rh (id 2): expected a BLOB (the column is "
                      "BLOB NOT NULL), got the REAL 0.5; " +
                      rebuild(path)});
  reset();
  edit(path, "UPDATE suction_deliveries SET suction_grasp_id = 'one' WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": suction_deliveries.suction_grasp_id (id 2): expected an INTEGER "
                      "(the column is INTEGER NOT NULL), got the TEXT 'one'; " +
                      rebuild(path)});
  reset();
  flip_blob_bit(path, "suction_deliveries", "joints_rh", 5);
  expect_input_error([&] { Database::open(path); },
                     {path + ": suction_deliveries: expected the content digest stored when it "
                             "was written (meta.digest.suction_deliveries = ",
                      "its rows changed since (a damaged or edited file); " + rebuild(path)});
  reset();
  edit(path, "DELETE FROM meta WHERE key = 'digest.suction_deliveries'");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": meta.digest.suction_deliveries: expected the content digest of table "
                      "suction_deliveries (a database of schema version 7 or later holds one per "
                      "table, written with it), got no such key; " +
                      rebuild(path)});
  reset();
  EXPECT_NO_THROW(Database::open(path));
}

TEST(OpenVerification, WrongStorageClassesAndColumns) {
  const std::string path = write_small(temp_dir("db_verify_types"));
  const std::string pristine = read_file(path);
  const auto refused = [&](const std::string& sql, std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(sql);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    edit(path, sql);
    expect_input_error([&] { Database::open(path); }, fragments);
  };
  refused("UPDATE roadmaps SET dof = 6.5 WHERE id = 2",
          {path + ": roadmaps.dof (id 2): expected an INTEGER (the column is INTEGER NOT NULL), "
                  "got the REAL 6.5"});
  refused("UPDATE shared_grasps SET joints_rr = 'x' WHERE id = 1",
          {path + ": shared_grasps.joints_rr (id 1): expected a BLOB (the column is BLOB NOT "
                  "NULL), got the TEXT 'x'"});
  refused("UPDATE parts SET name = x'00ff' WHERE id = 1",
          {path + ": parts.name (id 1): expected a TEXT (the column is TEXT NOT NULL), got a "
                  "BLOB of 2 bytes"});
  refused(
      "UPDATE regrasp_edges SET filter_id = 'none' WHERE filter_id IS NOT NULL AND id = "
      "(SELECT min(id) FROM regrasp_edges WHERE filter_id IS NOT NULL)",
      {": regrasp_edges.filter_id (id ",
       "): expected an INTEGER or NULL (the column is INTEGER), got the TEXT 'none'"});
  refused("UPDATE meta SET value = x'01' WHERE key = 'product_name'",
          {path + ": meta.value (key 'product_name'): expected a TEXT (the column is TEXT NOT "
                  "NULL), got a BLOB of 1 byte"});
  refused("ALTER TABLE robot_grasps ADD COLUMN note TEXT",
          {path + ": robot_grasps: expected the 26 columns of schema version 10, got 27 columns "
                  "(column 27 is 'note', expected none)"});
}

TEST(OpenVerification, OneUlpInAStoredReal) {
  const std::string path = write_small(temp_dir("db_verify_ulp"));
  flip_real(path, "robot_grasps", "tcp_x", 3);
  expect_input_error([&] { Database::open(path); },
                     {path + ": robot_grasps: expected the content digest stored when it was "
                             "written (meta.digest.robot_grasps = ",
                      rebuild(path)});
}

TEST(OpenVerification, OneBitInAJointBlob) {
  const std::string path = write_small(temp_dir("db_verify_blob_bit"));
  flip_blob_bit(path, "shared_grasps", "joints_rr", 1);
  expect_input_error([&] { Database::open(path); },
                     {path + ": shared_grasps: expected the content digest stored when it was "
                             "written (meta.digest.shared_grasps = ",
                      rebuild(path)});
}

TEST(OpenVerification, OneBitFlippedInTheFile) {
  // A bit flipped on disk inside a stored double (SQLite stores a REAL as 8 big-endian bytes):
  // SQLite's integrity check cannot see it, the content digest of its table does.
  const std::string path = write_small(temp_dir("db_verify_file_bit"));
  double value = 0.0;
  {
    detail::Connection connection(path, SQLITE_OPEN_READONLY, path);
    {
      detail::Statement select(connection, "SELECT tcp_y FROM robot_grasps WHERE id = 4", kEdit);
      ASSERT_TRUE(select.step());
      value = select.column_double(0);
    }
    connection.close();
  }
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  std::string big_endian(8, '\0');
  for (int i = 7; i >= 0; --i, bits >>= 8) big_endian[i] = static_cast<char>(bits & 0xff);
  std::string bytes = read_file(path);
  const auto at = occurrences(bytes, big_endian);
  ASSERT_EQ(at.size(), 1u) << "the value must be unique in the file";
  bytes[at[0] + 7] = static_cast<char>(bytes[at[0] + 7] ^ 1);
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  EXPECT_EQ(content_digest(path).size(), 64u) << "the file passes SQLite's integrity check";
  expect_input_error([&] { Database::open(path); },
                     {path + ": robot_grasps: expected the content digest stored when it was "
                             "written (meta.digest.robot_grasps = ",
                      rebuild(path)});
}

TEST(OpenVerification, MissingDigestInACurrentVersionFile) {
  const std::string path = write_small(temp_dir("db_verify_missing_digest"));
  edit(path, "DELETE FROM meta WHERE key = 'digest.robot_grasps'");
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": meta.digest.robot_grasps: expected the content digest of table "
                      "robot_grasps (a database of schema version 7 or later holds one per "
                      "table, written with it), got no such key; " +
                      rebuild(path)});
  // Without any digest (a version 6 file with its version number raised, say): meta's is the first.
  edit(path, "DELETE FROM meta WHERE key GLOB 'digest.*'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta.digest.meta: expected the content digest of table meta"});
}

TEST(OpenVerification, ComfortMapDigestIsCheckedWhenTheMapsAreRead) {
  const std::string path = write_small(temp_dir("db_verify_comfort"));
  flip_real(path, "comfort_maps", "coverage", 2);
  // Opened without the maps (as the planner does), the table is not read, so not checked...
  OpenOptions without;
  without.comfort_maps = false;
  const Database db = Database::open(path, without);
  // ...until the maps are read from the file.
  expect_input_error([&] { db.read_comfort_maps(); },
                     {path + ": comfort_maps: expected the content digest stored when it was "
                             "written (meta.digest.comfort_maps = ",
                      rebuild(path)});
  expect_input_error([&] { Database::open(path); },
                     {path + ": comfort_maps: expected the content digest"});
  // A storage class is checked either way.
  edit(path, "UPDATE comfort_maps SET coverage = 'full' WHERE id = 1");
  expect_input_error([&] { Database::open(path, without); },
                     {path + ": comfort_maps.coverage (id 1): expected a REAL"});
}

// Same records and seed: the same digests, whatever the creation time or the file; each table's
// digest changes with that table only; and none of them enters the content digest.
TEST(OpenVerification, DigestsAreDeterministicAndOutsideTheContentDigest) {
  const std::string dir = temp_dir("db_verify_deterministic");
  Sample a = make_sample();
  Sample b = make_sample();
  b.meta.created_at = "2031-01-01T00:00:00Z";
  write_sample(dir + "/a.db", a);
  write_sample(dir + "/b.db", b);
  const auto digests = stored_digests(dir + "/a.db");
  EXPECT_EQ(stored_digests(dir + "/b.db"), digests);
  EXPECT_EQ(content_digest(dir + "/a.db"), content_digest(dir + "/b.db"));

  Sample c = make_sample();
  c.parts[1].robot_grasps[2].quality = std::nextafter(c.parts[1].robot_grasps[2].quality, 2.0);
  write_sample(dir + "/c.db", c);
  const auto changed = stored_digests(dir + "/c.db");
  ASSERT_EQ(changed.size(), digests.size());
  for (std::size_t i = 0; i < digests.size(); ++i) {
    EXPECT_EQ(changed[i].second != digests[i].second, digests[i].first == "digest.robot_grasps")
        << digests[i].first;
  }

  // Removing the stored digests leaves the content digest as it was: it never covered them.
  const std::string before = content_digest(dir + "/a.db");
  edit(dir + "/a.db", "DELETE FROM meta WHERE key GLOB 'digest.*'");
  EXPECT_EQ(content_digest(dir + "/a.db"), before);
  edit(dir + "/a.db", "INSERT INTO meta (key, value) VALUES ('digest.parts', 'x')");
  EXPECT_EQ(content_digest(dir + "/a.db"), before);
}

// A version 6 file (the same tables but suction_deliveries, no digests): refused with the way out;
// migrated, it holds the digests the writer gives the same content, and opens.
TEST(OpenVerification, Version6FileIsMigratedWithItsDigests) {
  const std::string dir = temp_dir("db_verify_v6");
  Sample sample = make_sample();
  sample.parts[0].suction_deliveries.clear();  // a version 6 file cannot hold any
  const std::string path = dir + "/v6.db";
  write_sample(path, sample);  // its relays lose their repick arm with the column
  edit(path,
       "DROP TABLE suction_deliveries;"
       "ALTER TABLE table_regrasps DROP COLUMN repick_arm;" +
           regrasp_edges_before_v9_sql() + handover_candidates_before_v10_sql() +
           "DELETE FROM meta WHERE key GLOB 'digest.*';"
           "UPDATE meta SET value = '6' WHERE key = 'schema_version'");
  // This hila's writer for the same records: a version 6 regrasp is taken again by its own arm,
  // no edge's duration is estimated and no candidate takes a body.
  for (auto& r : sample.parts[0].table_regrasps) r.repick_arm = r.arm;
  clear_durations(sample);
  clear_bodies(sample);
  const std::string written = dir + "/written.db";
  write_sample(written, sample);
  expect_input_error([&] { Database::open(path); },
                     {path +
                      ": meta.schema_version: expected a database this hila reads (schema "
                      "version 10), got one written by schema version 6 (an older hila); " +
                      rebuild(path) + " (or migrate it in place with hila::db::migrate_in_place)"});
  migrate_in_place(path);
  EXPECT_NO_THROW(Database::open(path)) << "built by this hila: opens with the default options";
  EXPECT_EQ(stored_digests(path), stored_digests(written));
  EXPECT_EQ(content_digest(path), content_digest(written));
  // From then on it is verified like any other file.
  flip_real(path, "placements", "stability", 1);
  expect_input_error([&] { Database::open(path); },
                     {path + ": placements: expected the content digest stored when it was "
                             "written"});
}
