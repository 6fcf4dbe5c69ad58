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
#include <optional>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>
#include <stdexcept>

#include "collision/rigid.hpp"
#include "core/fault_injection.hpp"
#include "core/interrupt.hpp"
#include "contact/contact_time.hpp"
#include "motion/growth_law.hpp"
#include "geometry/distance.hpp"
#include "neighbors/cell_neighbors.hpp"
#include "observers/overlap.hpp"
#include "core/box.hpp"
#include "system/rigid_bodies.hpp"
#include "setup/rigid_setup.hpp"
#include "system/simulation.hpp"
#include "core/state.hpp"

namespace hb {

// The growth thermostat, per degree of freedom. Each species' translational kinetic energy is
// scaled to 3 N_a kT / 2 by one factor on its velocities, and for each species and each principal
// body axis k the spin components W_k (body frame) by one factor so that sum_i I_ik W_ik^2 / 2 =
// N_a kT / 2. A single factor on all of w is not enough: for a smooth body of revolution with a
// spherical-top inertia no collision exerts a torque about the symmetry axis, so that spin is
// conserved; the heat of the growth goes into the five other degrees of freedom, a common
// rescaling drains the decoupled one (~0.5 kT at phi = 0.4) and leaves the others hot (T_trans
// 1.02-1.10 after the growth). Smooth spheres in a mixture likewise keep their spin: their three
// axes are rescaled on their own. A degree of freedom with no energy (zero, or below 1e-20 of its
// species' kinetic energy: the rounding left by rotating a zero body-frame component to the lab
// frame and back) is left alone, not blown up to kT. Different factors per species would give the
// system a net momentum, so each species of two or more bodies first has its own centre-of-mass
// velocity removed (a lone body of a species keeps its velocity; the total momentum is then
// removed from all at the end). mass(i) and moments(i) (body-frame principal moments) are the
// body's at its current scale. Returns the kinetic energy removed.
template <class Mass, class Moments>
double thermalize_per_dof(State& s, double kT, Mass&& mass, Moments&& moments) {
  std::size_t groups = 1;
  for (std::size_t i = 0; i < s.size(); ++i) groups = std::max<std::size_t>(groups, s.species[i] + 1);
  // per group: translational energy, rotational energy per axis, body count
  std::vector<double> kt(groups, 0.0), n(groups, 0.0), m(groups, 0.0);
  std::vector<Vec3> kr(groups, Vec3::Zero()), p(groups, Vec3::Zero());
  double before = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::size_t g = s.species[i];
    const Vec3 W = s.q[i].conjugate() * s.w[i];  // body frame
    const double mi = mass(i);
    before += 0.5 * mi * s.v[i].squaredNorm() + 0.5 * W.dot(moments(i).cwiseProduct(W));
    kr[g] += 0.5 * moments(i).cwiseProduct(W.cwiseProduct(W));
    p[g] += mi * s.v[i];
    m[g] += mi;
    n[g] += 1.0;
  }
  bool lone = false;  // a species of one body keeps its momentum
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::size_t g = s.species[i];
    if (n[g] >= 2.0) s.v[i] -= p[g] / m[g];
    else lone = lone || n[g] == 1.0;
    kt[g] += 0.5 * mass(i) * s.v[i].squaredNorm();
  }
  std::vector<double> ft(groups, 1.0);
  std::vector<Vec3> fr(groups, Vec3::Ones());
  for (std::size_t g = 0; g < groups; ++g) {
    const double t3 = 1.5 * n[g] * kT, t1 = 0.5 * n[g] * kT;
    const double floor = 1e-20 * (kt[g] + kr[g].sum());
    if (kt[g] > floor) ft[g] = std::sqrt(t3 / kt[g]);
    for (int k = 0; k < 3; ++k)
      if (kr[g][k] > floor) fr[g][k] = std::sqrt(t1 / kr[g][k]);
  }
  Vec3 ptot = Vec3::Zero();
  double mtot = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const std::size_t g = s.species[i];
    s.v[i] *= ft[g];
    const Vec3 W = s.q[i].conjugate() * s.w[i];
    s.w[i] = s.q[i] * Vec3(W.cwiseProduct(fr[g]));
    ptot += mass(i) * s.v[i];
    mtot += mass(i);
  }
  if (lone && mtot > 0.0)
    for (auto& v : s.v) v -= ptot / mtot;
  double after = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3 W = s.q[i].conjugate() * s.w[i];
    after += 0.5 * mass(i) * s.v[i].squaredNorm() + 0.5 * W.dot(moments(i).cwiseProduct(W));
  }
  return before - after;
}

