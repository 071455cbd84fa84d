#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "list_codec.hpp"

using namespace hila::db::detail;

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

}  // namespace

TEST(ListCodec, DoublesAreLittleEndianEightBytesEach) {
  Eigen::VectorXd v(2);
  v << 1.0, -2.5;
  // 1.0 = 0x3ff0000000000000, -2.5 = 0xc004000000000000, least significant byte first.
  EXPECT_EQ(hex(encode_doubles(v)), "000000000000f03f00000000000004c0");
}

TEST(ListCodec, DoublesRoundTripBitForBit) {
  Eigen::VectorXd v(7);
  v << -0.0, std::numeric_limits<double>::denorm_min(), 1e300, -1e-300, 3.141592653589793,
      std::numeric_limits<double>::infinity(), std::nan("");
  const std::string bytes = encode_doubles(v);
  ASSERT_EQ(bytes.size(), 56u);
  Eigen::VectorXd back(3);  // resized by the decoder
  ASSERT_TRUE(decode_doubles(bytes, back));
  ASSERT_EQ(back.size(), 7);
  EXPECT_EQ(encode_doubles(back), bytes) << "same bits, NaN and -0.0 included";
  EXPECT_TRUE(std::signbit(back[0]));
  EXPECT_TRUE(std::isnan(back[6]));
}

TEST(ListCodec, EmptyVectorIsEmptyBytesAndBack) {
  EXPECT_EQ(encode_doubles(Eigen::VectorXd()), "");
  Eigen::VectorXd back = Eigen::VectorXd::Ones(4);
  ASSERT_TRUE(decode_doubles("", back));
  EXPECT_EQ(back.size(), 0);
}

TEST(ListCodec, PartialDoubleIsRefused) {
  Eigen::VectorXd back;
  EXPECT_FALSE(decode_doubles(std::string(7, '\0'), back));
  EXPECT_FALSE(decode_doubles(std::string(17, '\0'), back));
  EXPECT_TRUE(decode_doubles(std::string(16, '\0'), back));
  EXPECT_EQ(back, Eigen::Vector2d::Zero());
}

TEST(ListCodec, SingleDoubleHelpers) {
  std::string out;
  put_double(out, -2.5);
  ASSERT_EQ(out.size(), 8u);
  EXPECT_EQ(get_double(reinterpret_cast<const unsigned char*>(out.data())), -2.5);
}

TEST(ListCodec, NamesJoinedByNewline) {
  EXPECT_EQ(encode_names({}), "");
  EXPECT_EQ(encode_names({"a"}), "a");
  EXPECT_EQ(encode_names({"side panel", "Gehäuse 'ß'", "x"}), "side panel\nGehäuse 'ß'\nx");
  for (const std::vector<std::string>& names :
       {std::vector<std::string>{}, {"a"}, {" a ", "b;c", "部品"}, {"x", "x"}}) {
    EXPECT_EQ(decode_names(encode_names(names)), names);
    EXPECT_EQ(invalid_name(names), -1);
  }
}

TEST(ListCodec, NamesTheEncodingCannotKeepAreFound) {
  EXPECT_EQ(invalid_name({""}), 0);
  EXPECT_EQ(invalid_name({"a", "b\nc"}), 1);
  EXPECT_EQ(invalid_name({"a", "b", ""}), 2);
  // What would go wrong: an empty name alone reads back as no names, one with '\n' as two.
  EXPECT_TRUE(decode_names(encode_names({""})).empty());
  EXPECT_EQ(decode_names(encode_names({"b\nc"})).size(), 2u);
}

TEST(ListCodec, BitsAreLeastSignificantFirstWithZeroPadding) {
  // 13 bits: edges 0, 2, 8 and 12 set -> byte 0 = 0b00000101, byte 1 = 0b00010001.
  std::vector<bool> bits(13, false);
  bits[0] = bits[2] = bits[8] = bits[12] = true;
  const std::string bytes = encode_bits(bits);
  EXPECT_EQ(hex(bytes), "0511");
  std::vector<bool> back(3, true);  // resized by the decoder
  ASSERT_TRUE(decode_bits(bytes, 13, back));
  EXPECT_EQ(back, bits);
  // Exactly one byte, and none.
  EXPECT_EQ(hex(encode_bits(std::vector<bool>(8, true))), "ff");
  EXPECT_EQ(encode_bits({}), "");
  ASSERT_TRUE(decode_bits("", 0, back));
  EXPECT_TRUE(back.empty());
}

