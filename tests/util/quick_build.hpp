#pragma once

#include <cstdint>

#include "hila/offline/build.hpp"

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

}  // namespace hila::test
