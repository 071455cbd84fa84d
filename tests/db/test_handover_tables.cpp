// The schema version 3 tables (handover_stages, robot_handovers, handover_candidates,
// shared_grasps, ergonomics) through DatabaseWriter and Database.

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

void expect_same(const HandoverStageRecord& got, const HandoverStageRecord& want) {
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_EQ(got.finished_parts, want.finished_parts);
  EXPECT_EQ(got.draws, want.draws);
  EXPECT_EQ(got.candidates, want.candidates);
  EXPECT_EQ(got.comfortable, want.comfortable);
  EXPECT_EQ(got.comfortable_default_body, want.comfortable_default_body);
  EXPECT_EQ(got.goals, want.goals);
  EXPECT_EQ(got.robot_handovers, want.robot_handovers);
  EXPECT_EQ(got.two_hands, want.two_hands);
  EXPECT_EQ(got.failure, want.failure);
}

void expect_same(const RobotHandoverRecord& got, const RobotHandoverRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_LT(pose_error(got.board, want.board), 1e-12);
  EXPECT_EQ(got.suction_grasp_id, want.suction_grasp_id);
  EXPECT_EQ(got.arm, want.arm);
  expect_same_joints(got.joints, want.joints);
}

void expect_same(const HandoverCandidateRecord& got, const HandoverCandidateRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_EQ(got.sample, want.sample);
  EXPECT_LT(pose_error(got.board, want.board), 1e-12);
  EXPECT_EQ(got.distance, want.distance);
  EXPECT_EQ(got.quality, want.quality);
  EXPECT_EQ(got.status, want.status);
  EXPECT_EQ(got.rank, want.rank);
  EXPECT_EQ(got.human_arm, want.human_arm);
  EXPECT_EQ(got.human_grasp_id, want.human_grasp_id);
  EXPECT_EQ(got.human_quality, want.human_quality);
  EXPECT_EQ(got.second_arm, want.second_arm);
  EXPECT_EQ(got.second_grasp_id, want.second_grasp_id);
  EXPECT_EQ(got.second_quality, want.second_quality);
  expect_same_joints(got.human_joints, want.human_joints);
  expect_same_joints(got.second_joints, want.second_joints);
  EXPECT_EQ(got.bodies, want.bodies);
}

void expect_same(const SharedGraspRecord& got, const SharedGraspRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.candidate_id, want.candidate_id);
  EXPECT_EQ(got.robot_grasp_id, want.robot_grasp_id);
  EXPECT_EQ(got.robot_handover_id, want.robot_handover_id);
  EXPECT_EQ(got.arm, want.arm);
  expect_same_joints(got.joints_rr, want.joints_rr);
  expect_same_joints(got.joints_rh, want.joints_rh);
  EXPECT_EQ(got.inclination_rr_deg, want.inclination_rr_deg);
  EXPECT_EQ(got.inclination_rh_deg, want.inclination_rh_deg);
}

void expect_same(const ErgonomicsRecord& got, const ErgonomicsRecord& want) {
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_EQ(got.method, want.method);
  EXPECT_EQ(got.reachable, want.reachable);
  EXPECT_EQ(got.torso_flexion_deg, want.torso_flexion_deg);
  EXPECT_EQ(got.shoulder_elevated, want.shoulder_elevated);
  EXPECT_EQ(got.reach, want.reach);
  EXPECT_EQ(got.reorientation_deg, want.reorientation_deg);
  EXPECT_EQ(got.quality, want.quality);
  EXPECT_EQ(got.arm, want.arm);
}

// A writer at `path` with the sample's meta and parts (with their grasps) written, so records of
// the new tables have something to refer to.
struct Fixture {
  Sample sample = make_sample();
  std::unique_ptr<DatabaseWriter> writer;
  std::vector<std::int64_t> part_ids;

  explicit Fixture(const std::string& path) : writer(std::make_unique<DatabaseWriter>(path)) {
    writer->write_meta(sample.meta);
    for (const auto& p : sample.parts) {
      const auto id = writer->add_part(p.part);
      writer->add_robot_grasps(id, p.robot_grasps);
      writer->add_suction_grasps(id, p.suction_grasps);
      writer->add_human_grasps(id, p.human_grasps);
      part_ids.push_back(id);
    }
  }
};

}  // namespace

class HandoverRoundTrip : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    path_ = temp_dir("db_handover_" + test) + "/p.db";
    sample_ = make_sample();
    ids_ = write_sample(path_, sample_);
  }
  std::string path_;
  Sample sample_;
  std::vector<std::int64_t> ids_;
};

TEST_F(HandoverRoundTrip, MetaHumanBodies) {
  const Database db = Database::open(path_);
  EXPECT_EQ(db.meta().human_bodies, "1.75 male; 1.55 female");
  EXPECT_EQ(db.meta().schema_version, 10);
}

