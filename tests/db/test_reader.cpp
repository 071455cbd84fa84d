#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "hila/db/database.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::test_data;
using namespace hila::test;

namespace {

// Doubles must come back bit-exact (SQLite REAL is an IEEE double); only poses go through a
// quaternion and are compared to 1e-12.
void expect_same(const PartRecord& a, const PartRecord& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.assembly_order, b.assembly_order);
  EXPECT_EQ(a.mesh_file, b.mesh_file);
  EXPECT_EQ(a.mesh_hash, b.mesh_hash);
  EXPECT_EQ(a.mass, b.mass);
  EXPECT_EQ(a.mass_properties.volume, b.mass_properties.volume);
  EXPECT_EQ(a.mass_properties.com, b.mass_properties.com);
  EXPECT_EQ(a.mass_properties.inertia, b.mass_properties.inertia);
  EXPECT_EQ(a.extent, b.extent);
  EXPECT_EQ(a.triangle_count, b.triangle_count);
  EXPECT_LT(pose_error(a.target, b.target), 1e-12);
  EXPECT_LT(pose_error(a.initial, b.initial), 1e-12);
}

}  // namespace

class ReaderRoundTrip : public ::testing::Test {
 protected:
  void SetUp() override {
    // One directory per test: ctest runs the tests of this fixture in parallel processes.
    const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    path_ = temp_dir("db_reader_" + test) + "/p.db";
    sample_ = make_sample();
    ids_ = write_sample(path_, sample_);
  }
  std::string path_;
  Sample sample_;
  std::vector<std::int64_t> ids_;
};

TEST_F(ReaderRoundTrip, Meta) {
  const Database db = Database::open(path_);
  const Meta& m = db.meta();
  const Meta& e = sample_.meta;
  EXPECT_EQ(m.schema_version, current_schema_version());
  EXPECT_EQ(m.hila_version, e.hila_version);
  EXPECT_EQ(m.product_name, e.product_name);
  EXPECT_EQ(m.cell_hash, e.cell_hash);
  EXPECT_EQ(m.product_hash, e.product_hash);
  EXPECT_EQ(m.settings_hash, e.settings_hash);
  EXPECT_EQ(m.seed, e.seed) << "2^64 - 1 must survive";
  EXPECT_EQ(m.created_at, e.created_at);
  EXPECT_EQ(m.cell_file, e.cell_file);
  EXPECT_EQ(m.product_file, e.product_file);
  EXPECT_EQ(m.human_bodies, e.human_bodies);
  EXPECT_EQ(db.path(), path_);
}

TEST_F(ReaderRoundTrip, PartsWithIdsInOrder) {
  const Database db = Database::open(path_);
  ASSERT_EQ(db.parts().size(), sample_.parts.size());
  EXPECT_EQ(ids_, (std::vector<std::int64_t>{1, 2}));
  for (std::size_t k = 0; k < sample_.parts.size(); ++k) {
    SCOPED_TRACE(sample_.parts[k].part.name);
    EXPECT_EQ(db.parts()[k].id, ids_[k]);
    expect_same(db.parts()[k], sample_.parts[k].part);
  }
  EXPECT_EQ(db.parts()[0].name, "Gehäuse-ß-部品-🔩") << "UTF-8 names survive";
}

TEST_F(ReaderRoundTrip, Placements) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < sample_.parts.size(); ++k) {
    const auto got = db.placements(ids_[k]);
    const auto& want = sample_.parts[k].placements;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(got[i].part_id, ids_[k]);
      EXPECT_LT(pose_error(got[i].part_in_plane, want[i].part_in_plane), 1e-12);
      EXPECT_EQ(got[i].stability, want[i].stability);
    }
  }
}

