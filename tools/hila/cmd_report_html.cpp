#include "cmd_report_html.hpp"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "db_scenes.hpp"
#include "hila/core/error.hpp"
#include "hila/db/database.hpp"
#include "hila/viz/cell_export.hpp"
#include "hila/viz/report_html.hpp"
#include "io_checks.hpp"
#include "scene_exports.hpp"

namespace hila::tools {

namespace {

// Goals shown per part; gripper grasps drawn per part (a thousand per part would make the page
// about 20 MB: `hila export grasps` writes them all).
constexpr int kReportGoals = 5;
constexpr std::size_t kReportGrasps = 120;

// At most `count` of the view's gripper grasps, evenly spread over their θc order (the lowest and
// the highest kept).
void thin_grasps(viz::GraspsView& view, std::size_t count) {
  auto& grasps = view.gripper;
  if (grasps.size() <= count || count < 2) return;
  std::stable_sort(grasps.begin(), grasps.end(),
                   [](const auto& a, const auto& b) { return a.theta_c_deg < b.theta_c_deg; });
  std::vector<viz::GripperGraspView> kept;
  for (std::size_t i = 0; i < count; ++i)
    kept.push_back(grasps[i * (grasps.size() - 1) / (count - 1)]);
  grasps = std::move(kept);
}

// three.js's files under its folder (libjs-three's layout; the npm package's is the same).
constexpr const char* kThreeFiles[] = {"build/three.min.js", "examples/js/loaders/GLTFLoader.js",
                                       "examples/js/controls/OrbitControls.js"};

std::string read_text(const std::string& path, const std::string& role) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || text.str().empty()) {
    throw core::InputError(path, role, "a readable, non-empty file (tools/setup installs it)",
                           "cannot read it");
  }
  return text.str();
}

std::vector<viz::ReportPart> report_parts(const db::Database& database) {
  std::vector<viz::ReportPart> parts;
  for (const db::PartRecord& record : database.parts()) {
    viz::ReportPart p;
    p.name = record.name;
    p.order = record.assembly_order;
    for (const auto& g : database.robot_grasps(record.id)) p.theta_c_deg.push_back(g.theta_c_deg);
    if (const db::HandoverStageRecord* stage = database.handover_stage(record.id)) {
      p.has_stage = true;
      p.candidates = stage->candidates;
      p.comfortable = stage->comfortable;
      p.goals = stage->goals;
      p.failure = stage->failure;
    }
    for (const auto& goal : database.handover_goals(record.id)) {
      p.goal_quality.push_back(goal.quality);
    }
    parts.push_back(std::move(p));
  }
  std::sort(parts.begin(), parts.end(),
            [](const viz::ReportPart& a, const viz::ReportPart& b) { return a.order < b.order; });
  return parts;
}

// What `hila report ergonomics` compares: every board by every method.
std::vector<viz::ReportErgonomics> report_ergonomics(const db::Database& database) {
  std::vector<viz::ReportErgonomics> rows;
  for (const db::PartRecord& part : database.parts()) {
    for (const db::ErgonomicsRecord& e : database.ergonomics(part.id)) {
      rows.push_back({part.name, part.assembly_order, e.method, e.reachable, e.torso_flexion_deg,
                      e.shoulder_elevated, e.reach, e.reorientation_deg, e.quality, e.arm});
    }
  }
  return rows;
}

// The cell with the product: tool on its stand, parts at their targets and initial poses.
std::string cell_scene_glb(const std::string& cell_file, const std::string& product_file) {
  const auto cell = core::Cell::load(cell_file);
  const core::ProductSpec product = core::load_product(product_file);
  viz::CellView view = viz::product_view(product);
  view.robot_q = cell->home_configuration(cell->spec().gripper.jaw_max);
  return viz::cell_glb(*cell, view);
}

}  // namespace

int run_report_html(const ReportHtmlOptions& opt) {
  const auto started = std::chrono::steady_clock::now();
  std::vector<InputFile> inputs{{opt.database, "the database"}};
  if (!opt.plan_file.empty()) inputs.push_back({opt.plan_file, "the plan file"});
  for (const char* f : kThreeFiles) inputs.push_back({opt.three_dir + "/" + f, "three.js"});
  check_output_path("-o", opt.output, inputs);

  std::optional<PlanScene> plan;
  if (!opt.plan_file.empty()) {
    plan = read_plan_scene(opt.database, opt.plan_file, opt.scene);
    inputs.insert(inputs.end(), plan->inputs.begin(), plan->inputs.end());
    check_output_path("-o", opt.output, inputs);
  }
  // The cell and product the plan's scene names, else the ones given (default: the bundled).
  const std::string cell_file =
      plan ? plan->files.cell : (opt.cell_file.empty() ? default_cell_path() : opt.cell_file);
  const std::string product_file =
      plan ? plan->files.product
           : (opt.product_file.empty() ? default_product_path() : opt.product_file);
  for (auto&& more : {cell_input_files(cell_file), product_input_files(product_file)}) {
    inputs.insert(inputs.end(), more.begin(), more.end());
  }
  check_output_path("-o", opt.output, inputs);

  // Checks that the database was built from these files (with a plan, the scene's).
  const CheckedDatabase checked = open_checked_database(opt.database, cell_file, product_file);
  const db::Database& database = checked.database;

  viz::ReportInput input;
  input.product = database.meta().product_name;
  input.database = opt.database;
  input.parts = report_parts(database);
  input.ergonomics = report_ergonomics(database);
  input.three = {read_text(opt.three_dir + "/" + kThreeFiles[0], "three.js"),
                 read_text(opt.three_dir + "/" + kThreeFiles[1], "three.js GLTFLoader"),
                 read_text(opt.three_dir + "/" + kThreeFiles[2], "three.js OrbitControls")};
  input.scenes.push_back({"cell: " + input.product + " at its targets and on the table",
                          cell_scene_glb(cell_file, product_file)});
  // Each part's grasps and its best goals (as `export grasps` and `export goals` write them).
  for (const viz::ReportPart& part : input.parts) {
    viz::GraspsView grasps = grasps_view(checked, part.name, "");
    const std::size_t all = grasps.gripper.size();
    thin_grasps(grasps, kReportGrasps);
    input.scenes.push_back({"grasps: " + part.name + " (" + std::to_string(grasps.gripper.size()) +
                                " of " + std::to_string(all) +
                                " gripper grasps by θc, the suction cups by margin)",
                            viz::grasps_glb(*checked.cell, grasps)});
    if (!part.goal_quality.empty()) {
      input.scenes.push_back(
          {"goals: " + part.name + " (the best " +
               std::to_string(
                   std::min(static_cast<std::size_t>(kReportGoals), part.goal_quality.size())) +
               ", by Q)",
           viz::goals_glb(*checked.cell, goals_view(checked, part.name, kReportGoals))});
    }
  }
  if (plan) {
    input.scenes.push_back({"plan: " + opt.plan_file, plan_scene_glb(*plan)});
    input.plan = &plan->plan;
  }
  const std::string page = viz::report_html(input);
  write_file_atomically(opt.output, page);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  std::cout << "wrote " << opt.output << " (" << page.size() << " bytes, " << input.scenes.size()
            << " scene(s), " << seconds << " s); open it in a browser: file://"
            << std::filesystem::absolute(opt.output).string() << "\n";
  return 0;
}

}  // namespace hila::tools
