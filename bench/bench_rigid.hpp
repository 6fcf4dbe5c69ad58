// Shared pieces of the rigid-body performance benchmarks (bench_rigid, bench_ratio): key=value
// arguments, building ellipsoid / superquadric / hard-sphere simulations from one description,
// and timing a stretch of collisions with the solver counters it took.
#pragma once
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "math/morton.hpp"
#include "setup/builder.hpp"
#include "shapes/inertia.hpp"

#include "bench_common.hpp"

namespace hbbench {

using hb::Vec3;
using Json = nlohmann::ordered_json;

// Arguments `key=value`; every key must be known (a typo must not silently fall back to a default).
class Args {
 public:
  Args(int argc, char** argv) {
    for (int k = 1; k < argc; ++k) {
      const std::string a = argv[k];
      const auto eq = a.find('=');
      if (eq == std::string::npos || eq == 0) throw std::invalid_argument("expected key=value, got '" + a + "'");
      kv_[a.substr(0, eq)] = a.substr(eq + 1);
    }
  }
  double num(const std::string& key, double def) {
    used_[key] = true;
    const auto it = kv_.find(key);
    if (it == kv_.end()) return def;
    char* end = nullptr;
    const double v = std::strtod(it->second.c_str(), &end);
    if (end == it->second.c_str() || *end != '\0') throw std::invalid_argument("bad number for " + key);
    return v;
  }
  std::string str(const std::string& key, const std::string& def) {
    used_[key] = true;
    const auto it = kv_.find(key);
    return it == kv_.end() ? def : it->second;
  }
  // Call after reading every key.
  void check_all_used() const {
    for (const auto& [k, v] : kv_)
      if (!used_.count(k)) throw std::invalid_argument("unknown argument '" + k + "'");
  }

