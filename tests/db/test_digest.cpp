#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::test_data;
using namespace hila::test;

TEST(Digest, SameRecordsGiveTheSameDigestDespiteCreatedAtAndTemporaryName) {
  const std::string dir = temp_dir("db_digest_same");
  Sample a = make_sample();
  Sample b = make_sample();
  b.meta.created_at = "2031-01-01T00:00:00Z";
  write_sample(dir + "/a.db", a);
  write_sample(dir + "/b.db", b);  // another target, so another temporary file name
  // The files differ (created_at is stored), the digests must not.
  ASSERT_NE(read_file(dir + "/a.db"), read_file(dir + "/b.db"));
  const std::string digest = content_digest(dir + "/a.db");
  EXPECT_EQ(digest.size(), 64u);
  EXPECT_EQ(digest, content_digest(dir + "/b.db"));
  EXPECT_EQ(digest, content_digest(dir + "/a.db")) << "stable across calls";
  EXPECT_NE(digest, sha256_hex(read_file(dir + "/a.db"))) << "not a hash of the file bytes";
}

TEST(Digest, OneUlpInOneGraspQualityChangesIt) {
  const std::string dir = temp_dir("db_digest_ulp");
  Sample a = make_sample();
  Sample b = make_sample();
  double& q = b.parts[1].robot_grasps[2].quality;
  q = std::nextafter(q, 2.0);
  ASSERT_NE(q, a.parts[1].robot_grasps[2].quality);
  write_sample(dir + "/a.db", a);
  write_sample(dir + "/b.db", b);
  EXPECT_NE(content_digest(dir + "/a.db"), content_digest(dir + "/b.db"));
}

