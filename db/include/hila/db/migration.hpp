#pragma once

#include <string>
#include <vector>

namespace hila::db::detail {

// One schema upgrade: SQL that turns a database of `from_version` into `from_version + 1`. The
// framework updates meta.schema_version itself; the SQL only changes tables and rows.
struct MigrationStep {
  int from_version = 0;
  std::string sql;
};

// The steps this build of hila knows, in order (1 -> 2 adds comfort_maps, 2 -> 3 the handover and
// ergonomics tables and meta.human_bodies, 3 -> 4 the roadmap and regrasp-graph tables, 4 -> 5
// direct_grasps, 5 -> 6 table_regrasps, 6 -> 7 the per-table content digests in meta, which the
// migration itself writes after its last step, 7 -> 8 suction_deliveries and
// table_regrasps.repick_arm, 8 -> 9 regrasp_edges.duration, 9 -> 10
// handover_candidates.bodies).
const std::vector<MigrationStep>& migration_steps();

// True if `steps` hold one step for every version from `from_version` up to `to_version` - 1.
bool can_migrate(const std::vector<MigrationStep>& steps, int from_version, int to_version);

// migrate_in_place with an explicit step list and target version, so the framework can be tested
// with synthetic steps. A target version of 7 or later gets the content digests of its tables
// (those of hila's schema that the version has) after the last step. Throws DatabaseError when a
// step is missing, fails, or the file is newer.
void migrate_with_steps(const std::string& path, const std::vector<MigrationStep>& steps,
                        int target_version);

// Runs SQL on a database file (created if missing) in one transaction. For tests and tools that
// need hand-made databases (old versions, foreign files); hila writes through DatabaseWriter.
void execute_script(const std::string& path, const std::string& sql);

}  // namespace hila::db::detail
