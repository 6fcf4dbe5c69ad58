#include "io/run.hpp"

#include <fmt/format.h>

#include <atomic>
#include <functional>
#include <memory>
#include <csignal>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <limits>
#include <optional>
#include <sstream>

#include "core/fault_injection.hpp"
#include "core/interrupt.hpp"
#include "io/checkpoint.hpp"
#include "io/config.hpp"
#include "io/files.hpp"
#include "io/gsd_hoomd.hpp"
#include "io/progress.hpp"
#include "io/run_directory.hpp"
#include "io/shape_io.hpp"
#include "observers/correlations.hpp"
#include "observers/structure.hpp"
#include "observers/thermo.hpp"
#include "observers/wall_observables.hpp"
#include "setup/builder.hpp"

namespace hb {

namespace {

extern "C" void on_signal(int sig) { request_stop(sig); }

struct SignalGuard {
  struct sigaction old_int {}, old_term {};
  SignalGuard() {
    clear_stop();
    struct sigaction sa {};
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
  }
  ~SignalGuard() {
    sigaction(SIGINT, &old_int, nullptr);
    sigaction(SIGTERM, &old_term, nullptr);
  }
};

double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

std::string default_out_dir(const std::string& config_path) {
  return "run-" + std::filesystem::path(config_path).stem().string();
}

// Rows of log.tsv, kept in log.tsv.part while running and renamed at the end.
class LogTable {
 public:
  static constexpr const char* kHeader =
      "time\tcollisions\tZ_block\tZ_mean\ttemperature\tenergy_drift\tcollision_rate\n";
  // Opens the table keeping the first `keep_rows` data rows of an existing .part file, or of the
  // committed table when the run had finished (a kill between the commit and summary.json, or a
  // finished run being extended).
  LogTable(std::string path, std::uint64_t keep_rows, bool resume)
      : path_(std::move(path)), part_(path_ + ".part") {
    std::string kept = kHeader;
    if (resume) {
      const std::string from = file_exists(part_) || !file_exists(path_) ? part_ : path_;
      std::ifstream in(from);
      if (!in && keep_rows > 0)
        throw InputError(fmt::format("{}: missing; it holds the log rows before the checkpoint", part_));
      std::string line;
      std::getline(in, line);  // header
      for (std::uint64_t k = 0; k < keep_rows; ++k) {
        if (!std::getline(in, line))
          throw InputError(fmt::format("{}: has fewer rows than the checkpoint records", from));
        kept += line + "\n";
      }
    }
    write_file_atomic(part_, kept);
    try {
      out_ = AppendFile(part_);
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());
    }
  }
  template <class... T>
  void row(const T&... v) {
    std::string s;
    ((s += fmt::format("{:.10g}\t", v)), ...);
    s.back() = '\n';
    out_.write(s);  // every write checked (a full disk throws, naming the file)
  }
  void commit() {
    out_.close();
    std::filesystem::rename(part_, path_);
  }

 private:
  std::string path_, part_;
  AppendFile out_;
};

// The bodies of species a (same order), for the per-species correlations of a mixture.
State species_subset(const State& s, std::size_t a) {
  std::vector<std::size_t> idx;
  for (std::size_t i = 0; i < s.size(); ++i)
    if (s.species[i] == a) idx.push_back(i);
  State out;
  out.resize(idx.size());
  for (std::size_t k = 0; k < idx.size(); ++k) {
    const std::size_t i = idx[k];
    out.r[k] = s.r[i], out.v[k] = s.v[i], out.q[k] = s.q[i], out.w[k] = s.w[i];
    out.t[k] = s.t[i], out.count[k] = s.count[i], out.image[k] = s.image[i];
    out.species[k] = s.species[i], out.scale[k] = s.scale[i];
  }
  return out;
}

// Keeps the first `frames` frames of a trajectory (after a resume from an older checkpoint).
void truncate_trajectory(const std::string& path, std::uint64_t frames) {
  const gsd::Reader r(path);
  if (r.nframes() == frames) return;
  if (r.nframes() < frames)
    throw InputError(fmt::format("{}: has {} frames, the checkpoint expects at least {}", path,
                                 r.nframes(), frames));
  const std::string tmp = path + ".trunc";
  {
    auto w = gsd::HoomdWriter::create(tmp);
    for (std::uint64_t f = 0; f < frames; ++f) w.write_frame(gsd::read_frame(r, f));
    w.sync();
    w.close();
  }
  std::filesystem::rename(tmp, path);
}

// The state became non-finite: a run-time failure whose checkpoint is the previous one.
class NonFiniteState : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Has the measured run reached its end (run.time or run.max_collisions)?
template <class Sim>
bool run_finished(const Sim& sim, const Config& cfg, const DriverState& d) {
  if (d.phase < 1) return false;
  if (!(sim.now() < cfg.equilibrate_time + cfg.time)) return true;
  return cfg.max_collisions && double(sim.collisions()) - d.coll0 >= double(cfg.max_collisions);
}

// A restored state must be one a run can reach: finite and without overlaps.
template <class Sim>
void check_restored(const Sim& sim, const SystemOps& ops, const std::string& path) {
  const State& s = sim.state();
  for (std::size_t i = 0; i < s.size(); ++i) {
    const bool ok = s.r[i].allFinite() && s.v[i].allFinite() && s.w[i].allFinite() &&
                    s.q[i].coeffs().allFinite() && std::isfinite(s.t[i]) && std::isfinite(s.scale[i]);
    if (!ok) throw InputError(fmt::format("{}: body {} has a non-finite position, orientation, velocity or time", path, i));
  }
  const auto rep = ops.overlaps(synchronized_state(sim), sim.box());
  if (rep.overlaps > 0)
    throw InputError(fmt::format("{}: holds {} overlapping pairs (min gap {:.3g}); no run reaches such a "
                                 "state: the file is damaged or not this run's", path, rep.overlaps,
                                 rep.min_distance));
}

// The run driver, generic over the simulation type (sphere cells / sphere lists / ...).
template <class Sim>
class Driver {
 public:
  Driver(const Config& cfg, const RunOptions& opt, const std::string& dir, Sim& sim,
         const DriverState& st, const SystemOps& ops, nlohmann::json extra)
      : cfg_(cfg), opt_(opt), dir_(dir), sim_(sim), st_(st), ops_(ops),
        extra_(std::move(extra)),
        corr_(correlation_spec(cfg)), rdf_(rdf_spec(cfg)),
        gr_partial_(cfg.species.size(), int(cfg.gr_bins)), temps_(cfg.species.size()) {
    if (partial_gr()) corr_species_.assign(cfg.species.size(), TimeCorrelations(correlation_spec(cfg)));
    for (std::size_t a = 0; a < std::min(corr_species_.size(), st_.corr_species.size()); ++a)
      if (!st_.corr_species[a].empty()) corr_species_[a].load(st_.corr_species[a]);
    if (!st_.pressure.empty()) pressure_.load(st_.pressure);
    if (!st_.corr.empty()) corr_.load(st_.corr);
    if (!st_.gr.empty()) rdf_.load(st_.gr);
    if (!st_.nematic.empty()) nem_.load(st_.nematic);
    if (!st_.gr_partial.empty()) gr_partial_.load(st_.gr_partial);
    if (!st_.temperatures.empty()) temps_.load(st_.temperatures);
    const std::size_t ns = cfg_.species.size();
    st_.pair_collisions.resize(ns * (ns + 1) / 2, 0.0);
    const WallSpec& walls = cfg_.boundaries.walls;
    if (walls.any()) {
      wall_pressure_.emplace(wall_area(walls, sim_.box()));
      profiles_.emplace(walls, sim_.box(), profile_species(cfg_.species), default_profile_bin(cfg_.species));
      if (!st_.wall_pressure.empty()) wall_pressure_->load(st_.wall_pressure);
      if (!st_.profiles.empty()) profiles_->load(st_.profiles);
    }
  }

