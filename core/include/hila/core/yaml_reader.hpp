#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <initializer_list>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/pose.hpp"

namespace hila::core {

// A YAML node that remembers its file and its path ("robot.arms[1].home") so that every
// conversion error names both, plus what was expected and what was found.
class YamlNode {
 public:
  static YamlNode load_file(const std::string& path);
  static YamlNode from_string(const std::string& text, const std::string& name);

  YamlNode at(const std::string& key) const;  // required field
  std::optional<YamlNode> find(const std::string& key) const;
  bool has(const std::string& key) const;
  YamlNode at(std::size_t index) const;
  std::size_t size() const;
  bool is_map() const;
  bool is_sequence() const;
  // Throws if the map has a key outside `allowed` (catches typos such as "masss").
  void expect_only(std::initializer_list<const char*> allowed) const;

  double as_double() const;
  double as_positive() const;  // > 0
  double as_non_negative() const;
  double as_double_in(double lo, double hi) const;
  int as_int() const;
  bool as_bool() const;
  std::string as_string() const;
  std::vector<double> as_doubles(std::size_t expected_size = 0) const;  // 0: any size
  Eigen::Vector3d as_vec3() const;
  Eigen::Vector3d as_unit_vec3() const;
  std::vector<std::string> keys() const;
  // {xyz: [x,y,z], one of rpy_deg: [...] | rpy: [...] radians | quat_wxyz: [...] |
  //  rotation: [[...],[...],[...]]}. Rotations must be proper (unit quaternion, orthonormal).
  Pose as_pose() const;

  // Resolves a path written in this file relative to the file's folder.
  std::string resolve_path(const std::string& relative) const;

  const std::string& file() const { return *file_; }
  const std::string& path() const { return path_; }
  [[noreturn]] void fail(const std::string& expected, const std::string& got) const;

 private:
  YamlNode(YAML::Node node, std::shared_ptr<const std::string> file, std::string path);
  std::string describe() const;
  // A map key's text; an InputError at this map for a key that is a list or a map.
  std::string key_text(const YAML::Node& key) const;

  YAML::Node node_;
  std::shared_ptr<const std::string> file_;
  std::string path_;
};

}  // namespace hila::core
