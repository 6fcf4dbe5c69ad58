// Lubachevsky–Stillinger growth: dense initial states of hard rigid bodies (docs/growth.md).
//
// All bodies are scaled about their centres by the common factor s(t) = s0 + g (t - t0) while
// the event-driven run goes on; at t_stop (s = s_stop, normally 1: the target shape) the
// growth stops.  The packing fraction is phi(t) = phi_target s(t)^3.
//
//  - Contact prediction: the generic contact-time solver with the scale law
//    (ContactInput::growth; contact/contact_time.hpp derives the growing-shape terms).
//  - Collision rule: scaling about the centre moves the surface point x of a body with
//    centre r at (s'/s) (x - r).  At the contact point x_C with normal n (A into B) the
//    outward normal speed of A's surface is (s'/s) n.(x_C - r_A) and that of B's (outward
//    normal -n) is -(s'/s) n.(x_C - r_B); their sum is
//        grow = (s'/s) n.(r_B - r_A) = (s'/s) n.r_AB  (>= 0 for convex bodies containing their
//    centres), which collision/rigid.hpp's `collide` turns into u'.n = -u.n - 2 grow: the gap
//    opens after the collision at the rate it closed, and the kinetic energy rises by J grow.
//  - Thermostat: `grow_bodies` stops the loop every `rescale_interval` of simulated time,
//    streams every body to that instant, rescales v and w to the translational and rotational
//    temperature kT, and rebuilds the Simulation (a full re-prediction: new velocities).
//
// The pair model is RigidBodies<S> (or RigidMixture) with a growth law (`law`, motion/
// growth_law.hpp). Its predictions cover [now, t_stop] only (contacts after t_stop are reported
// as none): a run that continues past t_stop must re-predict every body at t_stop (grow_bodies
// does: it ends there, and the caller continues with a rigid simulation at the target size).
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "collision/rigid.hpp"
#include "contact/contact_time.hpp"
#include "motion/growth_law.hpp"
#include "geometry/distance.hpp"
#include "neighbors/cell_neighbors.hpp"
#include "observers/overlap.hpp"
#include "system/box.hpp"
#include "system/rigid_bodies.hpp"
#include "setup/rigid_setup.hpp"
#include "system/simulation.hpp"
#include "system/state.hpp"

namespace hb {

// Scale every v and every w so that the translational kinetic energy kt and the rotational one
// kr both become 3 N kT / 2 (a zero one stays zero); returns the kinetic energy removed.
inline double scale_to_temperature(State& s, double kt, double kr, double kT) {
  const double target = 1.5 * double(s.size()) * kT;
  const double ft = kt > 0.0 ? std::sqrt(target / kt) : 1.0;
  const double fr = kr > 0.0 ? std::sqrt(target / kr) : 1.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.v[i] *= ft;
    s.w[i] *= fr;
  }
  return kt + kr - ((kt > 0.0 ? target : 0.0) + (kr > 0.0 ? target : 0.0));
}

// Rescale translational and rotational velocities to the temperature kT (any tops: the
// rotational kinetic energy w.I_lab w / 2 is quadratic in w).
inline void rescale_to_temperature(State& s, const MassProperties& mass, double kT) {
  double kt = 0.0, kr = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    kt += 0.5 * mass.mass * s.v[i].squaredNorm();
    kr += mass.spherical ? 0.5 * s.w[i].squaredNorm() / mass.inv_scalar_inertia
                         : 0.5 * s.w[i].dot(mass.apply_inertia(s.q[i], s.w[i]));
  }
  scale_to_temperature(s, kt, kr, kT);
}

struct GrowthOptions {
  double rate = 0.05;              // ds/dt, s relative to the target size (time unit sqrt(m l^2/kT))
  double phi0 = 0.1;               // packing fraction of the starting lattice (grow_to)
  double kT = 1.0;                 // thermostat temperature
  double rescale_interval = 0.5;   // simulated time between velocity rescalings
};

struct GrowthResult {
  State state;  // synchronized; time stamps reset to 0 (the start of the continuing run)
  Box box;
  double phi = 0.0;         // N v_body / V at the end (the target)
  double time = 0.0;        // simulated time of the growth
  double s0 = 1.0;          // initial scale
  std::uint64_t collisions = 0;
  std::uint64_t rescales = 0;
  double heat_removed = 0.0;  // kinetic energy removed by the thermostat (sum)
  double wall_seconds = 0.0;
  OverlapReport overlaps;   // independent check of the final state (ellipsoids: grow_to)
  SolverStats stats;
};

