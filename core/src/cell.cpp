#include "hila/core/cell.hpp"

#include <algorithm>
#include <set>

#include "hila/core/error.hpp"
#include "hila/core/human_model.hpp"
#include "hila/core/yaml_reader.hpp"

namespace hila::core {

namespace {

Eigen::VectorXd degrees_vector(const YamlNode& node, std::size_t n) {
  const auto v = node.as_doubles(n);
  Eigen::VectorXd out(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) out[static_cast<Eigen::Index>(i)] = deg_to_rad(v[i]);
  return out;
}

Eigen::VectorXd positive_degrees_vector(const YamlNode& node, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) node.at(i).as_positive();
  return degrees_vector(node, n);
}

// An arm's payload: {rated_kg, allowed_kg (default rated_kg), tooling: [{name, mass_kg, com}]}.
// Masses within (0, 1000] kg; a tooling item within (0, rated].
PayloadSpec parse_payload(const YamlNode& node) {
  node.expect_only({"rated_kg", "allowed_kg", "tooling"});
  PayloadSpec p;
  p.stated = true;
  p.rated = node.at("rated_kg").as_double_in(1e-3, 1000.0);
  p.allowed = p.rated;
  if (const auto a = node.find("allowed_kg")) {
    p.allowed = a->as_double_in(p.rated, 1000.0);
  }
  if (const auto tooling = node.find("tooling")) {
    if (!tooling->is_sequence()) tooling->fail("a list of {name, mass_kg, com}", "another node");
    for (std::size_t i = 0; i < tooling->size(); ++i) {
      const YamlNode t = tooling->at(i);
      t.expect_only({"name", "mass_kg", "com"});
      ToolingMass m;
      m.name = t.at("name").as_string();
      m.mass = t.at("mass_kg").as_double_in(1e-6, p.allowed);
      if (const auto com = t.find("com")) m.com = com->as_vec3();
      p.tooling.push_back(m);
    }
  }
  return p;
}

ArmSpec parse_arm(const YamlNode& node) {
  node.expect_only({"name", "base_link", "tip_link", "flange_link", "finger_joint", "kinematics",
                    "home_deg", "max_velocity_deg_s", "max_acceleration_deg_s2", "payload"});
  ArmSpec arm;
  arm.name = node.at("name").as_string();
  arm.base_link = node.at("base_link").as_string();
  arm.tip_link = node.at("tip_link").as_string();
  arm.flange_link = node.at("flange_link").as_string();
  arm.finger_joint = node.at("finger_joint").as_string();
  if (const auto k = node.find("kinematics")) {
    k->expect_only({"type", "d1", "a2", "a3", "d4", "d5", "d6"});
    const std::string type = k->at("type").as_string();
    if (type == "ur") {
      UrDhParameters dh;
      dh.d1 = k->at("d1").as_double();
      dh.a2 = k->at("a2").as_double();
      dh.a3 = k->at("a3").as_double();
      dh.d4 = k->at("d4").as_double();
      dh.d5 = k->at("d5").as_double();
      dh.d6 = k->at("d6").as_double();
      arm.ur_dh = dh;
    } else if (type != "generic") {
      k->at("type").fail("'ur' or 'generic'", "'" + type + "'");
    }
  }
  // Lengths are checked against the chain's DoF once the URDF is loaded (Cell::load).
  arm.home = degrees_vector(node.at("home_deg"), node.at("home_deg").size());
  arm.max_velocity =
      positive_degrees_vector(node.at("max_velocity_deg_s"), node.at("max_velocity_deg_s").size());
  arm.max_acceleration = positive_degrees_vector(node.at("max_acceleration_deg_s2"),
                                                 node.at("max_acceleration_deg_s2").size());
  if (const auto p = node.find("payload")) arm.payload = parse_payload(*p);
  return arm;
}

PadSpec parse_pad(const YamlNode& pad) {
  pad.expect_only(
      {"friction", "elastic_modulus", "thickness", "radius_1", "radius_2", "width", "length"});
  PadSpec p;
  p.friction = pad.at("friction").as_double_in(0.01, 3.0);
  p.elastic_modulus = pad.at("elastic_modulus").as_positive();
  p.thickness = pad.at("thickness").as_positive();
  p.radius_1 = pad.at("radius_1").as_positive();
  p.radius_2 = pad.at("radius_2").as_positive();
  p.width = pad.at("width").as_positive();
  p.length = pad.at("length").as_positive();
  return p;
}

HumanHandSpec parse_hand(const YamlNode& node) {
  node.expect_only({"aperture_range", "grip_force", "pad", "finger_thickness", "finger_width",
                    "finger_length", "palm_width", "palm_length", "palm_thickness"});
  HumanHandSpec h;
  const auto aperture = node.at("aperture_range").as_doubles(2);
  if (!(aperture[0] >= 0 && aperture[1] > aperture[0] && aperture[1] < 0.3)) {
    node.at("aperture_range")
        .fail("[min, max] in metres with 0 <= min < max < 0.3",
              "[" + format_number(aperture[0]) + ", " + format_number(aperture[1]) + "]");
  }
  h.aperture_min = aperture[0];
  h.aperture_max = aperture[1];
  h.grip_force = node.at("grip_force").as_positive();
  h.pad = parse_pad(node.at("pad"));
  h.finger_thickness = node.at("finger_thickness").as_positive();
  h.finger_width = node.at("finger_width").as_positive();
  h.finger_length = node.at("finger_length").as_positive();
  h.palm_width = node.at("palm_width").as_positive();
  h.palm_length = node.at("palm_length").as_positive();
  h.palm_thickness = node.at("palm_thickness").as_positive();
  return h;
}

GripperSpec parse_gripper(const YamlNode& node) {
  node.expect_only({"tcp_in_flange", "opening_axis", "approach_axis", "jaw_range",
                    "grip_force_range", "grip_force", "pad", "friction_torque_capacity",
                    "slip_step_deg"});
  GripperSpec g;
  g.tcp_in_flange = node.at("tcp_in_flange").as_pose();
  check_pose(g.tcp_in_flange, node.file(), "gripper.tcp_in_flange");
  g.opening_axis = node.at("opening_axis").as_unit_vec3();
  g.approach_axis = node.at("approach_axis").as_unit_vec3();
  if (std::abs(g.opening_axis.dot(g.approach_axis)) > 1e-6) {
    node.at("approach_axis")
        .fail("an axis perpendicular to opening_axis", "a non-perpendicular one");
  }
  const auto jaw = node.at("jaw_range").as_doubles(2);
  if (!(jaw[0] >= 0 && jaw[1] > jaw[0] && jaw[1] < 0.5)) {
    node.at("jaw_range")
        .fail("[min, max] in metres with 0 <= min < max < 0.5",
              "[" + format_number(jaw[0]) + ", " + format_number(jaw[1]) + "]" +
                  (jaw[1] >= 0.5 ? " (millimetres?)" : ""));
  }
  g.jaw_min = jaw[0];
  g.jaw_max = jaw[1];
  const auto force = node.at("grip_force_range").as_doubles(2);
  if (!(force[0] > 0 && force[1] >= force[0])) {
    node.at("grip_force_range").fail("[min, max] newtons with 0 < min <= max", "an invalid range");
  }
  g.grip_force_min = force[0];
  g.grip_force_max = force[1];
  g.grip_force = node.at("grip_force").as_double_in(force[0], force[1]);
  g.pad = parse_pad(node.at("pad"));
  g.friction_torque_capacity = node.at("friction_torque_capacity").as_positive();
  if (node.has("slip_step_deg")) g.slip_step_deg = node.at("slip_step_deg").as_double_in(0.01, 45);
  return g;
}

}  // namespace

