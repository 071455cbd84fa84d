#include <memory>
#include <string>
#include <utility>

#include "cmd_report_html.hpp"
#include "commands.hpp"
#include "hila/core/error.hpp"
#include "report_ergonomics.hpp"

namespace hila::tools {

namespace {

struct ReportOptions {
  std::string what = "ergonomics";
  ReportErgonomicsOptions ergonomics;  // `report ergonomics`
  ReportHtmlOptions html;              // `report html`
};

int run_report(ReportOptions opt) {
  if (opt.what == "html") {
    if (opt.html.output.empty()) {
      throw core::InputError("command line", "report html", "-o report.html", "none");
    }
    if (opt.ergonomics.workers_given) {
      throw core::InputError("command line", "--workers", "no --workers with report html",
                             "'" + opt.ergonomics.workers + "'");
    }
    opt.html.database = opt.ergonomics.database;
    return run_report_html(opt.html);
  }
  if (opt.what != "ergonomics") {
    throw core::InputError("command line", "report", "ergonomics or html", "'" + opt.what + "'");
  }
  for (const auto& [given, option] :
       {std::pair{opt.html.cell_file, "--cell"}, std::pair{opt.html.product_file, "--product"},
        std::pair{opt.html.plan_file, "--plan"}, std::pair{opt.html.output, "-o"}}) {
    if (!given.empty()) {
      throw core::InputError("command line", option,
                             std::string("no ") + option +
                                 " with report ergonomics (an option of report html; the "
                                 "report reads the cell and product the scene names)",
                             "'" + given + "'");
    }
  }
  opt.ergonomics.scene = opt.html.scene;
  return run_report_ergonomics(opt.ergonomics);
}

}  // namespace

void add_report_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<ReportOptions>();
  auto* report = app.add_subcommand("report", "Reports computed from a product database");
  report
      ->add_option("what", opt->what,
                   "ergonomics (a table), or html (a page with a 3D viewer and charts, -o)")
      ->required();
  report->add_option("database", opt->ergonomics.database, "database file")->required();
  report->add_flag("--json", opt->ergonomics.json, "ergonomics: print JSON");
  CLI::Option* workers =
      report->add_option("--workers", opt->ergonomics.workers,
                         "ergonomics: the workers, STATURE[:SEX] items such as "
                         "1.50:female,1.595:female,1.722:male,1.82:male,1.95:male (default: the "
                         "database's worker set, else the scene's worker, else the cell's human)");
  report->add_option("--plan", opt->html.plan_file, "html: a plan file (hila plan -o) to animate");
  report->add_option("--scene", opt->html.scene,
                     "ergonomics: the scene the boards are planned in (default: the bundled scene "
                     "of the database's product); html: the plan's scene (default: the plan's)");
  report->add_option("--cell", opt->html.cell_file,
                     "html without --plan: the database's cell YAML (default: the bundled)");
  report->add_option("--product", opt->html.product_file,
                     "html without --plan: the database's product YAML (default: the cabinet)");
  report->add_option("-o,--output", opt->html.output, "html: the page to write");
  report->add_option("--three-js", opt->html.three_dir, "html: three.js folder (libjs-three)")
      ->capture_default_str();
  report->callback([opt, workers, &action] {
    opt->ergonomics.workers_given = workers->count() > 0;
    action = [opt] { return run_report(*opt); };
  });
}

}  // namespace hila::tools
