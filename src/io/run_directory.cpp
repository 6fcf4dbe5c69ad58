#include "io/run_directory.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>

#include "io/run.hpp"

namespace hb {

namespace fs = std::filesystem;

namespace {

// Files whose presence marks a directory as holding a hardbody run.
constexpr std::array<const char*, 5> kRunMarkers = {"config.resolved.toml", "checkpoint.gsd", "summary.json",
                                                    "log.tsv", "log.tsv.part"};

bool holds_run(const fs::path& dir) {
  for (const char* m : kRunMarkers)
    if (fs::exists(dir / m)) return true;
  return false;
}

// Entries of dir other than the lock file.
bool has_entries_besides_lock(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename() != RunDirectory::kLockName) return true;
  return false;
}

}  // namespace

RunDirectory::RunDirectory(const std::string& path, bool resume, bool overwrite) : path_(path) {
  if (path.empty()) throw InputError("--out: empty path (give a directory, or leave --out out for ./run-<config stem>)");
  const fs::path dir(path);
  std::error_code ec;
  const auto st = fs::status(dir, ec);
  const bool exists = fs::exists(st);
  if (exists && !fs::is_directory(st))
    throw InputError(fmt::format("--out {}: exists and is not a directory", path));
  if (resume && !exists)
    throw InputError(fmt::format("{}/checkpoint.gsd: no checkpoint to resume from (the directory does not exist)", path));
  if (!exists) {
    fs::create_directories(dir, ec);
    if (ec) throw InputError(fmt::format("--out {}: cannot create the directory: {}", path, ec.message()));
    created_ = true;
  }
  const std::string lock = (dir / kLockName).string();
  fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    const int e = errno;
    discard_if_unused();
    throw InputError(fmt::format("--out {}: not writable ({})", path, std::strerror(e)));
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = {0};
    const ssize_t n = ::pread(fd_, pid, sizeof pid - 1, 0);
    ::close(fd_);
    fd_ = -1;
    throw InputError(fmt::format("{}: in use by another hardbody run{}; wait for it or choose another --out",
                                 path, n > 0 ? fmt::format(" (pid {})", std::string(pid, std::strcspn(pid, "\n"))) : ""));
  }
  const std::string me = fmt::format("{}\n", ::getpid());
  if (::ftruncate(fd_, 0) != 0 || ::pwrite(fd_, me.data(), me.size(), 0) != ssize_t(me.size())) {
    const int e = errno;
    discard_if_unused();
    throw InputError(fmt::format("--out {}: not writable ({})", path, std::strerror(e)));
  }
  if (resume) return;  // the checkpoint itself is checked by the resume
  if (!has_entries_besides_lock(dir)) return;
  if (!holds_run(dir))
    throw InputError(fmt::format("--out {}: exists, is not empty and holds no hardbody run; choose another directory", path));
  if (!overwrite)
    throw InputError(fmt::format("--out {}: holds a previous run; use --resume to continue it or --overwrite to replace it", path));
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().filename() == kLockName) continue;
    fs::remove_all(e.path(), ec);
    if (ec) throw InputError(fmt::format("--overwrite: cannot remove {}: {}", e.path().string(), ec.message()));
  }
}

RunDirectory::~RunDirectory() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

void RunDirectory::discard_if_unused() noexcept {
  if (!created_) return;
  std::error_code ec;
  const fs::path dir(path_);
  bool other = true;
  try {
    other = has_entries_besides_lock(dir);
  } catch (...) {
  }
  if (other) return;
  if (fd_ >= 0) ::close(fd_), fd_ = -1;
  fs::remove_all(dir, ec);
  created_ = false;
}

}  // namespace hb