TEST(Digest, EveryKindOfChangeIsSeen) {
  const std::string dir = temp_dir("db_digest_changes");
  const Sample base = make_sample();
  write_sample(dir + "/base.db", base);
  const std::string reference = content_digest(dir + "/base.db");

  std::vector<std::pair<std::string, Sample>> variants;
  auto add = [&](const std::string& name, auto change) {
    Sample s = make_sample();
    change(s);
    variants.emplace_back(name, s);
  };
  add("meta seed", [](Sample& s) { s.meta.seed -= 1; });
  add("meta cell hash", [](Sample& s) { s.meta.cell_hash[0] = 'x'; });
  add("part name", [](Sample& s) { s.parts[0].part.name += " "; });
  add("flag", [](Sample& s) {
    s.parts[1].human_grasps[0].one_hand_stable = !s.parts[1].human_grasps[0].one_hand_stable;
  });
  add("a placement less", [](Sample& s) { s.parts[0].placements.pop_back(); });
  add("records moved between parts", [](Sample& s) {
    s.parts[1].suction_grasps = s.parts[0].suction_grasps;
    s.parts[0].suction_grasps.clear();
  });
  add("part order", [](Sample& s) { std::swap(s.parts[0], s.parts[1]); });
  add("comfort map order", [](Sample& s) { std::swap(s.comfort_maps[0], s.comfort_maps[1]); });
  add("a comfort map less", [](Sample& s) { s.comfort_maps.pop_back(); });
  add("comfort map seed", [](Sample& s) { s.comfort_maps[0].seed += 1; });
  add("comfort orientation", [](Sample& s) {
    auto& q = s.comfort_maps[1].orientations[6];
    q.w() = std::nextafter(q.w(), 2.0);
  });
  add("comfort map arm name", [](Sample& s) { s.comfort_maps[1].arm = "Left"; });
  // Schema version 3: the handover and ergonomics tables and meta.human_bodies.
  // (Fewer bodies only with masks that name none beyond them: the writer refuses others.)
  add("meta human bodies", [](Sample& s) { s.meta.human_bodies = "1.75 male; 1.56 female"; });
  add("one human body", [](Sample& s) {
    s.meta.human_bodies = "1.75 male";
    for (auto& p : s.parts) {
      for (auto& c : p.handover_candidates) c.bodies &= 1u;
    }
  });
  add("no human bodies", [](Sample& s) {
    s.meta.human_bodies.clear();
    clear_bodies(s);
  });
  add("stage failure", [](Sample& s) { s.parts[1].handover_stage->failure += "."; });
  add("stage finished parts order", [](Sample& s) {
    auto& names = s.parts[1].handover_stage->finished_parts;
    std::swap(names[0], names[1]);
  });
  add("stage count", [](Sample& s) { s.parts[0].handover_stage->comfortable_default_body += 1; });
  add("stage flag", [](Sample& s) { s.parts[0].handover_stage->two_hands = true; });
  add("no stage", [](Sample& s) { s.parts[1].handover_stage.reset(); });
  add("robot handover arm", [](Sample& s) { s.parts[0].robot_handovers[1].arm = "left"; });
  add("robot handover suction grasp",
      [](Sample& s) { s.parts[0].robot_handovers[0].suction_grasp_id = 2; });
  add("robot handover joint ulp", [](Sample& s) {
    double& q = s.parts[0].robot_handovers[2].joints[5];
    q = std::nextafter(q, 10.0);
  });
  add("robot handover joint -0.0 to +0.0",
      [](Sample& s) { s.parts[0].robot_handovers[0].joints[2] = 0.0; });
  add("an empty joint vector gets one joint",
      [](Sample& s) { s.parts[0].robot_handovers[1].joints = Eigen::VectorXd::Zero(1); });
  add("candidate distance ulp", [](Sample& s) {
    double& d = s.parts[0].handover_candidates[2].distance;
    d = std::nextafter(d, 1.0);
  });
  add("candidate ranks swapped", [](Sample& s) {
    std::swap(s.parts[0].handover_candidates[1].rank, s.parts[0].handover_candidates[3].rank);
  });
  add("candidate status",
      [](Sample& s) { s.parts[0].handover_candidates[0].status = "no_shared_grasp"; });
  add("candidate human grasp",
      [](Sample& s) { s.parts[0].handover_candidates[5].human_grasp_id = 3; });
  add("candidate second joints",
      [](Sample& s) { s.parts[0].handover_candidates[3].second_joints.conservativeResize(6); });
  add("shared grasp inclination ulp", [](Sample& s) {
    double& a = s.parts[0].shared_grasps[4].inclination_rr_deg;
    a = std::nextafter(a, 90.0);
  });
  add("shared grasp robot grasp",
      [](Sample& s) { s.parts[0].shared_grasps[8].robot_grasp_id = 5; });
  add("shared grasp joints swapped", [](Sample& s) {
    auto& g = s.parts[0].shared_grasps[3];
    std::swap(g.joints_rr, g.joints_rh);
  });
  add("a shared grasp less", [](Sample& s) { s.parts[0].shared_grasps.pop_back(); });
  add("ergonomics flag", [](Sample& s) { s.parts[1].ergonomics[0].shoulder_elevated = true; });
  add("ergonomics reach", [](Sample& s) {
    double& r = s.parts[0].ergonomics[2].reach;
    r = std::nextafter(r, 0.0);
  });
  add("ergonomics order",
      [](Sample& s) { std::swap(s.parts[0].ergonomics[0], s.parts[0].ergonomics[1]); });
  add("ergonomics arm", [](Sample& s) { s.parts[1].ergonomics[1].arm = "left ✋"; });
  // Schema version 4: roadmaps, their filters and the regrasp graph.
  add("roadmap node joint ulp", [](Sample& s) {
    double& q = s.roadmaps[0].nodes[7][3];
    q = std::nextafter(q, 10.0);
  });
  add("roadmap node joint -0.0 to +0.0", [](Sample& s) { s.roadmaps[0].nodes[0][1] = 0.0; });
  add("roadmap gravity ulp", [](Sample& s) {
    double& g = s.roadmaps[1].node_gravity[4].z();
    g = std::nextafter(g, 10.0);
  });
  add("roadmap edge max inclination ulp", [](Sample& s) {
    double& a = s.roadmaps[1].edge_max_inclination_deg[7];
    a = std::nextafter(a, 0.0);
  });
  add("roadmap edge length ulp", [](Sample& s) {
    double& l = s.roadmaps[0].edge_length[12];
    l = std::nextafter(l, 0.0);
  });
  add("roadmap resolution", [](Sample& s) { s.roadmaps[1].resolution = 0.025; });
  add("roadmaps swapped", [](Sample& s) { std::swap(s.roadmaps[0].arm, s.roadmaps[1].arm); });
  add("filter theta_c ulp", [](Sample& s) {
    double& t = s.parts[1].roadmap_filters[1].theta_c_deg;
    t = std::nextafter(t, 1.0);
  });
  add("filter grasp", [](Sample& s) { s.parts[0].roadmap_filters[0].grasp_id = 2; });
  add("filter order", [](Sample& s) {
    auto& filters = s.parts[0].roadmap_filters;
    std::swap(filters[0], filters[1]);
  });
  add("regrasp node solution ulp", [](Sample& s) {
    double& q = s.parts[0].regrasp_nodes[6].solutions[3][2];
    q = std::nextafter(q, 10.0);
  });
  add("regrasp node solution -0.0 to +0.0",
      [](Sample& s) { s.parts[0].regrasp_nodes[2].solutions[1][0] = 0.0; });
  add("regrasp node a solution less",
      [](Sample& s) { s.parts[0].regrasp_nodes[2].solutions.pop_back(); });
  add("regrasp node arm", [](Sample& s) { s.parts[1].regrasp_nodes[0].arm = "right"; });
  add("regrasp edge cost ulp", [](Sample& s) {
    double& c = s.parts[0].regrasp_edges[1].cost;
    c = std::nextafter(c, 10.0);
  });
  add("regrasp edge path nodes", [](Sample& s) { s.parts[0].regrasp_edges[0].path_nodes += 1; });
  add("regrasp edge reversed", [](Sample& s) {
    auto& e = s.parts[0].regrasp_edges[2];
    std::swap(e.from_node, e.to_node);
  });
  add("regrasp edge filter", [](Sample& s) { s.parts[0].regrasp_edges[1].filter_id = 2; });
  add("regrasp edge via", [](Sample& s) { s.parts[0].regrasp_edges[0].via = "bridge"; });
  add("regrasp edge path waypoint ulp", [](Sample& s) {
    double& q = s.parts[1].regrasp_edges[1].path[2][3];
    q = std::nextafter(q, 10.0);
  });
  add("regrasp edge path -0.0 to +0.0",
      [](Sample& s) { s.parts[0].regrasp_edges[1].path[1][0] = 0.0; });
  add("regrasp edge path a waypoint less", [](Sample& s) {
    auto& path = s.parts[0].regrasp_edges[0].path;
    path.erase(path.begin() + 2);
  });
  add("regrasp edge path waypoints swapped", [](Sample& s) {
    auto& path = s.parts[0].regrasp_edges[0].path;
    std::swap(path[1], path[2]);
  });
  // Schema version 9: the estimated duration along the path.
  add("regrasp edge duration ulp", [](Sample& s) {
    double& d = s.parts[0].regrasp_edges[0].duration;
    d = std::nextafter(d, 10.0);
  });
  add("regrasp edge duration not estimated",
      [](Sample& s) { s.parts[0].regrasp_edges[1].duration = 0.0; });
  add("regrasp edge duration estimated",
      [](Sample& s) { s.parts[0].regrasp_edges[2].duration = 0.75; });
  add("regrasp edge durations swapped", [](Sample& s) {
    std::swap(s.parts[0].regrasp_edges[0].duration, s.parts[0].regrasp_edges[1].duration);
  });
  add("regrasp edge duration subnormal to 0",
      [](Sample& s) { s.parts[1].regrasp_edges[1].duration = 0.0; });
  // Schema version 10: the bodies of meta.human_bodies each candidate takes.
  add("candidate takes a body more",
      [](Sample& s) { s.parts[0].handover_candidates[2].bodies = 3; });
  add("candidate takes a body less",
      [](Sample& s) { s.parts[0].handover_candidates[1].bodies = 1; });
  add("candidate takes the other body",
      [](Sample& s) { s.parts[1].handover_candidates[0].bodies = 1; });
  add("candidate bodies swapped", [](Sample& s) {
    auto& c = s.parts[0].handover_candidates;
    std::swap(c[2].bodies, c[3].bodies);
  });
  add("no candidate takes a body", [](Sample& s) { clear_bodies(s); });
  // Schema version 5: direct grasps.
  add("direct grasp pick inclination ulp", [](Sample& s) {
    double& a = s.parts[0].direct_grasps[3].inclination_pick_deg;
    a = std::nextafter(a, 90.0);
  });
  add("direct grasp robot-human inclination ulp", [](Sample& s) {
    double& a = s.parts[0].direct_grasps[2].inclination_rh_deg;
    a = std::nextafter(a, 0.0);
  });
  add("direct grasp robot grasp",
      [](Sample& s) { s.parts[0].direct_grasps[1].robot_grasp_id = 3; });
  add("direct grasp candidate", [](Sample& s) { s.parts[0].direct_grasps[6].candidate_id = 4; });
  add("direct grasp arm", [](Sample& s) { s.parts[0].direct_grasps[0].arm = "right"; });
  add("direct grasp joints swapped", [](Sample& s) {
    auto& g = s.parts[0].direct_grasps[5];
    std::swap(g.joints_pick, g.joints_rh);
  });
  add("direct grasp pick joint -0.0 to +0.0",
      [](Sample& s) { s.parts[0].direct_grasps[0].joints_pick[1] = 0.0; });
  add("direct grasp joint ulp", [](Sample& s) {
    double& q = s.parts[0].direct_grasps[4].joints_rh[3];
    q = std::nextafter(q, 10.0);
  });
  add("direct grasps reordered",
      [](Sample& s) { std::swap(s.parts[0].direct_grasps[0], s.parts[0].direct_grasps[2]); });
  add("a direct grasp less", [](Sample& s) { s.parts[0].direct_grasps.pop_back(); });
  add("no direct grasps", [](Sample& s) { s.parts[0].direct_grasps.clear(); });
  // Schema version 6: table regrasps.
  add("table regrasp place inclination ulp", [](Sample& s) {
    double& a = s.parts[0].table_regrasps[2].inclination_place_deg;
    a = std::nextafter(a, 90.0);
  });
  add("table regrasp repick inclination ulp", [](Sample& s) {
    double& a = s.parts[0].table_regrasps[4].inclination_repick_deg;
    a = std::nextafter(a, 0.0);
  });
  add("table regrasp inclinations swapped", [](Sample& s) {
    auto& r = s.parts[0].table_regrasps[1];
    std::swap(r.inclination_pick_deg, r.inclination_rh_deg);
  });
  add("table regrasp pick grasp",
      [](Sample& s) { s.parts[0].table_regrasps[0].pick_grasp_id = 5; });
  add("table regrasp robot grasp",
      [](Sample& s) { s.parts[0].table_regrasps[3].robot_grasp_id = 1; });
  add("table regrasp grasps swapped", [](Sample& s) {
    auto& r = s.parts[0].table_regrasps[2];
    std::swap(r.pick_grasp_id, r.robot_grasp_id);
  });
  add("table regrasp candidate", [](Sample& s) { s.parts[0].table_regrasps[2].candidate_id = 5; });
  add("table regrasp arm", [](Sample& s) { s.parts[0].table_regrasps[0].arm = "right"; });
  // Schema version 8: the arm that takes it again.
  add("table regrasp repick arm (a relay)",
      [](Sample& s) { s.parts[0].table_regrasps[2].repick_arm = "right"; });
  add("table regrasp relay undone", [](Sample& s) {
    s.parts[0].table_regrasps[1].repick_arm = s.parts[0].table_regrasps[1].arm;
  });
  add("table regrasp arm and repick arm swapped", [](Sample& s) {
    auto& r = s.parts[0].table_regrasps[4];
    std::swap(r.arm, r.repick_arm);
  });
  add("table regrasp placement position ulp", [](Sample& s) {
    double& x = s.parts[0].table_regrasps[3].placement.translation().x();
    x = std::nextafter(x, 10.0);
  });
  add("table regrasp placement turned", [](Sample& s) {
    auto& placement = s.parts[0].table_regrasps[1].placement;
    placement.linear() = Eigen::Matrix3d::Identity();
  });
  add("table regrasp joints swapped", [](Sample& s) {
    auto& r = s.parts[0].table_regrasps[0];
    std::swap(r.joints_place, r.joints_repick);
  });
  add("table regrasp place joint -0.0 to +0.0",
      [](Sample& s) { s.parts[0].table_regrasps[0].joints_place[3] = 0.0; });
  add("table regrasp repick joint ulp", [](Sample& s) {
    double& q = s.parts[0].table_regrasps[3].joints_repick[2];
    q = std::nextafter(q, 10.0);
  });
  add("table regrasps reordered",
      [](Sample& s) { std::swap(s.parts[0].table_regrasps[0], s.parts[0].table_regrasps[2]); });
  add("a table regrasp less", [](Sample& s) { s.parts[0].table_regrasps.pop_back(); });
  add("no table regrasps", [](Sample& s) { s.parts[0].table_regrasps.clear(); });
  // Schema version 8: suction deliveries.
  add("suction delivery candidate",
      [](Sample& s) { s.parts[0].suction_deliveries[3].candidate_id = 4; });
  add("suction delivery suction grasp",
      [](Sample& s) { s.parts[0].suction_deliveries[1].suction_grasp_id = 1; });
  add("suction delivery arm", [](Sample& s) { s.parts[0].suction_deliveries[4].arm = "right"; });
  add("suction delivery joint ulp", [](Sample& s) {
    double& q = s.parts[0].suction_deliveries[3].joints_rh[6];
    q = std::nextafter(q, 10.0);
  });
  add("suction delivery joint -0.0 to +0.0",
      [](Sample& s) { s.parts[0].suction_deliveries[0].joints_rh[1] = 0.0; });
  add("suction delivery joint subnormal to 0",
      [](Sample& s) { s.parts[0].suction_deliveries[4].joints_rh[5] = 0.0; });
  add("suction delivery empty joints get one joint",
      [](Sample& s) { s.parts[0].suction_deliveries[2].joints_rh = Eigen::VectorXd::Zero(1); });
  add("suction delivery a joint less",
      [](Sample& s) { s.parts[0].suction_deliveries[3].joints_rh.conservativeResize(6); });
  add("suction deliveries reordered", [](Sample& s) {
    std::swap(s.parts[0].suction_deliveries[0], s.parts[0].suction_deliveries[1]);
  });
  add("a suction delivery less", [](Sample& s) { s.parts[0].suction_deliveries.pop_back(); });
  add("no suction deliveries", [](Sample& s) { s.parts[0].suction_deliveries.clear(); });
  for (const auto& [name, sample] : variants) {
    const std::string path = dir + "/variant.db";
    write_sample(path, sample);
    EXPECT_NE(content_digest(path), reference) << name;
  }
}