  static CorrelationSpec correlation_spec(const Config& c) {
    CorrelationSpec s;
    s.interval = c.obs_interval > 0.0 ? c.obs_interval : 1.0;
    s.origin_every = int(c.obs_origin_every);
    s.max_lag_samples = std::max(1, int(std::lround(c.obs_max_lag / s.interval)));
    s.q = c.obs_q;
    s.max_q_vectors = int(c.obs_q_vectors);
    return s;
  }
  static RdfSpec rdf_spec(const Config& c) {
    RdfSpec s;
    s.bins = int(c.gr_bins);
    return s;
  }

  void run() {
    const double t_eq = cfg_.equilibrate_time, t_end = t_eq + cfg_.time;
    const std::uint64_t n = sim_.state().size();
    LogTable log(dir_ + "/log.tsv", st_.log_rows, opt_.resume);
    const std::string traj = dir_ + "/trajectory.gsd";
    std::optional<gsd::HoomdWriter> writer;
    if (cfg_.trajectory) {
      if (opt_.resume && st_.frames > 0) {
        truncate_trajectory(traj, st_.frames);
        writer.emplace(gsd::HoomdWriter::append(traj));
      } else {
        writer.emplace(gsd::HoomdWriter::create(traj));
      }
    }
    if (st_.phase == 2 && !run_finished(sim_, cfg_, st_)) st_.phase = 1;  // extended: measure on
    const double cpu0 = cpu_seconds();
    last_checkpoint_ = progress_.wall_seconds();
    auto measured_cpu = [&] { return st_.cpu_prev + (st_.phase == 1 ? cpu_seconds() - cpu_mark_ : 0.0); };
    if (st_.phase == 1) cpu_mark_ = cpu0;

    // the first checkpoint at once: a run stopped in its first checkpoint interval (600 wall
    // seconds by default) still resumes, and the growth is not repeated
    if (!opt_.resume) write_checkpoint();
    std::uint64_t steps = 0;
    while (st_.phase < 2) {
      if (st_.phase == 0 && sim_.now() >= t_eq) {
        // start of the measured run
        st_.phase = 1;
        st_.e0 = energy();
        st_.coll0 = double(sim_.collisions());
        st_.stale0 = double(sim_.stale_events());
        st_.rescheduled0 = double(sim_.rescheduled_events());
        for (int k = 0; k < kEventTypes; ++k) st_.events0[k] = double(sim_.event_counts()[k]);
        st_.block_start = sim_.now();
        st_.next_snapshot = sim_.now();
        st_.next_corr = sim_.now();
        st_.next_gr = sim_.now();
        cpu_mark_ = cpu_seconds();
        wall_mark_ = progress_.wall_seconds();
        if (cfg_.thermostat.active() && cfg_.thermostat.during == ThermostatSpec::During::equilibration)
          sim_.set_thermostat(false);
      }
      // snapshots: a trajectory frame (if written), the independent checks and, with walls, the
      // profiles (sampled on the snapshot grid even without a trajectory)
      if (st_.phase == 1 && (writer || profiles_) && sim_.now() >= st_.next_snapshot) {
        if (writer) {
          writer->write_frame(make_frame(sim_, cfg_.species, false, nullptr));
          writer->sync();
          st_.frames += 1;
        }
        st_.next_snapshot += cfg_.snapshot_interval;
        // every snapshot is also checked for overlaps by the independent test
        const State snap = synchronized_state(sim_);
        const auto rep = ops_.overlaps(snap, sim_.box());
        snapshot_overlaps_ += rep.overlaps;
        snapshot_min_gap_ = std::min(snapshot_min_gap_, rep.min_distance);
        if (profiles_) {
          profiles_->sample(sim_.now(), snap, sim_.box());
          const double pen = wall_penetration(snap);
          worst_wall_penetration_ = std::max(worst_wall_penetration_, pen);
          if (pen > 0.0) ++snapshot_wall_penetrations_;
        }
      }
      if (st_.phase == 1) sample_observables();
      const double block_end = st_.phase == 0 ? t_eq : log_block_end(st_.block_start, t_end);
      double target = block_end;
      if (st_.phase == 1 && (writer || profiles_)) target = std::min(target, st_.next_snapshot);
      if (st_.phase == 1 && cfg_.obs_interval > 0.0) target = std::min(target, st_.next_corr);
      if (st_.phase == 1 && cfg_.gr_interval > 0.0) target = std::min(target, st_.next_gr);
      bool limit = false;
      for (;;) {
        const StepInfo s = sim_.step(target);
        if (s.type == EventType::None) break;
        if (st_.phase == 1 && s.type == EventType::Wall && wall_pressure_)
          wall_pressure_->add(s.record.time, s.record.J);
        if (st_.phase == 1 && s.type == EventType::Collision && !s.stale) {
          pressure_.on_collision(s.record);
          count_pair(s.record);
          if (cfg_.max_collisions &&
              sim_.collisions() - std::uint64_t(st_.coll0) >= cfg_.max_collisions) {
            limit = true;
            break;
          }
        }
        if ((++steps & 4095) == 0) housekeeping();
      }
      if (sim_.now() >= block_end || limit) check_finite();  // each log block (and equilibration end)
      if (st_.phase == 1 && (sim_.now() >= block_end || limit)) {
        const double kT = temperature();
        pressure_.close_block(sim_.now() - st_.block_start, kT, n);
        if (wall_pressure_) wall_pressure_->close_block(sim_.now() - st_.block_start, kT);
        st_.block_start = sim_.now();
        if (!all_spheres()) nem_.sample(sim_.now() - t_eq, synchronized_state(sim_), sim_.box());
        temps_.sample(species_temperatures(synchronized_state(sim_)));
        log.row(sim_.now() - t_eq, double(sim_.collisions()) - st_.coll0, pressure_.last_Z(),
                pressure_.Z().mean, kT, (energy() - st_.e0) / st_.e0,
                pressure_.collision_rate().mean);
        st_.log_rows += 1;
        if (sim_.now() >= t_end || limit) {
          if (writer) {  // the final state is the last frame (the grid's frames are all earlier)
            writer->write_frame(make_frame(sim_, cfg_.species, false, nullptr));
            writer->sync();
            st_.frames += 1;
            // a grid time at the end is this frame (an extended run does not repeat it)
            if (!(st_.next_snapshot > sim_.now())) st_.next_snapshot += cfg_.snapshot_interval;
          }
          st_.cpu_prev = measured_cpu();
          st_.wall_prev += progress_.wall_seconds() - wall_mark_;
          wall_mark_ = progress_.wall_seconds();
          st_.phase = 2;
        }
      }
      housekeeping();
      const double frac = st_.phase == 0 ? sim_.now() / t_end
                                         : std::max(sim_.now() / t_end,
                                                    cfg_.max_collisions ? (double(sim_.collisions()) - st_.coll0) / cfg_.max_collisions : 0.0);
      if (!opt_.quiet)
        // time as in log.tsv: measured time (from 0) once measuring, simulated time before
        progress_.update(st_.phase == 0 ? "equilibrate" : "measure", st_.phase == 0 ? sim_.now() : sim_.now() - t_eq, sim_.collisions(),
                         st_.phase == 0 ? 0.0 : pressure_.Z().mean, std::min(frac, 1.0));
    }
    if (!opt_.quiet) progress_.finish();
    write_checkpoint();
    if (writer) writer->close();
    finish(log);
  }

