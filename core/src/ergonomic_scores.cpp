#include "hila/core/ergonomic_scores.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/error.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::core {

namespace {

// ---- Tables --------------------------------------------------------------------------------
// The values are those of the published methods; rows and columns are the sub-scores from 1.

// RULA posture score A: McAtamney & Corlett (1993) Table 1, Table A of the RULA Employee
// Assessment Worksheet. [upper arm 1-6][lower arm 1-3][wrist 1-4 x wrist twist 1-2].
constexpr int kRulaTableA[6][3][8] = {
    {{1, 2, 2, 2, 2, 3, 3, 3}, {2, 2, 2, 2, 3, 3, 3, 3}, {2, 3, 3, 3, 3, 3, 4, 4}},
    {{2, 3, 3, 3, 3, 4, 4, 4}, {3, 3, 3, 3, 3, 4, 4, 4}, {3, 4, 4, 4, 4, 4, 5, 5}},
    {{3, 3, 4, 4, 4, 4, 5, 5}, {3, 4, 4, 4, 4, 4, 5, 5}, {4, 4, 4, 4, 4, 5, 5, 5}},
    {{4, 4, 4, 4, 4, 5, 5, 5}, {4, 4, 4, 4, 4, 5, 5, 5}, {4, 4, 4, 5, 5, 5, 6, 6}},
    {{5, 5, 5, 5, 5, 6, 6, 7}, {5, 6, 6, 6, 6, 7, 7, 7}, {6, 6, 6, 7, 7, 7, 7, 8}},
    {{7, 7, 7, 7, 7, 8, 8, 9}, {8, 8, 8, 8, 8, 9, 9, 9}, {9, 9, 9, 9, 9, 9, 9, 9}},
};

// RULA posture score B: McAtamney & Corlett (1993) Table 2, the worksheet's Table B.
// [neck 1-6][trunk 1-6 x legs 1-2].
constexpr int kRulaTableB[6][12] = {
    {1, 3, 2, 3, 3, 4, 5, 5, 6, 6, 7, 7}, {2, 3, 2, 3, 4, 5, 5, 5, 6, 7, 7, 7},
    {3, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 7}, {5, 5, 5, 6, 6, 7, 7, 7, 7, 7, 8, 8},
    {7, 7, 7, 7, 7, 8, 8, 8, 8, 8, 8, 8}, {8, 8, 8, 8, 8, 8, 8, 9, 9, 9, 9, 9},
};

// RULA grand score: McAtamney & Corlett (1993) grand-score table, the worksheet's Table C.
// [score C 1-8+][score D 1-7+].
constexpr int kRulaTableC[8][7] = {
    {1, 2, 3, 3, 4, 5, 5}, {2, 2, 3, 4, 4, 5, 5}, {3, 3, 3, 4, 4, 5, 6}, {3, 3, 3, 4, 5, 6, 6},
    {4, 4, 4, 5, 6, 7, 7}, {4, 4, 5, 6, 6, 7, 7}, {5, 5, 6, 6, 7, 7, 7}, {5, 5, 6, 7, 7, 7, 7},
};

// REBA Table A: Hignett & McAtamney (2000), Table A of the REBA Employee Assessment Worksheet.
// [trunk 1-5][neck 1-3][legs 1-4].
constexpr int kRebaTableA[5][3][4] = {
    {{1, 2, 3, 4}, {1, 2, 3, 4}, {3, 3, 5, 6}}, {{2, 3, 4, 5}, {3, 4, 5, 6}, {4, 5, 6, 7}},
    {{2, 4, 5, 6}, {4, 5, 6, 7}, {5, 6, 7, 8}}, {{3, 5, 6, 7}, {5, 6, 7, 8}, {6, 7, 8, 9}},
    {{4, 6, 7, 8}, {6, 7, 8, 9}, {7, 8, 9, 9}},
};

// REBA Table B: Hignett & McAtamney (2000), the worksheet's Table B.
// [upper arm 1-6][lower arm 1-2][wrist 1-3].
constexpr int kRebaTableB[6][2][3] = {
    {{1, 2, 2}, {1, 2, 3}}, {{1, 2, 3}, {2, 3, 4}}, {{3, 4, 5}, {4, 5, 5}},
    {{4, 5, 5}, {5, 6, 7}}, {{6, 7, 8}, {7, 8, 8}}, {{7, 8, 8}, {8, 9, 9}},
};

// REBA Table C: Hignett & McAtamney (2000), the worksheet's Table C. [score A 1-12][score B 1-12].
constexpr int kRebaTableC[12][12] = {{1, 1, 1, 2, 3, 3, 4, 5, 6, 7, 7, 7},
                                     {1, 2, 2, 3, 4, 4, 5, 6, 6, 7, 7, 8},
                                     {2, 3, 3, 3, 4, 5, 6, 7, 7, 8, 8, 8},
                                     {3, 4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9},
                                     {4, 4, 4, 5, 6, 7, 8, 8, 9, 9, 9, 9},
                                     {6, 6, 6, 7, 8, 8, 9, 9, 10, 10, 10, 10},
                                     {7, 7, 7, 8, 9, 9, 9, 10, 10, 11, 11, 11},
                                     {8, 8, 8, 9, 10, 10, 10, 10, 10, 11, 11, 11},
                                     {9, 9, 9, 10, 10, 10, 11, 11, 11, 12, 12, 12},
                                     {10, 10, 10, 11, 11, 11, 11, 12, 12, 12, 12, 12},
                                     {11, 11, 11, 11, 12, 12, 12, 12, 12, 12, 12, 12},
                                     {12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12, 12}};

void check_index(const char* table, const char* name, int value, int max) {
  if (value < 1 || value > max) {
    throw InputError(table, name, "a score in [1, " + std::to_string(max) + "]",
                     std::to_string(value));
  }
}

// `deg` once checked to be a finite angle within [-180, 180] (InputError naming `what` and
// `field` otherwise).
double angle(const char* what, const char* field, double deg) {
  if (!std::isfinite(deg) || std::abs(deg) > 180.0) {
    throw InputError(what, field, "an angle in degrees within [-180, 180]", format_number(deg));
  }
  return deg;
}

void check_enum(const char* what, const char* field, int value, int max, const char* expected) {
  if (value < 0 || value > max) throw InputError(what, field, expected, std::to_string(value));
}

void check_load(const std::string& what, double kg) {
  if (!std::isfinite(kg) || kg < 0.0) {
    throw InputError(what, "load_kg", "a load in kg >= 0", format_number(kg));
  }
}

// Upper arm, both methods: 20 deg extension to 20 deg flexion 1; beyond 20 deg extension or
// 20-45 deg flexion 2; 45-90 deg 3; beyond 90 deg 4.
int upper_arm_position(const char* what, double upper_arm_flexion_deg) {
  const double deg = angle(what, "upper_arm_flexion_deg", upper_arm_flexion_deg);
  if (deg < -20.0) return 2;
  if (deg <= 20.0) return 1;
  if (deg <= 45.0) return 2;
  if (deg <= 90.0) return 3;
  return 4;
}

// Lower arm, both methods: 60-100 deg of elbow flexion 1, otherwise 2.
int lower_arm_position(const char* what, double lower_arm_flexion_deg) {
  const double deg = angle(what, "lower_arm_flexion_deg", lower_arm_flexion_deg);
  return deg >= 60.0 && deg <= 100.0 ? 1 : 2;
}

// Trunk, both methods: upright 1; flexion 0-20 deg 2, 20-60 deg 3, beyond 60 deg 4. REBA scores
// extension 0-20 deg 2 and beyond 20 deg 3; RULA gives no score for extension and takes REBA's.
int trunk_position(const char* what, double trunk_flexion_deg) {
  const double deg = angle(what, "trunk_flexion_deg", trunk_flexion_deg);
  if (std::abs(deg) <= kNeutralBandDeg) return 1;
  if (deg < 0.0) return deg >= -20.0 ? 2 : 3;
  if (deg <= 20.0) return 2;
  if (deg <= 60.0) return 3;
  return 4;
}

}  // namespace