TEST(Digest, OneComfortValueByteChangesIt) {
  const std::string dir = temp_dir("db_digest_comfort_value");
  Sample a = make_sample();
  Sample b = make_sample();
  // A bin in the middle, and one that was 0 (the common case: a bin the arm never reached).
  std::uint8_t& v = b.comfort_maps[0].values[117];
  v = static_cast<std::uint8_t>(v + 1);
  write_sample(dir + "/a.db", a);
  write_sample(dir + "/b.db", b);
  EXPECT_NE(content_digest(dir + "/a.db"), content_digest(dir + "/b.db"));
  Sample c = make_sample();
  auto& values = c.comfort_maps[1].values;
  const auto zero = std::find(values.begin(), values.end(), 0);
  ASSERT_NE(zero, values.end());
  *zero = 1;
  write_sample(dir + "/c.db", c);
  EXPECT_NE(content_digest(dir + "/a.db"), content_digest(dir + "/c.db"));
  write_sample(dir + "/d.db", make_sample());
  EXPECT_EQ(content_digest(dir + "/a.db"), content_digest(dir + "/d.db"));
}

TEST(Digest, OneRoadmapFilterBitChangesIt) {
  const std::string dir = temp_dir("db_digest_filter_bit");
  write_sample(dir + "/a.db", make_sample());
  const std::string reference = content_digest(dir + "/a.db");
  // Edge 12 of 13 (the last, alone in its byte) and edge 3 (in a full byte), each flipped with
  // the components and counts that go with it (the writer refuses anything else).
  for (const std::size_t edge : {std::size_t{12}, std::size_t{3}}) {
    SCOPED_TRACE(edge);
    Sample b = make_sample();
    RoadmapFilterRecord& f = b.parts[0].roadmap_filters[0];
    ASSERT_EQ(f.edges.size(), 13u);
    f.edges[edge] = !f.edges[edge];
    complete_filter(f, b.roadmaps[0]);
    write_sample(dir + "/b.db", b);
    EXPECT_NE(content_digest(dir + "/b.db"), reference);
  }
  write_sample(dir + "/c.db", make_sample());
  EXPECT_EQ(content_digest(dir + "/c.db"), reference) << "and the same sample gives the same";
}