  // Checkpoint of the current moment (also used on failures).
  // A state that is not finite (a solver or integration failure nothing else caught) ends the run
  // with exit 3, naming the first such body with its state (a reproducer of its motion); it is
  // never written over the previous checkpoint.
  void check_finite() const {
    try {
      fault_point("nonfinite");  // tests: HARDBODY_FAULT=nonfinite:FAIL:N stands for a damaged state
    } catch (const std::runtime_error& e) {
      throw NonFiniteState(fmt::format("{}: a non-finite state (injected)", e.what()));
    }
    const State& s = sim_.state();
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.r[i].allFinite() && s.v[i].allFinite() && s.w[i].allFinite() && s.q[i].coeffs().allFinite() &&
          std::isfinite(s.t[i]))
        continue;
      throw NonFiniteState(fmt::format(
          "body {} has a non-finite state at t = {:.17g}: position [{:.17g}, {:.17g}, {:.17g}], "
          "orientation [{:.17g}, {:.17g}, {:.17g}, {:.17g}], velocity [{:.17g}, {:.17g}, {:.17g}], "
          "angular velocity [{:.17g}, {:.17g}, {:.17g}], time stamp {:.17g}", i, sim_.now(),
          s.r[i].x(), s.r[i].y(), s.r[i].z(), s.q[i].w(), s.q[i].x(), s.q[i].y(), s.q[i].z(),
          s.v[i].x(), s.v[i].y(), s.v[i].z(), s.w[i].x(), s.w[i].y(), s.w[i].z(), s.t[i]));
    }
  }

  void write_checkpoint() {
    fault_point("checkpoint");
    check_finite();  // a damaged state never replaces the last good checkpoint
    st_.pressure = pressure_.save();
    st_.corr = corr_.save();
    st_.gr = rdf_.save();
    st_.nematic = nem_.save();
    st_.temperatures = temps_.save();
    if (wall_pressure_) st_.wall_pressure = wall_pressure_->save();
    if (profiles_) st_.profiles = profiles_->save();
    {
      const AndersenThermostat& th = sim_.body_events().thermostat();
      st_.thermostat_next = th.next_times();
      st_.thermostat_count.assign(th.counts().begin(), th.counts().end());
    }
    if (partial_gr()) st_.gr_partial = gr_partial_.save();
    st_.corr_species.clear();
    for (const auto& c : corr_species_) st_.corr_species.push_back(c.save());
    if (st_.phase == 1) {
      const double c = cpu_seconds(), w = progress_.wall_seconds();
      st_.cpu_prev += c - cpu_mark_;
      st_.wall_prev += w - wall_mark_;
      cpu_mark_ = c;
      wall_mark_ = w;
    }
    gsd::write_frame_atomic(dir_ + "/checkpoint.gsd", make_checkpoint(sim_, cfg_.species, cfg_, st_));
    last_checkpoint_ = progress_.wall_seconds();
  }

 private:
  // Samples due at the current time (the loop stops exactly at each sampling time).
  void sample_observables() {
    const bool corr = cfg_.obs_interval > 0.0 && sim_.now() >= st_.next_corr;
    const bool gr = cfg_.gr_interval > 0.0 && sim_.now() >= st_.next_gr;
    if (!corr && !gr) return;
    const State s = synchronized_state(sim_);
    // Every due observer prepares its sample (the work; a stop request may interrupt it and
    // change nothing), then all commit (no throw): a checkpoint never holds half a sample.
    if (corr) {
      corr_.prepare(sim_.now(), s, sim_.box());
      for (std::size_t a = 0; a < corr_species_.size(); ++a)
        corr_species_[a].prepare(sim_.now(), species_subset(s, a), sim_.box());
    }
    if (gr) {
      rdf_.prepare(sim_.now(), s, sim_.box());
      if (partial_gr()) gr_partial_.prepare(sim_.now(), s, sim_.box(), rdf_.r_max_for(sim_.box(), s.size()));
    }
    if (corr) {
      corr_.commit();
      for (auto& c : corr_species_) c.commit();
      st_.next_corr += cfg_.obs_interval;
    }
    if (gr) {
      rdf_.commit();
      if (partial_gr()) gr_partial_.commit();
      st_.next_gr += cfg_.gr_interval;
    }
  }

  void housekeeping() {
    fault_point(st_.phase == 0 ? "equilibrate" : "measure");
    poll_interrupt();
    if (progress_.wall_seconds() - last_checkpoint_ >= cfg_.checkpoint_interval) write_checkpoint();
  }
  // End of the log block that starts at t0: one log interval later, or the end of the run. A
  // remainder within rounding of zero joins this block: intervals that are not exact in binary
  // (0.1) once left a last block of length ~1e-16 whose Z_block = 1 inflated Z_error.
  double log_block_end(double t0, double t_end) const {
    const double t = t0 + cfg_.log_interval;
    return t_end - t <= 1e-9 * cfg_.log_interval ? t_end : t;
  }
  bool partial_gr() const { return cfg_.species.size() > 1; }
  bool all_spheres() const {
    for (const Species& sp : cfg_.species)
      if (!std::holds_alternative<Sphere>(sp.shape)) return false;
    return true;
  }
  double energy() const { return ops_.kinetic(sim_.state()); }
  // translational temperature 2 K_trans / (3 N)
  double temperature() const { return ops_.temperature(sim_.state()); }
  // index of the species pair (a <= b) in st_.pair_collisions
  std::size_t pair_index(std::size_t a, std::size_t b) const {
    return species_pair_index(a, b, cfg_.species.size());
  }
  void count_pair(const CollisionRecord& r) {
    const State& s = sim_.state();
    st_.pair_collisions[pair_index(s.species[r.a], s.species[r.b])] += 1.0;
  }
  // One sample of SpeciesTemperatures from a synchronized state: per species the translational
  // temperature and I_k W_k^2 per principal axis (W the body-frame angular velocity).
  std::vector<double> species_temperatures(const State& st) const {
    const std::size_t ns = cfg_.species.size();
    std::vector<double> out(ns * SpeciesTemperatures::kValues, 0.0), n(ns, 0.0);
    for (std::size_t i = 0; i < st.size(); ++i) {
      const std::size_t a = st.species[i];
      const double sc = st.scale[i];
      n[a] += 1.0;
      out[4 * a] += ops_.body_mass(st, i) * st.v[i].squaredNorm() / 3.0;
      const Vec3 wb = st.q[i].conjugate() * st.w[i];  // body-frame angular velocity
      const Vec3 kr = (cfg_.species[a].inertia * std::pow(sc, 5)).cwiseProduct(wb.cwiseProduct(wb));
      for (int k = 0; k < 3; ++k) out[4 * a + 1 + k] += kr[k];
    }
    for (std::size_t a = 0; a < ns; ++a)
      for (std::size_t c = 0; c < 4; ++c) out[4 * a + c] /= std::max(n[a], 1.0);
    return out;
  }
  // summary.json "species": per species its resolved mass and inertia and its temperatures (means
  // over the log blocks of the measured run with block-averaged errors; the final state if no
  // block closed); "species_pairs": measured collision rate of a body of species a with bodies of
  // species b.
  void species_summary(nlohmann::json& j, const State& st, double measured_time) const {
    const std::size_t ns = cfg_.species.size();
    SpeciesTemperatures temps = temps_;
    if (temps.samples() == 0) temps.sample(species_temperatures(st));
    nlohmann::json list = nlohmann::json::array();
    for (std::size_t a = 0; a < ns; ++a) {
      const Species& sp = cfg_.species[a];
      nlohmann::json o;
      o["name"] = sp.name;
      o["count"] = sp.count;
      o["mass"] = sp.mass;
      o["inertia"] = {sp.inertia.x(), sp.inertia.y(), sp.inertia.z()};
      const MeanError tt = temps.get(a, 0);
      o["temperature_translational"] = tt.mean;
      o["temperature_translational_error"] = tt.error;
      if (std::holds_alternative<Sphere>(sp.shape)) {  // smooth spheres never exchange spin
        o["temperature_rotational"] = nullptr;
        o["temperature_rotational_axes"] = nullptr;
        o["temperature_rotational_axes_error"] = nullptr;
      } else {
        const MeanError rx = temps.get(a, 1), ry = temps.get(a, 2), rz = temps.get(a, 3);
        o["temperature_rotational"] = (rx.mean + ry.mean + rz.mean) / 3.0;
        o["temperature_rotational_axes"] = {rx.mean, ry.mean, rz.mean};
        o["temperature_rotational_axes_error"] = {rx.error, ry.error, rz.error};
      }
      if (sp.poly.active()) o["polydispersity"] = {{"width", sp.poly.width}};
      list.push_back(o);
    }
    j["species"] = list;
    nlohmann::json pairs = nlohmann::json::array();
    for (std::size_t a = 0; a < ns; ++a)
      for (std::size_t b = 0; b < ns; ++b) {
        // each a-b collision involves one body of a and one of b (two of a when a == b)
        const double c = st_.pair_collisions[pair_index(a, b)] * (a == b ? 2.0 : 1.0);
        pairs.push_back({{"a", cfg_.species[a].name}, {"b", cfg_.species[b].name}, {"collisions", st_.pair_collisions[pair_index(a, b)]},
                         {"collision_rate", measured_time > 0.0 ? c / (double(cfg_.species[a].count) * measured_time) : 0.0}});
      }
    j["species_pairs"] = pairs;
  }

  void finish(LogTable& log) {
    fault_point("final");
    const State st = synchronized_state(sim_);
    const std::uint64_t n = st.size();
    const double e1 = ops_.kinetic(st);
    const Vec3 p = ops_.momentum(st);
    const double p_scale = ops_.momentum_scale(st);
    const auto rep = ops_.overlaps(st, sim_.box());
    const std::uint64_t ncoll = sim_.collisions() - std::uint64_t(st_.coll0);
    const auto Z = pressure_.Z();
    const auto rate = pressure_.collision_rate();
    const double cpu = st_.cpu_prev, wall = st_.wall_prev;

    nlohmann::json j;
    j["particles"] = n;
    j["packing_fraction"] = body_volume(cfg_.species, st) / phi_volume(cfg_, sim_.box());
    j["box"] = {sim_.box().L.x(), sim_.box().L.y(), sim_.box().L.z()};
    if (cfg_.species.size() == 1) {
      j["shape"] = shape_to_json(cfg_.one().shape);
    } else {
      j["shape"] = nlohmann::json::array();
      for (const Species& sp : cfg_.species) j["shape"].push_back(shape_to_json(sp.shape));
    }
    j["time"] = pressure_.measured_time();
    j["collisions"] = ncoll;
    j["wall_seconds"] = wall;
    j["cpu_seconds"] = cpu;
    j["collisions_per_second"] = cpu > 0 ? double(ncoll) / cpu : 0.0;
    j["tau_c_us"] = ncoll > 0 ? 1e6 * cpu / double(ncoll) : 0.0;
    j["Z"] = Z.mean;
    j["Z_error"] = Z.error;  // NaN -> null: unknown (fewer than 2 log blocks)
    j["Z_blocks"] = Z.blocks;
    j["collision_rate"] = rate.mean;
    j["collision_rate_error"] = rate.error;
    species_summary(j, st, pressure_.measured_time());
    // The temperature of the measured stretch: the time average of the translational temperature
    // (one sample per log block; mixtures: the count-weighted mean of the species' averages, its
    // error combining theirs as independent); the instantaneous one of the final state beside it.
    {
      double t = 0.0, e2 = 0.0;
      for (const auto& sp : j["species"]) {
        const double w = double(sp["count"].get<std::size_t>()) / double(n);
        t += w * sp["temperature_translational"].get<double>();
        const auto& err = sp["temperature_translational_error"];
        e2 = err.is_number() && std::isfinite(e2) ? e2 + w * w * std::pow(err.get<double>(), 2)
                                                 : std::numeric_limits<double>::quiet_NaN();
      }
      j["temperature"] = t;
      j["temperature_error"] = std::sqrt(e2);  // NaN -> null: fewer than 2 log blocks
      j["temperature_final"] = ops_.temperature(st);
    }
    j["energy_drift"] = (e1 - st_.e0) / st_.e0;
    j["total_momentum"] = {p.x(), p.y(), p.z()};
    j["momentum_drift"] = p.norm() / p_scale;
    j["overlaps"] = rep.overlaps;
    j["min_distance"] = rep.min_distance;
    if (wall_pressure_) {
      const MeanError wp = wall_pressure_->pressure();
      j["wall_pressure"] = wp.mean;
      j["wall_pressure_error"] = wp.error;  // NaN -> null: fewer than 2 log blocks
      // the independent check of every snapshot and the final state: the support-function
      // distance of each body to each wall (> 0: through it)
      const double final_pen = wall_penetration(st);
      worst_wall_penetration_ = std::max(worst_wall_penetration_, final_pen);
      j["wall_penetrations"] = snapshot_wall_penetrations_ + (final_pen > 0.0 ? 1 : 0);
      j["max_wall_penetration"] = worst_wall_penetration_;
      // hard spheres of one size: the contact value of the centre density (the contact theorem
      // says beta P_wall = rho(sigma / 2) at a planar wall, rho(R - sigma / 2) (1 - sigma / 2R)^2
      // in a spherical container of radius R)
      if (const Sphere* sph = std::get_if<Sphere>(&cfg_.one().shape);
          sph && cfg_.species.size() == 1 && !cfg_.one().poly.active() && cfg_.boundaries.walls.any() &&
          profiles_->samples() > 0) {
        const int k = cfg_.boundaries.walls.planes[2] ? 2 : cfg_.boundaries.walls.planes[1] ? 1 : 0;
        const bool radial = cfg_.boundaries.walls.container();
        try {
          const ContactValue cv = contact_density(*profiles_, radial ? 'r' : "xyz"[k], sph->radius);
          j["wall_contact_density"] = cv.density;
          j["wall_contact_density_error"] = cv.error;
        } catch (const std::invalid_argument&) {  // too few bins beyond contact: not reported
        }
      }
      write_file_atomic(dir_ + "/density_profile.tsv", profiles_->to_tsv());
      if (profiles_->has_order()) write_file_atomic(dir_ + "/order_profile.tsv", profiles_->order_tsv());
    }
    if (cfg_.thermostat.active())
      j["thermostat"] = {{"type", "andersen"}, {"rate", cfg_.thermostat.rate},
                         {"during", cfg_.thermostat.during == ThermostatSpec::During::always ? "always" : "equilibration"}};
    nlohmann::json ev;
    const auto& events = sim_.event_counts();
    for (int k = 1; k < kEventTypes; ++k)
      if (events[k] > 0 || k == int(EventType::Collision))
        ev[event_name(EventType(k))] = double(events[k]) - st_.events0[k];
    ev["stale"] = double(sim_.stale_events()) - st_.stale0;
    ev["rescheduled"] = double(sim_.rescheduled_events()) - st_.rescheduled0;
    j["events"] = ev;
    j["solver_fallbacks"] = 0;
    if constexpr (requires { sim_.model().stats; }) {
      const SolverStats& ss = sim_.model().stats;
      j["solver_fallbacks"] = ss.fallbacks + ss.distance_fallbacks + ss.collision_distance_fallbacks;
      const double np = double(std::max<std::uint64_t>(ss.predictions, 1));
      j["solver"] = {{"contact_predictions", ss.predictions},
                     {"predictions_per_collision", double(ss.predictions) / double(std::max<std::uint64_t>(ncoll, 1))},
                     {"distance_evals_per_prediction", double(ss.distance_evals) / np},
                     {"distance_nr_iterations_per_eval",
                      double(ss.distance_nr_iterations) / double(std::max<std::uint64_t>(ss.distance_evals, 1))},
                     {"contact_nr_iterations", ss.contact_nr_iterations},
                     {"grazing_searches", ss.grazing_searches},
                     {"contact_fallbacks", ss.fallbacks},
                     {"distance_fallbacks", ss.distance_fallbacks},
                     {"collision_distance_fallbacks", ss.collision_distance_fallbacks},
                     {"grazing_separations", ss.grazing_separations},
                     {"note", "counts cover this session of the run (equilibration included; a resumed run counts from the resume)"}};
    }
    j["seed"] = cfg_.seed;
    j["neighbors"] = cfg_.neighbors_method;
    j["equilibrate_time"] = cfg_.equilibrate_time;
    j["trajectory_frames"] = st_.frames;
    j["snapshot_overlaps"] = snapshot_overlaps_;  // summed over this session's snapshots
    j["snapshot_min_distance"] = snapshot_min_gap_;
    if constexpr (requires { sim_.neighbors().truncated_searches(); })
      j["nnl_escape_searches_truncated"] = sim_.neighbors().truncated_searches();
    if constexpr (requires { sim_.neighbors().window_ends(); })  // in events.nnl_rebuild, box kept
      j["nnl_window_ends"] = sim_.neighbors().window_ends();
    if (cfg_.obs_interval > 0.0) {
      const auto fit = corr_.diffusion();
      if (fit.points > 0) {
        j["diffusion_coefficient"] = fit.D;
        j["diffusion_fit_range"] = {fit.t_from, fit.t_to};
      }
      write_file_atomic(dir_ + "/correlations.tsv", corr_.to_tsv());
      for (std::size_t a = 0; a < corr_species_.size(); ++a) {
        const auto fa = corr_species_[a].diffusion();
        if (fa.points > 0) j["species"][a]["diffusion_coefficient"] = fa.D;
        write_file_atomic(dir_ + "/correlations_" + cfg_.species[a].name + ".tsv", corr_species_[a].to_tsv());
      }
    }
    if (cfg_.gr_interval > 0.0) write_file_atomic(dir_ + "/gr.tsv", rdf_.to_tsv());
    if (cfg_.gr_interval > 0.0 && partial_gr()) {
      std::vector<std::string> names;
      for (const Species& sp : cfg_.species) names.push_back(sp.name);
      write_file_atomic(dir_ + "/gr_partial.tsv", gr_partial_.to_tsv(names));
    }
    if (!all_spheres()) write_file_atomic(dir_ + "/nematic.tsv", nem_.to_tsv());  // spheres: S2 = 1
    if (!Z.error_known())
      j["notes"].push_back(fmt::format(
          "Z_error, collision_rate_error and the temperature errors are null (unknown): the "
          "measured run has {} log block(s), the block error needs at least 2 (run.time / "
          "output.log_interval >= 2)", Z.blocks));
    for (const auto& [k, v] : extra_.items()) j[k] = v;
    log.commit();
    fault_point("summary");
    write_file_atomic(dir_ + "/summary.json", j.dump(2) + "\n");
    if (!opt_.quiet)
      std::fprintf(stderr, "hardbody: %s: t=%.6g collisions=%llu Z=%.5f +- %s overlaps=%llu -> %s\n",
                   cfg_.source.c_str(), pressure_.measured_time(), (unsigned long long)ncoll, Z.mean,
                   Z.error_known() ? fmt::format("{:.5f}", Z.error).c_str()
                                   : "unknown (fewer than 2 log blocks)",
                   (unsigned long long)rep.overlaps, dir_.c_str());
    if (rep.overlaps > 0 || snapshot_overlaps_ > 0)
      throw RunFailure(fmt::format("{} overlapping pairs in the final state (min gap {:.3g}), {} in snapshots",
                                   rep.overlaps, rep.min_distance, snapshot_overlaps_));
  }

  const Config& cfg_;
  const RunOptions& opt_;
  std::string dir_;
  Sim& sim_;
  DriverState st_;
  const SystemOps& ops_;
  nlohmann::json extra_;  // merged into summary.json
  VirialPressure pressure_;
  TimeCorrelations corr_;
  RadialDistribution rdf_;
  PartialRadialDistribution gr_partial_;  // mixtures: g_ab(r)
  std::vector<TimeCorrelations> corr_species_;  // mixtures: MSD, C2, F_self per species
  NematicOrder nem_;
  SpeciesTemperatures temps_;  // per species and axis, one sample per log block
  Progress progress_;
  double cpu_mark_ = 0.0, wall_mark_ = 0.0, last_checkpoint_ = 0.0;
  std::uint64_t snapshot_overlaps_ = 0;
  double snapshot_min_gap_ = kInf;
  std::optional<WallPressure> wall_pressure_;  // with walls
  std::optional<DensityProfiles> profiles_;    // with walls
  std::uint64_t snapshot_wall_penetrations_ = 0;
  double worst_wall_penetration_ = -kInf;

  // The deepest penetration of a body into a wall in a synchronised state (support-function
  // distance, > 0 through the wall; -inf without walls).
  double wall_penetration(const State& s) const {
    double worst = -kInf;
    if constexpr (requires { Sim::model_type::kBodyEvents; }) {
      const Box& box = sim_.box();
      for (std::uint32_t i = 0; i < s.size(); ++i)
        sim_.model().visit_body(s, i, sim_.now(), [&](const auto& shape, const MassProperties&, const BodyGrowth& g, double) {
          if (const SphericalContainer& c = sim_.body_events().container(); c.active()) {
            worst = std::max(worst, -c.distance(shape, s.body(i), g.s, box));
            return;
          }
          for (int f = 0; f < 6; ++f)
            if (!box.periodic[f >> 1])
              worst = std::max(worst, -PlanarWalls::distance(shape, s.body(i), g.s, box, f));
        });
    }
    return worst;
  }
};

