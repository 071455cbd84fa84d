#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/human_body.hpp"
#include "hila/offline/ergonomics.hpp"
#include "hila/offline/human_comfort.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/scene.hpp"
#include "receiving_ergonomics.hpp"

namespace hila::tools {

// The three ways a board reaches the worker that `hila report ergonomics` compares: hila's
// planned handover, the board laid flat on the table in front of the worker, the worker alone
// taking it from the stack.
inline constexpr std::array<const char*, 3> kErgonomicsMethods = {"hila", "table", "alone"};

// A worker the report is for.
struct ReportWorker {
  std::string label;  // "1.5 female", or "cell human"
  std::string from;   // "--workers", "database" (meta.human_bodies), "scene", "cell"
  std::shared_ptr<const core::HumanBody> body;  // nullptr: the cell's own human
};

// How the worker takes a board by one method.
struct TakenPosture {
  // hila: the plan's status ("solved", "no goal", ...); table and alone: "reachable",
  // "unreachable", or "not evaluated" (a part without a stable placement has no table drop).
  std::string status;
  bool scored = false;  // a posture, scored: every figure below is set
  std::string why;      // not scored: why (the plan's reason, "unreachable", a scoring error)
  std::string arm;      // the hand that takes it (hila: the goal's hand)
  std::map<std::string, Eigen::VectorXd> joints;  // each receiving hand's arm joints, rad
  double torso_flexion_deg = 0.0;
  double reach = 0.0;              // m, the hand's grasp frame from its shoulder joint
  double reorientation_deg = 0.0;  // left to the target, modulo the part's symmetries
  double quality = 0.0;            // Q (paper Eq. 4) of the arm at the posture; the weaker hand's
  ReceivingErgonomics ergonomics;  // RULA, REBA, where the posture puts the worker
  // The re-orientation left, turned in the worker's hands at the scene's stance
  // (offline::turn_in_hands, from the board as taken): set for a scored posture.
  std::optional<offline::Turn> turn;
  // hila only: the goal planned, the way and whether the planner took it as a natural posture.
  int goal_rank = -1;
  std::int64_t candidate = 0;
  std::string way;
  bool natural_posture = false;
};

struct BoardPostures {
  std::string board;
  int order = 0;
  int symmetries = 0;                             // of the part's mesh (the identity included)
  std::map<std::string, TakenPosture> by_method;  // kErgonomicsMethods
};

struct WorkerPostures {
  ReportWorker worker;
  core::HeightBand band;  // hip and shoulder heights at the stance, neutral posture (m, world)
  std::vector<BoardPostures> boards;
};

// What every worker's report is computed from, loaded once.
struct ErgonomicsContext {
  std::shared_ptr<const online::PlannerModel> model;
  online::Scene scene;  // the scene the sequence starts from; its worker is replaced by each's
  // The cell human's comfort maps (the database's); nullopt when they cannot be read
  // (comfort_error says why): the table and the alone postures are then not evaluated.
  std::optional<offline::HumanComfort> comfort;
  std::string comfort_error;
  std::map<std::string, std::vector<Eigen::Matrix3d>> symmetries;  // by part
};

// Loads the model, the scene and the comfort maps. Throws core::InputError / db::DatabaseError
// as `hila plan` does (a scene that does not load, a database built from other files).
ErgonomicsContext load_ergonomics_context(const std::string& database, const std::string& scene);

// Every board still to be handled in the context's scene, for `worker`: (a) planned in assembly
// order by a BoardPlanner of its own, each scene following from the last (as `hila plan --all`
// for the scene naming the worker), and the planned receiving posture scored as the plan file
// scores it; (b) laid flat at the table spot and (c) taken from the stack, the posture searched
// for the worker's body (offline::evaluate_ergonomics with the build's settings and seed) and
// scored by the same functions. `deadline_s` seconds per board.
WorkerPostures worker_postures(const ErgonomicsContext& context, const ReportWorker& worker,
                               double deadline_s);

}  // namespace hila::tools
