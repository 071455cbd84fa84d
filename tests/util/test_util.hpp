#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <initializer_list>
#include <memory>
#include <random>
#include <string>

#include "hila/core/cell.hpp"
#include "hila/core/kinematic_chain.hpp"
#include "hila/core/pose.hpp"

namespace hila::test {

std::string data_path(const std::string& relative);  // under meshes/
std::string cell_path();                             // meshes/cell/cell.yaml
std::string product_path();                          // meshes/cabinet/product.yaml

// The reference cell, loaded once per test binary.
std::shared_ptr<const core::Cell> reference_cell();
// The arm's first analytic IK solution (nearest its home) for its TCP pointing straight down at
// `p` (world); a failed expectation and the home configuration when there is none.
Eigen::VectorXd arm_pointing_down_at(const core::Cell& cell, const core::Arm& arm,
                                     const Eigen::Vector3d& p);

// A fresh, empty directory for this test in this process (removed and recreated on every call).
std::string temp_dir(const std::string& name);
// Writes `text` to `dir/name` and returns the path.
std::string write_file(const std::string& dir, const std::string& name, const std::string& text);
std::string read_file(const std::string& path);

// A shell command's exit status (-1 when it did not exit) and its stdout and stderr together.
struct CommandRun {
  int status = -1;
  std::string out;
};
CommandRun run_command(const std::string& command);
// The reference cell with one text change (`from`, which must occur, replaced by `to`), written
// into `dir` with the URDFs it names; returns the cell file's path.
std::string cell_variant(const std::string& dir, const std::string& from, const std::string& to);

// A 49 x 68 x 25 mm L bracket of 2.4 mm steel (tools/dev/gen_products --seed 1, product 16)
// lying on the left of the table, no face for the suction cup, as a one-part product written into
// `dir` (bracket.obj, product.yaml); returns the product file's path. Its gripper grasps where it
// lies leave the human no room: a regrasp on the table serves it.
std::string bracket_product(const std::string& dir);

core::Pose random_pose(std::mt19937_64& rng, double position_range = 1.0);
// Joints drawn uniformly within the chain's limits.
Eigen::VectorXd random_within(const core::KinematicChain& chain, std::mt19937_64& rng);

// Runs `fn`, expects core::InputError whose message contains every fragment.
void expect_input_error(const std::function<void()>& fn,
                        std::initializer_list<std::string> fragments);

}  // namespace hila::test
