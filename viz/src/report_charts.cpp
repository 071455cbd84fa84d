#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <map>
#include <sstream>

#include "hila/viz/report_html.hpp"

namespace hila::viz {

namespace {

// Layout in CSS pixels: part names left of the plot, the axis below it.
constexpr double kLabelWidth = 150;
constexpr double kPlotWidth = 560;
constexpr double kRightMargin = 60;
constexpr double kTopMargin = 10;
constexpr double kAxisHeight = 36;
constexpr double kWidth = kLabelWidth + kPlotWidth + kRightMargin;

// Colours of the bars and dots (colour-blind safe, Okabe–Ito).
constexpr const char* kPalette[] = {"#0072B2", "#E69F00", "#009E73", "#CC79A7",
                                    "#56B4E9", "#D55E00", "#F0E442", "#000000"};

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

std::string num(double v, int decimals = 1) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

// Opens an <svg> of `height` pixels with a title for screen readers.
std::string open_svg(double height, const std::string& title) {
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"chart\" width=\"" + num(kWidth, 0) +
         "\" height=\"" + num(height, 0) + "\" viewBox=\"0 0 " + num(kWidth, 0) + " " +
         num(height, 0) + "\" role=\"img\"><title>" + escape(title) + "</title>\n";
}

std::string text(double x, double y, const std::string& s, const std::string& anchor = "start",
                 const std::string& extra = "") {
  return "<text x=\"" + num(x) + "\" y=\"" + num(y) + "\" text-anchor=\"" + anchor + "\"" + extra +
         ">" + escape(s) + "</text>\n";
}

std::string line(double x1, double y1, double x2, double y2, const std::string& style) {
  return "<line x1=\"" + num(x1) + "\" y1=\"" + num(y1) + "\" x2=\"" + num(x2) + "\" y2=\"" +
         num(y2) + "\" " + style + "/>\n";
}

std::string rect(double x, double y, double w, double h, const std::string& fill,
                 const std::string& tip, const std::string& extra = "") {
  return "<rect x=\"" + num(x, 2) + "\" y=\"" + num(y, 1) + "\" width=\"" +
         num(std::max(w, 0.5), 2) + "\" height=\"" + num(h, 1) + "\" fill=\"" + fill + "\"" +
         extra + "><title>" + escape(tip) + "</title></rect>\n";
}

// A horizontal axis under the plot at `y`: ticks at `values`, placed by `x_of`.
template <typename Scale>
std::string axis(double y, const std::vector<double>& values, Scale x_of, int decimals,
                 const std::string& label) {
  std::string s = line(kLabelWidth, y, kLabelWidth + kPlotWidth, y, "class=\"axis\"");
  for (double v : values) {
    const double x = x_of(v);
    s += line(x, kTopMargin, x, y, "class=\"grid\"");
    s += text(x, y + 14, num(v, decimals), "middle");
  }
  s += text(kLabelWidth + kPlotWidth / 2, y + 30, label, "middle", " class=\"axis-label\"");
  return s;
}

std::string part_label(const ReportPart& p) {
  return std::to_string(p.order) + " " + p.name;
}

}  // namespace

std::string theta_c_svg(const std::vector<ReportPart>& parts) {
  // Per part a histogram of θc in 2-degree bins, the bar height relative to the part's fullest.
  constexpr double kRow = 34;
  constexpr double kBinDeg = 2.0;
  constexpr int kBins = 45;  // 0..90 deg
  const double height = kTopMargin + kRow * static_cast<double>(parts.size()) + kAxisHeight;
  const auto x_of = [](double deg) { return kLabelWidth + kPlotWidth * deg / 90.0; };
  std::string s = open_svg(height, "θc of every robot grasp per part");
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const ReportPart& p = parts[i];
    const double top = kTopMargin + kRow * static_cast<double>(i);
    s += text(4, top + kRow / 2 + 4, part_label(p));
    s += text(kLabelWidth + kPlotWidth + 6, top + kRow / 2 + 4,
              std::to_string(p.theta_c_deg.size()), "start", " class=\"note\"");
    std::vector<int> bins(kBins, 0);
    for (double t : p.theta_c_deg) {
      bins[std::clamp(static_cast<int>(t / kBinDeg), 0, kBins - 1)] += 1;
    }
    const int fullest = std::max(1, *std::max_element(bins.begin(), bins.end()));
    for (int b = 0; b < kBins; ++b) {
      if (bins[b] == 0) continue;
      const double h = (kRow - 6) * bins[b] / fullest;
      s += rect(x_of(b * kBinDeg), top + kRow - 3 - h, x_of(kBinDeg) - x_of(0) - 1, h, kPalette[0],
                p.name + ": " + std::to_string(bins[b]) + " grasps with θc in [" +
                    num(b * kBinDeg, 0) + ", " + num((b + 1) * kBinDeg, 0) + ") deg");
    }
  }
  s += axis(height - kAxisHeight, {0, 15, 30, 45, 60, 75, 90}, x_of, 0,
            "θc (deg): the part's tilt the grasp holds; 90 = no limit (right: grasp count)");
  return s + "</svg>\n";
}

