#pragma once

// Encodings of the values that are lists: joint vectors as BLOBs of little-endian doubles, lists
// of part names as newline-joined TEXT. Private to hila::db.

#include <Eigen/Core>
#include <string>
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

}  // namespace hila::db::detail