TEST_F(HandoverRoundTrip, Stages) {
  const Database db = Database::open(path_);
  ASSERT_EQ(db.handover_stages().size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    SCOPED_TRACE(k);
    const HandoverStageRecord* stage = db.handover_stage(ids_[k]);
    ASSERT_NE(stage, nullptr);
    EXPECT_EQ(stage, &db.handover_stages()[k]);
    expect_same(*stage, *sample_.parts[k].handover_stage);
  }
  EXPECT_TRUE(db.handover_stage(ids_[0])->finished_parts.empty()) << "the empty list";
  EXPECT_EQ(db.handover_stage(ids_[1])->finished_parts,
            (std::vector<std::string>{"Gehäuse-ß-部品-🔩", "shelf 'top' / ü"}));
  EXPECT_TRUE(db.handover_stage(ids_[1])->two_hands);
  EXPECT_EQ(db.handover_stage(3), nullptr);
  EXPECT_EQ(db.handover_stage(0), nullptr);
}

TEST_F(HandoverRoundTrip, RobotHandovers) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto got = db.robot_handovers(ids_[k]);
    const auto& want = sample_.parts[k].robot_handovers;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      expect_same(got[i], want[i]);
    }
  }
  const auto got = db.robot_handovers(ids_[0]);
  ASSERT_EQ(got.size(), 3u);
  EXPECT_EQ(got[0].joints.size(), 6);
  EXPECT_EQ(got[1].joints.size(), 0) << "an empty vector stays empty";
  EXPECT_TRUE(std::signbit(got[0].joints[2])) << "-0.0 survives in a blob";
  EXPECT_EQ(got[0].joints[4], std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(db.robot_handovers(ids_[1]).empty());
}

TEST_F(HandoverRoundTrip, CandidatesInIdOrder) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto got = db.handover_candidates(ids_[k]);
    const auto& want = sample_.parts[k].handover_candidates;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      expect_same(got[i], want[i]);
    }
  }
  const auto all = db.handover_candidates(ids_[0]);
  EXPECT_EQ(all[0].quality, 1e-310) << "subnormal";
  EXPECT_EQ(db.handover_candidates(ids_[1])[0].second_quality, -1e300);
  EXPECT_TRUE(db.handover_candidates(99).empty());
}

TEST_F(HandoverRoundTrip, CandidateBodiesBitForBit) {
  // Schema version 10: the bodies of meta.human_bodies (the build's worker set) each candidate is
  // comfortable for, bit i for body i, as written: every mask of the sample's two bodies.
  const Database db = Database::open(path_);
  ASSERT_EQ(human_body_labels(db.meta().human_bodies),
            (std::vector<std::string>{"1.75 male", "1.55 female"}));
  std::vector<std::uint32_t> got;
  for (std::size_t k = 0; k < 2; ++k) {
    for (const auto& c : db.handover_candidates(ids_[k])) got.push_back(c.bodies);
  }
  EXPECT_EQ(got, (std::vector<std::uint32_t>{0, 3, 1, 2, 3, 0, 2, 0, 1}));
  const auto goals = db.handover_goals(ids_[0]);
  ASSERT_EQ(goals.size(), 3u);
  EXPECT_EQ(goals[0].bodies, 2u) << "goals carry theirs";
  // Each value in its own column, an INTEGER.
  const auto probe = [&](const std::string& count_sql, int expected) {
    detail::execute_script(
        path_, "CREATE TEMP TABLE probe (n INTEGER CHECK (n = " + std::to_string(expected) +
                   ")); INSERT INTO probe " + count_sql);
  };
  probe("SELECT count(*) FROM handover_candidates WHERE typeof(bodies) = 'integer'", 9);
  probe("SELECT count(*) FROM handover_candidates WHERE bodies = 3 AND id IN (2, 5)", 2);
  probe("SELECT count(*) FROM handover_candidates WHERE bodies = 0", 3);
}

TEST_F(HandoverRoundTrip, CandidateBodiesChecksInTheFile) {
  // The file's CHECK keeps a mask to 32 unsigned bits, for rows edited by hand; it cannot know
  // how many bodies meta.human_bodies names (Database::open checks that).
  for (const std::string sql : {
           "UPDATE handover_candidates SET bodies = -1 WHERE id = 1",
           "UPDATE handover_candidates SET bodies = 4294967296 WHERE id = 2",
           "UPDATE handover_candidates SET bodies = -9223372036854775808 WHERE id = 3",
           "UPDATE handover_candidates SET bodies = NULL WHERE id = 1",
       }) {
    SCOPED_TRACE(sql);
    expect_input_error(
        [&] { detail::execute_script(path_, sql); },
        {std::string(sql.find("NULL") == std::string::npos ? "CHECK constraint failed"
                                                           : "NOT NULL constraint failed")});
  }
  EXPECT_NO_THROW(
      detail::execute_script(path_, "UPDATE handover_candidates SET bodies = 0 WHERE id = 2"));
  EXPECT_NO_THROW(detail::execute_script(
      path_, "UPDATE handover_candidates SET bodies = 4294967295 WHERE id = 3"));
}

