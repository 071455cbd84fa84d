#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <initializer_list>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/error.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/robot_model.hpp"
#include "util/test_util.hpp"

using namespace hila;

// ---- Worked examples ----------------------------------------------------------------------------
//
// Each example states its source and asserts every score the source publishes. The inputs are
// angles inside the published band of each body-part score and the observations (flags) the
// source reports.

namespace {

// Asserts the scores a source publishes, written as it prints them: "name value, name value".
// `names` lists the scores in the order of `got`; scores the source does not publish are not
// asserted.
void expect_published(const std::string& names, const std::vector<int>& got,
                      const std::string& published) {
  std::vector<std::string> known;
  std::istringstream name_list(names);
  for (std::string name; std::getline(name_list, name, ',');) {
    known.push_back(name.substr(name.find_first_not_of(' ')));
  }
  ASSERT_EQ(known.size(), got.size());
  std::istringstream items(published);
  for (std::string item; std::getline(items, item, ',');) {
    const size_t begin = item.find_first_not_of(' '), value_at = item.find_last_of(' ');
    const std::string name = item.substr(begin, value_at - begin);
    const auto at = std::find(known.begin(), known.end(), name);
    ASSERT_NE(at, known.end()) << "no score named '" << name << "'";
    EXPECT_EQ(got[at - known.begin()], std::stoi(item.substr(value_at + 1))) << name;
  }
}

const std::string kRulaScores =
    "upper arm, lower arm, wrist, wrist twist, posture A, force/load, score C, neck, trunk, legs, "
    "posture B, score D, grand";
const std::string kRebaScores =
    "neck, trunk, legs, Table A, load/force, score A, upper arm, lower arm, wrist, Table B, "
    "score B, Table C, coupling, activity, REBA";

std::vector<int> scores_of(const core::RulaScore& s) {
  return {s.upper_arm, s.lower_arm, s.wrist, s.wrist_twist, s.posture_a, s.force_load, s.score_c,
          s.neck,      s.trunk,     s.legs,  s.posture_b,   s.score_d,   s.grand};
}

std::vector<int> scores_of(const core::RebaScore& s) {
  return {s.neck,    s.trunk,     s.legs,      s.posture_a, s.load_force,
          s.score_a, s.upper_arm, s.lower_arm, s.wrist,     s.posture_b,
          s.score_b, s.score_c,   s.coupling,  s.activity,  s.reba};
}

void expect_rula(const core::RulaInputs& in, const std::string& published) {
  expect_published(kRulaScores, scores_of(core::rula(in)), published);
}

void expect_reba(const core::RebaInputs& in, const std::string& published) {
  expect_published(kRebaScores, scores_of(core::reba(in)), published);
}

}  // namespace

// REBA, "Pose Left" and "Pose Right" of the ergonomics-metrics package's README
// (https://github.com/rs9000/ergonomics, also https://pypi.org/project/ergonomics-metrics/): neck
// 2, trunk 2, legs 2, upper arm 1, lower arm 2, wrist 3 (left) or 2 (right); score A 4, score B 3
// (left) or 2 (right), score C 4, REBA 4. No load, coupling or activity points are published
// (score A = Table A, score B = Table B, REBA = score C). The README gives scores, not angles:
// the angles below are two different postures in the same bands.
TEST(ErgonomicScores, RebaWorkedExampleErgonomicsMetricsPoses) {
  core::RebaInputs left;
  left.neck_flexion_deg = 25.0;       // > 20 deg flexion: 2
  left.trunk_flexion_deg = 12.0;      // 0-20 deg flexion: 2
  left.legs_bilateral = false;        // one leg bearing the weight: 2
  left.upper_arm_flexion_deg = 10.0;  // within +-20 deg: 1
  left.lower_arm_flexion_deg = 30.0;  // < 60 deg: 2
  left.wrist_flexion_deg = 25.0;      // > 15 deg: 2, deviated + 1
  left.wrist_deviated_or_twisted = true;
  expect_reba(left,
              "neck 2, trunk 2, legs 2, score A 4, upper arm 1, lower arm 2, wrist 3, score B 3, "
              "Table C 4, REBA 4");
  EXPECT_STREQ(core::reba_risk_level(core::reba(left).reba), "medium");

  core::RebaInputs right;
  right.neck_flexion_deg = -10.0;       // in extension: 2
  right.trunk_flexion_deg = -12.0;      // 0-20 deg extension: 2
  right.knee_flexion_deg = 45.0;        // both feet down (1), knees 30-60 deg (+1): 2
  right.upper_arm_flexion_deg = -15.0;  // 1
  right.lower_arm_flexion_deg = 120.0;  // > 100 deg: 2
  right.wrist_flexion_deg = -20.0;      // > 15 deg extension: 2
  expect_reba(right,
              "neck 2, trunk 2, legs 2, score A 4, upper arm 1, lower arm 2, wrist 2, score B 2, "
              "Table C 4, REBA 4");
}

// REBA, the example of Ergonomics Plus, "REBA: A Step-by-Step Guide"
// (https://ergo-plus.com/reba-assessment-tool-guide/; the example's notes as reproduced in the
// presentation https://www.scribd.com/presentation/331248872/Rapid-Entire-Body-Assessment-REBA):
// trunk 0-20 deg (+2) side-bent about 10 deg (+1) = 3; right upper arm raised above 90 deg (+4)
// with the shoulder raised (+1) and the arm abducted (+1) = 6; lower arm outside 60-100 deg = 2;
// wrist +2 with a twist (+1) = 3; final REBA 9, and 4 after the change of method. The guide's
// text does not give the neck, legs, load, coupling and activity scores (only its worksheet
// image does), so the final 9 is not asserted; Table B for 6 / 2 / 3 is 9 (its worksheet's
// Table B).
TEST(ErgonomicScores, RebaWorkedExampleErgoPlusGuide) {
  core::RebaInputs in;
  in.trunk_flexion_deg = 15.0;
  in.trunk_side_bent = true;
  in.upper_arm_flexion_deg = 120.0;
  in.shoulder_raised = true;
  in.upper_arm_abducted_or_rotated = true;
  in.lower_arm_flexion_deg = 30.0;
  in.wrist_flexion_deg = 30.0;
  in.wrist_deviated_or_twisted = true;
  expect_reba(in, "trunk 3, upper arm 6, lower arm 2, wrist 3, Table B 9");
  EXPECT_STREQ(core::reba_risk_level(9), "high");
  EXPECT_STREQ(core::reba_risk_level(4), "medium");
}

