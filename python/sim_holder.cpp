#include "sim_holder.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

#include "io/checkpoint.hpp"
#include "io/run.hpp"
#include "setup/builder.hpp"

namespace hb::python {

namespace {

// The simulation plus what the builder knows about its bodies beyond the event loop.
template <class Sim>
class Holder final : public SimHandle {
 public:
  Holder(Sim sim, SystemOps ops) : sim_(std::move(sim)), ops_(std::move(ops)) {}

  double now() const override { return sim_.now(); }
  std::uint64_t collisions() const override { return sim_.collisions(); }
  std::uint64_t stale_events() const override { return sim_.stale_events(); }
  std::array<std::uint64_t, kEventTypes> event_counts() const override { return sim_.event_counts(); }
  const Box& box() const override { return sim_.box(); }
  State synchronized() const override { return synchronized_state(sim_); }
  double kinetic_energy() const override { return ops_.kinetic(sim_.state()); }
  double temperature() const override { return ops_.temperature(sim_.state()); }
  OverlapReport overlaps() const override { return ops_.overlaps(synchronized_state(sim_), sim_.box()); }

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
  SystemOps ops_;
};

// The builder's assembly of the config, started from its own start (lattice or growth, as
// `hardbody run` does) or from the given bodies.
std::unique_ptr<SimHandle> build(const Config& c, const Box* box, const State* start) {
  std::unique_ptr<SimHandle> h;
  try {
    assemble(c, [&](const auto& as) {
      using Sim = typename std::decay_t<decltype(as)>::Sim;
      if (start) {
        h = std::make_unique<Holder<Sim>>(as.simulate(*box, *start), as.ops());
      } else {
        Start s = as.start();
        h = std::make_unique<Holder<Sim>>(as.simulate(s.box, std::move(s.state)), as.ops());
      }
    });
  } catch (const std::invalid_argument& e) {  // the lattice starts reject a too dense system
    throw ConfigError(fmt::format("{}: key 'system.packing_fraction': {} ({} particles at {})",
                                  c.source, e.what(), c.particles, c.packing_fraction));
  }
  if (!h) throw std::logic_error("the builder assembled no simulation for this config");
  return h;
}

}  // namespace

std::unique_ptr<SimHandle> make_simulation(const Config& c) { return build(c, nullptr, nullptr); }

std::unique_ptr<SimHandle> make_simulation(const Config& c, const Box& box, const State& start) {
  if (start.size() != c.particles)
    throw ConfigError(fmt::format("{}: key 'system.particles': {} in the config, {} bodies given",
                                  c.source, c.particles, start.size()));
  // the bodies' species (GSD typeid) must be the config's, count for count
  std::vector<std::uint64_t> counts(c.species.size(), 0);
  for (std::size_t i = 0; i < start.size(); ++i) {
    if (start.species[i] >= c.species.size())
      throw ConfigError(fmt::format("{}: key 'species': body {} has type id {}, the config has {} species",
                                    c.source, i, start.species[i], c.species.size()));
    ++counts[start.species[i]];
  }
  for (std::size_t a = 0; a < counts.size(); ++a)
    if (counts[a] != c.species[a].count)
      throw ConfigError(fmt::format("{}: key 'species': {} bodies of species '{}' given, the config has {}",
                                    c.source, counts[a], c.species[a].name, c.species[a].count));
  auto h = build(c, &box, &start);
  const OverlapReport rep = h->overlaps();
  if (rep.overlaps > 0)
    throw InputError(fmt::format("the given bodies overlap ({} pairs)", rep.overlaps));
  return h;
}

}  // namespace hb::python
