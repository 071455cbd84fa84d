#pragma once

#include <functional>
#include <string>
#include <vector>

#include "hila/online/board_planner.hpp"
#include "hila/online/planner_model.hpp"
#include "hila/online/scene.hpp"

namespace hila::tools {

// The seconds `hila plan` gives each board by default (--deadline).
inline constexpr double kDefaultBoardDeadlineSeconds = 30.0;

// The boards `hila plan --all` plans: every board of the product not finished in `scene`, in the
// product's order.
std::vector<std::string> boards_to_plan(const online::PlannerModel& model,
                                        const online::Scene& scene);

// Plans `boards` one after the other as `hila plan` does, each scene following from the last: the
// board finished at its target, the tool where the plan left it (in hand, or set down at its
// place), both arms home. A board not planned is assembled by hand: the next scenes have it
// finished all the same. `deadline_s` seconds per board. `planned` is called after each board
// with its plan and the scene it was planned in.
void plan_in_sequence(
    const online::PlannerModel& model, online::BoardPlanner& planner, online::Scene scene,
    const std::vector<std::string>& boards, double deadline_s,
    const std::function<void(const online::BoardPlan&, const online::Scene&)>& planned);

}  // namespace hila::tools
