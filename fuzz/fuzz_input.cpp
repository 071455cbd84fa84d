#include "fuzz_input.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "hila/core/error.hpp"

namespace hila::fuzz {

namespace fs = std::filesystem;

namespace {

std::string& created_dir() {
  static std::string dir;
  return dir;
}

void remove_created_dir() {
  std::error_code ignored;
  fs::remove_all(created_dir(), ignored);
}

}  // namespace

std::string work_dir(const std::string& data_folder,
                     std::initializer_list<const char*> extensions) {
  if (!created_dir().empty()) std::abort();  // one per process
  std::string dir;
  if (const char* fixed = std::getenv("HILA_FUZZ_DIR"); fixed != nullptr && *fixed != '\0') {
    dir = fixed;  // the same path on every run (fuzz/run --runs)
    fs::remove_all(dir);
    fs::create_directories(dir);
  } else {
    const char* tmp = std::getenv("TMPDIR");
    dir = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/hila_fuzz_XXXXXX";
    if (mkdtemp(dir.data()) == nullptr) {
      std::perror(dir.c_str());
      std::abort();
    }
  }
  created_dir() = dir;
  std::atexit(remove_created_dir);
  for (const auto& entry : fs::directory_iterator(fs::path(HILA_DATA_DIR) / data_folder)) {
    for (const char* extension : extensions) {
      if (entry.path().extension() == extension) {
        fs::create_symlink(entry.path(), fs::path(dir) / entry.path().filename());
      }
    }
  }
  return dir;
}

std::string write_input(const std::string& dir, const std::string& name, const std::uint8_t* data,
                        std::size_t size) {
  const fs::path path = fs::path(dir) / name;
  fs::remove(path);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::perror(path.c_str());
    std::abort();
  }
  return path.string();
}

void expect_input_errors_only(const std::function<void()>& read) {
  try {
    read();
  } catch (const core::InputError& e) {
    // The input was refused with a message naming the file, the field and what was expected.
    static const bool print = std::getenv("HILA_FUZZ_PRINT") != nullptr;
    if (print) std::fprintf(stderr, "input error: %s\n", e.what());
  }
}

}  // namespace hila::fuzz
