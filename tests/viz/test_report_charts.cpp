#include <gtest/gtest.h>

#include <regex>

#include "hila/viz/report_html.hpp"

namespace hila::test {
namespace {

// Width of the bar whose tooltip starts with `tip` in the `chart`-th <svg> (0-based).
double bar_width(const std::string& svg, int chart, const std::string& tip) {
  std::size_t from = 0;
  for (int c = 0; c <= chart; ++c) from = svg.find("<svg", from + (c ? 1 : 0));
  const std::size_t to = svg.find("</svg>", from);
  const std::string one = svg.substr(from, to - from);
  const std::regex bar("<rect [^>]*width=\"([0-9.]+)\"[^>]*><title>" + tip);
  std::smatch m;
  if (!std::regex_search(one, m, bar)) return -1.0;
  return std::stod(m[1]);
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(ReportCharts, ErgonomicsBarsPerBoardAndMethodInThreeCharts) {
  std::vector<viz::ReportErgonomics> rows{
      {"plate", 1, "hila", true, 5.0, false, 0.40, 20.0, 0.12, "right"},
      {"plate", 1, "table", true, 10.0, true, 0.55, 90.0, 0.08, "right"},
      {"plate", 1, "alone", true, 30.0, false, 0.62, 180.0, 0.04, "left"},
      {"bar", 2, "hila", true, 0.0, false, 0.50, 10.0, 0.10, "right"},
      {"bar", 2, "table", false, 0.0, false, 0.0, 0.0, 0.0, ""},
      {"bar", 2, "alone", true, 25.0, true, 0.60, 90.0, 0.05, "left"},
  };
  const std::string svg = viz::ergonomics_svg(rows, 20.0);
  EXPECT_EQ(count(svg, "<svg"), 3);
  // A bar per reachable board and method in each chart; the unreachable one named instead.
  EXPECT_EQ(count(svg, "<title>plate, "), 3 * 3);
  EXPECT_EQ(count(svg, "<title>bar, "), 3 * 2);
  EXPECT_EQ(count(svg, "table: unreachable"), 3);
  // The bars' lengths follow the values: torso flexion, reach, re-orientation.
  EXPECT_LT(bar_width(svg, 0, "plate, hila"), bar_width(svg, 0, "plate, table"));
  EXPECT_NEAR(bar_width(svg, 0, "plate, alone"), 6.0 * bar_width(svg, 0, "plate, hila"), 0.1);
  EXPECT_LT(bar_width(svg, 1, "plate, hila"), bar_width(svg, 1, "plate, table"));
  EXPECT_NEAR(bar_width(svg, 2, "plate, alone"), 2.0 * bar_width(svg, 2, "bar, alone"), 0.1);
  // Counts as `hila report ergonomics` makes them: bent forward from 20 deg, shoulder work.
  EXPECT_NE(svg.find("alone: 2 bent forward, 1 with the elbow at or above the shoulder, 0 "
                     "unreachable"),
            std::string::npos);
  EXPECT_NE(svg.find("hila: 0 bent forward, 0 with the elbow"), std::string::npos);
  EXPECT_NE(svg.find("table: 0 bent forward, 1 with the elbow at or above the shoulder, 1 "
                     "unreachable"),
            std::string::npos);
  EXPECT_NE(svg.find("hila: mean 0.45 m, comfort Q mean 0.110"), std::string::npos);
}

TEST(ReportCharts, NoErgonomicsNoChartInThePage) {
  viz::ReportInput input;
  input.product = "p";
  const std::string without = viz::report_html(input);
  EXPECT_EQ(without.find("Ergonomics"), std::string::npos);
  input.ergonomics.push_back({"plate", 1, "hila", true, 5.0, false, 0.4, 20.0, 0.12, "right"});
  EXPECT_NE(viz::report_html(input).find("Ergonomics"), std::string::npos);
}

}  // namespace
}  // namespace hila::test
