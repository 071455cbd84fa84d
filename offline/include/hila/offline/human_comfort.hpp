#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/comfort_map.hpp"
#include "hila/core/human_body.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/pose.hpp"

namespace hila::offline {

// The comfort of hand poses given in the world, for the cell's human and, optionally, a set of
// other bodies standing at the same stance.
//
// A body of another stature is served by the cell human's maps: `hila human` scales every
// segment with stature and keeps the joint limits, so an arm of stature H is a scaled copy of the
// cell's arm about its shoulder, and Q (paper Eq. 4, made dimensionless by the reach) is
// scale-invariant. The hand position relative to that body's shoulder is scaled by the ratio of
// the reaches and looked up in the cell human's map. The constructor verifies the scaled-copy
// property by forward kinematics and rejects a body set that breaks it.
class HumanComfort {
 public:
  // `maps[i]` belongs to cell.human_arms()[i].
  HumanComfort(const core::Cell& cell, std::vector<core::ComfortMap> maps,
               const std::vector<core::HumanBodySpec>& bodies = {});

  int arm_count() const { return static_cast<int>(maps_.size()); }
  const std::string& arm_name(int arm) const { return arm_names_[static_cast<std::size_t>(arm)]; }
  int body_count() const { return static_cast<int>(bodies_.size()); }  // 0: the cell's human
  const core::ComfortMap& map(int arm) const { return maps_[static_cast<std::size_t>(arm)]; }

  // The cell's human arm base (torso, upright) in the world.
  const core::Pose& arm_base(int arm) const { return arm_base_[static_cast<std::size_t>(arm)]; }
  // Q of the cell's human with hand `arm` at `hand` (world), by map lookup.
  double quality(int arm, const core::Pose& hand) const;
  // Q of body `body` of the set.
  double body_quality(int body, int arm, const core::Pose& hand) const;
  const core::HumanBody& body(int b) const { return *bodies_[static_cast<std::size_t>(b)].body; }

 private:
  struct Body {
    std::shared_ptr<const core::HumanBody> body;  // its model and the scaled lookup
    std::vector<core::Pose> world_to_base;        // per arm: inverse of the torso pose
  };
  std::vector<core::ComfortMap> maps_;
  std::vector<std::string> arm_names_;
  std::vector<core::Pose> arm_base_;
  std::vector<core::Pose> world_to_base_;
  std::vector<Body> bodies_;
};

// The most bodies a set may have: each goal records which take it as bits of a 32-bit mask
// (HandoverCandidateRecord::bodies).
inline constexpr std::size_t kMaxHumanBodies = 32;

// Parses a body set: "STATURE[:SEX]" items joined by commas, e.g. "1.50:female,1.722,1.90:male"
// (sex defaults to male; stature in metres within [core::kMinStature, core::kMaxStature]).
// Throws InputError naming the command line, `field` and the item.
std::vector<core::HumanBodySpec> parse_human_bodies(const std::string& text,
                                                    const std::string& field);
// "1.5 female; 1.722 male": the stored form.
std::string format_human_bodies(const std::vector<core::HumanBodySpec>& bodies);
// The stored form read back (meta.human_bodies of the database `file`). Throws InputError naming
// `file` and meta.human_bodies for an item that is not "STATURE SEX" within the human model's
// statures.
std::vector<core::HumanBodySpec> parse_stored_human_bodies(const std::string& stored,
                                                           const std::string& file);

}  // namespace hila::offline
