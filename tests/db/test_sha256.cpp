#include <gtest/gtest.h>

#include <string>

#include "hila/core/error.hpp"
#include "hila/db/database.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::test;

TEST(Sha256, KnownVectors) {
  // FIPS 180-2 test vectors.
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, HexIsLowerCaseAnd64Characters) {
  const std::string hex = sha256_hex("hila");
  ASSERT_EQ(hex.size(), 64u);
  EXPECT_EQ(hex.find_first_not_of("0123456789abcdef"), std::string::npos) << hex;
}

TEST(Sha256, BytesWithNulAreHashedInFull) {
  const std::string with_nul("a\0b", 3);
  EXPECT_NE(sha256_hex(with_nul), sha256_hex("a"));
  EXPECT_NE(sha256_hex(with_nul), sha256_hex(std::string("a\0c", 3)));
}

TEST(Sha256, FileEqualsHashOfItsBytes) {
  const std::string dir = temp_dir("db_sha256_file");
  // Larger than the read buffer and containing every byte value, so chunking and binary mode
  // both matter.
  std::string bytes;
  for (int i = 0; i < 200000; ++i) bytes.push_back(static_cast<char>((i * 7919) & 0xff));
  const std::string path = write_file(dir, "data.bin", bytes);
  ASSERT_EQ(read_file(path).size(), bytes.size());
  EXPECT_EQ(sha256_file(path), sha256_hex(bytes));
  EXPECT_EQ(sha256_file(write_file(dir, "abc.txt", "abc")),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_file(write_file(dir, "empty.txt", "")), sha256_hex(""));
}

TEST(Sha256, MissingFileIsAnInputErrorNamingIt) {
  const std::string path = temp_dir("db_sha256_missing") + "/nope.stl";
  expect_input_error([&] { sha256_file(path); }, {path, "no such file"});
  try {
    sha256_file(path);
    FAIL() << "no exception";
  } catch (const hila::core::InputError& e) {
    EXPECT_EQ(e.file(), path);
  }
}

TEST(Sha256, DirectoryIsAnInputError) {
  const std::string dir = temp_dir("db_sha256_dir");
  expect_input_error([&] { sha256_file(dir); }, {dir, "a directory"});
}