std::string stages_svg(const std::vector<ReportPart>& parts) {
  // Candidates, |S| and |𝕊| on a log scale: thousands of candidates against a few goals.
  constexpr double kBar = 8;
  constexpr double kRow = 3 * kBar + 10;
  int most = 10;
  for (const ReportPart& p : parts) most = std::max(most, p.candidates);
  const double decades = std::ceil(std::log10(static_cast<double>(most)));
  const auto x_of = [&](double n) {
    return kLabelWidth + kPlotWidth * std::log10(std::max(n, 1.0)) / decades;
  };
  const double height = kTopMargin + kRow * static_cast<double>(parts.size()) + kAxisHeight + 18;
  std::string s = open_svg(height, "Handover candidates, |S| and |𝕊| per part");
  const char* names[] = {"candidates (Eq. 1)", "|S| comfortable", "|𝕊| goals"};
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const ReportPart& p = parts[i];
    const double top = kTopMargin + kRow * static_cast<double>(i);
    s += text(4, top + kRow / 2 + 2, part_label(p));
    if (!p.has_stage) {
      s += text(kLabelWidth + 4, top + kRow / 2 + 2, "no handover stage in the database", "start",
                " class=\"note\"");
      continue;
    }
    const int values[] = {p.candidates, p.comfortable, p.goals};
    for (int k = 0; k < 3; ++k) {
      const double y = top + 2 + kBar * k;
      const double w = values[k] > 0 ? x_of(values[k]) - kLabelWidth : 0.0;
      std::string tip = p.name + ": " + names[k] + " " + std::to_string(values[k]);
      if (k == 2 && !p.failure.empty()) tip += " (" + p.failure + ")";
      s += rect(kLabelWidth, y, w, kBar - 1, kPalette[k], tip);
      s += text(kLabelWidth + w + 3, y + kBar - 1, std::to_string(values[k]), "start",
                " class=\"small\"");
    }
  }
  std::vector<double> ticks;
  for (int d = 0; d <= static_cast<int>(decades); ++d) ticks.push_back(std::pow(10.0, d));
  s += axis(height - kAxisHeight - 18, ticks, x_of, 0, "count (log scale)");
  for (int k = 0; k < 3; ++k) {
    const double x = kLabelWidth + 170.0 * k;
    s += rect(x, height - 12, 10, 10, kPalette[k], names[k]);
    s += text(x + 14, height - 3, names[k], "start", " class=\"small\"");
  }
  return s + "</svg>\n";
}

