#include "hila/core/product.hpp"

#include <algorithm>
#include <set>

#include "hila/core/error.hpp"
#include "hila/core/yaml_reader.hpp"

namespace hila::core {

double unit_scale_from_name(const std::string& unit, const std::string& file,
                            const std::string& field) {
  if (unit == "m") return 1.0;
  if (unit == "cm") return 0.01;
  if (unit == "mm") return 0.001;
  if (unit == "in") return 0.0254;
  throw InputError(file, field, "one of m, cm, mm, in", "'" + unit + "'");
}

namespace {
// The range of a part's mass (kg). 1 g: lighter than a small washer, a value below is a typo
// (1e-300) or a unit slip. 25 kg: the reference mass a person may lift at all (ISO 11228-1),
// so no part handed to a person weighs more, and over eight times a UR3's 3 kg rated payload;
// 100 or 800 are grams written as kilograms. Whether an arm lifts a part within its payload is
// `hila product check`'s question (exit 1), not this plausibility bound.
constexpr double kMinPartMass = 0.001;
constexpr double kMaxPartMass = 25.0;

// The name quoted on one line: control characters as \n, \t or \xNN.
std::string quoted_name(const std::string& name) {
  static const char* const kHex = "0123456789abcdef";
  std::string out = "'";
  for (const unsigned char c : name) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      out += std::string("\\x") + kHex[c >> 4] + kHex[c & 15];
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "'";
}

// A part name labels tables, messages, plan files and database rows: it must be one printable
// line.
void check_part_name(const YamlNode& node, const std::string& name) {
  if (name.empty()) node.fail("a non-empty part name", "''");
  for (const unsigned char c : name) {
    if (c < 0x20 || c == 0x7f) {
      node.fail("a part name on one line, without control characters", quoted_name(name));
    }
  }
}
}  // namespace

const PartSpec& ProductSpec::part(const std::string& part_name) const {
  for (const auto& p : parts) {
    if (p.name == part_name) return p;
  }
  std::string names;
  for (const auto& p : parts) names += (names.empty() ? "" : ", ") + p.name;
  throw InputError(file, "part", "one of: " + names, "'" + part_name + "'");
}

ProductSpec load_product(const std::string& path) {
  const YamlNode root = YamlNode::load_file(path);
  root.expect_only({"name", "assembly_frame", "suction_tool_pose", "parts"});
  ProductSpec product;
  product.file = path;
  product.name = root.at("name").as_string();
  product.assembly_frame = root.at("assembly_frame").as_pose();
  check_pose(product.assembly_frame, path, "assembly_frame");
  product.suction_tool_pose = root.at("suction_tool_pose").as_pose();
  check_pose(product.suction_tool_pose, path, "suction_tool_pose");
  const YamlNode parts = root.at("parts");
  if (!parts.is_sequence() || parts.size() == 0) parts.fail("a non-empty list of parts", "none");
  std::set<std::string> names;
  std::set<int> orders;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const YamlNode p = parts.at(i);
    p.expect_only({"name", "mesh", "mesh_unit", "mass", "target", "initial", "order"});
    PartSpec part;
    part.name = p.at("name").as_string();
    check_part_name(p.at("name"), part.name);
    if (!names.insert(part.name).second) p.at("name").fail("a unique part name", "a duplicate");
    part.mesh_file = p.resolve_path(p.at("mesh").as_string());
    part.unit_scale =
        unit_scale_from_name(p.at("mesh_unit").as_string(), path, p.path() + ".mesh_unit");
    part.mass = p.at("mass").as_double();
    if (part.mass < kMinPartMass || part.mass > kMaxPartMass) {
      p.at("mass").fail("a mass in kilograms in [" + format_number(kMinPartMass) + ", " +
                            format_number(kMaxPartMass) + "]",
                        format_number(part.mass));
    }
    part.target = p.at("target").as_pose();
    check_pose(part.target, path, p.path() + ".target");
    part.initial = p.at("initial").as_pose();
    check_pose(part.initial, path, p.path() + ".initial");
    part.order = p.at("order").as_int();
    if (!orders.insert(part.order).second)
      p.at("order").fail("a unique assembly order", "a duplicate");
    try {
      part.mesh = load_mesh(part.mesh_file, part.unit_scale);
    } catch (const InputError& e) {
      throw InputError(path, p.path() + ".mesh", "a readable, non-empty mesh with finite vertices",
                       std::string("'") + e.what() + "'");
    }
    const Eigen::Vector3d extent = part.mesh.max_corner() - part.mesh.min_corner();
    if (extent.maxCoeff() > 3.0) {
      throw InputError(path, p.path() + ".mesh_unit",
                       "a unit that gives a plausible part size (under 3 m)",
                       format_number(extent.maxCoeff()) + " m across (is the mesh in mm?)");
    }
    if (extent.maxCoeff() < 0.005) {
      throw InputError(path, p.path() + ".mesh_unit",
                       "a unit that gives a plausible part size (over 5 mm)",
                       format_number(extent.maxCoeff()) + " m across (is the mesh in m, not mm?)");
    }
    product.parts.push_back(std::move(part));
  }
  std::sort(product.parts.begin(), product.parts.end(),
            [](const PartSpec& a, const PartSpec& b) { return a.order < b.order; });
  for (std::size_t i = 0; i < product.parts.size(); ++i) {
    if (product.parts[i].order != static_cast<int>(i) + 1) {
      parts.fail("orders 1.." + std::to_string(product.parts.size()),
                 "order " + std::to_string(product.parts[i].order) + " at position " +
                     std::to_string(i + 1));
    }
  }
  return product;
}

}  // namespace hila::core