TEST(HumanBodyLabels, TheItemsOfMetaHumanBodiesInStoredOrder) {
  EXPECT_TRUE(human_body_labels("").empty());
  EXPECT_EQ(human_body_labels("1.5 female"), std::vector<std::string>{"1.5 female"});
  EXPECT_EQ(human_body_labels("1.5 female; 1.82 male"),
            (std::vector<std::string>{"1.5 female", "1.82 male"}));
  EXPECT_EQ(human_body_labels("1.82 male; 1.5 female; 1.722 male"),
            (std::vector<std::string>{"1.82 male", "1.5 female", "1.722 male"}));
  // Only "; " separates; empty items are none.
  EXPECT_EQ(human_body_labels("; 1.5 female; ; 1.82 male; "),
            (std::vector<std::string>{"1.5 female", "1.82 male"}));
  EXPECT_EQ(human_body_labels("1.5 female;1.82 male"),
            std::vector<std::string>{"1.5 female;1.82 male"});
}

TEST_F(HandoverRoundTrip, GoalsByRank) {
  const Database db = Database::open(path_);
  const auto goals = db.handover_goals(ids_[0]);
  ASSERT_EQ(goals.size(), 3u);
  // Written with ranks 2, 0, 1 (candidate ids 2, 4, 5): read back by rank.
  EXPECT_EQ(goals[0].id, 4);
  EXPECT_EQ(goals[1].id, 5);
  EXPECT_EQ(goals[2].id, 2);
  for (int r = 0; r < 3; ++r) {
    EXPECT_EQ(goals[r].rank, r);
    EXPECT_EQ(goals[r].status, "goal");
    EXPECT_EQ(goals[r].human_joints.size(), 7);
  }
  expect_same(goals[0], sample_.parts[0].handover_candidates[3]);
  EXPECT_TRUE(db.handover_goals(ids_[1]).empty()) << "a part without goals";
}

TEST_F(HandoverRoundTrip, SharedGraspsPerCandidate) {
  const Database db = Database::open(path_);
  std::size_t total = 0;
  for (const auto& c : sample_.parts[0].handover_candidates) {
    SCOPED_TRACE(c.id);
    std::vector<SharedGraspRecord> want;
    for (const auto& g : sample_.parts[0].shared_grasps) {
      if (g.candidate_id == c.id) want.push_back(g);
    }
    const auto got = db.shared_grasps(c.id);
    ASSERT_EQ(got.size(), want.size());
    EXPECT_EQ(got.size(), c.status == "goal" ? 3u : 0u);
    for (std::size_t i = 0; i < want.size(); ++i) expect_same(got[i], want[i]);
    total += got.size();
  }
  EXPECT_EQ(total, 9u);
  EXPECT_EQ(db.shared_grasps(2)[2].joints_rh.size(), 0) << "an empty vector stays empty";
  EXPECT_TRUE(db.shared_grasps(0).empty());
}

TEST_F(HandoverRoundTrip, ErgonomicsInWriteOrder) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto got = db.ergonomics(ids_[k]);
    const auto& want = sample_.parts[k].ergonomics;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      expect_same(got[i], want[i]);
    }
  }
  const auto got = db.ergonomics(ids_[0]);
  EXPECT_EQ(got[0].method, "hila");
  EXPECT_EQ(got[1].method, "table");
  EXPECT_EQ(got[2].method, "alone");
  EXPECT_TRUE(db.ergonomics(5).empty());
}

