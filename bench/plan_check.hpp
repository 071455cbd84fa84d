#pragma once

#include <string>
#include <vector>

#include "hila/online/board_planner.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/scene.hpp"

namespace hila::bench {

struct PlanCheck {
  std::vector<std::string> problems;  // empty: the plan is valid
  int steps = 0;
  int samples = 0;  // configurations the validator checked
  bool valid() const { return problems.empty(); }
};

// Re-checks a solved board plan without trusting the planner's own bookkeeping: a fresh World
// for the scene, and the robot, the tool and the board replayed from the scene's start through
// the steps and their events alone (suction on/off, gripper close/open, tool grasped), with the
// grasps looked up in the database by the plan's ids. Every step must start where its arm is
// and after the previous step, pass validate_motion (collisions of what moves, slip within the
// grasp's theta_c, joint limits, velocities and accelerations) with what it holds, what the
// other arm holds and what stands where at that moment; no arm may move while both hold the
// board; and each attachment must happen where the object is: the tool at its handle on the
// table, the cup on the board at its detected pose, the gripper on the board at the plan's
// robot-robot pose, the board at the plan's robot-human pose when the human is waited for, and
// the board must end with the human.
PlanCheck check_plan(const online::PlannerModel& model, const online::Scene& scene,
                     const online::BoardPlan& plan, const online::BoardPlanSettings& settings);

}  // namespace hila::bench
