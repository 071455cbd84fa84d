#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "hila/db/database.hpp"
#include "sqlite_handle.hpp"
#include "util/test_util.hpp"

using namespace hila::db;
using namespace hila::db::detail;
using namespace hila::test;

namespace {
const ErrorContext kContext{"test_field", "a test statement", "do the fix"};
}

TEST(SqliteHandle, ReadOnlyOpenOfMissingFileFailsAndCreatesNothing) {
  const std::string path = temp_dir("db_handle_missing") + "/none.db";
  expect_input_error([&] { Connection c(path, SQLITE_OPEN_READONLY, "shown.db"); },
                     {"shown.db: (file)", "SQLite error"});
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(SqliteHandle, BindAndReadBackEveryType) {
  Connection c(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "mem");
  c.exec("CREATE TABLE t (r REAL, i INTEGER, s TEXT)", kContext);
  Statement insert(c, "INSERT INTO t VALUES (?, ?, ?)", kContext);
  const std::string text_with_nul("a\0b\xc3\xa4", 5);
  insert.bind_next(-1.5e-300);
  insert.bind_next(std::numeric_limits<std::int64_t>::min());
  insert.bind_next(text_with_nul);
  insert.run();
  // run() resets, so the statement can be bound again.
  insert.bind_next(std::nextafter(1.0, 2.0));
  insert.bind_next(std::int64_t{42});
  insert.bind_next(std::string());
  insert.run();

  Statement select(c, "SELECT r, i, s FROM t ORDER BY rowid", kContext);
  ASSERT_EQ(select.column_count(), 3);
  EXPECT_EQ(select.column_name(2), "s");
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.column_type(0), SQLITE_FLOAT);
  EXPECT_EQ(select.next_double(), -1.5e-300);
  EXPECT_EQ(select.next_int64(), std::numeric_limits<std::int64_t>::min());
  EXPECT_EQ(select.next_text(), text_with_nul);
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.next_double(), std::nextafter(1.0, 2.0));
  EXPECT_EQ(select.next_int64(), 42);
  EXPECT_EQ(select.next_text(), "");
  EXPECT_FALSE(select.step());
}

TEST(SqliteHandle, BlobsAreBlobsEvenWhenEmpty) {
  Connection c(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "mem");
  c.exec("CREATE TABLE t (b BLOB NOT NULL)", kContext);
  Statement insert(c, "INSERT INTO t VALUES (?)", kContext);
  const std::string bytes("\x00\xff\x01\x00", 4);
  insert.bind_blob(bytes);
  insert.run();
  insert.bind_blob(std::string());  // an empty blob, not NULL
  insert.run();
  Statement select(c, "SELECT b, typeof(b) FROM t ORDER BY rowid", kContext);
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.next_blob(), bytes);
  EXPECT_EQ(select.next_text(), "blob");
  ASSERT_TRUE(select.step());
  EXPECT_EQ(select.next_blob(), "");
  EXPECT_EQ(select.next_text(), "blob");
  EXPECT_FALSE(select.step());
}

TEST(SqliteHandle, BadSqlNamesFileFieldAndFix) {
  Connection c(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "shown.db");
  expect_input_error([&] { Statement s(c, "SELEKT 1", kContext); },
                     {"shown.db: test_field: expected a test statement, got SQLite error:",
                      "syntax error", "; do the fix"});
  expect_input_error([&] { c.exec("DROP TABLE missing_table", kContext); },
                     {"no such table: missing_table"});
}

TEST(SqliteHandle, NanIsReportedAsSuch) {
  // SQLite turns a NaN binding into NULL; the message says so instead of only "NOT NULL".
  Connection c(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "mem");
  c.exec("CREATE TABLE t (r REAL NOT NULL)", kContext);
  Statement insert(c, "INSERT INTO t VALUES (?)", kContext);
  insert.bind_next(std::nan(""));
  expect_input_error([&] { insert.run(); }, {"NOT NULL constraint failed: t.r", "NaN"});
}

TEST(SqliteHandle, CloseReportsSuccessAndIsIdempotent) {
  Connection c(":memory:", SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, "mem");
  EXPECT_NO_THROW(c.close());
  EXPECT_EQ(c.get(), nullptr);
  EXPECT_NO_THROW(c.close());
}
