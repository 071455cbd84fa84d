#include "io_checks.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "hila/core/cell.hpp"
#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/core/robot_model.hpp"
#include "hila/core/yaml_reader.hpp"

namespace hila::tools {

namespace fs = std::filesystem;

namespace {

// Every mesh a URDF's collision geometry names (the only meshes hila reads from a URDF).
void add_urdf_files(const std::string& urdf, const std::string& role,
                    std::vector<InputFile>& files) {
  files.push_back({urdf, role});
  try {
    const core::RobotModel model = core::RobotModel::load_urdf_file(urdf);
    for (const core::Link& link : model.links()) {
      for (const core::GeometrySpec& g : link.collisions) {
        if (g.type == core::GeometrySpec::Type::Mesh) {
          files.push_back({g.mesh_path, "a mesh of " + urdf});
        }
      }
    }
  } catch (const std::exception&) {
    // Unreadable: Cell::load reports it with the file and field.
  }
}

// The two paths name the same file: equal, a symbolic link to it, or a hard link of it.
// std::filesystem::equivalent answers when both exist; otherwise the normalised absolute paths
// are compared (an output that does not exist yet can still be spelled as an input).
bool same_file(const std::string& a, const std::string& b) {
  std::error_code error;
  if (fs::exists(a, error) && fs::exists(b, error)) {
    const bool equivalent = fs::equivalent(a, b, error);
    if (!error) return equivalent;
  }
  std::error_code error_a, error_b;
  const fs::path canonical_a = fs::weakly_canonical(a, error_a);
  const fs::path canonical_b = fs::weakly_canonical(b, error_b);
  if (error_a || error_b) {
    return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
  }
  return canonical_a == canonical_b;
}

std::string quoted(const std::string& s) {
  return "'" + s + "'";
}

}  // namespace

std::vector<InputFile> cell_input_files(const std::string& cell_file) {
  std::vector<InputFile> files{{cell_file, "the cell file"}};
  try {
    const core::CellSpec spec = core::load_cell_spec(cell_file);
    add_urdf_files(spec.robot_urdf, "the cell's robot URDF", files);
    add_urdf_files(spec.suction.tool_urdf, "the cell's suction tool URDF", files);
    add_urdf_files(spec.human_urdf, "the cell's human URDF", files);
  } catch (const std::exception&) {
    // Unreadable: Cell::load reports it with the file and field.
  }
  return files;
}

std::vector<InputFile> product_input_files(const std::string& product_file) {
  std::vector<InputFile> files{{product_file, "the product file"}};
  try {
    const core::YamlNode root = core::YamlNode::load_file(product_file);
    const core::YamlNode parts = root.at("parts");
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const core::YamlNode part = parts.at(i);
      if (!part.has("mesh")) continue;
      std::string name = part.has("name") ? part.at("name").as_string() : part.path();
      files.push_back({part.resolve_path(part.at("mesh").as_string()),
                       "the mesh of part '" + name + "'"});
    }
  } catch (const std::exception&) {
    // Unreadable: load_product reports it with the file and field.
  }
  return files;
}

void check_output_path(const std::string& option, const std::string& output,
                       const std::vector<InputFile>& inputs) {
  if (output.empty()) {
    throw core::InputError(option + ": expected an output file path, got ''");
  }
  std::error_code error;
  if (fs::is_directory(output, error)) {
    throw core::InputError(option + ": expected an output file path, got " + quoted(output) +
                           " (a directory)");
  }
  const std::string name = fs::path(output).filename().string();
  if (name.empty() || name == "." || name == "..") {
    throw core::InputError(option + ": expected an output file path, got " + quoted(output) +
                           " (a directory)");
  }
  const std::string dir = fs::path(output).parent_path().empty()
                              ? std::string(".")
                              : fs::path(output).parent_path().string();
  long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = 255;  // the folder is missing: the writer reports that
  if (name.size() + kTemporarySuffixBytes > static_cast<std::size_t>(name_max)) {
    throw core::InputError(option + ": expected a file name of at most " +
                           std::to_string(static_cast<std::size_t>(name_max) -
                                          kTemporarySuffixBytes) +
                           " bytes (the write adds a temporary suffix to it), got " +
                           std::to_string(name.size()) + " bytes in " + quoted(output));
  }
  for (const InputFile& input : inputs) {
    if (input.path.empty()) continue;
    if (same_file(output, input.path)) {
      // Spelled otherwise (a link, another relative path): say which input it is.
      const std::string role =
          output == input.path ? input.role : input.role + " " + quoted(input.path);
      throw core::InputError(option +
                             ": expected an output path that is not an input of the command, "
                             "got " +
                             quoted(output) + " (" + role + ")");
    }
  }
}

std::string temporary_path_beside(const std::string& path) {
  static std::atomic<unsigned long> counter{0};
  return path + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

void write_atomically(const std::string& path,
                      const std::function<void(const std::string& temporary)>& write) {
  const std::string temporary = temporary_path_beside(path);
  try {
    write(temporary);
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
      throw core::InputError(path, "(file)", "a writable path",
                             "cannot replace it (" + std::string(std::strerror(errno)) + ")");
    }
  } catch (...) {
    std::error_code ignored;
    fs::remove(temporary, ignored);
    throw;
  }
}

void write_file_atomically(const std::string& path, const std::string& text) {
  write_atomically(path, [&](const std::string& temporary) {
    auto fail = [&](const std::string& what) {
      throw core::InputError(path, "(file)", "a writable path",
                             what + " (" + std::string(std::strerror(errno)) + ")");
    };
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot create " + temporary);
    out << text;
    out.flush();
    if (!out) fail("the write failed");
    out.close();
    if (!out) fail("the write failed");
  });
}

int remove_dead_temporaries(const std::string& path) noexcept {
  int removed = 0;
  std::error_code error;
  const fs::path parent = fs::path(path).parent_path();
  const std::string prefix = fs::path(path).filename().string() + ".tmp-";
  for (const auto& entry : fs::directory_iterator(parent.empty() ? "." : parent, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0 || !entry.is_regular_file(error)) continue;
    // PATH.tmp-PID-N: the PID in decimal, then a dash.
    const std::string rest = name.substr(prefix.size());
    const auto dash = rest.find('-');
    if (dash == std::string::npos || dash == 0 || dash > 9) continue;
    if (!std::all_of(rest.begin(), rest.begin() + dash,
                     [](char c) { return c >= '0' && c <= '9'; }))
      continue;
    const pid_t pid = static_cast<pid_t>(std::stol(rest.substr(0, dash)));
    // kill(pid, 0) fails with ESRCH only when no such process exists; a running process (even
    // one that reused the PID) keeps its file.
    if (pid <= 0 || ::kill(pid, 0) == 0 || errno != ESRCH) continue;
    if (fs::remove(entry.path(), error)) ++removed;
  }
  return removed;
}

std::string home_collision(const core::Cell& cell) {
  const core::CellScene scene = core::build_cell_scene(cell, {.human_moves = true});
  core::CollisionData data(scene.model);
  core::set_cell_state(cell, scene, data, cell.home_configuration(cell.spec().gripper.jaw_max),
                       cell.human_neutral());
  core::CollisionPair pair;
  return core::in_collision(scene.model, data, &pair) ? core::describe_pair(scene.model, pair) : "";
}

}  // namespace hila::tools
