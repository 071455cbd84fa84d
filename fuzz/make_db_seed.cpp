// Writes the database fuzz target's seed: the db tests' sample database (tests/db/
// sample_records.hpp: two parts and every table, awkward values included), through DatabaseWriter.
// Usage: make_db_seed OUT.hila
#include <iostream>

#include "db/sample_records.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: make_db_seed OUT.hila\n";
    return 2;
  }
  namespace data = hila::db::test_data;
  data::write_sample(argv[1], data::make_sample());
  return 0;
}
