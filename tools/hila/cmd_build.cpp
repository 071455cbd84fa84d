#include <unistd.h>

#include <cstdio>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "hila/offline/build.hpp"

namespace hila::tools {

namespace {
struct BuildOptions {
  std::string product_file;
  std::string output;
  std::string cell_file;
  std::uint64_t seed = 1;
  int jobs = 1;
  long comfort_samples = offline::ComfortMapSettings{}.samples;
};

int run_build(const BuildOptions& opt) {
  offline::BuildSettings settings;
  settings.seed = opt.seed;
  settings.jobs = opt.jobs;
  settings.comfort.samples = opt.comfort_samples;
  // Progress only for a person watching a terminal; logs and pipes stay clean.
  const bool terminal = isatty(fileno(stderr)) != 0;
  offline::BuildProgress progress;
  if (terminal) {
    progress = [](const std::string& part, int done, int total) {
      std::cerr << "\r\033[K[" << done << "/" << total << "] " << part << std::flush;
      if (done == total) std::cerr << "\n";
    };
  }
  const auto summary =
      offline::build_database(opt.product_file, opt.cell_file, opt.output, settings, progress);
  std::cout << "built " << summary.output << " in " << std::fixed << std::setprecision(2)
            << summary.seconds << " s\n";
  std::cout << "  #  part            mass  robot  suction  human (1-hand)  theta_c deg\n";
  for (const auto& p : summary.parts) {
    std::cout << "  " << p.order << "  " << std::left << std::setw(14) << p.name << std::right
              << std::setw(6) << std::setprecision(2) << p.mass << std::setw(7) << p.robot_grasps
              << std::setw(9) << p.suction_grasps << std::setw(7) << p.human_grasps << " ("
              << std::setw(4) << p.one_hand_grasps << ")   " << std::setprecision(0)
              << p.theta_c_min_deg << "-" << p.theta_c_max_deg << "\n";
  }
  for (const auto& m : summary.comfort_maps) {
    std::cout << "  comfort map, " << m.arm << " arm: " << m.filled_bins << " bins filled, coverage "
              << std::setprecision(1) << 100.0 * m.coverage << " % (" << std::setprecision(2)
              << m.seconds << " s)\n";
  }
  return 0;
}
}  // namespace

void add_build_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<BuildOptions>();
  opt->cell_file = default_cell_path();
  auto* build = app.add_subcommand("build", "Build a product database (grasps, slip limits, ...)");
  build->add_option("product", opt->product_file, "product YAML file")->required();
  build->add_option("-o,--output", opt->output, "database file to write (atomically)")->required();
  build->add_option("--cell", opt->cell_file, "cell YAML file")->capture_default_str();
  build->add_option("--seed", opt->seed, "random seed (same seed, same content)")
      ->capture_default_str();
  build->add_option("--comfort-samples", opt->comfort_samples,
                    "arm postures sampled per human comfort map")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  build->add_option("--jobs", opt->jobs, "worker threads over parts")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  build->callback([opt, &action] { action = [opt] { return run_build(*opt); }; });
}

}  // namespace hila::tools
