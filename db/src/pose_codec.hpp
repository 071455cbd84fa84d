#pragma once

#include <array>
#include <optional>
#include <string>

#include "hila/core/pose.hpp"

namespace hila::db::detail {

// A pose as the 7 stored columns (x, y, z, qw, qx, qy, qz).
using PoseColumns = std::array<double, 7>;

// Canonical quaternion: normalized, qw >= 0 (and, for a half turn with qw = 0, the first
// non-zero of qx, qy, qz positive), so equal rotations always store equal numbers.
PoseColumns encode_pose(const core::Pose& pose);

// Rebuilds the pose; nullopt if a value is not finite or the quaternion is not a unit one (1e-9),
// which only a damaged or hand-edited database contains.
std::optional<core::Pose> decode_pose(const PoseColumns& columns);

// The same 7 numbers as text, space-separated, each with 17 significant digits (a meta value);
// parse_pose_text reads them back (nullopt for anything else, as decode_pose).
std::string format_pose_text(const core::Pose& pose);
std::optional<core::Pose> parse_pose_text(const std::string& text);

}  // namespace hila::db::detail
