#include "hila/online/validator.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <sstream>
#include <system_error>
#include <thread>

#include "hila/core/arm_poser.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"

namespace hila::online {

namespace {

class Reporter {
 public:
  explicit Reporter(ValidationReport& report) : report_(report) {}
  void add(const std::string& kind, double time, const std::string& detail) {
    for (const auto& v : report_.violations) {
      if (v.kind == kind) return;  // the first of each kind
    }
    report_.violations.push_back({kind, time, detail});
  }

 private:
  ValidationReport& report_;
};

std::string joint_text(int joint, double value, double limit, const char* unit) {
  std::ostringstream s;
  s.precision(4);
  s << "joint " << joint + 1 << ": " << value << " " << unit << " against " << limit;
  return s.str();
}

int sample_kind_order(const std::string& kind) {
  return kind == "joint_limit" ? 0 : kind == "slip" ? 1 : 2;
}

const core::Arm* find_arm(const core::Cell& cell, const std::string& name, std::size_t& index) {
  for (std::size_t i = 0; i < cell.arms().size(); ++i) {
    if (cell.arms()[i].spec.name == name) {
      index = i;
      return &cell.arms()[i];
    }
  }
  return nullptr;
}

}  // namespace

MotionValidation::MotionValidation(const World& world, const Motion& motion,
                                   const ValidatorSettings& settings)
    : world_(world), motion_(motion), settings_(settings) {
  Reporter violation(head_);
  arm_ = find_arm(world.cell(), motion.arm, arm_index_);
  if (arm_ == nullptr) {
    violation.add("format", 0.0, "unknown arm '" + motion.arm + "'");
    return;
  }
  const int dof = arm_->chain.dof();
  const std::size_t n = motion.q.size();
  if (n == 0 || motion.time.size() != n) {
    violation.add("format", 0.0, "expected one time per waypoint and at least one waypoint");
    return;
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (motion.q[i].size() != dof || !motion.q[i].allFinite() || !std::isfinite(motion.time[i]) ||
        (i > 0 && !(motion.time[i] > motion.time[i - 1]))) {
      violation.add("format", motion.time[i],
                    "waypoint " + std::to_string(i) +
                        ": expected finite joints of the arm's size at an increasing time");
      return;
    }
  }

  // Rates: velocity between waypoints, acceleration between consecutive velocities.
  const auto& vmax = arm_->spec.max_velocity;
  const auto& amax = arm_->spec.max_acceleration;
  Eigen::VectorXd previous_velocity;
  for (std::size_t i = 1; i < n; ++i) {
    const double dt = motion.time[i] - motion.time[i - 1];
    const Eigen::VectorXd v = (motion.q[i] - motion.q[i - 1]) / dt;
    for (int j = 0; j < dof && vmax.size() == dof; ++j) {
      if (std::abs(v[j]) > vmax[j] * (1.0 + settings.rate_tolerance)) {
        violation.add("velocity", motion.time[i], joint_text(j, std::abs(v[j]), vmax[j], "rad/s"));
      }
    }
    if (previous_velocity.size() == dof && amax.size() == dof) {
      const double mid = 0.5 * (motion.time[i] - motion.time[std::max<std::size_t>(i, 2) - 2]);
      const Eigen::VectorXd a = (v - previous_velocity) / std::max(mid, 1e-12);
      for (int j = 0; j < dof; ++j) {
        if (std::abs(a[j]) > amax[j] * (1.0 + settings.rate_tolerance)) {
          violation.add("acceleration", motion.time[i - 1],
                        joint_text(j, std::abs(a[j]), amax[j], "rad/s^2"));
        }
      }
    }
    previous_velocity = v;
  }

  // Dense samples (time order): no farther apart than the resolution.
  std::vector<int> steps(n, 0);
  std::size_t count = 1;
  for (std::size_t i = 1; i < n; ++i) {
    steps[i] = std::max(1, static_cast<int>(std::ceil((motion.q[i] - motion.q[i - 1]).norm() /
                                                      settings.resolution)));
    count += static_cast<std::size_t>(steps[i]);
  }
  samples_.resize(dof, static_cast<Eigen::Index>(count));
  times_.reserve(count);
  samples_.col(0) = motion.q.front();
  times_.push_back(motion.time.front());
  Eigen::Index column = 1;
  for (std::size_t i = 1; i < n; ++i) {
    const Eigen::VectorXd& a = motion.q[i - 1];
    const Eigen::VectorXd& b = motion.q[i];
    for (int k = 1; k <= steps[i]; ++k) {
      const double s = static_cast<double>(k) / steps[i];
      samples_.col(column++) = a + s * (b - a);
      times_.push_back(motion.time[i - 1] + s * (motion.time[i] - motion.time[i - 1]));
    }
  }
  head_.samples = static_cast<int>(count);
  findings_.resize((count + kPartSamples - 1) / kPartSamples);
}

void MotionValidation::check_parts(std::size_t first, std::size_t last, core::CollisionData& data) {
  assert(first <= last && last <= parts());
  if (first == last) return;
  const std::size_t end = std::min(last * kPartSamples, times_.size());
  const core::Cell& cell = world_.cell();
  const core::StageScene& stage = world_.stage();
  const core::Arm& arm = *arm_;
  const Motion& motion = motion_;
  const bool moves_tool = motion.tool_in_hand && static_cast<int>(arm_index_) == stage.suction_arm;
  std::vector<int> moving = stage.cell.arm_bodies[arm_index_];
  if (moves_tool) moving.insert(moving.end(), stage.tool_bodies.begin(), stage.tool_bodies.end());
  if (motion.holds_board) moving.push_back(stage.board);
  Eigen::VectorXd robot_q = motion.robot_q.size() == 0 ? cell.home_configuration() : motion.robot_q;
  if (!motion.holds_board) data.set_body_pose(stage.board, motion.board_world);
  // In the resting arm's hand (posed once) or on the table; a moving tool follows each sample.
  world_.place_tool(data, robot_q, motion.tool_in_hand, motion.tool_world);
  // The rest of the robot stands still: each sample moves this arm's links only.
  core::ArmPoser poser(cell, stage.cell, arm);
  poser.pose_robot(data, robot_q);
  const int tip_link = cell.robot().link_index(arm.spec.tip_link);  // the TCP, read off the pose
  // The arm's last link, gripper, tool in hand and held board move as one piece through the
  // motion: their pairs are checked once (at the motion's first sample), then left out of each
  // sample's.
  std::vector<int> rigid = core::rigid_tip_bodies(cell.robot(), stage.cell.robot, tip_link);
  if (moves_tool) rigid.insert(rigid.end(), stage.tool_bodies.begin(), stage.tool_bodies.end());
  if (motion.holds_board) rigid.push_back(stage.board);
  const Eigen::Vector3d down(0.0, 0.0, -1.0);
  Eigen::VectorXd q(samples_.rows());
  // This arm, the tool in its hand and the board it holds at sample i; the TCP.
  const auto pose_sample = [&](std::size_t i) -> const core::Pose& {
    q = samples_.col(static_cast<Eigen::Index>(i));
    cell.set_arm(robot_q, arm, q);
    poser.pose_arm(data, robot_q);
    const core::Pose& tcp = poser.link_pose(tip_link);
    if (moves_tool) core::set_tool_held(cell, stage, data, tcp);
    if (motion.holds_board) data.set_body_pose(stage.board, tcp * motion.board_in_tcp);
    return tcp;
  };
  // The rigid part's own verdict at the motion's first sample, whatever range this is: the
  // same pose on every thread, so the report cannot depend on how the parts were spread.
  pose_sample(0);
  core::CollisionPair rigid_pair;
  const bool rigid_collides = core::in_collision_among(stage.cell.model, data, rigid, &rigid_pair);
  for (std::size_t part = first; part < last; ++part) {
    ValidationReport local;
    Reporter violation(local);
    Findings& found = findings_[part];
    found.worst_slip_deg = 0.0;
    const std::size_t part_end = std::min(end, (part + 1) * kPartSamples);
    for (std::size_t i = part * kPartSamples; i < part_end; ++i) {
      const core::Pose& tcp = pose_sample(i);
      const double t = times_[i];
      if (!arm.chain.within_limits(q, settings_.limit_tolerance)) {
        violation.add("joint_limit", t, "outside the arm's joint limits");
      }
      if (motion.holds_board) {
        if (motion.theta_c_deg < 90.0) {
          const double slip = core::slip_angle_deg(tcp.linear() * motion.slip_axis_tcp,
                                                   tcp.linear() * motion.slip_lever_tcp, down);
          found.worst_slip_deg = std::max(found.worst_slip_deg, slip);
          if (slip > motion.theta_c_deg + settings_.slip_tolerance_deg) {
            std::ostringstream s;
            s.precision(4);
            s << "slip angle " << slip << " deg against theta_c " << motion.theta_c_deg << " deg";
            violation.add("slip", t, s.str());
          }
        }
      }
      core::CollisionPair pair = rigid_pair;
      const bool contact_allowed = (motion.start_in_contact && i == 0) ||
                                   (motion.end_in_contact && i + 1 == times_.size());
      if (!contact_allowed &&
          (rigid_collides || core::in_collision(stage.cell.model, data, moving, &pair, rigid))) {
        violation.add("collision", t,
                      stage.cell.model.body_name(pair.body_a) + " vs " +
                          stage.cell.model.body_name(pair.body_b));
      }
    }
    found.violations = std::move(local.violations);
  }
}

ValidationReport MotionValidation::report() const {
  ValidationReport report = head_;
  Reporter violation(report);
  std::vector<Violation> at_samples;
  for (const auto& f : findings_) {
    at_samples.insert(at_samples.end(), f.violations.begin(), f.violations.end());
    report.worst_slip_deg = std::max(report.worst_slip_deg, f.worst_slip_deg);
  }
  // As a single pass meets them: by time, and within a sample limits, slip, then collision.
  std::stable_sort(
      at_samples.begin(), at_samples.end(), [](const Violation& a, const Violation& b) {
        return a.time < b.time ||
               (a.time == b.time && sample_kind_order(a.kind) < sample_kind_order(b.kind));
      });
  for (const auto& v : at_samples) violation.add(v.kind, v.time, v.detail);
  return report;
}

ValidationReport validate_motion(const World& world, core::CollisionData& data,
                                 const Motion& motion, const ValidatorSettings& settings) {
  MotionValidation check(world, motion, settings);
  check.check_parts(0, check.parts(), data);
  return check.report();
}

ValidationReport validate_motion(const World& world, const std::vector<core::CollisionData*>& data,
                                 const Motion& motion, const ValidatorSettings& settings) {
  assert(!data.empty());
  MotionValidation check(world, motion, settings);
  // Contiguous ranges of parts, one per thread (a range poses the robot once).
  const std::size_t threads = std::min(data.size(), check.parts());
  auto range = [&](std::size_t t) {
    check.check_parts(check.parts() * t / threads, check.parts() * (t + 1) / threads, *data[t]);
  };
  std::vector<std::thread> workers;
  for (std::size_t t = 1; t < threads; ++t) {
    try {
      workers.emplace_back(range, t);
    } catch (const std::system_error&) {
      range(t);  // no thread to be had: this one does it
    }
  }
  if (threads > 0) range(0);
  for (auto& w : workers) w.join();
  return check.report();
}

}  // namespace hila::online