std::string goal_quality_svg(const std::vector<ReportPart>& parts) {
  // Q of every goal on [0, 1]; the first goal (the one the planner tries first) drawn large.
  constexpr double kRow = 24;
  const double height = kTopMargin + kRow * static_cast<double>(parts.size()) + kAxisHeight;
  const auto x_of = [](double q) { return kLabelWidth + kPlotWidth * std::clamp(q, 0.0, 1.0); };
  std::string s = open_svg(height, "Human comfort Q of the ranked handover goals per part");
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const ReportPart& p = parts[i];
    const double y = kTopMargin + kRow * static_cast<double>(i) + kRow / 2;
    s += text(4, y + 4, part_label(p));
    s += text(kLabelWidth + kPlotWidth + 6, y + 4, std::to_string(p.goal_quality.size()), "start",
              " class=\"note\"");
    if (p.goal_quality.empty()) {
      s += text(kLabelWidth + 4, y + 4, "no goal", "start", " class=\"note\"");
      continue;
    }
    // The later ranks first so the first goal's dot lies on top.
    for (std::size_t r = p.goal_quality.size(); r-- > 0;) {
      const bool first = r == 0;
      s += "<circle cx=\"" + num(x_of(p.goal_quality[r])) + "\" cy=\"" + num(y) + "\" r=\"" +
           (first ? "6" : "3.5") + "\" fill=\"" + (first ? kPalette[5] : kPalette[0]) +
           "\" fill-opacity=\"" + (first ? "1" : "0.45") + "\"><title>" +
           escape(p.name + ": goal " + std::to_string(r + 1) + ", Q " + num(p.goal_quality[r], 3)) +
           "</title></circle>\n";
    }
  }
  s += axis(height - kAxisHeight, {0, 0.2, 0.4, 0.6, 0.8, 1.0}, x_of, 1,
            "human comfort Q (large dot: the first goal by Eq. 8; right: goal count)");
  return s + "</svg>\n";
}

std::string timeline_svg(const PlanFile& plan) {
  // One row per arm; each step a bar over its time span, the boards played one after the other.
  std::vector<std::string> arms;
  std::map<std::string, int> step_colour;
  for (const PlanFileBoard& b : plan.boards) {
    for (const PlanFileStep& st : b.steps) {
      if (std::find(arms.begin(), arms.end(), st.arm) == arms.end()) arms.push_back(st.arm);
      step_colour.try_emplace(st.name, static_cast<int>(step_colour.size()) % 8);
    }
  }
  std::sort(arms.begin(), arms.end());
  constexpr double kRow = 30;
  constexpr double kBoardLabels = 16;
  const double legend_rows = std::ceil(static_cast<double>(step_colour.size()) / 4.0);
  const double plot_top = kTopMargin + kBoardLabels;
  const double plot_bottom =
      plot_top + kRow * static_cast<double>(std::max<std::size_t>(1, arms.size()));
  const double height = plot_bottom + kAxisHeight + 16 * legend_rows + 4;
  const double duration = std::max(plan.duration(), 1e-9);
  const auto x_of = [&](double t) { return kLabelWidth + kPlotWidth * t / duration; };
  std::string s = open_svg(height, "The plan's steps per arm against time");
  for (std::size_t a = 0; a < arms.size(); ++a) {
    s += text(4, plot_top + kRow * static_cast<double>(a) + kRow / 2 + 4, "arm " + arms[a]);
  }
  double start = 0.0;
  int unsolved = 0;
  for (const PlanFileBoard& b : plan.boards) {
    if (!b.solved()) {
      ++unsolved;
      continue;
    }
    s += line(x_of(start), kTopMargin, x_of(start), plot_bottom, "class=\"board\"");
    s += text(x_of(start) + 2, kTopMargin + 10, b.board, "start", " class=\"small\"");
    for (const PlanFileStep& st : b.steps) {
      if (st.time.empty()) continue;
      const auto row = std::find(arms.begin(), arms.end(), st.arm) - arms.begin();
      const double t0 = start + st.time.front();
      const double t1 = start + st.time.back();
      s += rect(x_of(t0), plot_top + kRow * static_cast<double>(row) + 4, x_of(t1) - x_of(t0),
                kRow - 8, kPalette[step_colour[st.name]],
                b.board + ": " + st.name + " (arm " + st.arm + ", " + num(t0, 2) + "–" +
                    num(t1, 2) + " s)");
    }
    start += b.duration;
  }
  std::vector<double> ticks;
  const double step = duration > 100 ? 20 : duration > 40 ? 10 : duration > 10 ? 5 : 1;
  for (double t = 0; t <= duration + 1e-9; t += step) ticks.push_back(t);
  std::string label = "time (s) of the whole plan, " + num(plan.duration(), 1) + " s";
  if (unsolved > 0) label += "; " + std::to_string(unsolved) + " board(s) not planned";
  s += axis(plot_bottom, ticks, x_of, 0, label);
  int k = 0;
  for (const auto& [name, colour] : step_colour) {
    const double x = kLabelWidth + 150.0 * (k % 4);
    const double y = plot_bottom + kAxisHeight + 4 + 16.0 * (k / 4);
    s += rect(x, y, 10, 10, kPalette[colour], name);
    s += text(x + 14, y + 9, name, "start", " class=\"small\"");
    ++k;
  }
  return s + "</svg>\n";
}

