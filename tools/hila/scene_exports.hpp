#pragma once

#include <string>
#include <vector>

#include "hila/online/scene.hpp"
#include "hila/viz/plan_file.hpp"
#include "io_checks.hpp"

namespace hila::tools {

// A plan to export with what it was planned in: its scene and the files behind it.
struct PlanScene {
  std::string database;
  viz::PlanFile plan;
  std::string scene_file;         // the one given, else the one the plan names
  online::SceneFiles files;       // the scene's cell and product files
  std::vector<InputFile> inputs;  // every file read: database, plan, scene, cell, product
};

// Reads the plan file and the scene's file names (`scene` empty: the plan's scene); throws
// core::InputError for a plan or scene file that cannot be read.
PlanScene read_plan_scene(const std::string& database, const std::string& plan_file,
                          const std::string& scene);

// The plan animated as a .glb (viz::plan_glb) from the scene's start. The database must have been
// built from the scene's cell and product, the plan for its product (core::InputError if not).
std::string plan_scene_glb(const PlanScene& plan);

}  // namespace hila::tools
