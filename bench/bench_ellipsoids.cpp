// Whole-simulation benchmark of hard ellipsoids: tau_c (CPU us per collision) with cell lists
// and with oriented-bounding-box neighbour lists, and where the time goes (solver counters).
// Usage: bench_ellipsoids [N] [phi] [X0] [method cells|nnl] [collisions] [warmup] [shell] [eps_d]
// Semi-axes [X0/2, 1/2, 1/2]: b = c = 1/2 (unit minor diameter for prolate bodies) and a = X0 b
// along the symmetry axis (the paper's X0 = a/b). Prints one JSON line.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include "setup/rigid_setup.hpp"

#include "bench_common.hpp"

using namespace hb;

template <class Sim>
int bench(Sim sim, const RigidSystemSpec& spec, double x0, const char* method, double coll,
          double warm, double shell) {
  while (sim.collisions() < warm) sim.step(kInf);
  const SolverStats s0 = sim.model().stats;
  const auto c0 = sim.collisions();
  const auto e0 = sim.event_counts();
  const double t0 = cpu_now();
  while (sim.collisions() - c0 < coll) sim.step(kInf);
  const double dt = cpu_now() - t0;
  const double nc = double(sim.collisions() - c0);
  const SolverStats& s1 = sim.model().stats;
  const double preds = double(s1.predictions - s0.predictions);
  const auto e1 = sim.event_counts();
  std::printf(
      "{\"bench\":\"ellipsoids\",\"N\":%zu,\"phi\":%.3f,\"X0\":%.3f,\"method\":\"%s\",\"shell\":%.3f,"
      "\"eps_d\":%.1e,\"collisions\":%.0f,\"cpu_seconds\":%.3f,\"tau_c_us\":%.2f,"
      "\"collisions_per_second\":%.1f,\"predictions_per_collision\":%.2f,"
      "\"distance_evals_per_prediction\":%.2f,\"distance_nr_iterations_per_eval\":%.2f,"
      "\"neighbour_events_per_collision\":%.3f,\"hits_per_collision\":%.2f,"
      "\"distance_evals_per_hit\":%.2f,\"axis_steps_per_collision\":%.1f,\"fallbacks\":%llu}\n",
      spec.n, spec.phi, x0, method, shell, spec.eps_d, nc, dt, 1e6 * dt / nc, nc / dt, preds / nc,
      double(s1.distance_evals - s0.distance_evals) / std::max(preds, 1.0),
      double(s1.distance_nr_iterations - s0.distance_nr_iterations) /
          std::max(double(s1.distance_evals - s0.distance_evals), 1.0),
      double(e1[2] + e1[3] - e0[2] - e0[3]) / nc, double(s1.hits - s0.hits) / nc,
      double(s1.hit_distance_evals - s0.hit_distance_evals) / std::max(double(s1.hits - s0.hits), 1.0),
      double(s1.axis_steps - s0.axis_steps) / nc,
      (unsigned long long)(s1.fallbacks + s1.distance_fallbacks - s0.fallbacks - s0.distance_fallbacks));
  return 0;
}

int main(int argc, char** argv) {
  RigidSystemSpec spec;
  spec.n = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 256;
  spec.phi = argc > 2 ? std::atof(argv[2]) : 0.5;
  const double x0 = argc > 3 ? std::atof(argv[3]) : 2.0;
  const char* method = argc > 4 ? argv[4] : "nnl";
  const double coll = argc > 5 ? std::atof(argv[5]) : 5000;
  const double warm = argc > 6 ? std::atof(argv[6]) : 2000;
  const double shell = argc > 7 ? std::atof(argv[7]) : 0.15;
  spec.eps_d = argc > 8 ? std::atof(argv[8]) : 1e-5;
  // the paper's convention: b = c = 0.5 (unit minor diameter), a = X0 b
  spec.semi_axes = Vec3(0.5 * x0, 0.5, 0.5);
  spec.inertia = Vec3::Constant(0.4 * spec.mass * std::pow(spec.semi_axes.minCoeff(), 2));
  if (std::strcmp(method, "cells") == 0)
    return bench(make_ellipsoid_cell_simulation(spec), spec, x0, method, coll, warm, shell);
  return bench(make_ellipsoid_list_simulation(spec, shell), spec, x0, method, coll, warm, shell);
}