namespace {

// One ergonomics measure of a board by a method: its value, the bar's end-of-bar note.
struct ErgonomicsMeasure {
  std::string title;  // the chart's
  std::string axis;   // the axis label
  int decimals = 0;
  double floor = 1.0;    // the axis reaches at least this
  double dashed = -1.0;  // a dashed line at this value (< 0: none)
  std::function<double(const ReportErgonomics&)> value;
  std::function<std::string(const ReportErgonomics&)> mark;  // after the value ("" none)
  // Below the plot, per method (its reachable rows).
  std::function<std::string(const std::vector<const ReportErgonomics*>&)> summary;
};

// Per board (assembly order) three bars, hila, table, alone, of `m`; an unreachable board named.
std::string ergonomics_chart(const std::vector<ReportErgonomics>& rows,
                             const ErgonomicsMeasure& m) {
  constexpr const char* kMethods[] = {"hila", "table", "alone"};
  constexpr double kBar = 9;
  constexpr double kRow = 3 * kBar + 10;
  std::map<std::pair<int, std::string>, std::map<std::string, const ReportErgonomics*>> boards;
  std::map<std::string, std::vector<const ReportErgonomics*>> reached;
  std::map<std::string, int> unreachable;
  double most = m.floor;
  for (const ReportErgonomics& r : rows) {
    boards[{r.order, r.part}][r.method] = &r;
    if (r.reachable) {
      most = std::max(most, m.value(r));
      reached[r.method].push_back(&r);
    } else {
      ++unreachable[r.method];
    }
  }
  const double magnitude = std::pow(10.0, std::floor(std::log10(most)));
  const double tick =
      most / magnitude > 5 ? 2 * magnitude : magnitude / (most / magnitude > 2 ? 1 : 2);
  most = tick * std::ceil(most / tick);
  const auto x_of = [&](double v) { return kLabelWidth + kPlotWidth * std::max(v, 0.0) / most; };
  const double plot_bottom = kTopMargin + kRow * static_cast<double>(boards.size());
  const double height = plot_bottom + kAxisHeight + 8 + 16 * 3;
  std::string s = open_svg(height, m.title);
  std::size_t i = 0;
  for (const auto& [key, methods] : boards) {
    const double top = kTopMargin + kRow * static_cast<double>(i++);
    s += text(4, top + kRow / 2 + 2, std::to_string(key.first) + " " + key.second);
    for (int k = 0; k < 3; ++k) {
      const double y = top + 2 + kBar * k;
      const auto it = methods.find(kMethods[k]);
      if (it == methods.end() || !it->second->reachable) {
        s += text(kLabelWidth + 3, y + kBar - 1,
                  std::string(kMethods[k]) + (it == methods.end() ? ": -" : ": unreachable"),
                  "start", " class=\"small note\"");
        continue;
      }
      const ReportErgonomics& r = *it->second;
      const double w = x_of(m.value(r)) - kLabelWidth;
      s += rect(kLabelWidth, y, w, kBar - 1, kPalette[k],
                key.second + ", " + r.method + ": torso " + num(r.torso_flexion_deg, 0) +
                    " deg, elbow " + (r.shoulder_elevated ? "at or above" : "below") +
                    " the shoulder, reach " + num(r.reach, 2) + " m, re-orientation " +
                    num(r.reorientation_deg, 0) + " deg, Q " + num(r.quality, 3) + " (arm " +
                    r.arm + ")");
      s += text(kLabelWidth + w + 3, y + kBar - 1, num(m.value(r), m.decimals) + m.mark(r), "start",
                " class=\"small\"");
    }
  }
  if (m.dashed >= 0.0) {
    s += line(x_of(m.dashed), kTopMargin, x_of(m.dashed), plot_bottom, "class=\"board\"");
  }
  std::vector<double> ticks;
  for (double v = 0; v <= most + 1e-9 * most; v += tick) ticks.push_back(v);
  s += axis(plot_bottom, ticks, x_of, tick < 1 ? (tick < 0.1 ? 2 : 1) : 0, m.axis);
  for (int k = 0; k < 3; ++k) {
    const std::string method = kMethods[k];
    const double y = plot_bottom + kAxisHeight + 6 + 16.0 * k;
    s += rect(kLabelWidth, y, 10, 10, kPalette[k], method);
    s += text(kLabelWidth + 14, y + 9,
              method + ": " + m.summary(reached[method]) + ", " +
                  std::to_string(unreachable[method]) + " unreachable",
              "start", " class=\"small\"");
  }
  return s + "</svg>\n";
}

std::string mean_of(const std::vector<const ReportErgonomics*>& rows,
                    double ReportErgonomics::*field, int decimals, const std::string& unit) {
  double sum = 0.0;
  for (const ReportErgonomics* r : rows) sum += r->*field;
  return "mean " + (rows.empty() ? std::string("-") : num(sum / rows.size(), decimals)) + unit;
}

}  // namespace