// RULA, statements of McAtamney & Corlett (1993), "RULA: a survey method for the investigation
// of work-related upper limb disorders", Applied Ergonomics 24(2):91-99, stage 3: "For a grand
// score of 1 or 2, the working posture would have scored 2 or less for both body segment groups A
// and B, and the scores for muscle use and force would be 0." Checked over every cell: a grand
// score of 1-2 exactly when score C and score D are both 2 or less; and on postures.
TEST(ErgonomicScores, RulaPaperGrandScoreOneOrTwoOnlyForLowScores) {
  for (int c = 1; c <= 13; ++c) {
    for (int d = 1; d <= 13; ++d) {
      EXPECT_EQ(core::rula_table_c(c, d) <= 2, c <= 2 && d <= 2) << "C " << c << " D " << d;
    }
  }
  core::RulaInputs in;  // every body part in its best band
  in.lower_arm_flexion_deg = 90.0;
  expect_rula(in, "posture A 1, posture B 1, grand 1");
  EXPECT_EQ(core::rula_action_level(1), 1);
  in.lower_arm_flexion_deg = 30.0;  // posture A 2: still 1-2
  expect_rula(in, "posture A 2, grand 2");
  in.muscle_use = true;  // the same posture held: no longer 1-2
  expect_rula(in, "score C 3, score D 2, grand 3");
  in.muscle_use = false;
  in.load_kg = 2.5;  // a force score: no longer 1-2
  expect_rula(in, "force/load 1, grand 3");
}

// RULA force/load score as the paper's text defines it (stage 2): 0 for an intermittent load
// under 2 kg; 1 for 2-10 kg intermittent; 2 for 2-10 kg static or repeated, "also 2 if the load
// is intermittent but more than 10 kg"; 3 for more than 10 kg static or repeated, and "if a load
// or force of any magnitude is experienced with rapid build-up or a jolting action the score is
// also 3". The worksheets' "more than 22 lbs: +3" simplifies the intermittent case.
TEST(ErgonomicScores, RulaPaperForceLoadScore) {
  const auto force = [](double kg, core::LoadPattern pattern, bool shock) {
    core::RulaInputs in;
    in.load_kg = kg;
    in.load_pattern = pattern;
    in.load_shock = shock;
    return core::rula(in).force_load;
  };
  using P = core::LoadPattern;
  EXPECT_EQ(force(1.9, P::Intermittent, false), 0);
  EXPECT_EQ(force(2.0, P::Intermittent, false), 1);
  EXPECT_EQ(force(10.0, P::Intermittent, false), 1);
  EXPECT_EQ(force(6.0, P::Static, false), 2);
  EXPECT_EQ(force(6.0, P::Repeated, false), 2);
  EXPECT_EQ(force(10.5, P::Intermittent, false), 2);
  EXPECT_EQ(force(10.5, P::Static, false), 3);
  EXPECT_EQ(force(10.5, P::Repeated, false), 3);
  EXPECT_EQ(force(0.5, P::Intermittent, true), 3);
}

// RULA worked through the worksheet step by step (McAtamney & Corlett 1993, Tables 1 and 2 and
// the grand-score table; the same values as the RULA Employee Assessment Worksheet,
// https://ergo-plus.com/wp-content/uploads/RULA.pdf). These are not published examples: no
// complete published RULA example (every sub-score with the grand score) could be retrieved
// for this change.
TEST(ErgonomicScores, RulaWorksheetStepByStep) {
  // A keyboard operator: upper arm 30 deg flexion (2), elbow 70 deg (1), wrist 10 deg extension
  // (2), wrist twist mid-range (1): Table A 3, + muscle use (repeated > 4/min) = 4; neck 15 deg
  // (2), trunk upright (1), legs supported (1): Table B 2, + 1 = 3; Table C row 4, column 3: 3.
  core::RulaInputs typing;
  typing.upper_arm_flexion_deg = 30.0;
  typing.lower_arm_flexion_deg = 70.0;
  typing.wrist_flexion_deg = -10.0;
  typing.neck_flexion_deg = 15.0;
  typing.muscle_use = true;
  expect_rula(typing,
              "upper arm 2, lower arm 1, wrist 2, wrist twist 1, posture A 3, score C 4, neck 2, "
              "trunk 1, legs 1, posture B 2, score D 3, grand 3");
  EXPECT_STREQ(core::rula_action(3), "investigate further");

  // Reaching to a high shelf: upper arm 100 deg (4) with the shoulder raised (+1) = 5, elbow 20
  // deg (2) out to the side (+1) = 3, wrist 20 deg flexed (3) and deviated (+1) = 4, twist near
  // the end (2): Table A 8, + muscle use 1 + a 6 kg box held static (2) = 11; neck 25 deg
  // extension (4), trunk 30 deg (3) twisted (+1) = 4, standing on one leg (2): Table B 7, + 3 =
  // 10; Table C row 8+, column 7+: 7.
  core::RulaInputs reach;
  reach.upper_arm_flexion_deg = 100.0;
  reach.shoulder_raised = true;
  reach.lower_arm_flexion_deg = 20.0;
  reach.arm_across_midline_or_out_to_side = true;
  reach.wrist_flexion_deg = 20.0;
  reach.wrist_deviated = true;
  reach.wrist_twist_near_end = true;
  reach.neck_flexion_deg = -25.0;
  reach.trunk_flexion_deg = 30.0;
  reach.trunk_twisted = true;
  reach.legs_supported = false;
  reach.muscle_use = true;
  reach.load_kg = 6.0;
  reach.load_pattern = core::LoadPattern::Static;
  expect_rula(reach,
              "upper arm 5, lower arm 3, wrist 4, wrist twist 2, posture A 8, force/load 2, "
              "score C 11, neck 4, trunk 4, legs 2, posture B 7, score D 10, grand 7");
  EXPECT_EQ(core::rula_action_level(7), 4);

  // Leaning on the elbow: upper arm 50 deg (3) supported (-1) = 2, elbow 110 deg (2), wrist
  // straight (1): Table A 3, + a 3 kg intermittent load (1) = 4; neck 5 deg (1), trunk 10 deg
  // (2), legs supported (1): Table B 2, + 1 = 3; Table C row 4, column 3: 3.
  core::RulaInputs lean;
  lean.upper_arm_flexion_deg = 50.0;
  lean.arm_supported = true;
  lean.lower_arm_flexion_deg = 110.0;
  lean.neck_flexion_deg = 5.0;
  lean.trunk_flexion_deg = 10.0;
  lean.load_kg = 3.0;
  expect_rula(
      lean,
      "upper arm 2, lower arm 2, wrist 1, posture A 3, score C 4, posture B 2, score D 3, grand 3");
}

