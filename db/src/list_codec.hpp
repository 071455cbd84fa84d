#pragma once

// Encodings of the values that are lists: joint vectors as BLOBs of little-endian doubles, lists
// of part names as newline-joined TEXT, and the roadmap arrays (schema version 4) as BLOBs of
// little-endian doubles, int32s and bits. Private to hila::db.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace hila::db::detail {

// One IEEE double as 8 little-endian bytes, and back (`bytes` points at 8 of them).
void put_double(std::string& out, double value);
double get_double(const unsigned char* bytes);

// 8 bytes per value, little-endian, in order; an empty vector is an empty string (an empty BLOB).
std::string encode_doubles(const Eigen::VectorXd& values);
// False unless `bytes` holds a whole number of doubles (size % 8 == 0); `values` is then resized.
bool decode_doubles(const std::string& bytes, Eigen::VectorXd& values);

// The names joined by "\n" (no trailing newline); an empty list is the empty string. Names must
// not be empty nor contain '\n' (the encoding could not tell them apart): see invalid_name().
std::string encode_names(const std::vector<std::string>& names);
std::vector<std::string> decode_names(const std::string& text);
// The index of the first name encode_names cannot store, or -1 when all are fine.
int invalid_name(const std::vector<std::string>& names);

// The roadmap arrays. Every decoder takes the element count the row declares and returns false
// unless `bytes` holds exactly that many elements (the output is then resized and filled).
//
// `count` vectors of `size` doubles each, concatenated (vector i at bytes 8 * size * i on); the
// encoders take the vectors as they are (callers check the sizes).
std::string encode_vectors(const std::vector<Eigen::VectorXd>& vectors);
std::string encode_vectors(const std::vector<Eigen::Vector3d>& vectors);
bool decode_vectors(const std::string& bytes, std::int64_t count, std::int64_t size,
                    std::vector<Eigen::VectorXd>& vectors);
bool decode_vectors(const std::string& bytes, std::int64_t count,
                    std::vector<Eigen::Vector3d>& vectors);
// 8 bytes per double.
std::string encode_double_list(const std::vector<double>& values);
bool decode_double_list(const std::string& bytes, std::int64_t count, std::vector<double>& values);
// 4 bytes per value: two's complement int32, little-endian.
std::string encode_int32s(const std::vector<int>& values);
bool decode_int32s(const std::string& bytes, std::int64_t count, std::vector<int>& values);
// Pairs as two int32s each (first, second).
std::string encode_int32_pairs(const std::vector<std::pair<int, int>>& pairs);
bool decode_int32_pairs(const std::string& bytes, std::int64_t count,
                        std::vector<std::pair<int, int>>& pairs);
// ceil(count / 8) bytes; bit i is bit i % 8 (least significant first) of byte i / 8, and the
// unused high bits of the last byte are 0 (the decoder refuses anything else, so equal bit lists
// always store equal bytes).
std::string encode_bits(const std::vector<bool>& bits);
bool decode_bits(const std::string& bytes, std::int64_t count, std::vector<bool>& bits);

// count * element_bytes, or -1 when count < 0 or the product exceeds what a BLOB can hold (2^31);
// a row's declared counts go through this before anything is compared with them.
std::int64_t blob_bytes(std::int64_t count, std::int64_t element_bytes);

}  // namespace hila::db::detail
