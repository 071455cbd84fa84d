// The schema version 5 table direct_grasps through DatabaseWriter and Database.

#include <gtest/gtest.h>

#include <cmath>
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

void expect_same(const DirectGraspRecord& got, const DirectGraspRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.candidate_id, want.candidate_id);
  EXPECT_EQ(got.robot_grasp_id, want.robot_grasp_id);
  EXPECT_EQ(got.arm, want.arm);
  expect_same_joints(got.joints_pick, want.joints_pick);
  expect_same_joints(got.joints_rh, want.joints_rh);
  EXPECT_EQ(got.inclination_pick_deg, want.inclination_pick_deg);
  EXPECT_EQ(got.inclination_rh_deg, want.inclination_rh_deg);
}

// A writer at `path` with the sample's meta, parts (with their grasps) and part 1's candidates
// written, so direct grasps have candidates and robot grasps to refer to.
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

TEST(DirectGrasps, EveryFieldRoundTripsPerCandidateInIdOrder) {
  const std::string path = temp_dir("db_direct_round_trip") + "/p.db";
  const Sample sample = make_sample();
  write_sample(path, sample);
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().schema_version, 10);

  const auto& written = sample.parts[0].direct_grasps;
  ASSERT_EQ(written.size(), 7u);
  std::size_t total = 0;
  for (const auto& part : sample.parts) {
    for (const auto& c : part.handover_candidates) {
      SCOPED_TRACE(c.id);
      std::vector<DirectGraspRecord> want;
      for (const auto& g : written) {
        if (g.candidate_id == c.id) want.push_back(g);
      }
      const auto got = db.direct_grasps(c.id);
      ASSERT_EQ(got.size(), want.size());
      for (std::size_t i = 0; i < want.size(); ++i) expect_same(got[i], want[i]);
      total += got.size();
    }
  }
  EXPECT_EQ(total, written.size()) << "every grasp belongs to exactly one candidate";

  // The goals' grasps were written interleaved (candidates 2, 4, 2, 5, 4, 2, 5): each candidate
  // gets its own, in id order.
  const auto ids = [&](std::int64_t candidate) {
    std::vector<std::int64_t> out;
    for (const auto& g : db.direct_grasps(candidate)) out.push_back(g.id);
    return out;
  };
  EXPECT_EQ(ids(2), (std::vector<std::int64_t>{1, 3, 6}));
  EXPECT_EQ(ids(4), (std::vector<std::int64_t>{2, 5}));
  EXPECT_EQ(ids(5), (std::vector<std::int64_t>{4, 7}));
  EXPECT_TRUE(db.direct_grasps(1).empty()) << "not a goal";
  EXPECT_TRUE(db.direct_grasps(7).empty()) << "part 2 has none";
  EXPECT_TRUE(db.direct_grasps(0).empty());
  EXPECT_TRUE(db.direct_grasps(99).empty());

  // The awkward values, spelled out.
  const auto two = db.direct_grasps(2);
  EXPECT_TRUE(std::signbit(two[0].joints_pick[1])) << "-0.0 survives in a blob";
  EXPECT_EQ(two[0].joints_pick[5], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(two[0].inclination_pick_deg, 0.0);
  EXPECT_EQ(two[1].inclination_rh_deg, 89.999999999999986);
  EXPECT_EQ(db.direct_grasps(5)[0].joints_pick.size(), 0) << "an empty vector stays empty";
  EXPECT_EQ(db.direct_grasps(5)[0].joints_rh.size(), 6);
  EXPECT_EQ(db.direct_grasps(4)[1].arm, "right ✋");

  // The shared grasps of the same goals are a table of their own, unchanged.
  std::size_t shared = 0;
  for (const auto& c : sample.parts[0].handover_candidates) shared += db.shared_grasps(c.id).size();
  EXPECT_EQ(shared, sample.parts[0].shared_grasps.size());
}

TEST(DirectGrasps, IdsContinueAcrossCallsWhateverTheRecordsSay) {
  const std::string path = temp_dir("db_direct_ids") + "/p.db";
  {
    Fixture f(path);
    DirectGraspRecord g;
    g.id = 42;  // ignored: the database assigns ids
    g.candidate_id = 4;
    g.robot_grasp_id = 2;
    g.arm = "left";
    f.writer->add_direct_grasps({g, g});
    f.writer->add_direct_grasps({});
    g.candidate_id = 2;
    g.robot_grasp_id = 9;  // a grasp of part 2: any written robot grasp may be referred to
    f.writer->add_direct_grasps({g});
    f.writer->commit();
  }
  const Database db = Database::open(path);
  const auto four = db.direct_grasps(4);
  ASSERT_EQ(four.size(), 2u);
  EXPECT_EQ(four[0].id, 1);
  EXPECT_EQ(four[1].id, 2);
  const auto two = db.direct_grasps(2);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].id, 3);
  EXPECT_EQ(two[0].robot_grasp_id, 9);
  EXPECT_EQ(two[0].joints_pick.size(), 0);
}