// The growth loop shared by every pair model with a growth law (`model.law` from s0 at t = 0 to
// 1 at t_stop): runs the event loop with cell lists in stretches of opt.rescale_interval,
// streams every body to the end of each stretch and calls rescale(state) (the thermostat; it
// returns the kinetic energy removed), then continues with a fresh prediction. The state's time
// stamps are taken as the start time 0; the result holds the synchronized state at t_stop, time
// stamps reset to 0 (no overlap check here).
template <class Model, class Rescale>
GrowthResult run_growth(Model model, State st, const Box& box, const GrowthOptions& opt,
                        Rescale rescale) {
  const double s0 = model.law.s0, t_stop = model.law.t_stop;
  if (!(s0 > 0.0 && s0 <= 1.0)) throw std::invalid_argument("grow_bodies: need 0 < s0 <= 1");
  if (!(opt.rate > 0.0) || !std::isfinite(opt.rate))
    throw std::invalid_argument("grow_bodies: the growth rate must be > 0");
  if (!(opt.rescale_interval > 0.0))
    throw std::invalid_argument("grow_bodies: rescale_interval must be > 0");
  const auto t_wall = std::chrono::steady_clock::now();
  GrowthResult res;
  res.box = box;
  res.s0 = s0;
  for (std::size_t i = 0; i < st.size(); ++i) st.t[i] = 0.0;
  rescale(st);
  double t = 0.0;
  while (t < t_stop) {
    const double t_next = std::min(t + opt.rescale_interval, t_stop);
    using Sim = Simulation<Model, CellNeighbors>;
    const double range = model.interaction_range();
    Sim sim(box, std::move(st), std::move(model), CellNeighbors(range), t);
    while (sim.step(t_next).type != EventType::None) {
    }
    sim.synchronize();
    res.collisions += sim.collisions();
    st = sim.state();
    model = sim.model();
    t = t_next;
    res.heat_removed += rescale(st);
    ++res.rescales;
  }
  res.time = t;
  if constexpr (requires { model.stats; }) res.stats = model.stats;
  for (std::size_t i = 0; i < st.size(); ++i) st.t[i] = 0.0;  // time 0 of the continuing run
  res.state = std::move(st);
  res.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t_wall).count();
  return res;
}

// Grow bodies of shape `shape` (given at its target size) from `st` (overlap-free at scale s0,
// positions in `box`) to scale 1 at growth rate opt.rate, rescaling the velocities to opt.kT
// every opt.rescale_interval (run_growth).
template <Shape S>
GrowthResult grow_bodies(const S& shape, const MassProperties& mass, State st, const Box& box,
                         double s0, const GrowthOptions& opt, double eps_d = 1e-5) {
  const double t_stop = (1.0 - s0) / opt.rate;
  RigidBodies<S> model{shape, mass, eps_d};
  model.law = GrowthLaw{s0, opt.rate, 0.0, t_stop};
  GrowthResult res = run_growth(std::move(model), std::move(st), box, opt, [&](State& x) {
    const double k = total_kinetic_energy(x, mass);
    rescale_to_temperature(x, mass, opt.kT);
    return k - total_kinetic_energy(x, mass);
  });
  res.phi = double(res.state.size()) * shape.volume() / box.volume();
  return res;
}

// Dense state of bodies of shape `shape` (at its target size): the lattice start
// `lattice(spec', box)` (rigid_setup.hpp; aligned bodies, Maxwell–Boltzmann velocities and spins
// from spec.seed) at spec' = spec with phi = opt.phi0, shrunk as a whole by
// s0 = (phi0 / spec.phi)^(1/3) so that target-size bodies fill spec.phi of the box, then grown to
// s = 1 (phi = spec.phi).  The final state is checked by `check(state, box)` (the shape's
// independent overlap test, an OverlapReport); an overlap throws std::runtime_error.
template <Shape S, class Lattice, class Check>
GrowthResult grow_lattice(const S& shape, const RigidSystemSpec& spec, const GrowthOptions& opt,
                          Lattice lattice, Check check) {
  if (!(spec.phi > 0.0) || !(opt.phi0 > 0.0) || opt.phi0 > spec.phi)
    throw std::invalid_argument("grow_to: need 0 < phi0 <= phi (target)");
  RigidSystemSpec start = spec;
  start.phi = opt.phi0;
  Box box;
  State st = lattice(start, box);
  const double s0 = std::cbrt(opt.phi0 / spec.phi);
  box.L *= s0;
  for (auto& r : st.r) r *= s0;
  GrowthResult res = grow_bodies(shape, MassProperties::principal(spec.mass, spec.inertia),
                                 std::move(st), box, s0, opt, spec.eps_d);
  res.overlaps = check(res.state, res.box);
  if (res.overlaps.overlaps != 0)
    throw std::runtime_error(fmt::format("grow_to: {} overlapping pairs in the grown state "
                                         "(min gap {:.3e}, seed {})",
                                         res.overlaps.overlaps, res.overlaps.min_distance,
                                         spec.seed));
  return res;
}

// Ellipsoids: grow_lattice from ellipsoid_start, checked with the Perram–Wertheim contact
// function.
inline GrowthResult grow_to(const RigidSystemSpec& spec, const GrowthOptions& opt = {}) {
  const Ellipsoid shape{spec.semi_axes.x(), spec.semi_axes.y(), spec.semi_axes.z()};
  return grow_lattice(shape, spec, opt, ellipsoid_start, [&](const State& s, const Box& b) {
    return ellipsoid_overlaps(s.r, s.q, b, spec.semi_axes);
  });
}

}  // namespace hb
