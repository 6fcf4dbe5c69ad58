// The output directory of `hardbody run`: one run, one process, nothing overwritten by accident.
//
//  - A new run (no --resume) needs a missing or empty directory. One that holds a previous run is
//    refused unless `overwrite` (--overwrite): then the old run's files are removed first, so no
//    stale plot, frame or table of the old run survives next to the new one. A non-empty directory
//    that holds no run is never emptied.
//  - --resume needs the directory and its checkpoint.
//  - The directory is locked (flock on DIR/.hardbody.lock) for the life of the process: a second
//    run on the same directory is refused at once instead of corrupting both. The lock file stays
//    (unlinking it would let a waiting process lock a file nobody else sees).
//  - Every check (path is a directory, writable, not locked) happens before any simulation work.
//    A directory this process created is removed again if the run stops with bad input
//    (`discard_if_unused`), so exit status 2 leaves nothing behind.
#pragma once
#include <string>

namespace hb {

class RunDirectory {
 public:
  // Throws InputError (exit 2) naming the directory and what to do.
  RunDirectory(const std::string& path, bool resume, bool overwrite);
  ~RunDirectory();
  RunDirectory(const RunDirectory&) = delete;
  RunDirectory& operator=(const RunDirectory&) = delete;

  const std::string& path() const { return path_; }
  // Removes the directory if this process created it and nothing but the lock is in it.
  void discard_if_unused() noexcept;

  static constexpr const char* kLockName = ".hardbody.lock";

 private:
  std::string path_;
  int fd_ = -1;
  bool created_ = false;
};

}  // namespace hb