CellSpec load_cell_spec(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.expect_only({"robot", "gripper", "suction", "obstacles", "human", "gravity"});
  CellSpec cell;
  cell.file = path;
  const YamlNode robot = root.at("robot");
  robot.expect_only({"urdf", "arms", "allowed_collisions"});
  cell.robot_urdf = robot.resolve_path(robot.at("urdf").as_string());
  const YamlNode arms = robot.at("arms");
  if (!arms.is_sequence() || arms.size() == 0) arms.fail("a list of arms", "none");
  std::set<std::string> names;
  for (std::size_t i = 0; i < arms.size(); ++i) {
    cell.arms.push_back(parse_arm(arms.at(i)));
    if (!names.insert(cell.arms.back().name).second) {
      arms.at(i).at("name").fail("a unique arm name", "'" + cell.arms.back().name + "' twice");
    }
  }
  if (const auto allowed = robot.find("allowed_collisions")) {
    for (std::size_t i = 0; i < allowed->size(); ++i) {
      const YamlNode pair = allowed->at(i);
      if (!pair.is_sequence() || pair.size() != 2)
        pair.fail("a pair [body, body]", "something else");
      cell.allowed_collisions.emplace_back(pair.at(0).as_string(), pair.at(1).as_string());
    }
  }
  cell.gripper = parse_gripper(root.at("gripper"));

  const YamlNode suction = root.at("suction");
  suction.expect_only({"tool_urdf", "handle_link", "cup_link", "handle_width", "cup_radius",
                       "max_force", "max_moment", "handle_in_tcp", "mass_kg", "com"});
  cell.suction.tool_urdf = suction.resolve_path(suction.at("tool_urdf").as_string());
  cell.suction.handle_link = suction.at("handle_link").as_string();
  cell.suction.cup_link = suction.at("cup_link").as_string();
  cell.suction.handle_width = suction.at("handle_width").as_positive();
  cell.suction.cup_radius = suction.at("cup_radius").as_positive();
  cell.suction.max_force = suction.at("max_force").as_positive();
  cell.suction.max_moment = suction.at("max_moment").as_positive();
  cell.suction.handle_in_tcp = suction.at("handle_in_tcp").as_pose();
  if (const auto m = suction.find("mass_kg")) cell.suction.mass = m->as_double_in(0.0, 100.0);
  if (const auto c = suction.find("com")) cell.suction.com = c->as_vec3();

  if (const auto obstacles = root.find("obstacles")) {
    for (std::size_t i = 0; i < obstacles->size(); ++i) {
      const YamlNode o = obstacles->at(i);
      o.expect_only({"name", "box", "pose"});
      BoxObstacle box;
      box.name = o.at("name").as_string();
      box.size = o.at("box").as_vec3();
      for (int k = 0; k < 3; ++k) {
        if (!(box.size[k] > 0))
          o.at("box").fail("three positive side lengths", "a non-positive side");
      }
      box.pose = o.at("pose").as_pose();
      cell.obstacles.push_back(box);
    }
  }

  const YamlNode human = root.at("human");
  human.expect_only({"urdf", "stance", "arms", "neutral_deg", "hand"});
  cell.human_urdf = human.resolve_path(human.at("urdf").as_string());
  cell.human_stance = human.at("stance").as_pose();
  const YamlNode human_arms = human.at("arms");
  for (std::size_t i = 0; i < human_arms.size(); ++i) {
    const YamlNode a = human_arms.at(i);
    a.expect_only({"name", "base_link", "tip_link"});
    cell.human_arms.push_back(
        {a.at("name").as_string(), a.at("base_link").as_string(), a.at("tip_link").as_string()});
  }
  cell.human_hand = parse_hand(human.at("hand"));
  if (const auto neutral = human.find("neutral_deg")) {
    cell.human_neutral = degrees_vector(*neutral, neutral->size());
  }
  if (root.has("gravity")) cell.gravity = root.at("gravity").as_double_in(9.0, 10.0);
  return cell;
}

