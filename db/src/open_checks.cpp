#include "open_checks.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <vector>

#include "hila/db/database.hpp"

namespace hila::db::detail {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kHeaderSize = 100;      // the SQLite database header
constexpr char kMagic[] = "SQLite format 3";  // plus its terminating '\0': 16 bytes

std::uint32_t big_endian(const unsigned char* bytes, int count) {
  std::uint32_t value = 0;
  for (int i = 0; i < count; ++i) value = (value << 8) | bytes[i];
  return value;
}

// What a non-SQLite file looks like, for "expected a hila database (SQLite), got ...".
std::string describe_foreign(const std::string& head, std::uintmax_t size) {
  const std::string shown = head.substr(0, 24);
  bool text = true;
  for (unsigned char c : shown) {
    if (!(std::isprint(c) || c == '\n' || c == '\r' || c == '\t' || c >= 0x80)) text = false;
  }
  if (text) {
    std::string printable;
    for (char c : shown) printable += (c == '\n' || c == '\r' || c == '\t') ? ' ' : c;
    printable.erase(printable.find_last_not_of(' ') + 1);
    return "a text file starting with \"" + printable + "\"";
  }
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  for (std::size_t i = 0; i < std::min<std::size_t>(shown.size(), 8); ++i) {
    const auto byte = static_cast<unsigned char>(shown[i]);
    if (i) hex += ' ';
    hex += kHex[byte >> 4];
    hex += kHex[byte & 0x0f];
  }
  return "a " + std::to_string(size) + "-byte file that is not SQLite (it starts with " + hex + ")";
}

// The numbers of a dotted version ("0.10.0" -> 0, 10, 0); empty unless it is only that.
std::vector<long> version_numbers(const std::string& version) {
  std::vector<long> numbers;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = version.find('.', start);
    const std::size_t end = dot == std::string::npos ? version.size() : dot;
    long number = 0;
    const auto [next, error] =
        std::from_chars(version.data() + start, version.data() + end, number);
    if (end == start || error != std::errc() || next != version.data() + end) return {};
    numbers.push_back(number);
    if (dot == std::string::npos) return numbers;
    start = dot + 1;
  }
}

// "SELECT column FROM table WHERE rowid = ?" as text ("?" when it cannot be read).
std::string referencing_value(Connection& connection, const std::string& table,
                              const std::string& column, std::int64_t rowid) {
  try {
    Statement select(connection,
                     "SELECT quote(\"" + column + "\") FROM \"" + table + "\" WHERE rowid = ?",
                     {table, "a readable row", ""});
    select.bind_next(rowid);
    return select.step() ? select.column_text(0) : "?";
  } catch (const DatabaseError&) {
    return "?";
  }
}

}  // namespace

std::string rebuild_hint(const std::string& path, const std::map<std::string, std::string>& meta) {
  const auto value = [&](const char* key) {
    const auto it = meta.find(key);
    return it == meta.end() ? std::string() : it->second;
  };
  // No --cell: meta holds file names without folders, so a cell path built from it could mislead.
  const std::string product = value("product_file");
  return "rebuild with: hila build " + (product.empty() ? "PRODUCT.yaml" : product) + " -o " + path;
}

