#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"
#include "hila/online/scene.hpp"

namespace hila::bench {

// How far a variation may stray from its base scene (what the cameras could plausibly report).
struct VariationSettings {
  double board_shift = 0.03;    // m, each of x and y, uniform in +-
  double board_yaw_deg = 30.0;  // about world z through the board's centre, uniform in +-
  double stance_shift = 0.05;   // m, the human's stance in x and y, uniform in +-
  double box_min = 0.10;        // m, the extra box's side (a cube)
  double box_max = 0.20;        // m
  double box_margin = 0.05;     // m kept between the box and what it must not touch
  int board_tries = 1000;       // board poses drawn before giving up
  int box_tries = 2000;         // box placements drawn before giving up
};

// One seeded scene and what was changed, for the report.
struct VariedScene {
  online::Scene scene;
  std::uint64_t seed = 0;
  Eigen::Vector2d board_shift = Eigen::Vector2d::Zero();  // m
  double board_yaw_deg = 0.0;
  int board_redraws = 0;  // board poses drawn and dropped because the board touched something
  Eigen::Vector2d stance_shift = Eigen::Vector2d::Zero();  // m
  double box_side = 0.0;                                   // m
  Eigen::Vector3d box_centre = Eigen::Vector3d::Zero();    // world
  double box_yaw_deg = 0.0;
};

// A seeded variation of `base` for planning `board` (std::mt19937_64, deterministic for a
// given standard library): the board's detected pose shifted in x/y and yawed about world z
// around its centre (its height kept; redrawn while the board would touch a finished board, the
// robot, the tool or the table), the human's stance shifted in x/y, and one extra box
// standing on the table, placed where it keeps `box_margin` from the board's footprint, the
// other boards still on the table, the assembly's footprint (every board at its target) and,
// checked by collision with the box grown by the margin, the robot at the scene's joints and
// the tool when it stands on the table. The box may block a way the arms would take: that is
// part of the problem. Throws std::runtime_error when no place is found.
VariedScene vary_scene(const online::Scene& base, const core::Cell& cell,
                       const core::ProductSpec& product, const std::string& board,
                       std::uint64_t seed, const VariationSettings& settings = {});

}  // namespace hila::bench
