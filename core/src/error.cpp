#include "hila/core/error.hpp"

#include <cmath>
#include <cstdio>

namespace hila::core {

InputError::InputError(const std::string& file, const std::string& field,
                       const std::string& expected, const std::string& got)
    : std::runtime_error(file + ": " + field + ": expected " + expected + ", got " + got),
      file_(file),
      field_(field) {}

InputError::InputError(const std::string& message) : std::runtime_error(message) {}

std::string format_number(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.10g", value);
  return buffer;
}

}  // namespace hila::core