// One species of rigid bodies (mass properties `mass`, body-frame inertia diagonal).
inline double rescale_to_temperature(State& s, const MassProperties& mass, double kT) {
  const Vec3 I = mass.inertia_body.diagonal();
  return thermalize_per_dof(s, kT, [&](std::size_t) { return mass.mass; }, [&](std::size_t) { return I; });
}

struct GrowthStatus {
  double scale = 1.0;       // s(t)
  double phi = 0.0;         // packing fraction reached: phi_target s^3
  double time = 0.0;        // simulated time
  std::uint64_t collisions = 0;
  double fraction = 0.0;    // of the growth time done
  double free_path = 0.0;   // mean free path of the last window (jam test), 0 until measured
};

struct GrowthOptions {
  double rate = 0.05;              // ds/dt, s relative to the target size (time unit sqrt(m l^2/kT))
  double phi0 = 0.1;               // packing fraction of the starting lattice (grow_to)
  double kT = 1.0;                 // thermostat temperature
  double rescale_interval = 0.5;   // simulated time between velocity rescalings
  double phi_target = 0.0;         // packing fraction at s = 1 (set by the grow_* functions)
  // Jam test: the growth stops (GrowthJammed) when the mean free path of the bodies, measured over
  // windows of kJamWindow N pair collisions (a wall bounce counts as half of one: it ends one
  // free flight), falls below jam_free_path x the interaction range
  // (the largest body diameter). For hard spheres beta P / rho ~ 0.3 sigma / (mean free path), so
  // the default 1e-4 is a reduced pressure ~ 3e3: far beyond any equilibrium state the growth
  // could be asked for (Z < 100 up to close packing of the crystal), and reached only when the
  // bodies are jammed: phi then rises by less than ~1e-3 before the gaps close (ellipsoids X0 = 2
  // grown at rate 0.05 towards 0.75: the test fires at phi = 0.6928; a tenfold smaller threshold
  // reaches 0.6999 at 4x the cost).
  double jam_free_path = 1e-4;
  // The box of the growth when it is not the cubic one the grow_* functions make from phi (an
  // aspect ratio, walls): its sides define phi, and on its axes that are not periodic the bodies
  // meet hard walls (locals/planar_walls.hpp, grazing step wall_eps) from the placement on.
  std::optional<Box> box;
  double wall_eps = 1e-5;
  // > 0: a hard spherical container of this radius about the box centre instead of walls on the
  // box faces (locals/spherical_container.hpp); its volume then defines phi.
  double container = 0.0;
  // Called every 1024 events (not thread-safe; may be empty). Signals are polled at the same
  // points (core/interrupt.hpp): an interrupted growth throws hb::Interrupted.
  std::function<void(const GrowthStatus&)> report;
};

// A growth that cannot reach its target: the bodies jammed at packing fraction `phi`.
class GrowthJammed : public std::runtime_error {
 public:
  GrowthJammed(const std::string& what, double phi) : std::runtime_error(what), phi(phi) {}
  double phi;
};

// A growth stopped by a run-time failure (a solver failure: its message carries the reproducer):
// the bodies at that moment (each at its own time stamp `state.t`), for inspection.
class GrowthFailed : public std::runtime_error {
 public:
  GrowthFailed(const std::string& what, State state, Box box, double time)
      : std::runtime_error(what), state(std::move(state)), box(box), time(time) {}
  State state;
  Box box;
  double time;
};