TEST_F(ReaderRoundTrip, RobotGrasps) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < sample_.parts.size(); ++k) {
    const auto got = db.robot_grasps(ids_[k]);
    const auto& want = sample_.parts[k].robot_grasps;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      SCOPED_TRACE(i);
      EXPECT_EQ(got[i].part_id, ids_[k]);
      EXPECT_LT(pose_error(got[i].tcp, want[i].tcp), 1e-12);
      EXPECT_EQ(got[i].jaw_width, want[i].jaw_width);
      EXPECT_EQ(got[i].contact_1, want[i].contact_1);
      EXPECT_EQ(got[i].normal_1, want[i].normal_1);
      EXPECT_EQ(got[i].contact_2, want[i].contact_2);
      EXPECT_EQ(got[i].normal_2, want[i].normal_2);
      EXPECT_EQ(got[i].quality, want[i].quality);
      EXPECT_EQ(got[i].friction_torque_capacity, want[i].friction_torque_capacity);
      EXPECT_EQ(got[i].lever, want[i].lever);
      EXPECT_EQ(got[i].theta_c_deg, want[i].theta_c_deg);
    }
  }
  EXPECT_TRUE(std::isinf(db.robot_grasps(ids_[0])[0].friction_torque_capacity));
}

TEST_F(ReaderRoundTrip, SuctionGrasps) {
  const Database db = Database::open(path_);
  const auto got = db.suction_grasps(ids_[0]);
  const auto& want = sample_.parts[0].suction_grasps;
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(got[i].part_id, ids_[0]);
    EXPECT_LT(pose_error(got[i].cup, want[i].cup), 1e-12);
    EXPECT_EQ(got[i].rotation_deg, want[i].rotation_deg);
    EXPECT_EQ(got[i].force_margin, want[i].force_margin);
    EXPECT_EQ(got[i].moment_margin, want[i].moment_margin) << "subnormal survives";
  }
  EXPECT_TRUE(db.suction_grasps(ids_[1]).empty()) << "part 2 has none";
}

TEST_F(ReaderRoundTrip, HumanGrasps) {
  const Database db = Database::open(path_);
  for (std::size_t k = 0; k < sample_.parts.size(); ++k) {
    const auto got = db.human_grasps(ids_[k]);
    const auto& want = sample_.parts[k].human_grasps;
    ASSERT_EQ(got.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) {
      EXPECT_EQ(got[i].part_id, ids_[k]);
      EXPECT_LT(pose_error(got[i].hand, want[i].hand), 1e-12);
      EXPECT_EQ(got[i].aperture, want[i].aperture);
      EXPECT_EQ(got[i].contact_1, want[i].contact_1);
      EXPECT_EQ(got[i].contact_2, want[i].contact_2);
      EXPECT_EQ(got[i].quality, want[i].quality);
      EXPECT_EQ(got[i].one_hand_stable, want[i].one_hand_stable);
    }
  }
  // Both values of the flag are present, so a constant reader would fail.
  EXPECT_NE(db.human_grasps(ids_[0])[0].one_hand_stable,
            db.human_grasps(ids_[0])[1].one_hand_stable);
}

TEST_F(ReaderRoundTrip, ComfortMapsInWriteOrder) {
  const Database db = Database::open(path_);
  ASSERT_EQ(db.comfort_maps().size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    const ComfortMapRecord& got = db.comfort_maps()[k];
    const ComfortMapRecord& want = sample_.comfort_maps[k];
    SCOPED_TRACE(want.arm);
    EXPECT_EQ(got.arm, want.arm);
    EXPECT_EQ(got.origin, want.origin);
    EXPECT_EQ(got.spacing, want.spacing);
    EXPECT_EQ(got.dims, want.dims);
    ASSERT_EQ(got.orientations.size(), want.orientations.size());
    for (std::size_t o = 0; o < want.orientations.size(); ++o) {
      EXPECT_EQ(got.orientations[o].coeffs(), want.orientations[o].coeffs()) << o;
    }
    EXPECT_EQ(got.values, want.values);
    EXPECT_EQ(got.samples, want.samples);
    EXPECT_EQ(got.seed, want.seed) << "a uint64 above 2^63 survives";
    EXPECT_EQ(got.coverage, want.coverage);
  }
  EXPECT_EQ(db.comfort_maps()[0].arm, "right");
  EXPECT_EQ(db.comfort_maps()[1].arm, "left");
}

TEST_F(ReaderRoundTrip, ComfortMapByArm) {
  const Database db = Database::open(path_);
  EXPECT_EQ(&db.comfort_map("left"), &db.comfort_maps()[1]);
  EXPECT_EQ(db.comfort_map("right").dims, Eigen::Vector3i(4, 3, 2));
  expect_input_error(
      [&] { db.comfort_map("torso"); },
      {path_ + ": comfort_maps", "expected a comfort map for arm 'torso' (arms: right, left)",
       "got no such arm"});
}

