#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "hila/core/product.hpp"

namespace hila::tools {

// Each subcommand registers its options on `app` and returns the action to run when chosen.
// Actions return the process exit status.
using Action = std::function<int()>;

void add_cell_command(CLI::App& app, Action& action);
void add_human_command(CLI::App& app, Action& action);
void add_mesh_command(CLI::App& app, Action& action);
void add_product_command(CLI::App& app, Action& action);
void add_build_command(CLI::App& app, Action& action);
void add_inspect_command(CLI::App& app, Action& action);
void add_report_command(CLI::App& app, Action& action);
void add_plan_command(CLI::App& app, Action& action);
void add_export_command(CLI::App& app, Action& action);

std::string default_cell_path();
// Runs the build's mesh checks (closed, manifold, no degenerate faces, ...) on every part of the
// product; a mesh the build would refuse throws core::InputError naming the mesh file, the
// part and the product file. Quick (no sampling): the build and `product check` run it first.
void check_part_meshes(const core::ProductSpec& product);
std::string default_product_path();
// The nominal scene bundled with hila for the product named `product` (the cabinet's:
// meshes/cabinet/scene.yaml, beside its product file); a path that does not exist when hila has
// none for it, "" for a name that is no plain folder name.
std::string default_scene_path(const std::string& product);

}  // namespace hila::tools
