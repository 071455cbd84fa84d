#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <string>

#include "hila/offline/build.hpp"
#include "util/test_util.hpp"

namespace hila::test {

// A complete cabinet build in seconds: few samples and candidates, a 300-milestone roadmap.
// Header-only: only tests that link hila::offline include it.
inline offline::BuildSettings quick_build_settings(std::uint64_t seed = 7, int jobs = 1) {
  offline::BuildSettings s;
  s.seed = seed;
  s.jobs = jobs;
  s.robot.samples = 500;
  s.human.samples = 300;
  s.comfort.spacing = 0.06;
  s.comfort.orientations = 100;
  s.comfort.samples = 20000;
  s.handover.candidates = 60;
  s.handover.max_candidates = 60;
  s.handover.rr_poses = 6;
  s.handover.human_ik_goals = 2;
  s.ergonomics.flexion_step_deg = 15.0;
  s.roadmap.nodes = 300;
  return s;
}

// The quick build with comfort maps and goal candidates dense enough that every board has goals
// a human standing a few centimetres off the cell's stance still takes.
inline offline::BuildSettings dense_quick_build_settings(std::uint64_t seed = 7, int jobs = 2) {
  offline::BuildSettings s = quick_build_settings(seed, jobs);
  s.comfort.samples = 400000;
  s.handover.candidates = 200;
  s.handover.max_candidates = 400;
  return s;
}

// The cabinet database a test plans from: the one tools/test builds (HILA_TEST_DATABASE: the
// default build with 1200 roadmap nodes), else the cabinet built with `settings` into a folder of
// this process's own named after `name` (ctest runs each case in a process of its own, two at a
// time).
inline std::string cabinet_database(const std::string& name,
                                    const offline::BuildSettings& settings) {
  if (const char* given = std::getenv("HILA_TEST_DATABASE")) return given;
  const std::string out = temp_dir(name + "_" + std::to_string(::getpid())) + "/cabinet.hila";
  offline::build_database(product_path(), cell_path(), out, settings);
  return out;
}

}  // namespace hila::test