// Writes the checkpoint of a stopping run and says what happened to it (a failed write, e.g. a
// full disk, leaves the previous checkpoint as it was: files are written to a temporary name and
// renamed).
template <class D>
std::string checkpoint_outcome(D& d, const std::string& dir, const std::string& failure = "") {
  try {
    d.write_checkpoint();
    return fmt::format("checkpoint written to {}/checkpoint.gsd", dir);
  } catch (const std::exception& w) {
    const std::string why = w.what() == failure ? std::string("the same error") : std::string(w.what());
    return fmt::format("checkpoint NOT written: {}; the previous checkpoint in {} is intact", why, dir);
  }
}

template <class Sim>
void drive(const Config& cfg, const RunOptions& opt, const std::string& dir, Sim& sim,
           const DriverState& st, const SystemOps& ops, nlohmann::json extra) {
  Driver<Sim> d(cfg, opt, dir, sim, st, ops, std::move(extra));
  try {
    d.run();
  } catch (const Interrupted& e) {
    throw RunInterrupted(fmt::format("interrupted by signal {}; {} (continue with --resume)", e.signal,
                                     checkpoint_outcome(d, dir)), e.signal);
  } catch (const ConfigError&) {
    throw;
  } catch (const InputError&) {
    throw;
  } catch (const NonFiniteState& e) {
    throw RunFailure(fmt::format("{} (checkpoint NOT written: the previous checkpoint in {} is intact)",
                                 e.what(), dir));
  } catch (const std::exception& e) {
    throw RunFailure(fmt::format("{} ({})", e.what(), checkpoint_outcome(d, dir, e.what())));
  }
}

