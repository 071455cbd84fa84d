#pragma once

#include <string>
#include <vector>

#include "hila/viz/plan_file.hpp"

namespace hila::viz {

// What the report shows of one part of a product database.
struct ReportPart {
  std::string name;
  int order = 0;                     // assembly order
  std::vector<double> theta_c_deg;   // relaxation limit θc of every robot grasp, deg
  bool has_stage = false;            // the database holds the part's handover stage
  int candidates = 0;                // Eq. 1 candidates
  int comfortable = 0;               // |S|
  int goals = 0;                     // |𝕊|
  std::vector<double> goal_quality;  // Q of the goals by rank (first: the best by Eq. 8)
  std::string failure;               // why the part has no goal ("" when it has one)
};

// One board's ergonomics by one method as the database stores it (`hila report ergonomics`):
// "hila" (the handover), "table" (laid flat on the table in front of the human) or "alone" (the
// human from the stack).
struct ReportErgonomics {
  std::string part;
  int order = 0;
  std::string method;
  bool reachable = false;
  double torso_flexion_deg = 0.0;  // least forward bend needed
  bool shoulder_elevated = false;  // elbow at or above the shoulder
  double reach = 0.0;              // m, shoulder to hand
  double reorientation_deg = 0.0;  // rotation left to bring the board to its target
  double quality = 0.0;            // comfort Q of the posture
  std::string arm;                 // the human arm used
};

// The report's 3D scenes: glTF 2.0 binaries (.glb) as hila::viz writes them.
struct ReportScene {
  std::string title;  // shown in the viewer's scene menu
  std::string glb;
};

// three.js as plain (non-module) scripts: three.min.js, then GLTFLoader.js and OrbitControls.js
// from its examples/js, which extend the global THREE.
struct ThreeJs {
  std::string three;
  std::string gltf_loader;
  std::string orbit_controls;
};

struct ReportInput {
  std::string product;
  std::string database;  // as given on the command line
  std::vector<ReportPart> parts;
  std::vector<ReportErgonomics> ergonomics;  // empty: no ergonomics chart
  std::vector<ReportScene> scenes;           // the viewer opens the last; its first animation plays
  const PlanFile* plan = nullptr;            // the timeline chart's plan; nullptr: none
  ThreeJs three;
};

// The report as one self-contained HTML page (no network, no server: the scripts and the .glb
// files are inlined, the .glb as base64). The viewer reads the URL's hash: "#t=SECONDS" shows
// the animation paused at that time (for screenshots); "#scene=N" opens scene N (0-based);
// "#clip=NAME" plays the scene's animation NAME (a board's own) instead of its first. The page
// sets <body data-status> to "ready" once the scene is drawn, or "error" with the message in
// #errors (also for errors the page's scripts log with console.error), and data-canvas-filled to
// the fraction of sampled canvas pixels that differ from the background.
std::string report_html(const ReportInput& input);

// The report's charts as inline SVG elements (width in CSS pixels, scaled to the page):
// θc of every grasp per part (dots), the candidates, |S| and |𝕊| per part (bars), the goals' Q
// per part (dots by rank), and the plan's steps per arm against time (bars, boards one after the
// other as the plan plays them).
std::string theta_c_svg(const std::vector<ReportPart>& parts);
std::string stages_svg(const std::vector<ReportPart>& parts);
std::string goal_quality_svg(const std::vector<ReportPart>& parts);
std::string timeline_svg(const PlanFile& plan);
// Three charts of the ergonomics per board, each with a bar per method (hila, table, alone; an
// unreachable board named): the torso flexion needed (the EAWS bend at `bent_forward_deg`
// dashed, ▲ for an elbow at or above the shoulder; below, each method's counts), the reach
// (below, the means of reach and comfort Q) and the re-orientation left (below, its mean).
std::string ergonomics_svg(const std::vector<ReportErgonomics>& rows,
                           double bent_forward_deg = 20.0);

// Base64 (RFC 4648, with padding) of `bytes`.
std::string base64(const std::string& bytes);

}  // namespace hila::viz
