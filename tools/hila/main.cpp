#include <CLI/CLI.hpp>
#include <algorithm>
#include <exception>
#include <iostream>

#include "commands.hpp"
#include "hila/core/error.hpp"

int main(int argc, char** argv) {
  CLI::App app{"hila: planner for human-robot collaborative assembly"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "hila " HILA_VERSION, "print the version and exit");
  hila::tools::Action action;
  hila::tools::add_cell_command(app, action);
  hila::tools::add_human_command(app, action);
  hila::tools::add_mesh_command(app, action);
  hila::tools::add_product_command(app, action);
  hila::tools::add_build_command(app, action);
  hila::tools::add_inspect_command(app, action);
  hila::tools::add_report_command(app, action);
  hila::tools::add_plan_command(app, action);
  hila::tools::add_export_command(app, action);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // Every command-line mistake is bad input (exit 2), on one line.
    std::string message = e.what();
    std::replace(message.begin(), message.end(), '\n', ' ');
    // CLI11 reports an unknown subcommand as a missing one: name it and list the known ones.
    if (app.get_subcommands().empty() && argc > 1 && argv[1][0] != '-') {
      std::string names;
      for (const CLI::App* sub : app.get_subcommands({})) {
        names += (names.empty() ? "" : ", ") + sub->get_name();
      }
      message = "expected a subcommand (" + names + "), got '" + argv[1] + "'";
    }
    // The help of the subcommand the mistake is in.
    std::string help = "hila";
    for (const CLI::App* sub = &app; !sub->get_subcommands().empty();) {
      sub = sub->get_subcommands().front();
      help += " " + sub->get_name();
    }
    std::cerr << "hila: error: " << message << " (" << help << " --help lists the options)\n";
    return 2;
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