// ---- RULA ----------------------------------------------------------------------------------

int rula_table_a(int upper_arm, int lower_arm, int wrist, int wrist_twist) {
  check_index("RULA Table A", "upper arm", upper_arm, 6);
  check_index("RULA Table A", "lower arm", lower_arm, 3);
  check_index("RULA Table A", "wrist", wrist, 4);
  check_index("RULA Table A", "wrist twist", wrist_twist, 2);
  return kRulaTableA[upper_arm - 1][lower_arm - 1][2 * (wrist - 1) + wrist_twist - 1];
}

int rula_table_b(int neck, int trunk, int legs) {
  check_index("RULA Table B", "neck", neck, 6);
  check_index("RULA Table B", "trunk", trunk, 6);
  check_index("RULA Table B", "legs", legs, 2);
  return kRulaTableB[neck - 1][2 * (trunk - 1) + legs - 1];
}

int rula_table_c(int score_c, int score_d) {
  check_index("RULA Table C", "score C", score_c, 99);
  check_index("RULA Table C", "score D", score_d, 99);
  return kRulaTableC[std::min(score_c, 8) - 1][std::min(score_d, 7) - 1];
}

RulaScore rula(const RulaInputs& in) {
  constexpr const char* kWhat = "RULA inputs";
  check_load(kWhat, in.load_kg);
  check_enum(kWhat, "load_pattern", static_cast<int>(in.load_pattern), 2,
             "intermittent, static or repeated");

  RulaScore s;
  s.upper_arm = std::max(1, upper_arm_position(kWhat, in.upper_arm_flexion_deg) +
                                in.shoulder_raised + in.upper_arm_abducted - in.arm_supported);
  s.lower_arm =
      lower_arm_position(kWhat, in.lower_arm_flexion_deg) + in.arm_across_midline_or_out_to_side;
  const double wrist = std::abs(angle(kWhat, "wrist_flexion_deg", in.wrist_flexion_deg));
  s.wrist = (wrist <= kNeutralBandDeg ? 1 : wrist <= 15.0 ? 2 : 3) + in.wrist_deviated;
  s.wrist_twist = in.wrist_twist_near_end ? 2 : 1;
  s.posture_a = rula_table_a(s.upper_arm, s.lower_arm, s.wrist, s.wrist_twist);

  const double neck = angle(kWhat, "neck_flexion_deg", in.neck_flexion_deg);
  s.neck = (neck < -kNeutralBandDeg ? 4
            : neck <= 10.0          ? 1
            : neck <= 20.0          ? 2
                                    : 3) +
           in.neck_twisted + in.neck_side_bent;
  s.trunk = trunk_position(kWhat, in.trunk_flexion_deg) + in.trunk_twisted + in.trunk_side_bent;
  s.legs = in.legs_supported ? 1 : 2;
  s.posture_b = rula_table_b(s.neck, s.trunk, s.legs);

  // Muscle use and force/load (McAtamney & Corlett 1993): under 2 kg intermittent 0; 2-10 kg
  // intermittent 1; 2-10 kg static or repeated, or over 10 kg intermittent 2; over 10 kg static
  // or repeated, or shock or rapid build-up at any load, 3.
  s.muscle_use = in.muscle_use ? 1 : 0;
  const bool sustained = in.load_pattern != LoadPattern::Intermittent;
  if (in.load_shock) {
    s.force_load = 3;
  } else if (in.load_kg < 2.0) {
    s.force_load = 0;
  } else if (in.load_kg <= 10.0) {
    s.force_load = sustained ? 2 : 1;
  } else {
    s.force_load = sustained ? 3 : 2;
  }
  s.score_c = s.posture_a + s.muscle_use + s.force_load;
  s.score_d = s.posture_b + s.muscle_use + s.force_load;
  s.grand = rula_table_c(s.score_c, s.score_d);
  return s;
}

