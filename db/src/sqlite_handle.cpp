#include "sqlite_handle.hpp"

#include <utility>

#include "hila/db/database.hpp"

namespace hila::db::detail {

namespace {
std::string sqlite_message(sqlite3* db) {
  std::string message = db ? sqlite3_errmsg(db) : "out of memory";
  // NaN binds as NULL, so a NaN field shows up as a NOT NULL violation: say so.
  if (db && sqlite3_extended_errcode(db) == SQLITE_CONSTRAINT_NOTNULL) {
    message += " (a NaN value? SQLite stores NaN as NULL)";
  }
  return "SQLite error: " + message;
}
}  // namespace

Connection::Connection(const std::string& path, int flags, std::string display_path)
    : display_path_(std::move(display_path)) {
  const int rc = sqlite3_open_v2(path.c_str(), &db_, flags, nullptr);
  if (rc != SQLITE_OK) {
    const std::string got = sqlite_message(db_);
    sqlite3_close(db_);  // a handle is returned even on failure (unless out of memory)
    db_ = nullptr;
    throw DatabaseError(display_path_, "(file)", "a database SQLite can open", got);
  }
  sqlite3_extended_result_codes(db_, 1);
}

Connection::~Connection() {
  // sqlite3_close_v2 defers the close if a statement is still alive instead of leaking.
  if (db_) sqlite3_close_v2(db_);
}

void Connection::exec(const std::string& sql, const ErrorContext& context) {
  if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK) fail(context);
}

void Connection::close() {
  if (!db_) return;
  if (sqlite3_close(db_) != SQLITE_OK) {
    fail({"(file)", "a database that closes cleanly", ""});
  }
  db_ = nullptr;
}

void Connection::fail(const ErrorContext& context) const {
  throw DatabaseError(display_path_, context.field, context.expected, sqlite_message(db_),
                      context.fix);
}

Statement::Statement(Connection& connection, const std::string& sql, ErrorContext context)
    : connection_(&connection), context_(std::move(context)) {
  if (sqlite3_prepare_v2(connection.get(), sql.c_str(), static_cast<int>(sql.size()), &stmt_,
                         nullptr) != SQLITE_OK) {
    fail();
  }
}

Statement::~Statement() {
  sqlite3_finalize(stmt_);
}

void Statement::fail() const {
  connection_->fail(context_);
}

void Statement::bind_next(double value) {
  if (sqlite3_bind_double(stmt_, bind_index_++, value) != SQLITE_OK) fail();
}

void Statement::bind_next(std::int64_t value) {
  if (sqlite3_bind_int64(stmt_, bind_index_++, value) != SQLITE_OK) fail();
}

void Statement::bind_next(const std::string& value) {
  if (sqlite3_bind_text(stmt_, bind_index_++, value.data(), static_cast<int>(value.size()),
                        SQLITE_TRANSIENT) != SQLITE_OK) {
    fail();
  }
}

void Statement::bind_blob(const std::string& bytes) {
  // data() is never null, so an empty string binds an empty blob (a null pointer would be NULL).
  if (sqlite3_bind_blob64(stmt_, bind_index_++, bytes.data(), bytes.size(), SQLITE_TRANSIENT) !=
      SQLITE_OK) {
    fail();
  }
}

void Statement::bind_null() {
  if (sqlite3_bind_null(stmt_, bind_index_++) != SQLITE_OK) fail();
}

bool Statement::step() {
  read_column_ = 0;
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  fail();
}

void Statement::run() {
  // A statement that unexpectedly returns rows is a programming error, not worth a code path.
  while (step()) {
  }
  reset();
}

void Statement::reset() {
  // sqlite3_reset repeats the last step's error code, which step() has already reported.
  sqlite3_reset(stmt_);
  if (sqlite3_clear_bindings(stmt_) != SQLITE_OK) fail();
  bind_index_ = 1;
  read_column_ = 0;
}

int Statement::column_count() const {
  return sqlite3_column_count(stmt_);
}

int Statement::column_type(int column) const {
  return sqlite3_column_type(stmt_, column);
}

std::string Statement::column_name(int column) const {
  const char* name = sqlite3_column_name(stmt_, column);
  return name ? name : "";
}

double Statement::column_double(int column) const {
  return sqlite3_column_double(stmt_, column);
}

std::int64_t Statement::column_int64(int column) const {
  return sqlite3_column_int64(stmt_, column);
}

std::string Statement::column_text(int column) const {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
  const int size = sqlite3_column_bytes(stmt_, column);  // after _text, as SQLite requires
  return text ? std::string(text, static_cast<std::size_t>(size)) : std::string();
}

std::string Statement::column_blob(int column) const {
  const auto* blob = static_cast<const char*>(sqlite3_column_blob(stmt_, column));
  const int size = sqlite3_column_bytes(stmt_, column);
  return blob ? std::string(blob, static_cast<std::size_t>(size)) : std::string();
}

std::string_view Statement::column_text_view(int column) const {
  const auto* text = reinterpret_cast<const char*>(sqlite3_column_text(stmt_, column));
  const int size = sqlite3_column_bytes(stmt_, column);
  return text ? std::string_view(text, static_cast<std::size_t>(size)) : std::string_view();
}

std::string_view Statement::column_blob_view(int column) const {
  const auto* blob = static_cast<const char*>(sqlite3_column_blob(stmt_, column));
  const int size = sqlite3_column_bytes(stmt_, column);
  return blob ? std::string_view(blob, static_cast<std::size_t>(size)) : std::string_view();
}

}  // namespace hila::db::detail
