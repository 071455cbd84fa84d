#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <stdexcept>

#include "hila/db/database.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::test_data;
using namespace hila::test;
namespace fs = std::filesystem;

namespace {

// Every file in `dir`, to see that nothing (no temporary, no journal) is left behind.
std::vector<std::string> files_in(const std::string& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  std::sort(names.begin(), names.end());
  return names;
}

bool can_create_file_in(const std::string& dir) {
  const std::string probe = dir + "/probe";
  const bool created = static_cast<bool>(std::ofstream(probe));
  fs::remove(probe);
  return created;
}

}  // namespace

TEST(Writer, CommitCreatesTargetAndRemovesTemporary) {
  const std::string dir = temp_dir("db_writer_commit");
  const std::string target = dir + "/p.db";
  std::string temp;
  {
    DatabaseWriter writer(target);
    temp = writer.temporary_path();
    EXPECT_EQ(temp.rfind(target + ".tmp-", 0), 0u) << temp;
    EXPECT_TRUE(fs::exists(temp));
    EXPECT_FALSE(fs::exists(target)) << "nothing appears at the target before commit";
    writer.write_meta(make_sample().meta);
    writer.add_part(make_sample().parts[0].part);
    writer.commit();
  }
  EXPECT_TRUE(fs::exists(target));
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
  EXPECT_EQ(Database::open(target).parts().size(), 1u);
}

TEST(Writer, DestroyedWithoutCommitLeavesNoTemporaryAndTargetUntouched) {
  const std::string dir = temp_dir("db_writer_abort");
  const std::string target = dir + "/p.db";
  write_sample(target, make_sample());
  const std::string before = read_file(target);
  ASSERT_FALSE(before.empty());
  std::string temp;
  {
    DatabaseWriter writer(target);
    temp = writer.temporary_path();
    Sample other = make_sample(99);
    writer.write_meta(other.meta);
    const auto id = writer.add_part(other.parts[0].part);
    writer.add_robot_grasps(id, other.parts[0].robot_grasps);
    // No commit: as if an exception unwound the build.
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
  EXPECT_EQ(read_file(target), before) << "the previous database must be byte-identical";
}

TEST(Writer, ExceptionDuringBuildLeavesNoTrace) {
  const std::string dir = temp_dir("db_writer_throw");
  const std::string target = dir + "/p.db";
  EXPECT_THROW(
      {
        DatabaseWriter writer(target);
        writer.write_meta(make_sample().meta);
        throw std::runtime_error("planner failed");
      },
      std::runtime_error);
  EXPECT_TRUE(files_in(dir).empty());
}

TEST(Writer, CommitReplacesAnExistingDatabase) {
  const std::string dir = temp_dir("db_writer_replace");
  const std::string target = dir + "/p.db";
  Sample first = make_sample();
  write_sample(target, first);
  Sample second = make_sample();
  second.parts.pop_back();
  second.meta.product_name = "second";
  write_sample(target, second);
  const Database db = Database::open(target);
  EXPECT_EQ(db.meta().product_name, "second");
  EXPECT_EQ(db.parts().size(), 1u);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"p.db"});
}

TEST(Writer, IdsAreAssignedInOrderIgnoringRecordIds) {
  const std::string target = temp_dir("db_writer_ids") + "/p.db";
  DatabaseWriter writer(target);
  writer.write_meta(make_sample().meta);
  PartRecord a;
  a.name = "a";
  a.id = 77;
  a.mass = 1.0;
  PartRecord b;
  b.name = "b";
  b.id = -5;
  b.mass = 2.0;
  EXPECT_EQ(writer.add_part(a), 1);
  EXPECT_EQ(writer.add_part(b), 2);
  RobotGraspRecord g;
  g.part_id = 1;  // ignored: the argument decides
  g.id = 1000;
  writer.add_robot_grasps(2, {g});
  writer.commit();
  const Database db = Database::open(target);
  ASSERT_EQ(db.robot_grasps(2).size(), 1u);
  EXPECT_EQ(db.robot_grasps(2)[0].id, 1);
  EXPECT_TRUE(db.robot_grasps(1).empty());
}

