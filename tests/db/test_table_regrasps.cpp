// The schema version 6 table table_regrasps (with repick_arm since version 8) through
// DatabaseWriter and Database.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <stdexcept>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::test_data;
using namespace hila::test;

namespace {

// Joint vectors are BLOBs of doubles: they come back bit for bit, -0.0 included.
void expect_same_joints(const Eigen::VectorXd& got, const Eigen::VectorXd& want) {
  ASSERT_EQ(got.size(), want.size());
  for (Eigen::Index i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i], want[i]) << i;
    EXPECT_EQ(std::signbit(got[i]), std::signbit(want[i])) << i;
  }
}

// The placement's position is stored as three REAL columns (exact); its rotation as a unit
// quaternion (to rounding).
void expect_same(const TableRegraspRecord& got, const TableRegraspRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.candidate_id, want.candidate_id);
  EXPECT_EQ(got.pick_grasp_id, want.pick_grasp_id);
  EXPECT_EQ(got.robot_grasp_id, want.robot_grasp_id);
  EXPECT_EQ(got.arm, want.arm);
  EXPECT_EQ(got.repick_arm, want.repick_arm);
  EXPECT_EQ(got.placement.translation(), want.placement.translation());
  EXPECT_LT(pose_error(got.placement, want.placement), 1e-12);
  {
    SCOPED_TRACE("joints_pick");
    expect_same_joints(got.joints_pick, want.joints_pick);
  }
  {
    SCOPED_TRACE("joints_place");
    expect_same_joints(got.joints_place, want.joints_place);
  }
  {
    SCOPED_TRACE("joints_repick");
    expect_same_joints(got.joints_repick, want.joints_repick);
  }
  {
    SCOPED_TRACE("joints_rh");
    expect_same_joints(got.joints_rh, want.joints_rh);
  }
  EXPECT_EQ(got.inclination_pick_deg, want.inclination_pick_deg);
  EXPECT_EQ(got.inclination_place_deg, want.inclination_place_deg);
  EXPECT_EQ(got.inclination_repick_deg, want.inclination_repick_deg);
  EXPECT_EQ(got.inclination_rh_deg, want.inclination_rh_deg);
}

// A writer at `path` with the sample's meta, parts (with their grasps) and part 1's candidates
// written, so table regrasps have candidates and robot grasps to refer to.
struct Fixture {
  Sample sample = make_sample();
  std::unique_ptr<DatabaseWriter> writer;

  explicit Fixture(const std::string& path) : writer(std::make_unique<DatabaseWriter>(path)) {
    writer->write_meta(sample.meta);
    for (const auto& p : sample.parts) {
      const auto id = writer->add_part(p.part);
      writer->add_robot_grasps(id, p.robot_grasps);
      writer->add_suction_grasps(id, p.suction_grasps);
      writer->add_human_grasps(id, p.human_grasps);
    }
    writer->add_handover_candidates(1, sample.parts[0].handover_candidates);
  }
};

}  // namespace