// A database opened without its comfort maps reads them later, the same as an open with them;
// a file replaced in between is refused rather than mixed with what was opened.
TEST_F(ReaderRoundTrip, ComfortMapsReadLaterAreTheOnesOpened) {
  OpenOptions without;
  without.comfort_maps = false;
  const Database lazy = Database::open(path_, without);
  ASSERT_TRUE(lazy.comfort_maps().empty());
  const auto later = lazy.read_comfort_maps();
  const Database full = Database::open(path_);
  ASSERT_EQ(later.size(), full.comfort_maps().size());
  for (std::size_t i = 0; i < later.size(); ++i) {
    EXPECT_EQ(later[i].arm, full.comfort_maps()[i].arm);
    EXPECT_EQ(later[i].dims, full.comfort_maps()[i].dims);
    EXPECT_EQ(later[i].values, full.comfort_maps()[i].values);
  }
  Sample rebuilt = make_sample();
  rebuilt.meta.created_at = "2031-01-01T00:00:00Z";
  std::filesystem::remove(path_);
  write_sample(path_, rebuilt);
  expect_input_error([&] { lazy.read_comfort_maps(); },
                     {path_ + ": meta", "a file rebuilt or replaced since"});
}

TEST_F(ReaderRoundTrip, PerPartFilteringKeepsIdOrderAcrossInterleavedWrites) {
  // Records of two parts written alternately: ids interleave, each part's list stays ordered.
  const std::string path = temp_dir("db_reader_interleaved") + "/p.db";
  {
    DatabaseWriter writer(path);
    writer.write_meta(sample_.meta);
    const auto a = writer.add_part(sample_.parts[0].part);
    const auto b = writer.add_part(sample_.parts[1].part);
    for (int round = 0; round < 3; ++round) {
      RobotGraspRecord g;
      g.quality = round;
      writer.add_robot_grasps(a, {g});
      g.quality = 10 + round;
      writer.add_robot_grasps(b, {g});
    }
    writer.commit();
  }
  const Database db = Database::open(path);
  const auto a = db.robot_grasps(1);
  const auto b = db.robot_grasps(2);
  ASSERT_EQ(a.size(), 3u);
  ASSERT_EQ(b.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(a[i].id, 2 * i + 1);
    EXPECT_EQ(a[i].quality, i);
    EXPECT_EQ(b[i].id, 2 * i + 2);
    EXPECT_EQ(b[i].quality, 10 + i);
  }
  EXPECT_TRUE(db.robot_grasps(3).empty());
  EXPECT_TRUE(db.placements(0).empty());
}

TEST_F(ReaderRoundTrip, PartByName) {
  const Database db = Database::open(path_);
  EXPECT_EQ(db.part("door panel 'left'").id, 2);
  EXPECT_EQ(db.part("Gehäuse-ß-部品-🔩").id, 1);
  expect_input_error([&] { db.part("lid"); }, {path_, "a part named 'lid'", "door panel 'left'"});
}

TEST_F(ReaderRoundTrip, MatchingHashesOpen) {
  OpenOptions options;
  options.expected_cell_hash = sample_.meta.cell_hash;
  options.expected_product_hash = sample_.meta.product_hash;
  EXPECT_NO_THROW(Database::open(path_, options));
}

TEST_F(ReaderRoundTrip, CellHashMismatchSaysWhatChangedAndHowToRebuild) {
  OpenOptions options;
  options.expected_cell_hash = std::string(64, 'd');
  expect_input_error([&] { Database::open(path_, options); },
                     {path_ + ": meta.cell_hash", "the cell changed since this database was built",
                      "cccccccccccc...", "dddddddddddd...",
                      "rebuild with: hila build meshes/cabinet/product.yaml -o " + path_});
}

TEST_F(ReaderRoundTrip, ProductHashMismatchSaysWhatChangedAndHowToRebuild) {
  OpenOptions options;
  options.expected_cell_hash = sample_.meta.cell_hash;
  options.expected_product_hash = std::string(64, 'b');
  expect_input_error(
      [&] { Database::open(path_, options); },
      {path_ + ": meta.product_hash", "the product changed since this database was built",
       "rebuild with: hila build"});
}

