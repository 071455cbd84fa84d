#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/error.hpp"
#include "hila/db/records.hpp"

namespace hila::db {

// The schema version this build of hila writes and reads.
int current_schema_version();

// This hila's version (the project version, e.g. "0.10.0"): what `hila build` stores in
// meta.hila_version, what DatabaseWriter stores for an empty Meta::hila_version, and what
// Database::open expects there by default (OpenOptions::expected_hila_version).
std::string hila_version();

// The bodies of a meta.human_bodies value in stored order: its items joined by "; ", e.g.
// "1.5 female; 1.82 male" -> {"1.5 female", "1.82 male"} ("" -> none; empty items are skipped).
// Bit i of HandoverCandidateRecord::bodies stands for item i.
std::vector<std::string> human_body_labels(const std::string& human_bodies);

// SHA-256 of bytes / of a file, lower-case hex. Throws core::InputError for an unreadable file.
std::string sha256_hex(const std::string& bytes);
std::string sha256_file(const std::string& path);

// Error opening or validating a database: the message names the file, what is wrong and how to
// fix it (e.g. "rebuild with: hila build PRODUCT.yaml -o FILE"). Derives from core::InputError.
// Message: "FILE: FIELD: expected X, got Y; FIX" (no "; FIX" when `fix` is empty).
class DatabaseError : public core::InputError {
 public:
  DatabaseError(const std::string& file, const std::string& field, const std::string& expected,
                const std::string& got, const std::string& fix = "");
};

// Writes a new database atomically: everything goes to a temporary file beside the target inside
// one transaction; commit() fsyncs and renames it into place. Destroyed without commit() (an
// exception, a kill), the temporary file is removed and any previous database at the target is
// untouched. Only hila::db speaks SQL.
class DatabaseWriter {
 public:
  // Throws DatabaseError if the target's folder is missing or not writable.
  explicit DatabaseWriter(const std::string& target_path);
  ~DatabaseWriter();
  DatabaseWriter(const DatabaseWriter&) = delete;
  DatabaseWriter& operator=(const DatabaseWriter&) = delete;

  // Record ids are assigned by the database (1, 2, ... per table in call order; the add_ calls
  // that return ids return them in record order); the records' own id and, where the call takes a
  // part_id, their part_id fields are ignored. An empty meta.created_at is filled with the current
  // UTC time, an empty meta.hila_version with hila_version(). A part_id (and any other id a record
  // refers to) must name a record written before, otherwise DatabaseError (FOREIGN KEY constraint
  // failed). After any failed call the writer refuses to commit (the temporary file is
  // discarded).
  void write_meta(const Meta& meta);  // schema_version is set by the writer
  // Returns the part id. part.mass must be finite and > 0 (kg): std::invalid_argument otherwise.
  std::int64_t add_part(const PartRecord& part);
  void add_placements(std::int64_t part_id, const std::vector<PlacementRecord>& placements);
  std::vector<std::int64_t> add_robot_grasps(std::int64_t part_id,
                                             const std::vector<RobotGraspRecord>& grasps);
  std::vector<std::int64_t> add_suction_grasps(std::int64_t part_id,
                                               const std::vector<SuctionGraspRecord>& grasps);
  std::vector<std::int64_t> add_human_grasps(std::int64_t part_id,
                                             const std::vector<HumanGraspRecord>& grasps);

