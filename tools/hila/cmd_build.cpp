#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "hila/core/cell.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/product.hpp"
#include "hila/db/database.hpp"
#include "hila/db/provenance.hpp"
#include "hila/offline/build.hpp"
#include "io_checks.hpp"
#include "option_checks.hpp"

namespace hila::tools {

namespace {
// Upper bounds of the build's counts: far above any useful value, low enough that a typo (an
// extra digit, a negative number read as huge) is refused instead of exhausting memory or time.
constexpr long long kMaxComfortSamples = 1'000'000'000;
constexpr long long kMaxCandidatesOrNodes = 1'000'000;
constexpr long long kMaxJobs = 1024;

struct BuildOptions {
  std::string product_file;
  std::string output;
  std::string cell_file;
  std::uint64_t seed = 1;
  int jobs = 1;
  long comfort_samples = core::ComfortMapSettings{}.samples;
  int handover_candidates = offline::HandoverSettings{}.candidates;
  int natural_candidates = offline::HandoverSettings{}.natural_candidates;
  double natural_max_rotation = offline::HandoverSettings{}.natural_max_rotation_deg;
  double comfort_threshold = offline::HandoverSettings{}.comfort_threshold;
  double comfort_floor = offline::HandoverSettings{}.comfort_floor;
  std::string bodies;
  int roadmap_nodes = offline::RoadmapSettings{}.nodes;
  bool if_outdated = false;
};

// Why the database at `path` is not what this build would write ("" when it is): missing,
// unreadable, another schema or hila version, other cell or product files, other settings or
// seed.
std::string why_outdated(const std::string& path, const std::string& cell_file,
                         const std::string& product_file, const offline::BuildSettings& settings) {
  if (!std::filesystem::exists(path)) return "it does not exist";
  // Unreadable inputs are the build's own error (exit 2), not a reason to rebuild.
  const std::string cell_hash = db::cell_hash(core::Cell::load(cell_file)->spec());
  const std::string product_hash = db::product_hash(core::load_product(product_file));
  db::Meta meta;
  try {
    meta = db::Database::open(path).meta();
  } catch (const std::exception& e) {
    return std::string("it cannot be used: ") + e.what();
  }
  if (meta.hila_version != HILA_VERSION) {
    return "it was built by hila " + meta.hila_version + ", this is " + HILA_VERSION;
  }
  if (meta.cell_hash != cell_hash) return "the cell (" + cell_file + " or its URDFs) changed";
  if (meta.product_hash != product_hash) {
    return "the product (" + product_file + " or its meshes) changed";
  }
  if (meta.settings_hash != offline::settings_hash(settings)) return "the build settings differ";
  if (meta.seed != settings.seed) return "the seed differs";
  return "";
}

int run_build(const BuildOptions& opt) {
  std::vector<InputFile> inputs = product_input_files(opt.product_file);
  for (auto&& file : cell_input_files(opt.cell_file)) inputs.push_back(file);
  check_output_path("-o", opt.output, inputs);
  // A mesh the build would refuse, refused before the comfort maps and roadmaps.
  const core::ProductSpec product = core::load_product(opt.product_file);
  check_part_meshes(product);
  // What `product check` and `cell check` report as failed checks (exit 1), refused before the
  // minutes of work: with them every board ends "no goal reachable".
  const auto cell = core::Cell::load(opt.cell_file);
  const std::vector<std::string> overlaps = colliding_parts(*cell, product, true);
  if (!overlaps.empty()) {
    std::string pairs;
    for (const auto& p : overlaps) pairs += (pairs.empty() ? "" : ", ") + p;
    std::cerr << "hila: " << opt.product_file << ": the finished assembly interpenetrates ("
              << pairs << "); nothing built (hila product check " << opt.product_file << ")\n";
    return 1;
  }
  const std::string home = home_collision(*cell);
  if (!home.empty()) {
    std::cerr << "hila: " << opt.cell_file << ": the robot at home is in collision (" << home
              << "); nothing built (hila cell check " << opt.cell_file << ")\n";
    return 1;
  }
  offline::BuildSettings settings;
  settings.seed = opt.seed;
  settings.jobs = opt.jobs;
  settings.comfort.samples = opt.comfort_samples;
  settings.handover.candidates = opt.handover_candidates;
  settings.handover.natural_candidates = opt.natural_candidates;
  settings.handover.natural_max_rotation_deg = opt.natural_max_rotation;
  settings.handover.comfort_threshold = opt.comfort_threshold;
  settings.handover.comfort_floor = opt.comfort_floor;
  settings.roadmap.nodes = opt.roadmap_nodes;
  if (!opt.bodies.empty())
    settings.human_bodies = offline::parse_human_bodies(opt.bodies, "--bodies");
  if (opt.if_outdated) {
    const std::string why = why_outdated(opt.output, opt.cell_file, opt.product_file, settings);
    if (why.empty()) {
      // A build killed while writing left its temporary beside the output; the writer removes
      // such files when it starts, and a kept output starts no writer.
      remove_dead_temporaries(opt.output);
      std::cout << opt.output
                << " is up to date (same hila version, cell, product, settings and seed): kept\n";
      return 0;
    }
    std::cout << "building " << opt.output << ": " << why << "\n";
  }
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
    std::cout << "  comfort map, " << m.arm << " arm: " << m.filled_bins
              << " bins filled, coverage " << std::setprecision(1) << 100.0 * m.coverage << " % ("
              << std::setprecision(2) << m.seconds << " s)\n";
  }
  std::cout << "  handover goals (Eq. 1 candidates, S comfortable"
            << (settings.human_bodies.empty() ? "" : " for one worker of the set at least")
            << ", 𝕊 with a shared grasp; goal Q the cell human's):\n";
  std::cout
      << "  #  part           candidates    |S|    |𝕊|  rr poses  goal Q  distance m   time s\n";
  for (const auto& p : summary.parts) {
    std::cout << "  " << p.order << "  " << std::left << std::setw(14) << p.name << std::right
              << std::setw(11) << p.handover_candidates << std::setw(7) << p.comfortable
              << std::setw(7) << p.goals << std::setw(10) << p.robot_handovers;
    if (p.goals > 0) {
      std::cout << std::setw(8) << std::setprecision(3) << p.goal_quality << std::setw(12)
                << p.goal_distance;
    } else {
      std::cout << std::setw(8) << "-" << std::setw(12) << "-";
    }
    std::cout << std::setw(9) << std::setprecision(2) << p.handover_seconds
              << (p.two_hands ? "  (two hands)" : "") << "\n";
  }
  for (const auto& m : summary.roadmaps) {
    std::cout << "  roadmap, " << m.arm << " arm: " << m.nodes << " nodes, " << m.edges
              << " edges (" << std::setprecision(1) << m.seconds << " s)\n";
  }
  std::cout
      << "  regrasp graph (first goals' shared grasps; transfers = receiving arm, robot-robot "
         "-> robot-human, within the grasp's filter; exchanges = robot-robot poses the suction "
         "arm's "
         "transfer reaches, of those examined):\n";
  std::cout
      << "  #  part           filters  nodes  edges  transfers  goals served  first  exchanges  "
         "time s\n";
  for (const auto& p : summary.parts) {
    std::cout << "  " << p.order << "  " << std::left << std::setw(14) << p.name << std::right
              << std::setw(8) << p.regrasp_filters << std::setw(7) << p.regrasp_nodes
              << std::setw(7) << p.regrasp_edges << std::setw(6) << p.transfers_connected << "/"
              << std::left << std::setw(4) << p.transfers << std::right << std::setw(9)
              << p.goals_served << "/" << std::left << std::setw(4) << p.goals_considered
              << std::right << std::setw(5);
    if (p.first_served_rank >= 0) {
      std::cout << p.first_served_rank;
    } else {
      std::cout << "-";
    }
    std::cout << std::setw(7) << p.exchanges_connected << "/" << std::left << std::setw(3)
              << p.exchanges_examined << std::right << std::setw(8) << std::setprecision(2)
              << p.regrasp_seconds << "\n";
  }
  if (const auto& relay = summary.tool_relay.handle) {
    const Eigen::Vector3d at = relay->translation();
    std::cout << "  suction tool relay: (" << std::fixed << std::setprecision(3) << at.x() << ", "
              << at.y() << ", " << at.z() << ") m, both arms take the tool there (of "
              << summary.tool_relay.places << " places, " << summary.tool_relay.clear
              << " clear of the parts)\n";
  }
  if (!settings.human_bodies.empty()) {
    std::cout << "  body set: " << offline::format_human_bodies(settings.human_bodies) << "\n";
    std::cout << "    goals each body takes comfortably (of |𝕊|):\n";
    for (const auto& p : summary.parts) {
      std::cout << "    " << std::left << std::setw(14) << p.name << std::right;
      for (std::size_t b = 0; b < p.goals_per_body.size(); ++b) {
        std::cout << "  " << core::human_body_label(settings.human_bodies[b]) << " "
                  << p.goals_per_body[b];
      }
      std::cout << "  (of " << p.goals << ")\n";
    }
  }
  const auto failed = summary.failed_parts();
  for (const auto& p : summary.parts) {
    if (!p.handover_failure.empty()) {
      std::cerr << "hila: " << p.name << ": no handover goal: " << p.handover_failure << "\n";
    }
    if (!p.regrasp_failure.empty()) {
      std::cerr << "hila: " << p.name
                << ": no goal reachable in the roadmaps: " << p.regrasp_failure << "\n";
    }
  }
  if (!failed.empty()) {
    std::cerr << "hila: " << failed.size() << " of " << summary.parts.size()
              << " boards have no handover goal; the database was written with the reasons "
                 "(hila inspect "
              << summary.output << " handover --part NAME)\n";
    return 1;
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
      ->capture_default_str()
      ->check(uint64_any());
  build
      ->add_option("--comfort-samples", opt->comfort_samples,
                   "arm postures sampled per human comfort map")
      ->capture_default_str()
      ->check(int_in(1, kMaxComfortSamples));
  build
      ->add_option("--handover-candidates", opt->handover_candidates,
                   "Eq. 1 candidate poses per board")
      ->capture_default_str()
      ->check(int_in(1, kMaxCandidatesOrNodes));
  build
      ->add_option("--natural-candidates", opt->natural_candidates,
                   "candidates with the part's centre between a worker's hip and shoulder height, "
                   "per worker whose band the part's fitted centre lies outside of (0: none)")
      ->capture_default_str()
      ->check(int_in(0, kMaxCandidatesOrNodes));
  build
      ->add_option("--natural-max-rotation", opt->natural_max_rotation,
                   "deg: the natural band candidates' orientation within this of the fitted one")
      ->capture_default_str()
      ->check(number_in(1.0, 180.0));
  build
      ->add_option("--comfort-threshold", opt->comfort_threshold,
                   "least human comfort Q of a handover goal (S)")
      ->capture_default_str()
      ->check(number_in(0.0, 1.0));
  build
      ->add_option("--comfort-floor", opt->comfort_floor,
                   "least comfort Q of the goals of a part with none above --comfort-threshold "
                   "(the threshold itself: none below it)")
      ->capture_default_str()
      ->check(number_in(0.0, 1.0));
  build->add_option(
      "--bodies", opt->bodies,
      "a worker set besides the cell's human: goals are built for each body and record which "
      "bodies take them comfortably, e.g. 1.50:female,1.595:female,1.82:male,1.95:male");
  build
      ->add_option("--roadmap-nodes", opt->roadmap_nodes,
                   "PRM milestones per robot arm roadmap (fewer: a faster, sparser build)")
      ->capture_default_str()
      ->check(int_in(1, kMaxCandidatesOrNodes));
  build->add_flag("--if-outdated", opt->if_outdated,
                  "keep the output when it was built by this hila from the same cell, product, "
                  "settings and seed; build it otherwise");
  build->add_option("--jobs", opt->jobs, "worker threads over parts")
      ->capture_default_str()
      ->check(int_in(1, kMaxJobs));
  build->callback([opt, &action] { action = [opt] { return run_build(*opt); }; });
}

}  // namespace hila::tools