int rula_action_level(int grand_score) {
  check_index("RULA", "grand score", grand_score, 7);
  return (grand_score + 1) / 2;
}

const char* rula_action(int grand_score) {
  switch (rula_action_level(grand_score)) {
    case 1:
      return "acceptable";
    case 2:
      return "investigate further";
    case 3:
      return "investigate and change soon";
    default:
      return "investigate and change now";
  }
}

// ---- REBA ----------------------------------------------------------------------------------

int reba_table_a(int trunk, int neck, int legs) {
  check_index("REBA Table A", "trunk", trunk, 5);
  check_index("REBA Table A", "neck", neck, 3);
  check_index("REBA Table A", "legs", legs, 4);
  return kRebaTableA[trunk - 1][neck - 1][legs - 1];
}

int reba_table_b(int upper_arm, int lower_arm, int wrist) {
  check_index("REBA Table B", "upper arm", upper_arm, 6);
  check_index("REBA Table B", "lower arm", lower_arm, 2);
  check_index("REBA Table B", "wrist", wrist, 3);
  return kRebaTableB[upper_arm - 1][lower_arm - 1][wrist - 1];
}

int reba_table_c(int score_a, int score_b) {
  check_index("REBA Table C", "score A", score_a, 12);
  check_index("REBA Table C", "score B", score_b, 12);
  return kRebaTableC[score_a - 1][score_b - 1];
}

