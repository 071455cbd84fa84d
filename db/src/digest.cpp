#include "digest.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "comfort_codec.hpp"
#include "hila/db/database.hpp"
#include "open_checks.hpp"
#include "schema.hpp"
#include "sha256.hpp"

namespace hila::db {

namespace detail {

namespace {

// Canonical serialization: fixed-width little-endian numbers, length-prefixed text and a type tag
// per value, so no two different tables produce the same byte stream. Buffered: a table is
// hundreds of thousands of values of a few bytes each, too small to hand to OpenSSL one by one.
class CanonicalStream {
 public:
  void tag(char t) { put(&t, 1); }
  void int64(std::int64_t value) {
    auto bits = static_cast<std::uint64_t>(value);
    unsigned char bytes[8];
    for (unsigned char& byte : bytes) {
      byte = static_cast<unsigned char>(bits & 0xff);
      bits >>= 8;
    }
    put(bytes, sizeof(bytes));
  }
  void real(double value) {
    std::uint64_t bits = 0;
    std::memcpy(&bits, &value, sizeof(bits));  // the exact bits: 1 ulp changes the digest
    int64(static_cast<std::int64_t>(bits));
  }
  void text(std::string_view value) {
    int64(static_cast<std::int64_t>(value.size()));
    put(value.data(), value.size());
  }
  void bytes(const std::vector<std::uint8_t>& value) {
    int64(static_cast<std::int64_t>(value.size()));
    put(value.data(), value.size());
  }
  std::string hex_digest() {
    flush();
    return hasher_.hex_digest();
  }

 private:
  static constexpr std::size_t kBufferBytes = 64 * 1024;

  void put(const void* data, std::size_t size) {
    if (buffer_.size() + size > kBufferBytes) flush();
    if (size >= kBufferBytes) {
      hasher_.update(data, size);
    } else {
      buffer_.append(static_cast<const char*>(data), size);
    }
  }
  void flush() {
    hasher_.update(buffer_);
    buffer_.clear();
  }