// summary.json "init": how the initial bodies were made.
nlohmann::json init_json(const StartInfo& i) {
  nlohmann::json j;
  if (i.method != "grow") {
    j = {{"method", i.method}};
  } else {
    const GrowthResult& g = i.result;
    j = {{"method", "grow"}, {"placement", i.placement}, {"phi0", i.growth.phi0},
         {"growth_rate", i.growth.rate}, {"growth_time", g.time}, {"growth_collisions", g.collisions},
         {"growth_wall_seconds", g.wall_seconds}, {"growth_velocity_rescales", g.rescales},
         {"min_distance_after_growth", g.overlaps.min_distance}};
  }
  if (!i.note.empty()) j["note"] = i.note;
  return j;
}

// init.method = "file": the bodies of a GSD frame, which must be the config's system (N, species
// counts, packing fraction); positions, orientations, velocities and spins as in the file.
Start start_from_file(const Config& cfg) {
  Start s;
  const long frame = cfg.init_frame == kLastFrame ? -1L : static_cast<long>(cfg.init_frame);
  s.state = state_from_gsd(cfg.init_file, frame, s.box);  // InputError naming the file
  const std::string where = fmt::format("{}: key 'init.file': {}", cfg.source, cfg.init_file);
  if (s.state.size() != cfg.particles)
    throw InputError(fmt::format("{} holds {} bodies, the config {}", where, s.state.size(), cfg.particles));
  std::vector<std::uint64_t> count(cfg.species.size(), 0);
  for (std::size_t i = 0; i < s.state.size(); ++i) {
    if (s.state.species[i] >= cfg.species.size())
      throw InputError(fmt::format("{}: body {} has type id {}, the config has {} species", where, i,
                                   s.state.species[i], cfg.species.size()));
    ++count[s.state.species[i]];
  }
  for (std::size_t a = 0; a < cfg.species.size(); ++a)
    if (count[a] != cfg.species[a].count)
      throw InputError(fmt::format("{} holds {} bodies of species {} ('{}'), the config {}", where, count[a], a,
                                   cfg.species[a].name, cfg.species[a].count));
  const double phi = body_volume(cfg.species, s.state) / phi_volume(cfg, s.box);
  if (!(std::abs(phi - cfg.packing_fraction) <= 1e-9 * cfg.packing_fraction))
    throw InputError(fmt::format("{}: its packing fraction is {:.17g}, system.packing_fraction is {}; set "
                                 "system.packing_fraction = {:.17g}", where, phi, cfg.packing_fraction, phi));
  s.info.method = "file";
  s.info.note = fmt::format("{} frame {}", cfg.init_file, frame < 0 ? std::string("last") : std::to_string(frame));
  return s;
}

