#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hila/core/bridge.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"
#include "hila/db/records.hpp"
#include "hila/offline/handover.hpp"
#include "hila/offline/roadmap.hpp"

namespace hila::offline {

struct RegraspSettings {
  // Handover goals are taken in Eq. 8 order, at most `goals` of them, each with its shared
  // grasps until one connects the whole chain; the search ends once `served_goals` goals are
  // served (the online planner tries them in the same order and rarely falls back further).
  // Filters are made for the grasps met on the way.
  int goals = 10;
  int served_goals = 3;
  // Then the goals the cell's human takes with the part's centre between hip and shoulder
  // height (core::natural_height_band), in Eq. 8 order: up to `served_natural` more served, of
  // at most `considered_natural` examined (each unserved one costs its grasps' chains).
  int served_natural = 2;
  int considered_natural = 4;
  int attach_neighbours = 10;  // roadmap nodes tried when connecting a configuration
  // The same for the receiving arm's pre-grasp at the exchange: beside the board it holds still,
  // most straight joins to the nearest nodes cross it.
  int way_in_neighbours = 150;
  // Where a filtered roadmap is cut (or an end does not attach), a bridge is planned.
  core::BridgeSettings bridge;
  // The receiving arm may take the board in any IK branch at the exchange and hand it over in
  // any at the goal: transits and transfers are tried through the roadmap for every branch
  // (pair), then bridged for at most this many.
  int transfer_bridges = 2;
  // A receiving-arm transfer the filtered roadmap cannot make (a bridge) gets up to this many
  // other bridges between the same ends (samples projected onto the slip limit), stored as
  // parallel transfer edges after it: online, a scene that blocks one often leaves another.
  // Six: under a tight slip limit most tries fail, and it takes more than one stored bridge for
  // a box to leave one free.
  int bridge_alternatives = 6;
  long alternative_checks = 200000;  // each alternative's budget (tight slip limits need many)
  std::uint64_t seed = 1;            // bridges' samplers
  double lift = 0.15;  // m, straight up from the stack (the build uses HandoverSettings::pick_lift)
  // The receiving arm's way in at the exchange: a pre-grasp this far (m) back from the grasp or
  // along the board's edge (as the online planner's approach), the straight motion into the
  // grasp checked at this resolution (rad, the online validator's). The build takes them from
  // HandoverSettings (exchange_approach, exchange_resolution), as the robot-robot poses.
  double approach = 0.05;
  double approach_resolution = 0.01;
  // Motions holding the board (attachments, roadmap edges, bridges) are checked this finely
  // (rad; the build takes HandoverSettings::exchange_resolution, the online validator's).
  double held_resolution = 0.01;
  // The online planner's own (MotionSettings::held_resolution): a suction-arm transfer to a
  // robot-robot pose that does not connect at held_resolution is searched again at this one, and
  // stored as blocked only where it fails there too (the online planner searches at this
  // resolution and mends the path for its validator).
  double online_held_resolution = 0.04;
  // That search's bridges draw this share of their samples around the robot-robot end (the
  // online planner's MotionSettings::wedged_focus).
  double coarse_focus = 0.6;
  // and at most this many checks each: the online planner's budget for a bridge from a wedged
  // end (MotionSettings::wedged_bridge_checks), so that what is stored as blocked is what the
  // online planner would not find either.
  long coarse_bridge_checks = 3000;
  // Each stored path's estimated duration (RegraspEdgeRecord::duration) is its time at the arm's
  // velocity and acceleration limits times this, in pieces of at most `timing_step` rad: the
  // online planner's defaults (BoardPlanSettings::speed_scale and timing_step), so that a stored
  // duration reads as the robot's seconds along the path before it is smoothed.
  double timing_speed_scale = 0.5;
  double timing_step = 0.05;
  std::string suction_arm = "right";
  std::string receiving_arm = "left";
};

// The regrasp graph of one board at its assembly stage (paper §V): nodes are the board's poses
// (suction pick from the stack, robot-robot handover, robot-human handover) × arm × grasp with
// their IK solutions, plus each arm at home; edges are transit (arm empty), transfer (arm holding
// the board, through the grasp's filtered roadmap) and handover (suction arm -> gripper arm).
// Indices are 0-based into this result and the board's inputs (-1: none); the build turns them
// into database ids:
//  - filters: roadmap_id is the arm index (0 suction arm, 1 receiving arm), grasp_id an index
//    into the board's robot (gripper) or suction grasps;
//  - nodes: grasp_id as above, robot_handover_id / candidate_id index HandoverResult's vectors;
//  - edges: from_node / to_node index `nodes`, filter_id indexes `filters`.
struct RegraspResult {
  std::vector<db::RoadmapFilterRecord> filters;
  std::vector<db::RegraspNodeRecord> nodes;
  std::vector<db::RegraspEdgeRecord> edges;
  int shared_grasps = 0;  // shared grasps tried
  // Shared grasps whose chain breaks before the exchange (the suction arm's pick, transit or
  // transfer, or the receiving arm's transit): no filter is made for them.
  int cut_before_exchange = 0;
  int transfers = 0;  // receiving-arm robot-robot -> robot-human transfers tried
  int transfers_connected = 0;
  // Suction deliveries of the first goals: the suction arm's transfers, the board on the cup,
  // from the lift to the robot-human pose, tried and connected.
  int suction_transfers = 0;
  int suction_transfers_connected = 0;
  // Robot-robot poses whose suction-arm transfer was examined (those of the goals examined), and
  // of those the ones it connected.
  int exchanges_examined = 0;
  int exchanges_connected = 0;
  int bridges = 0;           // edges connected by a bridge rather than the roadmap
  int alternatives = 0;      // of those, other bridges of a transfer (bridge_alternatives)
  int goals_considered = 0;  // goals examined (in Eq. 8 order)
  int goals_served = 0;      // goals with a connected chain home -> pick -> rr -> rh
  int first_served_rank = -1;
  std::string failure;  // why no goal is served (empty when one is)
  double seconds = 0.0;
};

// Roadmaps: the suction arm's and the receiving arm's (built by build_roadmap over the empty
// cell). The filters and the chains are planned at the board's stage (the parts before it
// finished at their nominal targets); the online planner re-validates against the actual
// assembly.
RegraspResult plan_regrasp(const core::Cell& cell, const core::ProductSpec& product,
                           std::size_t index, const BoardGrasps& grasps,
                           const HandoverResult& handover, const Roadmap& suction_roadmap,
                           const Roadmap& receiving_roadmap, const RegraspSettings& settings);

// A gripper grasp's slip data in the TCP frame (opening axis, lever to the centre of mass, θc).
GraspSlip grasp_slip(const core::Cell& cell, const db::RobotGraspRecord& grasp,
                     const Eigen::Vector3d& com);

}  // namespace hila::offline
