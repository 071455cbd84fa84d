#include "hila/db/migration.hpp"

#include <filesystem>
#include <map>

#include "atomic_file.hpp"
#include "digest.hpp"
#include "hila/db/database.hpp"
#include "open_checks.hpp"
#include "schema.hpp"
#include "sqlite_handle.hpp"

namespace hila::db {

namespace detail {

namespace {

// The step for each version in [from, to), or an empty map if one is missing or ambiguous.
std::map<int, const MigrationStep*> plan(const std::vector<MigrationStep>& steps, int from,
                                         int to) {
  std::map<int, const MigrationStep*> by_version;
  for (const auto& step : steps) {
    if (step.from_version >= from && step.from_version < to) {
      if (by_version.count(step.from_version)) return {};
      by_version[step.from_version] = &step;
    }
  }
  if (static_cast<int>(by_version.size()) != to - from) return {};
  return by_version;
}

}  // namespace

bool can_migrate(const std::vector<MigrationStep>& steps, int from_version, int to_version) {
  return from_version < to_version && !plan(steps, from_version, to_version).empty();
}

void migrate_with_steps(const std::string& path, const std::vector<MigrationStep>& steps,
                        int target_version) {
  int version = 0;
  std::string rebuild;
  {
    // Validate the original first: no point copying a foreign or corrupt file.
    const auto original = open_hila_database(path);
    const auto meta = read_meta_table(*original);
    version = stored_schema_version(path, meta);
    rebuild = rebuild_hint(path, meta);
  }
  if (version == target_version) return;
  if (version > target_version) {
    check_schema_version(path, version, target_version, false, rebuild);  // throws
  }
  const auto by_version = plan(steps, version, target_version);
  if (by_version.empty()) {
    throw DatabaseError(
        path, "meta.schema_version",
        "a schema version this hila can migrate to version " + std::to_string(target_version),
        "schema version " + std::to_string(version) + ", for which there is no migration", rebuild);
  }

  // Work on a copy beside the original and rename it over at the end: a failed or killed
  // migration leaves the original as it was.
  const std::string temp = temporary_path_for(path);
  try {
    std::filesystem::copy_file(path, temp, std::filesystem::copy_options::overwrite_existing);
    {
      Connection connection(temp, SQLITE_OPEN_READWRITE, path);
      // foreign_keys off (SQLite's default, said before BEGIN: the pragma is a no-op inside a
      // transaction): a step that rebuilds a table others refer to (9 -> 10) renames it out of
      // the way with legacy_alter_table, which leaves their references alone only so.
      connection.exec(
          "PRAGMA journal_mode = MEMORY; PRAGMA synchronous = OFF; PRAGMA foreign_keys = OFF;",
          {"(pragmas)", "a writable copy of the database", ""});
      connection.exec("BEGIN", {"(transaction)", "a writable copy of the database", ""});
      for (const auto& [from, step] : by_version) {
        const std::string field =
            "migration " + std::to_string(from) + " -> " + std::to_string(from + 1);
        connection.exec(step->sql, {field, "a migration step that applies cleanly", rebuild});
        Statement update(connection, "UPDATE meta SET value = ? WHERE key = 'schema_version'",
                         {field, "a writable meta table", ""});
        update.bind_next(std::to_string(from + 1));
        update.run();
      }
      if (target_version >= kTableDigestsSince) {
        // What the writer stores at commit, for the content the file now holds: the file had no
        // digests to check it against, so they vouch for the migration's result only.
        write_table_digests(connection, table_digests(connection, path, target_version, rebuild),
                            {"migration (content digests)", "a writable meta table", rebuild});
      }
      connection.exec("COMMIT", {"(commit)", "a migration that commits", ""});
      connection.close();
    }
    fsync_path(temp, path);
    rename_into_place(temp, path);
  } catch (const std::filesystem::filesystem_error& e) {
    remove_quietly(temp);
    throw DatabaseError(path, "(file)", "a database that can be copied for migration", e.what());
  } catch (...) {
    remove_quietly(temp);
    throw;
  }
}

void execute_script(const std::string& path, const std::string& sql) {
  Connection connection(path, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, path);
  const ErrorContext context{"(script)", "SQL that runs cleanly", ""};
  // The writer's constraints, so hand-made rows are checked the same way (and before BEGIN: the
  // pragma is a no-op inside a transaction).
  connection.exec("PRAGMA foreign_keys = ON", context);
  connection.exec("BEGIN", context);
  connection.exec(sql, context);
  connection.exec("COMMIT", context);
  connection.close();
}

}  // namespace detail

void migrate_in_place(const std::string& path) {
  detail::migrate_with_steps(path, detail::migration_steps(), current_schema_version());
}

}  // namespace hila::db