TEST(HandoverWriter, ReturnsTheAssignedIdsInOrder) {
  const std::string path = temp_dir("db_handover_ids") + "/p.db";
  const Sample sample = make_sample();
  DatabaseWriter writer(path);
  writer.write_meta(sample.meta);
  const auto a = writer.add_part(sample.parts[0].part);
  const auto b = writer.add_part(sample.parts[1].part);
  // Grasps: ids continue across parts and calls, whatever the records' own id fields say.
  RobotGraspRecord g;
  g.id = 42;
  EXPECT_EQ(writer.add_robot_grasps(a, {g, g}), (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(writer.add_robot_grasps(b, {g}), (std::vector<std::int64_t>{3}));
  EXPECT_TRUE(writer.add_robot_grasps(b, {}).empty());
  EXPECT_EQ(writer.add_suction_grasps(b, {SuctionGraspRecord{}, SuctionGraspRecord{}}),
            (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(writer.add_human_grasps(a, {HumanGraspRecord{}}), (std::vector<std::int64_t>{1}));
  EXPECT_EQ(writer.add_human_grasps(b, {HumanGraspRecord{}, HumanGraspRecord{}}),
            (std::vector<std::int64_t>{2, 3}));

  RobotHandoverRecord h;
  h.suction_grasp_id = 2;
  h.part_id = 77;  // ignored: the argument decides
  EXPECT_EQ(writer.add_robot_handovers(b, {h, h, h}), (std::vector<std::int64_t>{1, 2, 3}));
  HandoverCandidateRecord c;
  c.status = "uncomfortable";
  const auto first = writer.add_handover_candidates(a, {c, c});
  const auto second = writer.add_handover_candidates(b, {c});
  EXPECT_EQ(first, (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(second, (std::vector<std::int64_t>{3}));
  c.status = "goal";
  c.rank = 0;
  const auto goal = writer.add_handover_candidates(b, {c});
  SharedGraspRecord s;
  s.candidate_id = goal[0];
  s.robot_grasp_id = 3;
  s.robot_handover_id = 2;
  writer.add_shared_grasps({s, s});
  writer.commit();

  const Database db = Database::open(path);
  EXPECT_EQ(db.robot_handovers(b).size(), 3u);
  EXPECT_TRUE(db.robot_handovers(a).empty());
  ASSERT_EQ(db.handover_candidates(b).size(), 2u);
  EXPECT_EQ(db.handover_candidates(b)[1].id, 4);
  ASSERT_EQ(db.shared_grasps(4).size(), 2u);
  EXPECT_EQ(db.shared_grasps(4)[1].id, 2);
  EXPECT_EQ(db.shared_grasps(4)[1].robot_handover_id, 2);
}

TEST(HandoverWriter, NonFiniteValuesAreInvalidArgumentsNamingTableAndColumn) {
  const std::string dir = temp_dir("db_handover_nan");
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  // Each case on a fresh writer: a failed call makes the writer refuse to commit.
  const auto refused = [&](const std::string& name,
                           const std::function<void(DatabaseWriter&, const Sample&)>& write,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(dir + "/p.db");
    try {
      write(*f.writer, f.sample);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      for (const auto& fragment : fragments) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
            << "missing '" << fragment << "' in: " << e.what();
      }
    }
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  refused(
      "NaN joint of a robot handover",
      [&](DatabaseWriter& w, const Sample& s) {
        auto records = s.parts[0].robot_handovers;
        records[2].joints[3] = nan;
        w.add_robot_handovers(1, records);
      },
      {"DatabaseWriter::add_robot_handovers: robot_handovers.joints[3] (record 2 of 3, part id 1) "
       "must be finite, got nan"});
  refused("infinite board position",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].robot_handovers;
            records[0].board.translation().y() = -inf;
            w.add_robot_handovers(1, records);
          },
          {"robot_handovers.board_y (record 0 of 3", "got -inf"});
  refused("NaN candidate distance",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].handover_candidates;
            records[4].distance = nan;
            w.add_handover_candidates(1, records);
          },
          {"DatabaseWriter::add_handover_candidates: handover_candidates.distance (record 4 of 6, "
           "part id 1)"});
  refused("NaN candidate rotation",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].handover_candidates;
            records[1].board.linear()(0, 0) = nan;
            w.add_handover_candidates(1, records);
          },
          {"handover_candidates.board_q", "(record 1 of 6"});
  for (const char* column : {"quality", "human_quality", "second_quality"}) {
    refused(std::string("infinite candidate ") + column,
            [&](DatabaseWriter& w, const Sample& s) {
              auto records = s.parts[1].handover_candidates;
              HandoverCandidateRecord& c = records[0];
              (std::string(column) == "quality"         ? c.quality
               : std::string(column) == "human_quality" ? c.human_quality
                                                        : c.second_quality) = inf;
              w.add_handover_candidates(2, records);
            },
            {std::string("handover_candidates.") + column + " (record 0 of 3, part id 2)", "inf"});
  }
  refused("NaN second joint",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].handover_candidates;
            records[3].second_joints[6] = nan;
            w.add_handover_candidates(1, records);
          },
          {"handover_candidates.second_joints[6] (record 3 of 6"});
  refused("NaN human joint",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].handover_candidates;
            records[1].human_joints[0] = nan;
            w.add_handover_candidates(1, records);
          },
          {"handover_candidates.human_joints[0]"});
  refused("NaN shared grasp inclination",
          [&](DatabaseWriter& w, const Sample& s) {
            w.add_robot_handovers(1, s.parts[0].robot_handovers);
            w.add_handover_candidates(1, s.parts[0].handover_candidates);
            auto records = s.parts[0].shared_grasps;
            records[5].inclination_rh_deg = nan;
            w.add_shared_grasps(records);
          },
          {"DatabaseWriter::add_shared_grasps: shared_grasps.inclination_rh_deg (record 5 of 9, "
           "candidate id 4)"});
  refused("infinite shared grasp joint",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].shared_grasps;
            records[0].joints_rr[5] = inf;
            w.add_shared_grasps(records);
          },
          {"shared_grasps.joints_rr[5] (record 0 of 9"});
  refused("NaN shared grasp rh joint",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].shared_grasps;
            records[1].joints_rh[0] = nan;
            w.add_shared_grasps(records);
          },
          {"shared_grasps.joints_rh[0]"});
  refused("NaN rr inclination",
          [&](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].shared_grasps;
            records[1].inclination_rr_deg = nan;
            w.add_shared_grasps(records);
          },
          {"shared_grasps.inclination_rr_deg"});
  for (const char* column : {"torso_flexion_deg", "reach", "reorientation_deg", "quality"}) {
    refused(std::string("NaN ergonomics ") + column,
            [&](DatabaseWriter& w, const Sample& s) {
              auto records = s.parts[0].ergonomics;
              ErgonomicsRecord& e = records[1];
              const std::string c = column;
              (c == "torso_flexion_deg"   ? e.torso_flexion_deg
               : c == "reach"             ? e.reach
               : c == "reorientation_deg" ? e.reorientation_deg
                                          : e.quality) = nan;
              w.add_ergonomics(1, records);
            },
            {std::string("DatabaseWriter::add_ergonomics: ergonomics.") + column +
             " (record 1 of 3, part id 1) must be finite, got nan"});
  }
}

