#include "comfort_codec.hpp"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "list_codec.hpp"

namespace hila::db::detail {

namespace {

constexpr int kDeflateLevel = 6;
// zlib cannot expand data by more than about 1032:1, so a stored size beyond this bound is damage
// (and must not become a huge allocation).
constexpr std::int64_t kMaxInflateRatio = 1100;

}  // namespace

std::int64_t comfort_value_count(std::int64_t dim_x, std::int64_t dim_y, std::int64_t dim_z,
                                 std::int64_t orientation_count) {
  std::int64_t product = 1;
  for (const std::int64_t factor : {dim_x, dim_y, dim_z, orientation_count}) {
    if (factor < 0) return -1;
    if (factor != 0 && product > std::numeric_limits<std::int64_t>::max() / factor) return -1;
    product *= factor;
  }
  return product;
}

void validate_comfort_map(const ComfortMapRecord& map) {
  const std::string what =
      "DatabaseWriter::add_comfort_map: comfort map of arm '" + map.arm + "': ";
  if (map.arm.empty()) {
    throw std::invalid_argument("DatabaseWriter::add_comfort_map: empty arm name");
  }
  if (!(map.spacing > 0.0) || !std::isfinite(map.spacing)) {
    throw std::invalid_argument(what + "spacing must be a finite value > 0, got " +
                                std::to_string(map.spacing));
  }
  if (!map.origin.allFinite()) throw std::invalid_argument(what + "origin is not finite");
  if ((map.dims.array() <= 0).any()) {
    throw std::invalid_argument(what + "dims must all be > 0, got " + std::to_string(map.dims.x()) +
                                " x " + std::to_string(map.dims.y()) + " x " +
                                std::to_string(map.dims.z()));
  }
  const std::int64_t expected = comfort_value_count(
      map.dims.x(), map.dims.y(), map.dims.z(), static_cast<std::int64_t>(map.orientations.size()));
  if (expected < 0 || static_cast<std::uint64_t>(expected) != map.values.size()) {
    throw std::invalid_argument(
        what + "values must hold dims.prod() * orientations.size() = " +
        std::to_string(map.dims.x()) + " * " + std::to_string(map.dims.y()) + " * " +
        std::to_string(map.dims.z()) + " * " + std::to_string(map.orientations.size()) + " = " +
        std::to_string(expected) + " bytes, got " + std::to_string(map.values.size()));
  }
  for (std::size_t o = 0; o < map.orientations.size(); ++o) {
    const double norm = map.orientations[o].coeffs().norm();
    // Written so that NaN fails too.
    if (!(std::abs(norm - 1.0) <= kUnitQuaternionTolerance)) {
      throw std::invalid_argument(what + "orientation " + std::to_string(o) +
                                  " is not a unit quaternion (norm " + std::to_string(norm) +
                                  ", tolerance 1e-9)");
    }
  }
}

std::string encode_orientations(const std::vector<Eigen::Quaterniond>& orientations) {
  std::string bytes;
  bytes.reserve(orientations.size() * 32);
  for (const auto& q : orientations) {
    for (const double value : {q.w(), q.x(), q.y(), q.z()}) put_double(bytes, value);
  }
  return bytes;
}

bool decode_orientations(const std::string& bytes, std::int64_t count,
                         std::vector<Eigen::Quaterniond>& orientations) {
  if (count < 0 || bytes.size() / 32 != static_cast<std::uint64_t>(count) ||
      bytes.size() % 32 != 0) {
    return false;
  }
  orientations.clear();
  orientations.reserve(static_cast<std::size_t>(count));
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  for (std::int64_t o = 0; o < count; ++o) {
    const unsigned char* q = data + o * 32;
    orientations.emplace_back(get_double(q), get_double(q + 8), get_double(q + 16),
                              get_double(q + 24));  // (w, x, y, z)
  }
  return true;
}

std::string deflate_values(const std::vector<std::uint8_t>& values) {
  static const Bytef kNothing = 0;
  uLongf size = compressBound(static_cast<uLong>(values.size()));
  std::string compressed(size, '\0');
  const int rc = compress2(reinterpret_cast<Bytef*>(compressed.data()), &size,
                           values.empty() ? &kNothing : values.data(),
                           static_cast<uLong>(values.size()), kDeflateLevel);
  if (rc != Z_OK) {
    throw std::runtime_error("zlib compress2 failed (" + std::to_string(rc) + ") on " +
                             std::to_string(values.size()) + " bytes of comfort values");
  }
  compressed.resize(size);
  return compressed;
}

std::string inflate_values(const std::string& compressed, std::int64_t size,
                           std::vector<std::uint8_t>& values) {
  if (size < 0) return "a negative size";
  if (size > kMaxInflateRatio * static_cast<std::int64_t>(compressed.size()) + 1024) {
    return "a " + std::to_string(compressed.size()) + "-byte stream, too short to inflate to " +
           std::to_string(size) + " bytes";
  }
  values.assign(static_cast<std::size_t>(size), 0);
  z_stream stream{};
  if (inflateInit(&stream) != Z_OK) return "a zlib stream (zlib failed to initialise)";
  stream.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(compressed.data()));
  stream.next_out = values.data();
  // avail_in and avail_out are 32-bit: feed both in chunks. Once the output is full, one probe
  // byte tells a stream that ends there from one that holds more.
  constexpr std::size_t kChunk = std::numeric_limits<uInt>::max();
  std::size_t in_left = compressed.size();
  std::size_t out_left = values.size();
  unsigned char probe = 0;
  bool probing = false;
  bool overflow = false;
  int rc = Z_OK;
  while (true) {
    if (stream.avail_in == 0 && in_left > 0) {
      stream.avail_in = static_cast<uInt>(std::min(in_left, kChunk));
      in_left -= stream.avail_in;
    }
    if (stream.avail_out == 0) {
      if (out_left > 0) {
        stream.avail_out = static_cast<uInt>(std::min(out_left, kChunk));
        out_left -= stream.avail_out;
      } else if (!probing) {
        stream.next_out = &probe;
        stream.avail_out = 1;
        probing = true;
      } else {
        overflow = true;
        break;
      }
    }
    rc = inflate(&stream, Z_NO_FLUSH);
    // Z_BUF_ERROR: no progress possible, i.e. the input ended before the stream did.
    if (rc != Z_OK) break;
  }
  const std::uint64_t produced = stream.total_out;
  const bool trailing = stream.avail_in != 0 || in_left != 0;
  const std::string message = stream.msg ? stream.msg : "";
  inflateEnd(&stream);

  if (rc == Z_STREAM_END) {
    if (produced != static_cast<std::uint64_t>(size)) {
      return "a zlib stream of " + std::to_string(produced) + " bytes";
    }
    if (trailing) return "a zlib stream followed by extra bytes";
    return "";
  }
  if (overflow) return "a zlib stream of more than " + std::to_string(size) + " bytes";
  if (rc == Z_DATA_ERROR || rc == Z_NEED_DICT) {
    return "data that is not a valid zlib stream (" + (message.empty() ? "zlib" : message) + ")";
  }
  if (rc == Z_MEM_ERROR) return "a zlib stream that could not be inflated (out of memory)";
  return "a cut-off zlib stream (" + std::to_string(produced) + " bytes before it ends)";
}

}  // namespace hila::db::detail
