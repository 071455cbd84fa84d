#include "hila/core/yaml_reader.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "hila/core/error.hpp"

namespace hila::core {

namespace {
std::string short_repr(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list of " + std::to_string(node.size()) + " items";
  if (node.IsMap()) return "a map";
  return "an unknown node";
}

// Walks the parser's events (aliases unexpanded) and refuses a key that appears twice in one
// map: yaml-cpp's tree silently keeps the first value. Knows each node's path
// ("parts[0].mass") and line for the message.
class DuplicateKeyCheck : public YAML::EventHandler {
 public:
  explicit DuplicateKeyCheck(std::string file) : file_(std::move(file)) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { node(mark, nullptr); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { node(mark, nullptr); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string& value) override {
    node(mark, &value);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    frames_.push_back({false, node(mark, nullptr)});
  }
  void OnSequenceEnd() override { frames_.pop_back(); }
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    frames_.push_back({true, node(mark, nullptr)});
  }
  void OnMapEnd() override { frames_.pop_back(); }

 private:
  struct Frame {
    bool map = false;
    std::string path;
    std::size_t index = 0;                 // next item of a list
    bool expect_key = true;                // a map alternates key, value
    std::string key;                       // the key of the value that follows
    std::map<std::string, int> key_lines;  // 1-based line of each key so far
  };

  // Registers a node in its parent (as a key or a value) and returns its path.
  std::string node(const YAML::Mark& mark, const std::string* scalar) {
    if (frames_.empty()) return "";
    Frame& parent = frames_.back();
    const std::string prefix = parent.path.empty() ? "" : parent.path + ".";
    if (!parent.map) return parent.path + "[" + std::to_string(parent.index++) + "]";
    if (!parent.expect_key) {
      parent.expect_key = true;
      return prefix + parent.key;
    }
    parent.expect_key = false;
    parent.key = scalar != nullptr ? *scalar : "?";  // a key that is a list or map: no name
    if (scalar == nullptr) return prefix + "?";
    const int line = mark.line + 1;
    const auto [at, inserted] = parent.key_lines.emplace(*scalar, line);
    if (!inserted) {
      throw InputError(file_, prefix + *scalar, "a key that appears once in its map",
                       "'" + *scalar + "' again on line " + std::to_string(line) +
                           " (first on line " + std::to_string(at->second) + ")");
    }
    return prefix + *scalar;
  }

  std::string file_;
  std::vector<Frame> frames_;
};

// The document in `text`, refused when malformed or when a map repeats a key.
YAML::Node load_checked(const std::string& text, const std::string& file) {
  try {
    YAML::Node root = YAML::Load(text);
    std::istringstream in(text);
    YAML::Parser parser(in);
    DuplicateKeyCheck check(file);
    parser.HandleNextDocument(check);
    return root;
  } catch (const YAML::Exception& e) {
    throw InputError(file, "line " + std::to_string(e.mark.line + 1), "well-formed YAML", e.msg);
  }
}
}  // namespace

YamlNode::YamlNode(YAML::Node node, std::shared_ptr<const std::string> file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {}

YamlNode YamlNode::load_file(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "(file)", "an existing YAML file", "no such file");
  }
  if (std::filesystem::is_directory(path)) {
    throw InputError(path, "(file)", "a YAML file", "a directory");
  }
  std::ifstream in(path);
  if (!in) throw InputError(path, "(file)", "a readable YAML file", "a file that cannot be opened");
  std::ostringstream text;
  text << in.rdbuf();
  const YAML::Node root = load_checked(text.str(), path);
  if (!root.IsMap()) {
    throw InputError(path, "(document)", "a YAML map at the top level", short_repr(root));
  }
  return YamlNode(root, std::make_shared<const std::string>(path), "");
}

YamlNode YamlNode::from_string(const std::string& text, const std::string& name) {
  return YamlNode(load_checked(text, name), std::make_shared<const std::string>(name), "");
}

std::string YamlNode::describe() const {
  return short_repr(node_);
}

void YamlNode::fail(const std::string& expected, const std::string& got) const {
  throw InputError(*file_, path_.empty() ? "(document)" : path_, expected, got);
}

YamlNode YamlNode::at(const std::string& key) const {
  if (!node_.IsMap()) fail("a map with field '" + key + "'", describe());
  YAML::Node child = node_[key];
  const std::string child_path = path_.empty() ? key : path_ + "." + key;
  if (!child.IsDefined() || child.IsNull()) {
    throw InputError(*file_, child_path, "a value (required field)", "nothing");
  }
  return YamlNode(child, file_, child_path);
}

std::optional<YamlNode> YamlNode::find(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return at(key);
}

bool YamlNode::has(const std::string& key) const {
  if (!node_.IsMap()) return false;
  YAML::Node child = node_[key];
  return child.IsDefined() && !child.IsNull();
}

YamlNode YamlNode::at(std::size_t index) const {
  if (!node_.IsSequence()) fail("a list", describe());
  if (index >= node_.size()) fail("at least " + std::to_string(index + 1) + " items", describe());
  return YamlNode(node_[index], file_, path_ + "[" + std::to_string(index) + "]");
}

std::size_t YamlNode::size() const {
  if (!node_.IsSequence() && !node_.IsMap()) fail("a list or map", describe());
  return node_.size();
}

bool YamlNode::is_map() const {
  return node_.IsMap();
}
bool YamlNode::is_sequence() const {
  return node_.IsSequence();
}

std::string YamlNode::key_text(const YAML::Node& key) const {
  // A list or map written as a key (`[a, b]: 1`, a stray bracket in a flow map) names no field.
  if (!key.IsScalar()) fail("field names as keys", "a list or map used as a key");
  return key.Scalar();
}

