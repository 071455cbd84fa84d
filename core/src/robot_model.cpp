#include "hila/core/robot_model.hpp"

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <algorithm>
#include <cassert>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "hila/core/error.hpp"

namespace hila::core {

namespace {

// urdfdom reports parse problems through console_bridge; capture them for our error message.
class CaptureHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) {
      messages += (messages.empty() ? "" : "; ") + text;
    }
  }
  std::string messages;
};

Pose to_pose(const urdf::Pose& p) {
  Pose pose = Pose::Identity();
  pose.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  pose.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                      .normalized()
                      .toRotationMatrix();
  return pose;
}

std::string resolve_mesh(const std::string& filename, const std::string& base_dir) {
  std::string f = filename;
  const std::string file_prefix = "file://";
  if (f.rfind(file_prefix, 0) == 0) f = f.substr(file_prefix.size());
  const std::string package_prefix = "package://";
  if (f.rfind(package_prefix, 0) == 0) {
    // No ROS package index here: package paths are taken relative to the URDF's folder.
    f = f.substr(package_prefix.size());
    const auto slash = f.find('/');
    f = slash == std::string::npos ? f : f.substr(slash + 1);
  }
  const std::filesystem::path p(f);
  if (p.is_absolute()) return p.string();
  return (std::filesystem::path(base_dir) / p).lexically_normal().string();
}

GeometrySpec to_geometry(const urdf::Geometry& g, const Pose& origin, const std::string& base_dir,
                         const std::string& source, const std::string& link) {
  GeometrySpec spec;
  spec.origin = origin;
  const std::string field = "link '" + link + "' collision geometry";
  switch (g.type) {
    case urdf::Geometry::BOX: {
      const auto& b = static_cast<const urdf::Box&>(g);
      spec.type = GeometrySpec::Type::Box;
      spec.box_size = Eigen::Vector3d(b.dim.x, b.dim.y, b.dim.z);
      if (!(spec.box_size.array() > 0).all() || !spec.box_size.allFinite()) {
        throw InputError(source, field, "a box with positive finite sides", "non-positive size");
      }
      break;
    }
    case urdf::Geometry::CYLINDER: {
      const auto& c = static_cast<const urdf::Cylinder&>(g);
      spec.type = GeometrySpec::Type::Cylinder;
      spec.radius = c.radius;
      spec.length = c.length;
      if (!(c.radius > 0 && c.length > 0)) {
        throw InputError(
            source, field, "a cylinder with positive radius and length",
            "radius " + format_number(c.radius) + ", length " + format_number(c.length));
      }
      break;
    }
    case urdf::Geometry::SPHERE: {
      const auto& s = static_cast<const urdf::Sphere&>(g);
      spec.type = GeometrySpec::Type::Sphere;
      spec.radius = s.radius;
      if (!(s.radius > 0)) {
        throw InputError(source, field, "a sphere with positive radius", format_number(s.radius));
      }
      break;
    }
    case urdf::Geometry::MESH: {
      const auto& m = static_cast<const urdf::Mesh&>(g);
      spec.type = GeometrySpec::Type::Mesh;
      spec.mesh_path = resolve_mesh(m.filename, base_dir);
      spec.mesh_scale = Eigen::Vector3d(m.scale.x, m.scale.y, m.scale.z);
      break;
    }
  }
  if (!spec.origin.matrix().allFinite()) {
    throw InputError(source, field + " origin", "a finite pose", "NaN or infinite values");
  }
  return spec;
}

}  // namespace

RobotModel RobotModel::load_urdf_file(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "(file)", "an existing URDF file", "no such file");
  }
  if (std::filesystem::is_directory(path)) {
    throw InputError(path, "(file)", "a URDF file", "a directory");
  }
  std::ifstream in(path);
  if (!in) throw InputError(path, "(file)", "a readable URDF file", "cannot open");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return load_urdf_string(buffer.str(), path, std::filesystem::path(path).parent_path().string());
}