  Sha256 hasher_;
  std::string buffer_;
};

const char* storage_class_name(int storage_class) {
  switch (storage_class) {
    case SQLITE_INTEGER:
      return "INTEGER";
    case SQLITE_FLOAT:
      return "REAL";
    case SQLITE_TEXT:
      return "TEXT";
    case SQLITE_BLOB:
      return "BLOB";
    default:
      return "NULL";
  }
}

// What SQL's typeof() says of a value of that storage class.
const char* typeof_name(int storage_class) {
  switch (storage_class) {
    case SQLITE_INTEGER:
      return "integer";
    case SQLITE_FLOAT:
      return "real";
    case SQLITE_TEXT:
      return "text";
    case SQLITE_BLOB:
      return "blob";
    default:
      return "null";
  }
}

// "a REAL", "an INTEGER or NULL": what a column of the schema holds.
std::string describe_expected(const ColumnSpec& column) {
  const std::string name = storage_class_name(column.storage_class);
  return (column.storage_class == SQLITE_INTEGER ? "an " : "a ") + name +
         (column.nullable ? " or NULL" : "") + " (the column is " + name +
         (column.nullable ? "" : " NOT NULL") + ")";
}

// The value in the current row, for "got ...": its storage class and (shortened) value.
std::string describe_value(const Statement& select, int c) {
  switch (select.column_type(c)) {
    case SQLITE_INTEGER:
      return "the INTEGER " + std::to_string(select.column_int64(c));
    case SQLITE_FLOAT: {
      char buffer[32];
      std::snprintf(buffer, sizeof(buffer), "%.17g", select.column_double(c));
      return std::string("the REAL ") + buffer;
    }
    case SQLITE_TEXT: {
      constexpr std::size_t kShown = 40;
      const std::string_view text = select.column_text_view(c);
      return "the TEXT '" + std::string(text.substr(0, kShown)) +
             (text.size() > kShown ? "...'" : "'");
    }
    case SQLITE_BLOB: {
      const std::size_t size = select.column_blob_view(c).size();
      return "a BLOB of " + std::to_string(size) + (size == 1 ? " byte" : " bytes");
    }
    default:
      return "NULL";
  }
}

// The table's columns must be the schema's, in its order.
void check_columns(const Statement& select, const std::string& path, const std::string& table,
                   const std::vector<ColumnSpec>& spec, const std::string& fix) {
  const auto count = static_cast<std::size_t>(select.column_count());
  for (std::size_t c = 0; c < std::max(count, spec.size()); ++c) {
    const std::string got = c < count ? select.column_name(static_cast<int>(c)) : "";
    const std::string want = c < spec.size() ? spec[c].name : "";
    if (got == want) continue;
    throw DatabaseError(path, table,
                        "the " + std::to_string(spec.size()) + " columns of schema version " +
                            std::to_string(current_schema_version()),
                        std::to_string(count) + " columns (column " + std::to_string(c + 1) +
                            " is " + (got.empty() ? std::string("missing") : "'" + got + "'") +
                            ", expected " +
                            (want.empty() ? std::string("none") : "'" + want + "'") + ")",
                        fix);
  }
}

// How a table is laid out in its canonical bytes: which columns carry a comfort map's values.
struct TableLayout {
  int columns = 0;
  // Comfort map values are hashed uncompressed: the digest is about content, so it must not
  // depend on the zlib that compressed them.
  int value_bytes_column = -1;
  int deflated_column = -1;
};

// The table's header: its name and column names.
TableLayout stream_header(CanonicalStream& out, const std::string& table, const Statement& select) {
  TableLayout layout;
  layout.columns = select.column_count();
  out.tag('T');
  out.text(table);
  out.int64(layout.columns);
  for (int c = 0; c < layout.columns; ++c) {
    const std::string column = select.column_name(c);
    out.text(column);
    if (table == "comfort_maps" && column == "value_bytes") layout.value_bytes_column = c;
    if (table == "comfort_maps" && column == "values_deflate") layout.deflated_column = c;
  }
  return layout;
}

// One row: each value with its type tag. See TableDigest::hash_row for `inflated` and `strict`;
// `values` is scratch space for inflating.
void stream_row(CanonicalStream& out, const TableLayout& layout, const Statement& select,
                const std::string& path, const std::string& fix,
                const std::vector<std::uint8_t>* inflated, bool strict,
                std::vector<std::uint8_t>& values) {
  out.tag('R');
  for (int c = 0; c < layout.columns; ++c) {
    if (c == layout.deflated_column && layout.value_bytes_column >= 0 &&
        select.column_type(c) == SQLITE_BLOB) {
      if (!inflated) {
        const std::string problem = inflate_values(
            select.column_blob(c), select.column_int64(layout.value_bytes_column), values);
        if (!problem.empty() && strict) {
          throw DatabaseError(
              path,
              "comfort_maps.values_deflate (id " + std::to_string(select.column_int64(0)) + ")",
              "zlib-compressed values that inflate to value_bytes bytes", problem, fix);
        }
        if (!problem.empty()) {
          out.tag('x');
          out.text(select.column_blob_view(c));
          continue;
        }
        inflated = &values;
      }
      out.tag('z');
      out.bytes(*inflated);
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
        out.text(select.column_text_view(c));
        break;
      case SQLITE_BLOB:
        out.tag('b');
        out.text(select.column_blob_view(c));
        break;
      default:
        out.tag('n');
        break;
    }
  }
}

void stream_end(CanonicalStream& out, std::int64_t rows) {
  out.tag('E');
  out.int64(rows);
}

std::string short_digest(const std::string& hex) {
  return hex.size() > 12 ? hex.substr(0, 12) + "..." : hex;
}

}  // namespace

std::string digest_select(const std::string& table) {
  // meta has no id, so it is ordered by key.
  return table == "meta"
             ? std::string("SELECT * FROM meta WHERE ") + kDigestedMetaRows + " ORDER BY key"
             : "SELECT * FROM " + table + " ORDER BY id";
}

struct TableDigest::Impl {
  std::string path;
  std::string table;
  std::string fix;
  bool check_types = false;
  const std::vector<ColumnSpec>* spec = nullptr;
  CanonicalStream out;
  TableLayout layout;
  std::int64_t rows = 0;
  std::vector<std::uint8_t> values;
  bool begun = false;
};

TableDigest::TableDigest(std::string path, std::string table, std::string fix, bool check_types)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = std::move(path);
  impl_->table = std::move(table);
  impl_->fix = std::move(fix);
  impl_->check_types = check_types;
  impl_->spec = &schema_columns(impl_->table);
}

TableDigest::~TableDigest() = default;

void TableDigest::begin(Connection& connection, const Statement& select) {
  Impl& m = *impl_;
  if (m.check_types) {
    // The file's own columns, whatever the statement selects (prepared, never stepped).
    const Statement all(connection, "SELECT * FROM " + m.table,
                        {m.table, "a readable hila table", m.fix});
    check_columns(all, m.path, m.table, *m.spec, m.fix);
    for (int c = 0; c < select.column_count(); ++c) {
      if (select.column_count() != static_cast<int>(m.spec->size()) ||
          select.column_name(c) != (*m.spec)[c].name) {
        throw std::logic_error("TableDigest: the statement reading " + m.table +
                               " does not select its columns in the schema's order");
      }
    }
  }
  m.layout = stream_header(m.out, m.table, select);
  m.begun = true;
}

void TableDigest::check_row(const Statement& select) const {
  const Impl& m = *impl_;
  if (!m.check_types) return;
  const auto& spec = *m.spec;
  for (int c = 0; c < m.layout.columns; ++c) {
    const int type = select.column_type(c);
    if (type == spec[c].storage_class || (type == SQLITE_NULL && spec[c].nullable)) continue;
    const std::string row = m.table == "meta"
                                ? "key '" + std::string(select.column_text_view(0)) + "'"
                                : "id " + std::to_string(select.column_int64(0));
    throw DatabaseError(m.path, m.table + "." + spec[c].name + " (" + row + ")",
                        describe_expected(spec[c]), describe_value(select, c), m.fix);
  }
}

void TableDigest::hash_row(const Statement& select, const std::vector<std::uint8_t>* inflated,
                           bool strict) {
  Impl& m = *impl_;
  stream_row(m.out, m.layout, select, m.path, m.fix, inflated, strict, m.values);
  ++m.rows;
}

std::string TableDigest::finish() {
  Impl& m = *impl_;
  if (!m.begun) throw std::logic_error("TableDigest::finish before begin for " + m.table);
  stream_end(m.out, m.rows);
  return m.out.hex_digest();
}

std::string table_digest(Connection& connection, const std::string& path, const std::string& table,
                         const std::string& fix, bool check_types) {
  Statement select(connection, digest_select(table), {table, "a readable hila table", fix});
  TableDigest digest(path, table, fix, check_types);
  digest.begin(connection, select);
  while (select.step()) {
    digest.check_row(select);
    digest.hash_row(select);
  }
  return digest.finish();
}

void check_table_types(Connection& connection, const std::string& path, const std::string& table,
                       const std::string& fix) {
  // typeof() in SQL, so that SQLite reads no BLOB or TEXT content (a comfort map's values are
  // megabytes), only the record headers.
  const std::vector<ColumnSpec>& spec = schema_columns(table);
  const ErrorContext context{table, "a readable hila table", fix};
  {
    const Statement all(connection, "SELECT * FROM " + table, context);
    check_columns(all, path, table, spec, fix);
  }
  std::string sql = "SELECT rowid";
  for (const auto& column : spec) sql += ", typeof(" + column.name + ")";
  Statement types(connection, sql + " FROM " + table + " ORDER BY rowid", context);
  while (types.step()) {
    for (std::size_t c = 0; c < spec.size(); ++c) {
      const std::string_view type = types.column_text_view(static_cast<int>(c) + 1);
      if (type == typeof_name(spec[c].storage_class) || (type == "null" && spec[c].nullable)) {
        continue;
      }
      // The offending value itself, read once, for the message.
      Statement value(
          connection,
          "SELECT " + spec[c].name + ", " + spec[0].name + " FROM " + table + " WHERE rowid = ?",
          context);
      value.bind_next(types.column_int64(0));
      value.step();
      const std::string row = table == "meta" ? "key '" + value.column_text(1) + "'"
                                              : "id " + std::to_string(value.column_int64(1));
      throw DatabaseError(path, table + "." + spec[c].name + " (" + row + ")",
                          describe_expected(spec[c]), describe_value(value, 0), fix);
    }
  }
}

std::map<std::string, std::string> table_digests(Connection& connection, const std::string& path,
                                                 int version, const std::string& fix) {
  std::map<std::string, std::string> digests;
  for (const auto& table : kTables) {
    if (table.since_version > version) continue;
    digests[table.name] = table_digest(connection, path, table.name, fix, false);
  }
  return digests;
}

void write_table_digests(Connection& connection, const std::map<std::string, std::string>& digests,
                         const ErrorContext& context) {
  Statement insert(connection, "INSERT OR REPLACE INTO meta (key, value) VALUES (?, ?)", context);
  for (const auto& [table, digest] : digests) {
    insert.bind_next(digest_key(table));
    insert.bind_next(digest);
    insert.run();
  }
}

void check_table_digests(const std::string& path, const std::map<std::string, std::string>& meta,
                         const std::map<std::string, std::string>& computed,
                         const std::string& fix) {
  // In digest order, so the first table at fault is the one reported.
  for (const auto& table : kTables) {
    const auto digest = computed.find(table.name);
    if (digest == computed.end()) continue;
    const std::string key = digest_key(table.name);
    const auto stored = meta.find(key);
    if (stored == meta.end()) {
      throw DatabaseError(path, "meta." + key,
                          std::string("the content digest of table ") + table.name +
                              " (a database of schema version " +
                              std::to_string(kTableDigestsSince) +
                              " or later holds one per table, written with it)",
                          "no such key", fix);
    }
    if (stored->second != digest->second) {
      throw DatabaseError(
          path, table.name,
          "the content digest stored when it was written (meta." + key + " = " +
              short_digest(stored->second) + ")",
          short_digest(digest->second) + ": its rows changed since (a damaged or edited file)",
          fix);
    }
  }
}

}  // namespace detail

std::string content_digest(const std::string& path) {
  const auto connection = detail::open_hila_database(path);
  const auto meta = detail::read_meta_table(*connection);
  const int version = detail::stored_schema_version(path, meta);
  const std::string fix = detail::rebuild_hint(path, meta);
  detail::CanonicalStream out;
  out.text("hila content digest 1");
  std::vector<std::uint8_t> values;
  for (const auto& table : detail::kTables) {
    // The tables of the file's schema version: an older file has no newer tables.
    if (table.since_version > version) continue;
    detail::Statement select(*connection, detail::digest_select(table.name),
                             {table.name, "a readable hila table", fix});
    const detail::TableLayout layout = detail::stream_header(out, table.name, select);
    std::int64_t rows = 0;
    while (select.step()) {
      detail::stream_row(out, layout, select, path, fix, nullptr, true, values);
      ++rows;
    }
    detail::stream_end(out, rows);
  }
  return out.hex_digest();
}

}  // namespace hila::db