namespace {
void require_link(const RobotModel& model, const std::string& cell_file, const std::string& field,
                  const std::string& name) {
  if (!model.find_link(name)) {
    throw InputError(cell_file, field, "a link of " + model.source(), "'" + name + "'");
  }
}
}  // namespace

std::shared_ptr<const Cell> Cell::load(const std::string& path) {
  auto cell = std::make_shared<Cell>();
  cell->spec_ = load_cell_spec(path);
  const CellSpec& spec = cell->spec_;
  cell->robot_ = RobotModel::load_urdf_file(spec.robot_urdf);
  cell->human_ = RobotModel::load_urdf_file(spec.human_urdf);
  cell->tool_ = RobotModel::load_urdf_file(spec.suction.tool_urdf);
  require_link(cell->tool_, path, "suction.handle_link", spec.suction.handle_link);
  require_link(cell->tool_, path, "suction.cup_link", spec.suction.cup_link);

  for (std::size_t i = 0; i < spec.arms.size(); ++i) {
    const ArmSpec& a = spec.arms[i];
    const std::string field = "robot.arms[" + std::to_string(i) + "]";
    require_link(cell->robot_, path, field + ".base_link", a.base_link);
    require_link(cell->robot_, path, field + ".tip_link", a.tip_link);
    require_link(cell->robot_, path, field + ".flange_link", a.flange_link);
    KinematicChain chain(cell->robot_, a.base_link, a.tip_link);
    const std::pair<const char*, const Eigen::VectorXd*> per_joint[] = {
        {".home_deg", &a.home},
        {".max_velocity_deg_s", &a.max_velocity},
        {".max_acceleration_deg_s2", &a.max_acceleration}};
    for (const auto& [name, values] : per_joint) {
      if (values->size() != chain.dof()) {
        throw InputError(path, field + name,
                         std::to_string(chain.dof()) + " values (one per joint of " + a.base_link +
                             " -> " + a.tip_link + ")",
                         std::to_string(values->size()));
      }
    }
    if (!chain.within_limits(a.home, 1e-9)) {
      throw InputError(path, field + ".home_deg", "angles inside the URDF joint limits",
                       "a value outside them");
    }
    std::optional<UrIk> ik;
    if (a.ur_dh) {
      try {
        ik.emplace(chain, *a.ur_dh);
      } catch (const InputError& e) {
        throw InputError(path, field + ".kinematics",
                         "UR DH parameters matching " + spec.robot_urdf,
                         std::string("'") + e.what() + "'");
      }
    }
    // The jaw joint must be an independent prismatic joint of the robot.
    int finger_variable = -1;
    bool found = false;
    for (const Joint& j : cell->robot_.joints()) {
      if (j.name == a.finger_joint) {
        found = true;
        finger_variable = j.variable;
      }
    }
    if (!found || finger_variable < 0) {
      throw InputError(path, field + ".finger_joint", "an independent joint of " + spec.robot_urdf,
                       "'" + a.finger_joint + "'");
    }
    cell->arms_.push_back(Arm{a, std::move(chain), std::move(ik), finger_variable});
  }

  for (std::size_t i = 0; i < spec.human_arms.size(); ++i) {
    const HumanArmSpec& a = spec.human_arms[i];
    const std::string field = "human.arms[" + std::to_string(i) + "]";
    require_link(cell->human_, path, field + ".base_link", a.base_link);
    require_link(cell->human_, path, field + ".tip_link", a.tip_link);
    cell->human_arms_.push_back(HumanArm{a, KinematicChain(cell->human_, a.base_link, a.tip_link)});
  }
  if (spec.human_neutral.size() != 0 && spec.human_neutral.size() != cell->human_.num_variables()) {
    throw InputError(path, "human.neutral_deg",
                     std::to_string(cell->human_.num_variables()) + " joint angles",
                     std::to_string(spec.human_neutral.size()));
  }
  cell->human_neutral_ =
      spec.human_neutral.size() ? spec.human_neutral : human_neutral_configuration(cell->human_);
  check_pose(spec.human_stance, path, "human.stance");
  for (const auto& o : spec.obstacles) check_pose(o.pose, path, "obstacles." + o.name + ".pose");
  return cell;
}

