#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "comfort_codec.hpp"
#include "hila/db/database.hpp"
#include "hila/db/migration.hpp"
#include "sample_records.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::detail;
using namespace hila::db::test_data;
using namespace hila::test;

namespace {

std::string hex(const std::string& bytes) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (const unsigned char c : bytes) {
    out += kHex[c >> 4];
    out += kHex[c & 0x0f];
  }
  return out;
}

// zlib at another level than the writer's, to show that only the values matter.
std::string compress_at(const std::vector<std::uint8_t>& values, int level) {
  uLongf size = compressBound(static_cast<uLong>(values.size()));
  std::string out(size, '\0');
  EXPECT_EQ(compress2(reinterpret_cast<Bytef*>(out.data()), &size, values.data(),
                      static_cast<uLong>(values.size()), level),
            Z_OK);
  out.resize(size);
  return out;
}

}  // namespace

TEST(ComfortCodec, OrientationsAreLittleEndianDoublesWxyz) {
  const std::vector<Eigen::Quaterniond> q = {Eigen::Quaterniond(1.0, 0.0, -0.0, 0.0),
                                             Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5)};
  const std::string bytes = encode_orientations(q);
  ASSERT_EQ(bytes.size(), 64u);
  // 1.0 = 0x3ff0000000000000, least significant byte first; then x = 0, y = -0.0 (sign bit kept).
  EXPECT_EQ(hex(bytes.substr(0, 32)),
            "000000000000f03f"
            "0000000000000000"
            "0000000000000080"
            "0000000000000000");
  EXPECT_EQ(hex(bytes.substr(32, 8)), "000000000000e03f");  // 0.5
  EXPECT_EQ(hex(bytes.substr(40, 8)), "000000000000e0bf");  // -0.5

  std::vector<Eigen::Quaterniond> back;
  ASSERT_TRUE(decode_orientations(bytes, 2, back));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[1].coeffs(), q[1].coeffs());
  EXPECT_TRUE(std::signbit(back[0].y()));
  EXPECT_FALSE(decode_orientations(bytes, 3, back));
  EXPECT_FALSE(decode_orientations(bytes, 1, back));
  EXPECT_FALSE(decode_orientations(bytes.substr(0, 63), 2, back));
  EXPECT_FALSE(decode_orientations(bytes, -2, back));
  EXPECT_TRUE(decode_orientations("", 0, back));
  EXPECT_TRUE(back.empty());
}

TEST(ComfortCodec, ValueCountRefusesNegativeAndOverflow) {
  EXPECT_EQ(comfort_value_count(47, 47, 47, 128), 13289344);
  EXPECT_EQ(comfort_value_count(3, 2, 1, 0), 0);
  EXPECT_EQ(comfort_value_count(3, -2, 1, 4), -1);
  EXPECT_EQ(comfort_value_count(1 << 30, 1 << 30, 1 << 30, 1), -1);
}

TEST(ComfortCodec, DeflateInflateRoundTrip) {
  for (const std::size_t size : {std::size_t{0}, std::size_t{1}, std::size_t{100000}}) {
    SCOPED_TRACE(size);
    std::vector<std::uint8_t> values(size, 0);
    for (std::size_t i = 0; i < size; i += 37) values[i] = static_cast<std::uint8_t>(i % 255 + 1);
    const std::string compressed = deflate_values(values);
    EXPECT_FALSE(compressed.empty()) << "even no values make a (short) zlib stream";
    if (size == 100000) {
      EXPECT_LT(compressed.size(), size / 5) << "mostly zeros compress well";
    }
    std::vector<std::uint8_t> back{42};
    EXPECT_EQ(inflate_values(compressed, static_cast<std::int64_t>(size), back), "");
    EXPECT_EQ(back, values);
  }
}

TEST(ComfortCodec, InflateSaysWhatIsWrong) {
  std::vector<std::uint8_t> values(1000, 0);
  values[500] = 7;
  const std::string good = deflate_values(values);
  std::vector<std::uint8_t> out;
  EXPECT_EQ(inflate_values(good, 500, out), "a zlib stream of more than 500 bytes");
  EXPECT_EQ(inflate_values(good, 999, out), "a zlib stream of 1000 bytes");  // ends at the probe
  EXPECT_EQ(inflate_values(good, 1001, out), "a zlib stream of 1000 bytes");
  EXPECT_EQ(inflate_values(good + "x", 1000, out), "a zlib stream followed by extra bytes");
  EXPECT_NE(inflate_values(good.substr(0, good.size() - 3), 1000, out).find("cut-off"),
            std::string::npos);
  EXPECT_NE(inflate_values("", 1000, out).find("cut-off"), std::string::npos);
  std::string flipped = good;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x10);
  EXPECT_NE(inflate_values(flipped, 1000, out).find("not a valid zlib stream"), std::string::npos);
  EXPECT_NE(inflate_values("hello world", 1000, out).find("incorrect header check"),
            std::string::npos);
  EXPECT_EQ(inflate_values(good, -1, out), "a negative size");
  // A size no stream of this length can reach is refused before allocating it.
  EXPECT_NE(inflate_values(good, std::numeric_limits<std::int64_t>::max() / 2, out)
                .find("too short to inflate"),
            std::string::npos);
}

TEST(ComfortCodec, ValidationMessagesNameTheArm) {
  ComfortMapRecord map = make_comfort_map("left", 1, {2, 2, 2}, 3);
  EXPECT_NO_THROW(validate_comfort_map(map));
  map.values.pop_back();
  try {
    validate_comfort_map(map);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("comfort map of arm 'left'"), std::string::npos)
        << e.what();
  }
}

TEST(ComfortCodec, DigestAndReaderSeeTheValuesNotTheCompression) {
  const std::string dir = temp_dir("db_comfort_codec_level");
  const std::string path = dir + "/p.db";
  const Sample sample = make_sample();
  write_sample(path, sample);
  const std::string digest = content_digest(path);
  const std::string before = read_file(path);
  // The same values compressed by another zlib setting (as another zlib version might).
  const std::string stored = compress_at(sample.comfort_maps[0].values, 0);
  ASSERT_NE(stored, deflate_values(sample.comfort_maps[0].values));
  execute_script(
      path, "UPDATE comfort_maps SET values_deflate = x'" + hex(stored) + "' WHERE arm = 'right'");
  ASSERT_NE(read_file(path), before);
  EXPECT_EQ(content_digest(path), digest);
  EXPECT_EQ(Database::open(path).comfort_map("right").values, sample.comfort_maps[0].values);
}
