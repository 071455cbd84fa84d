#include "list_codec.hpp"

#include <cstdint>
#include <cstring>

namespace hila::db::detail {

void put_double(std::string& out, double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof(bits));
  for (int i = 0; i < 8; ++i) {
    out.push_back(static_cast<char>(bits & 0xff));
    bits >>= 8;
  }
}

double get_double(const unsigned char* bytes) {
  std::uint64_t bits = 0;
  for (int i = 7; i >= 0; --i) bits = (bits << 8) | bytes[i];
  double value = 0.0;
  std::memcpy(&value, &bits, sizeof(value));
  return value;
}

std::string encode_doubles(const Eigen::VectorXd& values) {
  std::string bytes;
  bytes.reserve(static_cast<std::size_t>(values.size()) * 8);
  for (Eigen::Index i = 0; i < values.size(); ++i) put_double(bytes, values[i]);
  return bytes;
}

bool decode_doubles(const std::string& bytes, Eigen::VectorXd& values) {
  if (bytes.size() % 8 != 0) return false;
  const auto count = static_cast<Eigen::Index>(bytes.size() / 8);
  values.resize(count);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  for (Eigen::Index i = 0; i < count; ++i) values[i] = get_double(data + 8 * i);
  return true;
}

std::string encode_names(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i) text += '\n';
    text += names[i];
  }
  return text;
}

std::vector<std::string> decode_names(const std::string& text) {
  std::vector<std::string> names;
  if (text.empty()) return names;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find('\n', start);
    names.push_back(text.substr(start, end == std::string::npos ? std::string::npos : end - start));
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return names;
}

int invalid_name(const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty() || names[i].find('\n') != std::string::npos) return static_cast<int>(i);
  }
  return -1;
}

namespace {

void put_int32(std::string& out, int value) {
  auto bits = static_cast<std::uint32_t>(value);
  for (int i = 0; i < 4; ++i) {
    out.push_back(static_cast<char>(bits & 0xff));
    bits >>= 8;
  }
}

int get_int32(const unsigned char* bytes) {
  std::uint32_t bits = 0;
  for (int i = 3; i >= 0; --i) bits = (bits << 8) | bytes[i];
  return static_cast<std::int32_t>(bits);
}

const unsigned char* data_of(const std::string& bytes) {
  return reinterpret_cast<const unsigned char*>(bytes.data());
}

bool has_size(const std::string& bytes, std::int64_t count, std::int64_t element_bytes) {
  const std::int64_t expected = blob_bytes(count, element_bytes);
  return expected >= 0 && static_cast<std::int64_t>(bytes.size()) == expected;
}

}  // namespace

std::int64_t blob_bytes(std::int64_t count, std::int64_t element_bytes) {
  constexpr std::int64_t kLimit = std::int64_t{1} << 31;
  if (count < 0 || element_bytes < 0) return -1;
  if (element_bytes != 0 && count > kLimit / element_bytes) return -1;
  return count * element_bytes;
}

std::string encode_vectors(const std::vector<Eigen::VectorXd>& vectors) {
  std::string bytes;
  for (const auto& v : vectors) bytes += encode_doubles(v);
  return bytes;
}

std::string encode_vectors(const std::vector<Eigen::Vector3d>& vectors) {
  std::string bytes;
  bytes.reserve(vectors.size() * 24);
  for (const auto& v : vectors) {
    for (int i = 0; i < 3; ++i) put_double(bytes, v[i]);
  }
  return bytes;
}

bool decode_vectors(const std::string& bytes, std::int64_t count, std::int64_t size,
                    std::vector<Eigen::VectorXd>& vectors) {
  if (size < 0 || !has_size(bytes, count, blob_bytes(size, 8))) return false;
  const unsigned char* data = data_of(bytes);
  vectors.assign(static_cast<std::size_t>(count), Eigen::VectorXd(size));
  for (std::int64_t i = 0; i < count; ++i) {
    for (std::int64_t j = 0; j < size; ++j) {
      vectors[static_cast<std::size_t>(i)][j] = get_double(data + 8 * (i * size + j));
    }
  }
  return true;
}

bool decode_vectors(const std::string& bytes, std::int64_t count,
                    std::vector<Eigen::Vector3d>& vectors) {
  if (!has_size(bytes, count, 24)) return false;
  const unsigned char* data = data_of(bytes);
  vectors.resize(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i) {
    for (int j = 0; j < 3; ++j)
      vectors[static_cast<std::size_t>(i)][j] = get_double(data + 24 * i + 8 * j);
  }
  return true;
}

std::string encode_double_list(const std::vector<double>& values) {
  std::string bytes;
  bytes.reserve(values.size() * 8);
  for (double v : values) put_double(bytes, v);
  return bytes;
}

bool decode_double_list(const std::string& bytes, std::int64_t count, std::vector<double>& values) {
  if (!has_size(bytes, count, 8)) return false;
  const unsigned char* data = data_of(bytes);
  values.resize(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i)
    values[static_cast<std::size_t>(i)] = get_double(data + 8 * i);
  return true;
}

std::string encode_int32s(const std::vector<int>& values) {
  std::string bytes;
  bytes.reserve(values.size() * 4);
  for (int v : values) put_int32(bytes, v);
  return bytes;
}

bool decode_int32s(const std::string& bytes, std::int64_t count, std::vector<int>& values) {
  if (!has_size(bytes, count, 4)) return false;
  const unsigned char* data = data_of(bytes);
  values.resize(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i)
    values[static_cast<std::size_t>(i)] = get_int32(data + 4 * i);
  return true;
}

std::string encode_int32_pairs(const std::vector<std::pair<int, int>>& pairs) {
  std::string bytes;
  bytes.reserve(pairs.size() * 8);
  for (const auto& [first, second] : pairs) {
    put_int32(bytes, first);
    put_int32(bytes, second);
  }
  return bytes;
}

bool decode_int32_pairs(const std::string& bytes, std::int64_t count,
                        std::vector<std::pair<int, int>>& pairs) {
  if (!has_size(bytes, count, 8)) return false;
  const unsigned char* data = data_of(bytes);
  pairs.resize(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i) {
    pairs[static_cast<std::size_t>(i)] = {get_int32(data + 8 * i), get_int32(data + 8 * i + 4)};
  }
  return true;
}

std::string encode_bits(const std::vector<bool>& bits) {
  std::string bytes((bits.size() + 7) / 8, '\0');
  for (std::size_t i = 0; i < bits.size(); ++i) {
    if (bits[i]) bytes[i / 8] = static_cast<char>(bytes[i / 8] | (1 << (i % 8)));
  }
  return bytes;
}

bool decode_bits(const std::string& bytes, std::int64_t count, std::vector<bool>& bits) {
  if (count < 0 || count > (std::int64_t{1} << 34) ||
      static_cast<std::int64_t>(bytes.size()) != (count + 7) / 8) {
    return false;
  }
  const unsigned char* data = data_of(bytes);
  if (count % 8 != 0 && (data[bytes.size() - 1] >> (count % 8)) != 0) return false;
  bits.resize(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i) {
    bits[static_cast<std::size_t>(i)] = ((data[i / 8] >> (i % 8)) & 1) != 0;
  }
  return true;
}

}  // namespace hila::db::detail