RobotModel RobotModel::load_urdf_string(const std::string& xml, const std::string& source_name,
                                        const std::string& base_dir) {
  // Text that is not XML at all (empty, a mesh, YAML): urdfdom would only say "Error document
  // empty.".
  std::size_t first = xml.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;  // a UTF-8 byte order mark
  first = xml.find_first_not_of(" \t\r\n", first);
  if (first == std::string::npos || xml[first] != '<') {
    throw InputError(source_name, "(file)", "a URDF (XML)",
                     first == std::string::npos ? "an empty file"
                                                : "text that is not XML (it does not begin with '<')");
  }
  CaptureHandler capture;
  console_bridge::useOutputHandler(&capture);
  urdf::ModelInterfaceSharedPtr urdf_model = urdf::parseURDF(xml);
  console_bridge::restorePreviousOutputHandler();
  if (!urdf_model) {
    throw InputError(source_name, "(robot)", "a valid URDF document",
                     capture.messages.empty() ? "a parse failure" : "'" + capture.messages + "'");
  }
  RobotModel model;
  model.name_ = urdf_model->getName();
  model.source_ = source_name;

  // Links first (sorted by name for a deterministic order), then joints in topological order.
  std::map<std::string, int> link_ids;
  std::vector<std::string> names;
  for (const auto& [name, link] : urdf_model->links_) names.push_back(name);
  for (const auto& name : names) {
    link_ids[name] = static_cast<int>(model.links_.size());
    Link link;
    link.name = name;
    const auto& ulink = urdf_model->links_.at(name);
    for (const auto& col : ulink->collision_array) {
      if (!col || !col->geometry) continue;
      link.collisions.push_back(
          to_geometry(*col->geometry, to_pose(col->origin), base_dir, source_name, name));
    }
    model.links_.push_back(std::move(link));
  }
  model.root_link_ = link_ids.at(urdf_model->getRoot()->name);

  std::map<std::string, int> joint_ids;
  std::function<void(const urdf::LinkConstSharedPtr&)> visit =
      [&](const urdf::LinkConstSharedPtr& parent) {
        // Child joints in name order for determinism.
        std::vector<urdf::JointSharedPtr> children = parent->child_joints;
        std::sort(children.begin(), children.end(),
                  [](const auto& a, const auto& b) { return a->name < b->name; });
        for (const auto& uj : children) {
          Joint joint;
          joint.name = uj->name;
          joint.parent_link = link_ids.at(uj->parent_link_name);
          joint.child_link = link_ids.at(uj->child_link_name);
          joint.origin = to_pose(uj->parent_to_joint_origin_transform);
          joint.axis = Eigen::Vector3d(uj->axis.x, uj->axis.y, uj->axis.z);
          switch (uj->type) {
            case urdf::Joint::REVOLUTE:
              joint.type = JointType::Revolute;
              break;
            case urdf::Joint::CONTINUOUS:
              joint.type = JointType::Continuous;
              break;
            case urdf::Joint::PRISMATIC:
              joint.type = JointType::Prismatic;
              break;
            case urdf::Joint::FIXED:
              joint.type = JointType::Fixed;
              break;
            default:
              throw InputError(source_name, "joint '" + uj->name + "' type",
                               "fixed, revolute, continuous or prismatic",
                               "an unsupported joint type");
          }
          if (joint.type != JointType::Fixed) {
            if (!(joint.axis.norm() > 0.5)) {
              throw InputError(source_name, "joint '" + uj->name + "' axis", "a non-zero axis",
                               "zero");
            }
            joint.axis.normalize();
            if (joint.type == JointType::Continuous) {
              joint.lower = -kPi;
              joint.upper = kPi;
            } else if (uj->limits) {
              joint.lower = uj->limits->lower;
              joint.upper = uj->limits->upper;
              joint.velocity_limit = uj->limits->velocity;
              if (!(joint.lower <= joint.upper)) {
                throw InputError(source_name, "joint '" + uj->name + "' limit", "lower <= upper",
                                 format_number(joint.lower) + " > " + format_number(joint.upper));
              }
            }
            if (uj->mimic) {
              joint.mimic_multiplier = uj->mimic->multiplier;
              joint.mimic_offset = uj->mimic->offset;
            }
          }
          const int id = static_cast<int>(model.joints_.size());
          joint_ids[joint.name] = id;
          model.links_[joint.child_link].parent_joint = id;
          model.links_[joint.parent_link].child_joints.push_back(id);
          model.joints_.push_back(joint);
          visit(urdf_model->getLink(uj->child_link_name));
        }
      };
  visit(urdf_model->getRoot());

  // Mimic joints resolve after all joints are known.
  for (const auto& [name, uj] : urdf_model->joints_) {
    if (!uj->mimic) continue;
    const auto it = joint_ids.find(uj->mimic->joint_name);
    if (it == joint_ids.end()) {
      throw InputError(source_name, "joint '" + name + "' mimic", "the name of a joint",
                       "'" + uj->mimic->joint_name + "'");
    }
    model.joints_[joint_ids.at(name)].mimic_joint = it->second;
  }
  for (std::size_t j = 0; j < model.joints_.size(); ++j) {
    Joint& joint = model.joints_[j];
    if (joint.type != JointType::Fixed && joint.mimic_joint < 0) {
      joint.variable = static_cast<int>(model.variable_joints_.size());
      model.variable_joints_.push_back(static_cast<int>(j));
    }
  }
  for (const Joint& joint : model.joints_) {
    if (joint.mimic_joint >= 0 && model.joints_[joint.mimic_joint].variable < 0) {
      throw InputError(source_name, "joint '" + joint.name + "' mimic",
                       "a movable, non-mimic joint",
                       "'" + model.joints_[joint.mimic_joint].name + "'");
    }
  }
  return model;
}

