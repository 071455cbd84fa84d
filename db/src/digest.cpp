#include <cstdint>
#include <cstring>

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
  std::string hex_digest() { return hasher_.hex_digest(); }

 private:
  detail::Sha256 hasher_;
};

}  // namespace

std::string content_digest(const std::string& path) {
  const auto connection = detail::open_hila_database(path);
  CanonicalStream out;
  out.text("hila content digest 1");
  for (const char* table : detail::kTables) {
    const std::string name = table;
    // created_at differs between otherwise identical builds; meta has no id, so order by key.
    const std::string sql = name == "meta"
                                ? "SELECT * FROM meta WHERE key <> 'created_at' ORDER BY key"
                                : "SELECT * FROM " + name + " ORDER BY id";
    detail::Statement select(*connection, sql,
                             {name, "a readable hila table", detail::rebuild_hint(path)});
    out.tag('T');
    out.text(name);
    out.int64(select.column_count());
    for (int c = 0; c < select.column_count(); ++c) out.text(select.column_name(c));
    std::int64_t rows = 0;
    while (select.step()) {
      out.tag('R');
      for (int c = 0; c < select.column_count(); ++c) {
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
