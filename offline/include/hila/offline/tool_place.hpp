#pragma once

#include <optional>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/product.hpp"
#include "hila/core/stage_scene.hpp"

namespace hila::offline {

// Where the suction tool stands on the table, and which arm can take it there.
//
// The tool rests on its stand (product.suction_tool_pose), which one arm may reach alone. A part
// only the other arm can pick by suction needs the tool handed over: the arm that reaches the
// stand carries the tool to a relay, a place on the table both arms reach, and the other takes it
// from there (online::BoardPlanner). The relay is found once per product and stored in the
// database (meta tool_relay).

// Whether `arm` can take the suction tool standing with its handle at `handle` (world) and set it
// down there, as the online tool stages do: an IK solution with the open hand at the handle, the
// one nearest it `approach` m back along the gripper's approach (open hand) and the one nearest
// it `lift` m above (holding the tool), each within the joint limits and clear of the cell and of
// `finished` and `stacked`.
bool reaches_tool_at(const core::Cell& cell, const std::string& arm, const core::Pose& handle,
                     const std::vector<core::PlacedPart>& finished,
                     const std::vector<core::PlacedPart>& stacked, double approach, double lift);

// reaches_tool_at the product's stand, the parts standing at the stage of product.parts[index].
bool reaches_tool_stand(const core::Cell& cell, const core::ProductSpec& product, std::size_t index,
                        const std::string& arm, double approach, double lift);

struct ToolRelaySettings {
  // Grid step over the top of the table the stand is on, m: the relay is within half of it of
  // the best place. The places both arms reach may be a strip a few cm wide between the stack and
  // the parts laid out (the cabinet's with a board on the left: about 5 cm), so 2.5 cm.
  double spacing = 0.025;
  // Handle yaws tried at each grid point: the stand's, turned about the world z axis by multiples
  // of 360 / yaw_steps degrees (a handle facing an arm is easier for it to take).
  int yaw_steps = 4;
  // Distance from the standing tool to every part (at its initial pose and at its target) and the
  // robot at home that a place should keep, m: room for the open fingers that take a part beside
  // it. Places that keep it come first; the others (the tool touching nothing) only where none
  // of those serves.
  double clearance = 0.03;
  double approach = 0.05;  // m, as the online tool pick's approach (HandoverSettings)
  double lift = 0.05;      // m, as the online tool lift
};

struct ToolRelay {
  std::optional<core::Pose> handle;  // the relay's handle pose (world); none when no place serves
  int places = 0;                    // candidate places tried (grid points x yaws)
  int clear = 0;                     // of those, the tool clear of the parts by the clearance
};

// The relay: among the places on the stand's table top (the stand's height and tilt, x and y on a
// grid, the yaws above) where the standing tool touches no part and every arm of the cell reaches
// it (reaches_tool_at, with every part both at its initial pose and at its target: a place that
// serves the whole assembly), those that keep the clearance first, then the one whose farthest
// arm base is nearest. Deterministic; none when the stand is on no obstacle of the cell or no
// place serves.
ToolRelay find_tool_relay(const core::Cell& cell, const core::ProductSpec& product,
                          const ToolRelaySettings& settings);

}  // namespace hila::offline
