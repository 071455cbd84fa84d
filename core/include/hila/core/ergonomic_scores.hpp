#pragma once

namespace hila::core {

// RULA (McAtamney & Corlett 1993, Applied Ergonomics 24(2):91-99) and REBA (Hignett & McAtamney
// 2000, Applied Ergonomics 31:201-205): the observational posture scores ergonomists use, from
// body-part angles and a few yes/no observations, through the methods' lookup tables, to RULA's
// grand score (1-7) and the REBA score (1-15).
//
// Angles are in degrees, measured from the neutral posture of the part: standing upright, arms
// hanging, elbows straight, wrists straight. Flexion (forward, toward the palm) is positive,
// extension negative. An angle on the edge of a published range takes the lower score (20 deg of
// upper-arm flexion is "20 deg extension to 20 deg flexion"), and an angle within
// kNeutralBandDeg of zero counts as neutral where a method scores "0 deg" or "upright" on its
// own (the RULA wrist, both trunks; the neck "in extension" begins beyond it).
inline constexpr double kNeutralBandDeg = 5.0;

// How a load or force is applied (RULA's force/load score).
enum class LoadPattern {
  Intermittent,  // held briefly, now and then
  Static,        // held for more than 1 minute
  Repeated,      // applied more than 4 times a minute
};

struct RulaInputs {
  // Group A: the assessed arm (RULA scores one side at a time).
  // Upper arm angle from the trunk's downward axis, deg: + flexion (forward), - extension.
  double upper_arm_flexion_deg = 0.0;
  bool shoulder_raised = false;     // shoulder girdle elevated (shrugged)
  bool upper_arm_abducted = false;  // arm raised out to the side
  bool arm_supported = false;       // arm supported or the person leaning on it (-1)
  // Elbow flexion, deg: 0 with the arm straight; 60-100 scores best.
  double lower_arm_flexion_deg = 80.0;
  bool arm_across_midline_or_out_to_side = false;  // the hand works across the body or out wide
  // Wrist angle, deg: + flexion (toward the palm), - extension.
  double wrist_flexion_deg = 0.0;
  bool wrist_deviated = false;        // radial or ulnar deviation (bent from the midline)
  bool wrist_twist_near_end = false;  // forearm rotation at or near the end of its range
  // Group B: neck, trunk, legs.
  double neck_flexion_deg = 0.0;  // + flexion (head forward), - extension
  bool neck_twisted = false;
  bool neck_side_bent = false;
  double trunk_flexion_deg = 0.0;  // + forward bend from upright, - extension (leaning back)
  bool trunk_twisted = false;
  bool trunk_side_bent = false;
  bool legs_supported = true;  // legs and feet supported, weight evenly balanced
  // Muscle use and force, applied to both groups (RULA steps 6-7 and 13-14).
  bool muscle_use = false;  // posture mainly static (held > 1 min) or repeated > 4 times a minute
  double load_kg = 0.0;     // load or force on the hand, kg (>= 0)
  LoadPattern load_pattern = LoadPattern::Intermittent;
  bool load_shock = false;  // shock or a force with rapid build-up
};

struct RulaScore {
  int upper_arm = 0;    // 1-6
  int lower_arm = 0;    // 1-3
  int wrist = 0;        // 1-4
  int wrist_twist = 0;  // 1-2
  int posture_a = 0;    // Table A, 1-9
  int muscle_use = 0;   // 0-1
  int force_load = 0;   // 0-3
  int score_c = 0;      // posture A + muscle use + force (wrist and arm score)
  int neck = 0;         // 1-6
  int trunk = 0;        // 1-6
  int legs = 0;         // 1-2
  int posture_b = 0;    // Table B, 1-9
  int score_d = 0;      // posture B + muscle use + force (neck, trunk and leg score)
  int grand = 0;        // Table C (row score C capped at 8, column score D at 7), 1-7
};

// Throws InputError ("RULA inputs", the field) on a non-finite angle or one outside
// [-180, 180], a negative or non-finite load, or an unknown load pattern.
RulaScore rula(const RulaInputs& inputs);

// RULA action level of a grand score: 1 (1-2), 2 (3-4), 3 (5-6), 4 (7). Throws InputError
// outside 1-7.
int rula_action_level(int grand_score);
// "acceptable", "investigate further", "investigate and change soon", "investigate and change
// now" for action levels 1-4 (of the grand score given).
const char* rula_action(int grand_score);

// REBA's coupling score: how the hands hold the load.
enum class Coupling {
  Good,          // well-fitting handle and a mid-range power grip (+0)
  Fair,          // hand hold acceptable but not ideal, or via another body part (+1)
  Poor,          // hand hold not acceptable although possible (+2)
  Unacceptable,  // awkward, unsafe grip, no handles (+3)
};

struct RebaInputs {
  // Group A: neck, trunk, legs.
  double neck_flexion_deg = 0.0;  // + flexion, - extension
  bool neck_twisted = false;
  bool neck_side_bent = false;
  double trunk_flexion_deg = 0.0;  // + forward bend from upright, - extension
  bool trunk_twisted = false;
  bool trunk_side_bent = false;
  // Bilateral weight bearing, walking or sitting; false: unilateral, feather weight bearing or
  // an unstable posture.
  bool legs_bilateral = true;
  double knee_flexion_deg = 0.0;  // deg, the more flexed knee: +1 for 30-60, +2 beyond 60
  bool sitting = false;           // the +2 for knees beyond 60 deg does not apply sitting
  double load_kg = 0.0;           // load or force handled, kg (>= 0)
  bool load_shock = false;        // shock or rapid build-up of force
  // Group B: the assessed arm.
  double upper_arm_flexion_deg = 0.0;  // from the trunk's downward axis: + flexion, - extension
  bool upper_arm_abducted_or_rotated = false;
  bool shoulder_raised = false;
  bool arm_supported = false;           // arm supported, leaning or gravity assisted (-1)
  double lower_arm_flexion_deg = 80.0;  // elbow flexion, deg: 60-100 scores best
  double wrist_flexion_deg = 0.0;       // + flexion, - extension
  bool wrist_deviated_or_twisted = false;
  Coupling coupling = Coupling::Good;
  // Activity: +1 each.
  bool static_posture = false;  // one or more body parts held for more than 1 minute
  bool repeated_small = false;  // small-range actions repeated more than 4 times a minute
  bool rapid_changes = false;   // rapid large changes in posture or an unstable base
};

struct RebaScore {
  int neck = 0;        // 1-3
  int trunk = 0;       // 1-5
  int legs = 0;        // 1-4
  int posture_a = 0;   // Table A, 1-9
  int load_force = 0;  // 0-3
  int score_a = 0;     // posture A + load/force, 1-12
  int upper_arm = 0;   // 1-6
  int lower_arm = 0;   // 1-2
  int wrist = 0;       // 1-3
  int posture_b = 0;   // Table B, 1-9
  int coupling = 0;    // 0-3
  int score_b = 0;     // posture B + coupling, 1-12
  int score_c = 0;     // Table C, 1-12
  int activity = 0;    // 0-3
  int reba = 0;        // score C + activity, 1-15
};

// Throws InputError ("REBA inputs", the field) like rula().
RebaScore reba(const RebaInputs& inputs);

// "negligible" (1), "low" (2-3), "medium" (4-7), "high" (8-10), "very high" (11-15); throws
// InputError outside 1-15.
const char* reba_risk_level(int reba_score);

// The methods' lookup tables by sub-score, each counted from 1; InputError outside a table's
// range. RULA Table C caps its row (score C) at 8 and its column (score D) at 7, as the
// worksheet's "8+" and "7+" do.
int rula_table_a(int upper_arm, int lower_arm, int wrist, int wrist_twist);
int rula_table_b(int neck, int trunk, int legs);
int rula_table_c(int score_c, int score_d);
int reba_table_a(int trunk, int neck, int legs);
int reba_table_b(int upper_arm, int lower_arm, int wrist);
int reba_table_c(int score_a, int score_b);

}  // namespace hila::core