const Arm& Cell::arm(const std::string& name) const {
  for (const Arm& a : arms_) {
    if (a.spec.name == name) return a;
  }
  std::string names;
  for (const Arm& a : arms_) names += (names.empty() ? "" : ", ") + a.spec.name;
  throw InputError(spec_.file, "arm", "one of: " + names, "'" + name + "'");
}

void Cell::set_arm(Eigen::VectorXd& robot_q, const Arm& arm, const Eigen::VectorXd& arm_q) const {
  const auto& vars = arm.chain.model_variables();
  for (std::size_t i = 0; i < vars.size(); ++i)
    robot_q[vars[i]] = arm_q[static_cast<Eigen::Index>(i)];
}

Eigen::VectorXd Cell::arm_joints(const Eigen::VectorXd& robot_q, const Arm& arm) const {
  const auto& vars = arm.chain.model_variables();
  Eigen::VectorXd q(static_cast<Eigen::Index>(vars.size()));
  for (std::size_t i = 0; i < vars.size(); ++i) q[static_cast<Eigen::Index>(i)] = robot_q[vars[i]];
  return q;
}

void Cell::set_jaw(Eigen::VectorXd& robot_q, const Arm& arm, double opening) const {
  // The URDF finger joint is the half opening (each finger moves by half).
  robot_q[arm.finger_variable] = 0.5 * opening;
}