// REBA worked through the worksheet (Hignett & McAtamney 2000; the REBA Employee Assessment
// Worksheet's Tables A-C), likewise not a published example: lifting a 12 kg box from a low
// shelf. Neck 30 deg (2) twisted and side-bent (+1, one point for either) = 3; trunk 70 deg (4)
// twisted (+1) = 5; both feet, knees 70 deg (1 + 2) = 3: Table A 9, + load over 10 kg (2) with a
// jerk (+1) = 12. Upper arm 50 deg (3), elbow 90 deg (1), wrist 10 deg (1): Table B 3, + poor
// coupling (2) = 5. Table C row 12, column 5: 12, + static and rapid changes (2) = 14.
TEST(ErgonomicScores, RebaWorksheetStepByStep) {
  core::RebaInputs in;
  in.neck_flexion_deg = 30.0;
  in.neck_twisted = true;
  in.neck_side_bent = true;
  in.trunk_flexion_deg = 70.0;
  in.trunk_twisted = true;
  in.knee_flexion_deg = 70.0;
  in.load_kg = 12.0;
  in.load_shock = true;
  in.upper_arm_flexion_deg = 50.0;
  in.lower_arm_flexion_deg = 90.0;
  in.wrist_flexion_deg = 10.0;
  in.coupling = core::Coupling::Poor;
  in.static_posture = true;
  in.rapid_changes = true;
  expect_reba(in,
              "neck 3, trunk 5, legs 3, Table A 9, load/force 3, score A 12, upper arm 3, "
              "lower arm 1, wrist 1, Table B 3, score B 5, Table C 12, activity 2, REBA 14");
  EXPECT_STREQ(core::reba_risk_level(14), "very high");
  in.sitting = true;  // knees beyond 60 deg while sitting: no leg points
  expect_reba(in, "legs 1");
}

// ---- Tables -------------------------------------------------------------------------------------

TEST(ErgonomicScores, TablesAtTheirCorners) {
  // {sub-scores..., value}: each table's best and worst cells and the ends of its first index.
  const int rula_a[][5] = {{1, 1, 1, 1, 1}, {1, 3, 4, 2, 4}, {6, 1, 1, 1, 7}, {6, 3, 4, 2, 9}};
  for (const auto& c : rula_a) EXPECT_EQ(core::rula_table_a(c[0], c[1], c[2], c[3]), c[4]);
  const int rula_b[][4] = {{1, 1, 1, 1}, {1, 6, 2, 7}, {6, 1, 1, 8}, {6, 6, 2, 9}};
  for (const auto& c : rula_b) EXPECT_EQ(core::rula_table_b(c[0], c[1], c[2]), c[3]);
  // Table C's "8+" row and "7+" column take every higher score.
  const int rula_c[][3] = {{1, 1, 1}, {1, 7, 5}, {8, 1, 5}, {8, 7, 7}, {13, 12, 7}, {12, 1, 5}};
  for (const auto& c : rula_c) EXPECT_EQ(core::rula_table_c(c[0], c[1]), c[2]);
  const int reba_a[][4] = {{1, 1, 1, 1}, {1, 3, 1, 3}, {1, 1, 4, 4}, {5, 1, 1, 4}, {5, 3, 4, 9}};
  for (const auto& c : reba_a) EXPECT_EQ(core::reba_table_a(c[0], c[1], c[2]), c[3]);
  const int reba_b[][4] = {{1, 1, 1, 1}, {1, 2, 3, 3}, {6, 1, 1, 7}, {6, 2, 3, 9}};
  for (const auto& c : reba_b) EXPECT_EQ(core::reba_table_b(c[0], c[1], c[2]), c[3]);
  const int reba_c[][3] = {{1, 1, 1}, {1, 12, 7}, {12, 1, 12}, {12, 12, 12}};
  for (const auto& c : reba_c) EXPECT_EQ(core::reba_table_c(c[0], c[1]), c[2]);
  // Outside a table: an input error naming the table and the sub-score.
  test::expect_input_error([] { core::rula_table_a(7, 1, 1, 1); }, {"RULA Table A", "upper arm"});
  test::expect_input_error([] { core::rula_table_b(1, 1, 3); }, {"RULA Table B", "legs", "got 3"});
  test::expect_input_error([] { core::rula_table_c(0, 1); }, {"RULA Table C", "score C"});
  test::expect_input_error([] { core::reba_table_a(1, 4, 1); }, {"REBA Table A", "neck"});
  test::expect_input_error([] { core::reba_table_b(1, 3, 1); }, {"REBA Table B", "lower arm"});
  test::expect_input_error([] { core::reba_table_c(13, 1); }, {"REBA Table C", "score A"});
}

