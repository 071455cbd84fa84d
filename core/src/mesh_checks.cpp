#include "mesh_checks.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <vector>

#include "hila/core/error.hpp"

namespace hila::core::mesh_checks {
namespace {

// Up to 40 bytes of `text` in quotes for a message; control characters and bytes past ASCII as
// \xNN.
std::string shown(std::string_view text) {
  constexpr std::size_t kShown = 40;
  std::string out = "'";
  for (std::size_t i = 0; i < std::min(text.size(), kShown); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      std::array<char, 5> hex{};
      std::snprintf(hex.data(), hex.size(), "\\x%02x", c);
      out += hex.data();
    }
  }
  return out + (text.size() > kShown ? "...'" : "'");
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool is_blank(char c) { return c == ' ' || c == '\t'; }
bool is_digit(char c) { return c >= '0' && c <= '9'; }
// What assimp's line readers take for a line end (ParsingUtils.h, IsLineEnd).
bool is_line_end(char c) { return c == '\n' || c == '\r' || c == '\0' || c == '\f'; }

// The words of a line, separated by blanks (spaces and tabs, assimp's IsSpace).
std::vector<std::string_view> words(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t at = 0;
  while (at < line.size()) {
    while (at < line.size() && is_blank(line[at])) ++at;
    const std::size_t start = at;
    while (at < line.size() && !is_blank(line[at])) ++at;
    if (at > start) out.push_back(line.substr(start, at - start));
  }
  return out;
}

std::string line_field(std::size_t number) { return "line " + std::to_string(number); }

// Lines ending in "\n" or "\r\n", numbered from 1. Any other line end assimp's IOStreamBuffer
// knows ('\r' alone, '\0', '\f') is refused: on those it reads past its buffer looking for '\n'.
class Lines {
 public:
  Lines(const std::string& path, std::string_view text, std::size_t at = 0, std::size_t number = 0)
      : path_(path), text_(text), at_(at), number_(number) {}

  bool done() const { return at_ >= text_.size(); }
  std::size_t position() const { return at_; }
  std::size_t number() const { return number_; }
  bool ended_in_crlf() const { return crlf_; }
  bool terminated() const { return terminated_; }

  std::string_view next() {
    ++number_;
    const std::size_t start = at_;
    std::size_t end = start;
    while (end < text_.size() && !is_line_end(text_[end])) ++end;
    crlf_ = end + 1 < text_.size() && text_[end] == '\r' && text_[end + 1] == '\n';
    terminated_ = crlf_ || (end < text_.size() && text_[end] == '\n');
    if (end < text_.size() && !terminated_) {
      throw InputError(path_, line_field(number_), "lines ending in \\n or \\r\\n",
                       shown(text_.substr(end, 1)) + " within the line");
    }
    at_ = end + (crlf_ ? 2 : terminated_ ? 1 : 0);
    return text_.substr(start, end - start);
  }