Eigen::VectorXd Cell::home_configuration(double jaw_opening) const {
  Eigen::VectorXd q = robot_.neutral_configuration();
  for (const Arm& a : arms_) {
    set_arm(q, a, a.spec.home);
    set_jaw(q, a, jaw_opening);
  }
  return q;
}

Eigen::VectorXd Cell::human_neutral() const {
  return human_neutral_;
}

CellScene build_cell_scene(const Cell& cell, const CellSceneOptions& options) {
  CellScene scene;
  scene.robot = add_robot(scene.model, cell.robot(), "");
  scene.human = add_robot(scene.model, cell.human(), "human/", !options.human_moves);
  for (const auto& o : cell.spec().obstacles) {
    GeometrySpec box;
    box.type = GeometrySpec::Type::Box;
    box.box_size = o.size;
    scene.obstacles.push_back(scene.model.add_body(o.name, {box}, true, o.pose));
  }
  for (const auto& [a, b] : cell.spec().allowed_collisions) {
    if (!scene.model.find_body(a)) {
      throw InputError(cell.spec().file, "robot.allowed_collisions",
                       "names of links with collision geometry or obstacles", "'" + a + "'");
    }
    if (!scene.model.find_body(b)) {
      throw InputError(cell.spec().file, "robot.allowed_collisions",
                       "names of links with collision geometry or obstacles", "'" + b + "'");
    }
    scene.model.allow(a, b);
  }
  for (const Arm& arm : cell.arms()) {
    scene.arm_bodies.push_back(
        subtree_bodies(cell.robot(), scene.robot, cell.robot().link_index(arm.spec.base_link)));
  }
  return scene;
}

void set_robot_state(const Cell& cell, const CellScene& scene, CollisionData& data,
                     const Eigen::VectorXd& robot_q) {
  thread_local std::vector<Pose> poses;
  cell.robot().link_poses(robot_q, poses);
  set_robot_pose(data, scene.robot, poses);
}

void set_cell_state(const Cell& cell, const CellScene& scene, CollisionData& data,
                    const Eigen::VectorXd& robot_q, const Eigen::VectorXd& human_q) {
  set_robot_state(cell, scene, data, robot_q);
  std::vector<Pose> poses;
  cell.human().link_poses(human_q, poses);
  set_robot_pose(data, scene.human, poses, cell.spec().human_stance);
}

void check_human_stance(const Cell& cell) {
  CollisionModel model;
  const RobotBodies robot = add_robot(model, cell.robot(), "robot/", true);
  const RobotBodies human = add_robot(model, cell.human(), "human/");
  for (const auto& o : cell.spec().obstacles) {
    GeometrySpec box;
    box.box_size = o.size;
    model.add_body(o.name, {box}, true, o.pose);
  }
  CollisionData data(model);
  std::vector<Pose> poses;
  cell.robot().link_poses(cell.home_configuration(), poses);
  set_robot_pose(data, robot, poses);
  cell.human().link_poses(cell.human_neutral(), poses);
  set_robot_pose(data, human, poses, cell.spec().human_stance);
  CollisionPair pair;
  if (in_collision(model, data, &pair)) {
    const auto is_human = [&](int body) {
      return std::find(human.link_to_body.begin(), human.link_to_body.end(), body) !=
             human.link_to_body.end();
    };
    if (is_human(pair.body_a) && is_human(pair.body_b)) {
      // No stance helps: the posture (or the human model) is at fault.
      throw InputError(cell.spec().file,
                       cell.spec().human_neutral.size() ? "human.neutral_deg" : "human.urdf",
                       "a neutral posture in which the human clears itself",
                       "the human intersecting itself (" + describe_pair(model, pair) + ")");
    }
    throw InputError(cell.spec().file, "human.stance",
                     "a stance where the human stands clear of the table, obstacles and robot",
                     "the human intersecting them (" + describe_pair(model, pair) + ")");
  }
}

}  // namespace hila::core
