// The schema version 4 tables (roadmaps, roadmap_filters, regrasp_nodes, regrasp_edges) through
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

// Doubles in BLOBs come back bit for bit, -0.0 included.
void expect_same_value(double got, double want) {
  EXPECT_EQ(got, want);
  EXPECT_EQ(std::signbit(got), std::signbit(want));
}

template <typename Vector>
void expect_same_values(const Vector& got, const Vector& want) {
  ASSERT_EQ(got.size(), want.size());
  for (Eigen::Index i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(i);
    expect_same_value(got[i], want[i]);
  }
}

void expect_same(const RoadmapRecord& got, const RoadmapRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.arm, want.arm);
  EXPECT_EQ(got.dof, want.dof);
  EXPECT_EQ(got.resolution, want.resolution);
  ASSERT_EQ(got.nodes.size(), want.nodes.size());
  ASSERT_EQ(got.node_gravity.size(), want.node_gravity.size());
  ASSERT_EQ(got.node_inclination_deg.size(), want.node_inclination_deg.size());
  for (std::size_t n = 0; n < want.nodes.size(); ++n) {
    SCOPED_TRACE("node " + std::to_string(n));
    expect_same_values(got.nodes[n], want.nodes[n]);
    expect_same_values(got.node_gravity[n], want.node_gravity[n]);
    expect_same_value(got.node_inclination_deg[n], want.node_inclination_deg[n]);
  }
  EXPECT_EQ(got.edges, want.edges);
  ASSERT_EQ(got.edge_length.size(), want.edge_length.size());
  ASSERT_EQ(got.edge_max_inclination_deg.size(), want.edge_max_inclination_deg.size());
  for (std::size_t e = 0; e < want.edges.size(); ++e) {
    SCOPED_TRACE("edge " + std::to_string(e));
    expect_same_value(got.edge_length[e], want.edge_length[e]);
    expect_same_value(got.edge_max_inclination_deg[e], want.edge_max_inclination_deg[e]);
  }
}

void expect_same(const RoadmapFilterRecord& got, const RoadmapFilterRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_EQ(got.roadmap_id, want.roadmap_id);
  EXPECT_EQ(got.grasp_kind, want.grasp_kind);
  EXPECT_EQ(got.grasp_id, want.grasp_id);
  EXPECT_EQ(got.theta_c_deg, want.theta_c_deg);
  EXPECT_EQ(got.edges, want.edges);
  EXPECT_EQ(got.component, want.component);
  EXPECT_EQ(got.valid_edges, want.valid_edges);
  EXPECT_EQ(got.components, want.components);
  EXPECT_EQ(got.largest_component, want.largest_component);
}

void expect_same(const RegraspNodeRecord& got, const RegraspNodeRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_EQ(got.kind, want.kind);
  EXPECT_EQ(got.arm, want.arm);
  EXPECT_EQ(got.grasp_kind, want.grasp_kind);
  EXPECT_EQ(got.grasp_id, want.grasp_id);
  EXPECT_EQ(got.robot_handover_id, want.robot_handover_id);
  EXPECT_EQ(got.candidate_id, want.candidate_id);
  EXPECT_LT(pose_error(got.board, want.board), 1e-12);
  ASSERT_EQ(got.solutions.size(), want.solutions.size());
  for (std::size_t i = 0; i < want.solutions.size(); ++i) {
    SCOPED_TRACE("solution " + std::to_string(i));
    expect_same_values(got.solutions[i], want.solutions[i]);
  }
}

void expect_same(const RegraspEdgeRecord& got, const RegraspEdgeRecord& want) {
  EXPECT_EQ(got.id, want.id);
  EXPECT_EQ(got.part_id, want.part_id);
  EXPECT_EQ(got.kind, want.kind);
  EXPECT_EQ(got.arm, want.arm);
  EXPECT_EQ(got.from_node, want.from_node);
  EXPECT_EQ(got.to_node, want.to_node);
  EXPECT_EQ(got.filter_id, want.filter_id);
  EXPECT_EQ(got.connected, want.connected);
  EXPECT_EQ(got.cost, want.cost);
  EXPECT_EQ(got.path_nodes, want.path_nodes);
  EXPECT_EQ(got.via, want.via);
  expect_same_value(got.duration, want.duration);
  ASSERT_EQ(got.path.size(), want.path.size());
  for (std::size_t i = 0; i < want.path.size(); ++i) {
    SCOPED_TRACE("waypoint " + std::to_string(i));
    expect_same_values(got.path[i], want.path[i]);
  }
}

// A writer at `path` with the sample's meta, parts with their grasps, robot handovers and
// candidates and (when `with_roadmaps`) roadmaps written, so version 4 records have something to
// refer to: the ids are the sample's.
struct Fixture {
  Sample sample = make_sample();
  std::unique_ptr<DatabaseWriter> writer;

  explicit Fixture(const std::string& path, bool with_roadmaps = true)
      : writer(std::make_unique<DatabaseWriter>(path)) {
    writer->write_meta(sample.meta);
    for (const auto& p : sample.parts) {
      const auto id = writer->add_part(p.part);
      writer->add_robot_grasps(id, p.robot_grasps);
      writer->add_suction_grasps(id, p.suction_grasps);
      writer->add_human_grasps(id, p.human_grasps);
    }
    for (std::size_t k = 0; k < sample.parts.size(); ++k) {
      const auto part_id = static_cast<std::int64_t>(k + 1);
      writer->add_robot_handovers(part_id, sample.parts[k].robot_handovers);
      writer->add_handover_candidates(part_id, sample.parts[k].handover_candidates);
    }
    if (with_roadmaps) {
      for (const auto& r : sample.roadmaps) writer->add_roadmap(r);
    }
  }
};

using Write = std::function<void(DatabaseWriter&, const Sample&)>;

// Each case on a fresh writer: the call throws std::invalid_argument whose message holds every
// fragment, and the writer then refuses to commit.
void expect_refused(const std::string& dir, const std::string& name, const Write& write,
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
}

// Likewise for a DatabaseError (a constraint of the file, or a grasp id that names none).
void expect_database_error(const std::string& dir, const std::string& name, const Write& write,
                           std::initializer_list<std::string> fragments) {
  SCOPED_TRACE(name);
  Fixture f(dir + "/p.db");
  try {
    write(*f.writer, f.sample);
    ADD_FAILURE() << "no exception";
  } catch (const DatabaseError& e) {
    for (const auto& fragment : fragments) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos)
          << "missing '" << fragment << "' in: " << e.what();
    }
  }
  EXPECT_THROW(f.writer->commit(), std::logic_error);
}

}  // namespace

class RoadmapRoundTrip : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    path_ = temp_dir("db_roadmap_" + test) + "/p.db";
    sample_ = make_sample();
    ids_ = write_sample(path_, sample_);
  }
  std::string path_;
  Sample sample_;
  std::vector<std::int64_t> ids_;
};

TEST_F(RoadmapRoundTrip, SchemaVersion) {
  EXPECT_EQ(Database::open(path_).meta().schema_version, 10);
}