 private:
  std::map<std::string, std::string> kv_;
  std::map<std::string, bool> used_;
};

// One rigid-body state point.  Bodies of revolution about body x: semi-axes (X0 b, b, b); the
// superquadric exponents are (2, 2, p) (the paper's section 5: n = m = 2, p varied).
struct RigidPoint {
  std::string shape = "ellipsoid";  // "ellipsoid" | "superquadric"
  std::string method = "nnl";       // "nnl" | "cells"
  hb::RigidSystemSpec spec;
  double x0 = 2.0;
  double p = 2.0;
  double shell = 0.15;
  bool revolution = true;  // the spheroids' spin-across bounds (false: the slow twin's |w|)
  bool box_test = true;    // the NNL's axis-aligned box test where it is on (false: off, the twin)
  bool short_windows = true;  // the NNL's short escape windows (false: long ones, the twin)
  double mean_free_cap = 2.0;  // short windows cut at c mean free times (0: off, the twin)
  bool memo = true;        // each pair's last separating axis kept (false: every search cold)
  bool shuffle = false;    // bodies numbered at random, not along the lattice's Morton curve
  bool resort = false;     // a state carried over between simulations renumbered along a curve
};

// Reads shape, N, phi, X0, b, p, inertia, revolution, box_test, short_windows, mean_free_cap,
// memo, shuffle, resort, eps_d, seed, method, shell.
// Defaults: the ellipsoids of bench_ellipsoids (b = 1/2, I = 2/5 m (smallest semi-axis)^2).
inline RigidPoint read_point(Args& a) {
  RigidPoint pt;
  pt.shape = a.str("shape", "ellipsoid");
  if (pt.shape != "ellipsoid" && pt.shape != "superquadric")
    throw std::invalid_argument("shape must be ellipsoid or superquadric");
  pt.method = a.str("method", "nnl");
  if (pt.method != "nnl" && pt.method != "cells") throw std::invalid_argument("method must be nnl or cells");
  pt.spec.n = static_cast<std::size_t>(a.num("N", 256));
  pt.spec.phi = a.num("phi", 0.5);
  pt.x0 = a.num("X0", 2.0);
  const double b = a.num("b", 0.5);
  pt.p = a.num("p", 2.0);
  pt.spec.semi_axes = Vec3(pt.x0 * b, b, b);
  pt.spec.exponents = Vec3(2.0, 2.0, pt.p);
  // inertia: a number (a spherical top) or "solid" (the uniform solid's principal moments)
  if (a.str("inertia", "") == "solid") {
    pt.spec.inertia = pt.shape == "ellipsoid"
                          ? hb::uniform_inertia(hb::Ellipsoid{pt.spec.semi_axes.x(), pt.spec.semi_axes.y(),
                                                              pt.spec.semi_axes.z()},
                                                pt.spec.mass)
                          : hb::uniform_inertia(hb::superquadric_shape(pt.spec), pt.spec.mass);
  } else {
    pt.spec.inertia = Vec3::Constant(a.num("inertia", 0.4 * pt.spec.mass * hb::sqr(pt.spec.semi_axes.minCoeff())));
  }
  pt.revolution = a.num("revolution", 1) != 0;
  pt.box_test = a.num("box_test", 1) != 0;
  pt.short_windows = a.num("short_windows", 1) != 0;
  pt.mean_free_cap = a.num("mean_free_cap", 2.0);
  pt.memo = a.num("memo", 1) != 0;
  pt.shuffle = a.num("shuffle", 0) != 0;
  pt.resort = a.num("resort", 0) != 0;
  pt.spec.eps_d = a.num("eps_d", 1e-5);
  pt.spec.seed = static_cast<std::uint64_t>(a.num("seed", 1));
  pt.shell = a.num("shell", 0.15);
  if (pt.shape == "ellipsoid" && pt.p != 2.0) throw std::invalid_argument("p is for superquadrics");
  return pt;
}

inline hb::UnitBody unit_body_of(const RigidPoint& pt) {
  return pt.shape == "ellipsoid" ? hb::UnitBody{} : hb::superquadric_unit_body(pt.spec);
}
inline double bounding_radius_of(const RigidPoint& pt) {
  return pt.shape == "ellipsoid" ? pt.spec.semi_axes.maxCoeff()
                                 : hb::superquadric_shape(pt.spec).bounding_radius();
}

// The lattice start's box for this point, or a reason why it has none.
struct LatticeCheck {
  bool ok = false;
  Vec3 L = Vec3::Zero();
  double phi_max = 0.0;
  std::string reason;
};
inline LatticeCheck check_lattice(const RigidPoint& pt) {
  LatticeCheck c;
  const hb::UnitBody unit = unit_body_of(pt);
  const hb::StretchedLattice lat = hb::stretched_lattice(pt.spec.n, pt.spec.semi_axes, unit);
  c.phi_max = lat.phi_max;
  if (pt.spec.phi > lat.phi_max * (1.0 - 1e-12)) {
    c.reason = "packing fraction above the lattice start's limit " + std::to_string(lat.phi_max);
    return c;
  }
  const double a0 = hb::lattice_constant(pt.spec.n, pt.spec.phi, lat.m, unit);
  for (int k = 0; k < 3; ++k) c.L[k] = pt.spec.semi_axes[k] * a0 * lat.m[k];
  // Both neighbour methods need every box side above two interaction ranges (cells) and four
  // circumradii of the neighbour-list box (minimum-image SAT, neighbors/obb_neighbors.hpp).
  const double need = std::max(4.0 * bounding_radius_of(pt),
                               4.0 * (pt.spec.semi_axes + Vec3::Constant(pt.shell)).norm());
  if (c.L.minCoeff() < need) {
    c.reason = "box side " + std::to_string(c.L.minCoeff()) + " below " + std::to_string(need);
    return c;
  }
  c.ok = true;
  return c;
}

// The smallest N >= the requested one (up to 16x) whose lattice start reaches phi in a box large
// enough for both neighbour methods; spec.n is set to it.  Returns the check of the last N tried.
inline LatticeCheck fit_particle_number(RigidPoint& pt) {
  const std::size_t n0 = pt.spec.n;
  LatticeCheck c;
  for (std::size_t n = n0; n <= 16 * n0; n = std::max(n + 4, static_cast<std::size_t>(n * 1.08))) {
    pt.spec.n = n;
    c = check_lattice(pt);
    if (c.ok) return c;
  }
  pt.spec.n = n0;
  return c;
}

// Counters of a simulation at one moment; differences give the cost of a stretch of events.
struct Tally {
  double cpu = 0, wall = 0, collisions = 0, neighbour_events = 0, stale = 0;
  double predictions = 0, distance_evals = 0, distance_nr = 0, contact_nr = 0, axis_steps = 0, axis_bounds = 0, hits = 0,
         hit_distance_evals = 0, grazing = 0, contact_fallbacks = 0, distance_fallbacks = 0,
         collision_distance_fallbacks = 0, prefiltered = 0, centre_line_clears = 0, collision_touches = 0,
         ordered_skips = 0;
  Tally operator-(const Tally& o) const {
    Tally d;
    d.cpu = cpu - o.cpu, d.wall = wall - o.wall, d.collisions = collisions - o.collisions;
    d.neighbour_events = neighbour_events - o.neighbour_events, d.stale = stale - o.stale;
    d.predictions = predictions - o.predictions, d.distance_evals = distance_evals - o.distance_evals;
    d.distance_nr = distance_nr - o.distance_nr, d.contact_nr = contact_nr - o.contact_nr;
    d.axis_steps = axis_steps - o.axis_steps;
    d.axis_bounds = axis_bounds - o.axis_bounds;
    d.hits = hits - o.hits, d.hit_distance_evals = hit_distance_evals - o.hit_distance_evals;
    d.grazing = grazing - o.grazing, d.contact_fallbacks = contact_fallbacks - o.contact_fallbacks;
    d.distance_fallbacks = distance_fallbacks - o.distance_fallbacks;
    d.collision_distance_fallbacks = collision_distance_fallbacks - o.collision_distance_fallbacks;
    d.prefiltered = prefiltered - o.prefiltered;
    d.centre_line_clears = centre_line_clears - o.centre_line_clears;
    d.collision_touches = collision_touches - o.collision_touches;
    d.ordered_skips = ordered_skips - o.ordered_skips;
    return d;
  }
  Tally& operator+=(const Tally& o) {
    cpu += o.cpu, wall += o.wall, collisions += o.collisions, neighbour_events += o.neighbour_events;
    stale += o.stale, predictions += o.predictions, distance_evals += o.distance_evals;
    distance_nr += o.distance_nr, contact_nr += o.contact_nr, axis_steps += o.axis_steps, axis_bounds += o.axis_bounds, hits += o.hits;
    hit_distance_evals += o.hit_distance_evals, grazing += o.grazing;
    contact_fallbacks += o.contact_fallbacks, distance_fallbacks += o.distance_fallbacks;
    collision_distance_fallbacks += o.collision_distance_fallbacks;
    prefiltered += o.prefiltered, centre_line_clears += o.centre_line_clears;
    collision_touches += o.collision_touches, ordered_skips += o.ordered_skips;
    return *this;
  }
  double fallbacks() const { return contact_fallbacks + distance_fallbacks + collision_distance_fallbacks; }
};

inline double wall_now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

template <class Sim>
Tally tally(const Sim& sim) {
  Tally t;
  t.cpu = cpu_now();
  t.wall = wall_now();
  const auto& e = sim.event_counts();
  t.collisions = double(sim.collisions());
  t.neighbour_events = double(e[int(hb::EventType::CellCross)] + e[int(hb::EventType::Rebuild)]);
  t.stale = double(sim.stale_events());
  if constexpr (requires { sim.model().stats; }) {
    const hb::SolverStats& s = sim.model().stats;
    t.predictions = double(s.predictions), t.distance_evals = double(s.distance_evals);
    t.distance_nr = double(s.distance_nr_iterations), t.contact_nr = double(s.contact_nr_iterations);
    t.axis_steps = double(s.axis_steps);
    t.axis_bounds = double(s.axis_bounds);
    t.hits = double(s.hits), t.hit_distance_evals = double(s.hit_distance_evals);
    t.grazing = double(s.grazing_searches), t.contact_fallbacks = double(s.fallbacks);
    t.distance_fallbacks = double(s.distance_fallbacks);
    t.collision_distance_fallbacks = double(s.collision_distance_fallbacks);
    t.prefiltered = double(s.prefiltered), t.centre_line_clears = double(s.centre_line_clears);
    t.collision_touches = double(s.collision_touches), t.ordered_skips = double(s.ordered_skips);
  }
  return t;
}

// Wall-clock share of each kind of event (collisions with their two re-predictions, neighbour
// events: cell crossings or list rebuilds with their re-prediction, stale collisions).
struct Split {
  double collision = 0, neighbour = 0, stale = 0;
};

// Runs `count` collisions (stops early once `budget` CPU seconds are spent and at least
// `min_count` collisions are done).  With `split`, each event is timed by its kind.
template <class Sim>
Tally run_collisions(Sim& sim, double count, double budget = hb::kInf, double min_count = 0,
                     Split* split = nullptr) {
  const Tally t0 = tally(sim);
  const double c0 = double(sim.collisions());
  for (std::uint64_t k = 0; double(sim.collisions()) - c0 < count; ++k) {
    if (split) {
      const double w0 = wall_now();
      const hb::StepInfo info = sim.step(hb::kInf);
      const double dw = wall_now() - w0;
      (info.stale ? split->stale : info.type == hb::EventType::Collision ? split->collision : split->neighbour) += dw;
    } else {
      sim.step(hb::kInf);
    }
    if ((k & 127) == 0 && cpu_now() - t0.cpu > budget && double(sim.collisions()) - c0 >= min_count) break;
  }
  return tally(sim) - t0;
}

// Per-collision figures of a stretch (the keys of bench_ellipsoids, plus a few).
inline void put_costs(Json& j, const Tally& d) {
  const double nc = std::max(d.collisions, 1.0), np = std::max(d.predictions, 1.0);
  j["collisions"] = d.collisions;
  j["cpu_seconds"] = d.cpu;
  j["tau_c_us"] = 1e6 * d.cpu / nc;
  j["collisions_per_second"] = d.collisions / std::max(d.cpu, 1e-12);
  j["predictions_per_collision"] = d.predictions / nc;
  // of those, answered without a solver: by the bounding spheres, the gap along one axis or the
  // ordered loop (system/rigid_bodies.hpp predict_contacts), by the gap along one axis alone,
  // and by the ordered loop alone
  j["prefiltered_per_collision"] = d.prefiltered / nc;
  j["centre_line_clears_per_collision"] = d.centre_line_clears / nc;
  j["ordered_skips_per_collision"] = d.ordered_skips / nc;
  j["collision_touches_per_collision"] = d.collision_touches / nc;
  j["distance_evals_per_prediction"] = d.distance_evals / np;
  j["distance_evals_per_collision"] = d.distance_evals / nc;
  j["distance_nr_iterations_per_eval"] = d.distance_nr / std::max(d.distance_evals, 1.0);
  j["axis_steps_per_collision"] = d.axis_steps / nc;
  j["axis_steps_per_prediction"] = d.axis_steps / np;
  j["axis_bounds_per_collision"] = d.axis_bounds / nc;
  j["neighbour_events_per_collision"] = d.neighbour_events / nc;
  j["stale_per_collision"] = d.stale / nc;
  j["hits_per_collision"] = d.hits / nc;
  j["distance_evals_per_hit"] = d.hit_distance_evals / std::max(d.hits, 1.0);
  // every contact-system Newton iteration (those of solves that find no contact too), per hit
  j["contact_nr_iterations_per_hit"] = d.contact_nr / std::max(d.hits, 1.0);
  j["grazing_searches_per_collision"] = d.grazing / nc;
  j["fallbacks"] = d.fallbacks();
}

// A configuration to start a simulation from: the lattice start of a point, or the synchronized
// state of an earlier simulation (every body at time `now`).
struct Start {
  hb::Box box;
  hb::State state;
  double now = 0.0;
};
// The point as a run configuration: benchmarks assemble their systems with the same builder as
// `hardbody run` and the Python module (setup/builder.hpp).
inline hb::Config config_of(const RigidPoint& pt) {
  hb::Config c;
  c.source = "benchmark point";
  c.particles = pt.spec.n;
  c.packing_fraction = pt.spec.phi;
  c.seed = pt.spec.seed;
  c.temperature = pt.spec.kT;
  hb::Species& sp = c.species.at(0);
  sp.count = pt.spec.n;
  sp.mass = pt.spec.mass;
  const Vec3 a = pt.spec.semi_axes, e = pt.spec.exponents;
  if (pt.shape == "ellipsoid") sp.shape = hb::Ellipsoid{a.x(), a.y(), a.z()};
  else sp.shape = hb::Superquadric{a.x(), a.y(), a.z(), e.x(), e.y(), e.z()};
  sp.name = std::string(hb::shape_name(sp.shape));
  sp.inertia = pt.spec.inertia;
  c.eps_d = pt.spec.eps_d;
  c.neighbors_method = pt.method;
  c.shell = pt.shell;
  c.init_method = "lattice";
  return c;
}
// Hard spheres of diameter 1 (shell 0: cell lists, else shell neighbour lists).
inline hb::Config sphere_config(std::size_t n, double phi, double shell, std::uint64_t seed) {
  hb::Config c;
  c.source = "benchmark point";
  c.particles = n;
  c.packing_fraction = phi;
  c.seed = seed;
  c.species.at(0) = hb::Species{"sphere", n, hb::Sphere{0.5}, 1.0, Vec3::Constant(0.1), {}};
  c.neighbors_method = shell > 0.0 ? "nnl" : "cells";
  c.shell = shell;
  return c;
}

// Calls f(assembly) for a rigid-body configuration (the builder also knows spheres: not here).
template <class F>
void with_rigid_assembly(const hb::Config& c, F&& f) {
  hb::assemble(c, [&](const auto& as) {
    if constexpr (requires { as.model().shape.bounding_radius(); }) f(as);  // one species
    else throw std::invalid_argument("not a rigid-body point");
  });
}

// The same bodies in a new numbering: body k of the result is body perm[k] of a.
inline hb::State renumbered(const hb::State& a, const std::vector<std::uint32_t>& perm) {
  hb::State b = a;
  for (std::size_t k = 0; k < perm.size(); ++k) {
    const std::size_t m = perm[k];
    b.r[k] = a.r[m], b.v[k] = a.v[m], b.q[k] = a.q[m], b.w[k] = a.w[m], b.t[k] = a.t[m];
    b.count[k] = a.count[m], b.image[k] = a.image[m], b.species[k] = a.species[m];
    b.scale[k] = a.scale[m];
  }
  return b;
}
// The bodies of a synchronized state numbered along the Morton curve of a grid of about one
// cell per body (what the lattice start does at its start, and the hard-sphere loop does every
// few N events): `resort=1` applies it where a simulation is rebuilt from a carried-over state,
// to measure what the order lost over the run before costs.
inline hb::State morton_sorted(const hb::State& s, const hb::Box& box) {
  const std::size_t n = s.size();
  const auto m = static_cast<std::uint32_t>(std::clamp(std::cbrt(double(n)), 1.0, double(1u << 20)));
  std::vector<std::uint64_t> key(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t c[3];
    for (int d = 0; d < 3; ++d) {
      const double u = std::floor(s.r[i][d] / box.L[d] * m);
      c[d] = static_cast<std::uint32_t>(std::clamp(u, 0.0, double(m - 1)));
    }
    key[i] = hb::morton_code(c[0], c[1], c[2]);
  }
  return renumbered(s, hb::sorting_permutation(key));
}

inline Start lattice_start_of(const RigidPoint& pt) {
  Start st;
  with_rigid_assembly(config_of(pt), [&](const auto& as) {
    hb::Start s = as.start();
    st.box = s.box;
    st.state = std::move(s.state);
  });
  if (pt.shuffle) {  // the same bodies, numbered in a random order (fixed seed)
    std::vector<std::uint32_t> perm(st.state.size());
    std::iota(perm.begin(), perm.end(), std::uint32_t(0));
    std::mt19937_64 g(pt.spec.seed);
    std::shuffle(perm.begin(), perm.end(), g);
    st.state = renumbered(st.state, perm);
  }
  return st;
}

// Builds the simulation of a rigid point from `st` and hands it to f (a generic lambda).
template <class F>
void with_rigid_simulation(const RigidPoint& pt, Start st, F&& f) {
  with_rigid_assembly(config_of(pt), [&](const auto& as) {
    auto sim = as.simulate(st.box, std::move(st.state), st.now);
    if constexpr (requires { sim.model().options.revolution_bounds; })
      sim.model().options.revolution_bounds = pt.revolution;
    if constexpr (requires { sim.neighbors().set_revolution_bounds(true); })
      sim.neighbors().set_revolution_bounds(pt.revolution);
    if constexpr (requires { sim.neighbors().set_box_test(false); })
      if (!pt.box_test) sim.neighbors().set_box_test(false);  // off after init: nothing stale
    if constexpr (requires { sim.neighbors().set_short_windows(false); })
      sim.neighbors().set_short_windows(pt.short_windows);  // from the next escape search on
    if constexpr (requires { sim.neighbors().set_mean_free_cap(0.0); })
      sim.neighbors().set_mean_free_cap(pt.mean_free_cap);
    if constexpr (requires { sim.model().memo.on; }) sim.model().memo.on = pt.memo;
    f(std::move(sim));
  });
}

// main() of a benchmark: bad arguments and unexpected errors exit with status 2 and one message.
inline int guarded_main(const char* name, int (*run)(int, char**), int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return 2;
  }
}

