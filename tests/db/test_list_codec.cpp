#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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
