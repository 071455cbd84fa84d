#pragma once

// Checks shared by everything that opens an existing database (reader, digest, migration).

#include <map>
#include <memory>
#include <string>

#include "sqlite_handle.hpp"

namespace hila::db::detail {

// "rebuild with: hila build PRODUCT.yaml -o <path>", naming the stored product file when the meta
// table is known.
std::string rebuild_hint(const std::string& path,
                         const std::map<std::string, std::string>& meta = {});

// The file exists, is a regular file, starts with "SQLite format 3\0" and is as long as its header
// says (catches empty, foreign and truncated files before SQLite sees them). Throws DatabaseError.
void check_sqlite_file(const std::string& path);

// check_sqlite_file, then opens read-only (never creates), runs PRAGMA quick_check and requires
// hila's meta table. Throws DatabaseError naming `path`.
std::unique_ptr<Connection> open_hila_database(const std::string& path);

// The meta table as key -> value.
std::map<std::string, std::string> read_meta_table(Connection& connection);

// meta.schema_version as an integer. Throws DatabaseError if missing or not an integer.
int stored_schema_version(const std::string& path, const std::map<std::string, std::string>& meta);

// Throws DatabaseError unless `stored` equals `expected`: older says "written by schema version
// N" and how to rebuild (and that it can be migrated when `can_migrate`), newer says to upgrade.
void check_schema_version(const std::string& path, int stored, int expected, bool can_migrate,
                          const std::string& rebuild);

// Throws DatabaseError unless meta.hila_version `stored` equals `expected` (the test `hila build
// --if-outdated` makes): the message says which hila built the file, older or newer when both are
// dotted numbers, and how to rebuild (or to upgrade hila, for a newer one).
void check_hila_version(const std::string& path, const std::string& stored,
                        const std::string& expected, const std::string& rebuild);

// Throws DatabaseError naming the table, column, row id and the missing id when a reference names
// no row: a foreign key (PRAGMA foreign_key_check, which must return no row) or a grasp_id of
// roadmap_filters or regrasp_nodes, whose table depends on grasp_kind so SQLite cannot check it.
void check_references(Connection& connection, const std::string& path, const std::string& fix);

}  // namespace hila::db::detail