inline Json describe(const RigidPoint& pt) {
  Json j;
  j["shape"] = pt.shape;
  j["N"] = pt.spec.n;
  j["phi"] = pt.spec.phi;
  j["X0"] = pt.x0;
  j["p"] = pt.p;
  j["semi_axes"] = {pt.spec.semi_axes.x(), pt.spec.semi_axes.y(), pt.spec.semi_axes.z()};
  j["exponents"] = {pt.spec.exponents.x(), pt.spec.exponents.y(), pt.spec.exponents.z()};
  if (hb::spherical_top(pt.spec.inertia)) j["inertia"] = pt.spec.inertia.x();
  else j["inertia"] = {pt.spec.inertia.x(), pt.spec.inertia.y(), pt.spec.inertia.z()};
  j["revolution"] = pt.revolution;
  j["box_test"] = pt.box_test;
  j["short_windows"] = pt.short_windows;
  j["mean_free_cap"] = pt.mean_free_cap;
  j["memo"] = pt.memo;
  j["shuffle"] = pt.shuffle;
  j["resort"] = pt.resort;
  j["method"] = pt.method;
  j["shell"] = pt.shell;
  j["eps_d"] = pt.spec.eps_d;
  j["seed"] = pt.spec.seed;
  return j;
}

}  // namespace hbbench