  // Handover goals and ergonomics (schema version 3). Every double of these records (poses, joint
  // values included) must be finite: otherwise std::invalid_argument naming the call, table.column,
  // the record and the value, before anything of the call is written.
  //
  // One stage per part, for stage.part_id: DatabaseError for a second stage of the same part
  // (UNIQUE constraint failed: handover_stages.part_id) or an unknown part. finished_parts names
  // must be non-empty and free of '\n' (std::invalid_argument): they are stored "\n"-joined.
  void add_handover_stage(const HandoverStageRecord& stage);
  // suction_grasp_id must be a written suction grasp.
  std::vector<std::int64_t> add_robot_handovers(std::int64_t part_id,
                                                const std::vector<RobotHandoverRecord>& handovers);
  // status must be "uncomfortable", "no_shared_grasp" or "goal", rank >= 0 for a goal and -1
  // otherwise (DatabaseError: CHECK constraint failed). human_grasp_id and second_grasp_id are
  // stored as given (0: none), not checked against human_grasps.
  std::vector<std::int64_t> add_handover_candidates(
      std::int64_t part_id, const std::vector<HandoverCandidateRecord>& candidates);
  // candidate_id, robot_grasp_id and robot_handover_id are taken from each record and must name
  // written records.
  void add_shared_grasps(const std::vector<SharedGraspRecord>& grasps);
  // candidate_id and robot_grasp_id are taken from each record and must name written records;
  // arm must be non-empty (schema version 5).
  void add_direct_grasps(const std::vector<DirectGraspRecord>& grasps);
  // candidate_id, pick_grasp_id and robot_grasp_id are taken from each record and must name
  // written records; arm and repick_arm must be non-empty, the placement and joints finite (schema
  // version 6; repick_arm since 8).
  void add_table_regrasps(const std::vector<TableRegraspRecord>& regrasps);
  // candidate_id and suction_grasp_id are taken from each record and must name written records;
  // arm must be non-empty, joints_rh finite (schema version 8).
  void add_suction_deliveries(const std::vector<SuctionDeliveryRecord>& deliveries);
  // method must be "hila", "table" or "alone", at most one row per part and method (DatabaseError:
  // CHECK / UNIQUE constraint failed).
  void add_ergonomics(std::int64_t part_id, const std::vector<ErgonomicsRecord>& rows);
  // One map per human arm; the values are stored zlib-compressed. Throws std::invalid_argument
  // for an empty arm name, spacing <= 0, a dimension <= 0, values.size() != dims.prod() *
  // orientations.size() or an orientation that is not a unit quaternion (to 1e-9), and
  // DatabaseError for an arm that already has a map.
  void add_comfort_map(const ComfortMapRecord& map);

  // Roadmaps and the regrasp graph (schema version 4). As for version 3, every double (joint
  // values, gravity directions, poses, costs) must be finite, and the records are checked before
  // anything of the call is written: a mistake is std::invalid_argument naming the call,
  // table.column, the record and what was expected, e.g. "DatabaseWriter::add_roadmap:
  // roadmaps.node_gravity (arm 'left'): RoadmapRecord::node_gravity holds 9 values, expected
  // one per node (10)".
  //
  // One roadmap per arm (DatabaseError: UNIQUE constraint failed: roadmaps.arm); returns its id.
  // Refused: an empty arm name, dof <= 0, resolution not > 0, a node of another size than dof,
  // node_gravity or node_inclination_deg not one per node, edge_length or
  // edge_max_inclination_deg not one per edge, an edge not 0 <= first < second < nodes.size().
  std::int64_t add_roadmap(const RoadmapRecord& roadmap);
  // part_id, roadmap_id and grasp_id are taken from each record. roadmap_id must name a roadmap
  // of this writer (FOREIGN KEY constraint failed otherwise); edges must hold one bit per edge of
  // that roadmap and component one id >= 0 per node, the ids equal at both ends of every set
  // edge; valid_edges, components and largest_component must be the counts of those. grasp_kind
  // must be "gripper" or "suction" and grasp_id a written robot_grasps or suction_grasps id
  // respectively (DatabaseError otherwise); at most one filter per part, roadmap and grasp
  // (UNIQUE constraint failed). Returns the ids in record order.
  std::vector<std::int64_t> add_roadmap_filters(const std::vector<RoadmapFilterRecord>& filters);
  // part_id and the ids are taken from each record. kind must be "home", "pick",
  // "robot_handover" or "human_handover"; grasp_kind "" exactly for "home" (with grasp_id 0),
  // else "gripper" or "suction" with grasp_id a written grasp of that kind; robot_handover_id
  // non-zero exactly for "robot_handover" and candidate_id exactly for "human_handover" (both
  // must name written records); at least one solution, all of one size > 0. Returns the ids.
  std::vector<std::int64_t> add_regrasp_nodes(const std::vector<RegraspNodeRecord>& nodes);
  // part_id and the ids are taken from each record. kind must be "transit", "transfer" or
  // "handover"; filter_id non-zero exactly for "transfer" (a written roadmap filter); from_node
  // and to_node written regrasp nodes; cost finite and >= 0, path_nodes >= 0, both 0 when not
  // connected, cost 0 for a handover. A connected "transit" or "transfer" edge has via "roadmap"
  // or "bridge" and a path of at least 2 waypoints, all of one size > 0 (finite); an edge that is
  // not connected and a "handover" edge have via "" and no path. duration finite and >= 0, 0
  // without a path (schema version 9). Returns the ids.
  std::vector<std::int64_t> add_regrasp_edges(const std::vector<RegraspEdgeRecord>& edges);
  // Stores each table's content digest in meta (digest.<table>, what Database::open compares),
  // then commits as described above.
  void commit();

