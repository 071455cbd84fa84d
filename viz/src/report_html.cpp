#include "hila/viz/report_html.hpp"

#include <iomanip>
#include <sstream>

#include "report_viewer.hpp"

namespace hila::viz {

namespace {

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// A script's text inlined in <script>: "</script" inside it would end the element early.
std::string script(const std::string& js) {
  std::string out;
  out.reserve(js.size() + 32);
  out += "<script>";
  for (std::size_t i = 0; i < js.size(); ++i) {
    if (js[i] == '<' && js.compare(i, 8, "</script") == 0) {
      out += "<\\/";
      i += 1;
      continue;
    }
    out += js[i];
  }
  return out + "</script>\n";
}

std::string fixed(double v, int decimals) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

constexpr const char* kStyle = R"CSS(
body { font: 14px/1.4 system-ui, sans-serif; margin: 0 auto; max-width: 1100px; padding: 0 16px;
       color: #1d2125; }
h1 { font-size: 20px; margin: 12px 0 4px; }
h2 { font-size: 16px; margin: 20px 0 6px; }
p.meta { margin: 0 0 8px; color: #555; }
#viewer { width: 100%; height: 560px; background: #eef1f4; position: relative; }
#viewer canvas { width: 100%; height: 100%; display: block; }
#controls { display: flex; gap: 10px; align-items: center; margin: 6px 0; }
#controls input[type=range] { flex: 1; }
#errors { color: #b00020; white-space: pre-wrap; }
svg.chart { max-width: 100%; height: auto; font-size: 12px; }
svg.chart .axis { stroke: #333; }
svg.chart .grid { stroke: #ddd; }
svg.chart .board { stroke: #999; stroke-dasharray: 3 3; }
svg.chart .note, svg.chart .axis-label { fill: #555; }
svg.chart .small { font-size: 10px; }
table { border-collapse: collapse; font-size: 13px; }
td, th { padding: 2px 8px; text-align: right; border-bottom: 1px solid #ddd; }
td:first-child, th:first-child, td.why { text-align: left; }
)CSS";

std::string parts_table(const std::vector<ReportPart>& parts) {
  std::string s =
      "<table><tr><th>part</th><th>grasps</th><th>candidates</th><th>|S|</th><th>|𝕊|</th>"
      "<th>first goal's Q</th><th>why no goal</th></tr>\n";
  for (const ReportPart& p : parts) {
    s += "<tr><td>" + std::to_string(p.order) + " " + escape(p.name) + "</td><td>" +
         std::to_string(p.theta_c_deg.size()) + "</td>";
    if (p.has_stage) {
      s += "<td>" + std::to_string(p.candidates) + "</td><td>" + std::to_string(p.comfortable) +
           "</td><td>" + std::to_string(p.goals) + "</td>";
    } else {
      s += "<td>-</td><td>-</td><td>-</td>";
    }
    s += "<td>" + (p.goal_quality.empty() ? "-" : fixed(p.goal_quality.front(), 3)) +
         "</td><td class=\"why\">" + escape(p.failure) + "</td></tr>\n";
  }
  return s + "</table>\n";
}

std::string plan_table(const PlanFile& plan) {
  std::string s = "<table><tr><th>board</th><th>status</th><th>steps</th><th>motion s</th></tr>\n";
  for (const PlanFileBoard& b : plan.boards) {
    s += "<tr><td>" + escape(b.board) + "</td><td class=\"why\">" + escape(b.status) + "</td><td>" +
         std::to_string(b.steps.size()) + "</td><td>" + (b.solved() ? fixed(b.duration, 2) : "-") +
         "</td></tr>\n";
  }
  return s + "</table>\n";
}

}  // namespace

std::string base64(const std::string& bytes) {
  static constexpr char kDigits[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16 |
                       static_cast<unsigned char>(bytes[i + 1]) << 8 |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kDigits[v >> 18 & 63];
    out += kDigits[v >> 12 & 63];
    out += kDigits[v >> 6 & 63];
    out += kDigits[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const unsigned v = static_cast<unsigned char>(bytes[i]) << 16 |
                       (two ? static_cast<unsigned char>(bytes[i + 1]) << 8 : 0u);
    out += kDigits[v >> 18 & 63];
    out += kDigits[v >> 12 & 63];
    out += two ? kDigits[v >> 6 & 63] : '=';
    out += '=';
  }
  return out;
}

std::string report_html(const ReportInput& input) {
  std::string page;
  page +=
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>hila report: " +
      escape(input.product) + "</title>\n<style>" + kStyle + "</style>\n";
  page += script(report_error_script());
  page += "</head><body>\n<h1>hila report: " + escape(input.product) + "</h1>\n";
  page += "<p class=\"meta\">database " + escape(input.database);
  if (input.plan != nullptr) page += ", plan " + escape(input.plan->file);
  page += ". Drag to turn the view, scroll to zoom, right-drag to pan.</p>\n";
  page += "<pre id=\"errors\" hidden></pre>\n<div id=\"viewer\"></div>\n";
  page +=
      "<div id=\"controls\"><select id=\"scene\" aria-label=\"scene\"></select>"
      "<select id=\"clip\" aria-label=\"animation\" hidden></select>"
      "<button id=\"play\">pause</button>"
      "<input id=\"time\" type=\"range\" min=\"0\" max=\"0\" step=\"0.01\" value=\"0\" "
      "aria-label=\"time\"><span id=\"time-text\"></span>"
      "<select id=\"speed\" aria-label=\"speed\"><option value=\"1\">1×</option>"
      "<option value=\"2\">2×</option><option value=\"5\" selected>5×</option>"
      "<option value=\"10\">10×</option></select></div>\n";
  if (input.plan != nullptr) {
    page += "<h2>Plan: steps per arm</h2>\n" + timeline_svg(*input.plan) + plan_table(*input.plan);
  }
  page += "<h2>Parts</h2>\n" + parts_table(input.parts);
  page += "<h2>θc per robot grasp</h2>\n" + theta_c_svg(input.parts);
  page += "<h2>Handover candidates, |S| and |𝕊|</h2>\n" + stages_svg(input.parts);
  page += "<h2>Human comfort Q of the ranked goals</h2>\n" + goal_quality_svg(input.parts);
  if (!input.ergonomics.empty()) {
    page += "<h2>Ergonomics: hila against the table and the human alone</h2>\n" +
            ergonomics_svg(input.ergonomics);
  }
  for (std::size_t i = 0; i < input.scenes.size(); ++i) {
    page += "<script type=\"application/octet-stream\" class=\"scene\" data-title=\"" +
            escape(input.scenes[i].title) + "\">" + base64(input.scenes[i].glb) + "</script>\n";
  }
  page += script(input.three.three);
  page += script(input.three.gltf_loader);
  page += script(input.three.orbit_controls);
  page += script(report_viewer_script());
  return page + "</body></html>\n";
}

}  // namespace hila::viz
