#pragma once

// Thin RAII wrappers over the SQLite C API. Private to hila::db: no public header includes this.

#include <sqlite3.h>

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

namespace hila::db::detail {

// What a failure means to the user: "FILE: field: expected <expected>, got SQLite error: ...; fix".
struct ErrorContext {
  std::string field;
  std::string expected;
  std::string fix;
};

// An open connection. Every failure becomes a DatabaseError naming `display_path` (the file the
// user knows, e.g. the target rather than the writer's temporary file).
class Connection {
 public:
  Connection(const std::string& path, int flags, std::string display_path);
  ~Connection();
  Connection(const Connection&) = delete;
  Connection& operator=(const Connection&) = delete;

  sqlite3* get() const { return db_; }
  const std::string& display_path() const { return display_path_; }

  // Runs one or more statements without results.
  void exec(const std::string& sql, const ErrorContext& context);
  // Closes now (checking the result) instead of in the destructor. Statements must be finalized.
  void close();

  // Throws DatabaseError(display_path, field, expected, "SQLite error: <errmsg>", fix).
  [[noreturn]] void fail(const ErrorContext& context) const;

 private:
  sqlite3* db_ = nullptr;
  std::string display_path_;
};

// A prepared statement; bind with bind_next() in column order, read with next_*() in column order.
class Statement {
 public:
  Statement(Connection& connection, const std::string& sql, ErrorContext context);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  void bind_next(double value);
  void bind_next(std::int64_t value);
  void bind_next(const std::string& value);
  void bind_blob(const std::string& bytes);  // a BLOB (bind_next binds a string as TEXT)
  void bind_null();

  // Steps once: true if a row is available. Throws DatabaseError on failure.
  bool step();
  // Runs a statement that returns no rows, then resets it for the next binding.
  void run();
  void reset();

  int column_count() const;
  int column_type(int column) const;
  std::string column_name(int column) const;
  double column_double(int column) const;
  std::int64_t column_int64(int column) const;
  std::string column_text(int column) const;
  std::string column_blob(int column) const;
  // The same bytes without a copy, valid until the next step() or reset() (for hashing).
  std::string_view column_text_view(int column) const;
  std::string_view column_blob_view(int column) const;

  // Sequential reads for the current row, starting at column 0 after each step().
  double next_double() { return column_double(read_column_++); }
  std::int64_t next_int64() { return column_int64(read_column_++); }
  std::string next_text() { return column_text(read_column_++); }
  std::string next_blob() { return column_blob(read_column_++); }

  // Changes the error context, e.g. to name the part being written.
  void set_context(ErrorContext context) { context_ = std::move(context); }

 private:
  [[noreturn]] void fail() const;

  Connection* connection_;
  sqlite3_stmt* stmt_ = nullptr;
  ErrorContext context_;
  int bind_index_ = 1;
  int read_column_ = 0;
};

}  // namespace hila::db::detail