 private:
  const std::string& path_;
  std::string_view text_;
  std::size_t at_;
  std::size_t number_;
  bool crlf_ = false;
  bool terminated_ = false;
};

// ---- PLY ----------------------------------------------------------------------------------------

enum class Kind { unsigned_integer, signed_integer, real };
struct PlyType {
  Kind kind = Kind::unsigned_integer;
  int size = 1;  // bytes in a binary file
};

// The property types assimp knows (PlyParser.cpp, Property::ParseDataType); it drops a property of
// any other type and, with it, the rest of its element's properties.
std::optional<PlyType> ply_type(std::string_view name) {
  if (name == "char" || name == "int8") return PlyType{Kind::signed_integer, 1};
  if (name == "uchar" || name == "uint8") return PlyType{Kind::unsigned_integer, 1};
  if (name == "short" || name == "int16") return PlyType{Kind::signed_integer, 2};
  if (name == "ushort" || name == "uint16") return PlyType{Kind::unsigned_integer, 2};
  if (name == "int" || name == "int32") return PlyType{Kind::signed_integer, 4};
  if (name == "uint" || name == "uint32") return PlyType{Kind::unsigned_integer, 4};
  if (name == "float" || name == "float32") return PlyType{Kind::real, 4};
  if (name == "double" || name == "float64" || name == "double64") return PlyType{Kind::real, 8};
  return std::nullopt;
}

struct PlyProperty {
  std::string name;
  bool list = false;
  PlyType count;  // a list's length
  PlyType item;   // the value, or each of a list's values
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

struct PlyHeader {
  PlyFormat format = PlyFormat::ascii;
  std::vector<PlyElement> elements;
  std::size_t body = 0;   // where the records start
  std::size_t lines = 0;  // the header's lines
};

constexpr const char* kTypes =
    "a PLY type (char, uchar, short, ushort, int, uint, float, double, int8, uint8, int16, "
    "uint16, int32, uint32, float32, float64)";

// The header, line by line, as assimp's PLY::DOM::ParseHeader reads it, but strictly: assimp ends
// an element's properties at a blank line, a comment or a property of unknown type and ignores
// what follows, so that its records would no longer be what the header seems to say.
PlyHeader read_ply_header(const std::string& path, std::string_view text) {
  Lines lines(path, text);
  PlyHeader header;
  std::string_view line = lines.next();
  auto w = words(line);
  const auto refuse = [&](const std::string& expected, const std::string& got) {
    throw InputError(path, line_field(lines.number()), expected, got);
  };
  if (w.size() != 1 || lower(std::string(w[0])) != "ply") refuse("a first line 'ply'", shown(line));
  line = lines.next();
  w = words(line);
  if (w.size() != 3 || w[0] != "format" || w[2] != "1.0" ||
      (w[1] != "ascii" && w[1] != "binary_little_endian" && w[1] != "binary_big_endian")) {
    refuse("'format ascii 1.0', 'format binary_little_endian 1.0' or 'format binary_big_endian 1.0'",
           shown(line));
  }
  header.format = w[1] == "ascii"                  ? PlyFormat::ascii
                  : w[1] == "binary_little_endian" ? PlyFormat::binary_little_endian
                                                   : PlyFormat::binary_big_endian;
  for (;;) {
    if (lines.done()) {
      throw InputError(path, "(file)", "a PLY header that ends with an end_header line",
                       "no end_header line (a file cut short?)");
    }
    line = lines.next();
    w = words(line);
    if (w.empty()) refuse("a header line", "a blank line");
    if (w[0] == "comment" || w[0] == "obj_info") {
      if (!header.elements.empty()) {
        refuse("comments before the first element (not between properties)", shown(line));
      }
    } else if (w[0] == "element") {
      const bool digits = w.size() == 3 && !w[2].empty() && w[2].size() <= 10 &&
                          std::all_of(w[2].begin(), w[2].end(), is_digit);
      if (!digits || std::stoull(std::string(w[2])) > 0xffffffffULL) {
        refuse("'element NAME COUNT' with a COUNT below 2^32", shown(line));
      }
      header.elements.push_back({std::string(w[1]), std::stoull(std::string(w[2])), {}});
    } else if (w[0] == "property") {
      if (header.elements.empty()) refuse("an element line before its properties", shown(line));
      PlyProperty property;
      if (w.size() == 3) {
        const auto type = ply_type(w[1]);
        if (!type) refuse(kTypes, shown(w[1]));
        property.item = *type;
      } else if (w.size() == 5 && w[1] == "list") {
        const auto count = ply_type(w[2]);
        if (!count || count->kind == Kind::real) {
          refuse("an integer PLY type for a list's length", shown(w[2]));
        }
        const auto item = ply_type(w[3]);
        if (!item) refuse(kTypes, shown(w[3]));
        property.list = true;
        property.count = *count;
        property.item = *item;
      } else {
        refuse("'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME'", shown(line));
      }
      property.name = std::string(w.back());
      header.elements.back().properties.push_back(property);
    } else if (w[0] == "end_header" && w.size() == 1) {
      break;
    } else {
      refuse("a PLY header line (comment, obj_info, element, property or end_header)",
             shown(line));
    }
  }
  for (const PlyElement& element : header.elements) {
    if (element.count > 0 && element.properties.empty()) {
      throw InputError(path, "element '" + element.name + "'", "properties for its records",
                       "none");
    }
  }
  header.lines = lines.number();
  header.body = lines.position();
  // assimp's binary reader starts after the end_header line's first line-end byte and then drops
  // one '\n': after "\r\n" the same place, after "\n\n" one byte further.
  if (header.format != PlyFormat::ascii && !lines.ended_in_crlf() && header.body < text.size() &&
      text[header.body] == '\n') {
    ++header.body;
  }
  return header;
}

// Whether `word` is one whole value of `type` as assimp's ASCII reader reads it (strtoul10,
// strtol10, fast_atoreal_move): it stops at the first character it cannot take and reads the rest
// as the next value, and its 64-bit digit reader gives up, without moving, past 19 digits.
bool is_ply_value(std::string_view word, const PlyType& type) {
  std::size_t at = 0;
  const auto digits = [&](std::size_t most) {
    const std::size_t start = at;
    while (at < word.size() && is_digit(word[at])) ++at;
    return at > start && at - start <= most;
  };
  if (type.kind != Kind::unsigned_integer && at < word.size() && (word[at] == '+' || word[at] == '-')) {
    ++at;
  }
  if (type.kind != Kind::real) return digits(word.size()) && at == word.size();
  const std::string rest = lower(std::string(word.substr(at)));
  if (rest == "nan" || rest == "inf" || rest == "infinity") return true;
  constexpr std::size_t kMostDigits = 19;
  if (at < word.size() && is_digit(word[at])) {
    if (!digits(kMostDigits)) return false;
    if (at < word.size() && word[at] == '.') {
      ++at;
      if (at < word.size() && is_digit(word[at])) digits(word.size());
    }
  } else if (at + 1 < word.size() && word[at] == '.' && is_digit(word[at + 1])) {
    ++at;
    digits(word.size());
  } else {
    return false;
  }
  if (at < word.size() && (word[at] == 'e' || word[at] == 'E')) {
    ++at;
    if (at < word.size() && (word[at] == '+' || word[at] == '-')) ++at;
    if (!digits(kMostDigits)) return false;
  }
  return at == word.size();
}

// A list's length as assimp takes it: the digits modulo 2^32, negated for a minus sign, as an
// unsigned 32-bit number (PropertyInstance::ConvertTo<unsigned int>).
std::uint64_t ply_list_length(std::string_view word) {
  std::uint32_t value = 0;
  for (const char c : word) {
    if (is_digit(c)) value = value * 10U + static_cast<std::uint32_t>(c - '0');
  }
  return word.front() == '-' ? std::uint32_t{0} - value : value;
}

std::string type_name(const PlyType& type) {
  const char* kind = type.kind == Kind::real             ? "a real number"
                     : type.kind == Kind::signed_integer ? "an integer"
                                                         : "an unsigned integer";
  return std::string(kind);
}

// ASCII records: one line each (assimp's PLY reader takes one line per record and allocates a
// list's values from its length before reading them, 3·10⁹ corners: 24 GB).
void check_ply_ascii(const std::string& path, std::string_view text, const PlyHeader& header) {
  Lines lines(path, text, header.body, header.lines);
  for (const PlyElement& element : header.elements) {
    for (std::uint64_t record = 0; record < element.count; ++record) {
      if (lines.done()) {
        throw InputError(path, "element '" + element.name + "'",
                         std::to_string(element.count) + " record lines",
                         "the end of the file after " + std::to_string(record));
      }
      const std::string_view line = lines.next();
      const auto w = words(line);
      const std::string field = line_field(lines.number());
      const std::string what = "element '" + element.name + "' record " + std::to_string(record);
      if (!lines.terminated()) {
        throw InputError(path, field, "a record line ending in a line end (" + what + ")",
                         "the end of the file");
      }
      std::size_t at = 0;
      const auto value = [&](const PlyType& type, const std::string& name) {
        if (at >= w.size()) {
          throw InputError(path, field, "a value for property '" + name + "' (" + what + ")",
                           "the end of the line");
        }
        if (!is_ply_value(w[at], type)) {
          throw InputError(path, field,
                           type_name(type) + " for property '" + name + "' (" + what + ")",
                           shown(w[at]));
        }
        return w[at++];
      };
      for (const PlyProperty& property : element.properties) {
        if (!property.list) {
          value(property.item, property.name);
          continue;
        }
        const std::uint64_t length = ply_list_length(value(property.count, property.name));
        if (length > w.size() - at) {
          throw InputError(path, field,
                           "a list length for property '" + property.name + "' (" + what +
                               ") of at most the " + std::to_string(w.size() - at) +
                               " values that follow",
                           std::to_string(length));
        }
        for (std::uint64_t i = 0; i < length; ++i) value(property.item, property.name);
      }
      if (at != w.size()) {
        throw InputError(path, field, std::to_string(at) + " values (" + what + ")",
                         "more: " + shown(w[at]));
      }
    }
  }
  // assimp reads one line past the records: its line ends are checked too, and those after it.
  while (!lines.done()) lines.next();
}

// A binary value's bits as assimp reads a list length (ParseValueBinary, then ConvertTo<unsigned
// int>): signed types widened with their sign, the result taken modulo 2^32.
std::uint64_t binary_list_length(std::string_view bytes, const PlyType& type, bool big_endian) {
  std::uint64_t bits = 0;
  for (int i = 0; i < type.size; ++i) {
    const auto byte = static_cast<unsigned char>(bytes[big_endian ? i : type.size - 1 - i]);
    bits = (bits << 8) | byte;
  }
  if (type.kind == Kind::signed_integer && (bits >> (8 * type.size - 1)) != 0) {
    bits |= ~std::uint64_t{0} << (8 * type.size);  // sign-extended
  }
  return bits & 0xffffffffULL;
}

// Binary records: each within the file (assimp allocates an element's records, and a list's
// values, from the counts before reading them).
void check_ply_binary(const std::string& path, std::string_view text, const PlyHeader& header) {
  const bool big_endian = header.format == PlyFormat::binary_big_endian;
  std::uint64_t at = header.body;
  const std::uint64_t size = text.size();
  for (const PlyElement& element : header.elements) {
    std::uint64_t least = 0;  // a record's bytes with empty lists
    for (const PlyProperty& p : element.properties) {
      least += static_cast<std::uint64_t>(p.list ? p.count.size : p.item.size);
    }
    if (element.count > 0 && element.count > (size - at) / least) {
      throw InputError(path, "element '" + element.name + "'",
                       "at most " + std::to_string((size - at) / least) + " records of " +
                           std::to_string(least) + " or more bytes in the " +
                           std::to_string(size - at) + " bytes left",
                       std::to_string(element.count));
    }
    for (std::uint64_t record = 0; record < element.count; ++record) {
      const std::string field =
          "element '" + element.name + "' record " + std::to_string(record);
      for (const PlyProperty& p : element.properties) {
        const int head = p.list ? p.count.size : p.item.size;
        if (size - at < static_cast<std::uint64_t>(head)) {
          throw InputError(path, field, "property '" + p.name + "' within the file",
                           "the end of the file");
        }
        if (!p.list) {
          at += static_cast<std::uint64_t>(head);
          continue;
        }
        const std::uint64_t length =
            binary_list_length(text.substr(at, static_cast<std::size_t>(head)), p.count, big_endian);
        at += static_cast<std::uint64_t>(head);
        const std::uint64_t room = (size - at) / static_cast<std::uint64_t>(p.item.size);
        if (length > room) {
          throw InputError(path, field,
                           "a list length for property '" + p.name + "' of at most " +
                               std::to_string(room) + " (the values left in the file)",
                           std::to_string(length));
        }
        at += length * static_cast<std::uint64_t>(p.item.size);
      }
    }
  }
}

}  // namespace

std::string checked_extension(const std::string& path) {
  const std::string extension = lower(std::filesystem::path(path).extension().string());
  if (extension != ".stl" && extension != ".obj" && extension != ".ply") {
    throw InputError(path, "(file)", "a mesh file ending in .stl, .obj or .ply",
                     extension.empty() ? "no extension" : shown(extension));
  }
  return extension;
}

void check_ply(const std::string& path, std::string_view text) {
  const PlyHeader header = read_ply_header(path, text);
  if (header.format == PlyFormat::ascii) {
    check_ply_ascii(path, text, header);
  } else {
    check_ply_binary(path, text, header);
  }
}

void check_obj(const std::string& path, std::string_view text) {
  // assimp's OBJ reader counts a one-corner line ('l 1') as no vertex when it sizes the mesh's
  // vertex array and as one when it fills it; after two of them a longer line writes 12 bytes past
  // the array (ObjFileImporter::createVertexArray): heap corruption that aborts much later. Any
  // byte after a line end may start a statement (a line continued with '\' joins the next one);
  // each corner word that starts with a digit or a sign gives assimp at least one corner, or an
  // error.
  std::size_t number = 1;
  for (std::size_t start = 0; start < text.size();) {
    std::size_t end = start;
    while (end < text.size() && !is_line_end(text[end])) ++end;
    const std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line[0] == 'l') {
      const auto w = words(line);
      const bool corners = w.size() >= 3 && std::all_of(w.begin() + 1, w.end(), [](auto word) {
                             return is_digit(word[0]) || word[0] == '-' || word[0] == '+';
                           });
      if (!corners) {
        throw InputError(path, line_field(number),
                         "a line statement ('l') of at least two corner indices", shown(line));
      }
    }
    if (end < text.size() && text[end] == '\n') ++number;
    start = end + 1;
  }
}

}  // namespace hila::core::mesh_checks
