#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::core {

// One worker's body in a cell: the human model `hila human` makes for a stature and sex
// (generate_human_urdf), with the cell's human arms (the same names and links), standing where
// the cell's human would, and how the cell human's comfort maps serve it.
//
// `hila human` scales every segment with stature and keeps the joint limits, so the body's arm
// is a scaled copy of the cell human's arm about its shoulder; Q (paper Eq. 4, made
// dimensionless by the reach) is scale-invariant, so the body's hand at p (its arm base frame)
// is as comfortable as the cell human's at shoulder0 + (L0 / Lb) (p - shoulder_b) with the same
// orientation (to_cell_arm), L the arms' reaches. The constructor verifies the scaled-copy
// property by forward kinematics. Immutable; safe to share between threads.
class HumanBody {
 public:
  // Throws InputError (file `where`, field `field`) when the body's arms are not scaled copies of
  // the cell's human arms (a cell human not made by `hila human`, or another structure).
  HumanBody(const Cell& cell, const HumanBodySpec& spec, const std::string& where = "human bodies",
            const std::string& field = "");

  const HumanBodySpec& spec() const { return spec_; }
  std::string label() const;  // "1.5 female"
  const RobotModel& model() const { return model_; }
  // The cell's human arms on this body: the same names, links and order as cell.human_arms().
  const std::vector<HumanArm>& arms() const { return arms_; }
  // -1 for an arm the cell has not.
  int arm_index(const std::string& name) const;
  // The posture while the robot works: the cell's human.neutral_deg where the cell gives one
  // (the same joint order: both are models of `hila human`), else the body's own relaxed
  // standing posture (human_neutral_configuration).
  const Eigen::VectorXd& neutral() const { return neutral_; }
  // The arm's base link (the torso) in the human's floor frame at the neutral posture.
  const Pose& base_in_stance(int arm) const { return base_in_stance_[index(arm)]; }
  // The cell human's reach over this body's (characteristic_length of the arm chains).
  double scale(int arm) const { return scale_[index(arm)]; }
  // Where the cell human's comfort map (the cell arm's base frame) serves this body's hand at
  // `hand_in_base` (this body's arm base frame): the position scaled about the shoulders, the
  // orientation kept.
  Pose to_cell_arm(int arm, const Pose& hand_in_base) const;
  // Whether this body is the cell's human itself to 1e-12 (the same reach, shoulders and torso
  // poses): its goals, maps and postures are the database's as stored.
  bool same_as_cell() const { return same_as_cell_; }
  // The whole configuration from arms' chain joints (the rest at neutral()), as
  // core::human_posture does for the cell's human. Throws InputError for an unknown arm or a
  // wrong joint count.
  Eigen::VectorXd posture(
      const std::vector<std::pair<std::string, Eigen::VectorXd>>& arm_joints) const;

 private:
  std::size_t index(int arm) const { return static_cast<std::size_t>(arm); }

  HumanBodySpec spec_;
  RobotModel model_;
  std::vector<HumanArm> arms_;
  Eigen::VectorXd neutral_;
  std::vector<Pose> base_in_stance_;
  std::vector<Eigen::Vector3d> shoulder_, cell_shoulder_;
  std::vector<double> scale_;
  bool same_as_cell_ = false;
};

// "1.5 female" (format_number of the stature).
std::string human_body_label(const HumanBodySpec& spec);

// The heights (m, world z) between which a worker holds a part in a natural posture: from the
// hip (the arms' base link, the lower of the two) to the shoulder (the arms' first joint, the
// higher), at the neutral posture standing at `stance`. `body` nullptr: the cell's human.
struct HeightBand {
  double hip_z = 0.0;
  double shoulder_z = 0.0;
  bool contains(double z) const { return z >= hip_z && z <= shoulder_z; }
};
HeightBand natural_height_band(const Cell& cell, const HumanBody* body, const Pose& stance);

}  // namespace hila::core
