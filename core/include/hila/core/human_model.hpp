#pragma once

#include <string>

namespace hila::core {

enum class Sex { Male, Female };

struct HumanBodySpec {
  // Default: mean young Japanese adult male (AIST 1991-92 body-dimension survey).
  double stature = 1.722;  // m
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

// Link names used by the cell file for the arm chains.
inline constexpr const char* kHumanArmBase = "torso";
std::string human_grasp_link(const std::string& side);  // "left_hand_grasp"

}  // namespace hila::core