TEST(HandoverWriter, BodiesBeyondTheBodySetAreRefused) {
  // Bit i of a candidate's bodies names body i of meta.human_bodies (schema version 10): a bit at
  // or beyond the body count names none, refused before anything of the call is written (and the
  // writer then refuses to commit).
  const std::string dir = temp_dir("db_handover_bodies");
  const auto refused = [&](const std::string& name, const std::string& human_bodies,
                           const std::function<void(DatabaseWriter&, const Sample&)>& write,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(dir + "/p.db");
    f.sample.meta.human_bodies = human_bodies;
    f.writer->write_meta(f.sample.meta);
    try {
      write(*f.writer, f.sample);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      for (const auto& fragment : fragments) {
        EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
            << "missing '" << fragment << "' in: " << e.what();
      }
    }
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  refused("bit 2 of two bodies", "1.75 male; 1.55 female",
          [](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[0].handover_candidates;
            records[4].bodies = 4;
            w.add_handover_candidates(1, records);
          },
          {"DatabaseWriter::add_handover_candidates: handover_candidates.bodies (record 4 of 6, "
           "part id 1): expected a mask of the 2 bodies of meta.human_bodies ('1.75 male; 1.55 "
           "female'): bits 0 to 1, from 0 to 3, got HandoverCandidateRecord::bodies = 4 (bit 2 "
           "set)"});
  refused("bit 31 of two bodies", "1.75 male; 1.55 female",
          [](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[1].handover_candidates;
            records[2].bodies = 0x80000001u;
            w.add_handover_candidates(2, records);
          },
          {"handover_candidates.bodies (record 2 of 3, part id 2)",
           "got HandoverCandidateRecord::bodies = 2147483649 (bit 31 set)"});
  refused("bit 1 of one body", "1.75 male",
          [](DatabaseWriter& w, const Sample& s) {
            w.add_handover_candidates(1, s.parts[0].handover_candidates);  // record 1 has 3
          },
          {"handover_candidates.bodies (record 1 of 6, part id 1): expected a mask of the 1 body "
           "of meta.human_bodies ('1.75 male'): bits 0 to 0, from 0 to 1, got "
           "HandoverCandidateRecord::bodies = 3 (bit 1 set)"});
  refused("any bit without a body set", "",
          [](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[1].handover_candidates;
            records[0].bodies = 0;
            w.add_handover_candidates(2, records);  // record 2 has 1
          },
          {"handover_candidates.bodies (record 2 of 3, part id 2): expected 0 (meta.human_bodies "
           "names no body: the cell's human only), got HandoverCandidateRecord::bodies = 1 (bit "
           "0 set)"});
  refused("a body set of empty items", "; ",
          [](DatabaseWriter& w, const Sample& s) {
            auto records = s.parts[1].handover_candidates;
            records[0].bodies = 0;
            w.add_handover_candidates(2, records);
          },
          {"expected 0 (meta.human_bodies names no body"});
  // Before write_meta the writer knows no body: only 0.
  {
    DatabaseWriter writer(dir + "/early.db");
    PartRecord part;
    part.mass = 1.0;
    const std::int64_t id = writer.add_part(part);
    HandoverCandidateRecord c;
    c.status = "uncomfortable";
    c.bodies = 1;
    try {
      writer.add_handover_candidates(id, {c});
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("handover_candidates.bodies (record 0 of 1, part id 1): "
                                           "expected 0 before write_meta"),
                std::string::npos)
          << e.what();
    }
  }
  // A body set written after the candidates must still cover their masks.
  {
    DatabaseWriter writer(dir + "/late.db");
    PartRecord part;
    part.mass = 1.0;
    Meta meta;
    meta.human_bodies = "1.75 male; 1.55 female";
    writer.write_meta(meta);
    const std::int64_t id = writer.add_part(part);
    HandoverCandidateRecord c;
    c.status = "uncomfortable";
    c.bodies = 2;
    writer.add_handover_candidates(id, {c});
    meta.human_bodies = "1.75 male";
    try {
      writer.write_meta(meta);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(
                    "DatabaseWriter::write_meta: meta.human_bodies (the candidates written "
                    "before): expected the bodies their masks name (handover_candidates.bodies: "
                    "bits 0 to 1), got 1 ('1.75 male')"),
                std::string::npos)
          << e.what();
    }
    EXPECT_THROW(writer.commit(), std::logic_error);
  }
  // Every bit of a 32-bit mask names a body of 32 (or more); 0 is always fine.
  {
    const std::string path = dir + "/many.db";
    {
      Fixture f(path);
      std::string bodies;
      for (int i = 0; i < 33; ++i) bodies += (i ? "; " : "") + std::to_string(150 + i) + " male";
      f.sample.meta.human_bodies = bodies;
      f.writer->write_meta(f.sample.meta);
      auto records = f.sample.parts[1].handover_candidates;
      records[0].bodies = 0xffffffffu;
      records[1].bodies = 0x80000000u;
      records[2].bodies = 0;
      f.writer->add_handover_candidates(2, records);
      f.writer->commit();
    }
    const auto read = Database::open(path).handover_candidates(2);
    ASSERT_EQ(read.size(), 3u);
    EXPECT_EQ(read[0].bodies, 0xffffffffu);
    EXPECT_EQ(read[1].bodies, 0x80000000u);
    EXPECT_EQ(read[2].bodies, 0u);
  }
}

