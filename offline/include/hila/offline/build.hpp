#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/comfort_map.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/product.hpp"
#include "hila/db/provenance.hpp"
#include "hila/offline/ergonomics.hpp"
#include "hila/offline/handover.hpp"
#include "hila/offline/human_grasps.hpp"
#include "hila/offline/regrasp.hpp"
#include "hila/offline/robot_grasps.hpp"
#include "hila/offline/suction_grasps.hpp"
#include "hila/offline/tool_place.hpp"

namespace hila::offline {

struct BuildSettings {
  std::uint64_t seed = 1;
  int jobs = 1;  // worker threads over parts; the content never depends on it
  RobotGraspSettings robot;
  SuctionSettings suction;
  HumanGraspSettings human;
  core::ComfortMapSettings comfort;  // one map per human arm of the cell
  HandoverSettings handover;
  ErgonomicsSettings ergonomics;
  RoadmapSettings roadmap;  // one per arm; suction_arm follows handover.suction_arm
  RegraspSettings regrasp;  // arms follow handover's
  // The tool's relay (with handover.swap_roles): approach and lift follow handover's
  // exchange_approach and pick_lift.
  ToolRelaySettings tool_relay;
  // Empty: handover goals must be comfortable for the cell's human. Otherwise for every body of
  // the set (statures and sexes, served by the cell human's maps; see HumanComfort).
  std::vector<core::HumanBodySpec> human_bodies;
};

struct PartBuildSummary {
  std::string name;
  int order = 0;
  double mass = 0.0;
  int placements = 0;
  int robot_grasps = 0;
  int suction_grasps = 0;
  int human_grasps = 0;
  int one_hand_grasps = 0;
  double theta_c_min_deg = 90.0;
  double theta_c_max_deg = 90.0;
  double seconds = 0.0;
  // Handover goals (paper §IV, §VI-B).
  int handover_draws = 0;
  int handover_candidates = 0;
  int comfortable = 0;               // |S|
  int comfortable_default_body = 0;  // HandoverStageRecord::comfortable_default_body
  int goals = 0;                     // |𝕊|
  // With a body set: goals each body of the set takes comfortably (its bit of
  // HandoverCandidateRecord::bodies), in the set's order.
  std::vector<int> goals_per_body;
  int robot_handovers = 0;
  bool two_hands = false;
  double goal_quality = 0.0;     // the first goal's
  double goal_distance = 0.0;    // Eq. 8
  std::string handover_failure;  // empty when the board has goals
  std::string suction_arm;       // the arm that picks by suction and hands over (its goals')
  double handover_seconds = 0.0;
  // Regrasp graph (filtered roadmaps, paper §V).
  int regrasp_filters = 0;
  int regrasp_nodes = 0;
  int regrasp_edges = 0;
  int transfers = 0;  // receiving-arm robot-robot -> robot-human transfers tried
  int transfers_connected = 0;
  int bridges = 0;
  int goals_considered = 0;
  int goals_served = 0;  // goals whose whole chain connects in the roadmaps
  int first_served_rank = -1;
  int exchanges_examined = 0;  // robot-robot poses whose suction-arm transfer was examined
  int exchanges_connected = 0;
  std::string regrasp_failure;
  double regrasp_seconds = 0.0;
};

struct RoadmapSummary {
  std::string arm;
  int nodes = 0;
  int edges = 0;
  double seconds = 0.0;
};

struct ComfortMapSummary {
  std::string arm;
  long filled_bins = 0;
  double coverage = 0.0;
  double seconds = 0.0;
};

struct BuildSummary {
  std::string output;
  std::vector<PartBuildSummary> parts;          // in assembly order
  std::vector<ComfortMapSummary> comfort_maps;  // in the cell's human-arm order
  std::vector<RoadmapSummary> roadmaps;         // suction arm, receiving arm
  ToolRelay tool_relay;                         // where both arms take the tool (meta tool_relay)
  double seconds = 0.0;
  // Boards without a handover goal (the database is still written, with the reasons stored).
  std::vector<std::string> failed_parts() const;
  // Boards with goals none of which connects through the roadmaps (home -> pick -> robot-robot
  // -> robot-human). Not a failure: the online planner repairs cut roadmaps, at a cost in time.
  std::vector<std::string> unconnected_parts() const;
};

// Called as each part finishes (from a worker thread, serialised): name, parts done, total.
using BuildProgress = std::function<void(const std::string& part, int done, int total)>;

// Hashes that tie a database to its inputs: the cell's and the product's (db/provenance.hpp)
// and the content-relevant settings' (not `jobs`).
using db::cell_hash;
using db::product_hash;
std::string settings_hash(const BuildSettings& settings);

// The per-part seed: independent of the part's position in the file and of the thread that
// builds it.
std::uint64_t part_seed(std::uint64_t seed, const std::string& part_name, std::uint64_t stream);

// SHA-256 of a mesh as loaded (vertices and triangles, metres): db::PartRecord::mesh_hash.
std::string mesh_hash(const core::TriangleMesh& mesh);

// Builds the product database: part analysis, robot grasps with theta_c, suction and human
// grasps and the human comfort maps (in parallel over parts and arms), then per board its
// handover goals and the ergonomics comparison (in parallel over boards); written atomically
// (the previous file survives any failure). A board without a handover goal does not stop the
// build: its stage record says why and BuildSummary::failed_parts() lists it.
// Throws core::InputError for bad input, naming the file, the part and the field.
BuildSummary build_database(const std::string& product_path, const std::string& cell_path,
                            const std::string& output_path, const BuildSettings& settings,
                            const BuildProgress& progress = {});

}  // namespace hila::offline
