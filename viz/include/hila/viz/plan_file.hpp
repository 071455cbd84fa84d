#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/pose.hpp"

namespace hila::viz {

// A plan file as `hila plan -o` writes it (docs/online.md, "The plan file"): what an export
// needs of it.
struct PlanFileStep {
  std::string name;
  std::string arm;
  std::vector<std::string> events;      // in order; "suction_off" and "gripper_open" start a step
  std::vector<double> time;             // s from the board's start, non-decreasing
  std::vector<Eigen::VectorXd> joints;  // the arm's joints at each time, rad
};

struct PlanFileBoard {
  std::string board;
  std::string status;                        // "solved", or why not
  double duration = 0;                       // s, 0 when not solved
  std::optional<core::Pose> robot_handover;  // world, an exchange's
  std::optional<core::Pose> human_handover;  // world, at the goal
  std::vector<PlanFileStep> steps;
  bool solved() const { return status == "solved"; }
};

struct PlanFile {
  std::string file;
  std::string database;  // as written by `hila plan`
  std::string scene;
  std::string product;
  std::vector<PlanFileBoard> boards;  // in the order planned
  // The sum of the boards' durations: the whole plan played board after board, s.
  double duration() const;
};

// Reads and checks a plan file: the format (`hila_plan` 1), finite numbers, steps whose times
// are non-decreasing, start at or after the previous step's end and end by the board's duration,
// one joint vector of one size per time. Throws core::InputError naming the file and the field.
PlanFile read_plan_file(const std::string& path);
// The same from the file's text; `file` names it in messages.
PlanFile parse_plan_file(const std::string& text, const std::string& file);

}  // namespace hila::viz
