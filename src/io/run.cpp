#include "io/run.hpp"

#include <fmt/format.h>

#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/config.hpp"
#include "io/files.hpp"
#include "io/progress.hpp"
#include "observers/overlap.hpp"
#include "observers/thermo.hpp"
#include "system/init.hpp"
#include "system/sphere_setup.hpp"

namespace hb {

namespace {

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

std::string default_out_dir(const std::string& config_path) {
  return "run-" + std::filesystem::path(config_path).stem().string();
}

nlohmann::json shape_json(const ShapeSpec& s) {
  nlohmann::json j;
  j["type"] = s.type;
  if (s.type == "sphere") {
    j["radius"] = s.radius;
  } else {
    j["semi_axes"] = {s.semi_axes.x(), s.semi_axes.y(), s.semi_axes.z()};
    if (s.type == "superquadric") j["exponents"] = {s.exponents.x(), s.exponents.y(), s.exponents.z()};
  }
  return j;
}

// Everything a hard-sphere run needs, checked before any file is written.
struct SpherePlan {
  SphereSystemSpec spec;
  Box box;
};

SpherePlan plan_spheres(const Config& c) {
  SpherePlan p;
  p.spec.n = c.particles;
  p.spec.phi = c.packing_fraction;
  p.spec.sigma = 2.0 * c.shape.radius;
  p.spec.mass = c.mass;
  p.spec.kT = c.temperature;
  p.spec.seed = c.seed;
  const double v = c.shape.volume();
  p.box = cubic_box_for(c.particles, v, c.packing_fraction);
  const double phi_max = fcc_max_packing_fraction(c.particles);
  if (c.packing_fraction > phi_max * (1.0 - 1e-12))
    throw ConfigError(fmt::format(
        "{}: key 'system.packing_fraction': {} is too dense for an FCC start with {} particles "
        "(at most {:.4f}; use N = 4 m^3 for up to 0.74)",
        c.source, c.packing_fraction, c.particles, phi_max));
  if (p.box.L.minCoeff() < 2.0 * p.spec.sigma)
    throw ConfigError(fmt::format(
        "{}: key 'system.particles': {} particles at packing fraction {} give a box of side "
        "{:.3g}, less than two diameters; use more particles",
        c.source, c.particles, c.packing_fraction, p.box.L.x()));
  return p;
}

class LogTable {
 public:
  explicit LogTable(std::string path) : path_(std::move(path)), part_(path_ + ".part") {
    out_.open(part_);
    if (!out_) throw InputError(fmt::format("{}: cannot write", part_));
    out_ << "time\tcollisions\tZ_block\tZ_mean\ttemperature\tenergy_drift\tcollision_rate\n";
  }
  template <class... T>
  void row(const T&... v) {
    std::string s;
    ((s += fmt::format("{:.10g}\t", v)), ...);
    s.back() = '\n';
    out_ << s;
    out_.flush();
  }
  void commit() {
    out_.close();
    std::filesystem::rename(part_, path_);
  }

