#pragma once

#include <string>

namespace hila::tools {

// Where Debian's libjs-three puts three.js (build/three.min.js, examples/js/...).
inline constexpr const char* kDefaultThreeJsDir = "/usr/share/javascript/three";

struct ReportHtmlOptions {
  std::string database;
  std::string plan_file;     // empty: the cell and the charts only
  std::string scene;         // empty: the scene the plan names
  std::string cell_file;     // without a plan: the database's cell (empty: the bundled one)
  std::string product_file;  // without a plan: the database's product (empty: the bundled one)
  std::string output;
  std::string three_dir = kDefaultThreeJsDir;
};

// `hila report html`: the database (and the plan) as one self-contained HTML page.
int run_report_html(const ReportHtmlOptions& opt);

}  // namespace hila::tools
