// Small file utilities: atomic whole-file writes (temporary name + rename), checked appends, and
// directories. Every write failure (a short write, ENOSPC, EIO from fsync or close) throws
// std::runtime_error "<file>: <what failed>: <OS error>", e.g. "run/summary.json.tmp: cannot
// write: No space left on device".
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace hb {

// Writes `content` to path + ".tmp", syncs it to disk, and renames it over `path`. On failure the
// temporary file is removed and the previous `path` is untouched.
void write_file_atomic(const std::string& path, const std::string& content);

// A file opened for appending whose every write is checked (for tables written row by row).
class AppendFile {
 public:
  AppendFile() = default;
  // Opens (creates; with truncate, empties) `path` for appending; throws on failure.
  explicit AppendFile(std::string path, bool truncate = false);
  ~AppendFile();
  AppendFile(AppendFile&& o) noexcept;
  AppendFile& operator=(AppendFile&& o) noexcept;
  AppendFile(const AppendFile&) = delete;
  AppendFile& operator=(const AppendFile&) = delete;

  void write(std::string_view text);  // all of it reaches the kernel, or it throws
  void sync();                        // fsync: on the disk
  void close();                       // throws if close reports an error
  bool is_open() const { return fd_ >= 0; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  int fd_ = -1;
};

// Writes all n bytes to fd (retrying short writes and EINTR); throws naming `path` and `what`.
void write_all(int fd, const void* data, std::size_t n, const std::string& path,
               std::string_view what = "cannot write");

// Creates a directory and its parents (like mkdir -p). Throws std::runtime_error on failure.
void make_directories(const std::string& path);
bool file_exists(const std::string& path);

}  // namespace hb