// The assembly's start (a lattice, or a growth with a progress line and the jam test). A jammed
// growth is bad input (exit 2: the target cannot be reached); a stop request during it exits
// 128 + signal (the growth has no checkpoint: --resume starts it again).
template <class A>
Start make_start(const Config& cfg, const RunOptions& opt, const std::string& dir, const A& as) {
  Progress progress;
  StartOptions so{opt.quiet, {}};
  GrowthStatus last;
  bool grew = false;
  auto show = [&](const GrowthStatus& g, bool force) {
    progress.update_text("grow", fmt::format("t={:.4g} phi={:.5f} -> {:.5g} free path={:.3g}", g.time, g.phi,
                                             cfg.packing_fraction, g.free_path),
                         g.collisions, g.fraction, force);
  };
  if (!opt.quiet)
    so.growth_report = [&](const GrowthStatus& g) {
      last = g, grew = true;
      show(g, false);
    };
  auto done = [&] {  // the last growth line is always shown
    if (opt.quiet) return;
    if (grew) show(last, true);
    progress.finish();
  };
  if (cfg.init_method == "file") return start_from_file(cfg);
  try {
    Start s = as.start(so);
    done();
    return s;
  } catch (const GrowthJammed& e) {
    done();
    if (cfg.boundaries.walls.container())  // the container's radius sets phi: name it
      throw InputError(fmt::format("{}: key 'walls.sphere': a container of radius {} holds the {} bodies at "
                                   "phi = {:.6g}, which cannot be reached: {}; ask for a larger container, or "
                                   "grow more slowly (init.growth_rate)",
                                   cfg.source, cfg.boundaries.walls.sphere_radius, cfg.particles,
                                   cfg.packing_fraction, e.what()));
    throw InputError(fmt::format("{}: key 'system.packing_fraction': {} cannot be reached: {}; ask for a "
                                 "lower packing fraction, or grow more slowly (init.growth_rate)",
                                 cfg.source, cfg.packing_fraction, e.what()));
  } catch (const GrowthFailed& e) {
    done();
    // no checkpoint exists in the growth: the bodies at the failure go to a frame for inspection
    std::string saved;
    try {
      gsd::write_frame_atomic(dir + "/growth-failure.gsd",
                              ckpt::frame_source(e.state, e.box, e.time, 0, cfg.species));
      saved = fmt::format("the bodies at the failure are in {}/growth-failure.gsd", dir);
    } catch (const std::exception& w) {
      saved = fmt::format("the bodies at the failure could not be written ({})", w.what());
    }
    throw RunFailure(fmt::format("{}; {} (the growth has no checkpoint: --resume starts it again)",
                                 e.what(), saved));
  } catch (const Interrupted& e) {
    done();
    throw RunInterrupted(fmt::format("interrupted by signal {} during the start (growth); no checkpoint "
                                     "exists yet: --resume starts the run again in {}", e.signal, dir),
                         e.signal);
  }
}

