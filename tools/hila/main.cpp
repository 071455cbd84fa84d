#include <CLI/CLI.hpp>
#include <exception>
#include <iostream>

#include "commands.hpp"
#include "hila/core/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hila: planner for human-robot collaborative assembly"};
  app.require_subcommand(1);
  hila::tools::Action action;
  hila::tools::add_cell_command(app, action);
  hila::tools::add_human_command(app, action);
  hila::tools::add_mesh_command(app, action);
  hila::tools::add_product_command(app, action);
  hila::tools::add_build_command(app, action);
  hila::tools::add_inspect_command(app, action);
  hila::tools::add_report_command(app, action);
  hila::tools::add_plan_command(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    return action ? action() : 0;
  } catch (const hila::core::InputError& e) {
    std::cerr << "hila: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "hila: internal error: " << e.what() << "\n";
    return 3;
  }
}