namespace {

// Every cell of a table of any rank, with its neighbour one step up along each index: the value
// never falls. `dims` are the sizes, `lookup` reads a cell by 1-based indices.
void expect_monotone(const std::string& name, const std::vector<int>& dims,
                     const std::function<int(const std::vector<int>&)>& lookup) {
  std::vector<int> idx(dims.size(), 1);
  int cells = 0;
  while (true) {
    const int here = lookup(idx);
    for (size_t k = 0; k < dims.size(); ++k) {
      if (idx[k] == dims[k]) continue;
      std::vector<int> up = idx;
      ++up[k];
      EXPECT_GE(lookup(up), here) << name << " falls along index " << k << " at cell " << cells;
    }
    ++cells;
    size_t k = 0;
    while (k < dims.size() && idx[k] == dims[k]) idx[k++] = 1;
    if (k == dims.size()) break;
    ++idx[k];
  }
}

}  // namespace

// A worse body-part score never lowers a table's value: every cell of the six tables.
TEST(ErgonomicScores, TablesNeverFallAsASubScoreRises) {
  expect_monotone("RULA Table A", {6, 3, 4, 2}, [](const std::vector<int>& i) {
    return core::rula_table_a(i[0], i[1], i[2], i[3]);
  });
  expect_monotone("RULA Table B", {6, 6, 2},
                  [](const std::vector<int>& i) { return core::rula_table_b(i[0], i[1], i[2]); });
  expect_monotone("RULA Table C", {10, 10},
                  [](const std::vector<int>& i) { return core::rula_table_c(i[0], i[1]); });
  expect_monotone("REBA Table A", {5, 3, 4},
                  [](const std::vector<int>& i) { return core::reba_table_a(i[0], i[1], i[2]); });
  expect_monotone("REBA Table B", {6, 2, 3},
                  [](const std::vector<int>& i) { return core::reba_table_b(i[0], i[1], i[2]); });
  expect_monotone("REBA Table C", {12, 12},
                  [](const std::vector<int>& i) { return core::reba_table_c(i[0], i[1]); });
}

namespace {

// Moves an angle away from its best value (`neutral`) by `step` degrees, staying within 180.
double away(double deg, double neutral, double step) {
  const double moved = deg >= neutral ? deg + step : deg - step;
  return std::clamp(moved, -180.0, 180.0);
}

// Copies of `base`, each worse in one respect: a flag of `worse_true` set, one of `worse_false`
// cleared, an angle of `from_zero` moved `step` further from 0.
template <class Inputs>
std::vector<Inputs> made_worse(const Inputs& base, std::initializer_list<bool Inputs::*> worse_true,
                               std::initializer_list<bool Inputs::*> worse_false,
                               std::initializer_list<double Inputs::*> from_zero, double step) {
  std::vector<Inputs> out;
  for (bool Inputs::*flag : worse_true) (out.emplace_back(base).*flag) = true;
  for (bool Inputs::*flag : worse_false) (out.emplace_back(base).*flag) = false;
  for (double Inputs::*deg : from_zero) (out.emplace_back(base).*deg) = away(base.*deg, 0, step);
  // The lower arm scores best at 60-100 deg.
  out.emplace_back(base).lower_arm_flexion_deg = away(base.lower_arm_flexion_deg, 80, step);
  out.emplace_back(base).load_kg += step / 4;
  return out;
}

template <class Inputs>
void randomize(Inputs& in, std::mt19937_64& rng, std::initializer_list<bool Inputs::*> flags,
               std::initializer_list<double Inputs::*> angles) {
  std::bernoulli_distribution coin(0.3);
  std::uniform_real_distribution<double> deg(-60.0, 60.0), kg(0.0, 15.0);
  for (bool Inputs::*flag : flags) in.*flag = coin(rng);
  for (double Inputs::*angle : angles) in.*angle = deg(rng);
  in.upper_arm_flexion_deg *= 2;
  in.lower_arm_flexion_deg = 75 + 1.25 * in.lower_arm_flexion_deg;  // 0-150 deg
  in.load_kg = kg(rng);
}

void expect_no_score_falls(const std::string& names, const std::vector<int>& before,
                           const std::vector<int>& after) {
  for (size_t i = 0; i < before.size(); ++i) {
    EXPECT_GE(after[i], before[i]) << "score " << i << " of " << names;
  }
}

}  // namespace