TEST(Writer, DuplicatePartNameFailsAndTheWriterThenRefusesToCommit) {
  const std::string dir = temp_dir("db_writer_duplicate");
  const std::string target = dir + "/p.db";
  DatabaseWriter writer(target);
  writer.write_meta(make_sample().meta);
  PartRecord part;
  part.name = "door";
  part.mass = 1.0;
  writer.add_part(part);
  expect_input_error([&] { writer.add_part(part); },
                     {target, "parts (part 'door')", "UNIQUE constraint failed: parts.name"});
  EXPECT_THROW(writer.commit(), std::logic_error);
  EXPECT_FALSE(fs::exists(target));
}

TEST(Writer, RecordsForAnUnknownPartAreRefused) {
  const std::string target = temp_dir("db_writer_fk") + "/p.db";
  DatabaseWriter writer(target);
  writer.write_meta(make_sample().meta);
  expect_input_error([&] { writer.add_human_grasps(3, {HumanGraspRecord{}}); },
                     {target, "human_grasps (part id 3)", "FOREIGN KEY constraint failed"});
}

TEST(Writer, NanValueIsRefusedWithAHint) {
  const std::string target = temp_dir("db_writer_nan") + "/p.db";
  DatabaseWriter writer(target);
  writer.write_meta(make_sample().meta);
  const auto id = writer.add_part(make_sample().parts[0].part);
  SuctionGraspRecord g;
  g.force_margin = std::nan("");
  expect_input_error([&] { writer.add_suction_grasps(id, {g}); },
                     {target, "suction_grasps", "suction_grasps.force_margin", "NaN"});
}