void check_sqlite_file(const std::string& path) {
  const std::string expected = "a hila database (SQLite)";
  std::error_code ec;
  const auto status = fs::status(path, ec);
  if (!fs::exists(status)) {
    throw DatabaseError(path, "(file)", "an existing hila database", "no such file",
                        "check the path, or build it with: hila build PRODUCT.yaml -o " + path);
  }
  if (fs::is_directory(status)) {
    throw DatabaseError(path, "(file)", expected, "a directory", "check the path");
  }
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) {
    throw DatabaseError(path, "(file)", expected, "a file whose size cannot be read",
                        "check the path");
  }
  if (size == 0) throw DatabaseError(path, "(file)", expected, "an empty file", rebuild_hint(path));

  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw DatabaseError(path, "(file)", expected, "a file that cannot be opened",
                        "check its permissions");
  }
  std::string head(kHeaderSize, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));

  if (head.size() < sizeof(kMagic) ||
      head.compare(0, sizeof(kMagic), kMagic, sizeof(kMagic)) != 0) {
    // A prefix of the magic is a cut-off SQLite file rather than a foreign one.
    if (head.size() < sizeof(kMagic) && std::string(kMagic, sizeof(kMagic)).starts_with(head)) {
      throw DatabaseError(path, "(file)", expected,
                          "a truncated SQLite file (" + std::to_string(size) + " bytes)",
                          rebuild_hint(path));
    }
    throw DatabaseError(path, "(file)", expected, describe_foreign(head, size),
                        "check the path, or rebuild with: hila build PRODUCT.yaml -o " + path);
  }
  if (head.size() < kHeaderSize) {
    throw DatabaseError(path, "(file)", expected,
                        "a truncated SQLite file (" + std::to_string(size) +
                            " bytes, shorter than the 100-byte header)",
                        rebuild_hint(path));
  }
  const auto* bytes = reinterpret_cast<const unsigned char*>(head.data());
  std::uint64_t page_size = big_endian(bytes + 16, 2);
  if (page_size == 1) page_size = 65536;  // how the header spells 64 KiB
  // The in-header page count is only valid when "version-valid-for" equals the change counter.
  const bool count_valid = big_endian(bytes + 92, 4) == big_endian(bytes + 24, 4);
  const std::uint64_t page_count = big_endian(bytes + 28, 4);
  const std::uint64_t expected_size = page_size * page_count;
  if (page_size >= 512 && ((count_valid && size < expected_size) || size % page_size != 0)) {
    throw DatabaseError(path, "(file)", expected,
                        "a truncated SQLite file (" + std::to_string(size) +
                            " bytes, its header says " + std::to_string(page_count) + " pages of " +
                            std::to_string(page_size) + " bytes)",
                        rebuild_hint(path));
  }
}

std::unique_ptr<Connection> open_hila_database(const std::string& path) {
  check_sqlite_file(path);
  // READONLY: never creates the file, never writes to it, so opening cannot damage a database.
  // NOMUTEX: a connection is used by one thread only, so SQLite need not lock around every call.
  auto connection =
      std::make_unique<Connection>(path, SQLITE_OPEN_READONLY | SQLITE_OPEN_NOMUTEX, path);
  const ErrorContext integrity{"(integrity)", "an intact hila database (SQLite)",
                               rebuild_hint(path)};
  {
    Statement check(*connection, "PRAGMA quick_check", integrity);
    std::vector<std::string> problems;
    while (check.step()) {
      const std::string line = check.column_text(0);
      if (line != "ok" && problems.size() < 3) problems.push_back(line);
    }
    if (!problems.empty()) {
      std::string got = "a corrupt database (PRAGMA quick_check: ";
      for (std::size_t i = 0; i < problems.size(); ++i) got += (i ? "; " : "") + problems[i];
      throw DatabaseError(path, integrity.field, integrity.expected, got + ")", integrity.fix);
    }
  }
  {
    Statement tables(*connection,
                     "SELECT name FROM sqlite_master WHERE type = 'table' ORDER BY name",
                     integrity);
    std::string names;
    bool has_meta = false;
    while (tables.step()) {
      const std::string name = tables.column_text(0);
      has_meta = has_meta || name == "meta";
      names += (names.empty() ? "" : ", ") + name;
    }
    if (!has_meta) {
      throw DatabaseError(path, "meta", "a hila database (SQLite with hila's meta table)",
                          "an SQLite database without it (tables: " +
                              (names.empty() ? std::string("none") : names) +
                              "), not written by hila",
                          "check the path, or rebuild with: hila build PRODUCT.yaml -o " + path);
    }
  }
  return connection;
}

std::map<std::string, std::string> read_meta_table(Connection& connection) {
  Statement select(connection, "SELECT key, value FROM meta",
                   {"meta", "a readable meta table", rebuild_hint(connection.display_path())});
  std::map<std::string, std::string> meta;
  while (select.step()) meta[select.column_text(0)] = select.column_text(1);
  return meta;
}

int stored_schema_version(const std::string& path, const std::map<std::string, std::string>& meta) {
  const auto it = meta.find("schema_version");
  if (it == meta.end()) {
    throw DatabaseError(path, "meta.schema_version", "the schema version", "no such key",
                        rebuild_hint(path));
  }
  const std::string& text = it->second;
  int version = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), version);
  if (error != std::errc() || end != text.data() + text.size() || text.empty()) {
    throw DatabaseError(path, "meta.schema_version", "an integer", "'" + text + "'",
                        rebuild_hint(path));
  }
  return version;
}

