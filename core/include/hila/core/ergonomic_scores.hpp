#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace hila::core {

class Cell;
class RobotModel;

// RULA (McAtamney & Corlett 1993, Applied Ergonomics 24(2):91-99) and REBA (Hignett & McAtamney
// 2000, Applied Ergonomics 31:201-205): the observational posture scores ergonomists use, from
// body-part angles and a few yes/no observations, through the methods' lookup tables, to RULA's
// grand score (1-7) and the REBA score (1-15). docs/ergonomic_scores.md describes both and the
// posture mapping below.
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

// ---- From hila's human model -------------------------------------------------------------------
//
// The posture of one arm of a human model built by generate_human_urdf (its joint names and
// axes), from a configuration in the model's variable order (what cell.human() and
// cell.human_neutral() use). Angles in degrees.
struct HumanArmAngles {
  double trunk_flexion = 0.0;  // torso_flexion: + forward bend
  // Angle between the upper arm and the torso's downward axis (0-180), negative when the arm
  // points behind the torso's frontal plane below shoulder height (extension). From the
  // shoulder joints: cos(elevation) = cos(flexion) cos(abduction).
  double upper_arm_elevation = 0.0;
  // Angle of the upper arm out of the sagittal plane through the shoulder, away from the body
  // positive (-90 to 90).
  double upper_arm_abduction = 0.0;
  double shoulder_rotation = 0.0;  // about the upper arm
  double elbow_flexion = 0.0;      // 0 straight
  double forearm_rotation = 0.0;   // forearm_pronation: + pronation
  double wrist_flexion = 0.0;      // + toward the palm
  double wrist_deviation = 0.0;    // + radial (toward the thumb)
  // The wrist's distance from the shoulder's sagittal plane, outward positive, and from the
  // body's midline (the torso's sagittal plane), toward this arm's side positive; metres, from
  // forward kinematics.
  double wrist_lateral_of_shoulder = 0.0;
  double wrist_lateral_of_midline = 0.0;
  double shoulder_lateral_of_midline = 0.0;
  bool forearm_rotation_near_end = false;  // beyond kTwistNearEndFraction of its joint limit
};

// Thresholds where RULA or REBA name a posture but give no angle.
inline constexpr double kAbductedDeg = 20.0;    // upper arm out to the side (the +-20 deg band)
inline constexpr double kArmRotatedDeg = 45.0;  // REBA "rotated": shoulder rotation
inline constexpr double kTwistNearEndFraction = 0.75;  // forearm rotation near its range's end
// "Out to the side": the wrist lateral of the shoulder by more than this fraction of the
// shoulder's distance from the midline.
inline constexpr double kOutToSideFraction = 0.5;

// Throws InputError (the model's source, the joint) when a joint of generate_human_urdf is
// missing, and InputError when `side` is not "left" or "right" or `q` is not a finite vector of
// the model's variables.
HumanArmAngles human_arm_angles(const RobotModel& human, const Eigen::VectorXd& q,
                                const std::string& side);

// RULA inputs for one arm holding `load_kg` (>= 0), its share when two hands hold it (half).
// Mapping: upper arm = upper_arm_elevation, abducted beyond kAbductedDeg; lower arm = elbow
// flexion, across the midline when the wrist crosses the body's midline, out to the side by
// kOutToSideFraction; wrist = wrist flexion, deviated beyond kNeutralBandDeg; wrist twist near
// the end by kTwistNearEndFraction; trunk = torso flexion. The model has no joint for the neck,
// the shoulder girdle, trunk twist or side bend, or the legs: neck upright and straight,
// shoulders not raised, trunk not twisted or side-bent, standing balanced on both feet. The arm
// is not supported; muscle use, load pattern and shock keep their defaults (set them on the
// result).
RulaInputs rula_inputs_from_posture(const RobotModel& human, const Eigen::VectorXd& q,
                                    const std::string& side, double load_kg, bool two_hands);

// REBA inputs likewise, with the whole load (REBA's load score is the body's, group A): upper
// arm abducted or rotated beyond kAbductedDeg or kArmRotatedDeg, wrist deviated or twisted as
// for RULA, knees straight, both feet bearing weight; coupling and activity keep their defaults.
RebaInputs reba_inputs_from_posture(const RobotModel& human, const Eigen::VectorXd& q,
                                    const std::string& side, double load_kg);

// The human's whole configuration (cell.human()'s variables) at a posture given by arm, what
// the functions above read: cell.human_neutral() with each named human arm's chain joints (rad,
// in the chain's order: a handover goal's stored human_joints, second_joints) set. Throws
// InputError for an arm the cell has not, or joints of the wrong count or not finite.
Eigen::VectorXd human_posture(
    const Cell& cell, const std::vector<std::pair<std::string, Eigen::VectorXd>>& arm_joints);

}  // namespace hila::core