// Starts a new run from the assembly's start, or resumes from the checkpoint (a finished run is
// left alone, or extended when run.time or run.max_collisions grew).
template <class A>
void start_or_resume_in(const Config& cfg, const RunOptions& opt, const std::string& dir, const A& as) {
  if (opt.resume) {
    const std::string ck = dir + "/checkpoint.gsd";
    if (!file_exists(ck)) {
      const std::string marker = dir + "/config.resolved.toml";
      if (!file_exists(marker)) throw InputError(fmt::format("{}: no checkpoint to resume from", ck));
      // stopped before its first checkpoint (during the start): start again with the same config
      std::ostringstream text;
      text << std::ifstream(marker).rdbuf();
      if (text.str() != to_toml(cfg))
        throw InputError(fmt::format("{}: the run stopped before its first checkpoint with another "
                                     "config ({}); start it again with --overwrite", dir, marker));
      if (!opt.quiet)
        std::fprintf(stderr, "hardbody: %s: no checkpoint yet (stopped during the start); starting again\n", dir.c_str());
      std::error_code ec;
      std::filesystem::remove(dir + "/growth-failure.gsd", ec);  // of the failed start, if any
      RunOptions fresh = opt;
      fresh.resume = false;
      start_or_resume_in(cfg, fresh, dir, as);
      return;
    }
    auto r = read_checkpoint<typename A::neighbors_type>(ck, cfg);
    r.box.periodic = box_for(cfg).periodic;  // the walls are the config's
    std::optional<AndersenThermostat> th;
    if (cfg.thermostat.active()) {
      th.emplace(as.body_events().thermostat());
      std::vector<std::uint64_t> counts(r.driver.thermostat_count.begin(), r.driver.thermostat_count.end());
      if (r.driver.thermostat_next.size() == r.state.size()) th->restore(r.driver.thermostat_next, counts);
      if (r.driver.phase >= 1 && cfg.thermostat.during == ThermostatSpec::During::equilibration) th->set_on(false);
    }
    auto sim = as.restore(r.box, std::move(r.state), r.neighbors, r.loop, th ? &*th : nullptr);
    check_restored(sim, as.ops(), ck);
    const double t_ck = sim.now() - cfg.equilibrate_time;  // measured time reached
    if (r.driver.phase >= 1 && t_ck > cfg.time)
      throw InputError(fmt::format("{}: run.time = {} ends before the checkpoint's t = {:.10g}; a resume "
                                   "may only extend a run", cfg.source, cfg.time, t_ck));
    if (r.driver.phase >= 1 && cfg.max_collisions &&
        double(sim.collisions()) - r.driver.coll0 > double(cfg.max_collisions))
      throw InputError(fmt::format("{}: run.max_collisions = {} is below the {} collisions the checkpoint "
                                   "has measured; a resume may only extend a run", cfg.source,
                                   cfg.max_collisions, double(sim.collisions()) - r.driver.coll0));
    if (run_finished(sim, cfg, r.driver) && file_exists(dir + "/summary.json")) {
      std::fprintf(stderr,
                   "hardbody: %s: the run is finished (summary.json, t = %.10g); nothing to do. To "
                   "extend it: --resume --set run.time=T with T > %.10g\n",
                   dir.c_str(), t_ck, t_ck);
      return;
    }
    const bool grown = cfg.mixture() || (cfg.init_method == "grow" && cfg.packing_fraction > cfg.init_phi0);
    const char* method = cfg.init_method == "file" ? "file" : grown ? "grow" : "lattice";
    drive(cfg, opt, dir, sim, r.driver, as.ops(), {{"init", {{"method", method}}}});
    return;
  }
  // config.resolved.toml marks the directory as this run's before the start is made: a run
  // stopped during its growth (no checkpoint yet) is resumed by starting again (the start is a
  // function of the config).
  write_file_atomic(dir + "/config.resolved.toml", to_toml(cfg));
  Start start = make_start(cfg, opt, dir, as);
  start.box.periodic = box_for(cfg).periodic;  // the walls are the config's (a file start too)
  auto sim = as.simulate(start.box, std::move(start.state));
  {
    const auto rep = as.ops().overlaps(sim.state(), sim.box());
    if (rep.overlaps > 0)
      throw InputError(fmt::format("{}: the initial configuration has {} overlapping pairs",
                                   cfg.source, rep.overlaps));
  }
  drive(cfg, opt, dir, sim, DriverState{}, as.ops(), {{"init", init_json(start.info)}});
}

