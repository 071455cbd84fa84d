#pragma once

#include <string>

namespace hila::tools {

struct ReportErgonomicsOptions {
  std::string database;
  // The scene the boards are planned in (docs/scene.md); empty: the bundled scene of the
  // database's product (meshes/PRODUCT/scene.yaml).
  std::string scene;
  // "STATURE[:SEX],..." (offline::parse_human_bodies) when workers_given; otherwise the
  // database's worker set (meta.human_bodies), else the scene's worker, else the cell's human.
  std::string workers;
  bool workers_given = false;  // --workers was on the command line (perhaps as '')
  bool json = false;
};

// `hila report ergonomics`: per worker and board, the posture hila's planned handover leaves the
// worker in against the board laid on the table and the worker alone fetching it from the stack
// (docs/cli.md). Returns the exit status; throws core::InputError for bad input.
int run_report_ergonomics(const ReportErgonomicsOptions& options);

}  // namespace hila::tools
