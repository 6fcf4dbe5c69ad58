// `hardbody run`: configuration -> system -> event loop with observers -> output files.
#pragma once
#include <stdexcept>
#include <string>
#include <vector>

namespace hb {

struct RunOptions {
  std::string config_path;
  std::string out_dir;  // empty: ./run-<config stem>
  std::vector<std::string> overrides;
  bool out_given = false;  // --out was given (then an empty out_dir is an error)
  bool resume = false;
  bool overwrite = false;  // replace a previous run in out_dir (io/run_directory.hpp)
  bool quiet = false;   // no progress line
};

// Bad input (config, files): exit status 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};
// A failure while running (solver failure, overlap found): exit status 3.
class RunFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Stopped by SIGINT/SIGTERM after writing a checkpoint: exit status 128 + signal.
class RunInterrupted : public std::runtime_error {
 public:
  RunInterrupted(const std::string& what, int sig) : std::runtime_error(what), signal(sig) {}
  int signal;
};

// Runs the simulation; throws ConfigError / InputError / RunFailure.
void run_simulation(const RunOptions& opt);

}  // namespace hb