int RobotModel::link_index(const std::string& name, const std::string& field) const {
  if (auto id = find_link(name)) return *id;
  throw InputError(source_, field, "the name of a link of robot '" + name_ + "'", "'" + name + "'");
}

std::optional<int> RobotModel::find_link(const std::string& name) const {
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (links_[i].name == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

int RobotModel::joint_index(const std::string& name, const std::string& field) const {
  for (std::size_t i = 0; i < joints_.size(); ++i) {
    if (joints_[i].name == name) return static_cast<int>(i);
  }
  throw InputError(source_, field, "the name of a joint of robot '" + name_ + "'",
                   "'" + name + "'");
}

Eigen::VectorXd RobotModel::lower_limits() const {
  Eigen::VectorXd lo(num_variables());
  for (int i = 0; i < num_variables(); ++i) lo[i] = joints_[variable_joints_[i]].lower;
  return lo;
}

Eigen::VectorXd RobotModel::upper_limits() const {
  Eigen::VectorXd hi(num_variables());
  for (int i = 0; i < num_variables(); ++i) hi[i] = joints_[variable_joints_[i]].upper;
  return hi;
}

Eigen::VectorXd RobotModel::neutral_configuration() const {
  return Eigen::VectorXd::Zero(num_variables()).cwiseMax(lower_limits()).cwiseMin(upper_limits());
}

double RobotModel::joint_value(const Eigen::VectorXd& q, int joint) const {
  const Joint& j = joints_[joint];
  if (j.variable >= 0) return q[j.variable];
  if (j.mimic_joint >= 0) {
    return j.mimic_multiplier * q[joints_[j.mimic_joint].variable] + j.mimic_offset;
  }
  return 0.0;
}

Pose joint_motion(const Joint& joint, double value) {
  Pose motion = Pose::Identity();
  switch (joint.type) {
    case JointType::Revolute:
    case JointType::Continuous:
      motion.linear() = Eigen::AngleAxisd(value, joint.axis).toRotationMatrix();
      break;
    case JointType::Prismatic:
      motion.translation() = value * joint.axis;
      break;
    case JointType::Fixed:
      break;
  }
  return motion;
}

void RobotModel::link_poses(const Eigen::VectorXd& q, std::vector<Pose>& out) const {
  assert(q.size() == num_variables());
  out.resize(links_.size());
  out[root_link_] = Pose::Identity();
  for (std::size_t j = 0; j < joints_.size(); ++j) {
    const Joint& joint = joints_[j];
    Pose child = out[joint.parent_link] * joint.origin;
    if (joint.type != JointType::Fixed) {
      child = child * joint_motion(joint, joint_value(q, static_cast<int>(j)));
    }
    out[joint.child_link] = child;
  }
}

bool RobotModel::adjacent(int link_a, int link_b) const {
  const int ja = links_[link_a].parent_joint;
  const int jb = links_[link_b].parent_joint;
  return (ja >= 0 && joints_[ja].parent_link == link_b) ||
         (jb >= 0 && joints_[jb].parent_link == link_a);
}

}  // namespace hila::core