// Random postures (fixed seed); each is made worse in one respect at a time (an angle further
// from neutral, an adjustment that applies, a heavier or more sustained load, a worse coupling,
// more activity): no score falls, from the body part up to the grand score.
TEST(ErgonomicScores, AWorsePostureNeverLowersTheScore) {
  using R = core::RulaInputs;
  using B = core::RebaInputs;
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> step(0.5, 40.0);
  for (int trial = 0; trial < 3000; ++trial) {
    SCOPED_TRACE("trial " + std::to_string(trial));
    const double d = step(rng);
    R r;
    randomize(r, rng,
              {&R::shoulder_raised, &R::upper_arm_abducted, &R::arm_supported,
               &R::arm_across_midline_or_out_to_side, &R::wrist_deviated, &R::wrist_twist_near_end,
               &R::neck_twisted, &R::neck_side_bent, &R::trunk_twisted, &R::trunk_side_bent,
               &R::legs_supported, &R::muscle_use, &R::load_shock},
              {&R::upper_arm_flexion_deg, &R::lower_arm_flexion_deg, &R::wrist_flexion_deg,
               &R::neck_flexion_deg, &R::trunk_flexion_deg});
    r.load_pattern = rng() % 2 ? core::LoadPattern::Static : core::LoadPattern::Intermittent;
    std::vector<R> worse = made_worse(
        r,
        {&R::shoulder_raised, &R::upper_arm_abducted, &R::arm_across_midline_or_out_to_side,
         &R::wrist_deviated, &R::wrist_twist_near_end, &R::neck_twisted, &R::neck_side_bent,
         &R::trunk_twisted, &R::trunk_side_bent, &R::muscle_use, &R::load_shock},
        {&R::arm_supported, &R::legs_supported},
        {&R::upper_arm_flexion_deg, &R::wrist_flexion_deg, &R::trunk_flexion_deg}, d);
    worse.emplace_back(r).load_pattern = core::LoadPattern::Repeated;
    // The neck scores extension 4: further forward is worse from upright or flexion, further
    // back from upright or extension.
    if (r.neck_flexion_deg >= 0) worse.emplace_back(r).neck_flexion_deg += d;
    if (r.neck_flexion_deg <= 0) worse.emplace_back(r).neck_flexion_deg -= d;
    for (const R& w : worse) {
      expect_no_score_falls(kRulaScores, scores_of(core::rula(r)), scores_of(core::rula(w)));
    }

    B b;
    randomize(
        b, rng,
        {&B::neck_twisted, &B::neck_side_bent, &B::trunk_twisted, &B::trunk_side_bent,
         &B::legs_bilateral, &B::load_shock, &B::upper_arm_abducted_or_rotated, &B::shoulder_raised,
         &B::arm_supported, &B::wrist_deviated_or_twisted, &B::static_posture},
        {&B::neck_flexion_deg, &B::trunk_flexion_deg, &B::knee_flexion_deg,
         &B::upper_arm_flexion_deg, &B::lower_arm_flexion_deg, &B::wrist_flexion_deg});
    b.knee_flexion_deg = std::abs(b.knee_flexion_deg) * 1.5;
    b.coupling = static_cast<core::Coupling>(rng() % 3);
    std::vector<B> worse_b = made_worse(
        b,
        {&B::neck_side_bent, &B::trunk_twisted, &B::load_shock, &B::upper_arm_abducted_or_rotated,
         &B::shoulder_raised, &B::wrist_deviated_or_twisted, &B::repeated_small, &B::rapid_changes},
        {&B::legs_bilateral, &B::arm_supported},
        {&B::trunk_flexion_deg, &B::upper_arm_flexion_deg, &B::wrist_flexion_deg}, d);
    worse_b.emplace_back(b).coupling = core::Coupling::Unacceptable;
    worse_b.emplace_back(b).knee_flexion_deg += d;
    // In extension already the neck's worst: further forward only from upright or flexion.
    if (b.neck_flexion_deg >= 0) worse_b.emplace_back(b).neck_flexion_deg += d;
    for (const B& w : worse_b) {
      expect_no_score_falls(kRebaScores, scores_of(core::reba(b)), scores_of(core::reba(w)));
    }
  }
}

TEST(ErgonomicScores, ScoresStayInTheirPublishedRanges) {
  core::RulaInputs worst;
  worst.upper_arm_flexion_deg = 170;
  worst.shoulder_raised = worst.upper_arm_abducted = true;
  worst.lower_arm_flexion_deg = 5;
  worst.arm_across_midline_or_out_to_side = true;
  worst.wrist_flexion_deg = 60;
  worst.wrist_deviated = worst.wrist_twist_near_end = true;
  worst.neck_flexion_deg = -40;
  worst.neck_twisted = worst.neck_side_bent = true;
  worst.trunk_flexion_deg = 80;
  worst.trunk_twisted = worst.trunk_side_bent = true;
  worst.legs_supported = false;
  worst.muscle_use = true;
  worst.load_kg = 30;
  worst.load_pattern = core::LoadPattern::Static;
  expect_rula(
      worst,
      "upper arm 6, lower arm 3, wrist 4, posture A 9, neck 6, trunk 6, posture B 9, grand 7");
  core::RulaInputs supported;
  supported.arm_supported = true;  // 1 - 1 stays 1
  EXPECT_EQ(core::rula(supported).upper_arm, 1);

  core::RebaInputs b;
  b.neck_flexion_deg = 40;
  b.neck_twisted = b.neck_side_bent = true;
  b.trunk_flexion_deg = 80;
  b.trunk_twisted = b.trunk_side_bent = true;
  b.legs_bilateral = false;
  b.knee_flexion_deg = 90;
  b.load_kg = 20;
  b.load_shock = true;
  b.upper_arm_flexion_deg = 150;
  b.upper_arm_abducted_or_rotated = b.shoulder_raised = true;
  b.lower_arm_flexion_deg = 150;
  b.wrist_flexion_deg = 50;
  b.wrist_deviated_or_twisted = true;
  b.coupling = core::Coupling::Unacceptable;
  b.static_posture = b.repeated_small = b.rapid_changes = true;
  expect_reba(b, "neck 3, trunk 5, legs 4, score A 12, upper arm 6, wrist 3, score B 12, REBA 15");
  EXPECT_EQ(core::reba(core::RebaInputs{}).reba, 1);
  EXPECT_STREQ(core::reba_risk_level(1), "negligible");
  EXPECT_STREQ(core::reba_risk_level(15), "very high");
}

