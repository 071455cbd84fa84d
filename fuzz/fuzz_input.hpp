#pragma once

// What every fuzz target shares: a scratch folder per process, the input written as a file there,
// and the rule that only hila's documented input errors are expected.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <string>

namespace hila::fuzz {

// A new folder under $TMPDIR (default /tmp), or the folder $HILA_FUZZ_DIR (emptied) when set,
// removed when the process exits normally. A fixed folder makes a run with a fixed seed
// repeatable: the path is in every error message, and libFuzzer learns from the strings the
// target compares. It holds a
// symbolic link to each file of meshes/`data_folder` whose extension is one of `extensions`
// (".stl"), so that the input can name the bundled meshes or URDFs by a relative path. Call once
// per process.
std::string work_dir(const std::string& data_folder, std::initializer_list<const char*> extensions);

// Writes the input to `dir`/`name` (a new file: never through a link) and returns its path.
std::string write_input(const std::string& dir, const std::string& name, const std::uint8_t* data,
                        std::size_t size);

// Runs `read`. core::InputError (and the errors derived from it, db::DatabaseError) is hila's
// documented answer to bad input (exit 2) and is expected; any other exception escapes, and
// libFuzzer reports it as a crash, as it does signals and sanitizer reports. With HILA_FUZZ_PRINT
// set in the environment each input error's message goes to stderr (is a seed read cleanly?).
void expect_input_errors_only(const std::function<void()>& read);

}  // namespace hila::fuzz
