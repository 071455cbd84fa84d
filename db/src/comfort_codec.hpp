#pragma once

// Encoding of comfort maps for the comfort_maps table: orientations as little-endian doubles,
// values zlib-compressed. Private to hila::db.

#include <cstdint>
#include <string>
#include <vector>

#include "hila/db/records.hpp"

namespace hila::db::detail {

// How far a stored orientation's norm may be from 1.
inline constexpr double kUnitQuaternionTolerance = 1e-9;

// Throws std::invalid_argument naming the arm and what is wrong: an empty arm name, a spacing or
// origin that is not finite and positive/finite, a dimension <= 0, a values size other than
// dims.prod() * orientations.size(), an orientation that is not a unit quaternion.
void validate_comfort_map(const ComfortMapRecord& map);

// dims.prod() * orientation_count, or -1 when a factor is negative or the product overflows.
std::int64_t comfort_value_count(std::int64_t dim_x, std::int64_t dim_y, std::int64_t dim_z,
                                 std::int64_t orientation_count);

// 32 bytes per orientation: w, x, y, z as IEEE doubles, little-endian.
std::string encode_orientations(const std::vector<Eigen::Quaterniond>& orientations);
// False unless `bytes` holds exactly `count` orientations.
bool decode_orientations(const std::string& bytes, std::int64_t count,
                         std::vector<Eigen::Quaterniond>& orientations);

// zlib compress2 at level 6. Throws std::runtime_error if zlib fails (out of memory).
std::string deflate_values(const std::vector<std::uint8_t>& values);

// Inflates a zlib stream that must hold exactly `size` bytes and nothing after them. Returns an
// empty string on success, otherwise what is wrong (for "got ..." in a DatabaseError).
std::string inflate_values(const std::string& compressed, std::int64_t size,
                           std::vector<std::uint8_t>& values);

}  // namespace hila::db::detail
