// libFuzzer target: opening a database (db::Database::open: the file's integrity, schema and hila
// version, column types, references, the per-table digests, then every record). The input is the
// SQLite file; the seed is make_db_seed's.
#include "fuzz_input.hpp"
#include "hila/db/database.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string dir = hila::fuzz::work_dir("cabinet", {});
  const std::string path = hila::fuzz::write_input(dir, "fuzz.hila", data, size);
  hila::fuzz::expect_input_errors_only([&] { hila::db::Database::open(path); });
  return 0;
}
