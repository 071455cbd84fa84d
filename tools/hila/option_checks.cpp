#include "option_checks.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "hila/core/error.hpp"

namespace hila::tools {

namespace {
std::string got(const std::string& text) {
  return text.empty() ? "''" : text;
}
}  // namespace

CLI::Validator int_in(long long lo, long long hi) {
  const std::string range = "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        long long value = 0;
        const char* end = text.data() + text.size();
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (error != std::errc() || stop != end || value < lo || value > hi) {
          return "expected an integer in " + range + ", got " + got(text);
        }
        return "";
      },
      "INT in " + range);
}

CLI::Validator uint64_any() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::uint64_t value = 0;
        const char* end = text.data() + text.size();
        // from_chars into an unsigned type takes no sign and reports overflow past 2^64 - 1.
        const auto [stop, error] = std::from_chars(text.data(), end, value);
        if (error != std::errc() || stop != end) {
          return "expected an integer in [0, 2^64), got " + got(text);
        }
        return "";
      },
      "INT in [0, 2^64)");
}

CLI::Validator number_in(double lo, double hi, bool lo_open, const std::string& unit) {
  const std::string range = std::string(lo_open ? "(" : "[") + core::format_number(lo) + ", " +
                            core::format_number(hi) + "]";
  const std::string what = unit.empty() ? "a number" : unit;
  return CLI::Validator(
      [lo, hi, lo_open, range, what](std::string& text) -> std::string {
        errno = 0;
        char* stop = nullptr;
        const double value = std::strtod(text.c_str(), &stop);
        const bool parsed = !text.empty() && stop == text.c_str() + text.size() && errno == 0;
        const bool inside = std::isfinite(value) && (lo_open ? value > lo : value >= lo) &&
                            value <= hi;
        if (!parsed || !inside) return "expected " + what + " in " + range + ", got " + got(text);
        return "";
      },
      "NUMBER in " + range);
}

}  // namespace hila::tools
