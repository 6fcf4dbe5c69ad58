// Trajectory frames and checkpoints in GSD (HOOMD schema). A checkpoint holds, besides the
// OVITO-readable frame, the exact double-precision state at the bodies' own time stamps, the
// event calendar, the neighbour structure and the driver's accumulators, so that
// `hardbody run --resume` continues bit for bit.
#pragma once
#include <array>
#include <fmt/format.h>
#include <memory>

#include <cstdint>
#include <string>
#include <vector>

#include "io/config.hpp"
#include "io/gsd_hoomd.hpp"
#include "io/run.hpp"
#include "contact/axis_memo.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "core/box.hpp"
#include "system/simulation.hpp"
#include "core/state.hpp"

namespace hb {

// What the run driver accumulates (checkpointed with the state).
struct DriverState {
  int phase = 0;  // 0 equilibrating, 1 measuring, 2 done
  double e0 = 0.0, coll0 = 0.0, stale0 = 0.0, rescheduled0 = 0.0;
  std::array<double, kEventTypes> events0{};
  std::uint64_t log_rows = 0, frames = 0;
  double next_snapshot = 0.0, block_start = 0.0;
  double cpu_prev = 0.0, wall_prev = 0.0;  // measured-phase seconds of earlier sessions
  std::vector<double> pressure;            // VirialPressure::save()
  double next_corr = 0.0, next_gr = 0.0;   // next sampling times of the observables
  std::vector<double> corr, gr, nematic;   // their save() records
  std::vector<double> gr_partial;          // PartialRadialDistribution::save() (mixtures)
  std::vector<double> temperatures;        // SpeciesTemperatures::save()
  std::vector<std::vector<double>> corr_species;  // TimeCorrelations::save() per species (mixtures)
  std::vector<double> pair_collisions;     // measured collisions per species pair a <= b (row-major upper triangle)
  std::vector<double> wall_pressure;       // WallPressure::save() (walls)
  std::vector<double> profiles;            // DensityProfiles::save() (walls)
  std::vector<double> thermostat_next;     // AndersenThermostat: each body's next event time
  std::vector<double> thermostat_count;    //   and its event count
};

// A copy of the state with every body streamed to the current time and wrapped into the box.
template <class Sim>
State synchronized_state(const Sim& sim) {
  State s = sim.state();
  for (std::uint32_t i = 0; i < s.size(); ++i) {
    s.advance_to(i, sim.now());
    s.image[i] += sim.box().wrap(s.r[i]);
  }
  return s;
}

namespace ckpt {
struct ConfigSignature {
  std::vector<std::string> names;
  std::vector<double> values;
};
ConfigSignature config_signature(const Config& c);

// The frame of the bodies at `now` (each streamed to `now` and wrapped into the box exactly as
// synchronized_state does), with the exact doubles in log chunks. Its chunks are made a buffer
// at a time while they are written: nothing of size N is copied. `s` must outlive the frame.
gsd::FrameSource frame_source(const State& s, const Box& box, double now, std::uint64_t step,
                              const SpeciesTable& species);
// Adds what a resume needs: the state at the bodies' own time stamps (views of `s`), the event
// calendar, the driver's accumulators and the config signature. Not the model's memo
// (loop.memo is not read): make_checkpoint streams it from the model (memo_rows).
void add_checkpoint_sources(gsd::FrameSource& f, const State& s, LoopSnapshot loop,
                            const DriverState& d, const Config& c);
gsd::ChunkSource encode(std::vector<std::array<int, 3>> c);
gsd::ChunkSource encode(std::vector<Vec3> c);
gsd::ChunkSource encode(ObbSnapshot c);
// A view of a rigid model's axis memo (contact/axis_memo.hpp) as rows x, y, z, j of
// hardbody/solver_memo, streamed: `m` must outlive the frame.
gsd::ChunkSource memo_rows(const AxisMemo& m);

// Reading back (throw InputError naming the file and the problem).
struct Reader {
  std::string path;
  gsd::HoomdFrame f;
  const gsd::LogArray& get(const std::string& key, std::uint64_t rows, std::uint32_t cols) const;
  std::vector<Vec3> vec3s(const std::string& key, std::uint64_t n) const;
  std::vector<Quat> quats(const std::string& key, std::uint64_t n) const;
  std::vector<Event> events(const std::string& key, std::uint64_t n) const;
  std::vector<double> row(const std::string& key) const;
};
Reader open(const std::string& path, const Config& c);
void read_core(const Reader& r, Box& box, State& s, LoopSnapshot& loop, DriverState& d);
void decode(const Reader& r, std::vector<std::array<int, 3>>& out);
void decode(const Reader& r, std::vector<Vec3>& out);
void decode(const Reader& r, ObbSnapshot& out);
}  // namespace ckpt

// One trajectory frame (synchronised positions) at the simulation's current time, streamed from
// the simulation's state (which must not change until the frame is written).
template <class Sim>
gsd::FrameSource make_frame(const Sim& sim, const SpeciesTable& species, bool, const void*) {
  return ckpt::frame_source(sim.state(), sim.box(), sim.now(), sim.collisions(), species);
}

template <class Sim>
gsd::FrameSource make_checkpoint(const Sim& sim, const SpeciesTable& species, const Config& c,
                                 const DriverState& d) {
  gsd::FrameSource f = make_frame(sim, species, true, nullptr);
  ckpt::add_checkpoint_sources(f, sim.state(), sim.snapshot(/*with_memo=*/false), d, c);
  f.log["particles/hardbody/neighbors"] = ckpt::encode(sim.neighbors().snapshot());
  // The model's memo between solves (rigid models), read back by read_core into the loop's
  // snapshot: a view, not a copy (1 kB a body).
  if constexpr (requires { sim.model().memo.size(); })
    if (sim.model().memo.size() > 0) f.log["hardbody/solver_memo"] = ckpt::memo_rows(sim.model().memo);
  return f;
}

// The bodies of one GSD frame (hardbody's exact log chunks when present, else the HOOMD float
// chunks; HOOMD positions are in a box centred on 0) as a State at time 0, and its box.
// frame < 0 counts from the end. Throws InputError naming the file.
State state_from_gsd(const std::string& path, long frame, Box& box);

template <class Nb>
struct Restored {
  Box box;
  State state;
  LoopSnapshot loop;
  DriverState driver;
  decltype(std::declval<const Nb&>().snapshot()) neighbors;
};

template <class Nb>
Restored<Nb> read_checkpoint(const std::string& path, const Config& c) {
  Restored<Nb> r;
  const ckpt::Reader rd = ckpt::open(path, c);
  ckpt::read_core(rd, r.box, r.state, r.loop, r.driver);
  ckpt::decode(rd, r.neighbors);
  return r;
}

}  // namespace hb
