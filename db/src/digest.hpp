#pragma once

// Content hashing shared by content_digest, the per-table digests the writer and a migration store
// in meta, and Database::open, which recomputes them while it loads and compares. Private to
// hila::db.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "sqlite_handle.hpp"

namespace hila::db::detail {

// The meta rows every digest covers: all but created_at (it differs between otherwise identical
// builds) and the stored digests themselves (a digest cannot cover itself).
inline constexpr const char* kDigestedMetaRows = "key <> 'created_at' AND key NOT GLOB 'digest.*'";

// One table's content digest: SHA-256 of the bytes content_digest hashes for the table (its name,
// its column names, then each row, each value with a type tag, comfort map values inflated), fed
// row by row from a statement that selects all the table's columns in the schema's order (in id
// order; meta in key order and only kDigestedMetaRows). With `check_types` it also checks the
// table's columns and each value's storage class (SQLite's typeof) against the current schema
// (schema_columns): a DatabaseError naming the table, the column and the row's id (meta: its key)
// for a REAL column holding TEXT, a NOT NULL column holding NULL, and the like.
class TableDigest {
 public:
  TableDigest(std::string path, std::string table, std::string fix, bool check_types);
  ~TableDigest();
  TableDigest(const TableDigest&) = delete;
  TableDigest& operator=(const TableDigest&) = delete;

  // Once, before the first row: the table's columns (read from `connection`) must be the schema's
  // (with check_types), and `select` must select them all in that order (else std::logic_error).
  void begin(Connection& connection, const Statement& select);
  // After each step(), before the row's values are read: their storage classes.
  void check_row(const Statement& select) const;
  // After check_row, in the same row: hashes it. The reader passes a comfort map's values as it
  // inflated them (`inflated`); without them they are inflated here. Values that do not inflate
  // are a DatabaseError when `strict`; otherwise their stored bytes are hashed under a tag of their
  // own (a digest no writer stores), so that the reader can say what is wrong with them.
  void hash_row(const Statement& select, const std::vector<std::uint8_t>* inflated = nullptr,
                bool strict = false);
  // After the last row: the digest, lower-case hex.
  std::string finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// SHA-256 hex of one table, read on its own (TableDigest over the whole table).
std::string table_digest(Connection& connection, const std::string& path, const std::string& table,
                         const std::string& fix, bool check_types);

// Checks the storage classes of one table's values without hashing (nor inflating) them: for the
// comfort maps when they are not loaded.
void check_table_types(Connection& connection, const std::string& path, const std::string& table,
                       const std::string& fix);

// table_digest of each table of schema `version` (those the version has), keyed by table name: what
// the writer stores at commit and a migration after its last step.
std::map<std::string, std::string> table_digests(Connection& connection, const std::string& path,
                                                 int version, const std::string& fix);

// Stores `digests` as meta rows digest_key(table) -> hex (replacing any). `context` describes the
// write for error messages.
void write_table_digests(Connection& connection, const std::map<std::string, std::string>& digests,
                         const ErrorContext& context);

// Throws DatabaseError unless `meta` holds, for every table of `computed`, its digest_key with
// that value: a missing key is "meta.digest.TABLE: ..., got no such key", another value "TABLE:
// expected the content digest stored when it was written (...), got ...".
void check_table_digests(const std::string& path, const std::map<std::string, std::string>& meta,
                         const std::map<std::string, std::string>& computed,
                         const std::string& fix);

// The statement content_digest and TableDigest read a table with: every column, rows in digest
// order.
std::string digest_select(const std::string& table);

}  // namespace hila::db::detail