void YamlNode::expect_only(std::initializer_list<const char*> allowed) const {
  if (!node_.IsMap()) fail("a map", describe());
  for (const auto& kv : node_) {
    const std::string key = key_text(kv.first);
    const bool known =
        std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return key == a; });
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw InputError(*file_, path_.empty() ? key : path_ + "." + key, "one of: " + list,
                       "unknown field '" + key + "'");
    }
  }
}

double YamlNode::as_double() const {
  if (!node_.IsScalar()) fail("a number", describe());
  double value = 0.0;
  const std::string& s = node_.Scalar();
  if (s == "nan" || s == "NaN" || s == ".nan" || s == ".NaN") fail("a finite number", "NaN");
  if (!YAML::convert<double>::decode(node_, value)) fail("a number", describe());
  if (!std::isfinite(value)) fail("a finite number", format_number(value));
  return value;
}

double YamlNode::as_positive() const {
  const double v = as_double();
  if (!(v > 0.0)) fail("a positive number", format_number(v));
  return v;
}

double YamlNode::as_non_negative() const {
  const double v = as_double();
  if (v < 0.0) fail("a non-negative number", format_number(v));
  return v;
}

double YamlNode::as_double_in(double lo, double hi) const {
  const double v = as_double();
  if (v < lo || v > hi) {
    fail("a number in [" + format_number(lo) + ", " + format_number(hi) + "]", format_number(v));
  }
  return v;
}

int YamlNode::as_int() const {
  if (!node_.IsScalar()) fail("an integer", describe());
  int value = 0;
  if (!YAML::convert<int>::decode(node_, value)) fail("an integer", describe());
  return value;
}

bool YamlNode::as_bool() const {
  if (!node_.IsScalar()) fail("true or false", describe());
  bool value = false;
  if (!YAML::convert<bool>::decode(node_, value)) fail("true or false", describe());
  return value;
}

std::string YamlNode::as_string() const {
  if (!node_.IsScalar()) fail("a string", describe());
  return node_.Scalar();
}

std::vector<double> YamlNode::as_doubles(std::size_t expected_size) const {
  if (!node_.IsSequence()) {
    fail(expected_size ? "a list of " + std::to_string(expected_size) + " numbers"
                       : "a list of numbers",
         describe());
  }
  if (expected_size != 0 && node_.size() != expected_size) {
    fail("a list of " + std::to_string(expected_size) + " numbers", describe());
  }
  std::vector<double> out;
  out.reserve(node_.size());
  for (std::size_t i = 0; i < node_.size(); ++i) out.push_back(at(i).as_double());
  return out;
}

Eigen::Vector3d YamlNode::as_vec3() const {
  const auto v = as_doubles(3);
  return {v[0], v[1], v[2]};
}

Eigen::Vector3d YamlNode::as_unit_vec3() const {
  const Eigen::Vector3d v = as_vec3();
  if (std::abs(v.norm() - 1.0) > 1e-6) fail("a unit vector", "norm " + format_number(v.norm()));
  return v;
}

std::vector<std::string> YamlNode::keys() const {
  if (!node_.IsMap()) fail("a map", describe());
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(key_text(kv.first));
  return out;
}

Pose YamlNode::as_pose() const {
  expect_only({"xyz", "rpy_deg", "rpy", "quat_wxyz", "rotation"});
  Pose pose = Pose::Identity();
  pose.translation() = at("xyz").as_vec3();
  int rotations = 0;
  // Angles within one turn either way: beyond that a value is a typo (1e300 degrees is no
  // rotation anyone meant, and its sine has lost every digit).
  const auto angles = [](const YamlNode& node, double turn, const std::string& unit) {
    const std::vector<double> v = node.as_doubles(3);
    for (std::size_t i = 0; i < 3; ++i) {
      if (std::abs(v[i]) > turn) {
        node.at(i).fail("an angle in " + unit + " in [" + format_number(-turn) + ", " +
                            format_number(turn) + "]",
                        format_number(v[i]));
      }
    }
    return Eigen::Vector3d(v[0], v[1], v[2]);
  };
  if (has("rpy_deg")) {
    ++rotations;
    pose.linear() = rpy_to_matrix(angles(at("rpy_deg"), 360.0, "degrees") * kPi / 180.0);
  }
  if (has("rpy")) {
    ++rotations;
    pose.linear() = rpy_to_matrix(angles(at("rpy"), 2.0 * kPi, "radians"));
  }
  if (has("quat_wxyz")) {
    ++rotations;
    const auto q = at("quat_wxyz").as_doubles(4);
    const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (std::abs(norm - 1.0) > 1e-6) {
      at("quat_wxyz").fail("a unit quaternion", "norm " + format_number(norm));
    }
    pose.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  }
  if (has("rotation")) {
    ++rotations;
    const YamlNode rows = at("rotation");
    if (!rows.is_sequence() || rows.size() != 3) rows.fail("3 rows of 3 numbers", describe());
    Eigen::Matrix3d r;
    for (int i = 0; i < 3; ++i) r.row(i) = rows.at(i).as_vec3().transpose();
    pose.linear() = r;
    check_pose(pose, *file_, path_ + ".rotation");
  }
  if (rotations > 1) fail("at most one of rpy_deg, rpy, quat_wxyz, rotation", "several");
  return pose;
}

std::string YamlNode::resolve_path(const std::string& relative) const {
  const std::filesystem::path p(relative);
  if (p.is_absolute()) return p.string();
  return (std::filesystem::path(*file_).parent_path() / p).lexically_normal().string();
}

}  // namespace hila::core
