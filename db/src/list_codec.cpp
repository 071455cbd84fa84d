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

}  // namespace hila::db::detail
