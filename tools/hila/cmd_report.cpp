#include <algorithm>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>

#include "cmd_report_html.hpp"
#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/db/database.hpp"

namespace hila::tools {

namespace {

// EAWS (the paper's Table 2): the torso counts as bent forward from 20 degrees.
constexpr double kBentForwardDeg = 20.0;
constexpr const char* kMethods[] = {"hila", "table", "alone"};

struct ReportOptions {
  std::string what = "ergonomics";
  std::string database;
  bool json = false;
  ReportHtmlOptions html;  // `report html`
};

struct Totals {
  int boards = 0;
  int unreachable = 0;
  int bent = 0;
  int shoulder = 0;
  double reach = 0.0;
  double reorientation = 0.0;
  double quality = 0.0;
};

// Compares a count where fewer is better.
std::string fewer(int ours, int theirs, const char* none_left) {
  if (ours == 0 && theirs > 0) return none_left;
  if (ours < theirs) return "decreased";
  if (ours > theirs) return "increased";
  return "the same";
}

std::string compare(double ours, double theirs, double tolerance, const char* better,
                    const char* worse) {
  if (ours < theirs - tolerance) return better;
  if (ours > theirs + tolerance) return worse;
  return "the same";
}

nlohmann::json ergonomics_json(const db::Database& database) {
  nlohmann::json boards = nlohmann::json::array();
  std::map<std::string, Totals> totals;
  for (const auto& part : database.parts()) {
    nlohmann::json row = {{"part", part.name}, {"order", part.assembly_order}};
    for (const auto& e : database.ergonomics(part.id)) {
      Totals& t = totals[e.method];
      ++t.boards;
      nlohmann::json m = {{"reachable", e.reachable}};
      if (e.reachable) {
        const bool bent = e.torso_flexion_deg >= kBentForwardDeg;
        t.bent += bent ? 1 : 0;
        t.shoulder += e.shoulder_elevated ? 1 : 0;
        t.reach += e.reach;
        t.quality += e.quality;
        m.update({{"torso_flexion_deg", e.torso_flexion_deg},
                  {"bent_forward", bent},
                  {"shoulder_elevated", e.shoulder_elevated},
                  {"reach", e.reach},
                  {"quality", e.quality},
                  {"arm", e.arm}});
      } else {
        ++t.unreachable;
      }
      t.reorientation += e.reorientation_deg;
      m["reorientation_deg"] = e.reorientation_deg;
      row[e.method] = m;
    }
    boards.push_back(row);
  }
  nlohmann::json summary = nlohmann::json::object();
  for (const char* method : kMethods) {
    const Totals& t = totals[method];
    const int reached = t.boards - t.unreachable;
    summary[method] = {{"boards", t.boards},
                       {"unreachable", t.unreachable},
                       {"bent_forward", t.bent},
                       {"shoulder_elevated", t.shoulder},
                       {"mean_reach", reached ? t.reach / reached : 0.0},
                       {"mean_reorientation_deg", t.boards ? t.reorientation / t.boards : 0.0},
                       {"mean_quality", reached ? t.quality / reached : 0.0}};
  }
  nlohmann::json verdicts = nlohmann::json::object();
  for (const char* baseline : {"alone", "table"}) {
    const auto& a = summary["hila"];
    const auto& b = summary[baseline];
    verdicts[baseline] = {
        {"bent_forward",
         fewer(a["bent_forward"].get<int>(), b["bent_forward"].get<int>(), "eliminated")},
        {"shoulder_work",
         fewer(a["shoulder_elevated"].get<int>(), b["shoulder_elevated"].get<int>(), "eliminated")},
        {"reaching", compare(a["mean_reach"].get<double>(), b["mean_reach"].get<double>(), 0.02,
                             "shorter", "longer")},
        {"reorientation",
         compare(a["mean_reorientation_deg"].get<double>(),
                 b["mean_reorientation_deg"].get<double>(), 2.0, "decreased", "increased")},
        {"comfort", compare(-a["mean_quality"].get<double>(), -b["mean_quality"].get<double>(),
                            0.005, "more comfortable", "less comfortable")}};
  }
  return {{"database", database.path()},
          {"product", database.meta().product_name},
          {"bent_forward_from_deg", kBentForwardDeg},
          {"boards", boards},
          {"summary", summary},
          {"verdicts_hila_vs", verdicts}};
}

std::string cell_text(const nlohmann::json& m) {
  if (m.is_null()) return "-";  // not evaluated (no goal, no placement)
  if (!m["reachable"].get<bool>()) return "unreachable";
  std::ostringstream s;
  s << std::fixed << std::setprecision(0) << m["torso_flexion_deg"].get<double>() << "/"
    << (m["shoulder_elevated"].get<bool>() ? "up" : "--") << "/" << std::setprecision(2)
    << m["reach"].get<double>() << "/" << std::setprecision(0)
    << m["reorientation_deg"].get<double>() << "/" << std::setprecision(3)
    << m["quality"].get<double>();
  return s.str();
}

int run_report(ReportOptions opt) {
  if (opt.what == "html") {
    if (opt.html.output.empty()) {
      throw core::InputError("command line", "report html", "-o report.html", "none");
    }
    opt.html.database = opt.database;
    return run_report_html(opt.html);
  }
  if (opt.what != "ergonomics") {
    throw core::InputError("command line", "report", "ergonomics or html", "'" + opt.what + "'");
  }
  const db::Database database = db::Database::open(opt.database);
  const auto j = ergonomics_json(database);
  if (opt.json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::cout << "ergonomics of " << j["product"].get<std::string>()
            << ": (a) hila's handover, (b) laid flat on the table in front of the human, "
               "(c) the human alone from the stack\n"
            << "  per method: torso flexion deg / elbow at or above the shoulder / reach m / "
               "re-orientation left deg / comfort Q\n";
  std::cout << "  #  board          " << std::left << std::setw(27) << "(a) hila" << std::setw(27)
            << "(b) table"
            << "(c) alone" << std::right << "\n";
  for (const auto& b : j["boards"]) {
    std::cout << "  " << b["order"].get<int>() << "  " << std::left << std::setw(15)
              << b["part"].get<std::string>() << std::setw(27)
              << cell_text(b.value("hila", nlohmann::json())) << std::setw(27)
              << cell_text(b.value("table", nlohmann::json()))
              << cell_text(b.value("alone", nlohmann::json())) << std::right << "\n";
  }
  std::cout << "  boards bent forward (>= " << kBentForwardDeg << " deg): hila "
            << j["summary"]["hila"]["bent_forward"].get<int>() << ", table "
            << j["summary"]["table"]["bent_forward"].get<int>() << ", alone "
            << j["summary"]["alone"]["bent_forward"].get<int>() << "\n";
  for (const char* baseline : {"alone", "table"}) {
    const auto& v = j["verdicts_hila_vs"][baseline];
    std::cout << "  hila vs " << baseline << ": bent forward "
              << v["bent_forward"].get<std::string>() << "; shoulder work "
              << v["shoulder_work"].get<std::string>() << "; reaching "
              << v["reaching"].get<std::string>() << "; re-orientation "
              << v["reorientation"].get<std::string>() << "; comfort "
              << v["comfort"].get<std::string>() << "\n";
  }
  return 0;
}

}  // namespace

void add_report_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<ReportOptions>();
  auto* report = app.add_subcommand("report", "Reports computed from a product database");
  report
      ->add_option("what", opt->what,
                   "ergonomics (a table), or html (a page with a 3D viewer and charts, -o)")
      ->required();
  report->add_option("database", opt->database, "database file")->required();
  report->add_flag("--json", opt->json, "print JSON (ergonomics)");
  report->add_option("--plan", opt->html.plan_file, "html: a plan file (hila plan -o) to animate");
  report->add_option("--scene", opt->html.scene, "html: the plan's scene (default: the plan's)");
  report->add_option("--cell", opt->html.cell_file,
                     "html without --plan: the database's cell YAML (default: the bundled)");
  report->add_option("--product", opt->html.product_file,
                     "html without --plan: the database's product YAML (default: the cabinet)");
  report->add_option("-o,--output", opt->html.output, "html: the page to write");
  report->add_option("--three-js", opt->html.three_dir, "html: three.js folder (libjs-three)")
      ->capture_default_str();
  report->callback([opt, &action] { action = [opt] { return run_report(*opt); }; });
}

}  // namespace hila::tools