TEST(HandoverWriter, RefusedValueFailsTheWriterAndLeavesNoFile) {
  const std::string dir = temp_dir("db_handover_refused");
  Fixture f(dir + "/p.db");
  const std::string temp = f.writer->temporary_path();
  auto records = f.sample.parts[0].robot_handovers;
  records.back().joints[0] = std::nan("");
  EXPECT_THROW(f.writer->add_robot_handovers(1, records), std::invalid_argument);
  EXPECT_THROW(f.writer->add_robot_handovers(1, f.sample.parts[0].robot_handovers),
               std::logic_error)
      << "a failed writer refuses further writes";
  EXPECT_THROW(f.writer->commit(), std::logic_error);
  f.writer.reset();
  EXPECT_FALSE(std::filesystem::exists(temp));
  EXPECT_FALSE(std::filesystem::exists(dir + "/p.db"));
}

TEST(HandoverWriter, FinishedPartNamesMustSurviveTheNewlineEncoding) {
  const std::string dir = temp_dir("db_handover_names");
  for (const auto& [names, fragment] :
       std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"a", ""}, "name 1 is empty"},
           {{"two\nlines"}, "name 0 is 'two\nlines'"},
       }) {
    SCOPED_TRACE(fragment);
    Fixture f(dir + "/p.db");
    HandoverStageRecord stage;
    stage.part_id = 1;
    stage.finished_parts = names;
    try {
      f.writer->add_handover_stage(stage);
      ADD_FAILURE() << "no exception";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("handover_stages.finished_parts (part id 1)"),
                std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  }
  // A single name, and names with spaces and quotes, are fine.
  const std::string path = dir + "/ok.db";
  {
    Fixture f(path);
    HandoverStageRecord stage;
    stage.part_id = 2;
    stage.finished_parts = {" padded ", "it's"};
    f.writer->add_handover_stage(stage);
    stage.part_id = 1;
    stage.finished_parts = {"x"};
    f.writer->add_handover_stage(stage);
    f.writer->commit();
  }
  const Database db = Database::open(path);
  EXPECT_EQ(db.handover_stage(2)->finished_parts, (std::vector<std::string>{" padded ", "it's"}));
  EXPECT_EQ(db.handover_stage(1)->finished_parts, (std::vector<std::string>{"x"}));
  EXPECT_EQ(db.handover_stages()[0].part_id, 2) << "id (write) order";
}

