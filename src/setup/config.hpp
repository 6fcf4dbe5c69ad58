// The run configuration as data: what the builder (setup/builder.hpp) assembles a run from.
// Reading, validating and writing it (TOML) is io/config.hpp; every field is a config key there.
#pragma once
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "math/types.hpp"
#include "core/boundaries.hpp"
#include "core/species.hpp"
#include "shapes/registry.hpp"

namespace hb {

// Bad configuration: exit status 2, one message naming the file, the key and, where known, the line.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

inline constexpr std::uint64_t kLastFrame = ~std::uint64_t(0);

struct Config {
  std::string source;  // file the config was read from
  // [system]
  std::uint64_t particles = 0;  // N: the total over the species
  double packing_fraction = 0.0;  // optional with walls.sphere: the reader sets N v / V_container
  std::uint64_t seed = 1;
  double temperature = 1.0;
  // [[species]], or the one-species shorthand [shape] + system.particles + system.mass (+
  // shape.inertia: a spherical top, default 2/5 m r_min^2), resolved into one species named
  // after the shape type
  SpeciesTable species{Species{}};
  bool species_given = false;  // written back as [[species]] (else as the shorthand)

  const Species& one() const { return species.front(); }  // the species of a one-species run
  bool mixture() const { return species.size() > 1 || species.front().poly.active(); }
  // [box], [walls]: the box's side ratios, hard planar walls or a spherical container (the box
  // itself: setup/box_setup.hpp box_for)
  BoundarySpec boundaries;
  // [thermostat]
  ThermostatSpec thermostat;
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
  double max_output_gb = 20.0;  // a run whose files would exceed this (estimated) is refused
  // [init]  dense starts of non-spherical bodies
  std::string init_method = "auto";  // "grow" (Lubachevsky–Stillinger from init.phi0) | "lattice"
                                     // ("auto" is resolved by load_config)
  double init_phi0 = 0.1;            // packing fraction of the dilute lattice that is grown
  std::string init_file;             // init.method = "file": the GSD file of the start
  std::uint64_t init_frame = kLastFrame;  // its frame (kLastFrame: the last)
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

}  // namespace hb