TEST(TableRegrasps, EveryFieldRoundTripsPerCandidateInIdOrder) {
  const std::string path = temp_dir("db_table_regrasps_round_trip") + "/p.db";
  const Sample sample = make_sample();
  write_sample(path, sample);
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);

  const auto& written = sample.parts[0].table_regrasps;
  ASSERT_EQ(written.size(), 5u);
  std::size_t total = 0;
  for (const auto& part : sample.parts) {
    for (const auto& c : part.handover_candidates) {
      SCOPED_TRACE(c.id);
      std::vector<TableRegraspRecord> want;
      for (const auto& r : written) {
        if (r.candidate_id == c.id) want.push_back(r);
      }
      const auto got = db.table_regrasps(c.id);
      ASSERT_EQ(got.size(), want.size());
      for (std::size_t i = 0; i < want.size(); ++i) expect_same(got[i], want[i]);
      total += got.size();
    }
  }
  EXPECT_EQ(total, written.size()) << "every regrasp belongs to exactly one candidate";

  // The goals' regrasps were written interleaved (candidates 5, 2, 4, 2, 5): each candidate gets
  // its own, in id order.
  const auto ids = [&](std::int64_t candidate) {
    std::vector<std::int64_t> out;
    for (const auto& r : db.table_regrasps(candidate)) out.push_back(r.id);
    return out;
  };
  EXPECT_EQ(ids(2), (std::vector<std::int64_t>{2, 4}));
  EXPECT_EQ(ids(4), (std::vector<std::int64_t>{3}));
  EXPECT_EQ(ids(5), (std::vector<std::int64_t>{1, 5}));
  EXPECT_TRUE(db.table_regrasps(1).empty()) << "not a goal";
  EXPECT_TRUE(db.table_regrasps(7).empty()) << "part 2 has none";
  EXPECT_TRUE(db.table_regrasps(0).empty());
  EXPECT_TRUE(db.table_regrasps(99).empty());

  // The awkward values, spelled out.
  const auto five = db.table_regrasps(5);
  ASSERT_EQ(five.size(), 2u);
  EXPECT_TRUE(std::signbit(five[0].joints_place[3])) << "-0.0 survives in a blob";
  EXPECT_EQ(five[0].joints_place[3], 0.0);
  EXPECT_EQ(five[0].joints_repick[0], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(five[0].inclination_pick_deg, 0.0);
  EXPECT_EQ(five[1].joints_pick[2], -std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(std::signbit(five[1].joints_rh[5]));
  EXPECT_EQ(five[1].inclination_repick_deg, 89.999999999999986);
  EXPECT_EQ(five[1].inclination_place_deg, 17.5 * 4 + 1e-13 + 1.5);
  EXPECT_EQ(five[1].inclination_rh_deg, 17.5 * 4 + 1e-13 + 4.0);
  EXPECT_EQ(five[0].arm, "left");
  EXPECT_EQ(five[0].repick_arm, "left") << "set down and taken again by the same arm";
  EXPECT_EQ(five[1].arm, "left");
  EXPECT_EQ(five[1].repick_arm, "right") << "a relay: the other arm takes it again";
  const auto two = db.table_regrasps(2);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].pick_grasp_id, 4);
  EXPECT_EQ(two[0].robot_grasp_id, 4) << "set down and taken again with the same grasp";
  EXPECT_EQ(two[0].arm, "right");
  EXPECT_EQ(two[0].repick_arm, "left") << "a relay the other way";
  EXPECT_EQ(two[0].placement.translation(), Eigen::Vector3d(0.5, -0.25, 0.0625));
  EXPECT_EQ(two[0].placement.linear(),
            Eigen::Vector3d(-1.0, -1.0, 1.0).asDiagonal().toDenseMatrix())
      << "a half turn about the vertical, exactly";
  EXPECT_EQ(two[1].pick_grasp_id, 3);
  EXPECT_EQ(two[1].robot_grasp_id, 5);
  EXPECT_EQ(two[1].arm, "left ✋");
  EXPECT_EQ(two[1].repick_arm, "left ✋");
  const auto four = db.table_regrasps(4);
  ASSERT_EQ(four.size(), 1u);
  EXPECT_EQ(four[0].repick_arm, "left");
  EXPECT_EQ(four[0].joints_place.size(), 0) << "an empty vector stays empty";
  EXPECT_EQ(four[0].joints_repick.size(), 0);
  EXPECT_EQ(four[0].joints_pick.size(), 6);
  EXPECT_EQ(four[0].joints_rh.size(), 6);
  EXPECT_EQ(four[0].placement.translation().y(), std::numeric_limits<double>::denorm_min());

  // The direct grasps of the same goals are a table of their own, unchanged.
  std::size_t direct = 0;
  for (const auto& c : sample.parts[0].handover_candidates) direct += db.direct_grasps(c.id).size();
  EXPECT_EQ(direct, sample.parts[0].direct_grasps.size());
}

