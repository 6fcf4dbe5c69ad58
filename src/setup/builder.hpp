// THE BUILDER: a validated Config -> a ready simulation. The command line (`hardbody run`), the
// Python module and the benchmarks all assemble their runs here, so they cannot drift apart.
//
// assemble(config, f) checks everything that needs the geometry (ConfigError naming the key:
// the lattice start holds the packing fraction, the box is wide enough for the interaction range)
// and calls f with one typed Assembly: the pair model, the neighbour method and the start the
// config asks for, behind a small interface:
//   start(opt)               the initial bodies: the lattice at the target packing fraction, or
//                            (init.method = "grow" above init.phi0) a dilute lattice grown
//                            Lubachevsky–Stillinger style, checked by the independent test
//   simulate(box, state, t)  a simulation from given bodies (a start, a GSD frame, a benchmark's
//                            earlier state), every body predicted afresh at time t
//   restore(box, state, neighbour snapshot, loop snapshot)
//                            the simulation a checkpoint describes, continued bit for bit
//   ops()                    kinetic energy, temperature and the independent overlap check
// One-species hard spheres take the analytic fast path (HardSpheres), sphere mixtures and
// polydisperse spheres HardSphereMixture (cell lists, a grown random start); one species of
// another shape the rigid-body model of its registry type (any top; cells or oriented-box lists);
// every other mixture the generic RigidMixture (cell lists, a grown random start).
#pragma once
#include <fmt/format.h>

#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <variant>

#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "neighbors/shell_neighbors.hpp"
#include "observers/overlap_check.hpp"
#include "setup/box_setup.hpp"
#include "setup/config.hpp"
#include "setup/growth.hpp"
#include "setup/init.hpp"
#include "setup/mixture_setup.hpp"
#include "setup/rigid_setup.hpp"
#include "setup/sphere_setup.hpp"
#include "system/hard_sphere_mixture.hpp"
#include "system/hard_spheres.hpp"
#include "system/rigid_bodies.hpp"
#include "system/simulation.hpp"

namespace hb {

// What a driver needs to know about the bodies beyond the event loop.
struct SystemOps {
  std::vector<double> species_mass;             // per species, at scale 1
  std::function<double(const State&)> kinetic;  // total kinetic energy (translation + rotation)
  OverlapCheck overlaps;                        // independent check of a synchronized state

  double body_mass(const State& s, std::size_t i) const {
    return species_mass[s.species[i]] * s.scale[i] * s.scale[i] * s.scale[i];
  }
  double translational_kinetic(const State& s) const {
    double k = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) k += body_mass(s, i) * s.v[i].squaredNorm();
    return 0.5 * k;
  }
  // translational temperature 2 K_trans / (3 N)
  double temperature(const State& s) const { return 2.0 * translational_kinetic(s) / (3.0 * double(s.size())); }
  Vec3 momentum(const State& s) const {
    Vec3 p = Vec3::Zero();
    for (std::size_t i = 0; i < s.size(); ++i) p += body_mass(s, i) * s.v[i];
    return p;
  }
  double momentum_scale(const State& s) const {  // sum of |p_i|: the scale of the total's rounding
    double p = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) p += body_mass(s, i) * s.v[i].norm();
    return p;
  }
};

// Masses of the species at scale 1.
inline std::vector<double> species_masses(const SpeciesTable& t) {
  std::vector<double> m;
  for (const Species& s : t) m.push_back(s.mass);
  return m;
}

// How the initial bodies were made (summary.json "init").
struct StartInfo {
  std::string method = "lattice";  // "lattice" | "grow"
  std::string placement;           // method "grow": "lattice" (dilute lattice) | "random"
  std::string note;                // why the start differs from what was asked (or empty)
  GrowthOptions growth;            // method "grow"
  GrowthResult result;             // method "grow" (its state moved out)
};
struct Start {
  Box box;
  State state;
  StartInfo info;
};
struct StartOptions {
  bool quiet = true;  // false: one line on stderr before a growth
  std::function<void(const GrowthStatus&)> growth_report;  // progress of a growth (may be empty)
};

// The geometry checks (ConfigError naming the key) and the specifications of the starts.
SphereSystemSpec plan_spheres(const Config& c);        // one species of spheres
HardSphereMixture plan_sphere_mixture(const Config& c);  // several species or polydisperse spheres
RigidSystemSpec plan_rigid(const Config& c);           // one species of non-spherical bodies
RigidMixture plan_rigid_mixture(const Config& c);      // any other mixture or polydispersity