TEST(Digest, OneRegraspPathValueChangesIt) {
  const std::string dir = temp_dir("db_digest_regrasp_path");
  write_sample(dir + "/a.db", make_sample());
  const std::string reference = content_digest(dir + "/a.db");
  // One joint value of one waypoint of part 1's first edge (a path via the roadmap), by one ulp.
  Sample b = make_sample();
  ASSERT_EQ(b.parts[0].regrasp_edges[0].via, "roadmap");
  double& q = b.parts[0].regrasp_edges[0].path[3][4];
  const double before = q;
  q = std::nextafter(q, 10.0);
  ASSERT_NE(q, before);
  write_sample(dir + "/b.db", b);
  EXPECT_NE(content_digest(dir + "/b.db"), reference);
  write_sample(dir + "/c.db", make_sample());
  EXPECT_EQ(content_digest(dir + "/c.db"), reference) << "and the same sample gives the same";
}

TEST(Digest, IndependentOfTheFileName) {
  const std::string dir = temp_dir("db_digest_rename");
  write_sample(dir + "/a.db", make_sample());
  const std::string before = content_digest(dir + "/a.db");
  std::filesystem::rename(dir + "/a.db", dir + "/elsewhere.sqlite");
  EXPECT_EQ(content_digest(dir + "/elsewhere.sqlite"), before);
}

TEST(Digest, CreatedAtIsTheOnlyIgnoredMetaKey) {
  const std::string dir = temp_dir("db_digest_meta");
  write_sample(dir + "/a.db", make_sample());
  const std::string before = content_digest(dir + "/a.db");
  detail::execute_script(dir + "/a.db", "UPDATE meta SET value = 'x' WHERE key = 'created_at'");
  EXPECT_EQ(content_digest(dir + "/a.db"), before);
  detail::execute_script(dir + "/a.db", "UPDATE meta SET value = 'x' WHERE key = 'hila_version'");
  EXPECT_NE(content_digest(dir + "/a.db"), before);
}

TEST(Digest, RefusesNonHilaFiles) {
  const std::string dir = temp_dir("db_digest_foreign");
  expect_input_error([&] { content_digest(write_file(dir, "t.db", "hello")); },
                     {"t.db", "expected a hila database (SQLite)"});
  expect_input_error([&] { content_digest(dir + "/missing.db"); }, {"no such file"});
}