TEST(TableRegrasps, IdsContinueAcrossCallsWhateverTheRecordsSay) {
  const std::string path = temp_dir("db_table_regrasps_ids") + "/p.db";
  {
    Fixture f(path);
    TableRegraspRecord r;
    r.id = 42;  // ignored: the database assigns ids
    r.candidate_id = 4;
    r.pick_grasp_id = 3;
    r.robot_grasp_id = 2;
    r.arm = "left";
    r.repick_arm = "right";
    f.writer->add_table_regrasps({r, r});
    f.writer->add_table_regrasps({});
    r.candidate_id = 2;
    r.pick_grasp_id = 8;   // a grasp of part 2: any written robot grasp may be referred to
    r.robot_grasp_id = 9;  // likewise
    f.writer->add_table_regrasps({r});
    f.writer->commit();
  }
  const Database db = Database::open(path);
  const auto four = db.table_regrasps(4);
  ASSERT_EQ(four.size(), 2u);
  EXPECT_EQ(four[0].id, 1);
  EXPECT_EQ(four[1].id, 2);
  EXPECT_EQ(four[1].pick_grasp_id, 3);
  EXPECT_EQ(four[1].robot_grasp_id, 2);
  EXPECT_EQ(four[1].arm, "left");
  EXPECT_EQ(four[1].repick_arm, "right");
  const auto two = db.table_regrasps(2);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].id, 3);
  EXPECT_EQ(two[0].pick_grasp_id, 8);
  EXPECT_EQ(two[0].robot_grasp_id, 9);
  EXPECT_TRUE(two[0].placement.isApprox(hila::core::Pose::Identity())) << "the default placement";
  EXPECT_EQ(two[0].joints_pick.size(), 0);
  EXPECT_EQ(two[0].joints_place.size(), 0);
  EXPECT_EQ(two[0].joints_repick.size(), 0);
  EXPECT_EQ(two[0].joints_rh.size(), 0);
}