TEST_F(RoadmapRoundTrip, RoadmapsBitForBitInIdOrder) {
  const Database db = Database::open(path_);
  ASSERT_EQ(db.roadmaps().size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    SCOPED_TRACE(i);
    expect_same(db.roadmaps()[i], sample_.roadmaps[i]);
  }
  const RoadmapRecord* left = db.roadmap("left");
  ASSERT_NE(left, nullptr);
  EXPECT_EQ(left, &db.roadmaps()[0]);
  EXPECT_EQ(db.roadmap("right"), &db.roadmaps()[1]);
  EXPECT_EQ(db.roadmap("Left"), nullptr);
  EXPECT_EQ(db.roadmap(""), nullptr);
  EXPECT_EQ(left->nodes.size(), 11u);
  EXPECT_EQ(left->edges.size(), 13u);
  EXPECT_TRUE(std::signbit(left->nodes[0][1])) << "-0.0 survives in a blob";
  EXPECT_EQ(left->nodes[0][5], std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(std::signbit(left->node_gravity[0].x()));
  EXPECT_EQ(left->node_inclination_deg[1], 90.0);
  EXPECT_EQ(db.roadmap("right")->dof, 7);
  EXPECT_EQ(db.roadmap("right")->nodes[4].size(), 7);
}

TEST_F(RoadmapRoundTrip, FiltersWithBitListsOfAnyLength) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto got = db.roadmap_filters(ids_[k]);
    const auto& want = sample_.parts[k].roadmap_filters;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      expect_same(got[i], want[i]);
      const RoadmapFilterRecord* by_id = db.roadmap_filter(want[i].id);
      ASSERT_NE(by_id, nullptr);
      EXPECT_EQ(by_id->id, want[i].id);
      expect_same(*by_id, want[i]);
    }
  }
  const auto filters = db.roadmap_filters(ids_[0]);
  // 13 bits (two bytes, three unused bits), of which the last must survive; all set; 8 bits.
  ASSERT_EQ(filters[0].edges.size(), 13u);
  EXPECT_EQ(filters[1].edges, std::vector<bool>(13, true));
  EXPECT_EQ(filters[1].components, 1) << "every edge set: the sample roadmap is connected";
  ASSERT_EQ(filters[2].edges.size(), 8u);
  EXPECT_EQ(filters[3].edges, std::vector<bool>(8, false));
  EXPECT_EQ(filters[3].components, 5);
  EXPECT_EQ(filters[3].largest_component, 1);
  EXPECT_EQ(db.roadmap_filters(ids_[1])[1].theta_c_deg, 1e-300);
  EXPECT_EQ(db.roadmap_filter(0), nullptr);
  EXPECT_EQ(db.roadmap_filter(7), nullptr);
  EXPECT_EQ(db.roadmap_filter(-1), nullptr);
  EXPECT_TRUE(db.roadmap_filters(3).empty());
}

TEST_F(RoadmapRoundTrip, RegraspNodesOfEveryKind) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto got = db.regrasp_nodes(ids_[k]);
    const auto& want = sample_.parts[k].regrasp_nodes;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      expect_same(got[i], want[i]);
    }
  }
  const auto nodes = db.regrasp_nodes(ids_[0]);
  ASSERT_EQ(nodes.size(), 7u);
  EXPECT_EQ(nodes[0].kind, "home");
  EXPECT_EQ(nodes[0].grasp_kind, "");
  EXPECT_EQ(nodes[0].robot_handover_id, 0) << "NULL reads as 0";
  EXPECT_EQ(nodes[4].robot_handover_id, 1);
  EXPECT_EQ(nodes[6].candidate_id, 2);
  EXPECT_EQ(nodes[6].solutions.size(), 4u);
  EXPECT_TRUE(std::signbit(nodes[2].solutions[1][0]));
  EXPECT_EQ(nodes[2].solutions[2][5], std::numeric_limits<double>::denorm_min());
  EXPECT_EQ(nodes[1].solutions[0].size(), 7) << "the right arm's dof";
  EXPECT_TRUE(db.regrasp_nodes(0).empty());
}

TEST_F(RoadmapRoundTrip, RegraspEdgesOfEveryKind) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < 2; ++k) {
    const auto got = db.regrasp_edges(ids_[k]);
    const auto& want = sample_.parts[k].regrasp_edges;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      expect_same(got[i], want[i]);
    }
  }
  const auto edges = db.regrasp_edges(ids_[0]);
  EXPECT_EQ(edges[0].filter_id, 0) << "NULL reads as 0";
  EXPECT_EQ(edges[1].filter_id, 1);
  EXPECT_FALSE(edges[3].connected);
  EXPECT_EQ(edges[5].cost, 1e300);
  EXPECT_EQ(edges[5].path_nodes, 2147483647);
  EXPECT_EQ(db.regrasp_edges(ids_[1])[1].cost, std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(db.regrasp_edges(5).empty());
}

TEST_F(RoadmapRoundTrip, RegraspEdgePathsAndHowTheyWereConnected) {
  const Database db = Database::open(path_);
  const auto edges = db.regrasp_edges(ids_[0]);
  const auto nodes = db.regrasp_nodes(ids_[0]);
  ASSERT_EQ(edges.size(), 6u);
  EXPECT_EQ(edges[0].via, "roadmap");
  EXPECT_EQ(edges[1].via, "bridge");
  EXPECT_EQ(edges[3].via, "") << "not connected";
  EXPECT_TRUE(edges[3].path.empty());
  EXPECT_EQ(edges[4].via, "") << "a handover";
  EXPECT_TRUE(edges[4].path.empty());
  ASSERT_EQ(edges[0].path.size(), 6u);
  EXPECT_EQ(edges[0].path.front(), nodes[0].solutions[0]) << "from the from-node's first solution";
  EXPECT_EQ(edges[0].path.back(), nodes[2].solutions[0]) << "to the to-node's first solution";
  ASSERT_EQ(edges[2].path.size(), 4u);
  EXPECT_EQ(edges[2].path[0].size(), 7) << "the right arm's dof";
  ASSERT_EQ(edges[5].path.size(), 2u) << "the least a path has";
  ASSERT_EQ(edges[1].path.size(), 3u);
  EXPECT_TRUE(std::signbit(edges[1].path[1][0]));
  EXPECT_EQ(edges[1].path[1][4], std::numeric_limits<double>::denorm_min());
  const auto other = db.regrasp_edges(ids_[1]);
  EXPECT_TRUE(other[0].path.empty());
  ASSERT_EQ(other[1].path.size(), 5u);
  EXPECT_EQ(other[1].path[2][1], 1e300);
}

TEST_F(RoadmapRoundTrip, RegraspEdgeDurationsBitForBit) {
  // Schema version 9: each edge's estimated time along its path, as written.
  const Database db = Database::open(path_);
  const auto edges = db.regrasp_edges(ids_[0]);
  ASSERT_EQ(edges.size(), 6u);
  EXPECT_EQ(edges[0].duration, 6.125);
  EXPECT_EQ(edges[1].duration, 0.1) << "not exactly representable, read back bit for bit";
  EXPECT_EQ(edges[2].duration, 0.0) << "a path whose time was not estimated";
  EXPECT_FALSE(edges[2].path.empty());
  EXPECT_EQ(edges[3].duration, 0.0) << "not connected: no path";
  EXPECT_EQ(edges[4].duration, 0.0) << "a handover: no path";
  EXPECT_EQ(edges[5].duration, 1e300);
  const auto other = db.regrasp_edges(ids_[1]);
  ASSERT_EQ(other.size(), 2u);
  EXPECT_EQ(other[0].duration, 0.0);
  EXPECT_EQ(other[1].duration, std::numeric_limits<double>::denorm_min());
  // Each value in its own column, a REAL.
  const auto probe = [&](const std::string& count_sql, int expected) {
    detail::execute_script(
        path_, "CREATE TEMP TABLE probe (n INTEGER CHECK (n = " + std::to_string(expected) +
                   ")); INSERT INTO probe " + count_sql);
  };
  probe("SELECT count(*) FROM regrasp_edges WHERE typeof(duration) = 'real'", 8);
  probe("SELECT count(*) FROM regrasp_edges WHERE duration = 6.125 AND id = 1", 1);
  probe("SELECT count(*) FROM regrasp_edges WHERE duration > 0", 4);
}

