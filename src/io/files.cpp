#include "io/files.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <fmt/format.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <utility>

namespace hb {

namespace {

[[noreturn]] void fail(const std::string& path, std::string_view what, int err) {
  throw std::runtime_error(fmt::format("{}: {}: {}", path, what, std::strerror(err)));
}

// fsync of the directory that holds `path`, so that a rename into it survives a crash.
void sync_parent(const std::string& path) {
  const auto p = std::filesystem::path(path);
  const auto dir = p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // the rename is done; durability of the directory entry is best effort
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

void write_all(int fd, const void* data, std::size_t n, const std::string& path,
               std::string_view what) {
  const auto* p = static_cast<const char*>(data);
  while (n > 0) {
    const ssize_t r = ::write(fd, p, n);
    if (r < 0 && errno == EINTR) continue;
    if (r < 0) fail(path, what, errno);
    if (r == 0) fail(path, what, ENOSPC);  // no progress: only a full device does that
    p += r;
    n -= static_cast<std::size_t>(r);
  }
}

void write_file_atomic(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp";
  try {
    AppendFile f(tmp, true);
    f.write(content);
    f.sync();
    f.close();
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    fail(path, "cannot rename " + tmp + " into place", e);
  }
  sync_parent(path);
}

AppendFile::AppendFile(std::string path, bool truncate) : path_(std::move(path)) {
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC | (truncate ? O_TRUNC : 0),
               0644);
  if (fd_ < 0) fail(path_, "cannot open for writing", errno);
}

AppendFile::~AppendFile() {
  if (fd_ >= 0) ::close(fd_);
}

AppendFile::AppendFile(AppendFile&& o) noexcept
    : path_(std::move(o.path_)), fd_(std::exchange(o.fd_, -1)) {}

AppendFile& AppendFile::operator=(AppendFile&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(o.path_);
    fd_ = std::exchange(o.fd_, -1);
  }
  return *this;
}

void AppendFile::write(std::string_view text) {
  if (fd_ < 0) throw std::logic_error(fmt::format("{}: write after close", path_));
  write_all(fd_, text.data(), text.size(), path_);
}

void AppendFile::sync() {
  if (fd_ >= 0 && ::fsync(fd_) != 0) fail(path_, "cannot sync to disk", errno);
}

void AppendFile::close() {
  if (fd_ < 0) return;
  if (::close(std::exchange(fd_, -1)) != 0) fail(path_, "cannot close", errno);
}

void make_directories(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) throw std::runtime_error(fmt::format("{}: cannot create directory: {}", path, ec.message()));
}

bool file_exists(const std::string& path) { return std::filesystem::exists(path); }

}  // namespace hb
