#pragma once

#include <Eigen/Core>
#include <string>

namespace hila::core {

class RobotModel;

enum class Sex { Male, Female };

// Statures (m) of the AIST 1991-92 body-dimension survey's young adults (18-29 years; 217 men,
// 204 women): mean maximum stature 1.7219 m (men) and 1.5954 m (women). The survey's standard
// deviations are not restated here; the percentiles are mean -/+ 1.645 SD with the SD of
// 20-29-year-olds of the 2018 National Health and Nutrition Survey (Japan): 0.057 m (women),
// 0.059 m (men). The human model covers at least kFemaleStatureP5 to kTallStature.
inline constexpr double kDefaultStature = 1.722;  // mean man, the default body
inline constexpr double kFemaleStatureMean = 1.595;
inline constexpr double kFemaleStatureP5 = 1.50;  // 5th-percentile woman
inline constexpr double kMaleStatureP95 = 1.82;   // 95th-percentile man
inline constexpr double kTallStature = 1.95;      // a tall man beyond the survey's 95th percentile
// The statures human_dimensions accepts (m): adults, with room beyond the tested range.
inline constexpr double kMinStature = 1.30;
inline constexpr double kMaxStature = 2.20;

struct HumanBodySpec {
  // Default: mean young Japanese adult male (AIST 1991-92 body-dimension survey).
  double stature = kDefaultStature;  // m
  Sex sex = Sex::Male;
};

// Segment lengths from stature by standard anthropometric ratios (Drillis & Contini; DESIGN §4).
struct HumanDimensions {
  double stature = 0.0;
  double hip_height = 0.0;           // 0.530 H
  double shoulder_height = 0.0;      // 0.818 H
  double shoulder_half_width = 0.0;  // biacromial / 2: 0.245 H male, 0.230 H female
  double upper_arm = 0.0;            // 0.186 H
  double forearm = 0.0;              // 0.146 H
  double hand = 0.0;                 // 0.108 H
  double chest_depth = 0.0;          // 0.130 H
  double head_radius = 0.0;          // 0.060 H
};

// Throws InputError (field "stature") outside the adult range 1.30–2.20 m.
HumanDimensions human_dimensions(const HumanBodySpec& spec);

// URDF of a standing human: legs, a torso with a flexion joint at the hip, head, and two 7-DoF
// arms (shoulder flexion, abduction, rotation; elbow flexion; forearm pronation; wrist flexion,
// deviation) with range-of-motion limits from the ergonomics literature, a hand, and a grasp
// frame per hand (z = approach from the wrist to the fingers, y = closing axis = palm normal).
// Frame: origin on the floor between the feet, x forward, z up.
std::string generate_human_urdf(const HumanBodySpec& spec);

// Smallest distance (m) the neutral posture keeps between the human's own links (pairs that
// `hila cell check` tests: every pair except a link and its nearest ancestor with geometry).
inline constexpr double kHumanNeutralClearance = 0.003;

// The relaxed standing posture of a human model, the cell's human posture when the cell file
// gives no `human.neutral_deg`: every joint at zero clamped into its limits (trunk upright, arms
// hanging, palms medial), except that where a hanging arm comes within kHumanNeutralClearance of
// the body both shoulders abduct by the smallest multiple of 0.5 degrees, at most 10, that
// clears it. The arm hangs straight from the shoulder at biacromial/2 from the midline, the hips
// below are 0.19 H wide: a woman's shoulders (0.230 H) leave her hanging forearm (0.0203 H in
// radius) 0.0003 H (0.5 mm) inside her hips, and people hold the arm off the hip (the elbow's
// carrying angle does it in life; this model's elbow has none), here by 0.5 to 1 degree. A man's
// arm (0.245 H) hangs clear (at least 4.2 mm from 1.45 m up) and stays at zero. A model without
// `left_shoulder_abduction` / `right_shoulder_abduction` joints gets the zero posture.
Eigen::VectorXd human_neutral_configuration(const RobotModel& human);

// Link names used by the cell file for the arm chains.
inline constexpr const char* kHumanArmBase = "torso";
std::string human_grasp_link(const std::string& side);  // "left_hand_grasp"

}  // namespace hila::core
