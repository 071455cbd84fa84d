#pragma once

#include <functional>
#include <string>
#include <vector>

namespace hila::core {
class Cell;
struct ProductSpec;
}  // namespace hila::core

namespace hila::tools {

// A file a command reads, with how messages name it ("the product file").
struct InputFile {
  std::string path;
  std::string role;
};

// The files behind a cell YAML: itself, its URDFs and every mesh those name. Collected for the
// output check only: a file that cannot be read is skipped here (its loader reports it).
std::vector<InputFile> cell_input_files(const std::string& cell_file);
// The files behind a product YAML: itself and every part mesh. Skips unreadable files likewise.
std::vector<InputFile> product_input_files(const std::string& product_file);

// Throws core::InputError (exit 2) for an output path `option` (e.g. "-o") that cannot be written
// safely, before any work: empty, a directory, a file name too long to take the temporary suffix
// the write adds, or the same file as one of `inputs` (the same path, a symbolic link to it or a
// hard link of it). The message names the option, the path and, for an input, its role.
void check_output_path(const std::string& option, const std::string& output,
                       const std::vector<InputFile>& inputs);

// Bytes a temporary file name may add to the output's name (".tmp-PID-N" and SQLite's
// "-journal"): a longer name cannot be written atomically.
inline constexpr std::size_t kTemporarySuffixBytes = 32;

// A temporary path beside `path`, unique to this process and call.
std::string temporary_path_beside(const std::string& path);

// Removes the temporaries of `path` (PATH.tmp-PID-..., the names temporary_path_beside and the
// database writer make) whose process no longer runs: a build killed while writing left them.
// A temporary of a running process, or anything else, is kept. Returns how many were removed.
int remove_dead_temporaries(const std::string& path) noexcept;

// Writes `path` through a temporary file beside it: `write` writes the temporary path (throwing
// on failure), which is then renamed into place. On any failure (no space, no permission, an
// exception from `write`) the temporary file is removed, a previous file at `path` is untouched,
// and the exception propagates (core::InputError naming `path` for a failed rename).
void write_atomically(const std::string& path,
                      const std::function<void(const std::string& temporary)>& write);
// write_atomically of a text; a failed write throws core::InputError naming `path` and the reason.
void write_file_atomically(const std::string& path, const std::string& text);

// Checks of the inputs' content that `product check` and `cell check` report and `build` makes
// before its long work.

// The pairs ("a <-> b") that interpenetrate with every part at its target (`at_targets`) or at
// its initial pose, beside the cell's obstacles; at the initial poses also the suction tool at
// product.suction_tool_pose.
std::vector<std::string> colliding_parts(const core::Cell& cell, const core::ProductSpec& product,
                                         bool at_targets);

// The colliding pair ("a <-> b") when the robot at home (jaws open) collides with itself, the
// obstacles or the human at the stance in the neutral posture; "" when it is collision-free.
std::string home_collision(const core::Cell& cell);

// A problem with a part's pose: an error makes `product check` exit 1, a warning does not.
struct PoseFinding {
  std::string part;
  std::string pose;  // "initial" or "target"
  bool error = true;
  std::string problem;
};
// Initial poses resting on an obstacle's top or on another part (the lowest point within 5 mm,
// not below), each within some robot arm's reach (the TCP's reach from the shoulder plus the
// suction cup's offset, against the part's bounding sphere): errors. Targets not below the top
// of the obstacle under them: errors; within the reach of a human arm at the stance: warnings.
std::vector<PoseFinding> check_part_poses(const core::Cell& cell, const core::ProductSpec& product);

}  // namespace hila::tools
