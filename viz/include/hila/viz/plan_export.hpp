#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/viz/plan_file.hpp"

namespace hila::viz {

// The cell as the plan found it (its scene file, docs/scene.md).
struct PlanStart {
  std::map<std::string, core::Pose> initial;  // world pose of every board the plan handles
  std::vector<core::PlacedPart> finished;     // boards already assembled, at their world poses
  core::Pose assembly_frame = core::Pose::Identity();  // where the plan's boards end (world)
  core::Pose tool = core::Pose::Identity();  // the suction tool's handle (world) on the table
  bool tool_in_hand = false;  // held by the suction arm (the plan's tool_/suction_ steps' arm)
  std::optional<core::Pose> human_stance;        // world; empty: the cell's
  std::map<std::string, Eigen::VectorXd> robot;  // arm name -> joints at the start; missing: home
};

// The plan as an animated glTF 2.0 binary (.glb): the cell's nodes as cell_glb names them, at
// the start, and one animation "plan" playing the boards one after the other (board k from the
// sum of the earlier boards' durations; its end is PlanFile::duration()). Channels:
// - each arm joint's child link node: its rotation (a prismatic joint: its translation) at every
//   time stamp of that arm's steps, LINEAR, so glTF's interpolation is the plan's linear
//   interpolation of the joints;
// - visibility (scale 1 or 0, STEP) of the copies of the board and the tool: "stack/B" (on the
//   table until picked), "held/B#i" (a child of the holding arm's TCP link node, from the grasp
//   event on), "placed/B#i" (where it was let go, in the world), "finished/B" (at its target in
//   the assembly frame from the board's end; an unsolved board from its start), "tool/LINK#i".
// Besides "plan", one animation per solved board, named after the board, over that board's span:
// its times run from 0 to the board's duration (the plan file's times of the board), with the
// same channels keyed at its start, its end and the time stamps between, so that each board can
// be played on its own. No animation when nothing moves.
// The jaws stay open and the human stays in the neutral posture. Throws core::InputError for a
// board or arm the cell or product does not know, or joints of the wrong size.
std::string plan_glb(const core::Cell& cell, const core::ProductSpec& product,
                     const PlanStart& start, const PlanFile& plan);

}  // namespace hila::viz