TEST_F(RoadmapRoundTrip, RegraspEdgeDurationChecksInTheFile) {
  // The file's CHECKs refuse a negative duration and one on an edge without a path, for rows
  // edited by hand; a path may have 0 (not estimated) or any time.
  for (const std::string sql : {
           "UPDATE regrasp_edges SET duration = -1.0 WHERE id = 1",
           "UPDATE regrasp_edges SET duration = -1e-300 WHERE id = 2",
           "UPDATE regrasp_edges SET duration = 2.5 WHERE id = 4",     // not connected
           "UPDATE regrasp_edges SET duration = 1e-300 WHERE id = 5",  // a handover
           "UPDATE regrasp_edges SET duration = NULL WHERE id = 1",
       }) {
    SCOPED_TRACE(sql);
    expect_input_error(
        [&] { detail::execute_script(path_, sql); },
        {std::string(sql.find("NULL") == std::string::npos ? "CHECK constraint failed"
                                                           : "NOT NULL constraint failed")});
  }
  EXPECT_NO_THROW(
      detail::execute_script(path_, "UPDATE regrasp_edges SET duration = 0 WHERE id = 1"));
  EXPECT_NO_THROW(
      detail::execute_script(path_, "UPDATE regrasp_edges SET duration = 7 WHERE id = 3"));
}

TEST_F(RoadmapRoundTrip, RegraspEdgePathColumnsInTheFile) {
  // As in ReferencesThatDoNotApplyAreNullInTheFile: a TEMP probe table whose CHECK fails unless
  // the count is as expected.
  const auto probe = [&](const std::string& count_sql, int expected) {
    detail::execute_script(
        path_, "CREATE TEMP TABLE probe (n INTEGER CHECK (n = " + std::to_string(expected) +
                   ")); INSERT INTO probe " + count_sql);
  };
  // Five edges with a path (6, 3, 4, 2 and 5 waypoints), three without (0, 0, x'').
  probe("SELECT count(*) FROM regrasp_edges WHERE length(path) = 8 * path_waypoints * path_dof", 8);
  probe(
      "SELECT count(*) FROM regrasp_edges WHERE via = '' AND path_dof = 0 AND "
      "path_waypoints = 0 AND typeof(path) = 'blob' AND length(path) = 0",
      3);
  probe("SELECT sum(path_waypoints) FROM regrasp_edges", 20);
  probe("SELECT count(*) FROM regrasp_edges WHERE via = 'bridge'", 2);
  // The file's CHECKs keep via, connected, kind and the path together for rows made by hand.
  for (const std::string sql : {
           "UPDATE regrasp_edges SET via = 'rrt' WHERE id = 1",
           "UPDATE regrasp_edges SET via = 'bridge' WHERE id = 4",   // not connected
           "UPDATE regrasp_edges SET via = 'roadmap' WHERE id = 5",  // a handover
           "UPDATE regrasp_edges SET via = '', path_dof = 0, path_waypoints = 0, path = x'' "
           "WHERE id = 1",                                              // connected without via
           "UPDATE regrasp_edges SET path_waypoints = 0 WHERE id = 2",  // via without a path
           "UPDATE regrasp_edges SET path_waypoints = 2 WHERE id = 4",  // a path without via
       }) {
    SCOPED_TRACE(sql);
    expect_input_error([&] { detail::execute_script(path_, sql); }, {"CHECK constraint failed"});
  }
}

TEST_F(RoadmapRoundTrip, ReferencesThatDoNotApplyAreNullInTheFile) {
  // A probe table whose CHECK fails unless each count is as expected (execute_script has no
  // results to read); TEMP, so the file is not changed.
  const auto probe = [&](const std::string& count_sql, int expected) {
    detail::execute_script(
        path_, "CREATE TEMP TABLE probe (n INTEGER CHECK (n = " + std::to_string(expected) +
                   ")); INSERT INTO probe " + count_sql);
  };
  probe("SELECT count(*) FROM regrasp_nodes WHERE robot_handover_id IS NULL", 8);
  probe("SELECT count(*) FROM regrasp_nodes WHERE candidate_id IS NULL", 8);
  probe("SELECT count(*) FROM regrasp_edges WHERE filter_id IS NULL", 4);
  probe("SELECT count(*) FROM regrasp_nodes WHERE robot_handover_id = 0 OR candidate_id = 0", 0);
  probe("SELECT count(*) FROM regrasp_edges WHERE filter_id = 0", 0);
  // The probe can fail.
  expect_input_error(
      [&] { probe("SELECT count(*) FROM regrasp_edges WHERE filter_id IS NULL", 5); },
      {"CHECK constraint failed"});
  // And the file's CHECKs keep NULL and kind together for rows made by hand.
  expect_input_error(
      [&] {
        detail::execute_script(path_, "UPDATE regrasp_nodes SET candidate_id = 2 WHERE id = 1");
      },
      {"CHECK constraint failed"});
  expect_input_error(
      [&] {
        detail::execute_script(path_, "UPDATE regrasp_edges SET filter_id = NULL WHERE id = 2");
      },
      {"CHECK constraint failed"});
  expect_input_error(
      [&] { detail::execute_script(path_, "UPDATE regrasp_edges SET connected = 0 WHERE id = 1"); },
      {"CHECK constraint failed"});
}

TEST(RoadmapWriter, EmptyRoadmapAndRoadmapWithoutEdges) {
  const std::string path = temp_dir("db_roadmap_empty") + "/p.db";
  RoadmapRecord empty;
  empty.arm = "spare";
  empty.dof = 6;
  empty.resolution = 0.1;
  RoadmapRecord isolated = make_roadmap("left", 3, 6, 4, 0);
  RoadmapFilterRecord none;
  RoadmapFilterRecord isolated_filter;
  {
    Fixture f(path, false);
    EXPECT_EQ(f.writer->add_roadmap(empty), 1);
    EXPECT_EQ(f.writer->add_roadmap(isolated), 2);
    none.part_id = 1;
    none.roadmap_id = 1;
    none.grasp_kind = "gripper";
    none.grasp_id = 1;
    std::mt19937_64 rng(1);
    isolated_filter = make_filter(isolated, 2, rng, "suction", 2, 90.0, 1.0);
    isolated_filter.part_id = 1;
    EXPECT_EQ(f.writer->add_roadmap_filters({none, isolated_filter}),
              (std::vector<std::int64_t>{1, 2}));
    EXPECT_TRUE(f.writer->add_roadmap_filters({}).empty());
    f.writer->commit();
  }
  const Database db = Database::open(path);
  ASSERT_EQ(db.roadmaps().size(), 2u);
  empty.id = 1;
  expect_same(*db.roadmap("spare"), empty);
  EXPECT_TRUE(db.roadmap("spare")->nodes.empty());
  isolated.id = 2;
  expect_same(*db.roadmap("left"), isolated);
  none.id = 1;
  expect_same(*db.roadmap_filter(1), none);
  EXPECT_TRUE(db.roadmap_filter(1)->edges.empty());
  isolated_filter.id = 2;
  expect_same(*db.roadmap_filter(2), isolated_filter);
  EXPECT_EQ(db.roadmap_filter(2)->component, (std::vector<int>{0, 1, 2, 3}));
  EXPECT_EQ(db.roadmap_filter(2)->components, 4);
  EXPECT_EQ(db.roadmap_filters(1).size(), 2u);
  EXPECT_TRUE(db.roadmap_filters(2).empty());
}

