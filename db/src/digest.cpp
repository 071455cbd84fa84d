#include <cstdint>
#include <cstring>
#include <vector>

#include "comfort_codec.hpp"
#include "hila/db/database.hpp"
#include "open_checks.hpp"
#include "schema.hpp"
#include "sha256.hpp"
#include "sqlite_handle.hpp"

namespace hila::db {

namespace {

// Canonical serialization: fixed-width little-endian numbers, length-prefixed text and a type tag
// per value, so no two different tables produce the same byte stream.
class CanonicalStream {
 public:
  void tag(char t) { hasher_.update(&t, 1); }
  void int64(std::int64_t value) {
    auto bits = static_cast<std::uint64_t>(value);
    unsigned char bytes[8];
    for (unsigned char& byte : bytes) {
      byte = static_cast<unsigned char>(bits & 0xff);
      bits >>= 8;
    }
    hasher_.update(bytes, sizeof(bytes));
  }
  void real(double value) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));  // the exact bits: 1 ulp changes the digest
    int64(static_cast<std::int64_t>(bits));
  }
  void text(const std::string& value) {
    int64(static_cast<std::int64_t>(value.size()));
    hasher_.update(value);
  }
  void bytes(const std::vector<std::uint8_t>& value) {
    int64(static_cast<std::int64_t>(value.size()));
    hasher_.update(value.data(), value.size());
  }
  std::string hex_digest() { return hasher_.hex_digest(); }

 private:
  detail::Sha256 hasher_;
};

}  // namespace

std::string content_digest(const std::string& path) {
  const auto connection = detail::open_hila_database(path);
  const auto meta = detail::read_meta_table(*connection);
  const int version = detail::stored_schema_version(path, meta);
  const std::string fix = detail::rebuild_hint(path, meta);
  CanonicalStream out;
  out.text("hila content digest 1");
  for (const auto& table : detail::kTables) {
    // The tables of the file's schema version: an older file has no newer tables.
    if (table.since_version > version) continue;
    const std::string name = table.name;
    // created_at differs between otherwise identical builds; meta has no id, so order by key.
    const std::string sql = name == "meta"
                                ? "SELECT * FROM meta WHERE key <> 'created_at' ORDER BY key"
                                : "SELECT * FROM " + name + " ORDER BY id";
    detail::Statement select(*connection, sql, {name, "a readable hila table", fix});
    out.tag('T');
    out.text(name);
    out.int64(select.column_count());
    // Comfort map values are hashed uncompressed: the digest is about content, so it must not
    // depend on the zlib that compressed them.
    int value_bytes_column = -1;
    int deflated_column = -1;
    for (int c = 0; c < select.column_count(); ++c) {
      const std::string column = select.column_name(c);
      out.text(column);
      if (name == "comfort_maps" && column == "value_bytes") value_bytes_column = c;
      if (name == "comfort_maps" && column == "values_deflate") deflated_column = c;
    }
    std::int64_t rows = 0;
    std::vector<std::uint8_t> values;
    while (select.step()) {
      out.tag('R');
      for (int c = 0; c < select.column_count(); ++c) {
        if (c == deflated_column && value_bytes_column >= 0 &&
            select.column_type(c) == SQLITE_BLOB) {
          const std::string problem = detail::inflate_values(
              select.column_blob(c), select.column_int64(value_bytes_column), values);
          if (!problem.empty()) {
            throw DatabaseError(
                path,
                "comfort_maps.values_deflate (id " + std::to_string(select.column_int64(0)) + ")",
                "zlib-compressed values that inflate to value_bytes bytes", problem, fix);
          }
          out.tag('z');
          out.bytes(values);
          continue;
        }
        switch (select.column_type(c)) {
          case SQLITE_INTEGER:
            out.tag('i');
            out.int64(select.column_int64(c));
            break;
          case SQLITE_FLOAT:
            out.tag('f');
            out.real(select.column_double(c));
            break;
          case SQLITE_TEXT:
            out.tag('t');
            out.text(select.column_text(c));
            break;
          case SQLITE_BLOB:
            out.tag('b');
            out.text(select.column_blob(c));
            break;
          default:
            out.tag('n');
            break;
        }
      }
      ++rows;
    }
    out.tag('E');
    out.int64(rows);
  }
  return out.hex_digest();
}

}  // namespace hila::db