TEST(ErgonomicScores, OutOfDomainInputsAreInputErrors) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  test::expect_input_error(
      [&] {
        core::RulaInputs in;
        in.upper_arm_flexion_deg = nan;
        core::rula(in);
      },
      {"RULA inputs", "upper_arm_flexion_deg", "expected an angle", "got nan"});
  test::expect_input_error(
      [] {
        core::RulaInputs in;
        in.load_kg = -1.0;
        core::rula(in);
      },
      {"RULA inputs", "load_kg", "expected a load in kg >= 0", "got -1"});
  test::expect_input_error(
      [] {
        core::RebaInputs in;
        in.wrist_flexion_deg = std::numeric_limits<double>::infinity();
        core::reba(in);
      },
      {"REBA inputs", "wrist_flexion_deg", "got inf"});
  test::expect_input_error(
      [] {
        core::RebaInputs in;
        in.trunk_flexion_deg = 200.0;
        core::reba(in);
      },
      {"REBA inputs", "trunk_flexion_deg", "[-180, 180]", "got 200"});
  test::expect_input_error(
      [&] {
        core::RebaInputs in;
        in.load_kg = nan;
        core::reba(in);
      },
      {"REBA inputs", "load_kg", "got nan"});
  test::expect_input_error([] { core::reba_risk_level(16); }, {"REBA", "score", "got 16"});
  test::expect_input_error([] { core::rula_action_level(0); }, {"RULA", "grand score", "got 0"});
}

// ---- From hila's human model --------------------------------------------------------------------

namespace {

struct Body {
  core::RobotModel model;
  Eigen::VectorXd neutral;
};

Body body(const core::HumanBodySpec& spec) {
  auto model = core::RobotModel::load_urdf_string(core::generate_human_urdf(spec), "human");
  Eigen::VectorXd neutral = core::human_neutral_configuration(model);
  return {std::move(model), std::move(neutral)};
}

// The reference cell's human in its neutral posture (arms hanging) with some joints set (deg).
Eigen::VectorXd posed(const core::Cell& cell,
                      std::initializer_list<std::pair<std::string, double>> joint_deg) {
  const core::RobotModel& human = cell.human();
  Eigen::VectorXd q = cell.human_neutral();
  for (const auto& [joint, deg] : joint_deg) {
    q[human.joints()[human.joint_index(joint)].variable] = core::deg_to_rad(deg);
  }
  return q;
}

core::RulaScore rula_at(const core::Cell& cell, const Eigen::VectorXd& q, const std::string& side) {
  return core::rula(core::rula_inputs_from_posture(cell.human(), q, side, 0.0, false));
}

core::RebaScore reba_at(const core::Cell& cell, const Eigen::VectorXd& q, const std::string& side) {
  return core::reba(core::reba_inputs_from_posture(cell.human(), q, side, 0.0));
}

const std::string kSides[] = {"left", "right"};

}  // namespace

// The cell's human at its neutral posture (arms hanging) scores the lowest upper-arm, trunk and
// wrist scores on both sides; the 1.50 m woman's shoulders abduct by about a degree to clear her
// hips and still count as not abducted.
TEST(ErgonomicScores, NeutralPostureScoresTheMinimumUpperArmScore) {
  const auto cell = test::reference_cell();
  std::vector<Body> bodies;
  bodies.push_back({cell->human(), cell->human_neutral()});
  bodies.push_back(body({core::kFemaleStatureP5, core::Sex::Female}));
  for (const Body& b : bodies) {
    for (const std::string& side : kSides) {
      SCOPED_TRACE(side);
      const core::HumanArmAngles a = core::human_arm_angles(b.model, b.neutral, side);
      EXPECT_LT(std::abs(a.upper_arm_elevation), 2.0);
      EXPECT_FALSE(a.forearm_rotation_near_end);
      const core::RulaInputs in =
          core::rula_inputs_from_posture(b.model, b.neutral, side, 0.0, false);
      EXPECT_FALSE(in.upper_arm_abducted);
      EXPECT_FALSE(in.arm_across_midline_or_out_to_side);
      // Elbow straight: outside 60-100 deg (2); no neck or leg joints: upright, both feet (1).
      // Table A (1, 2, 1, 1) = 2, Table B (1, 1, 1) = 1, Table C (2, 1) = 2.
      expect_rula(in, "upper arm 1, lower arm 2, wrist 1, neck 1, trunk 1, legs 1, grand 2");
      // REBA Table B (1, 2, 1) = 1, Table A (1, 1, 1) = 1: the lowest score.
      expect_reba(core::reba_inputs_from_posture(b.model, b.neutral, side, 0.0),
                  "trunk 1, upper arm 1, REBA 1");
    }
  }
  // The woman's hanging arm is off the vertical (0.5-1 deg), the man's is not.
  EXPECT_GT(core::human_arm_angles(bodies[1].model, bodies[1].neutral, "left").upper_arm_elevation,
            0.4);
  EXPECT_EQ(core::human_arm_angles(bodies[0].model, bodies[0].neutral, "left").upper_arm_elevation,
            0.0);
}

