#include "hila/viz/plan_export.hpp"

#include <algorithm>
#include <limits>

#include "cell_nodes.hpp"
#include "hila/core/error.hpp"

namespace hila::viz {

namespace {

// Where a copy of the board or the tool is shown and when: under `parent` (-1: the world) at
// `local`, visible from `begin` to `end` (s, the whole plan's time).
struct Phase {
  std::string name;
  int parent = -1;
  core::Pose local = core::Pose::Identity();
  double begin = 0.0;
  double end = 0.0;
};

// What holds a board or the tool: an arm's TCP (`arm` non-empty, `pose` in its tip link's frame)
// or nothing (`pose` in the world), since `since`.
struct Holder {
  std::string arm;
  core::Pose pose = core::Pose::Identity();
  double since = 0.0;
};

bool starts_step(const std::string& event) {
  // Released before the arm leaves (docs/online.md, the plan file's events).
  return event == "suction_off" || event == "gripper_open";
}

// Steps' arm of the suction tool: the arm of the first tool_ or suction_ step.
std::string suction_arm(const PlanFile& plan) {
  for (const PlanFileBoard& b : plan.boards) {
    for (const PlanFileStep& s : b.steps) {
      if (s.name.rfind("tool_", 0) == 0 || s.name.rfind("suction_", 0) == 0) return s.arm;
    }
  }
  return "";
}

class PlanPlayer {
 public:
  PlanPlayer(const core::Cell& cell, Eigen::VectorXd robot_q)
      : cell_(cell), robot_q_(std::move(robot_q)) {}

  const Eigen::VectorXd& robot_q() const { return robot_q_; }
  void set_arm(const core::Arm& arm, const Eigen::VectorXd& q) { cell_.set_arm(robot_q_, arm, q); }

  // The arm's TCP link pose (world) at the current configuration.
  core::Pose tip(const std::string& arm) const {
    std::vector<core::Pose> links;
    cell_.robot().link_poses(robot_q_, links);
    return links[static_cast<std::size_t>(cell_.robot().link_index(cell_.arm(arm).spec.tip_link))];
  }
  core::Pose world(const Holder& h) const { return h.arm.empty() ? h.pose : tip(h.arm) * h.pose; }