TEST(ListCodec, BitsOfAnotherCountOrWithPaddingSetAreRefused) {
  std::vector<bool> back;
  EXPECT_FALSE(decode_bits(std::string(1, '\x01'), 13, back)) << "one byte short";
  EXPECT_FALSE(decode_bits(std::string(3, '\x01'), 13, back)) << "one byte too many";
  EXPECT_FALSE(decode_bits(std::string("\x01\x20", 2), 13, back)) << "bit 13 is padding";
  EXPECT_TRUE(decode_bits(std::string("\x01\x10", 2), 13, back)) << "bit 12 is the last edge";
  EXPECT_FALSE(decode_bits("", -1, back));
  EXPECT_FALSE(decode_bits(std::string(1, '\0'), 0, back));
}

TEST(ListCodec, Int32sAndPairsAreLittleEndianFourBytesEach) {
  EXPECT_EQ(hex(encode_int32s({1, -2, 0x01020304})), "01000000feffffff04030201");
  std::vector<int> ints;
  ASSERT_TRUE(decode_int32s(encode_int32s({7, -1, 2147483647}), 3, ints));
  EXPECT_EQ(ints, (std::vector<int>{7, -1, 2147483647}));
  EXPECT_FALSE(decode_int32s(std::string(11, '\0'), 3, ints));
  EXPECT_FALSE(decode_int32s(std::string(12, '\0'), 2, ints));

  const std::vector<std::pair<int, int>> pairs = {{0, 1}, {3, 10}};
  EXPECT_EQ(hex(encode_int32_pairs(pairs)), "0000000001000000030000000a000000");
  std::vector<std::pair<int, int>> back;
  ASSERT_TRUE(decode_int32_pairs(encode_int32_pairs(pairs), 2, back));
  EXPECT_EQ(back, pairs);
  EXPECT_FALSE(decode_int32_pairs(std::string(15, '\0'), 2, back)) << "a truncated pair";
  EXPECT_FALSE(decode_int32_pairs(std::string(8, '\0'), 2, back));
}

TEST(ListCodec, VectorListsRoundTripBitForBit) {
  std::vector<Eigen::VectorXd> joints = {Eigen::VectorXd(3), Eigen::VectorXd(3)};
  joints[0] << -0.0, 1.0, std::numeric_limits<double>::denorm_min();
  joints[1] << -2.5, 1e300, 3.0;
  const std::string bytes = encode_vectors(joints);
  ASSERT_EQ(bytes.size(), 48u);
  EXPECT_EQ(bytes.substr(24, 8), encode_doubles(Eigen::VectorXd::Constant(1, -2.5)))
      << "vector 1 starts at byte 8 * size";
  std::vector<Eigen::VectorXd> back;
  ASSERT_TRUE(decode_vectors(bytes, 2, 3, back));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(encode_vectors(back), bytes);
  EXPECT_TRUE(std::signbit(back[0][0]));
  EXPECT_FALSE(decode_vectors(bytes, 3, 3, back)) << "48 bytes are not 3 x 3 doubles";
  EXPECT_FALSE(decode_vectors(bytes, 2, 2, back)) << "48 bytes are not 2 x 2 doubles";
  EXPECT_TRUE(decode_vectors(bytes, 3, 2, back)) << "only the total size is in the bytes";
  EXPECT_FALSE(decode_vectors(bytes.substr(1), 2, 3, back));
  ASSERT_TRUE(decode_vectors("", 0, 6, back));
  EXPECT_TRUE(back.empty());

  const std::vector<Eigen::Vector3d> directions = {{0.0, -0.0, -1.0}, {0.6, 0.8, 0.0}};
  const std::string direction_bytes = encode_vectors(directions);
  ASSERT_EQ(direction_bytes.size(), 48u);
  std::vector<Eigen::Vector3d> directions_back;
  ASSERT_TRUE(decode_vectors(direction_bytes, 2, directions_back));
  EXPECT_EQ(directions_back, directions);
  EXPECT_TRUE(std::signbit(directions_back[0].y()));
  EXPECT_FALSE(decode_vectors(direction_bytes, 3, directions_back));

  const std::vector<double> values = {0.25, -0.0, 90.0};
  std::vector<double> values_back;
  ASSERT_TRUE(decode_double_list(encode_double_list(values), 3, values_back));
  EXPECT_EQ(values_back, values);
  EXPECT_TRUE(std::signbit(values_back[1]));
  EXPECT_FALSE(decode_double_list(encode_double_list(values), 4, values_back));
}

TEST(ListCodec, BlobBytesRefusesNegativeAndHugeCounts) {
  EXPECT_EQ(blob_bytes(13, 8), 104);
  EXPECT_EQ(blob_bytes(0, 8), 0);
  EXPECT_EQ(blob_bytes(-1, 8), -1);
  EXPECT_EQ(blob_bytes(std::int64_t{1} << 40, 8), -1);
  EXPECT_EQ(blob_bytes(std::int64_t{1} << 28, 8), std::int64_t{1} << 31);
}
