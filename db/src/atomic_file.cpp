#include "atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "hila/db/database.hpp"

namespace hila::db::detail {

namespace fs = std::filesystem;

std::string temporary_path_for(const std::string& target) {
  static std::atomic<unsigned long> counter{0};
  return target + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

int remove_stale_temporaries(const std::string& target) noexcept {
  int removed = 0;
  std::error_code ec;
  const std::string prefix = fs::path(target).filename().string() + ".tmp-";
  for (const auto& entry : fs::directory_iterator(directory_of(target), ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string rest = name.substr(prefix.size());
    const auto dash = rest.find('-');
    if (dash == std::string::npos || dash == 0) continue;
    const std::string pid_text = rest.substr(0, dash);
    char* end = nullptr;
    const long pid = std::strtol(pid_text.c_str(), &end, 10);
    if (end == nullptr || *end != '\0' || pid <= 0) continue;
    // kill(pid, 0) fails with ESRCH only when no such process exists.
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    if (fs::remove(entry.path(), ec)) ++removed;
  }
  return removed;
}

std::string directory_of(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

void require_writable_directory(const std::string& target) {
  const std::string dir = directory_of(target);
  const std::string expected = "a writable directory to write " + target + " into";
  std::error_code ec;
  const auto dir_status = fs::status(dir, ec);
  if (!fs::exists(dir_status)) {
    throw DatabaseError(dir, "(directory)", expected, "no such directory",
                        "create it or choose another output path");
  }
  if (!fs::is_directory(dir_status)) {
    throw DatabaseError(dir, "(directory)", expected, "a file", "choose another output path");
  }
  // access() answers for the real user, which is who creates the temporary file.
  if (::access(dir.c_str(), W_OK | X_OK) != 0) {
    throw DatabaseError(
        dir, "(directory)", expected,
        "a directory without write permission (" + std::string(std::strerror(errno)) + ")",
        "make it writable or choose another output path");
  }
  if (fs::is_directory(fs::status(target, ec))) {
    throw DatabaseError(target, "(file)", "a file path to write the database to", "a directory",
                        "give a file name, e.g. " + (fs::path(target) / "product.db").string());
  }
}

void fsync_path(const std::string& path, const std::string& display_path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0 || ::fsync(fd) != 0) {
    const std::string reason = std::strerror(errno);
    if (fd >= 0) ::close(fd);
    throw DatabaseError(display_path, "(file)", "a file that can be flushed to disk",
                        "fsync failed: " + reason);
  }
  if (::close(fd) != 0) {
    throw DatabaseError(display_path, "(file)", "a file that can be flushed to disk",
                        "close failed: " + std::string(std::strerror(errno)));
  }
}

void rename_into_place(const std::string& from, const std::string& to) {
  if (std::rename(from.c_str(), to.c_str()) != 0) {
    throw DatabaseError(to, "(file)", "a path the new database can be renamed to",
                        "rename from " + from + " failed: " + std::strerror(errno));
  }
  const std::string dir = directory_of(to);
  fsync_path(dir, dir);
}

void remove_quietly(const std::string& path) noexcept {
  std::error_code ec;
  fs::remove(path, ec);
}

}  // namespace hila::db::detail
