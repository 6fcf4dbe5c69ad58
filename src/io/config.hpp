// The run configuration (TOML), validated in full before anything is written. Every problem is
// reported as one ConfigError naming the file, the key and, where known, the line.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "math/types.hpp"

namespace hb {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ShapeSpec {
  std::string type = "sphere";  // sphere | ellipsoid | superquadric
  double radius = 0.5;          // sphere
  Vec3 semi_axes = Vec3(0.5, 0.5, 0.5);
  Vec3 exponents = Vec3(2, 2, 2);
  double inertia = 0.0;         // scalar moment of inertia; 0 = default 2/5 m r_min^2

  double volume() const;        // body volume
  double max_semi_axis() const;
};

struct Config {
  std::string source;  // file the config was read from
  // [system]
  std::uint64_t particles = 0;
  double packing_fraction = 0.0;
  std::uint64_t seed = 1;
  double temperature = 1.0;
  double mass = 1.0;
  // [shape]
  ShapeSpec shape;
  // [run]
  double equilibrate_time = 0.0;
  double time = 0.0;
  std::uint64_t max_collisions = 0;  // 0: no limit; otherwise the measured run stops there
  // [neighbors]
  std::string neighbors_method = "cells";  // default: "cells" for spheres, "nnl" otherwise
  double shell = 0.15;
  // [solver]
  double eps_d = 1e-5;
  // [output]
  double log_interval = 1.0;
  double snapshot_interval = 10.0;
  double checkpoint_interval = 600.0;  // wall seconds
  bool trajectory = true;
  // [init]  dense starts of non-spherical bodies
  std::string init_method = "grow";  // "grow" (Lubachevsky–Stillinger from init.phi0) | "lattice"
  double init_phi0 = 0.1;            // packing fraction of the dilute lattice that is grown
  double init_growth_rate = 0.05;    // d(scale)/dt of the growth
  // [observables]
  double obs_interval = 0.1;     // sampling interval of MSD, C2, F_self (0: off)
  std::uint64_t obs_origin_every = 10;
  double obs_max_lag = 10.0;     // longest lag time of the correlation tables
  double obs_q = 2.0 * kPi;      // target |q| of F_self
  std::uint64_t obs_q_vectors = 6;
  double gr_interval = 5.0;      // sampling interval of g(r) (0: off)
  std::uint64_t gr_bins = 200;
};

// Reads and validates a config file; `overrides` are "section.key=value" strings (--set) whose
// values are TOML literals. Throws ConfigError.
Config load_config(const std::string& path, const std::vector<std::string>& overrides = {});
// Parses and validates TOML text (for tests); `name` is used in messages.
Config parse_config(const std::string& text, const std::string& name,
                    const std::vector<std::string>& overrides = {});
// The fully resolved config, every key present, as TOML text.
std::string to_toml(const Config& c);

}  // namespace hb
