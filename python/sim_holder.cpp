#include "sim_holder.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "io/checkpoint.hpp"
#include "io/plan.hpp"
#include "system/init.hpp"
#include "system/rigid_setup.hpp"
#include "system/sphere_setup.hpp"

namespace hb::python {

namespace {

// The simulation plus the two things the driver knows about the bodies beyond the event loop.
template <class Sim, class Kinetic, class Overlaps>
class Holder final : public SimHandle {
 public:
  Holder(Sim sim, double mass, Kinetic kinetic, Overlaps overlaps)
      : sim_(std::move(sim)), mass_(mass), kinetic_(kinetic), overlaps_(overlaps) {}

  double now() const override { return sim_.now(); }
  std::uint64_t collisions() const override { return sim_.collisions(); }
  std::uint64_t stale_events() const override { return sim_.stale_events(); }
  std::array<std::uint64_t, kEventTypes> event_counts() const override { return sim_.event_counts(); }
  const Box& box() const override { return sim_.box(); }
  State synchronized() const override { return synchronized_state(sim_); }
  double kinetic_energy() const override { return kinetic_(sim_.state()); }
  double temperature() const override {
    return 2.0 * hb::kinetic_energy(sim_.state(), mass_) / (3.0 * double(sim_.state().size()));
  }
  OverlapReport overlaps() const override { return overlaps_(synchronized_state(sim_), sim_.box()); }

  Stop advance(double t_end, std::uint64_t max_collisions, VirialPressure& pressure,
               const std::function<void()>& poll) override {
    std::uint64_t steps = 0;
    if (sim_.collisions() >= max_collisions) return Stop::collisions;
    for (;;) {
      const StepInfo s = sim_.step(t_end);
      if (s.type == EventType::None) return Stop::time;
      if (s.type == EventType::Collision && !s.stale) {
        pressure.on_collision(s.record);
        if (sim_.collisions() >= max_collisions) return Stop::collisions;
      }
      if ((++steps & 4095) == 0) poll();
    }
  }

 private:
  Sim sim_;
  double mass_;
  Kinetic kinetic_;
  Overlaps overlaps_;
};

template <class Sim, class K, class O>
std::unique_ptr<SimHandle> hold(Sim sim, double mass, K kinetic, O overlaps) {
  return std::make_unique<Holder<Sim, K, O>>(std::move(sim), mass, kinetic, overlaps);
}

std::unique_ptr<SimHandle> spheres(const Config& c, const Box* box, const State* start) {
  const SphereSystemSpec spec = plan_spheres(c);  // the run driver's checks and messages
  auto kinetic = [m = spec.mass](const State& s) { return hb::kinetic_energy(s, m); };
  auto overlaps = [sigma = spec.sigma](const State& s, const Box& b) {
    return sphere_overlaps(s.r, b, sigma);
  };
  if (start) {
    const HardSpheres model{spec.sigma, spec.mass};
    if (spec.shell > 0.0)
      return hold(SphereListSim(*box, *start, model, ShellNeighbors(spec.sigma, spec.shell)),
                  spec.mass, kinetic, overlaps);
    return hold(SphereCellSim(*box, *start, model, CellNeighbors(spec.sigma)), spec.mass, kinetic,
                overlaps);
  }
  if (spec.shell > 0.0)
    return hold(make_hard_sphere_list_simulation(spec), spec.mass, kinetic, overlaps);
  return hold(make_hard_sphere_cell_simulation(spec), spec.mass, kinetic, overlaps);
}

std::unique_ptr<SimHandle> ellipsoids(const Config& c, const Box* box, const State* start) {
  const RigidSystemSpec spec = plan_ellipsoids(c);
  const auto proto = ellipsoid_model(spec);
  auto kinetic = [proto](const State& s) { return proto.kinetic_energy(s); };
  auto overlaps = [axes = spec.semi_axes](const State& s, const Box& b) {
    return ellipsoid_overlaps(s.r, s.q, b, axes);
  };
  if (start) {
    if (c.neighbors_method == "nnl")
      return hold(EllipsoidListSim(*box, *start, ellipsoid_model(spec),
                                   ObbNeighbors<Ellipsoid>(proto.shape, c.shell)),
                  spec.mass, kinetic, overlaps);
    return hold(EllipsoidCellSim(*box, *start, ellipsoid_model(spec),
                                 CellNeighbors(proto.interaction_range())),
                spec.mass, kinetic, overlaps);
  }
  if (c.neighbors_method == "nnl")
    return hold(make_ellipsoid_list_simulation(spec, c.shell), spec.mass, kinetic, overlaps);
  return hold(make_ellipsoid_cell_simulation(spec), spec.mass, kinetic, overlaps);
}

}  // namespace

namespace {
std::unique_ptr<SimHandle> build(const Config& c, const Box* box, const State* start) {
  try {
    if (c.shape.type == "sphere") return spheres(c, box, start);
    if (c.shape.type == "ellipsoid") return ellipsoids(c, box, start);
  } catch (const std::invalid_argument& e) {  // the lattice starts reject a too dense system
    throw ConfigError(fmt::format("{}: key 'system.packing_fraction': {} ({} particles at {})",
                                  c.source, e.what(), c.particles, c.packing_fraction));
  }
  throw ConfigError(fmt::format("{}: key 'shape.type': '{}' bodies are not yet supported", c.source,
                                c.shape.type));
}
}  // namespace

std::unique_ptr<SimHandle> make_simulation(const Config& c) { return build(c, nullptr, nullptr); }

std::unique_ptr<SimHandle> make_simulation(const Config& c, const Box& box, const State& start) {
  if (start.size() != c.particles)
    throw ConfigError(fmt::format("{}: key 'system.particles': {} in the config, {} bodies given",
                                  c.source, c.particles, start.size()));
  auto h = build(c, &box, &start);
  const OverlapReport rep = h->overlaps();
  if (rep.overlaps > 0)
    throw InputError(fmt::format("the given bodies overlap ({} pairs)", rep.overlaps));
  return h;
}

}  // namespace hb::python