RebaScore reba(const RebaInputs& in) {
  constexpr const char* kWhat = "REBA inputs";
  check_load(kWhat, in.load_kg);
  const int coupling = static_cast<int>(in.coupling);
  check_enum(kWhat, "coupling", coupling, 3, "good, fair, poor or unacceptable");

  RebaScore s;
  // Group A. Neck: 0-20 deg flexion 1; beyond 20 deg or in extension 2; +1 if twisted or side
  // flexed (one point for either, as Hignett & McAtamney have it, so that the neck stays within
  // Table A's 1-3 and the trunk within 1-5; RULA adds one point for each).
  const double neck = angle(kWhat, "neck_flexion_deg", in.neck_flexion_deg);
  s.neck = (neck < -kNeutralBandDeg || neck > 20.0 ? 2 : 1) +
           (in.neck_twisted || in.neck_side_bent ? 1 : 0);
  s.trunk = trunk_position(kWhat, in.trunk_flexion_deg) +
            (in.trunk_twisted || in.trunk_side_bent ? 1 : 0);
  // Legs: bilateral weight bearing 1, unilateral or unstable 2; knees 30-60 deg +1, beyond 60
  // deg +2 (not when sitting).
  const double knee = angle(kWhat, "knee_flexion_deg", in.knee_flexion_deg);
  s.legs = (in.legs_bilateral ? 1 : 2) + (knee > 60.0    ? (in.sitting ? 0 : 2)
                                          : knee >= 30.0 ? 1
                                                         : 0);
  s.posture_a = reba_table_a(s.trunk, s.neck, s.legs);
  // Load/force: under 5 kg 0, 5-10 kg 1, over 10 kg 2; +1 for shock or rapid build-up.
  s.load_force = (in.load_kg < 5.0 ? 0 : in.load_kg <= 10.0 ? 1 : 2) + (in.load_shock ? 1 : 0);
  s.score_a = s.posture_a + s.load_force;

  // Group B.
  s.upper_arm =
      std::max(1, upper_arm_position(kWhat, in.upper_arm_flexion_deg) +
                      in.upper_arm_abducted_or_rotated + in.shoulder_raised - in.arm_supported);
  s.lower_arm = lower_arm_position(kWhat, in.lower_arm_flexion_deg);
  const double wrist = std::abs(angle(kWhat, "wrist_flexion_deg", in.wrist_flexion_deg));
  s.wrist = (wrist <= 15.0 ? 1 : 2) + in.wrist_deviated_or_twisted;
  s.posture_b = reba_table_b(s.upper_arm, s.lower_arm, s.wrist);
  s.coupling = coupling;
  s.score_b = s.posture_b + s.coupling;

  s.score_c = reba_table_c(s.score_a, s.score_b);
  s.activity = in.static_posture + in.repeated_small + in.rapid_changes;
  s.reba = s.score_c + s.activity;
  return s;
}