TEST(ErgonomicScores, ShoulderFlexionAndTorsoFlexionGiveTheirBands) {
  const auto cell = test::reference_cell();
  for (const std::string& side : kSides) {
    SCOPED_TRACE(side);
    const std::string shoulder = side + "_shoulder_";
    const Eigen::VectorXd raised = posed(*cell, {{shoulder + "flexion", 100.0}});
    EXPECT_NEAR(core::human_arm_angles(cell->human(), raised, side).upper_arm_elevation, 100.0,
                1e-9);
    EXPECT_EQ(rula_at(*cell, raised, side).upper_arm, 4);  // > 90 deg
    EXPECT_EQ(reba_at(*cell, raised, side).upper_arm, 4);
    // Extension: the arm swung back 30 degrees scores "beyond 20 deg extension".
    const Eigen::VectorXd back = posed(*cell, {{shoulder + "flexion", -30.0}});
    EXPECT_NEAR(core::human_arm_angles(cell->human(), back, side).upper_arm_elevation, -30.0, 1e-9);
    EXPECT_EQ(rula_at(*cell, back, side).upper_arm, 2);
    // Abduction of 60 deg: raised 60 deg from the torso (3) and abducted (+1).
    const Eigen::VectorXd wide = posed(*cell, {{shoulder + "abduction", 60.0}});
    const core::HumanArmAngles a = core::human_arm_angles(cell->human(), wide, side);
    EXPECT_NEAR(a.upper_arm_elevation, 60.0, 1e-9);
    EXPECT_NEAR(a.upper_arm_abduction, 60.0, 1e-9);
    EXPECT_EQ(rula_at(*cell, wide, side).upper_arm, 4);

    const Eigen::VectorXd bent = posed(*cell, {{"torso_flexion", 30.0}});
    EXPECT_NEAR(core::human_arm_angles(cell->human(), bent, side).trunk_flexion, 30.0, 1e-9);
    EXPECT_EQ(rula_at(*cell, bent, side).trunk, 3);  // 20-60 deg
    EXPECT_EQ(reba_at(*cell, bent, side).trunk, 3);
    // Bending at the hip carries the hanging arms with the torso: relative to it they still hang.
    EXPECT_EQ(rula_at(*cell, bent, side).upper_arm, 1);
  }
}

// The upper-arm angle of the mapping (from the shoulder joints' values, closed form) against
// forward kinematics: the angle between the upper arm (shoulder to elbow, from RobotModel link
// poses) and the torso's downward axis, for random arm postures within the joint limits and a
// random torso flexion (fixed seed), on three bodies; extension where the elbow is behind the
// torso's frontal plane and below the shoulder.
TEST(ErgonomicScores, UpperArmAngleMatchesForwardKinematics) {
  std::mt19937_64 rng(4242);
  int extensions = 0;
  for (const core::HumanBodySpec spec :
       {core::HumanBodySpec{}, core::HumanBodySpec{core::kFemaleStatureP5, core::Sex::Female},
        core::HumanBodySpec{core::kTallStature, core::Sex::Male}}) {
    const Body b = body(spec);
    const core::RobotModel& human = b.model;
    const Eigen::VectorXd lo = human.lower_limits(), hi = human.upper_limits();
    const int torso_variable = human.joints()[human.joint_index("torso_flexion")].variable;
    std::vector<core::Pose> poses;
    for (int trial = 0; trial < 400; ++trial) {
      Eigen::VectorXd q(human.num_variables());
      for (int i = 0; i < q.size(); ++i) {
        q[i] = std::uniform_real_distribution<double>(lo[i], hi[i])(rng);
      }
      human.link_poses(q, poses);
      const core::Pose& torso = poses[human.link_index("torso")];
      for (const std::string& side : kSides) {
        const Eigen::Vector3d shoulder =
            poses[human.link_index(side + "_shoulder_flexion_link")].translation();
        const Eigen::Vector3d elbow = poses[human.link_index(side + "_elbow_link")].translation();
        const Eigen::Vector3d arm = torso.linear().transpose() * (elbow - shoulder).normalized();
        const double fk_deg = core::rad_to_deg(std::acos(std::clamp(-arm.z(), -1.0, 1.0)));
        const bool fk_extension = arm.x() < 0.0 && arm.z() < 0.0;
        extensions += fk_extension;
        const core::HumanArmAngles a = core::human_arm_angles(human, q, side);
        SCOPED_TRACE(side + " trial " + std::to_string(trial));
        EXPECT_NEAR(std::abs(a.upper_arm_elevation), fk_deg, 1e-6);
        EXPECT_EQ(a.upper_arm_elevation < 0.0, fk_extension && fk_deg > 1e-9);
        EXPECT_NEAR(a.trunk_flexion, core::rad_to_deg(q[torso_variable]), 1e-9);
        // The score follows the FK angle's band.
        const double signed_fk = fk_extension ? -fk_deg : fk_deg;
        const int band = signed_fk < -20   ? 2
                         : signed_fk <= 20 ? 1
                         : signed_fk <= 45 ? 2
                         : signed_fk <= 90 ? 3
                                           : 4;
        EXPECT_EQ(core::rula(core::rula_inputs_from_posture(human, q, side, 0.0, false)).upper_arm,
                  band + (a.upper_arm_abduction > core::kAbductedDeg));
      }
    }
  }
  EXPECT_GT(extensions, 20);  // the sample reaches the extension branch
}

// Upper arm forward and elbow bent 90 deg: the forearm points up in front of the shoulder (no
// lower-arm point); turned about the upper arm by 90 deg either way it points across the body or
// out to the side (+1), one direction each, and REBA counts the shoulder as rotated.
TEST(ErgonomicScores, ForearmAcrossTheBodyOrOutToTheSide) {
  const auto cell = test::reference_cell();
  for (const std::string& side : kSides) {
    SCOPED_TRACE(side);
    const auto reach = [&](double rotation_deg) {
      return posed(*cell, {{side + "_shoulder_flexion", 90.0},
                           {side + "_elbow_flexion", 90.0},
                           {side + "_shoulder_rotation", rotation_deg}});
    };
    const core::HumanArmAngles up = core::human_arm_angles(cell->human(), reach(0.0), side);
    EXPECT_NEAR(up.wrist_lateral_of_shoulder, 0.0, 0.02);
    EXPECT_EQ(rula_at(*cell, reach(0.0), side).lower_arm, 1);
    int across = 0, out = 0;
    for (const double rotation : {-90.0, 90.0}) {
      const core::HumanArmAngles a = core::human_arm_angles(cell->human(), reach(rotation), side);
      across += a.wrist_lateral_of_midline < 0.0;
      out += a.wrist_lateral_of_shoulder > core::kOutToSideFraction * a.shoulder_lateral_of_midline;
      EXPECT_EQ(rula_at(*cell, reach(rotation), side).lower_arm, 2);  // 90 deg elbow (1) + 1
      EXPECT_TRUE(core::reba_inputs_from_posture(cell->human(), reach(rotation), side, 0.0)
                      .upper_arm_abducted_or_rotated);
    }
    EXPECT_EQ(across, 1);
    EXPECT_EQ(out, 1);
  }
}