TEST(HandoverWriter, ConstraintViolationsAreDatabaseErrors) {
  const std::string dir = temp_dir("db_handover_constraints");
  const std::string target = dir + "/p.db";
  // Each case on a fresh writer; the message names the target, the table and the constraint.
  const auto refused = [&](const std::string& name,
                           const std::function<void(DatabaseWriter&, const Sample&)>& write,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    Fixture f(target);
    expect_input_error([&] { write(*f.writer, f.sample); }, fragments);
    EXPECT_THROW(f.writer->commit(), std::logic_error);
  };
  refused("stage of an unknown part",
          [](DatabaseWriter& w, const Sample& s) {
            HandoverStageRecord stage = *s.parts[0].handover_stage;
            stage.part_id = 9;
            w.add_handover_stage(stage);
          },
          {target, "handover_stages (part id 9)", "FOREIGN KEY constraint failed"});
  refused(
      "second stage of a part",
      [](DatabaseWriter& w, const Sample& s) {
        w.add_handover_stage(*s.parts[0].handover_stage);
        w.add_handover_stage(*s.parts[0].handover_stage);
      },
      {target, "handover_stages (part id 1)", "UNIQUE constraint failed: handover_stages.part_id"});
  refused("robot handover of an unknown part",
          [](DatabaseWriter& w, const Sample& s) {
            w.add_robot_handovers(3, s.parts[0].robot_handovers);
          },
          {"robot_handovers (part id 3)", "FOREIGN KEY constraint failed"});
  refused("robot handover with an unknown suction grasp",
          [](DatabaseWriter& w, const Sample&) {
            RobotHandoverRecord h;
            h.suction_grasp_id = 3;  // the sample has two
            w.add_robot_handovers(1, {h});
          },
          {"robot_handovers (part id 1)", "FOREIGN KEY constraint failed"});
  refused("unknown status",
          [](DatabaseWriter& w, const Sample&) {
            HandoverCandidateRecord c;
            c.status = "Goal";
            c.rank = -1;
            w.add_handover_candidates(1, {c});
          },
          {"handover_candidates (part id 1)", "CHECK constraint failed"});
  refused("goal without a rank",
          [](DatabaseWriter& w, const Sample&) {
            HandoverCandidateRecord c;
            c.status = "goal";
            c.rank = -1;
            w.add_handover_candidates(1, {c});
          },
          {"handover_candidates (part id 1)", "CHECK constraint failed"});
  refused("ranked non-goal",
          [](DatabaseWriter& w, const Sample&) {
            HandoverCandidateRecord c;
            c.status = "no_shared_grasp";
            c.rank = 0;
            w.add_handover_candidates(1, {c});
          },
          {"CHECK constraint failed"});
  refused("shared grasp of an unknown candidate",
          [](DatabaseWriter& w, const Sample& s) {
            w.add_robot_handovers(1, s.parts[0].robot_handovers);
            w.add_shared_grasps({s.parts[0].shared_grasps[0]});  // no candidates written
          },
          {"shared_grasps (candidate id 2, robot grasp id 2, robot handover id 1)",
           "FOREIGN KEY constraint failed"});
  refused("shared grasp of an unknown robot grasp",
          [](DatabaseWriter& w, const Sample& s) {
            w.add_robot_handovers(1, s.parts[0].robot_handovers);
            w.add_handover_candidates(1, s.parts[0].handover_candidates);
            SharedGraspRecord g = s.parts[0].shared_grasps[0];
            g.robot_grasp_id = 100;
            w.add_shared_grasps({g});
          },
          {"robot grasp id 100", "FOREIGN KEY constraint failed"});
  refused("shared grasp of an unknown robot handover",
          [](DatabaseWriter& w, const Sample& s) {
            w.add_handover_candidates(1, s.parts[0].handover_candidates);
            w.add_shared_grasps({s.parts[0].shared_grasps[0]});  // no robot handovers written
          },
          {"robot handover id 1", "FOREIGN KEY constraint failed"});
  refused("unknown ergonomics method",
          [](DatabaseWriter& w, const Sample&) {
            ErgonomicsRecord e;
            e.method = "robot";
            w.add_ergonomics(1, {e});
          },
          {"ergonomics (part id 1, method 'robot')", "CHECK constraint failed"});
  refused("a method twice for a part",
          [](DatabaseWriter& w, const Sample& s) {
            w.add_ergonomics(1, s.parts[0].ergonomics);
            w.add_ergonomics(1, {s.parts[0].ergonomics[1]});
          },
          {"ergonomics (part id 1, method 'table')",
           "UNIQUE constraint failed: ergonomics.part_id, ergonomics.method"});
  refused("ergonomics of an unknown part",
          [](DatabaseWriter& w, const Sample& s) { w.add_ergonomics(0, s.parts[0].ergonomics); },
          {"ergonomics (part id 0, method 'hila')", "FOREIGN KEY constraint failed"});
  // The same method for another part is fine.
  Fixture f(target);
  f.writer->add_ergonomics(1, f.sample.parts[0].ergonomics);
  f.writer->add_ergonomics(2, f.sample.parts[0].ergonomics);
  f.writer->commit();
  EXPECT_EQ(Database::open(target).ergonomics(2).size(), 3u);
}

