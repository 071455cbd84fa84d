// The schema version 8 table suction_deliveries through DatabaseWriter and Database.

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

void expect_same(const SuctionDeliveryRecord& got, const SuctionDeliveryRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.candidate_id, want.candidate_id);
  EXPECT_EQ(got.suction_grasp_id, want.suction_grasp_id);
  EXPECT_EQ(got.arm, want.arm);
  SCOPED_TRACE("joints_rh");
  expect_same_joints(got.joints_rh, want.joints_rh);
}

// A writer at `path` with the sample's meta, parts (with their grasps) and part 1's candidates
// written, so suction deliveries have candidates and suction grasps to refer to.
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

TEST(SuctionDeliveries, EveryFieldRoundTripsPerCandidateInIdOrder) {
  const std::string path = temp_dir("db_suction_deliveries_round_trip") + "/p.db";
  const Sample sample = make_sample();
  write_sample(path, sample);
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);

  const auto& written = sample.parts[0].suction_deliveries;
  ASSERT_EQ(written.size(), 5u);
  EXPECT_TRUE(sample.parts[1].suction_deliveries.empty()) << "part 2 has no suction grasps";
  std::size_t total = 0;
  for (const auto& part : sample.parts) {
    for (const auto& c : part.handover_candidates) {
      SCOPED_TRACE(c.id);
      std::vector<SuctionDeliveryRecord> want;
      for (const auto& d : written) {
        if (d.candidate_id == c.id) want.push_back(d);
      }
      const auto got = db.suction_deliveries(c.id);
      ASSERT_EQ(got.size(), want.size());
      for (std::size_t i = 0; i < want.size(); ++i) expect_same(got[i], want[i]);
      total += got.size();
    }
  }
  EXPECT_EQ(total, written.size()) << "every delivery belongs to exactly one candidate";

  // The goals' deliveries were written interleaved (candidates 4, 5, 4, 2, 5): each candidate
  // gets its own, in id order.
  const auto ids = [&](std::int64_t candidate) {
    std::vector<std::int64_t> out;
    for (const auto& d : db.suction_deliveries(candidate)) out.push_back(d.id);
    return out;
  };
  EXPECT_EQ(ids(2), (std::vector<std::int64_t>{4}));
  EXPECT_EQ(ids(4), (std::vector<std::int64_t>{1, 3}));
  EXPECT_EQ(ids(5), (std::vector<std::int64_t>{2, 5}));
  EXPECT_TRUE(db.suction_deliveries(1).empty()) << "not a goal";
  EXPECT_TRUE(db.suction_deliveries(7).empty()) << "part 2 has none";
  EXPECT_TRUE(db.suction_deliveries(0).empty());
  EXPECT_TRUE(db.suction_deliveries(99).empty());

  // The awkward values, spelled out.
  const auto four = db.suction_deliveries(4);
  ASSERT_EQ(four.size(), 2u);
  EXPECT_EQ(four[0].suction_grasp_id, 1);
  EXPECT_EQ(four[0].arm, "right");
  ASSERT_EQ(four[0].joints_rh.size(), 6);
  EXPECT_EQ(four[0].joints_rh[1], 0.0);
  EXPECT_TRUE(std::signbit(four[0].joints_rh[1])) << "-0.0 survives in a blob";
  EXPECT_EQ(four[1].suction_grasp_id, 1);
  EXPECT_EQ(four[1].arm, "left");
  EXPECT_EQ(four[1].joints_rh.size(), 0) << "an empty vector stays empty";
  const auto five = db.suction_deliveries(5);
  ASSERT_EQ(five.size(), 2u);
  EXPECT_EQ(five[0].suction_grasp_id, 2);
  EXPECT_EQ(five[1].suction_grasp_id, 1);
  EXPECT_EQ(five[1].arm, "right ✋");
  ASSERT_EQ(five[1].joints_rh.size(), 6);
  EXPECT_EQ(five[1].joints_rh[5], std::numeric_limits<double>::denorm_min());
  const auto two = db.suction_deliveries(2);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].suction_grasp_id, 2);
  EXPECT_EQ(two[0].joints_rh.size(), 7) << "an arm of seven joints";

  // The other ways of the same goals are tables of their own, unchanged.
  std::size_t direct = 0;
  std::size_t regrasps = 0;
  for (const auto& c : sample.parts[0].handover_candidates) {
    direct += db.direct_grasps(c.id).size();
    regrasps += db.table_regrasps(c.id).size();
  }
  EXPECT_EQ(direct, sample.parts[0].direct_grasps.size());
  EXPECT_EQ(regrasps, sample.parts[0].table_regrasps.size());
}