TEST(DirectGrasps, MistakesAreInvalidArgumentsNamingTableColumnAndRecord) {
  const std::string dir = temp_dir("db_direct_invalid");
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  // Each case on a fresh writer: a failed call makes the writer refuse to commit.
  const auto refused = [&](const std::string& name,
                           const std::function<void(std::vector<DirectGraspRecord>&)>& change,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(dir + "/p.db");
    auto records = f.sample.parts[0].direct_grasps;
    change(records);
    try {
      f.writer->add_direct_grasps(records);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      for (const auto& fragment : fragments) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
            << "missing '" << fragment << "' in: " << e.what();
      }
    }
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  refused("empty arm", [](auto& r) { r[3].arm.clear(); },
          {"DatabaseWriter::add_direct_grasps: direct_grasps.arm (record 3 of 7, candidate id 5): "
           "DirectGraspRecord::arm is empty, expected an arm name"});
  refused("NaN pick inclination", [&](auto& r) { r[6].inclination_pick_deg = nan; },
          {"DatabaseWriter::add_direct_grasps: direct_grasps.inclination_pick_deg (record 6 of 7, "
           "candidate id 5) must be finite, got nan"});
  refused("infinite robot-human inclination", [&](auto& r) { r[1].inclination_rh_deg = -inf; },
          {"direct_grasps.inclination_rh_deg (record 1 of 7, candidate id 4)", "got -inf"});
  refused("NaN pick joint", [&](auto& r) { r[0].joints_pick[4] = nan; },
          {"direct_grasps.joints_pick[4] (record 0 of 7, candidate id 2)", "got nan"});
  refused("infinite robot-human joint", [&](auto& r) { r[5].joints_rh[0] = inf; },
          {"direct_grasps.joints_rh[0] (record 5 of 7, candidate id 2)", "got inf"});
  // Every record is checked, in record order, before any is written: the first bad one is named.
  refused("two mistakes",
          [&](auto& r) {
            r[2].inclination_rh_deg = nan;
            r[4].arm.clear();
          },
          {"direct_grasps.inclination_rh_deg (record 2 of 7"});
}

TEST(DirectGrasps, UnknownReferencesAreDatabaseErrors) {
  const std::string dir = temp_dir("db_direct_references");
  const std::string target = dir + "/p.db";
  const auto refused = [&](const std::string& name, const DirectGraspRecord& g,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(target);
    expect_input_error([&] { f.writer->add_direct_grasps({g}); }, fragments);
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  DirectGraspRecord g = make_sample().parts[0].direct_grasps[1];
  g.candidate_id = 10;  // part 1's six candidates are written, part 2's are not
  refused("unknown candidate", g,
          {target, "direct_grasps (candidate id 10, robot grasp id 4, arm 'right')",
           "FOREIGN KEY constraint failed"});
  g.candidate_id = 4;
  g.robot_grasp_id = 10;  // the sample has 5 + 4
  refused("unknown robot grasp", g,
          {target, "direct_grasps (candidate id 4, robot grasp id 10, arm 'right')",
           "FOREIGN KEY constraint failed"});
  // The same record with known references is written.
  g.robot_grasp_id = 9;
  Fixture f(target);
  f.writer->add_direct_grasps({g});
  f.writer->commit();
  ASSERT_EQ(Database::open(target).direct_grasps(4).size(), 1u);
}

TEST(DirectGrasps, DamagedJointBlobIsADatabaseError) {
  const std::string path = temp_dir("db_direct_damaged") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  detail::execute_script(path, "UPDATE direct_grasps SET joints_pick = x'0001020304' WHERE id = 2");
  expect_input_error([&] { Database::open(path); },
                     {path + ": direct_grasps.joints_pick (id 2)",
                      "expected finite joint values as little-endian doubles (8 bytes each)",
                      "got 5 bytes", "rebuild with: hila build meshes/cabinet/product.yaml"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A NaN (little-endian 0x7ff8000000000000) in a blob the writer would have refused.
  detail::execute_script(path,
                         "UPDATE direct_grasps SET joints_rh = x'000000000000f87f' WHERE id = 6");
  expect_input_error([&] { Database::open(path); },
                     {"direct_grasps.joints_rh (id 6)", "got a value that is not finite"});
}

TEST(DirectGrasps, ACurrentFileWithoutTheTableIsRefused) {
  // The reader reads the table: a current file that lacks it (damaged by hand) cannot open.
  const std::string path = temp_dir("db_direct_missing") + "/p.db";
  write_sample(path, make_sample());
  detail::execute_script(path, "DROP TABLE direct_grasps");
  expect_input_error(
      [&] { Database::open(path); },
      {path + ": direct_grasps: expected a readable hila table", "no such table: direct_grasps"});
}

TEST(DirectGrasps, EmptyTableOpens) {
  const std::string path = temp_dir("db_direct_empty") + "/p.db";
  {
    Fixture f(path);
    f.writer->commit();
  }
  const Database db = Database::open(path);
  for (const auto& c : db.handover_candidates(1)) EXPECT_TRUE(db.direct_grasps(c.id).empty());
}