const char* reba_risk_level(int reba_score) {
  check_index("REBA", "score", reba_score, 15);
  if (reba_score == 1) return "negligible";
  if (reba_score <= 3) return "low";
  if (reba_score <= 7) return "medium";
  if (reba_score <= 10) return "high";
  return "very high";
}

// ---- From the human model ------------------------------------------------------------------

HumanArmAngles human_arm_angles(const RobotModel& human, const Eigen::VectorXd& q,
                                const std::string& side) {
  if (side != "left" && side != "right") {
    throw InputError("human posture", "side", "\"left\" or \"right\"", "\"" + side + "\"");
  }
  if (q.size() != human.num_variables() || !q.allFinite()) {
    throw InputError(human.source(), "human configuration",
                     std::to_string(human.num_variables()) + " finite joint values",
                     q.allFinite() ? std::to_string(q.size()) + " values" : "a non-finite value");
  }
  const auto value = [&](const std::string& joint) {
    return human.joint_value(q, human.joint_index(joint, "human joint"));
  };
  const std::string p = side + "_";
  const double flexion = value(p + "shoulder_flexion");
  const double abduction = value(p + "shoulder_abduction");

  HumanArmAngles a;
  a.trunk_flexion = rad_to_deg(value("torso_flexion"));
  // generate_human_urdf: flexion about the torso's -y, then abduction about +-x (mirrored so
  // that positive moves the arm away from the body). The hanging arm (0, 0, -1) then points
  // along (cos(ab) sin(fl), +-sin(ab), -cos(ab) cos(fl)) in the torso frame.
  const double forward = std::cos(abduction) * std::sin(flexion);
  const double outward = std::sin(abduction);
  const double down = std::cos(abduction) * std::cos(flexion);
  const double elevation = rad_to_deg(std::atan2(std::hypot(forward, outward), down));
  a.upper_arm_elevation = forward < 0.0 && down > 0.0 ? -elevation : elevation;
  a.upper_arm_abduction = rad_to_deg(std::asin(std::clamp(outward, -1.0, 1.0)));
  a.shoulder_rotation = rad_to_deg(value(p + "shoulder_rotation"));
  a.elbow_flexion = rad_to_deg(value(p + "elbow_flexion"));
  const int pronation = human.joint_index(p + "forearm_pronation", "human joint");
  const double rotation = human.joint_value(q, pronation);
  a.forearm_rotation = rad_to_deg(rotation);
  const Joint& forearm = human.joints()[pronation];
  a.forearm_rotation_near_end =
      (forearm.upper > 0.0 && rotation > kTwistNearEndFraction * forearm.upper) ||
      (forearm.lower < 0.0 && rotation < kTwistNearEndFraction * forearm.lower);
  a.wrist_flexion = rad_to_deg(value(p + "wrist_flexion"));
  a.wrist_deviation = rad_to_deg(value(p + "wrist_deviation"));

  // Where the wrist is, across the body, in the torso frame (y toward the left arm).
  std::vector<Pose> poses;
  human.link_poses(q, poses);
  const Pose torso_inv = poses[human.link_index("torso", "human link")].inverse();
  const double mirror = side == "left" ? 1.0 : -1.0;
  const auto lateral = [&](const std::string& link) {
    return mirror * (torso_inv * poses[human.link_index(link, "human link")].translation()).y();
  };
  a.shoulder_lateral_of_midline = lateral(p + "shoulder_flexion_link");
  a.wrist_lateral_of_midline = lateral(p + "wrist_link");
  a.wrist_lateral_of_shoulder = a.wrist_lateral_of_midline - a.shoulder_lateral_of_midline;
  return a;
}