TEST(SuctionDeliveries, IdsContinueAcrossCallsWhateverTheRecordsSay) {
  const std::string path = temp_dir("db_suction_deliveries_ids") + "/p.db";
  {
    Fixture f(path);
    SuctionDeliveryRecord d;
    d.id = 42;  // ignored: the database assigns ids
    d.candidate_id = 4;
    d.suction_grasp_id = 2;
    d.arm = "right";
    d.joints_rh = Eigen::Vector2d(0.5, -1.0);
    f.writer->add_suction_deliveries({d, d});
    f.writer->add_suction_deliveries({});
    d.candidate_id = 5;
    d.suction_grasp_id = 1;
    d.joints_rh = Eigen::VectorXd();
    f.writer->add_suction_deliveries({d});
    f.writer->commit();
  }
  const Database db = Database::open(path);
  const auto four = db.suction_deliveries(4);
  ASSERT_EQ(four.size(), 2u);
  EXPECT_EQ(four[0].id, 1);
  EXPECT_EQ(four[1].id, 2);
  EXPECT_EQ(four[1].suction_grasp_id, 2);
  EXPECT_EQ(four[1].joints_rh, Eigen::Vector2d(0.5, -1.0));
  const auto five = db.suction_deliveries(5);
  ASSERT_EQ(five.size(), 1u);
  EXPECT_EQ(five[0].id, 3);
  EXPECT_EQ(five[0].suction_grasp_id, 1);
  EXPECT_EQ(five[0].arm, "right");
  EXPECT_EQ(five[0].joints_rh.size(), 0);
}

TEST(SuctionDeliveries, MistakesAreInvalidArgumentsNamingTableColumnAndRecord) {
  const std::string dir = temp_dir("db_suction_deliveries_invalid");
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  // Each case on a fresh writer: a failed call makes the writer refuse to commit.
  const auto refused = [&](const std::string& name,
                           const std::function<void(std::vector<SuctionDeliveryRecord>&)>& change,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(dir + "/p.db");
    auto records = f.sample.parts[0].suction_deliveries;
    change(records);
    try {
      f.writer->add_suction_deliveries(records);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      for (const auto& fragment : fragments) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
            << "missing '" << fragment << "' in: " << e.what();
      }
    }
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  refused("empty arm", [](auto& r) { r[1].arm.clear(); },
          {"DatabaseWriter::add_suction_deliveries: suction_deliveries.arm (record 1 of 5, "
           "candidate id 5): SuctionDeliveryRecord::arm is empty, expected an arm name"});
  refused("NaN robot-human joint", [&](auto& r) { r[3].joints_rh[6] = nan; },
          {"DatabaseWriter::add_suction_deliveries: suction_deliveries.joints_rh[6] (record 3 of "
           "5, candidate id 2) must be finite, got nan"});
  refused("infinite robot-human joint", [&](auto& r) { r[0].joints_rh[0] = inf; },
          {"suction_deliveries.joints_rh[0] (record 0 of 5, candidate id 4)", "got inf"});
  refused("negative infinite robot-human joint", [&](auto& r) { r[4].joints_rh[2] = -inf; },
          {"suction_deliveries.joints_rh[2] (record 4 of 5, candidate id 5)", "got -inf"});
  // Every record is checked, in record order, before any is written: the first bad one is named.
  refused("two mistakes",
          [&](auto& r) {
            r[1].joints_rh[3] = nan;
            r[3].arm.clear();
          },
          {"suction_deliveries.joints_rh[3] (record 1 of 5"});
}