template <class A>
void start_or_resume(const Config& cfg, const RunOptions& opt, const std::string& dir, const A& as) {
  const SignalGuard guard;
  RunDirectory rd(dir, opt.resume, opt.overwrite);  // checked and locked before any work
  // Bad input found before the first checkpoint leaves nothing behind (the marker written before
  // the start included).
  auto discard = [&] {
    std::error_code ec;
    if (!opt.resume && !file_exists(dir + "/checkpoint.gsd"))
      std::filesystem::remove(dir + "/config.resolved.toml", ec);
    rd.discard_if_unused();
  };
  try {
    start_or_resume_in(cfg, opt, dir, as);
    // a stop request that arrived during the final outputs: they are complete, but the caller
    // asked to stop and hears so (a campaign's --resume then finds the run finished)
    if (const int sig = pending_signal())
      throw RunInterrupted(fmt::format("interrupted by signal {} as the run finished; its outputs in {} are "
                                       "complete (--resume has nothing to do)", sig, dir), sig);
  } catch (const InputError&) {
    discard();
    throw;
  } catch (const ConfigError&) {
    discard();
    throw;
  } catch (const std::invalid_argument&) {
    discard();
    throw;
  }
}

}  // namespace

void run_simulation(const RunOptions& opt) {
  const Config cfg = load_config(opt.config_path, opt.overrides);
  const std::string dir = opt.out_dir.empty() && !opt.out_given ? default_out_dir(opt.config_path) : opt.out_dir;
  try {
    // Everything is checked (by the builder) before any file is written.
    assemble(cfg, [&](const auto& as) { start_or_resume(cfg, opt, dir, as); });
  } catch (const std::filesystem::filesystem_error& e) {
    throw InputError(e.what());
  } catch (const std::invalid_argument& e) {
    throw InputError(fmt::format("{}: {}", cfg.source, e.what()));
  }
}

}  // namespace hb