TEST(Writer, ComfortMapWithWrongSizesOrValuesIsInvalidArgument) {
  const std::string dir = temp_dir("db_writer_comfort_invalid");
  const ComfortMapRecord good = make_comfort_map("right", 3, {3, 2, 2}, 5);
  // Each case on a fresh writer: a failed call makes the writer refuse to commit.
  const auto refused = [&](const std::string& name,
                           const std::function<void(ComfortMapRecord&)>& change,
                           const std::string& fragment) {
    SCOPED_TRACE(name);
    ComfortMapRecord map = good;
    change(map);
    DatabaseWriter writer(dir + "/p.db");
    writer.write_meta(make_sample().meta);
    try {
      writer.add_comfort_map(map);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
    EXPECT_THROW(writer.commit(), std::logic_error);
  };
  refused(
      "empty arm", [](ComfortMapRecord& m) { m.arm.clear(); }, "empty arm name");
  refused(
      "zero spacing", [](ComfortMapRecord& m) { m.spacing = 0.0; }, "spacing");
  refused(
      "NaN spacing", [](ComfortMapRecord& m) { m.spacing = std::nan(""); }, "spacing");
  refused(
      "infinite origin",
      [](ComfortMapRecord& m) { m.origin.x() = std::numeric_limits<double>::infinity(); },
      "origin");
  refused(
      "zero dimension", [](ComfortMapRecord& m) { m.dims.z() = 0; }, "3 x 2 x 0");
  refused(
      "negative dimension", [](ComfortMapRecord& m) { m.dims.x() = -3; }, "dims");
  refused(
      "a value too many", [](ComfortMapRecord& m) { m.values.push_back(0); },
      "values must hold dims.prod() * orientations.size() = 3 * 2 * 2 * 5 = 60 bytes, got 61");
  refused(
      "a value too few", [](ComfortMapRecord& m) { m.values.pop_back(); }, "got 59");
  refused(
      "an orientation too many",
      [](ComfortMapRecord& m) { m.orientations.push_back(Eigen::Quaterniond::Identity()); },
      "= 72 bytes, got 60");
  refused(
      "dims swapped for a wrong total",
      [](ComfortMapRecord& m) {
        m.dims = {3, 2, 3};
      },
      "= 90 bytes");
  refused(
      "non-unit orientation", [](ComfortMapRecord& m) { m.orientations[3].coeffs() *= 1.0 + 1e-8; },
      "orientation 3 is not a unit quaternion");
  refused(
      "NaN orientation", [](ComfortMapRecord& m) { m.orientations[0].w() = std::nan(""); },
      "orientation 0");
  // Within the tolerance is fine.
  ComfortMapRecord close = good;
  close.orientations[0].coeffs() *= 1.0 + 1e-12;
  DatabaseWriter writer(dir + "/p.db");
  writer.write_meta(make_sample().meta);
  EXPECT_NO_THROW(writer.add_comfort_map(close));
  writer.commit();
  EXPECT_EQ(Database::open(dir + "/p.db").comfort_maps().size(), 1u);
}

TEST(Writer, DuplicateArmFailsAndTheWriterThenRefusesToCommit) {
  const std::string dir = temp_dir("db_writer_comfort_duplicate");
  const std::string target = dir + "/p.db";
  DatabaseWriter writer(target);
  writer.write_meta(make_sample().meta);
  writer.add_comfort_map(make_comfort_map("left", 1, {2, 2, 2}, 3));
  writer.add_comfort_map(make_comfort_map("right", 2, {2, 2, 2}, 3));
  expect_input_error(
      [&] {
        writer.add_comfort_map(make_comfort_map("left", 3, {3, 3, 3}, 4));
      },
      {target, "comfort_maps (arm 'left')", "UNIQUE constraint failed: comfort_maps.arm"});
  EXPECT_THROW(writer.commit(), std::logic_error);
  EXPECT_FALSE(fs::exists(target));
}

TEST(Writer, MisuseIsALogicError) {
  const std::string dir = temp_dir("db_writer_misuse");
  {
    DatabaseWriter writer(dir + "/no_meta.db");
    writer.add_part(make_sample().parts[0].part);
    EXPECT_THROW(writer.commit(), std::logic_error) << "a database without meta cannot be opened";
  }
  EXPECT_FALSE(fs::exists(dir + "/no_meta.db"));
  DatabaseWriter writer(dir + "/p.db");
  writer.write_meta(make_sample().meta);
  writer.commit();
  EXPECT_THROW(writer.add_part(PartRecord{}), std::logic_error);
  EXPECT_THROW(writer.commit(), std::logic_error);
  EXPECT_TRUE(fs::exists(dir + "/p.db")) << "the committed database stays";
}

TEST(Writer, EmptyCreatedAtIsFilledSchemaVersionIsSet) {
  const std::string target = temp_dir("db_writer_meta") + "/p.db";
  Meta meta = make_sample().meta;
  meta.created_at.clear();
  meta.schema_version = 12345;  // ignored: the writer writes its own version
  {
    DatabaseWriter writer(target);
    writer.write_meta(meta);
    writer.commit();
  }
  const Database db = Database::open(target);
  EXPECT_EQ(db.meta().schema_version, current_schema_version());
  const std::string& created = db.meta().created_at;
  ASSERT_EQ(created.size(), 20u) << created;  // 2024-06-11T10:00:00Z
  EXPECT_EQ(created[4], '-');
  EXPECT_EQ(created[10], 'T');
  EXPECT_EQ(created.back(), 'Z');
}

TEST(Writer, MissingTargetDirectoryIsNamed) {
  const std::string dir = temp_dir("db_writer_nodir") + "/missing";
  expect_input_error([&] { DatabaseWriter writer(dir + "/p.db"); },
                     {dir, "expected a writable directory", "no such directory"});
  EXPECT_FALSE(fs::exists(dir));
}

TEST(Writer, ReadOnlyTargetDirectory) {
  const std::string dir = temp_dir("db_writer_readonly");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                           fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  if (can_create_file_in(dir)) {
    // Root ignores 0555: the directory is in fact writable, so the writer must work normally.
    // (The refusal is asserted when the suite runs as an ordinary user.)
    write_sample(dir + "/p.db", make_sample());
    EXPECT_EQ(Database::open(dir + "/p.db").parts().size(), 2u);
  } else {
    expect_input_error([&] { DatabaseWriter writer(dir + "/p.db"); },
                       {dir, "expected a writable directory", "without write permission"});
    EXPECT_TRUE(files_in(dir).empty());
  }
  fs::permissions(dir, fs::perms::owner_all);
}

TEST(Writer, BareFileNameWritesIntoTheCurrentDirectory) {
  const std::string dir = temp_dir("db_writer_cwd");
  const fs::path previous = fs::current_path();
  fs::current_path(dir);
  try {
    write_sample("bare.db", make_sample());
  } catch (...) {
    fs::current_path(previous);
    throw;
  }
  fs::current_path(previous);
  EXPECT_EQ(files_in(dir), std::vector<std::string>{"bare.db"});
}
