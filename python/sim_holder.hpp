// A type-erased handle on one of the library's Simulation<Model, Neighbors> types, for the
// Python module only (the library stays template-based). Built from a validated Config.
#pragma once
#include <array>
#include <cstdint>
#include <functional>
#include <memory>

#include "events/event.hpp"
#include "io/config.hpp"
#include "observers/overlap.hpp"
#include "observers/thermo.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb::python {

// Where an advance() call stopped.
enum class Stop { time, collisions };

class SimHandle {
 public:
  virtual ~SimHandle() = default;
  virtual double now() const = 0;
  virtual std::uint64_t collisions() const = 0;
  virtual std::uint64_t stale_events() const = 0;
  virtual std::array<std::uint64_t, kEventTypes> event_counts() const = 0;
  virtual const Box& box() const = 0;
  // Every body streamed to now() and wrapped into [0, L) (images updated).
  virtual State synchronized() const = 0;
  // Total kinetic energy (translation + rotation).
  virtual double kinetic_energy() const = 0;
  // Translational temperature 2 K_trans / (3 N).
  virtual double temperature() const = 0;
  // Overlapping pairs by the independent check (sphere distances / Perram–Wertheim).
  virtual OverlapReport overlaps() const = 0;
  // Runs events up to time t_end, or until collisions() == max_collisions, whichever comes
  // first. Real collisions are fed to `pressure`; `poll` is called every few thousand events
  // (it may throw to abort, e.g. on Ctrl-C).
  virtual Stop advance(double t_end, std::uint64_t max_collisions, VirialPressure& pressure,
                       const std::function<void()>& poll) = 0;
};

// Builds the simulation a Config describes (as `hardbody run` does, from t = 0; nothing is
// written). Throws ConfigError for a config the run driver would reject.
std::unique_ptr<SimHandle> make_simulation(const Config& c);
// The same, from given bodies and box (e.g. a GSD frame) instead of the lattice start; the
// number of bodies must match the config. Throws ConfigError / InputError.
std::unique_ptr<SimHandle> make_simulation(const Config& c, const Box& box, const State& start);

}  // namespace hb::python