void check_schema_version(const std::string& path, int stored, int expected, bool can_migrate,
                          const std::string& rebuild) {
  if (stored == expected) return;
  const std::string wanted =
      "a database this hila reads (schema version " + std::to_string(expected) + ")";
  const std::string written = "one written by schema version " + std::to_string(stored);
  if (stored < expected) {
    throw DatabaseError(
        path, "meta.schema_version", wanted, written + " (an older hila)",
        rebuild + (can_migrate ? " (or migrate it in place with hila::db::migrate_in_place)" : ""));
  }
  throw DatabaseError(path, "meta.schema_version", wanted, written + " (a newer hila)",
                      "upgrade hila, or " + rebuild);
}

void check_hila_version(const std::string& path, const std::string& stored,
                        const std::string& expected, const std::string& rebuild) {
  if (stored == expected) return;
  const std::vector<long> have = version_numbers(stored);
  const std::vector<long> want = version_numbers(expected);
  const bool ordered = !have.empty() && !want.empty();
  const bool newer = ordered && have > want;
  std::string got = "one built by hila " + (stored.empty() ? std::string("''") : stored);
  if (ordered) {
    got += newer ? " (a newer hila)"
                 : " (an older hila, whose build differs: hila build --if-outdated rebuilds it)";
  }
  throw DatabaseError(path, "meta.hila_version", "a database built by this hila (" + expected + ")",
                      got, newer ? "upgrade hila, or " + rebuild : rebuild);
}

void check_references(Connection& connection, const std::string& path, const std::string& fix) {
  const ErrorContext context{"(foreign keys)", "references that can be checked", fix};
  {
    // One row per reference that names no row: table, rowid, parent table, foreign key number.
    Statement check(connection, "PRAGMA foreign_key_check", context);
    if (check.step()) {
      const std::string table = check.column_text(0);
      const std::int64_t rowid = check.column_int64(1);
      const std::string parent = check.column_text(2);
      const std::int64_t key = check.column_int64(3);
      std::int64_t count = 1;
      while (check.step()) ++count;
      std::string column = "?";
      {
        Statement list(connection, "SELECT \"from\" FROM pragma_foreign_key_list(?) WHERE id = ?",
                       context);
        list.bind_next(table);
        list.bind_next(key);
        if (list.step()) column = list.column_text(0);
      }
      throw DatabaseError(path, table + "." + column + " (id " + std::to_string(rowid) + ")",
                          "the id of a " + parent + " row",
                          referencing_value(connection, table, column, rowid) +
                              ", which names none (" +
                              (count == 1 ? std::string("the only reference")
                                          : "one of " + std::to_string(count) + " references") +
                              " PRAGMA foreign_key_check finds broken)",
                          fix);
    }
  }
  // grasp_id names a robot_grasps row for 'gripper', a suction_grasps row for 'suction'.
  for (const char* table : {"roadmap_filters", "regrasp_nodes"}) {
    const std::string t = table;
    Statement check(connection,
                    "SELECT id, grasp_kind, grasp_id FROM " + t +
                        " AS r WHERE (grasp_kind = 'gripper' AND NOT EXISTS (SELECT 1 FROM "
                        "robot_grasps AS g WHERE g.id = r.grasp_id)) OR (grasp_kind = 'suction' "
                        "AND NOT EXISTS (SELECT 1 FROM suction_grasps AS g WHERE g.id = "
                        "r.grasp_id)) ORDER BY id LIMIT 1",
                    {t, "a readable hila table", fix});
    if (check.step()) {
      const std::string kind = check.column_text(1);
      throw DatabaseError(path, t + ".grasp_id (id " + std::to_string(check.column_int64(0)) + ")",
                          std::string("the id of a ") +
                              (kind == "gripper" ? "robot_grasps" : "suction_grasps") +
                              " row (grasp_kind '" + kind + "')",
                          std::to_string(check.column_int64(2)) + ", which names none", fix);
    }
  }
}

}  // namespace hila::db::detail