// Wrist, forearm and load: flexion and deviation read off their joints, the forearm near the end
// of its pronation range, half the load per hand for RULA's arm and the whole load for REBA.
TEST(ErgonomicScores, WristForearmAndLoadFromThePosture) {
  const auto cell = test::reference_cell();
  const core::RobotModel& human = cell->human();
  const Eigen::VectorXd q = posed(*cell, {{"right_wrist_flexion", 20.0},
                                          {"right_wrist_deviation", -10.0},
                                          {"right_forearm_pronation", 70.0}});  // limit 80
  const core::RulaInputs r = core::rula_inputs_from_posture(human, q, "right", 6.0, true);
  EXPECT_NEAR(r.wrist_flexion_deg, 20.0, 1e-9);
  EXPECT_TRUE(r.wrist_deviated);
  EXPECT_TRUE(r.wrist_twist_near_end);  // beyond 3/4 of the limit
  EXPECT_DOUBLE_EQ(r.load_kg, 3.0);
  expect_rula(r, "wrist 4, wrist twist 2, force/load 1");  // 3 kg intermittent
  EXPECT_DOUBLE_EQ(core::rula_inputs_from_posture(human, q, "right", 6.0, false).load_kg, 6.0);
  const core::RebaInputs b = core::reba_inputs_from_posture(human, q, "right", 6.0);
  EXPECT_DOUBLE_EQ(b.load_kg, 6.0);
  EXPECT_TRUE(b.wrist_deviated_or_twisted);
  expect_reba(b, "load/force 1");
  // The other arm is untouched.
  const core::RulaInputs left = core::rula_inputs_from_posture(human, q, "left", 6.0, true);
  EXPECT_FALSE(left.wrist_deviated);
  EXPECT_FALSE(left.wrist_twist_near_end);
  const Eigen::VectorXd mid = posed(*cell, {{"right_forearm_pronation", 40.0}});
  EXPECT_FALSE(
      core::rula_inputs_from_posture(human, mid, "right", 0.0, false).wrist_twist_near_end);
}

TEST(ErgonomicScores, PostureMappingRejectsBadInput) {
  const auto cell = test::reference_cell();
  const core::RobotModel& human = cell->human();
  const Eigen::VectorXd q = cell->human_neutral();
  test::expect_input_error([&] { core::human_arm_angles(human, q, "middle"); },
                           {"side", "\"left\" or \"right\"", "got \"middle\""});
  test::expect_input_error([&] { core::human_arm_angles(human, q.head(3), "left"); },
                           {"human configuration", "15 finite joint values", "got 3 values"});
  Eigen::VectorXd bad = q;
  bad[0] = std::nan("");
  test::expect_input_error([&] { core::rula_inputs_from_posture(human, bad, "left", 1.0, false); },
                           {"human configuration", "got a non-finite value"});
  test::expect_input_error([&] { core::rula_inputs_from_posture(human, q, "left", -2.0, false); },
                           {"load_kg", "expected a load in kg >= 0", "got -2"});
  test::expect_input_error([&] { core::reba_inputs_from_posture(human, q, "left", std::nan("")); },
                           {"load_kg", "got nan"});
  // A model without the generated human's joints (the robot's).
  const core::RobotModel& robot = cell->robot();
  test::expect_input_error(
      [&] { core::human_arm_angles(robot, Eigen::VectorXd::Zero(robot.num_variables()), "left"); },
      {"human joint", "'left_shoulder_flexion'"});
}

// A human arm's chain joints placed into the whole human configuration: the hand where the
// chain's forward kinematics puts it (relative to the arm's base link), every other variable at
// the neutral posture.
TEST(ErgonomicScores, HumanPostureSetsTheNamedArmsChainJoints) {
  const auto cell = test::reference_cell();
  ASSERT_EQ(cell->human_arms().size(), 2u);
  const core::HumanArm& left = cell->human_arms()[0];
  const Eigen::VectorXd neutral = cell->human_neutral();
  const Eigen::VectorXd arm_q =
      (0.3 * left.chain.lower_limits() + 0.7 * left.chain.upper_limits()).eval();
  const Eigen::VectorXd q = core::human_posture(*cell, {{left.spec.name, arm_q}});
  ASSERT_EQ(q.size(), neutral.size());
  std::vector<core::Pose> links;
  cell->human().link_poses(q, links);
  const core::Pose base = links[cell->human().link_index(left.spec.base_link)];
  const core::Pose tip = links[cell->human().link_index(left.spec.tip_link)];
  EXPECT_TRUE((base.inverse() * tip).isApprox(left.chain.fk(arm_q), 1e-9));
  std::vector<bool> arm_variable(static_cast<std::size_t>(q.size()), false);
  for (const int v : left.chain.model_variables()) arm_variable[static_cast<std::size_t>(v)] = true;
  for (Eigen::Index i = 0; i < q.size(); ++i) {
    if (!arm_variable[static_cast<std::size_t>(i)]) {
      EXPECT_EQ(q[i], neutral[i]) << i;
    }
  }
  EXPECT_EQ(core::human_posture(*cell, {}), neutral);
  EXPECT_THROW(core::human_posture(*cell, {{"middle", arm_q}}), core::InputError);
  EXPECT_THROW(core::human_posture(*cell, {{"left", Eigen::VectorXd::Zero(2)}}), core::InputError);
}