TEST(TableRegrasps, MistakesAreInvalidArgumentsNamingTableColumnAndRecord) {
  const std::string dir = temp_dir("db_table_regrasps_invalid");
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  // Each case on a fresh writer: a failed call makes the writer refuse to commit.
  const auto refused = [&](const std::string& name,
                           const std::function<void(std::vector<TableRegraspRecord>&)>& change,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(dir + "/p.db");
    auto records = f.sample.parts[0].table_regrasps;
    change(records);
    try {
      f.writer->add_table_regrasps(records);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      for (const auto& fragment : fragments) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
            << "missing '" << fragment << "' in: " << e.what();
      }
    }
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  refused("empty arm", [](auto& r) { r[2].arm.clear(); },
          {"DatabaseWriter::add_table_regrasps: table_regrasps.arm (record 2 of 5, candidate id "
           "4): TableRegraspRecord::arm is empty, expected an arm name"});
  refused("empty repick arm", [](auto& r) { r[3].repick_arm.clear(); },
          {"DatabaseWriter::add_table_regrasps: table_regrasps.repick_arm (record 3 of 5, "
           "candidate id 2): TableRegraspRecord::repick_arm is empty, expected an arm name"});
  // Refused before anything is written: an earlier record that would fail its foreign key on
  // insertion is not reached.
  refused("empty repick arm after an unknown candidate",
          [](auto& r) {
            r[0].candidate_id = 99;
            r[4].repick_arm.clear();
          },
          {"table_regrasps.repick_arm (record 4 of 5, candidate id 5): TableRegraspRecord::"
           "repick_arm is empty"});
  refused("NaN pick inclination", [&](auto& r) { r[4].inclination_pick_deg = nan; },
          {"DatabaseWriter::add_table_regrasps: table_regrasps.inclination_pick_deg (record 4 of "
           "5, candidate id 5) must be finite, got nan"});
  refused("infinite place inclination", [&](auto& r) { r[1].inclination_place_deg = inf; },
          {"table_regrasps.inclination_place_deg (record 1 of 5, candidate id 2)", "got inf"});
  refused("NaN repick inclination", [&](auto& r) { r[0].inclination_repick_deg = nan; },
          {"table_regrasps.inclination_repick_deg (record 0 of 5, candidate id 5)", "got nan"});
  refused("infinite robot-human inclination", [&](auto& r) { r[3].inclination_rh_deg = -inf; },
          {"table_regrasps.inclination_rh_deg (record 3 of 5, candidate id 2)", "got -inf"});
  refused("NaN pick joint", [&](auto& r) { r[0].joints_pick[4] = nan; },
          {"table_regrasps.joints_pick[4] (record 0 of 5, candidate id 5)", "got nan"});
  refused("infinite place joint", [&](auto& r) { r[3].joints_place[1] = -inf; },
          {"table_regrasps.joints_place[1] (record 3 of 5, candidate id 2)", "got -inf"});
  refused("NaN repick joint", [&](auto& r) { r[1].joints_repick[5] = nan; },
          {"table_regrasps.joints_repick[5] (record 1 of 5, candidate id 2)", "got nan"});
  refused("infinite robot-human joint", [&](auto& r) { r[2].joints_rh[0] = inf; },
          {"table_regrasps.joints_rh[0] (record 2 of 5, candidate id 4)", "got inf"});
  refused("infinite placement position", [&](auto& r) { r[4].placement.translation().z() = -inf; },
          {"DatabaseWriter::add_table_regrasps: table_regrasps.placement_z (record 4 of 5, "
           "candidate id 5) must be finite, got -inf"});
  refused("NaN placement position", [&](auto& r) { r[0].placement.translation().x() = nan; },
          {"table_regrasps.placement_x (record 0 of 5, candidate id 5)", "got nan"});
  refused("NaN placement rotation", [&](auto& r) { r[2].placement.linear()(1, 1) = nan; },
          {"table_regrasps.placement_q", "(record 2 of 5, candidate id 4) must be finite"});
  // Every record is checked, in record order, before any is written: the first bad one is named.
  refused("two mistakes",
          [&](auto& r) {
            r[1].joints_rh[2] = nan;
            r[3].arm.clear();
          },
          {"table_regrasps.joints_rh[2] (record 1 of 5"});
}