  const std::string& temporary_path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct OpenOptions {
  // When set, opening fails (DatabaseError) unless the stored hash matches, with a message that
  // says which input changed and how to rebuild.
  std::optional<std::string> expected_cell_hash;
  std::optional<std::string> expected_product_hash;
  // The human comfort maps (about 13 MB per arm, most of the file and of the time to open it) are
  // read only when wanted: the online planner does not use them. Left out, comfort_maps() is
  // empty and comfort_map() says they were not loaded.
  bool comfort_maps = true;
  // The hila version the database must have been built by (meta.hila_version), as `hila build
  // --if-outdated` requires: by default this hila's. std::nullopt accepts any, e.g. to read a file
  // built by another hila or migrated from an older schema (migrate_in_place keeps the version).
  std::optional<std::string> expected_hila_version = hila_version();
};

// A read-only, fully loaded product database (small, except the comfort maps: about 13 MB per arm
// in memory, and the roadmaps and their filters: a few MB). Const after open: safe to share.
class Database {
 public:
  // Verifies the file, then loads it. Throws DatabaseError for a missing, truncated, corrupt or
  // foreign file (not SQLite, or SQLite without hila's meta table), another schema version,
  // another hila version (OpenOptions::expected_hila_version), a hash mismatch, a value of the
  // wrong storage class (a REAL column holding TEXT, a NOT NULL column holding NULL), a reference
  // that names no row, a damaged record (see docs/database.md), or a table whose content digest is
  // not the one stored in meta when the file was written (the comfort maps' only when they are
  // loaded). The message names the file, the table (and row where known), what was expected and
  // found, and how to rebuild.
  static Database open(const std::string& path, const OpenOptions& options = {});

  const std::string& path() const { return path_; }
  const Meta& meta() const { return meta_; }
  const std::vector<PartRecord>& parts() const { return parts_; }
  const PartRecord& part(const std::string& name) const;  // throws core::InputError naming the db
  std::vector<PlacementRecord> placements(std::int64_t part_id) const;
  std::vector<RobotGraspRecord> robot_grasps(std::int64_t part_id) const;
  std::vector<SuctionGraspRecord> suction_grasps(std::int64_t part_id) const;
  std::vector<HumanGraspRecord> human_grasps(std::int64_t part_id) const;
  // In the order they were written (id order); empty when opened without them
  // (OpenOptions::comfort_maps).
  const std::vector<ComfortMapRecord>& comfort_maps() const { return comfort_maps_; }
  const ComfortMapRecord& comfort_map(const std::string& arm) const;  // throws core::InputError
  // The comfort maps read from the file now, for a database opened without them. Throws
  // DatabaseError when the file is no longer the one opened (its meta table differs: rebuilt or
  // replaced) or its comfort_maps table is damaged (a value of the wrong storage class, a map
  // that does not decode, or a content digest other than the stored one).
  std::vector<ComfortMapRecord> read_comfort_maps() const;

