#include <gtest/gtest.h>

#include <string>

#include "hila/core/error.hpp"
#include "hila/db/database.hpp"

using hila::db::DatabaseError;

TEST(DatabaseError, MessageFollowsInputErrorFormatWithFix) {
  const DatabaseError e("out/p.db", "meta.cell_hash", "X", "Y", "rebuild with: hila build a -o b");
  EXPECT_STREQ(e.what(),
               "out/p.db: meta.cell_hash: expected X, got Y; rebuild with: hila build a -o b");
  EXPECT_EQ(e.file(), "out/p.db");
  EXPECT_EQ(e.field(), "meta.cell_hash");
}

TEST(DatabaseError, NoFixMeansNoTrailingSeparator) {
  const DatabaseError e("p.db", "(file)", "X", "Y");
  EXPECT_STREQ(e.what(), "p.db: (file): expected X, got Y");
}

TEST(DatabaseError, IsCaughtAsInputError) {
  // The CLI reports InputError as a user error (exit 2): database problems must land there.
  try {
    throw DatabaseError("p.db", "(file)", "X", "Y", "fix");
  } catch (const hila::core::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("fix"), std::string::npos);
    return;
  }
  FAIL() << "DatabaseError was not caught as core::InputError";
}
