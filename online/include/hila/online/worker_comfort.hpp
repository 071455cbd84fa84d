#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/comfort.hpp"
#include "hila/core/comfort_map.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/receiving_posture.hpp"
#include "hila/db/records.hpp"

namespace hila::online {

// The comfort (paper Eq. 4, by the database's comfort maps) of the human who is in the scene at
// a stored handover goal. The goals were ranked for the cell's human at the cell's stance; a
// worker standing elsewhere, or turned, reaches the same board pose with other arm postures, or
// not at all, and the planner must not hand over where they cannot take the part.
//
// The maps are in each human arm's base frame (the torso at the neutral posture), so the same
// map serves any stance: the arm base moves with the stance frame. The lookup is the build's
// (offline::HumanComfort::quality), so at the cell's stance a goal's quality is the stored one.
// A worker of another body (`worker:` in the scene, a core::HumanBody) is served by the same maps
// through the scaled-copy property (core::HumanBody::to_cell_arm, the build's lookup for a body
// set); every function takes that body, nullptr for the cell's own human.
// Immutable after construction; safe to share between threads.
class WorkerComfort {
 public:
  // `maps`: one record per human arm of the cell (the database's comfort_maps()). Throws
  // core::InputError naming the database when an arm of the cell has no map.
  WorkerComfort(const core::Cell& cell, const std::vector<db::ComfortMapRecord>& maps,
                const std::string& database_path);

  // Q with hand `arm` holding the part by `hand_in_part` while the part is at `part` (world),
  // for the human of `body` (nullptr: the cell's) standing at `stance`; 0 out of reach (or for an
  // arm the cell has not).
  double hand_quality(const std::string& arm, const core::Pose& part,
                      const core::Pose& hand_in_part, const core::Pose& stance,
                      const core::HumanBody* body = nullptr) const;

  // The goal's quality for the human at `stance`: its human grasp's, or the weaker hand's for a
  // two-hand goal. `human_grasps` by id (the part's). 0 when a grasp is missing.
  double goal_quality(const db::HandoverCandidateRecord& goal,
                      const std::map<std::int64_t, db::HumanGraspRecord>& human_grasps,
                      const core::Pose& stance, const core::HumanBody* body = nullptr) const;

  // Whether the human at `stance` reaches the goal's grasp with every hand it needs, by inverse
  // kinematics of the human arm (core::best_comfort, as the build confirms its first goals): from
  // the build's posture where the goal has one (a human a few centimetres off the built stance
  // is a few iterations away), then up to 8 seeded restarts, stopping at the first solution. The
  // weaker hand's Q at the postures found. The maps are sampled (a bin no sample reached reads
  // 0), so a low map Q does not mean out of reach; this does. With `body`, that body's own arms
  // (its chains, its torso at the stance; the build's posture is only the first seed).
  struct GoalReach {
    bool reachable = false;
    double quality = 0.0;                   // the weaker hand's Q at the postures found
    Eigen::VectorXd joints, second_joints;  // goal.human_arm's, goal.second_arm's (rad)
  };
  // Needs the cell's human arms only, not the maps: callable without loading them.
  static GoalReach goal_reach(const core::Cell& cell, const db::HandoverCandidateRecord& goal,
                              const std::map<std::int64_t, db::HumanGraspRecord>& human_grasps,
                              const core::Pose& stance, const core::HumanBody* body = nullptr,
                              const core::ComfortSettings& ik = reach_settings());
  // For a reach check: core::reach_settings().
  static core::ComfortSettings reach_settings() { return core::reach_settings(); }

 private:
  struct Arm {
    std::string name;
    core::ComfortMap map;
    core::Pose base_in_stance;  // the arm's base (torso) in the human's floor frame, neutral
  };
  const Arm* arm(const std::string& name) const;
  std::vector<Arm> arms_;
};

}  // namespace hila::online