std::string ergonomics_svg(const std::vector<ReportErgonomics>& rows, double bent_forward_deg) {
  ErgonomicsMeasure torso{
      "Torso flexion per board: hila against the baselines",
      "torso flexion (deg); dashed: bent forward from " + num(bent_forward_deg, 0) +
          " deg; ▲ elbow at or above the shoulder",
      0,
      bent_forward_deg + 10.0,
      bent_forward_deg,
      [](const ReportErgonomics& r) { return r.torso_flexion_deg; },
      [](const ReportErgonomics& r) { return std::string(r.shoulder_elevated ? " ▲" : ""); },
      [&](const std::vector<const ReportErgonomics*>& reached) {
        int bent = 0, shoulder = 0;
        for (const ReportErgonomics* r : reached) {
          bent += r->torso_flexion_deg >= bent_forward_deg ? 1 : 0;
          shoulder += r->shoulder_elevated ? 1 : 0;
        }
        return std::to_string(bent) + " bent forward, " + std::to_string(shoulder) +
               " with the elbow at or above the shoulder";
      }};
  ErgonomicsMeasure reach{"Reach per board: hila against the baselines",
                          "reach, shoulder to hand (m)",
                          2,
                          0.5,
                          -1.0,
                          [](const ReportErgonomics& r) { return r.reach; },
                          [](const ReportErgonomics&) { return std::string(); },
                          [](const std::vector<const ReportErgonomics*>& reached) {
                            return mean_of(reached, &ReportErgonomics::reach, 2, " m") +
                                   ", comfort Q " +
                                   mean_of(reached, &ReportErgonomics::quality, 3, "");
                          }};
  ErgonomicsMeasure turn{"Re-orientation left per board: hila against the baselines",
                         "rotation left to bring the board to its target (deg)",
                         0,
                         10.0,
                         -1.0,
                         [](const ReportErgonomics& r) { return r.reorientation_deg; },
                         [](const ReportErgonomics&) { return std::string(); },
                         [](const std::vector<const ReportErgonomics*>& reached) {
                           return mean_of(reached, &ReportErgonomics::reorientation_deg, 0, " deg");
                         }};
  return ergonomics_chart(rows, torso) + ergonomics_chart(rows, reach) +
         ergonomics_chart(rows, turn);
}

}  // namespace hila::viz