TEST(SuctionDeliveries, ARefusedCallFailsTheWriterAndLeavesNoFile) {
  // One bad record (the last) refuses the whole call; the writer then refuses to commit and
  // leaves no file behind.
  const std::string dir = temp_dir("db_suction_deliveries_nothing");
  const std::string path = dir + "/p.db";
  {
    Fixture f(path);
    auto records = f.sample.parts[0].suction_deliveries;
    records.back().arm.clear();
    EXPECT_THROW(f.writer->add_suction_deliveries(records), std::invalid_argument);
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(SuctionDeliveries, UnknownReferencesAreDatabaseErrors) {
  const std::string dir = temp_dir("db_suction_deliveries_references");
  const std::string target = dir + "/p.db";
  const auto refused = [&](const std::string& name, const SuctionDeliveryRecord& d,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(target);
    expect_input_error([&] { f.writer->add_suction_deliveries({d}); }, fragments);
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  SuctionDeliveryRecord d = make_sample().parts[0].suction_deliveries[0];
  ASSERT_EQ(d.candidate_id, 4);
  ASSERT_EQ(d.suction_grasp_id, 1);
  ASSERT_EQ(d.arm, "right");
  d.candidate_id = 10;  // part 1's six candidates are written, part 2's are not
  refused("unknown candidate", d,
          {target, "suction_deliveries (candidate id 10, suction grasp id 1, arm 'right')",
           "FOREIGN KEY constraint failed"});
  d.candidate_id = 0;
  refused("candidate id 0", d,
          {target, "suction_deliveries (candidate id 0, suction grasp id 1,",
           "FOREIGN KEY constraint failed"});
  d.candidate_id = 4;
  d.suction_grasp_id = 3;  // the sample has 2 (both of part 1)
  refused("unknown suction grasp", d,
          {target, "suction_deliveries (candidate id 4, suction grasp id 3, arm 'right')",
           "FOREIGN KEY constraint failed"});
  d.suction_grasp_id = 0;
  refused("suction grasp id 0", d,
          {target, "suction_deliveries (candidate id 4, suction grasp id 0,",
           "FOREIGN KEY constraint failed"});
  // The same record with known references is written.
  d.suction_grasp_id = 2;
  Fixture f(target);
  f.writer->add_suction_deliveries({d});
  f.writer->commit();
  const auto four = Database::open(target).suction_deliveries(4);
  ASSERT_EQ(four.size(), 1u);
  EXPECT_EQ(four[0].suction_grasp_id, 2);
  EXPECT_EQ(four[0].arm, "right");
}

TEST(SuctionDeliveries, DamagedRowsAreDatabaseErrors) {
  const std::string path = temp_dir("db_suction_deliveries_damaged") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  detail::execute_script(path,
                         "UPDATE suction_deliveries SET joints_rh = x'0001020304' WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path + ": suction_deliveries.joints_rh (id 2)",
                      "expected finite joint values as little-endian doubles (8 bytes each)",
                      "got 5 bytes", "rebuild with: hila build meshes/cabinet/product.yaml"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A NaN (little-endian 0x7ff8000000000000) in a blob the writer would have refused.
  detail::execute_script(
      path, "UPDATE suction_deliveries SET joints_rh = x'000000000000f87f' WHERE id = 5");
  expect_input_error([&] { Database::open(path); },
                     {"suction_deliveries.joints_rh (id 5)", "got a value that is not finite"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A value of the wrong storage class: reported as such, not as the digest mismatch it causes.
  detail::execute_script(path, "UPDATE suction_deliveries SET arm = x'00ff' WHERE id = 3");
  expect_input_error([&] { Database::open(path); },
                     {path + ": suction_deliveries.arm (id 3): expected a TEXT (the column is TEXT "
                             "NOT NULL), got a BLOB of 2 bytes"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  EXPECT_NO_THROW(Database::open(path));
}

TEST(SuctionDeliveries, AChangedRowIsRefusedByTheTableDigest) {
  // Edits every other check accepts (valid values, references that hold): only the table's
  // content digest, stored when the file was written, can tell.
  const std::string path = temp_dir("db_suction_deliveries_digest") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  const auto refused = [&](const std::string& sql) {
    SCOPED_TRACE(sql);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    detail::execute_script(path, sql);
    expect_input_error(
        [&] { Database::open(path); },
        {path + ": suction_deliveries: expected the content digest stored when it was "
                "written (meta.digest.suction_deliveries = ",
         "its rows changed since (a damaged or edited file); rebuild with: hila "
         "build meshes/cabinet/product.yaml -o " +
             path});
  };
  refused("UPDATE suction_deliveries SET arm = 'left' WHERE id = 1");
  refused("UPDATE suction_deliveries SET suction_grasp_id = 2 WHERE id = 1");
  refused("UPDATE suction_deliveries SET candidate_id = 2 WHERE id = 5");
  // -0.0 to +0.0 in the first delivery's joints_rh[1] (bytes 9 to 16 as substr counts, the sign
  // bit in the last).
  refused(
      "UPDATE suction_deliveries SET joints_rh = CAST(substr(joints_rh, 1, 15) || x'00' || "
      "substr(joints_rh, 17) AS BLOB) WHERE id = 1");
  refused("DELETE FROM suction_deliveries WHERE id = 4");
  refused(
      "INSERT INTO suction_deliveries (candidate_id, suction_grasp_id, arm, joints_rh) VALUES "
      "(2, 1, 'left', x'')");
  // The pristine file opens, its deliveries as written.
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  EXPECT_EQ(Database::open(path).suction_deliveries(4).size(), 2u);
}

TEST(SuctionDeliveries, ACurrentFileWithoutTheTableIsRefused) {
  // The reader reads the table: a current file that lacks it (damaged by hand) cannot open.
  const std::string path = temp_dir("db_suction_deliveries_missing") + "/p.db";
  write_sample(path, make_sample());
  detail::execute_script(path, "DROP TABLE suction_deliveries");
  expect_input_error([&] { Database::open(path); },
                     {path + ": suction_deliveries: expected a readable hila table",
                      "no such table: suction_deliveries"});
}

TEST(SuctionDeliveries, EmptyTableOpens) {
  const std::string path = temp_dir("db_suction_deliveries_empty") + "/p.db";
  {
    Fixture f(path);
    f.writer->commit();
  }
  const Database db = Database::open(path);
  ASSERT_EQ(db.handover_candidates(1).size(), 6u);
  for (const auto& c : db.handover_candidates(1)) {
    EXPECT_TRUE(db.suction_deliveries(c.id).empty());
  }
}