// The single-body event sources of a config (system/body_events.hpp): hard planar walls on the
// axes of walls.planes or the spherical container of walls.sphere (grazing step solver.eps_d) and
// the Andersen thermostat of [thermostat] (seeded by system.seed).
inline BodyEvents body_events_for(const Config& c) {
  AndersenThermostat th;
  if (c.thermostat.active()) th = AndersenThermostat(c.thermostat.rate, c.temperature, c.seed);
  return BodyEvents(PlanarWalls(c.boundaries.walls.planes, c.eps_d), std::move(th),
                    SphericalContainer(c.boundaries.walls.sphere_radius, c.eps_d));
}
// A box that is not the default periodic cube: the starts grow the bodies in box_for(c).
inline bool bounded(const Config& c) {
  return c.boundaries.walls.any() || c.boundaries.aspect != Vec3::Ones();
}

template <class Model, class Neighbors>
class Assembly {
 public:
  using Sim = Simulation<Model, Neighbors>;
  using neighbors_type = Neighbors;
  using StartFn = std::function<Start(const StartOptions&)>;

  Assembly(Model model, Neighbors nb, SystemOps ops, StartFn start, BodyEvents events = {})
      : model_(std::move(model)), nb_(std::move(nb)), ops_(std::move(ops)), start_(std::move(start)),
        events_(std::move(events)) {}

  const SystemOps& ops() const { return ops_; }
  const Model& model() const { return model_; }
  const BodyEvents& body_events() const { return events_; }
  Start start(const StartOptions& opt = {}) const { return start_(opt); }
  Sim simulate(const Box& box, State st, double now = 0.0) const {
    return Sim(box, std::move(st), model_, nb_, now, events_);
  }
  // thermostat: the thermostat's saved state (next event times, event counts), if it has one.
  template <class NbSnapshot>
  Sim restore(const Box& box, State st, const NbSnapshot& nb_snapshot, const LoopSnapshot& loop,
              const AndersenThermostat* thermostat = nullptr) const {
    Neighbors nb = nb_;
    nb.restore(box, st, nb_snapshot);
    BodyEvents ev = events_;
    if (thermostat) ev.thermostat() = *thermostat;
    return Sim(box, std::move(st), model_, std::move(nb), loop, std::move(ev));
  }

 private:
  Model model_;
  Neighbors nb_;
  SystemOps ops_;
  StartFn start_;
  BodyEvents events_;
};