 private:
  std::string path_, part_;
  std::ofstream out_;
};

}  // namespace

void run_simulation(const RunOptions& opt) {
  Config cfg = load_config(opt.config_path, opt.overrides);
  if (opt.resume) throw InputError("--resume: checkpoint restart is not implemented yet");
  if (cfg.shape.type != "sphere")
    throw InputError(fmt::format(
        "{}: key 'shape.type': '{}' bodies are not yet supported by `hardbody run` (only "
        "spheres; `hardbody distance` and `contact-time` take any shape)",
        cfg.source, cfg.shape.type));
  if (cfg.neighbors_method == "nnl")
    cfg.neighbors_method = "cells";  // spheres: cell lists are the neighbour method
  const SpherePlan plan = plan_spheres(cfg);

  // Build the system before writing anything: a bad start fails with nothing on disk.
  auto sim = make_hard_sphere_simulation(plan.spec);
  {
    const auto rep = sphere_overlaps(sim.state().r, sim.box(), plan.spec.sigma);
    if (rep.overlaps > 0)
      throw InputError(fmt::format("{}: the initial configuration has {} overlapping pairs",
                                   cfg.source, rep.overlaps));
  }
  const std::string dir = opt.out_dir.empty() ? default_out_dir(opt.config_path) : opt.out_dir;
  try {
    make_directories(dir);
    write_file_atomic(dir + "/config.resolved.toml", to_toml(cfg));
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }

  const std::size_t n = cfg.particles;
  const double mass = cfg.mass;
  const double t_eq = cfg.equilibrate_time, t_end = cfg.equilibrate_time + cfg.time;
  Progress progress;
  const double cpu0 = cpu_seconds();
  VirialPressure pressure;
  auto kT_now = [&](const State& s) { return 2.0 * kinetic_energy(s, mass) / (3.0 * double(n)); };

  // Equilibration: same dynamics, nothing measured.
  while (sim.now() < t_eq) {
    const double target = std::min(t_eq, sim.now() + cfg.log_interval);
    while (sim.step(target).type != EventType::None) {
    }
    progress.update("equilibrate", sim.now(), sim.collisions(), 0.0, sim.now() / t_end);
  }

  // Measurement.
  LogTable log(dir + "/log.tsv");
  const double e0 = kinetic_energy(sim.state(), mass);
  const std::uint64_t coll0 = sim.collisions();
  const auto events0 = sim.event_counts();
  const std::uint64_t stale0 = sim.stale_events();
  const double cpu_m0 = cpu_seconds(), wall_m0 = progress.wall_seconds();
  bool limit_hit = false;
  while (sim.now() < t_end && !limit_hit) {
    const double t0 = sim.now();
    const double target = std::min(t_end, t0 + cfg.log_interval);
    for (;;) {
      const StepInfo s = sim.step(target);
      if (s.type == EventType::None) break;
      if (s.type == EventType::Collision && !s.stale) {
        pressure.on_collision(s.record);
        if (cfg.max_collisions && sim.collisions() - coll0 >= cfg.max_collisions) {
          limit_hit = true;
          break;
        }
      }
    }
    const double kT = kT_now(sim.state());
    pressure.close_block(sim.now() - t0, kT, n);
    const double e = kinetic_energy(sim.state(), mass);
    log.row(sim.now() - t_eq, double(sim.collisions() - coll0), pressure.last_Z(), pressure.Z().mean,
            kT, (e - e0) / e0, pressure.collision_rate().mean);
    progress.update("measure", sim.now(), sim.collisions(), pressure.Z().mean,
                    std::max((sim.now()) / t_end,
                             cfg.max_collisions ? double(sim.collisions() - coll0) / cfg.max_collisions : 0.0));
  }
  progress.finish();
  const double cpu = cpu_seconds() - cpu_m0, wall = progress.wall_seconds() - wall_m0;

  sim.synchronize();
  const State& st = sim.state();
  const double e1 = kinetic_energy(st, mass);
  const Vec3 p = total_momentum(st, mass);
  double p_scale = 0.0;
  for (const auto& v : st.v) p_scale += mass * v.norm();
  const auto rep = sphere_overlaps(st.r, sim.box(), plan.spec.sigma);
  const std::uint64_t ncoll = sim.collisions() - coll0;
  const auto Z = pressure.Z();
  const auto rate = pressure.collision_rate();

  nlohmann::json j;
  j["particles"] = n;
  j["packing_fraction"] = double(n) * cfg.shape.volume() / sim.box().volume();
  j["box"] = {sim.box().L.x(), sim.box().L.y(), sim.box().L.z()};
  j["shape"] = shape_json(cfg.shape);
  j["time"] = pressure.measured_time();
  j["collisions"] = ncoll;
  j["wall_seconds"] = wall;
  j["cpu_seconds"] = cpu;
  j["collisions_per_second"] = cpu > 0 ? double(ncoll) / cpu : 0.0;
  j["tau_c_us"] = ncoll > 0 ? 1e6 * cpu / double(ncoll) : 0.0;
  j["Z"] = Z.mean;
  j["Z_error"] = Z.error;
  j["Z_blocks"] = Z.blocks;
  j["collision_rate"] = rate.mean;
  j["collision_rate_error"] = rate.error;
  j["temperature"] = kT_now(st);
  j["energy_drift"] = (e1 - e0) / e0;
  j["total_momentum"] = {p.x(), p.y(), p.z()};
  j["momentum_drift"] = p.norm() / p_scale;
  j["overlaps"] = rep.overlaps;
  j["min_distance"] = rep.min_distance;
  nlohmann::json ev;
  const auto& events = sim.event_counts();
  for (int k = 1; k < kEventTypes; ++k)
    if (k == int(EventType::Collision) || k == int(EventType::CellCross))
      ev[event_name(EventType(k))] = events[k] - events0[k];
  ev["stale"] = sim.stale_events() - stale0;
  j["events"] = ev;
  j["solver_fallbacks"] = 0;
  j["seed"] = cfg.seed;
  j["equilibrate_time"] = t_eq;
  j["total_cpu_seconds"] = cpu_seconds() - cpu0;
  try {
    log.commit();
    write_file_atomic(dir + "/summary.json", j.dump(2) + "\n");
  } catch (const std::exception& e) {
    throw RunFailure(e.what());
  }
  if (!opt.quiet)
    std::fprintf(stderr, "hardbody: %s: t=%.6g collisions=%llu Z=%.5f +- %.5f overlaps=%llu -> %s\n",
                 cfg.source.c_str(), pressure.measured_time(), (unsigned long long)ncoll, Z.mean,
                 Z.error, (unsigned long long)rep.overlaps, dir.c_str());
  if (rep.overlaps > 0)
    throw RunFailure(fmt::format("{} overlapping pairs in the final state (min gap {:.3g})",
                                 rep.overlaps, rep.min_distance));
}

}  // namespace hb
