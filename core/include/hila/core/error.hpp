#pragma once

#include <stdexcept>
#include <string>

namespace hila::core {

// Bad user input (files, fields, values). The message always names the file, the field and what
// was expected, so a cell engineer can fix the input without reading code.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& field, const std::string& expected,
             const std::string& got);
  explicit InputError(const std::string& message);

  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_;
  std::string field_;
};

// Formats a double for messages: shortest round-trippable form, "nan"/"inf" spelled out.
std::string format_number(double value);

}  // namespace hila::core
