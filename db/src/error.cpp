#include "hila/core/error.hpp"

#include "hila/db/database.hpp"

namespace hila::db {

namespace {
// The fix goes after the InputError's "got" part so file() and field() stay set for callers.
std::string with_fix(const std::string& got, const std::string& fix) {
  return fix.empty() ? got : got + "; " + fix;
}
}  // namespace

DatabaseError::DatabaseError(const std::string& file, const std::string& field,
                             const std::string& expected, const std::string& got,
                             const std::string& fix)
    : core::InputError(file, field, expected, with_fix(got, fix)) {}

}  // namespace hila::db
