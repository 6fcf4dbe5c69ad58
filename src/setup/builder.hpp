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
// One-species hard spheres take the analytic fast path (HardSpheres); every other shape the
// generic rigid-body model of its registry type.
#pragma once
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <variant>

#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "neighbors/shell_neighbors.hpp"
#include "observers/overlap_check.hpp"
#include "setup/config.hpp"
#include "setup/growth.hpp"
#include "setup/init.hpp"
#include "setup/rigid_setup.hpp"
#include "setup/sphere_setup.hpp"
#include "system/hard_spheres.hpp"
#include "system/rigid_bodies.hpp"
#include "system/simulation.hpp"

namespace hb {

// What a driver needs to know about the bodies beyond the event loop.
struct SystemOps {
  double mass = 1.0;
  std::function<double(const State&)> kinetic;  // total kinetic energy (translation + rotation)
  OverlapCheck overlaps;                        // independent check of a synchronized state
  // translational temperature 2 K_trans / (3 N)
  double temperature(const State& s) const {
    return 2.0 * kinetic_energy(s, mass) / (3.0 * double(s.size()));
  }
};

// How the initial bodies were made (summary.json "init").
struct StartInfo {
  std::string method = "lattice";  // "lattice" | "grow"
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
};

// The geometry checks (ConfigError naming the key) and the specifications of the starts.
SphereSystemSpec plan_spheres(const Config& c);
RigidSystemSpec plan_rigid(const Config& c);

template <class Model, class Neighbors>
class Assembly {
 public:
  using Sim = Simulation<Model, Neighbors>;
  using neighbors_type = Neighbors;
  using StartFn = std::function<Start(const StartOptions&)>;

  Assembly(Model model, Neighbors nb, SystemOps ops, StartFn start)
      : model_(std::move(model)), nb_(std::move(nb)), ops_(std::move(ops)), start_(std::move(start)) {}

  const SystemOps& ops() const { return ops_; }
  const Model& model() const { return model_; }
  Start start(const StartOptions& opt = {}) const { return start_(opt); }
  Sim simulate(const Box& box, State st, double now = 0.0) const {
    return Sim(box, std::move(st), model_, nb_, now);
  }
  template <class NbSnapshot>
  Sim restore(const Box& box, State st, const NbSnapshot& nb_snapshot, const LoopSnapshot& loop) const {
    Neighbors nb = nb_;
    nb.restore(box, st, nb_snapshot);
    return Sim(box, std::move(st), model_, std::move(nb), loop);
  }

 private:
  Model model_;
  Neighbors nb_;
  SystemOps ops_;
  StartFn start_;
};

namespace builder_detail {

template <class F>
void assemble_spheres(const Config& c, const Sphere&, F&& f) {
  const SphereSystemSpec spec = plan_spheres(c);
  SystemOps ops{spec.mass, [m = spec.mass](const State& s) { return kinetic_energy(s, m); },
                independent_overlap_check(c.shape)};
  auto start = [spec](const StartOptions&) {
    Start s;
    s.state = hard_sphere_start(spec, s.box);
    return s;
  };
  const HardSpheres model{spec.sigma, spec.mass};
  if (spec.shell > 0.0)
    f(Assembly<HardSpheres, ShellNeighbors>(model, ShellNeighbors(spec.sigma, spec.shell), ops, start));
  else
    f(Assembly<HardSpheres, CellNeighbors>(model, CellNeighbors(spec.sigma), ops, start));
}

// The unit body of the lattice start: the shape with unit semi-axes.
inline UnitBody unit_body_of(const Ellipsoid&) { return UnitBody{}; }
inline UnitBody unit_body_of(const Superquadric& q) {
  return unit_body(Superquadric{1.0, 1.0, 1.0, q.n, q.m, q.p});
}

template <Shape S, class F>
void assemble_rigid(const Config& c, const S& shape, F&& f) {
  const RigidSystemSpec spec = plan_rigid(c);
  const RigidBodies<S> model{shape, MassProperties::spherical_top(spec.mass, spec.inertia), spec.eps_d};
  SystemOps ops{spec.mass, [model](const State& s) { return model.kinetic_energy(s); },
                independent_overlap_check(c.shape)};
  const UnitBody unit = unit_body_of(shape);
  auto lattice = [unit](const RigidSystemSpec& sp, Box& box) { return lattice_start(sp, unit, box); };
  const bool grow = c.init_method == "grow" && c.packing_fraction > c.init_phi0;
  GrowthOptions go;
  go.rate = c.init_growth_rate;
  go.phi0 = c.init_phi0;
  go.kT = c.temperature;
  auto start = [=, check = ops.overlaps](const StartOptions& opt) {
    Start s;
    if (!grow) {
      s.state = lattice(spec, s.box);
      return s;
    }
    if (!opt.quiet)
      std::fprintf(stderr, "hardbody: growing from phi = %g to %g (rate %g) ...\n", go.phi0, spec.phi, go.rate);
    s.info.method = "grow";
    s.info.growth = go;
    s.info.result = grow_lattice(shape, spec, go, lattice, check);
    s.box = s.info.result.box;
    s.state = std::move(s.info.result.state);
    return s;
  };
  if (c.neighbors_method == "nnl")
    f(Assembly<RigidBodies<S>, ObbNeighbors<S>>(model, ObbNeighbors<S>(shape, c.shell), ops, start));
  else
    f(Assembly<RigidBodies<S>, CellNeighbors>(model, CellNeighbors(model.interaction_range()), ops, start));
}

}  // namespace builder_detail

// Calls f(assembly) with the typed Assembly of the config (see the header).
template <class F>
void assemble(const Config& c, F&& f) {
  std::visit(
      [&](const auto& shape) {
        using S = std::decay_t<decltype(shape)>;
        if constexpr (std::is_same_v<S, Sphere>)
          builder_detail::assemble_spheres(c, shape, f);
        else
          builder_detail::assemble_rigid(c, shape, f);
      },
      c.shape);
}

}  // namespace hb
