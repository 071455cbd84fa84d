#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/pose.hpp"

namespace hila::core {

enum class JointType { Fixed, Revolute, Continuous, Prismatic };

struct GeometrySpec {
  enum class Type { Box, Cylinder, Sphere, Mesh };
  Type type = Type::Box;
  Eigen::Vector3d box_size = Eigen::Vector3d::Zero();
  double radius = 0.0;
  double length = 0.0;    // cylinder, along its local z, centred
  std::string mesh_path;  // resolved, absolute or relative to the working directory
  Eigen::Vector3d mesh_scale = Eigen::Vector3d::Ones();
  Pose origin = Pose::Identity();  // in the link frame
};

struct Link {
  std::string name;
  int parent_joint = -1;
  std::vector<int> child_joints;
  std::vector<GeometrySpec> collisions;
};

struct Joint {
  std::string name;
  JointType type = JointType::Fixed;
  int parent_link = -1;
  int child_link = -1;
  Pose origin = Pose::Identity();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double lower = 0.0;
  double upper = 0.0;
  double velocity_limit = 0.0;
  int variable = -1;     // index into the configuration vector, -1 when fixed or mimic
  int mimic_joint = -1;  // joint whose value this one copies
  double mimic_multiplier = 1.0;
  double mimic_offset = 0.0;
};

// A kinematic tree read from URDF (urdfdom). Joints are kept in topological order (a joint comes
// after the joint of its parent link), so one forward pass computes every link pose.
class RobotModel {
 public:
  static RobotModel load_urdf_file(const std::string& path);
  static RobotModel load_urdf_string(const std::string& xml, const std::string& source_name,
                                     const std::string& base_dir = ".");

  const std::string& name() const { return name_; }
  const std::string& source() const { return source_; }
  const std::vector<Link>& links() const { return links_; }
  const std::vector<Joint>& joints() const { return joints_; }
  int root_link() const { return root_link_; }

  // Throws InputError naming the URDF and `field` when the name is unknown.
  int link_index(const std::string& name, const std::string& field = "link") const;
  int joint_index(const std::string& name, const std::string& field = "joint") const;
  std::optional<int> find_link(const std::string& name) const;

  int num_variables() const { return static_cast<int>(variable_joints_.size()); }
  const std::vector<int>& variable_joints() const { return variable_joints_; }
  Eigen::VectorXd lower_limits() const;
  Eigen::VectorXd upper_limits() const;
  // Zero clamped into the limits.
  Eigen::VectorXd neutral_configuration() const;

  // Pose of every link in the root frame; `out` is resized to links().size().
  void link_poses(const Eigen::VectorXd& q, std::vector<Pose>& out) const;
  double joint_value(const Eigen::VectorXd& q, int joint) const;

  // True if the two links are connected by a single joint.
  bool adjacent(int link_a, int link_b) const;

 private:
  std::string name_;
  std::string source_;
  std::vector<Link> links_;
  std::vector<Joint> joints_;
  std::vector<int> variable_joints_;
  int root_link_ = -1;
};

// Rigid motion of one joint at value `value` (rotation about or translation along its axis).
Pose joint_motion(const Joint& joint, double value);

}  // namespace hila::core
