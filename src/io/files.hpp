// Small file utilities: atomic whole-file writes (temporary name + rename) and directories.
#pragma once
#include <string>

namespace hb {

// Writes `content` to path + ".tmp", flushes it, and renames it over `path`. Throws
// std::runtime_error naming the file on failure; the previous file is never destroyed.
void write_file_atomic(const std::string& path, const std::string& content);
// Creates a directory and its parents (like mkdir -p). Throws std::runtime_error on failure.
void make_directories(const std::string& path);
bool file_exists(const std::string& path);

}  // namespace hb