TEST(TableRegrasps, ARefusedCallFailsTheWriterAndLeavesNoFile) {
  // One bad record (the last) refuses the whole call; the writer then refuses to commit and
  // leaves no file behind.
  const std::string dir = temp_dir("db_table_regrasps_nothing");
  const std::string path = dir + "/p.db";
  {
    Fixture f(path);
    auto records = f.sample.parts[0].table_regrasps;
    records.back().joints_rh[0] = std::nan("");
    EXPECT_THROW(f.writer->add_table_regrasps(records), std::invalid_argument);
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(TableRegrasps, UnknownReferencesAreDatabaseErrors) {
  const std::string dir = temp_dir("db_table_regrasps_references");
  const std::string target = dir + "/p.db";
  const auto refused = [&](const std::string& name, const TableRegraspRecord& r,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(target);
    expect_input_error([&] { f.writer->add_table_regrasps({r}); }, fragments);
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  TableRegraspRecord r = make_sample().parts[0].table_regrasps[2];
  ASSERT_EQ(r.candidate_id, 4);
  ASSERT_EQ(r.pick_grasp_id, 1);
  ASSERT_EQ(r.robot_grasp_id, 2);
  r.candidate_id = 10;  // part 1's six candidates are written, part 2's are not
  refused(
      "unknown candidate", r,
      {target, "table_regrasps (candidate id 10, pick grasp id 1, robot grasp id 2, arm 'left')",
       "FOREIGN KEY constraint failed"});
  r.candidate_id = 4;
  r.pick_grasp_id = 10;  // the sample has 5 + 4
  refused("unknown pick grasp", r,
          {target, "table_regrasps (candidate id 4, pick grasp id 10, robot grasp id 2",
           "FOREIGN KEY constraint failed"});
  r.pick_grasp_id = 0;
  refused("pick grasp id 0", r,
          {target, "table_regrasps (candidate id 4, pick grasp id 0,",
           "FOREIGN KEY constraint failed"});
  r.pick_grasp_id = 1;
  r.robot_grasp_id = 10;
  refused(
      "unknown robot grasp", r,
      {target, "table_regrasps (candidate id 4, pick grasp id 1, robot grasp id 10, arm 'left')",
       "FOREIGN KEY constraint failed"});
  // The same record with known references is written.
  r.robot_grasp_id = 9;
  Fixture f(target);
  f.writer->add_table_regrasps({r});
  f.writer->commit();
  const auto four = Database::open(target).table_regrasps(4);
  ASSERT_EQ(four.size(), 1u);
  EXPECT_EQ(four[0].pick_grasp_id, 1);
  EXPECT_EQ(four[0].robot_grasp_id, 9);
}

TEST(TableRegrasps, DamagedRowsAreDatabaseErrors) {
  const std::string path = temp_dir("db_table_regrasps_damaged") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  detail::execute_script(path,
                         "UPDATE table_regrasps SET joints_place = x'0001020304' WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path + ": table_regrasps.joints_place (id 2)",
                      "expected finite joint values as little-endian doubles (8 bytes each)",
                      "got 5 bytes", "rebuild with: hila build meshes/cabinet/product.yaml"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A NaN (little-endian 0x7ff8000000000000) in a blob the writer would have refused.
  detail::execute_script(
      path, "UPDATE table_regrasps SET joints_repick = x'000000000000f87f' WHERE id = 5");
  expect_input_error([&] { Database::open(path); },
                     {"table_regrasps.joints_repick (id 5)", "got a value that is not finite"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A repick arm that is not text.
  detail::execute_script(path, "UPDATE table_regrasps SET repick_arm = x'6c656674' WHERE id = 4");
  expect_input_error([&] { Database::open(path); },
                     {path + ": table_regrasps.repick_arm (id 4): expected a TEXT (the column is "
                             "TEXT NOT NULL), got a BLOB of 4 bytes"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A placement that is not a rotation.
  detail::execute_script(path, "UPDATE table_regrasps SET placement_qw = 2.0 WHERE id = 3");
  expect_input_error([&] { Database::open(path); },
                     {"table_regrasps.placement (id 3)", "a unit quaternion"});
}

TEST(TableRegrasps, ACurrentFileWithoutTheTableIsRefused) {
  // The reader reads the table: a current file that lacks it (damaged by hand) cannot open.
  const std::string path = temp_dir("db_table_regrasps_missing") + "/p.db";
  write_sample(path, make_sample());
  detail::execute_script(path, "DROP TABLE table_regrasps");
  expect_input_error(
      [&] { Database::open(path); },
      {path + ": table_regrasps: expected a readable hila table", "no such table: table_regrasps"});
}

TEST(TableRegrasps, ACurrentFileWithoutRepickArmIsRefused) {
  // A current file whose table lacks the column (a version 7 table with a current version
  // number, or damaged by hand) cannot open; a version 7 file is migrated instead (test_migration).
  const std::string path = temp_dir("db_table_regrasps_no_repick_arm") + "/p.db";
  write_sample(path, make_sample());
  detail::execute_script(path, "ALTER TABLE table_regrasps DROP COLUMN repick_arm");
  expect_input_error([&] { Database::open(path); },
                     {path + ": table_regrasps: expected a readable hila table",
                      "no such column: repick_arm", "rebuild with: hila build"});
}

TEST(TableRegrasps, EmptyTableOpens) {
  const std::string path = temp_dir("db_table_regrasps_empty") + "/p.db";
  {
    Fixture f(path);
    f.writer->commit();
  }
  const Database db = Database::open(path);
  ASSERT_EQ(db.handover_candidates(1).size(), 6u);
  for (const auto& c : db.handover_candidates(1)) EXPECT_TRUE(db.table_regrasps(c.id).empty());
}
