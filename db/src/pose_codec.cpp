#include "pose_codec.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace hila::db::detail {

PoseColumns encode_pose(const core::Pose& pose) {
  Eigen::Quaterniond q(pose.linear());
  q.normalize();
  // q and -q are the same rotation: pick one sign so the stored bytes are deterministic.
  double sign = 1.0;
  if (q.w() != 0.0) {
    sign = q.w() < 0.0 ? -1.0 : 1.0;
  } else if (q.x() != 0.0) {
    sign = q.x() < 0.0 ? -1.0 : 1.0;
  } else if (q.y() != 0.0) {
    sign = q.y() < 0.0 ? -1.0 : 1.0;
  } else {
    sign = q.z() < 0.0 ? -1.0 : 1.0;
  }
  const Eigen::Vector3d& t = pose.translation();
  // "+ 0.0" turns -0.0 into +0.0; SQLite would not keep the sign anyway.
  return {t.x(),
          t.y(),
          t.z(),
          sign * q.w() + 0.0,
          sign * q.x() + 0.0,
          sign * q.y() + 0.0,
          sign * q.z() + 0.0};
}

std::optional<core::Pose> decode_pose(const PoseColumns& c) {
  for (double value : c) {
    if (!std::isfinite(value)) return std::nullopt;
  }
  Eigen::Quaterniond q(c[3], c[4], c[5], c[6]);
  if (std::abs(q.norm() - 1.0) > 1e-9) return std::nullopt;
  q.normalize();
  core::Pose pose = core::Pose::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Eigen::Vector3d(c[0], c[1], c[2]);
  return pose;
}

std::string format_pose_text(const core::Pose& pose) {
  std::string text;
  char number[32];
  for (const double value : encode_pose(pose)) {
    std::snprintf(number, sizeof(number), "%.17g", value);
    if (!text.empty()) text += ' ';
    text += number;
  }
  return text;
}

std::optional<core::Pose> parse_pose_text(const std::string& text) {
  PoseColumns columns{};
  const char* at = text.data();
  const char* const end = text.data() + text.size();
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) {
      if (at == end || *at != ' ') return std::nullopt;
      ++at;
    }
    const auto [next, error] = std::from_chars(at, end, columns[i]);
    if (error != std::errc()) return std::nullopt;
    at = next;
  }
  if (at != end) return std::nullopt;
  return decode_pose(columns);
}

}  // namespace hila::db::detail