TEST_F(ReaderRoundTrip, DatabaseIsAValueThatOutlivesTheFile) {
  // Fully loaded at open: removing the file afterwards does not matter.
  const Database db = Database::open(path_);
  std::filesystem::remove(path_);
  const Database copy = db;
  EXPECT_EQ(copy.robot_grasps(ids_[0]).size(), sample_.parts[0].robot_grasps.size());
}

TEST(Reader, LargeComfortMapRoundTrip) {
  // About the shape of a real map: 1000 orientations, 92 % zeros, ~4.5 MB of values.
  const std::string dir = temp_dir("db_reader_comfort_large");
  const std::string path = dir + "/p.db";
  const ComfortMapRecord map = make_comfort_map("right", 11, {20, 16, 14}, 1000, 0.92);
  ASSERT_EQ(map.values.size(), 4480000u);
  {
    DatabaseWriter writer(path);
    writer.write_meta(make_sample().meta);
    writer.add_comfort_map(map);
    writer.commit();
  }
  const auto file_size = std::filesystem::file_size(path);
  EXPECT_LT(file_size, map.values.size() / 2) << "the values are stored compressed";
  RecordProperty("file_bytes", std::to_string(file_size));

  const Database db = Database::open(path);
  ASSERT_EQ(db.comfort_maps().size(), 1u);
  const ComfortMapRecord& got = db.comfort_map("right");
  EXPECT_EQ(got.dims, map.dims);
  ASSERT_EQ(got.values.size(), map.values.size());
  EXPECT_TRUE(got.values == map.values) << "every value byte";
  ASSERT_EQ(got.orientations.size(), 1000u);
  double worst = 0.0;
  for (std::size_t o = 0; o < map.orientations.size(); ++o) {
    worst = std::max(
        worst, (got.orientations[o].coeffs() - map.orientations[o].coeffs()).cwiseAbs().maxCoeff());
  }
  EXPECT_LE(worst, 1e-15);
  // The index convention: ((x * dims.y + y) * dims.z + z) * n_orient + o.
  const auto at = [&](const ComfortMapRecord& m, int x, int y, int z, int o) {
    return m.values[((static_cast<std::size_t>(x) * m.dims.y() + y) * m.dims.z() + z) *
                        m.orientations.size() +
                    o];
  };
  EXPECT_EQ(at(got, 19, 15, 13, 999), map.values.back());
  EXPECT_EQ(at(got, 7, 3, 11, 500), at(map, 7, 3, 11, 500));
}

// Opened without the comfort maps (the online planner's way): everything else is as a full open
// reads it, the maps are not there, and asking for one says why rather than "no such arm".
TEST(Reader, ComfortMapsAreLeftOutWhenNotWanted) {
  const std::string dir = temp_dir("db_reader_comfort_skipped");
  const std::string path = dir + "/p.db";
  const ComfortMapRecord map = make_comfort_map("right", 11, {4, 3, 2}, 10, 0.5);
  {
    DatabaseWriter writer(path);
    writer.write_meta(make_sample().meta);
    writer.add_comfort_map(map);
    writer.commit();
  }
  OpenOptions without;
  without.comfort_maps = false;
  const Database lean = Database::open(path, without);
  const Database full = Database::open(path);
  ASSERT_EQ(full.comfort_maps().size(), 1u);
  EXPECT_TRUE(lean.comfort_maps().empty());
  EXPECT_EQ(lean.meta().product_name, full.meta().product_name);
  EXPECT_EQ(lean.meta().cell_hash, full.meta().cell_hash);
  EXPECT_EQ(full.comfort_map("right").values, map.values);
  expect_input_error([&] { lean.comfort_map("right"); },
                     {path, "comfort_maps", "opened without its comfort maps"});
}

TEST(Reader, EmptyDatabaseOpens) {
  const std::string path = temp_dir("db_reader_empty") + "/p.db";
  {
    DatabaseWriter writer(path);
    writer.write_meta(Meta{});
    writer.commit();
  }
  const Database db = Database::open(path);
  EXPECT_TRUE(db.parts().empty());
  EXPECT_TRUE(db.comfort_maps().empty());
  EXPECT_TRUE(db.handover_stages().empty());
  EXPECT_EQ(db.meta().seed, 0u);
  EXPECT_EQ(db.meta().human_bodies, "");
  expect_input_error([&] { db.part("x"); }, {"parts: none"});
}
