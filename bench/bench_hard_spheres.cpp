// Whole-simulation benchmark of hard spheres: collisions per CPU second after equilibration.
// Usage: bench_hard_spheres [N] [phi] [collisions] [equilibration_collisions] [shell] [engine]
//                           [reorder]
// engine = generic (default): the generic event loop, with cell lists (shell = 0) or neighbour
// lists with that shell; engine = fast: the dedicated hard-sphere loop (system/sphere_engine.hpp)
// with cages of diameter shell (0: SphereEngine::default_shell, the fastest at phi 0.45 for the
// size: 0.5 up to N = 160000, 0.6, then 0.65 from N = 640000; see docs/benchmarks), its records
// re-sorted along the curve every `reorder` N events (default 16; 0: never).
// Prints one JSON line per run (machine-readable).
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "setup/sphere_setup.hpp"
#include "system/sphere_engine.hpp"

#include "bench_common.hpp"

using namespace hb;

template <class Sim>
int bench(Sim sim, const SphereSystemSpec& spec, double coll, double equil);
int bench_fast(const SphereSystemSpec& spec, double coll, double equil, double reorder);

int main(int argc, char** argv) {
  SphereSystemSpec spec;
  spec.n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 32000;
  spec.phi = argc > 2 ? std::atof(argv[2]) : 0.45;
  const double coll = argc > 3 ? std::atof(argv[3]) : 1e7;
  const double equil = argc > 4 ? std::atof(argv[4]) : 20.0 * spec.n;
  spec.shell = argc > 5 ? std::atof(argv[5]) : 0.0;
  const std::string engine = argc > 6 ? argv[6] : "generic";
  const double reorder = argc > 7 ? std::atof(argv[7]) : 16.0;
  if (engine == "fast") {
    if (spec.shell == 0.0) spec.shell = SphereEngine::default_shell(spec.n, spec.phi, spec.sigma);
    return bench_fast(spec, coll, equil, reorder);
  }
  if (engine != "generic") {
    std::fprintf(stderr, "engine must be generic or fast\n");
    return 2;
  }
  if (spec.shell > 0.0) return bench(make_hard_sphere_list_simulation(spec), spec, coll, equil);
  return bench(make_hard_sphere_cell_simulation(spec), spec, coll, equil);
}

template <class Sim>
int bench(Sim sim, const SphereSystemSpec& spec, double coll, double equil) {
  double t0 = cpu_now();
  const double tmax = 1e300;
  t0 = cpu_now();
  while (sim.collisions() < equil) sim.step(tmax);
  const double t_eq = cpu_now() - t0;
  const auto c0 = sim.collisions();
  const auto e0 = sim.event_counts();
  const auto s0 = sim.stale_events();
  t0 = cpu_now();
  while (sim.collisions() - c0 < coll) sim.step(tmax);
  const double dt = cpu_now() - t0;
  const double nc = double(sim.collisions() - c0);
  const auto e1 = sim.event_counts();
  std::printf(
      "{\"bench\":\"hard_spheres\",\"N\":%zu,\"phi\":%.4f,\"collisions\":%.0f,\"cpu_seconds\":%.3f,"
      "\"collisions_per_second\":%.4g,\"ns_per_collision\":%.1f,\"cell_crossings_per_collision\":%.3f,"
      "\"stale_per_collision\":%.3f,\"rebuilds_per_collision\":%.3f,\"shell\":%.3f,\"equil_s\":%.2f,"
      "\"engine\":\"generic\"}\n",
      spec.n, spec.phi, nc, dt, nc / dt, 1e9 * dt / nc,
      double(e1[2] - e0[2]) / nc, double(sim.stale_events() - s0) / nc,
      double(e1[3] - e0[3]) / nc, spec.shell, t_eq);
  return 0;
}

int bench_fast(const SphereSystemSpec& spec, double coll, double equil, double reorder) {
  Box box;
  // the start is dropped once the engine holds it (the process's memory is then the engine's)
  SphereEngine sim = [&] {
    const State start = hard_sphere_start(spec, box);
    return SphereEngine(box, start, spec.sigma, spec.shell);
  }();
  sim.set_reorder_interval(static_cast<std::uint64_t>(reorder * double(spec.n)));
  double t0 = cpu_now();
  while (double(sim.collisions()) < equil) sim.step();
  const double t_eq = cpu_now() - t0;
  const auto c0 = sim.collisions(), g0 = sim.cage_exits(), s0 = sim.stale_events();
  t0 = cpu_now();
  while (double(sim.collisions() - c0) < coll) sim.step();
  const double dt = cpu_now() - t0;
  const double nc = double(sim.collisions() - c0);
  std::printf(
      "{\"bench\":\"hard_spheres\",\"N\":%zu,\"phi\":%.4f,\"collisions\":%.0f,\"cpu_seconds\":%.3f,"
      "\"collisions_per_second\":%.4g,\"ns_per_collision\":%.1f,\"cell_crossings_per_collision\":0,"
      "\"stale_per_collision\":%.3f,\"rebuilds_per_collision\":%.3f,\"shell\":%.3f,\"equil_s\":%.2f,"
      "\"engine\":\"fast\",\"bytes_per_body\":%zu,\"reorder_every_N\":%g}\n",
      spec.n, spec.phi, nc, dt, nc / dt, 1e9 * dt / nc, double(sim.stale_events() - s0) / nc,
      double(sim.cage_exits() - g0) / nc, spec.shell, t_eq, sim.bytes_per_sphere(), reorder);
  return 0;
}