namespace builder_detail {

// The start of a mixture grown with options go: its state, checked by the independent test (an
// overlap throws).
inline Start grown_start(GrowthResult result, const GrowthOptions& go, const OverlapCheck& check,
                         std::uint64_t seed) {
  Start s;
  s.info.method = "grow";
  s.info.placement = "random";
  s.info.growth = go;
  s.info.result = std::move(result);
  s.info.result.overlaps = check(s.info.result.state, s.info.result.box);
  if (s.info.result.overlaps.overlaps != 0)
    throw std::runtime_error(fmt::format("mixture growth: {} overlapping pairs (seed {})",
                                         s.info.result.overlaps.overlaps, seed));
  s.box = s.info.result.box;
  s.state = std::move(s.info.result.state);
  return s;
}

// The start of a bounded box (walls, side ratios): random placement at init.phi0 (clear of the
// walls) in box_for(c), then growth with the walls in place, checked by `check`.
inline Start bounded_start(const Config& c, const OverlapCheck& check, const StartOptions& opt) {
  GrowthOptions g;
  g.rate = c.init_growth_rate;
  g.phi0 = std::min(c.init_phi0, c.packing_fraction);
  g.kT = c.temperature;
  g.box = box_for(c);
  g.wall_eps = c.eps_d;
  g.container = c.boundaries.walls.sphere_radius;
  g.report = opt.growth_report;
  bool spheres = true;
  for (const Species& sp : c.species) spheres = spheres && std::holds_alternative<Sphere>(sp.shape);
  if (!opt.quiet)
    std::fprintf(stderr, "hardbody: placing at phi = %g in a %.4g x %.4g x %.4g box, growing to %g (rate %g) ...\n",
                 g.phi0, g.box->L.x(), g.box->L.y(), g.box->L.z(), c.packing_fraction, g.rate);
  GrowthResult r = spheres ? grow_sphere_mixture(c.species, c.packing_fraction, c.seed, g)
                           : grow_rigid_mixture(c.species, c.packing_fraction, c.seed, g, c.eps_d);
  GrowthOptions info = g;
  info.report = nullptr;
  return grown_start(std::move(r), info, check, c.seed);
}
// The start function of an assembly: `start` for the periodic cube, bounded_start otherwise.
template <class StartFn>
std::function<Start(const StartOptions&)> start_for(const Config& c, const SystemOps& ops, StartFn start) {
  if (!bounded(c)) return start;
  return [c, check = ops.overlaps](const StartOptions& opt) { return bounded_start(c, check, opt); };
}

template <class F>
void assemble_spheres(const Config& c, F&& f) {
  if (c.mixture()) {
    const HardSphereMixture model = plan_sphere_mixture(c);
    SystemOps ops{species_masses(c.species), [model](const State& s) { return model.kinetic_energy(s); },
                  [model](const State& s, const Box& b) {
                    std::vector<double> radii(s.size());
                    for (std::size_t i = 0; i < s.size(); ++i) radii[i] = model.body_radius(s, i);
                    return sphere_mixture_overlaps(s.r, radii, b);
                  }};
    GrowthOptions go;
    go.rate = c.init_growth_rate;
    go.phi0 = std::min(c.init_phi0, c.packing_fraction);
    go.kT = c.temperature;
    auto start = [species = c.species, phi = c.packing_fraction, seed = c.seed, go,
                  check = ops.overlaps](const StartOptions& opt) {
      if (!opt.quiet)
        std::fprintf(stderr, "hardbody: placing at phi = %g, growing to %g (rate %g) ...\n", go.phi0, phi, go.rate);
      GrowthOptions g = go;
      g.report = opt.growth_report;
      return grown_start(grow_sphere_mixture(species, phi, seed, g), go, check, seed);
    };
    f(Assembly<HardSphereMixture, CellNeighbors>(model, CellNeighbors(model.interaction_range()), ops, start_for(c, ops, start), body_events_for(c)));
    return;
  }
  // one species: the monomorphic fast path
  const SphereSystemSpec spec = plan_spheres(c);
  SystemOps ops{species_masses(c.species), [m = spec.mass](const State& s) { return kinetic_energy(s, m); },
                independent_overlap_check(c.one().shape)};
  // init.method = "grow": random placement at init.phi0 grown to the target (a fluid start
  // for metastable states); otherwise the FCC lattice at the target
  const bool grow = c.init_method == "grow" && c.packing_fraction > c.init_phi0;
  GrowthOptions go;
  go.rate = c.init_growth_rate;
  go.phi0 = c.init_phi0;
  go.kT = c.temperature;
  auto start = [spec, grow, go, species = c.species, check = ops.overlaps](const StartOptions& opt) {
    if (grow) {
      if (!opt.quiet)
        std::fprintf(stderr, "hardbody: placing at phi = %g, growing to %g (rate %g) ...\n", go.phi0, spec.phi, go.rate);
      GrowthOptions g = go;
      g.report = opt.growth_report;
      return grown_start(grow_sphere_mixture(species, spec.phi, spec.seed, g), go, check, spec.seed);
    }
    Start s;
    s.state = hard_sphere_start(spec, s.box);
    return s;
  };
  const HardSpheres model{spec.sigma, spec.mass};
  if (spec.shell > 0.0)
    f(Assembly<HardSpheres, ShellNeighbors>(model, ShellNeighbors(spec.sigma, spec.shell), ops, start_for(c, ops, start), body_events_for(c)));
  else
    f(Assembly<HardSpheres, CellNeighbors>(model, CellNeighbors(spec.sigma), ops, start_for(c, ops, start), body_events_for(c)));
}

// The unit body of the lattice start: the shape with unit semi-axes.
inline UnitBody unit_body_of(const Ellipsoid&) { return UnitBody{}; }
inline UnitBody unit_body_of(const Superquadric& q) {
  return unit_body(Superquadric{1.0, 1.0, 1.0, q.n, q.m, q.p});
}

template <Shape S, class F>
void assemble_rigid(const Config& c, const S& shape, F&& f) {
  const RigidSystemSpec spec = plan_rigid(c);  // one species (any top)
  const RigidBodies<S> model{shape, MassProperties::principal(spec.mass, spec.inertia), spec.eps_d};
  SystemOps ops{species_masses(c.species), [model](const State& s) { return model.kinetic_energy(s); },
                independent_overlap_check(c.one().shape)};
  const UnitBody unit = unit_body_of(shape);
  auto lattice = [unit](const RigidSystemSpec& sp, Box& box) { return lattice_start(sp, unit, box); };
  const bool grow = c.init_method == "grow" && c.packing_fraction > c.init_phi0;
  GrowthOptions go;
  go.rate = c.init_growth_rate;
  go.phi0 = c.init_phi0;
  go.kT = c.temperature;
  auto start = [=, species = c.species, check = ops.overlaps](const StartOptions& opt) {
    if (spec.cubic_start) {  // the stretched lattice would be too thin: random placement, cubic box
      if (!opt.quiet)
        std::fprintf(stderr, "hardbody: placing at phi <= %g in a cubic box, growing to %g (rate %g) ...\n",
                     std::min(go.phi0, spec.phi), spec.phi, go.rate);
      GrowthOptions g = go;
      g.phi0 = std::min(go.phi0, spec.phi);
      g.report = opt.growth_report;
      return grown_start(grow_rigid_mixture(species, spec.phi, spec.seed, g, spec.eps_d), g, check, spec.seed);
    }
    Start s;
    if (!grow) {
      s.state = lattice(spec, s.box);
      if (c.init_method == "grow") {
        s.info.note = fmt::format("init.method = \"grow\" but system.packing_fraction = {} is not above "
                                  "init.phi0 = {}: started on the lattice at the target", spec.phi, go.phi0);
        if (!opt.quiet) std::fprintf(stderr, "hardbody: note: %s\n", s.info.note.c_str());
      }
      return s;
    }
    GrowthOptions g = go;
    g.report = opt.growth_report;
    if (!opt.quiet)
      std::fprintf(stderr, "hardbody: growing from phi = %g to %g (rate %g) ...\n", go.phi0, spec.phi, go.rate);
    s.info.method = "grow";
    s.info.placement = "lattice";
    s.info.growth = go;
    s.info.result = grow_lattice(shape, spec, g, lattice, check);
    s.box = s.info.result.box;
    s.state = std::move(s.info.result.state);
    return s;
  };
  if (c.neighbors_method == "nnl")
    f(Assembly<RigidBodies<S>, ObbNeighbors<S>>(model, ObbNeighbors<S>(shape, c.shell), ops, start_for(c, ops, start), body_events_for(c)));
  else
    f(Assembly<RigidBodies<S>, CellNeighbors>(model, CellNeighbors(model.interaction_range()), ops, start_for(c, ops, start), body_events_for(c)));
}

// Mixtures with non-spherical species, and polydisperse non-spherical bodies: the generic
// RigidMixture over cell lists or per-body oriented-box lists, started by random placement and
// growth of every body.
template <class F>
void assemble_rigid_mixture(const Config& c, F&& f) {
  const RigidMixture model = plan_rigid_mixture(c);
  SystemOps ops{species_masses(c.species), [model](const State& s) { return model.kinetic_energy(s); },
                mixture_overlap_check(model.shape)};
  GrowthOptions go;
  go.rate = c.init_growth_rate;
  go.phi0 = std::min(c.init_phi0, c.packing_fraction);
  go.kT = c.temperature;
  auto start = [species = c.species, phi = c.packing_fraction, seed = c.seed, eps_d = c.eps_d, go,
                check = ops.overlaps](const StartOptions& opt) {
    if (!opt.quiet)
      std::fprintf(stderr, "hardbody: placing at phi <= %g, growing to %g (rate %g) ...\n", go.phi0, phi, go.rate);
    GrowthOptions g = go;
    g.report = opt.growth_report;
    return grown_start(grow_rigid_mixture(species, phi, seed, g, eps_d), go, check, seed);
  };
  if (c.neighbors_method == "nnl")
    f(Assembly<RigidMixture, ObbNeighbors<AnyShape>>(
        model, ObbNeighbors<AnyShape>(model.shape, model.max_scale, c.shell), ops, start_for(c, ops, start), body_events_for(c)));
  else
    f(Assembly<RigidMixture, CellNeighbors>(model, CellNeighbors(model.interaction_range()), ops, start_for(c, ops, start), body_events_for(c)));
}

}  // namespace builder_detail

// Calls f(assembly) with the typed Assembly of the config (see the header).
template <class F>
void assemble(const Config& c, F&& f) {
  bool spheres = true;
  for (const Species& sp : c.species) spheres = spheres && std::holds_alternative<Sphere>(sp.shape);
  if (spheres) return builder_detail::assemble_spheres(c, f);
  if (c.mixture()) return builder_detail::assemble_rigid_mixture(c, f);
  std::visit(
      [&](const auto& shape) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(shape)>, Sphere>)
          builder_detail::assemble_rigid(c, shape, f);
      },
      c.one().shape);
}

}  // namespace hb