 private:
  const core::Cell& cell_;
  Eigen::VectorXd robot_q_;
};

// To the plan's end and after (glTF holds the last key).
constexpr double kForever = std::numeric_limits<double>::infinity();

// Scale keys that show a node from `begin` to `end` (kForever: and after the plan's end); false
// if never shown.
bool visibility_keys(double begin, double end, std::vector<float>& times,
                     std::vector<float>& values) {
  const float b = std::max(0.0f, static_cast<float>(begin));
  const float e = static_cast<float>(end);
  if (!(e > b)) return false;
  auto key = [&](float t, float v) {
    times.push_back(t);
    values.insert(values.end(), {v, v, v});
  };
  if (b > 0.0f) key(0.0f, 0.0f);
  key(b, 1.0f);
  if (end < kForever) key(e, 0.0f);
  return true;
}

// A node whose visibility changes: shown from `begin` to `end` (the whole plan's time).
struct Shown {
  int node = -1;
  double begin = 0.0;
  double end = 0.0;
};

// An animation's span of the whole plan: "plan" (0 to kForever) or a board's.
struct Window {
  std::string name;
  double begin = 0.0;
  double end = 0.0;
};

// STEP scale keys of `shown` over the board's window, in the window's time (0 to its length):
// a key at its start and end and at each change between.
void window_visibility_keys(const Shown& shown, const Window& window, std::vector<float>& times,
                            std::vector<float>& values) {
  auto visible = [&](double t) { return shown.begin <= t && t < shown.end ? 1.0f : 0.0f; };
  auto key = [&](double t) {
    const float tf = static_cast<float>(t - window.begin);
    if (!times.empty() && !(tf > times.back())) return;
    const float v = visible(t);
    times.push_back(tf);
    values.insert(values.end(), {v, v, v});
  };
  key(window.begin);
  for (double change : {shown.begin, shown.end}) {
    if (change > window.begin && change < window.end) key(change);
  }
  key(window.end);
}

// The arm's joints at `time` (the whole plan's), linear between its keys, held before the first
// and after the last.
Eigen::VectorXd joints_at(const std::vector<std::pair<double, Eigen::VectorXd>>& keys,
                          double time) {
  const auto after = std::upper_bound(keys.begin(), keys.end(), time,
                                      [](double t, const auto& key) { return t < key.first; });
  if (after == keys.begin()) return keys.front().second;
  if (after == keys.end()) return keys.back().second;
  const auto& [t0, q0] = *(after - 1);
  const auto& [t1, q1] = *after;
  const double f = (time - t0) / (t1 - t0);  // t1 > time >= t0
  return (1.0 - f) * q0 + f * q1;
}

}  // namespace

std::string plan_glb(const core::Cell& cell, const core::ProductSpec& product,
                     const PlanStart& start, const PlanFile& plan) {
  Eigen::VectorXd start_q = cell.home_configuration(cell.spec().gripper.jaw_max);
  for (const auto& [name, q] : start.robot) {
    const core::Arm& arm = cell.arm(name);
    if (q.size() != arm.chain.dof()) {
      throw core::InputError(plan.file, "robot." + name,
                             std::to_string(arm.chain.dof()) + " joint values",
                             std::to_string(q.size()));
    }
    cell.set_arm(start_q, arm, q);
  }
  GltfBuilder builder;
  CellView view;
  view.robot_q = start_q;
  view.human_stance = start.human_stance;
  const CellNodes nodes = add_cell_nodes(builder, cell, view);
  const Materials& m = nodes.materials;
  for (const core::PlacedPart& part : start.finished) {
    builder.add_node("finished/" + part.name, -1, part.pose,
                     add_part_mesh(builder, "finished/" + part.name, *part.mesh, m.finished));
  }
  auto tip_node = [&](const std::string& arm) {
    return nodes.robot_links[static_cast<std::size_t>(
        cell.robot().link_index(cell.arm(arm).spec.tip_link))];
  };

  std::vector<Shown> shown;     // nodes whose visibility changes during the plan
  std::vector<Window> windows;  // the solved boards' spans
  PlanPlayer player(cell, start_q);
  // Each arm's keys: (time in the whole plan, the arm's joints).
  std::map<std::string, std::vector<std::pair<double, Eigen::VectorXd>>> keys;
  const core::Pose handle_in_tcp = cell.spec().suction.handle_in_tcp;
  const std::string tool_arm = suction_arm(plan);
  std::vector<Phase> tool_phases;
  Holder tool;
  if (start.tool_in_hand && !tool_arm.empty()) {
    tool = {tool_arm, handle_in_tcp, 0.0};
  } else {
    tool.pose = start.tool;
  }
  auto tool_phase_until = [&](double t) {
    std::string suffix = "#";
    suffix += std::to_string(tool_phases.size());
    tool_phases.push_back(
        {suffix, tool.arm.empty() ? -1 : tip_node(tool.arm), tool.pose, tool.since, t});
  };

  double offset = 0.0;
  for (const PlanFileBoard& b : plan.boards) {
    const core::PartSpec& part = product.part(b.board);
    const auto initial = start.initial.find(b.board);
    Holder board{"", initial != start.initial.end() ? initial->second : part.initial, 0.0};
    std::vector<Phase> phases;
    std::string kind = "stack/";  // the copy now shown: on the table, held, placed
    int copies = 0;
    auto phase_until = [&](double t) {
      const std::string name = kind == "stack/"
                                   ? kind + b.board
                                   : kind + b.board + std::string("#") + std::to_string(copies++);
      phases.push_back(
          {name, board.arm.empty() ? -1 : tip_node(board.arm), board.pose, board.since, t});
    };
    auto hold = [&](const std::string& arm, double t) {
      const core::Pose world = player.world(board);
      phase_until(t);
      board = {arm, player.tip(arm).inverse() * world, t};
      kind = "held/";
    };
    auto release = [&](double t) {
      const core::Pose world = player.world(board);
      phase_until(t);
      board = {"", world, t};
      kind = "placed/";
    };
    const double end = offset + b.duration;
    for (const PlanFileStep& s : b.steps) {
      const core::Arm& arm = cell.arm(s.arm);
      for (const Eigen::VectorXd& q : s.joints) {
        if (q.size() != arm.chain.dof()) {
          throw core::InputError(plan.file, b.board + "." + s.name + ".joints_rad",
                                 std::to_string(arm.chain.dof()) + " joints for arm " + s.arm,
                                 std::to_string(q.size()));
        }
      }
      const double t0 = offset + s.time.front();
      const double t1 = offset + s.time.back();
      player.set_arm(arm, s.joints.front());
      for (const std::string& e : s.events) {
        if (starts_step(e) && board.arm == s.arm) release(t0);
      }
      auto& arm_keys = keys[s.arm];
      for (std::size_t i = 0; i < s.time.size(); ++i)
        arm_keys.emplace_back(offset + s.time[i], s.joints[i]);
      player.set_arm(arm, s.joints.back());
      for (const std::string& e : s.events) {
        if (e == "suction_on" || e == "gripper_close") {
          hold(s.arm, t1);
        } else if (e == "set_down" && board.arm == s.arm) {
          release(t1);
        } else if (e == "tool_grasped") {
          tool_phase_until(t1);
          tool = {s.arm, handle_in_tcp, t1};
        } else if (e == "tool_released" && tool.arm == s.arm) {
          tool_phase_until(t1);
          tool = {"", player.tip(s.arm) * handle_in_tcp, t1};
        }
      }
    }
    // Assembled at the board's end (an unsolved board by hand, at its start).
    phase_until(end);
    phases.push_back(
        {"finished/" + b.board, -1, start.assembly_frame * part.target, end, kForever});
    const int held_mesh = add_part_mesh(builder, "held/" + b.board, part.mesh, m.held);
    const int stack_mesh = add_part_mesh(builder, "stack/" + b.board, part.mesh, m.stacked);
    const int finished_mesh = add_part_mesh(builder, "finished/" + b.board, part.mesh, m.finished);
    for (const Phase& p : phases) {
      std::vector<float> times, values;
      if (!visibility_keys(p.begin, p.end, times, values)) continue;
      const int mesh = p.name.rfind("stack/", 0) == 0      ? stack_mesh
                       : p.name.rfind("finished/", 0) == 0 ? finished_mesh
                                                           : held_mesh;
      const int node = builder.add_node(p.name, p.parent, p.local, mesh);
      builder.set_node_scale(node, p.begin <= 0.0 ? 1.0 : 0.0);
      if (times.size() > 1) shown.push_back({node, p.begin, p.end});
    }
    if (b.solved() && b.duration > 0.0) windows.push_back({b.board, offset, end});
    offset = end;
  }
  tool_phase_until(kForever);
  for (const Phase& p : tool_phases) {
    std::vector<float> times, values;
    if (!visibility_keys(p.begin, p.end, times, values)) continue;
    const int root = add_tool_nodes(builder, cell, p.parent, p.local, p.name, m.tool);
    builder.set_node_scale(root, p.begin <= 0.0 ? 1.0 : 0.0);
    if (times.size() > 1) shown.push_back({root, p.begin, p.end});
  }
  // The whole plan first, then one animation per board over its own span.
  windows.insert(windows.begin(), {"plan", 0.0, kForever});
  if (shown.empty() && keys.empty()) windows.clear();  // nothing moves: no animation
  for (const Window& w : windows) {
    const int animation = builder.add_animation(w.name);
    for (const Shown& v : shown) {
      std::vector<float> times, values;
      if (w.end == kForever) {
        visibility_keys(v.begin, v.end, times, values);
      } else {
        window_visibility_keys(v, w, times, values);
      }
      builder.add_channel(animation, v.node, "scale", times, values, "STEP");
    }
  }

  // The arms' joints: the child link node of each joint, keyed at every time stamp (a board's
  // animation: at its start, its end and the stamps between).
  for (const auto& [arm_name, arm_keys] : keys) {
    const core::Arm& arm = cell.arm(arm_name);
    for (int k = 0; k < arm.chain.dof(); ++k) {
      const int variable = arm.chain.model_variables()[static_cast<std::size_t>(k)];
      const int j = cell.robot().variable_joints()[static_cast<std::size_t>(variable)];
      const core::Joint& joint = cell.robot().joints()[static_cast<std::size_t>(j)];
      const bool prismatic = joint.type == core::JointType::Prismatic;
      const int node = nodes.robot_links[static_cast<std::size_t>(joint.child_link)];
      for (std::size_t a = 0; a < windows.size(); ++a) {
        const Window& w = windows[a];
        std::vector<float> times, values;
        Eigen::Quaterniond previous = Eigen::Quaterniond::Identity();
        auto key = [&](double t, double value) {
          const float tf = static_cast<float>(t);
          if (!times.empty() && !(tf > times.back())) return;  // a step's start: the last's end
          times.push_back(tf);
          const core::Pose local = joint.origin * core::joint_motion(joint, value);
          if (prismatic) {
            for (int c = 0; c < 3; ++c)
              values.push_back(static_cast<float>(local.translation()[c]));
          } else {
            Eigen::Quaterniond r(local.linear());
            if (r.dot(previous) < 0.0) r.coeffs() *= -1.0;  // the same rotation, no flips
            previous = r;
            values.insert(values.end(), {static_cast<float>(r.x()), static_cast<float>(r.y()),
                                         static_cast<float>(r.z()), static_cast<float>(r.w())});
          }
        };
        if (w.end == kForever) {
          for (const auto& [t, q] : arm_keys) key(t, q[k]);
        } else {
          key(0.0, joints_at(arm_keys, w.begin)[k]);
          for (const auto& [t, q] : arm_keys) {
            if (t > w.begin && t < w.end) key(t - w.begin, q[k]);
          }
          key(w.end - w.begin, joints_at(arm_keys, w.end)[k]);
        }
        builder.add_channel(static_cast<int>(a), node, prismatic ? "translation" : "rotation",
                            times, values, "LINEAR");
      }
    }
  }
  return builder.glb();
}

}  // namespace hila::viz