  // Handover goals and ergonomics. The part's stage, or nullptr when the database has none for it
  // (the pointer stays valid as long as this Database). All stages in id order.
  const HandoverStageRecord* handover_stage(std::int64_t part_id) const;
  const std::vector<HandoverStageRecord>& handover_stages() const { return handover_stages_; }
  std::vector<RobotHandoverRecord> robot_handovers(std::int64_t part_id) const;          // id order
  std::vector<HandoverCandidateRecord> handover_candidates(std::int64_t part_id) const;  // id order
  // The part's candidates with status "goal", by rank ascending (then id).
  std::vector<HandoverCandidateRecord> handover_goals(std::int64_t part_id) const;
  std::vector<SharedGraspRecord> shared_grasps(std::int64_t candidate_id) const;    // id order
  std::vector<DirectGraspRecord> direct_grasps(std::int64_t candidate_id) const;    // id order
  std::vector<TableRegraspRecord> table_regrasps(std::int64_t candidate_id) const;  // id order
  std::vector<SuctionDeliveryRecord> suction_deliveries(
      std::int64_t candidate_id) const;                                  // id order
  std::vector<ErgonomicsRecord> ergonomics(std::int64_t part_id) const;  // id (write) order

  // Roadmaps and the regrasp graph (schema version 4). The arm's roadmap, or nullptr when the
  // database has none for it (valid as long as this Database); all roadmaps in id order.
  const RoadmapRecord* roadmap(const std::string& arm) const;
  const std::vector<RoadmapRecord>& roadmaps() const { return roadmaps_; }
  std::vector<RoadmapFilterRecord> roadmap_filters(std::int64_t part_id) const;  // id order
  const RoadmapFilterRecord* roadmap_filter(std::int64_t id) const;          // nullptr when none
  std::vector<RegraspNodeRecord> regrasp_nodes(std::int64_t part_id) const;  // id order
  std::vector<RegraspEdgeRecord> regrasp_edges(std::int64_t part_id) const;  // id order

 private:
  std::string path_;
  Meta meta_;
  std::vector<PartRecord> parts_;
  std::vector<PlacementRecord> placements_;
  std::vector<RobotGraspRecord> robot_grasps_;
  std::vector<SuctionGraspRecord> suction_grasps_;
  std::vector<HumanGraspRecord> human_grasps_;
  std::vector<ComfortMapRecord> comfort_maps_;
  bool comfort_maps_loaded_ = true;
  std::vector<HandoverStageRecord> handover_stages_;
  std::vector<RobotHandoverRecord> robot_handovers_;
  std::vector<HandoverCandidateRecord> handover_candidates_;
  std::vector<SharedGraspRecord> shared_grasps_;
  std::vector<DirectGraspRecord> direct_grasps_;
  std::vector<TableRegraspRecord> table_regrasps_;
  std::vector<SuctionDeliveryRecord> suction_deliveries_;
  std::vector<ErgonomicsRecord> ergonomics_;
  std::vector<RoadmapRecord> roadmaps_;
  std::vector<RoadmapFilterRecord> roadmap_filters_;  // id order: roadmap_filter() bisects
  std::vector<RegraspNodeRecord> regrasp_nodes_;
  std::vector<RegraspEdgeRecord> regrasp_edges_;
};

// Upgrades a database written by an older schema version to current_schema_version(): copies it
// beside itself, applies the migration steps in one transaction, stores the content digest of
// every table of the result (as the writer does) and renames the copy over the original (atomic:
// on any error the original is untouched). A current database is left as is. meta.hila_version
// is kept: open the result with OpenOptions::expected_hila_version = std::nullopt.
// Throws DatabaseError for a newer, foreign or corrupt file, or when no migration path exists.
void migrate_in_place(const std::string& path);

// A hash of the database content (every table of the file's schema version, rows in id order,
// doubles by their exact bits, comfort map values uncompressed), ignoring meta.created_at and
// the stored per-table digests (meta digest.*): two builds from the same inputs and seed have the
// same digest. It reads any hila database of any schema version and verifies nothing beyond the
// file's integrity: Database::open is what refuses a damaged or outdated file.
std::string content_digest(const std::string& path);

}  // namespace hila::db