TEST(HandoverReader, DamagedJointBlobIsADatabaseError) {
  const std::string path = temp_dir("db_handover_damaged") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  detail::execute_script(path, "UPDATE robot_handovers SET joints = x'0001020304' WHERE id = 3");
  expect_input_error([&] { Database::open(path); },
                     {path + ": robot_handovers.joints (id 3)",
                      "expected finite joint values as little-endian doubles (8 bytes each)",
                      "got 5 bytes", "rebuild with: hila build meshes/cabinet/product.yaml"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  // A NaN (little-endian 0x7ff8000000000000) in a blob the writer would have refused.
  detail::execute_script(path,
                         "UPDATE shared_grasps SET joints_rh = x'000000000000f87f' WHERE id = 4");
  expect_input_error([&] { Database::open(path); },
                     {"shared_grasps.joints_rh (id 4)", "got a value that is not finite"});
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  detail::execute_script(path, "UPDATE handover_candidates SET board_qw = 2.0 WHERE id = 5");
  expect_input_error([&] { Database::open(path); },
                     {"handover_candidates.board (id 5)", "a unit quaternion"});
}

TEST(HandoverReader, BodiesBeyondTheBodySetAreDatabaseErrors) {
  // A mask with a bit at or beyond the body count of meta.human_bodies names no body: the writer
  // refuses it, so in a file it is an edit, which Database::open refuses naming the row (before
  // the content digest: the more specific check speaks first). The file's CHECK bounds a mask to
  // 32 bits only, and a value past it (written with the CHECKs ignored; SQLite does not verify
  // them on open's read-only connection) is refused the same way.
  const std::string path = temp_dir("db_handover_bodies_edited") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  const auto damaged = [&](const std::string& name, const std::string& sql,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    detail::execute_script(path, "PRAGMA ignore_check_constraints = ON;" + sql);
    expect_input_error([&] { Database::open(path); }, fragments);
  };
  damaged("bit 2 of two bodies", "UPDATE handover_candidates SET bodies = 4 WHERE id = 2",
          {path +
           ": handover_candidates.bodies (id 2): expected a mask of the 2 bodies of "
           "meta.human_bodies ('1.75 male; 1.55 female'): bits 0 to 1, from 0 to 3, got "
           "4; rebuild with: hila build meshes/cabinet/product.yaml -o " +
           path});
  damaged("bit 31", "UPDATE handover_candidates SET bodies = 2147483648 WHERE id = 7",
          {path + ": handover_candidates.bodies (id 7): expected a mask of the 2 bodies",
           "got 2147483648"});
  damaged(
      "negative", "UPDATE handover_candidates SET bodies = -1 WHERE id = 1",
      {path + ": handover_candidates.bodies (id 1): expected a mask of the 2 bodies", "got -1"});
  damaged("beyond 32 bits", "UPDATE handover_candidates SET bodies = 4294967297 WHERE id = 3",
          {path + ": handover_candidates.bodies (id 3)", "got 4294967297"});
  damaged("not an integer", "UPDATE handover_candidates SET bodies = 1.5 WHERE id = 3",
          {path + ": handover_candidates.bodies (id 3): expected an INTEGER (the column is "
                  "INTEGER NOT NULL), got the REAL 1.5"});
  // The body count is meta's: one body fewer, and the masks with bit 1 (ids 2, 4, 5, 7) name none.
  damaged("a body set edited to one body",
          "UPDATE meta SET value = '1.75 male' WHERE key = 'human_bodies'",
          {path + ": handover_candidates.bodies (id 2): expected a mask of the 1 body of "
                  "meta.human_bodies ('1.75 male'): bits 0 to 0, from 0 to 1, got 3"});
  damaged("a body set edited away", "UPDATE meta SET value = '' WHERE key = 'human_bodies'",
          {path + ": handover_candidates.bodies (id 2): expected 0 (meta.human_bodies names no "
                  "body: the cell's human only), got 3"});
  // Within the body set, an edit only the digest sees.
  damaged("another mask of the two bodies",
          "UPDATE handover_candidates SET bodies = 1 WHERE id = 2",
          {path + ": handover_candidates: expected the content digest stored when it was "
                  "written (meta.digest.handover_candidates = "});
}

TEST(HandoverReader, ACurrentFileWithoutBodiesIsRefused) {
  // A current file whose handover_candidates lacks the column (a version 9 table with a current
  // version number, or damaged by hand) cannot open; a version 9 file is migrated instead
  // (test_migration).
  const std::string path = temp_dir("db_handover_no_bodies") + "/p.db";
  write_sample(path, make_sample());
  detail::execute_script(path, handover_candidates_before_v10_sql());
  expect_input_error([&] { Database::open(path); },
                     {path + ": handover_candidates: expected a readable hila table",
                      "no such column: bodies", "rebuild with: hila build"});
}

TEST(HandoverReader, MissingHumanBodiesKeyIsAnEditTheMetaDigestRefuses) {
  // The writer always stores the key, so a file without it was edited since: meta's stored
  // content digest no longer matches. The content digest, which verifies nothing, still reads it.
  // (Without a body set its candidates take no body: otherwise their masks would name bodies the
  // file no longer has, which the loader reports first, as BodiesBeyondTheBodySetAreDatabaseErrors
  // shows.)
  const std::string path = temp_dir("db_handover_meta") + "/p.db";
  Sample sample = make_sample();
  clear_bodies(sample);
  write_sample(path, sample);
  detail::execute_script(path, "DELETE FROM meta WHERE key = 'human_bodies'");
  expect_input_error([&] { Database::open(path); },
                     {path + ": meta: expected the content digest stored when it was written"});
  EXPECT_EQ(content_digest(path).size(), 64u);
}

TEST(HandoverReader, EmptyTablesOpen) {
  const std::string path = temp_dir("db_handover_empty") + "/p.db";
  {
    DatabaseWriter writer(path);
    writer.write_meta(Meta{});
    PartRecord part;
    part.mass = 1.0;  // the only field the writer requires
    writer.add_part(part);
    writer.commit();
  }
  const Database db = Database::open(path);
  EXPECT_EQ(db.meta().human_bodies, "");
  EXPECT_TRUE(db.handover_stages().empty());
  EXPECT_EQ(db.handover_stage(1), nullptr);
  EXPECT_TRUE(db.robot_handovers(1).empty());
  EXPECT_TRUE(db.handover_candidates(1).empty());
  EXPECT_TRUE(db.handover_goals(1).empty());
  EXPECT_TRUE(db.shared_grasps(1).empty());
  EXPECT_TRUE(db.ergonomics(1).empty());
}