inline constexpr double kJamWindow = 25.0;  // a jam-test window: kJamWindow N pair collisions

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
// stamps and event counts reset to 0 (no overlap check here).
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
  const double range = model.interaction_range();
  const double n = double(st.size());
  auto status = [&](double t, std::uint64_t coll) {
    GrowthStatus g;
    g.scale = s0 + opt.rate * t;
    g.phi = opt.phi_target * g.scale * g.scale * g.scale;
    g.time = t;
    g.collisions = coll;
    g.fraction = t_stop > 0.0 ? t / t_stop : 1.0;
    return g;
  };
  // jam test window: start time, pair collisions and wall bounces at its start; `bounces` counts
  // the wall bounces of the finished rescale intervals (a bounce ends one body's free flight, a
  // pair collision two)
  double win_t = 0.0, free_path = 0.0;
  std::uint64_t win_c = 0, win_w = 0, bounces = 0;
  double t = 0.0;
  std::uint64_t steps = 0;  // events of the whole growth (signals and reports every 1024)
  while (t < t_stop) {
    const double t_next = std::min(t + opt.rescale_interval, t_stop);
    using Sim = Simulation<Model, CellNeighbors>;
    double v2 = 0.0;  // mean squared speed after the rescale (for the free path)
    for (const Vec3& v : st.v) v2 += v.squaredNorm();
    const double v_rms = std::sqrt(v2 / std::max(n, 1.0));
    Sim sim(box, std::move(st), std::move(model), CellNeighbors(range), t,
            opt.container > 0.0
                ? BodyEvents(PlanarWalls(), {}, SphericalContainer(opt.container, opt.wall_eps))
                : BodyEvents(PlanarWalls({!box.periodic[0], !box.periodic[1], !box.periodic[2]}, opt.wall_eps)));
    try {
    while (sim.step(t_next).type != EventType::None) {
      if ((++steps & 1023) != 0) continue;
      fault_point("growth");
      poll_interrupt("growth");
      const std::uint64_t c = res.collisions + sim.collisions();
      const std::uint64_t w = bounces + sim.event_counts()[static_cast<int>(EventType::Wall)];
      const double flights = 2.0 * double(c - win_c) + double(w - win_w);  // free flights ended
      if (flights >= 2.0 * kJamWindow * n) {
        // mean free time: window time over free flights ended per body
        const double tau = (sim.now() - win_t) * n / flights;
        free_path = tau * v_rms;
        win_t = sim.now(), win_c = c, win_w = w;
        if (free_path < opt.jam_free_path * range) {
          const GrowthStatus g = status(sim.now(), c);
          throw GrowthJammed(fmt::format(
              "the growth jammed at packing fraction {:.6f} (target {:.6g}): after {} collisions "
              "the mean free path is {:.3g} body lengths and phi no longer rises", g.phi,
              opt.phi_target, c, free_path / range), g.phi);
        }
      }
      if (opt.report) {
        GrowthStatus g = status(sim.now(), res.collisions + sim.collisions());
        g.free_path = free_path;
        opt.report(g);
      }
    }
    } catch (const Interrupted&) {
      throw;
    } catch (const GrowthJammed&) {
      throw;
    } catch (const std::runtime_error& e) {
      throw GrowthFailed(fmt::format("during the growth at t = {:.17g}: {}", sim.now(), e.what()),
                         sim.state(), box, sim.now());
    }
    sim.synchronize();
    res.collisions += sim.collisions();
    bounces += sim.event_counts()[static_cast<int>(EventType::Wall)];
    st = sim.state();
    model = sim.model();
    t = t_next;
    res.heat_removed += rescale(st);
    ++res.rescales;
  }
  res.time = t;
  if constexpr (requires { model.stats; }) res.stats = model.stats;
  // time 0 of the continuing run, and no velocity change yet (State::count: the counts of a
  // run count from its time 0; the neighbour lists' windows read them, neighbors/obb_neighbors.hpp)
  for (std::size_t i = 0; i < st.size(); ++i) st.t[i] = 0.0, st.count[i] = 0;
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
  GrowthOptions o = opt;
  o.phi_target = double(st.size()) * shape.volume() / box.volume();
  GrowthResult res = run_growth(std::move(model), std::move(st), box, o,
                                [&](State& x) { return rescale_to_temperature(x, mass, opt.kT); });
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
