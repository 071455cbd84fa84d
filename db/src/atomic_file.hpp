#pragma once

#include <string>

namespace hila::db::detail {

// "<target>.tmp-<pid>-<n>": beside the target (same file system, so rename is atomic) and unique
// per process and call.
std::string temporary_path_for(const std::string& target);

// The folder holding `path` ("." for a bare file name).
std::string directory_of(const std::string& path);

// Removes temporaries of `target` left by writers that died without cleaning up (a SIGKILL
// leaves TARGET.tmp-PID-N behind): those whose PID no longer runs. Returns how many.
int remove_stale_temporaries(const std::string& target) noexcept;

// Throws DatabaseError naming the directory unless `target`'s folder exists and is writable, and
// naming the target if it is itself a directory.
void require_writable_directory(const std::string& target);

// Flushes a file's (or a directory's) data to disk. Throws DatabaseError naming `display_path`.
void fsync_path(const std::string& path, const std::string& display_path);

// Renames `from` over `to` (atomic on POSIX) and fsyncs the folder so the rename itself is durable.
// `from` must already be fsynced. Throws DatabaseError naming `to`.
void rename_into_place(const std::string& from, const std::string& to);

// Removes a file if present, ignoring errors (cleanup paths must not throw).
void remove_quietly(const std::string& path) noexcept;

}  // namespace hila::db::detail
