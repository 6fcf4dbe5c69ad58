// Runs `hardbody run` in-process on a config text and returns the parsed summary.json.
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <unistd.h>
#include <vector>

#include "io/run.hpp"

namespace hbtest {

// The scratch directory of run `name`: under the temporary directory, named with this process's
// id, so that two test suites running at the same time (two checkouts on one machine) never
// write into each other's runs.
inline std::filesystem::path test_dir(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("hardbody-test-" + std::to_string(::getpid()) + "-" + name);
}

// The scratch directories this process made. They are removed when the process's tests end, if
// they all passed (ctest runs one test per process); a failed test's run stays for inspection,
// and HARDBODY_KEEP_TEST_RUNS=1 keeps them all.
inline std::vector<std::filesystem::path>& scratch_dirs() {
  static std::vector<std::filesystem::path> dirs;
  return dirs;
}
class ScratchCleanup : public ::testing::Environment {
 public:
  void TearDown() override {
    if (std::getenv("HARDBODY_KEEP_TEST_RUNS") || !::testing::UnitTest::GetInstance()->Passed()) return;
    for (const auto& d : scratch_dirs()) {
      std::error_code ec;
      std::filesystem::remove_all(d, ec);
    }
  }
};
inline const bool kScratchCleanupRegistered =
    (::testing::AddGlobalTestEnvironment(new ScratchCleanup), true);

inline nlohmann::json run_config(const std::string& name, const std::string& text,
                                 const std::vector<std::string>& overrides = {}) {
  const auto dir = test_dir(name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  scratch_dirs().push_back(dir);
  const auto cfg = dir / (name + ".toml");
  std::ofstream(cfg) << text;
  hb::RunOptions opt;
  opt.config_path = cfg.string();
  opt.out_dir = (dir / "out").string();
  opt.overrides = overrides;
  opt.quiet = true;
  hb::run_simulation(opt);
  std::ifstream in(dir / "out" / "summary.json");
  return nlohmann::json::parse(in);
}

// Hansen-Goos (J. Chem. Phys. 144, 164506 (2016)) hard-sphere equation of state,
// ../shared/reference/README.md; accurate to ~1e-4 in the fluid.
inline double z_hansen_goos(double phi) {
  const double b[8] = {9, -19, 47.0 / 3.0, -2.635232, -1.265575, 0.041212, 0.248245, -0.096495};
  double s = 0.0, p = 1.0;
  for (double bk : b) s += bk * p, p *= phi;
  const double q = 1.0 - phi;
  return 8.0 * std::log(q) / phi + s / (q * q * q);
}

inline std::string sphere_config(int n, double phi, double teq, double t, int seed = 1,
                                 double log_interval = 0.1) {
  return "[system]\nparticles = " + std::to_string(n) + "\npacking_fraction = " +
         std::to_string(phi) + "\nseed = " + std::to_string(seed) +
         "\n[shape]\ntype = \"sphere\"\nradius = 0.5\n[run]\nequilibrate_time = " +
         std::to_string(teq) + "\ntime = " + std::to_string(t) +
         "\n[output]\nlog_interval = " + std::to_string(log_interval) + "\n";
}

}  // namespace hbtest
