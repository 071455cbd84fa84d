#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

namespace hila::tools {

// CLI11 validators that read the option's text strictly and say what was expected in readable
// terms; CLI11 prefixes the option's name: "--jobs: expected an integer in [1, 1024], got 0".

// A decimal integer in [lo, hi] (no sign for an unsigned option, no exponent, no fraction).
CLI::Validator int_in(long long lo, long long hi);
// A decimal integer in [0, 2^64): a seed.
CLI::Validator uint64_any();
// A finite number in [lo, hi], or (lo, hi] when `lo_open`; `unit` ("seconds") words the message.
CLI::Validator number_in(double lo, double hi, bool lo_open = false, const std::string& unit = "");

}  // namespace hila::tools