namespace {

bool across_or_out(const HumanArmAngles& a) {
  return a.wrist_lateral_of_midline < 0.0 ||
         a.wrist_lateral_of_shoulder > kOutToSideFraction * a.shoulder_lateral_of_midline;
}

}  // namespace

RulaInputs rula_inputs_from_posture(const RobotModel& human, const Eigen::VectorXd& q,
                                    const std::string& side, double load_kg, bool two_hands) {
  check_load("RULA posture", load_kg);
  const HumanArmAngles a = human_arm_angles(human, q, side);
  RulaInputs in;
  in.upper_arm_flexion_deg = a.upper_arm_elevation;
  in.upper_arm_abducted = a.upper_arm_abduction > kAbductedDeg;
  in.lower_arm_flexion_deg = a.elbow_flexion;
  in.arm_across_midline_or_out_to_side = across_or_out(a);
  in.wrist_flexion_deg = a.wrist_flexion;
  in.wrist_deviated = std::abs(a.wrist_deviation) > kNeutralBandDeg;
  in.wrist_twist_near_end = a.forearm_rotation_near_end;
  in.trunk_flexion_deg = a.trunk_flexion;
  in.load_kg = two_hands ? load_kg / 2.0 : load_kg;
  return in;
}

RebaInputs reba_inputs_from_posture(const RobotModel& human, const Eigen::VectorXd& q,
                                    const std::string& side, double load_kg) {
  check_load("REBA posture", load_kg);
  const HumanArmAngles a = human_arm_angles(human, q, side);
  RebaInputs in;
  in.trunk_flexion_deg = a.trunk_flexion;
  in.load_kg = load_kg;
  in.upper_arm_flexion_deg = a.upper_arm_elevation;
  in.upper_arm_abducted_or_rotated =
      a.upper_arm_abduction > kAbductedDeg || std::abs(a.shoulder_rotation) > kArmRotatedDeg;
  in.lower_arm_flexion_deg = a.elbow_flexion;
  in.wrist_flexion_deg = a.wrist_flexion;
  in.wrist_deviated_or_twisted =
      std::abs(a.wrist_deviation) > kNeutralBandDeg || a.forearm_rotation_near_end;
  return in;
}

Eigen::VectorXd human_posture(
    const Cell& cell, const std::vector<std::pair<std::string, Eigen::VectorXd>>& arm_joints) {
  Eigen::VectorXd q = cell.human_neutral();
  for (const auto& [name, joints] : arm_joints) {
    const auto& arms = cell.human_arms();
    const std::string& wanted = name;  // a structured binding is not captured (clang before 16)
    const auto arm = std::find_if(arms.begin(), arms.end(),
                                  [&](const HumanArm& h) { return h.spec.name == wanted; });
    if (arm == arms.end()) {
      std::string names;
      for (const HumanArm& h : arms) names += (names.empty() ? "" : ", ") + h.spec.name;
      throw InputError(cell.spec().file, "human.arms", "one of: " + names, "'" + name + "'");
    }
    const auto& vars = arm->chain.model_variables();
    if (joints.size() != static_cast<Eigen::Index>(vars.size()) || !joints.allFinite()) {
      throw InputError(cell.spec().file, "human arm '" + name + "' joints",
                       std::to_string(vars.size()) + " finite values",
                       std::to_string(joints.size()) + (joints.allFinite() ? "" : " (not finite)"));
    }
    for (std::size_t i = 0; i < vars.size(); ++i) q[vars[i]] = joints[static_cast<Eigen::Index>(i)];
  }
  return q;
}

}  // namespace hila::core
