#include "io/resources.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <variant>

#include <fmt/format.h>

namespace hb {

namespace {

// ---- calibration ------------------------------------------------------------------------------
// Peak memory = kBaseBytes + N x (bytes per body of the model and neighbour method) + the
// correlation origins + the per-log-row series. Measured as the peak resident set (VmHWM of
// /proc/<pid>/status, read as getrusage(RUSAGE_CHILDREN).ru_maxrss by a Python wrapper) of
// `hardbody run` (Release, GCC 12, the tree of issue 13) with observables.interval = 0,
// gr_interval = 0, trajectory off, run.time = 0.01 (the first checkpoint, written at once,
// included), and the slope between sizes taken, rounded up by ~15 %:
//   spheres, cells, phi 0.45:       N = 32000 / 256000 / 864000:  24.8 / 104.8 / 338.4 MB (~384 B)
//   ellipsoids X0 = 2, nnl, phi 0.3: N = 4000 / 32000 / 108000:   11.9 / 39.4 / 96.4 MB (~750-980 B);
//     grown from phi0 = 0.1 to 0.15 at N = 32000: 37.4 MB (growth adds nothing measurable)
//   superquadrics [1.6, 0.8, 0.8] p = 4, nnl: N = 4000 / 32000:     12.0 / 38.1 MB (~930 B)
//   binary spheres, cells, phi 0.11: N = 32000 / 256000:          25.6 / 129.4 MB (~463 B)
//   64 correlation origins, N = 256000 spheres: +1237 MB (75 B per body and origin, the
//     checkpoint's copy included; the checkpoint file grows by 25 B per body and origin)
// Sphere neighbour lists and rigid mixtures were not measured: they take the rigid figure.
constexpr double kBaseBytes = 16e6;
constexpr double kSphereCellsBytes = 440.0;   // one species of spheres, cell lists
constexpr double kSphereMixtureBytes = 540.0; // sphere mixtures and polydisperse spheres
constexpr double kRigidBytes = 1000.0;        // ellipsoids, superquadrics, nnl, rigid mixtures
// TimeCorrelations keeps 6 doubles per body per live origin, at most kMaxOrigins (the default
// CorrelationSpec::max_origins).
constexpr double kMaxOrigins = 64.0;
constexpr double kOriginBytes = 86.0;
constexpr double kOriginCheckpointBytes = 28.0;
// Per log row kept in memory: Z and rate blocks, species temperatures per axis, the nematic series.
constexpr double kLogRowMemory = 32.0;
constexpr double kLogRowMemoryPerSpecies = 64.0;
// Files, measured: a GSD frame (HOOMD float positions and orientations plus the exact doubles
// under log/particles/hardbody/) 115-129 B per body (spheres N = 32000, superquadrics N = 4000);
// a checkpoint 340-430 B per body; a log.tsv / nematic.tsv row and a correlations.tsv row.
constexpr double kFrameBytesPerBody = 140.0;
constexpr double kFrameHeaderBytes = 16e3;    // per species: a superquadric's ConvexPolyhedron
constexpr double kCheckpointBytesPerBody = 480.0;
constexpr double kLogRowBytes = 160.0;
constexpr double kLagRowBytes = 200.0;

double per_body_bytes(const Config& c) {
  bool spheres = true;
  for (const Species& sp : c.species) spheres = spheres && std::holds_alternative<Sphere>(sp.shape);
  if (!spheres || c.neighbors_method != "cells") return kRigidBytes;
  return c.mixture() ? kSphereMixtureBytes : kSphereCellsBytes;
}

std::string size(double bytes) {
  if (bytes >= 1e9) return fmt::format("{:.3g} GB", bytes / 1e9);
  if (bytes >= 1e6) return fmt::format("{:.3g} MB", bytes / 1e6);
  return fmt::format("{:.3g} kB", bytes / 1e3);
}

}  // namespace

ResourceEstimate estimate_resources(const Config& c) {
  ResourceEstimate e;
  const double n = double(c.particles);
  const double species = double(c.species.size());
  const double tables = c.mixture() ? 1.0 + species : 1.0;  // whole system + one per species
  e.log_rows = std::ceil(c.time / c.log_interval);
  e.frames = c.trajectory ? std::floor(c.time / c.snapshot_interval) + 2.0 : 0.0;
  double origins = 0.0;
  if (c.obs_interval > 0.0) {
    e.lags = std::floor(c.obs_max_lag / c.obs_interval) + 1.0;
    origins = std::min(kMaxOrigins, std::ceil(e.lags / double(c.obs_origin_every)) + 1.0);
  }
  e.memory_bytes = kBaseBytes + n * per_body_bytes(c) + tables * origins * n * kOriginBytes +
                   e.log_rows * (kLogRowMemory + kLogRowMemoryPerSpecies * species) +
                   e.lags * tables * 12 * 8;
  e.trajectory_bytes = e.frames * (kFrameHeaderBytes * species + kFrameBytesPerBody * n);
  e.log_bytes = e.log_rows * kLogRowBytes * 2.0;
  e.table_bytes = e.lags * tables * kLagRowBytes + double(c.gr_bins) * 40.0 * (1.0 + species * species);
  e.checkpoint_bytes = n * kCheckpointBytesPerBody + tables * origins * n * kOriginCheckpointBytes;
  return e;
}

double available_memory_bytes() {
  std::ifstream in("/proc/meminfo");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string name, unit;
    double kb = 0.0;
    if (ss >> name >> kb >> unit && name == "MemAvailable:") return kb * 1024.0;
  }
  return 0.0;
}

void check_resources(const Config& c, double available_bytes) {
  const ResourceEstimate e = estimate_resources(c);
  if (available_bytes > 0.0 && e.memory_bytes > available_bytes)
    throw ConfigError(fmt::format(
        "{}: key 'system.particles': the run needs about {} of memory (N = {}), more than the {} "
        "available (MemAvailable in /proc/meminfo); use fewer bodies{}",
        c.source, size(e.memory_bytes), c.particles, size(available_bytes),
        c.obs_interval > 0.0 ? " or fewer correlation origins (observables.interval, origin_every)" : ""));
  const double limit = c.max_output_gb * 1e9;
  if (e.output_bytes() <= limit) return;
  // the largest part names the key to change
  const double parts[] = {e.trajectory_bytes, e.log_bytes, e.table_bytes, e.checkpoint_bytes};
  const int big = int(std::max_element(std::begin(parts), std::end(parts)) - std::begin(parts));
  const std::string what[] = {
      fmt::format("output.snapshot_interval = {}: {:.3g} trajectory frames, {}", c.snapshot_interval,
                  e.frames, size(e.trajectory_bytes)),
      fmt::format("output.log_interval = {}: {:.3g} log rows, {}", c.log_interval, e.log_rows, size(e.log_bytes)),
      fmt::format("observables.interval = {}: {:.3g} correlation lags up to observables.max_lag, {}",
                  c.obs_interval, e.lags, size(e.table_bytes)),
      fmt::format("system.particles = {}: checkpoint.gsd of {}", c.particles, size(e.checkpoint_bytes))};
  throw ConfigError(fmt::format("{}: {}: the run would write about {} in all, more than output.max_output_gb = {} "
                                "(raise it to allow this)",
                                c.source, what[big], size(e.output_bytes()), c.max_output_gb));
}

}  // namespace hb