TEST(RoadmapWriter, ReturnsTheAssignedIdsInOrder) {
  const std::string path = temp_dir("db_roadmap_ids") + "/p.db";
  Fixture f(path);  // roadmaps 1 and 2
  Sample& s = f.sample;
  RoadmapRecord third = s.roadmaps[0];
  third.arm = "third";
  third.id = 42;  // ignored
  EXPECT_EQ(f.writer->add_roadmap(third), 3);
  auto filters = s.parts[0].roadmap_filters;
  filters[0].id = 99;  // ignored
  EXPECT_EQ(f.writer->add_roadmap_filters({filters[0], filters[1]}),
            (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(f.writer->add_roadmap_filters({filters[2], filters[3]}),
            (std::vector<std::int64_t>{3, 4}));
  EXPECT_EQ(f.writer->add_roadmap_filters(s.parts[1].roadmap_filters),
            (std::vector<std::int64_t>{5, 6}));
  EXPECT_EQ(f.writer->add_regrasp_nodes(s.parts[0].regrasp_nodes),
            (std::vector<std::int64_t>{1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(f.writer->add_regrasp_nodes(s.parts[1].regrasp_nodes),
            (std::vector<std::int64_t>{8, 9, 10}));
  EXPECT_EQ(f.writer->add_regrasp_edges(s.parts[1].regrasp_edges),
            (std::vector<std::int64_t>{1, 2}));
  EXPECT_EQ(f.writer->add_regrasp_edges(s.parts[0].regrasp_edges),
            (std::vector<std::int64_t>{3, 4, 5, 6, 7, 8}));
  EXPECT_TRUE(f.writer->add_regrasp_edges({}).empty());
  f.writer->commit();
  const Database db = Database::open(path);
  EXPECT_EQ(db.roadmap("third")->id, 3);
  ASSERT_EQ(db.regrasp_edges(1).size(), 6u);
  EXPECT_EQ(db.regrasp_edges(1)[0].id, 3) << "id order, whatever the part";
  EXPECT_EQ(db.regrasp_edges(2)[1].id, 2);
}

TEST(RoadmapWriter, RoadmapMistakesAreInvalidArgumentsNamingTheField) {
  const std::string dir = temp_dir("db_roadmap_refused");
  const double nan = std::nan("");
  const double inf = std::numeric_limits<double>::infinity();
  // A roadmap for another arm (the fixture wrote the sample's), changed by `change`.
  const auto refused = [&](const std::string& name, std::function<void(RoadmapRecord&)> change,
                           std::initializer_list<std::string> fragments) {
    expect_refused(
        dir, name,
        [&](DatabaseWriter& w, const Sample& s) {
          RoadmapRecord r = s.roadmaps[0];
          r.arm = "spare";
          change(r);
          w.add_roadmap(r);
        },
        fragments);
  };
  refused("gravity size", [](RoadmapRecord& r) { r.node_gravity.pop_back(); },
          {"DatabaseWriter::add_roadmap: roadmaps.node_gravity (arm 'spare'): "
           "RoadmapRecord::node_gravity holds 10 values, expected one per node (11)"});
  refused("inclination size", [](RoadmapRecord& r) { r.node_inclination_deg.push_back(1.0); },
          {"roadmaps.node_inclination_deg (arm 'spare')", "holds 12 values", "one per node (11)"});
  refused("edge length size", [](RoadmapRecord& r) { r.edge_length.pop_back(); },
          {"roadmaps.edge_length (arm 'spare')", "RoadmapRecord::edge_length holds 12 values",
           "expected one per edge (13)"});
  refused("edge max inclination size", [](RoadmapRecord& r) { r.edge_max_inclination_deg.clear(); },
          {"roadmaps.edge_max_inclination_deg", "holds 0 values", "one per edge (13)"});
  refused("NaN in a node", [&](RoadmapRecord& r) { r.nodes[4][2] = nan; },
          {"DatabaseWriter::add_roadmap: roadmaps.node_joints[2] (arm 'spare', node 4) must be "
           "finite, got nan"});
  refused("node of another size", [](RoadmapRecord& r) { r.nodes[5].conservativeResize(5); },
          {"roadmaps.node_joints (arm 'spare')",
           "RoadmapRecord::nodes[5] has 5 joint values, expected dof = 6"});
  refused("infinite gravity", [&](RoadmapRecord& r) { r.node_gravity[0].y() = -inf; },
          {"roadmaps.node_gravity[1] (arm 'spare', node 0) must be finite, got -inf"});
  refused("NaN inclination", [&](RoadmapRecord& r) { r.node_inclination_deg[10] = nan; },
          {"roadmaps.node_inclination_deg (arm 'spare', node 10)"});
  refused("NaN edge length", [&](RoadmapRecord& r) { r.edge_length[3] = nan; },
          {"roadmaps.edge_length (arm 'spare', edge 3) must be finite"});
  refused("infinite edge inclination",
          [&](RoadmapRecord& r) { r.edge_max_inclination_deg[12] = inf; },
          {"roadmaps.edge_max_inclination_deg (arm 'spare', edge 12)", "got inf"});
  refused("edge out of range",
          [](RoadmapRecord& r) {
            r.edges[2] = {3, 11};
          },
          {"roadmaps.edge_nodes (arm 'spare'): RoadmapRecord::edges[2] is (3, 11), expected 0 <= "
           "first < second < 11 (the node count)"});
  refused("edge to itself",
          [](RoadmapRecord& r) {
            r.edges[0] = {4, 4};
          },
          {"RoadmapRecord::edges[0] is (4, 4)"});
  refused("edge backwards",
          [](RoadmapRecord& r) {
            r.edges[7] = {5, 1};
          },
          {"RoadmapRecord::edges[7] is (5, 1)"});
  refused("negative node",
          [](RoadmapRecord& r) {
            r.edges[12] = {-1, 1};
          },
          {"RoadmapRecord::edges[12] is (-1, 1)"});
  refused("no dof", [](RoadmapRecord& r) { r.dof = 0; },
          {"roadmaps.dof (arm 'spare'): RoadmapRecord::dof is 0, expected > 0"});
  refused("zero resolution", [](RoadmapRecord& r) { r.resolution = 0.0; },
          {"roadmaps.resolution (arm 'spare')", "expected a finite value > 0"});
  refused("NaN resolution", [&](RoadmapRecord& r) { r.resolution = nan; },
          {"roadmaps.resolution (arm 'spare')"});
  refused("no arm", [](RoadmapRecord& r) { r.arm.clear(); },
          {"roadmaps.arm (arm ''): RoadmapRecord::arm is empty"});
  // A second roadmap for an arm is the file's UNIQUE constraint.
  expect_database_error(
      dir, "second roadmap of an arm",
      [](DatabaseWriter& w, const Sample& s) { w.add_roadmap(s.roadmaps[1]); },
      {dir + "/p.db: roadmaps (arm 'right')", "UNIQUE constraint failed: roadmaps.arm"});
}

TEST(RoadmapWriter, FilterMistakesAreRefused) {
  const std::string dir = temp_dir("db_roadmap_filter_refused");
  // The sample's first filter (left roadmap, 13 edges, 11 nodes), changed by `change`.
  const auto refused = [&](const std::string& name,
                           std::function<void(RoadmapFilterRecord&)> change,
                           std::initializer_list<std::string> fragments) {
    expect_refused(
        dir, name,
        [&](DatabaseWriter& w, const Sample& s) {
          auto filters = s.parts[0].roadmap_filters;
          change(filters[1]);
          w.add_roadmap_filters(filters);
        },
        fragments);
  };
  refused("bit count", [](RoadmapFilterRecord& f) { f.edges.pop_back(); },
          {"DatabaseWriter::add_roadmap_filters: roadmap_filters.edge_bits (record 1 of 4, part "
           "id 1): RoadmapFilterRecord::edges holds 12 bits, expected one per edge of roadmap id "
           "1 (13)"});
  refused("a bit too many", [](RoadmapFilterRecord& f) { f.edges.push_back(false); },
          {"roadmap_filters.edge_bits", "holds 14 bits"});
  refused("component count", [](RoadmapFilterRecord& f) { f.component.push_back(0); },
          {"roadmap_filters.node_component (record 1 of 4, part id 1): "
           "RoadmapFilterRecord::component holds 12 ids, expected one per node of roadmap id 1 "
           "(11)"});
  refused("set edge across components",
          [](RoadmapFilterRecord& f) { f.component[3] = 1; },  // every edge is set, all in 0
          {"roadmap_filters.node_component", "is set but joins components"});
  refused("negative component",
          [](RoadmapFilterRecord& f) {
            f.edges.assign(13, false);
            f.component.assign(11, 0);
            f.component[6] = -1;
          },
          {"RoadmapFilterRecord::component[6] is -1, expected an id >= 0"});
  refused("valid edges", [](RoadmapFilterRecord& f) { f.valid_edges = 12; },
          {"roadmap_filters.valid_edges (record 1 of 4, part id 1): "
           "RoadmapFilterRecord::valid_edges is 12, expected the number of set edges (13)"});
  refused(
      "components", [](RoadmapFilterRecord& f) { f.components = 2; },
      {"roadmap_filters.components", "is 2, expected the number of distinct component ids (1)"});
  refused("largest component", [](RoadmapFilterRecord& f) { f.largest_component = 10; },
          {"roadmap_filters.largest_component", "is 10", "(11)"});
  refused("grasp kind", [](RoadmapFilterRecord& f) { f.grasp_kind = "Gripper"; },
          {"roadmap_filters.grasp_kind (record 1 of 4, part id 1): RoadmapFilterRecord::grasp_kind "
           "is 'Gripper', expected 'gripper' or 'suction'"});
  refused("NaN theta_c", [](RoadmapFilterRecord& f) { f.theta_c_deg = std::nan(""); },
          {"roadmap_filters.theta_c_deg (record 1 of 4, part id 1) must be finite, got nan"});

  expect_database_error(dir, "grasp that was not written",
                        [](DatabaseWriter& w, const Sample& s) {
                          auto f = s.parts[0].roadmap_filters[0];
                          f.grasp_id = 10;  // 9 robot grasps
                          w.add_roadmap_filters({f});
                        },
                        {"roadmap_filters.grasp_id (record 0 of 1, part id 1)",
                         "expected the id of a written robot_grasps row (grasp_kind 'gripper')",
                         "got 10, which names none"});
  expect_database_error(dir, "suction grasp that was not written",
                        [](DatabaseWriter& w, const Sample& s) {
                          auto f = s.parts[0].roadmap_filters[2];
                          f.grasp_id = 3;  // 2 suction grasps
                          w.add_roadmap_filters({f});
                        },
                        {"suction_grasps row (grasp_kind 'suction')", "got 3"});
  expect_database_error(dir, "unknown roadmap",
                        [](DatabaseWriter& w, const Sample& s) {
                          auto f = s.parts[0].roadmap_filters[0];
                          f.roadmap_id = 3;
                          w.add_roadmap_filters({f});
                        },
                        {"roadmap_filters (part id 1, roadmap id 3, gripper grasp id 1)",
                         "FOREIGN KEY constraint failed"});
  expect_database_error(dir, "unknown part",
                        [](DatabaseWriter& w, const Sample& s) {
                          auto f = s.parts[0].roadmap_filters[0];
                          f.part_id = 3;
                          w.add_roadmap_filters({f});
                        },
                        {"roadmap_filters (part id 3", "FOREIGN KEY constraint failed"});
  expect_database_error(
      dir, "a filter twice",
      [](DatabaseWriter& w, const Sample& s) {
        w.add_roadmap_filters({s.parts[0].roadmap_filters[2], s.parts[0].roadmap_filters[2]});
      },
      {"roadmap_filters (part id 1, roadmap id 2, suction grasp id 1)",
       "UNIQUE constraint failed: roadmap_filters.part_id, roadmap_filters.roadmap_id, "
       "roadmap_filters.grasp_kind, roadmap_filters.grasp_id"});
}

TEST(RoadmapWriter, RegraspNodeMistakesAreRefused) {
  const std::string dir = temp_dir("db_regrasp_node_refused");
  // The sample's part 1 nodes with node `index` changed by `change`.
  const auto refused = [&](const std::string& name, std::size_t index,
                           std::function<void(RegraspNodeRecord&)> change,
                           std::initializer_list<std::string> fragments) {
    expect_refused(
        dir, name,
        [&](DatabaseWriter& w, const Sample& s) {
          auto nodes = s.parts[0].regrasp_nodes;
          change(nodes[index]);
          w.add_regrasp_nodes(nodes);
        },
        fragments);
  };
  refused("unknown kind", 3, [](RegraspNodeRecord& n) { n.kind = "place"; },
          {"DatabaseWriter::add_regrasp_nodes: regrasp_nodes.kind (record 3 of 7, part id 1): "
           "RegraspNodeRecord::kind is 'place', expected 'home', 'pick', 'robot_handover' or "
           "'human_handover'"});
  refused("empty solutions", 6, [](RegraspNodeRecord& n) { n.solutions.clear(); },
          {"regrasp_nodes.solutions (record 6 of 7, part id 1): RegraspNodeRecord::solutions is "
           "empty, expected at least one"});
  refused("solutions of different sizes", 2,
          [](RegraspNodeRecord& n) { n.solutions[2].conservativeResize(7); },
          {"regrasp_nodes.solutions (record 2 of 7",
           "RegraspNodeRecord::solutions[2] has 7 joint values, expected as many as solutions[0] "
           "(6)"});
  refused("an empty solution", 0, [](RegraspNodeRecord& n) { n.solutions[0] = Eigen::VectorXd(); },
          {"RegraspNodeRecord::solutions[0] has 0 joint values, expected at least one"});
  refused("NaN in a solution", 6, [](RegraspNodeRecord& n) { n.solutions[1][4] = std::nan(""); },
          {"regrasp_nodes.solutions[4] (record 6 of 7, part id 1, solution 1) must be finite, got "
           "nan"});
  refused("NaN board", 3, [](RegraspNodeRecord& n) { n.board.translation().x() = std::nan(""); },
          {"regrasp_nodes.board_x (record 3 of 7, part id 1) must be finite"});
  refused("home with a grasp", 0, [](RegraspNodeRecord& n) { n.grasp_kind = "gripper"; },
          {"regrasp_nodes.grasp_kind (record 0 of 7, part id 1): RegraspNodeRecord::grasp_kind is "
           "'gripper' for a 'home' node, expected ''"});
  refused("home with a grasp id", 1, [](RegraspNodeRecord& n) { n.grasp_id = 1; },
          {"regrasp_nodes.grasp_id (record 1 of 7", "is 1 for a 'home' node, expected 0"});
  refused("pick without a grasp", 2, [](RegraspNodeRecord& n) { n.grasp_kind = ""; },
          {"regrasp_nodes.grasp_kind", "is '' for a 'pick' node, expected 'gripper' or 'suction'"});
  refused("robot handover without its id", 4, [](RegraspNodeRecord& n) { n.robot_handover_id = 0; },
          {"regrasp_nodes.robot_handover_id (record 4 of 7, part id 1): "
           "RegraspNodeRecord::robot_handover_id is 0 for a 'robot_handover' node, expected the "
           "id it refers to"});
  refused("pick with a candidate", 2, [](RegraspNodeRecord& n) { n.candidate_id = 2; },
          {"regrasp_nodes.candidate_id", "is 2 for a 'pick' node",
           "expected 0 (it applies to 'human_handover' nodes only)"});
  refused("human handover without its candidate", 6,
          [](RegraspNodeRecord& n) { n.candidate_id = 0; },
          {"regrasp_nodes.candidate_id (record 6 of 7"});
  refused("no arm", 5, [](RegraspNodeRecord& n) { n.arm.clear(); },
          {"regrasp_nodes.arm (record 5 of 7, part id 1): RegraspNodeRecord::arm is empty"});

  expect_database_error(
      dir, "grasp that was not written",
      [](DatabaseWriter& w, const Sample& s) {
        auto n = s.parts[0].regrasp_nodes[3];  // suction
        n.grasp_id = 5;
        w.add_regrasp_nodes({n});
      },
      {"regrasp_nodes.grasp_id (record 0 of 1, part id 1)", "suction_grasps", "got 5"});
  expect_database_error(dir, "unknown robot handover",
                        [](DatabaseWriter& w, const Sample& s) {
                          auto n = s.parts[0].regrasp_nodes[4];
                          n.robot_handover_id = 4;  // 3 written
                          w.add_regrasp_nodes({n});
                        },
                        {"regrasp_nodes (part id 1, robot_handover node of arm 'right')",
                         "FOREIGN KEY constraint failed"});
  expect_database_error(dir, "unknown candidate",
                        [](DatabaseWriter& w, const Sample& s) {
                          auto n = s.parts[0].regrasp_nodes[6];
                          n.candidate_id = 10;  // 9 written
                          w.add_regrasp_nodes({n});
                        },
                        {"regrasp_nodes (part id 1, human_handover node of arm 'left')",
                         "FOREIGN KEY constraint failed"});
}

TEST(RoadmapWriter, RegraspEdgeMistakesAreRefused) {
  const std::string dir = temp_dir("db_regrasp_edge_refused");
  // Part 1's nodes and filters written, then its edges with edge `index` changed by `change`.
  const auto write_with = [](std::size_t index, std::function<void(RegraspEdgeRecord&)> change) {
    return [index, change](DatabaseWriter& w, const Sample& s) {
      w.add_roadmap_filters(s.parts[0].roadmap_filters);
      w.add_regrasp_nodes(s.parts[0].regrasp_nodes);
      auto edges = s.parts[0].regrasp_edges;
      change(edges[index]);
      w.add_regrasp_edges(edges);
    };
  };
  const auto refused = [&](const std::string& name, std::size_t index,
                           std::function<void(RegraspEdgeRecord&)> change,
                           std::initializer_list<std::string> fragments) {
    expect_refused(dir, name, write_with(index, change), fragments);
  };
  refused("unknown kind", 0, [](RegraspEdgeRecord& e) { e.kind = "Transit"; },
          {"DatabaseWriter::add_regrasp_edges: regrasp_edges.kind (record 0 of 6, part id 1): "
           "RegraspEdgeRecord::kind is 'Transit', expected 'transit', 'transfer' or 'handover'"});
  refused("transfer without a filter", 1, [](RegraspEdgeRecord& e) { e.filter_id = 0; },
          {"regrasp_edges.filter_id (record 1 of 6, part id 1): RegraspEdgeRecord::filter_id is "
           "0 for a 'transfer' edge, expected the roadmap filter used"});
  refused("transit with a filter", 2, [](RegraspEdgeRecord& e) { e.filter_id = 3; },
          {"regrasp_edges.filter_id (record 2 of 6", "is 3 for a 'transit' edge",
           "expected 0 (only 'transfer' edges use one)"});
  refused("not connected with a cost", 3, [](RegraspEdgeRecord& e) { e.cost = 0.5; },
          {"regrasp_edges.cost (record 3 of 6, part id 1): RegraspEdgeRecord::cost is 0.500000 "
           "and path_nodes 0 for an edge that is not connected, expected 0"});
  refused("not connected with a path", 3, [](RegraspEdgeRecord& e) { e.path_nodes = 2; },
          {"regrasp_edges.path_nodes (record 3 of 6"});
  refused("NaN cost", 1, [](RegraspEdgeRecord& e) { e.cost = std::nan(""); },
          {"regrasp_edges.cost (record 1 of 6, part id 1) must be finite, got nan"});
  refused("negative cost", 0, [](RegraspEdgeRecord& e) { e.cost = -1.0; },
          {"regrasp_edges.cost", "is -1.000000, expected a path length >= 0"});
  refused("negative path", 0, [](RegraspEdgeRecord& e) { e.path_nodes = -1; },
          {"regrasp_edges.path_nodes", "is -1, expected >= 0"});
  refused("handover with a cost", 4, [](RegraspEdgeRecord& e) { e.cost = 0.25; },
          {"regrasp_edges.cost (record 4 of 6", "for a 'handover' edge, expected 0"});
  refused("no arm", 4, [](RegraspEdgeRecord& e) { e.arm = ""; },
          {"regrasp_edges.arm (record 4 of 6, part id 1): RegraspEdgeRecord::arm is empty"});
  // How an edge was connected and its path.
  refused("unknown via", 0, [](RegraspEdgeRecord& e) { e.via = "rrt"; },
          {"regrasp_edges.via (record 0 of 6, part id 1): RegraspEdgeRecord::via is 'rrt', "
           "expected 'roadmap' or 'bridge' (or '' without a path)"});
  refused("connected without via", 2, [](RegraspEdgeRecord& e) { e.via = ""; },
          {"regrasp_edges.via (record 2 of 6, part id 1): RegraspEdgeRecord::via is '' for a "
           "connected 'transit' edge, expected 'roadmap' or 'bridge'"});
  refused("bridge on an unconnected edge", 3, [](RegraspEdgeRecord& e) { e.via = "bridge"; },
          {"regrasp_edges.via (record 3 of 6, part id 1): RegraspEdgeRecord::via is 'bridge' for "
           "an edge that is not connected, expected ''"});
  refused("via on a handover", 4, [](RegraspEdgeRecord& e) { e.via = "roadmap"; },
          {"regrasp_edges.via (record 4 of 6", "is 'roadmap' for a 'handover' edge, expected ''"});
  refused("connected with one waypoint", 1, [](RegraspEdgeRecord& e) { e.path.resize(1); },
          {"regrasp_edges.path (record 1 of 6, part id 1): RegraspEdgeRecord::path has 1 "
           "waypoint for a connected 'transfer' edge, expected at least 2"});
  refused("connected without a path", 5, [](RegraspEdgeRecord& e) { e.path.clear(); },
          {"regrasp_edges.path (record 5 of 6", "has 0 waypoints", "expected at least 2"});
  refused("handover with a path", 4,
          [](RegraspEdgeRecord& e) { e.path.assign(2, Eigen::VectorXd::Zero(7)); },
          {"regrasp_edges.path (record 4 of 6, part id 1): RegraspEdgeRecord::path has 2 "
           "waypoints for a 'handover' edge, expected none"});
  refused("unconnected with a path", 3,
          [](RegraspEdgeRecord& e) { e.path.assign(2, Eigen::VectorXd::Zero(7)); },
          {"regrasp_edges.path (record 3 of 6",
           "has 2 waypoints for an edge that is not connected, expected none"});
  refused("waypoints of different sizes", 0,
          [](RegraspEdgeRecord& e) { e.path[3].conservativeResize(5); },
          {"regrasp_edges.path (record 0 of 6, part id 1): RegraspEdgeRecord::path[3] has 5 "
           "joint values, expected as many as path[0] (6)"});
  refused(
      "waypoints without joints", 5,
      [](RegraspEdgeRecord& e) { e.path.assign(2, Eigen::VectorXd()); },
      {"regrasp_edges.path (record 5 of 6", "path[0] has 0 joint values, expected at least one"});
  refused("NaN waypoint", 2, [](RegraspEdgeRecord& e) { e.path[1][4] = std::nan(""); },
          {"regrasp_edges.path[4] (record 2 of 6, part id 1, waypoint 1) must be finite, got nan"});
  refused(
      "infinite waypoint", 0,
      [](RegraspEdgeRecord& e) { e.path.back()[0] = -std::numeric_limits<double>::infinity(); },
      {"regrasp_edges.path[0] (record 0 of 6, part id 1, waypoint 5) must be finite, got -inf"});

  // The estimated duration (schema version 9).
  refused("negative duration", 0, [](RegraspEdgeRecord& e) { e.duration = -0.5; },
          {"DatabaseWriter::add_regrasp_edges: regrasp_edges.duration (record 0 of 6, part id 1): "
           "RegraspEdgeRecord::duration is -0.5, expected a time in seconds >= 0"});
  refused("the least negative duration", 1,
          [](RegraspEdgeRecord& e) { e.duration = -std::numeric_limits<double>::denorm_min(); },
          {"regrasp_edges.duration (record 1 of 6, part id 1): RegraspEdgeRecord::duration is "
           "-4.9406564584124654e-324, expected a time in seconds >= 0"});
  refused("NaN duration", 2, [](RegraspEdgeRecord& e) { e.duration = std::nan(""); },
          {"DatabaseWriter::add_regrasp_edges: regrasp_edges.duration (record 2 of 6, part id 1) "
           "must be finite, got nan"});
  refused("infinite duration", 5,
          [](RegraspEdgeRecord& e) { e.duration = std::numeric_limits<double>::infinity(); },
          {"regrasp_edges.duration (record 5 of 6, part id 1) must be finite, got inf"});
  refused("duration without a path (not connected)", 3,
          [](RegraspEdgeRecord& e) { e.duration = 2.5; },
          {"DatabaseWriter::add_regrasp_edges: regrasp_edges.duration (record 3 of 6, part id 1): "
           "RegraspEdgeRecord::duration is 2.5 for an edge without a path, expected 0"});
  refused("duration on a handover", 4, [](RegraspEdgeRecord& e) { e.duration = 1e-300; },
          {"regrasp_edges.duration (record 4 of 6, part id 1): RegraspEdgeRecord::duration is "
           "1e-300 for an edge without a path, expected 0"});
  // Refused before anything is written: an earlier edge that would fail its foreign key on
  // insertion is not reached.
  expect_refused(dir, "duration after an unknown node",
                 [](DatabaseWriter& w, const Sample& s) {
                   w.add_roadmap_filters(s.parts[0].roadmap_filters);
                   w.add_regrasp_nodes(s.parts[0].regrasp_nodes);
                   auto edges = s.parts[0].regrasp_edges;
                   edges[0].to_node = 99;
                   edges[4].duration = 1.0;
                   w.add_regrasp_edges(edges);
                 },
                 {"regrasp_edges.duration (record 4 of 6, part id 1)"});

  expect_database_error(
      dir, "unknown node", write_with(5, [](RegraspEdgeRecord& e) { e.to_node = 8; }),
      {"regrasp_edges (part id 1, transfer edge 6 -> 8)", "FOREIGN KEY constraint failed"});
  expect_database_error(
      dir, "unknown filter", write_with(1, [](RegraspEdgeRecord& e) { e.filter_id = 5; }),
      {"regrasp_edges (part id 1, transfer edge 3 -> 7)", "FOREIGN KEY constraint failed"});
}

TEST(RoadmapReader, TruncatedEdgeNodesIsADatabaseError) {
  const std::string path = temp_dir("db_roadmap_truncated") + "/p.db";
  write_sample(path, make_sample());
  ASSERT_NO_THROW(Database::open(path));
  detail::execute_script(path,
                         "UPDATE roadmaps SET edge_nodes = substr(edge_nodes, 1, "
                         "length(edge_nodes) - 1) WHERE arm = 'left'");
  expect_input_error(
      [&] { Database::open(path); },
      {path + ": roadmaps.edge_nodes (arm 'left', id 1)",
       "expected edge_count = 13 node pairs as little-endian int32s (8 bytes each, "
       "104 bytes)",
       "got 103 bytes", "rebuild with: hila build meshes/cabinet/product.yaml -o " + path});
}

TEST(RoadmapReader, DamagedRowsAreDatabaseErrors) {
  const std::string path = temp_dir("db_roadmap_damaged") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  const auto damaged = [&](const std::string& name, const std::string& sql,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    detail::execute_script(path, sql);
    expect_input_error([&] { Database::open(path); }, fragments);
  };
  damaged("NaN node joint (little-endian 0x7ff8000000000000)",
          "UPDATE roadmaps SET node_joints = CAST(x'000000000000f87f' || substr(node_joints, 9) "
          "AS BLOB) WHERE id = 2",
          {path + ": roadmaps.node_joints (arm 'right', id 2)", "expected finite values",
           "got a value that is not finite (node 0)"});
  damaged("node joints of another dof", "UPDATE roadmaps SET dof = 5 WHERE id = 1",
          {"roadmaps.node_joints (arm 'left', id 1)",
           "node_count * dof = 11 * 5 joint values as little-endian doubles", "got 528 bytes"});
  damaged("no dof", "UPDATE roadmaps SET dof = 0 WHERE id = 1",
          {"roadmaps.dof (arm 'left', id 1)", "expected an integer from 1 to 2147483647", "got 0"});
  damaged("gravity short",
          "UPDATE roadmaps SET node_gravity = substr(node_gravity, 25) WHERE id = 1",
          {"roadmaps.node_gravity (arm 'left', id 1)", "got 240 bytes"});
  damaged(
      "edge beyond the nodes",
      "UPDATE roadmaps SET edge_count = 1, edge_nodes = x'000000000b000000', edge_length = "
      "zeroblob(8), edge_max_inclination_deg = zeroblob(8) WHERE id = 1",
      {"roadmaps.edge_nodes (arm 'left', id 1)",
       "expected node pairs with 0 <= first < second < node_count = 11", "got edge 0 = (0, 11)"});
  damaged("negative edge count", "UPDATE roadmaps SET edge_count = -1 WHERE id = 2",
          {"roadmaps.edge_count (arm 'right', id 2)", "got -1"});
  damaged("component size mismatch",
          "UPDATE roadmap_filters SET node_component = substr(node_component, 5) WHERE id = 1",
          {path + ": roadmap_filters.node_component (id 1)",
           "expected one component id per node of roadmap id 1 (11) as little-endian int32s (4 "
           "bytes each, 44 bytes)",
           "got 40 bytes"});
  damaged("bits of another count", "UPDATE roadmap_filters SET edge_bits = x'ff' WHERE id = 2",
          {"roadmap_filters.edge_bits (id 2)", "13 bits in 2 bytes", "got 1 bytes"});
  damaged("unused bit set", "UPDATE roadmap_filters SET edge_bits = x'ffff' WHERE id = 2",
          {"roadmap_filters.edge_bits (id 2)", "the unused high bits 0",
           "got 2 bytes with an unused bit set"});
  damaged(
      "valid edges", "UPDATE roadmap_filters SET valid_edges = valid_edges + 1 WHERE id = 2",
      {"roadmap_filters.valid_edges (id 2)", "expected the set bits of edge_bits = 13", "got 14"});
  damaged("components", "UPDATE roadmap_filters SET components = 2 WHERE id = 2",
          {"roadmap_filters.components (id 2)", "the distinct ids of node_component = 1"});
  damaged("largest component", "UPDATE roadmap_filters SET largest_component = 3 WHERE id = 4",
          {"roadmap_filters.largest_component (id 4)", "= 1", "got 3"});
  damaged("set edge across components",
          "UPDATE roadmap_filters SET node_component = CAST(x'01000000' || "
          "substr(node_component, 5) AS BLOB) WHERE id = 2",
          {"roadmap_filters.node_component (id 2)",
           "expected the same id at both ends of every set edge"});
  damaged("negative component",
          "UPDATE roadmap_filters SET node_component = CAST(x'ffffffff' || "
          "substr(node_component, 5) AS BLOB) WHERE id = 4",
          {"roadmap_filters.node_component (id 4)", "component ids >= 0", "node 0: -1"});
  damaged("solutions truncated",
          "UPDATE regrasp_nodes SET solutions = substr(solutions, 2) WHERE id = 3",
          {path + ": regrasp_nodes.solutions (id 3)",
           "solution_count * dof = 3 * 6 joint values as little-endian doubles (48 bytes each, "
           "144 bytes)",
           "got 143 bytes"});
  damaged("no solutions",
          "UPDATE regrasp_nodes SET solution_count = 0, solutions = x'' WHERE id = 1",
          {"regrasp_nodes.solution_count (id 1)", "an integer from 1 to 2147483647", "got 0"});
  damaged("infinite solution",
          "UPDATE regrasp_nodes SET solutions = CAST(substr(solutions, 1, 8) || "
          "x'000000000000f07f' || substr(solutions, 17) AS BLOB) WHERE id = 7",
          {"regrasp_nodes.solutions (id 7)", "got a value that is not finite (solution 0)"});
  damaged("board quaternion", "UPDATE regrasp_nodes SET board_qw = 2.0 WHERE id = 5",
          {"regrasp_nodes.board (id 5)", "a unit quaternion"});
  // Edge 2 (part 1's transfer via a bridge) has 3 waypoints of 6 joints.
  damaged("path truncated", "UPDATE regrasp_edges SET path = substr(path, 2) WHERE id = 2",
          {path + ": regrasp_edges.path (id 2)",
           "expected path_waypoints * path_dof = 3 * 6 joint values as little-endian doubles (48 "
           "bytes each, 144 bytes)",
           "got 143 bytes"});
  damaged("path of another dof", "UPDATE regrasp_edges SET path_dof = 7 WHERE id = 2",
          {"regrasp_edges.path (id 2)", "3 * 7 joint values", "got 144 bytes"});
  damaged("NaN waypoint (little-endian 0x7ff8000000000000)",
          "UPDATE regrasp_edges SET path = CAST(substr(path, 1, 48) || x'000000000000f87f' || "
          "substr(path, 57) AS BLOB) WHERE id = 2",
          {path + ": regrasp_edges.path (id 2)", "expected finite values",
           "got a value that is not finite (waypoint 1)"});
  damaged("one waypoint",
          "UPDATE regrasp_edges SET path_waypoints = 1, path = substr(path, 1, 48) WHERE id = 2",
          {"regrasp_edges.path_waypoints (id 2)", "expected 0 (no path) or an integer from 2",
           "got 1"});
  damaged("negative waypoints", "UPDATE regrasp_edges SET path_waypoints = -2 WHERE id = 2",
          {"regrasp_edges.path_waypoints (id 2)", "got -2"});
  damaged("no joints", "UPDATE regrasp_edges SET path_dof = 0, path = x'' WHERE id = 2",
          {"regrasp_edges.path_dof (id 2)", "an integer from 1 to 2147483647", "got 0"});
  damaged("joints without waypoints", "UPDATE regrasp_edges SET path_dof = 6 WHERE id = 4",
          {"regrasp_edges.path_dof (id 4)", "expected 0 when path_waypoints is 0", "got 6"});
  // The duration (schema version 9). +infinity passes the file's CHECK (duration >= 0).
  damaged("infinite duration", "UPDATE regrasp_edges SET duration = 9e999 WHERE id = 2",
          {path +
           ": regrasp_edges.duration (id 2): expected a time in seconds, finite and >= 0, "
           "got inf; rebuild with: hila build meshes/cabinet/product.yaml -o " +
           path});
  damaged("duration that is not a number",
          "UPDATE regrasp_edges SET duration = 'slow' WHERE id = 1",
          {path + ": regrasp_edges.duration (id 1): expected a REAL (the column is REAL NOT "
                  "NULL), got the TEXT 'slow'"});
}

TEST(RoadmapReader, BadDurationsPastTheFilesChecksAreDatabaseErrors) {
  // A negative duration, or one on an edge without a path: the file's CHECKs refuse the edit
  // (RegraspEdgeDurationChecksInTheFile), but not one made with them ignored, and Database::open's
  // PRAGMA quick_check does not see it either (SQLite verifies no CHECK constraint on a read-only
  // connection): the loader refuses the row.
  const std::string path = temp_dir("db_roadmap_duration_unchecked") + "/p.db";
  write_sample(path, make_sample());
  const std::string pristine = read_file(path);
  const auto damaged = [&](const std::string& name, const std::string& sql,
                           std::initializer_list<std::string> fragments) {
    SCOPED_TRACE(name);
    std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
    detail::execute_script(path, "PRAGMA ignore_check_constraints = ON;" + sql);
    expect_input_error([&] { Database::open(path); }, fragments);
  };
  damaged("negative duration", "UPDATE regrasp_edges SET duration = -2.5 WHERE id = 3",
          {path +
           ": regrasp_edges.duration (id 3): expected a time in seconds, finite and >= 0, "
           "got -2.5; rebuild with: hila build meshes/cabinet/product.yaml -o " +
           path});
  damaged("the least negative duration",
          "UPDATE regrasp_edges SET duration = -4.9406564584124654e-324 WHERE id = 1",
          {path + ": regrasp_edges.duration (id 1): expected a time in seconds, finite and >= 0, "
                  "got -4.9406564584124654e-324"});
  damaged("duration without a path", "UPDATE regrasp_edges SET duration = 0.25 WHERE id = 4",
          {path + ": regrasp_edges.duration (id 4): expected 0 when path_waypoints is 0 (no "
                  "path), got 0.25; rebuild with: hila build"});
  damaged("duration on a handover", "UPDATE regrasp_edges SET duration = 3 WHERE id = 5",
          {"regrasp_edges.duration (id 5): expected 0 when path_waypoints is 0", "got 3"});
  // A file whose schema lost the CHECKs (edited first, then the value, each in a connection of its
  // own: a connection keeps the schema it read) is refused the same way.
  std::ofstream(path, std::ios::binary | std::ios::trunc) << pristine;
  detail::execute_script(
      path,
      "PRAGMA writable_schema = ON;"
      "UPDATE sqlite_master SET sql = replace(replace(sql, ' CHECK (duration >= 0)', ''), "
      "',\n  CHECK (path_waypoints <> 0 OR duration = 0)', '') WHERE name = 'regrasp_edges';"
      "PRAGMA writable_schema = OFF;");
  ASSERT_NO_THROW(Database::open(path)) << "the schema edit alone is not seen";
  detail::execute_script(path, "UPDATE regrasp_edges SET duration = -1 WHERE id = 6");
  expect_input_error([&] { Database::open(path); },
                     {path + ": regrasp_edges.duration (id 6): expected a time in seconds, "
                             "finite and >= 0, got -1"});
}

TEST(RoadmapReader, ACurrentFileWithoutDurationIsRefused) {
  // A current file whose regrasp_edges lacks the column (a version 8 table with a current version
  // number, or damaged by hand) cannot open; a version 8 file is migrated instead (test_migration).
  const std::string path = temp_dir("db_roadmap_no_duration") + "/p.db";
  write_sample(path, make_sample());
  detail::execute_script(path, regrasp_edges_before_v9_sql());
  expect_input_error([&] { Database::open(path); },
                     {path + ": regrasp_edges: expected a readable hila table",
                      "no such column: duration", "rebuild with: hila build"});
}

TEST(RoadmapReader, EmptyTablesOpen) {
  const std::string path = temp_dir("db_roadmap_empty_tables") + "/p.db";
  {
    DatabaseWriter writer(path);
    writer.write_meta(Meta{});
    PartRecord part;
    part.mass = 1.0;  // the only field the writer requires
    writer.add_part(part);
    writer.commit();
  }
  const Database db = Database::open(path);
  EXPECT_TRUE(db.roadmaps().empty());
  EXPECT_EQ(db.roadmap("left"), nullptr);
  EXPECT_TRUE(db.roadmap_filters(1).empty());
  EXPECT_EQ(db.roadmap_filter(1), nullptr);
  EXPECT_TRUE(db.regrasp_nodes(1).empty());
  EXPECT_TRUE(db.regrasp_edges(1).empty());
}
