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

  // Record ids are assigned by the database (1, 2, ... in call order); the records' own id and
  // part_id fields are ignored. An empty meta.created_at is filled with the current UTC time.
  // After any failed call the writer refuses to commit (the temporary file is discarded).
  void write_meta(const Meta& meta);              // schema_version is set by the writer
  std::int64_t add_part(const PartRecord& part);  // returns the part id
  void add_placements(std::int64_t part_id, const std::vector<PlacementRecord>& placements);
  void add_robot_grasps(std::int64_t part_id, const std::vector<RobotGraspRecord>& grasps);
  void add_suction_grasps(std::int64_t part_id, const std::vector<SuctionGraspRecord>& grasps);
  void add_human_grasps(std::int64_t part_id, const std::vector<HumanGraspRecord>& grasps);
  // One map per human arm; the values are stored zlib-compressed. Throws std::invalid_argument
  // for an empty arm name, spacing <= 0, a dimension <= 0, values.size() != dims.prod() *
  // orientations.size() or an orientation that is not a unit quaternion (to 1e-9), and
  // DatabaseError for an arm that already has a map.
  void add_comfort_map(const ComfortMapRecord& map);
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
};

// A read-only, fully loaded product database (small, except the comfort maps: about 13 MB per arm
// in memory). Const after open: safe to share.
class Database {
 public:
  // Throws DatabaseError for a missing, truncated, corrupt or foreign file (not SQLite, or SQLite
  // without hila's meta table), another schema version, or a hash mismatch.
  static Database open(const std::string& path, const OpenOptions& options = {});

  const std::string& path() const { return path_; }
  const Meta& meta() const { return meta_; }
  const std::vector<PartRecord>& parts() const { return parts_; }
  const PartRecord& part(const std::string& name) const;  // throws core::InputError naming the db
  std::vector<PlacementRecord> placements(std::int64_t part_id) const;
  std::vector<RobotGraspRecord> robot_grasps(std::int64_t part_id) const;
  std::vector<SuctionGraspRecord> suction_grasps(std::int64_t part_id) const;
  std::vector<HumanGraspRecord> human_grasps(std::int64_t part_id) const;
  // In the order they were written (id order).
  const std::vector<ComfortMapRecord>& comfort_maps() const { return comfort_maps_; }
  const ComfortMapRecord& comfort_map(const std::string& arm) const;  // throws core::InputError

 private:
  std::string path_;
  Meta meta_;
  std::vector<PartRecord> parts_;
  std::vector<PlacementRecord> placements_;
  std::vector<RobotGraspRecord> robot_grasps_;
  std::vector<SuctionGraspRecord> suction_grasps_;
  std::vector<HumanGraspRecord> human_grasps_;
  std::vector<ComfortMapRecord> comfort_maps_;
};

// Upgrades a database written by an older schema version to current_schema_version(): copies it
// beside itself, applies the migration steps in one transaction and renames the copy over the
// original (atomic: on any error the original is untouched). A current database is left as is.
// Throws DatabaseError for a newer, foreign or corrupt file, or when no migration path exists.
void migrate_in_place(const std::string& path);

// A hash of the database content (every table, rows in id order, doubles by their exact bits,
// comfort map values uncompressed), ignoring meta.created_at: two builds from the same inputs and
// seed have the same digest.
std::string content_digest(const std::string& path);

}  // namespace hila::db
