#include "io/checkpoint.hpp"

#include <cmath>

#include "io/shape_io.hpp"
#include "shapes/codec.hpp"

namespace hb::ckpt {

namespace {
constexpr const char* P = "particles/hardbody/";
std::string key(const char* k) { return std::string(P) + k; }
}  // namespace

static_assert(sizeof(Vec3) == 3 * sizeof(double) && sizeof(Eigen::Vector3i) == 3 * sizeof(int) &&
                  sizeof(std::array<int, 3>) == 3 * sizeof(std::int32_t),
              "vectors of these types are written as N x 3 arrays in place");

// Views of per-body arrays (no copy).
gsd::ChunkSource view(const std::vector<Vec3>& v) {
  return gsd::ChunkSource{gsd::Type::float64, v.size(), 3, v.empty() ? nullptr : v.data(), {}, {}};
}
gsd::ChunkSource view(const std::vector<double>& v) { return gsd::memory_source(v, 1); }
// The same of State's hot fields (one record per body, so read row by row). The field, like the
// State it belongs to, must outlive the frame's writing.
template <Vec3 HotRecord::*M>
gsd::ChunkSource view(const HotField<Vec3, M>& v) {
  return gsd::row_source<double>(v.size(), 3, [&v](std::uint64_t i, double* o) {
    o[0] = v[i].x(), o[1] = v[i].y(), o[2] = v[i].z();
  });
}
template <double HotRecord::*M>
gsd::ChunkSource view(const HotField<double, M>& v) {
  return gsd::row_source<double>(v.size(), 1, [&v](std::uint64_t i, double* o) { *o = v[i]; });
}
template <Quat HotRecord::*M>
gsd::ChunkSource quat_rows(const HotField<Quat, M>& q) {
  return gsd::row_source<double>(q.size(), 4, [&q](std::uint64_t i, double* o) {
    o[0] = q[i].w(), o[1] = q[i].x(), o[2] = q[i].y(), o[3] = q[i].z();
  });
}
// A record of the driver: 1 x n doubles (a GSD chunk needs a value: empty is stored as {0}).
gsd::ChunkSource record(const std::vector<double>& v) {
  gsd::LogArray a{1, static_cast<std::uint32_t>(std::max<std::size_t>(v.size(), 1)),
                  v.empty() ? std::vector<double>{0.0} : v};
  return gsd::owned_source(std::move(a));
}
// Events of the calendar: time, partner, partner count, type (all as doubles, exact).
gsd::ChunkSource event_rows(std::shared_ptr<const LoopSnapshot> loop,
                            const std::vector<Event> LoopSnapshot::*which) {
  const std::vector<Event>& e = (*loop).*which;
  return gsd::row_source<double>(e.size(), 4, [&e, loop](std::uint64_t i, double* o) {
    o[0] = e[i].time, o[1] = double(e[i].partner), o[2] = double(e[i].partner_count);
    o[3] = double(int(e[i].type));
  });
}

// Body i at `now`: what State::advance_to and Box::wrap make of it in synchronized_state.
struct Synced {
  Vec3 r;
  Quat q;
  Vec3 w;
  Eigen::Vector3i image;
};
Synced synced(const State& s, std::size_t i, double now, const Box& box, bool rotation) {
  Synced b{s.r[i], s.q[i], s.w[i], s.image[i]};
  const double dt = now - s.t[i];
  if (dt != 0.0) {
    b.r += s.v[i] * dt;
    if (rotation && b.w.squaredNorm() != 0.0) {
      if (spherical_top(s.top(i))) b.q = orientation_at(BodyState{b.r, b.q, s.v[i], b.w}, dt);
      else s.free_rotation(i).evaluate(dt, b.q, b.w);
    }
  }
  b.image += box.wrap(b.r);
  return b;
}

// The keys a checkpoint must agree on with the config that resumes it; the shape's part is its
// type (registry index) and the parameters of its codec entry.
ConfigSignature config_signature(const Config& c) {
  struct W final : ParamWriter {
    ConfigSignature sig;
    void add(std::string name, double v) {
      sig.names.push_back(std::move(name));
      sig.values.push_back(v);
    }
    std::string prefix;
    void number(std::string_view k, double v) override { add(fmt::format("{}{}", prefix, k), v); }
    void triple(std::string_view k, const Vec3& v) override {
      for (int i = 0; i < 3; ++i) add(fmt::format("{}{}[{}]", prefix, k, i), v[i]);
    }
  } w;
  w.add("system.particles", double(c.particles));
  w.add("system.packing_fraction", c.packing_fraction);
  w.add("system.seed", double(c.seed));
  w.add("system.temperature", c.temperature);
  w.add("species", double(c.species.size()));
  for (std::size_t k = 0; k < c.species.size(); ++k) {
    const Species& sp = c.species[k];
    const std::string p = c.species_given ? fmt::format("species[{}].", k) : "";
    w.prefix = p + "shape.";
    w.add(p + "count", double(sp.count));
    w.add(p + "shape.type", double(sp.shape.index()));
    encode_shape(sp.shape, w);
    w.add(p + "mass", sp.mass);
    for (int i = 0; i < 3; ++i) w.add(fmt::format("{}inertia[{}]", p, i), sp.inertia[i]);
    w.add(p + "polydispersity.distribution", double(int(sp.poly.distribution)));
    w.add(p + "polydispersity.width", sp.poly.width);
  }
  w.add("neighbors.method", c.neighbors_method == "cells" ? 0 : 1);
  w.add("neighbors.shell", c.shell);
  w.add("solver.eps_d", c.eps_d);
  for (int k = 0; k < 3; ++k) w.add(fmt::format("box.aspect[{}]", k), c.boundaries.aspect[k]);
  for (int k = 0; k < 3; ++k) w.add(fmt::format("walls.planes[{}]", k), c.boundaries.walls.planes[k] ? 1.0 : 0.0);
  w.add("walls.sphere", c.boundaries.walls.sphere_radius);
  w.add("thermostat.type", double(int(c.thermostat.type)));
  w.add("thermostat.rate", c.thermostat.rate);
  w.add("thermostat.during", double(int(c.thermostat.during)));
  // The keys that shape the measured stretch and its summary: a resume that changed one would
  // describe a different run (run.time and run.max_collisions may grow: that extends the run).
  w.add("run.equilibrate_time", c.equilibrate_time);
  w.add("output.log_interval", c.log_interval);
  w.add("output.snapshot_interval", c.snapshot_interval);
  w.add("output.trajectory", c.trajectory ? 1.0 : 0.0);
  w.add("observables.interval", c.obs_interval);
  w.add("observables.origin_every", double(c.obs_origin_every));
  w.add("observables.max_lag", c.obs_max_lag);
  w.add("observables.q", c.obs_q);
  w.add("observables.q_vectors", double(c.obs_q_vectors));
  w.add("observables.gr_interval", c.gr_interval);
  w.add("observables.gr_bins", double(c.gr_bins));
  return std::move(w.sig);
}

gsd::FrameSource frame_source(const State& s, const Box& box, double now, std::uint64_t step,
                              const SpeciesTable& species) {
  using gsd::row_source;
  const std::size_t n = s.size();
  const State* S = &s;
  gsd::FrameSource f;
  f.step = step;
  f.N = static_cast<std::uint32_t>(n);
  f.box = {float(box.L.x()), float(box.L.y()), float(box.L.z()), 0, 0, 0};
  // HOOMD boxes are centred on the origin; the engine's box is [0, L).
  f.position = row_source<float>(n, 3, [S, box, now](std::uint64_t i, float* o) {
    const Vec3 r = synced(*S, i, now, box, false).r;
    for (int k = 0; k < 3; ++k) o[k] = float(r[k] - 0.5 * box.L[k]);
  });
  f.orientation = row_source<float>(n, 4, [S, box, now](std::uint64_t i, float* o) {
    const Quat q = synced(*S, i, now, box, true).q;
    o[0] = float(q.w()), o[1] = float(q.x()), o[2] = float(q.y()), o[3] = float(q.z());
  });
  f.velocity = row_source<float>(n, 3, [S](std::uint64_t i, float* o) {
    for (int k = 0; k < 3; ++k) o[k] = float(S->v[i][k]);
  });
  f.image = row_source<std::int32_t>(n, 3, [S, box, now](std::uint64_t i, std::int32_t* o) {
    const Eigen::Vector3i m = synced(*S, i, now, box, false).image;
    for (int k = 0; k < 3; ++k) o[k] = m[k];
  });
  f.type_id = row_source<std::uint32_t>(n, 1, [S](std::uint64_t i, std::uint32_t* o) {
    *o = S->species[i];
  });
  std::vector<double> bounding;
  for (const Species& sp : species) {
    f.types.push_back(sp.name);
    f.type_shapes.push_back(gsd_type_shape(sp.shape));
    bounding.push_back(bounding_radius(sp.shape));
  }
  f.diameter = row_source<float>(n, 1, [S, bounding](std::uint64_t i, float* o) {
    *o = float(2.0 * bounding[S->species[i]] * S->scale[i]);
  });
  // Exact state in the engine's frame [0, L) (box_origin 0), for analysis and conversion.
  f.log[key("position_double")] = row_source<double>(n, 3, [S, box, now](std::uint64_t i, double* o) {
    const Vec3 r = synced(*S, i, now, box, false).r;
    o[0] = r.x(), o[1] = r.y(), o[2] = r.z();
  });
  f.log[key("orientation_double")] = row_source<double>(n, 4, [S, box, now](std::uint64_t i, double* o) {
    const Quat q = synced(*S, i, now, box, true).q;
    o[0] = q.w(), o[1] = q.x(), o[2] = q.y(), o[3] = q.z();
  });
  f.log[key("velocity_double")] = view(s.v);
  f.log[key("angular_velocity_double")] = row_source<double>(n, 3, [S, box, now](std::uint64_t i, double* o) {
    const Vec3 w = synced(*S, i, now, box, true).w;
    o[0] = w.x(), o[1] = w.y(), o[2] = w.z();
  });
  f.log[key("scale")] = view(s.scale);
  f.log["hardbody/time"] = record({now});
  f.log["hardbody/box_origin"] = record({0.0, 0.0, 0.0});
  f.log["hardbody/box_double"] = record({box.L.x(), box.L.y(), box.L.z(), 0.0, 0.0, 0.0});
  return f;
}

void add_checkpoint_sources(gsd::FrameSource& f, const State& s, LoopSnapshot loop_snapshot,
                            const DriverState& d, const Config& c) {
  const auto loop = std::make_shared<const LoopSnapshot>(std::move(loop_snapshot));
  f.log[key("state_r")] = view(s.r);
  f.log[key("state_v")] = view(s.v);
  f.log[key("state_q")] = quat_rows(s.q);
  f.log[key("state_w")] = view(s.w);
  f.log[key("state_t")] = view(s.t);
  // Integers as such (readers convert every numeric log chunk to double exactly).
  f.log[key("state_count")] = gsd::memory_source(s.count, 1);
  f.log[key("state_image")] = gsd::ChunkSource{gsd::Type::int32, s.image.size(), 3,
                                               s.image.empty() ? nullptr : s.image.data(), {}, {}};
  f.log[key("calendar")] = event_rows(loop, &LoopSnapshot::slot);
  f.log[key("best")] = event_rows(loop, &LoopSnapshot::best);
  std::vector<double> l{loop->now, double(loop->stale)};
  for (auto x : loop->counts) l.push_back(double(x));
  l.push_back(double(loop->rescheduled));
  f.log["hardbody/loop"] = record(l);
  std::vector<double> dr{double(d.phase), d.e0, d.coll0, d.stale0, double(d.log_rows),
                         double(d.frames), d.next_snapshot, d.block_start, d.cpu_prev, d.wall_prev,
                         d.next_corr, d.next_gr, d.rescheduled0};
  dr.insert(dr.end(), d.events0.begin(), d.events0.end());
  f.log["hardbody/driver"] = record(dr);
  f.log["hardbody/pressure"] = record(d.pressure);
  f.log["hardbody/obs_correlations"] = record(d.corr);
  f.log["hardbody/obs_gr"] = record(d.gr);
  f.log["hardbody/obs_nematic"] = record(d.nematic);
  f.log["hardbody/pair_collisions"] = record(d.pair_collisions);
  f.log["hardbody/obs_gr_partial"] = record(d.gr_partial);
  f.log["hardbody/obs_temperatures"] = record(d.temperatures);
  f.log["hardbody/obs_wall_pressure"] = record(d.wall_pressure);
  f.log["hardbody/obs_profiles"] = record(d.profiles);
  f.log["hardbody/thermostat_next"] = record(d.thermostat_next);
  f.log["hardbody/thermostat_count"] = record(d.thermostat_count);
  for (std::size_t a = 0; a < d.corr_species.size(); ++a)
    f.log[fmt::format("hardbody/obs_correlations_species{}", a)] = record(d.corr_species[a]);
  f.log["hardbody/config"] = record(config_signature(c).values);
}

gsd::ChunkSource memo_rows(const AxisMemo& m) {
  return gsd::row_source<double>(m.size(), 4, [&m](std::uint64_t k, double* o) {
    const AxisMemo::Row r = m.row(k);
    std::copy(r.begin(), r.end(), o);
  });
}

gsd::ChunkSource encode(std::vector<std::array<int, 3>> c) {
  auto keep = std::make_shared<const std::vector<std::array<int, 3>>>(std::move(c));
  return gsd::ChunkSource{gsd::Type::int32, keep->size(), 3, keep->empty() ? nullptr : keep->data(),
                          {}, keep};
}
gsd::ChunkSource encode(std::vector<Vec3> c) {
  auto keep = std::make_shared<const std::vector<Vec3>>(std::move(c));
  gsd::ChunkSource s = view(*keep);
  s.owner = std::move(keep);
  return s;
}
gsd::ChunkSource encode(ObbSnapshot c) {
  const auto sn = std::make_shared<const ObbSnapshot>(std::move(c));
  return gsd::row_source<double>(sn->centre.size(), 10, [sn](std::uint64_t i, double* o) {
    const Vec3 &x = sn->centre[i], &h = sn->half[i];
    const Quat& q = sn->q[i];
    const double v[10] = {x.x(), x.y(), x.z(), q.w(), q.x(), q.y(), q.z(), h.x(), h.y(), h.z()};
    std::copy(v, v + 10, o);
  });
}

const gsd::LogArray& Reader::get(const std::string& k, std::uint64_t rows, std::uint32_t cols) const {
  auto it = f.log.find(k);
  if (it == f.log.end())
    throw InputError(fmt::format("{}: not a hardbody checkpoint (chunk log/{} missing)", path, k));
  if ((rows && it->second.rows != rows) || (cols && it->second.cols != cols) ||
      it->second.values.size() != it->second.rows * it->second.cols)
    throw InputError(fmt::format("{}: chunk log/{} has shape {}x{}, expected {}x{}", path, k,
                                 it->second.rows, it->second.cols, rows, cols));
  return it->second;
}
std::vector<Vec3> Reader::vec3s(const std::string& k, std::uint64_t n) const {
  const auto& a = get(k, n, 3);
  std::vector<Vec3> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = Vec3(a.values[3 * i], a.values[3 * i + 1], a.values[3 * i + 2]);
  return v;
}
std::vector<Quat> Reader::quats(const std::string& k, std::uint64_t n) const {
  const auto& a = get(k, n, 4);
  std::vector<Quat> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = Quat(a.values[4 * i], a.values[4 * i + 1], a.values[4 * i + 2], a.values[4 * i + 3]);
  return v;
}
std::vector<Event> Reader::events(const std::string& k, std::uint64_t n) const {
  const auto& a = get(k, n, 4);
  std::vector<Event> v(n);
  for (std::size_t i = 0; i < n; ++i) {
    v[i].time = a.values[4 * i];
    v[i].owner = static_cast<std::uint32_t>(i);
    v[i].partner = static_cast<std::uint32_t>(a.values[4 * i + 1]);
    v[i].partner_count = static_cast<std::uint32_t>(a.values[4 * i + 2]);
    const int t = static_cast<int>(a.values[4 * i + 3]);
    if (t < 0 || t >= kEventTypes) throw InputError(fmt::format("{}: corrupt event record", path));
    v[i].type = EventType(t);
    if (v[i].type == EventType::Collision && v[i].partner >= n)
      throw InputError(fmt::format("{}: corrupt event record (partner {})", path, v[i].partner));
  }
  return v;
}
std::vector<double> Reader::row(const std::string& k) const { return get(k, 1, 0).values; }

Reader open(const std::string& path, const Config& c) {
  Reader r;
  r.path = path;
  try {
    r.f = gsd::read_last_frame(path);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  const auto sig = r.row("hardbody/config");
  const ConfigSignature want = config_signature(c);
  if (sig.size() != want.values.size())
    throw InputError(fmt::format("{}: checkpoint from an incompatible hardbody version (its config "
                                 "record has {} keys, this version writes {})",
                                 path, sig.size(), want.values.size()));
  std::string changed;  // every key that differs, not only the first
  for (std::size_t k = 0; k < sig.size(); ++k)
    if (sig[k] != want.values[k])
      changed += fmt::format("{}{} = {} there, {} now", changed.empty() ? "" : "; ", want.names[k],
                             sig[k], want.values[k]);
  if (!changed.empty())
    throw InputError(fmt::format(
        "{}: checkpoint was written with a different configuration ({}; config {}); a resume "
        "may only extend run.time or run.max_collisions", path, changed, c.source));
  if (r.f.N != c.particles)
    throw InputError(fmt::format("{}: checkpoint has {} particles, config {}", path, r.f.N, c.particles));
  return r;
}

void read_core(const Reader& r, Box& box, State& s, LoopSnapshot& loop, DriverState& d) {
  const std::uint64_t n = r.f.N;
  const auto b = r.row("hardbody/box_double");
  if (b.size() != 6) throw InputError(fmt::format("{}: bad box record", r.path));
  box.L = Vec3(b[0], b[1], b[2]);
  s.resize(n);
  s.r = r.vec3s(key("state_r"), n);
  s.v = r.vec3s(key("state_v"), n);
  s.q = r.quats(key("state_q"), n);
  s.w = r.vec3s(key("state_w"), n);
  s.t = r.get(key("state_t"), n, 1).values;
  const auto& cnt = r.get(key("state_count"), n, 1).values;
  const auto img = r.vec3s(key("state_image"), n);
  s.scale = r.get(key("scale"), n, 1).values;
  for (std::size_t i = 0; i < n; ++i) {
    s.count[i] = static_cast<std::uint32_t>(cnt[i]);
    s.image[i] = img[i].cast<int>();
    s.species[i] = static_cast<std::uint16_t>(r.f.type_id[i]);
  }
  loop.slot = r.events(key("calendar"), n);
  loop.best = r.events(key("best"), n);
  const auto l = r.row("hardbody/loop");
  if (l.size() != 3 + kEventTypes) throw InputError(fmt::format("{}: bad loop record", r.path));
  loop.now = l[0];
  loop.stale = std::uint64_t(l[1]);
  for (int k = 0; k < kEventTypes; ++k) loop.counts[k] = std::uint64_t(l[2 + k]);
  loop.rescheduled = std::uint64_t(l[2 + kEventTypes]);
  loop.memo.clear();
  if (auto m = r.f.log.find("hardbody/solver_memo"); m != r.f.log.end()) {
    const gsd::LogArray& a = m->second;
    if (a.cols != 4 || n == 0 || a.rows % n != 0)
      throw InputError(fmt::format("{}: hardbody/solver_memo has {} x {} values, not whole bodies "
                                   "of 4-value rows", r.path, a.rows, a.cols));
    loop.memo.resize(a.rows);
    for (std::size_t k = 0; k < a.rows; ++k) {
      const double* x = a.values.data() + 4 * k;
      if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]) || !(x[3] >= 0.0) ||
          !(x[3] <= 4294967295.0))
        throw InputError(fmt::format("{}: hardbody/solver_memo row {} is not an axis and a body", r.path, k));
      loop.memo[k] = {x[0], x[1], x[2], x[3]};
    }
  }
  const auto dr = r.row("hardbody/driver");
  if (dr.size() != 13 + kEventTypes) throw InputError(fmt::format("{}: bad driver record", r.path));
  d.phase = int(dr[0]);
  d.e0 = dr[1], d.coll0 = dr[2], d.stale0 = dr[3];
  d.log_rows = std::uint64_t(dr[4]), d.frames = std::uint64_t(dr[5]);
  d.next_snapshot = dr[6], d.block_start = dr[7], d.cpu_prev = dr[8], d.wall_prev = dr[9];
  d.next_corr = dr[10], d.next_gr = dr[11];
  d.rescheduled0 = dr[12];
  for (int k = 0; k < kEventTypes; ++k) d.events0[k] = dr[13 + k];
  // rows of length 1 holding 0 stand for empty records (GSD chunks need at least one value)
  auto record = [&](const char* k) {
    auto v = r.row(k);
    if (v.size() == 1 && v[0] == 0.0) v.clear();
    return v;
  };
  d.pressure = record("hardbody/pressure");
  d.corr = record("hardbody/obs_correlations");
  d.gr = record("hardbody/obs_gr");
  d.nematic = record("hardbody/obs_nematic");
  d.pair_collisions = record("hardbody/pair_collisions");
  d.gr_partial = record("hardbody/obs_gr_partial");
  d.temperatures = record("hardbody/obs_temperatures");
  auto optional_record = [&](const char* k) {
    return r.f.log.count(k) ? record(k) : std::vector<double>{};
  };
  d.wall_pressure = optional_record("hardbody/obs_wall_pressure");
  d.profiles = optional_record("hardbody/obs_profiles");
  d.thermostat_next = optional_record("hardbody/thermostat_next");
  d.thermostat_count = optional_record("hardbody/thermostat_count");
  d.corr_species.clear();
  for (std::size_t a = 0; r.f.log.count(fmt::format("hardbody/obs_correlations_species{}", a)); ++a)
    d.corr_species.push_back(record(fmt::format("hardbody/obs_correlations_species{}", a).c_str()));
}

void decode(const Reader& r, std::vector<std::array<int, 3>>& out) {
  const auto v = r.vec3s(key("neighbors"), r.f.N);
  out.resize(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) out[i] = {int(v[i].x()), int(v[i].y()), int(v[i].z())};
}
void decode(const Reader& r, std::vector<Vec3>& out) { out = r.vec3s(key("neighbors"), r.f.N); }

void decode(const Reader& r, ObbSnapshot& out) {
  const std::uint64_t n = r.f.N;
  const auto& a = r.get(key("neighbors"), n, 10);
  out.centre.resize(n);
  out.q.resize(n);
  out.half.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double* x = a.values.data() + 10 * i;
    out.centre[i] = Vec3(x[0], x[1], x[2]);
    out.q[i] = Quat(x[3], x[4], x[5], x[6]);
    out.half[i] = Vec3(x[7], x[8], x[9]);
  }
}

}  // namespace hb::ckpt

namespace hb {

State state_from_gsd(const std::string& path, long frame, Box& box) {
  gsd::HoomdFrame f;
  try {
    const gsd::Reader r(path);
    const long n = static_cast<long>(r.nframes());
    const long k = frame < 0 ? n + frame : frame;
    if (k < 0 || k >= n)
      throw InputError(fmt::format("{}: no frame {} (the file has {})", path, frame, n));
    f = gsd::read_frame(r, static_cast<std::uint64_t>(k));
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  const std::size_t n = f.N;
  auto exact = [&](const char* k, std::uint32_t cols) -> const std::vector<double>* {
    auto it = f.log.find(std::string("particles/hardbody/") + k);
    if (it == f.log.end() || it->second.rows != n || it->second.cols != cols) return nullptr;
    return &it->second.values;
  };
  auto b = f.log.find("hardbody/box_double");
  box.L = (b != f.log.end() && b->second.values.size() == 6)
              ? Vec3(b->second.values[0], b->second.values[1], b->second.values[2])
              : Vec3(f.box[0], f.box[1], f.box[2]);
  if (f.box[3] != 0 || f.box[4] != 0 || f.box[5] != 0)
    throw InputError(fmt::format("{}: tilted boxes are not supported", path));
  State s;
  s.resize(n);
  const auto* r = exact("position_double", 3);
  const auto* q = exact("orientation_double", 4);
  const auto* v = exact("velocity_double", 3);
  const auto* w = exact("angular_velocity_double", 3);
  for (std::size_t i = 0; i < n; ++i) {
    s.r[i] = r ? Vec3((*r)[3 * i], (*r)[3 * i + 1], (*r)[3 * i + 2])
               : Vec3(f.position[3 * i] + 0.5 * box.L.x(), f.position[3 * i + 1] + 0.5 * box.L.y(),
                      f.position[3 * i + 2] + 0.5 * box.L.z());
    s.q[i] = q ? Quat((*q)[4 * i], (*q)[4 * i + 1], (*q)[4 * i + 2], (*q)[4 * i + 3])
               : Quat(f.orientation[4 * i], f.orientation[4 * i + 1], f.orientation[4 * i + 2],
                      f.orientation[4 * i + 3]);
    s.q[i].normalize();
    s.v[i] = v ? Vec3((*v)[3 * i], (*v)[3 * i + 1], (*v)[3 * i + 2])
               : Vec3(f.velocity[3 * i], f.velocity[3 * i + 1], f.velocity[3 * i + 2]);
    if (w) s.w[i] = Vec3((*w)[3 * i], (*w)[3 * i + 1], (*w)[3 * i + 2]);
    s.image[i] = Eigen::Vector3i(f.image[3 * i], f.image[3 * i + 1], f.image[3 * i + 2]);
    s.species[i] = static_cast<std::uint16_t>(f.type_id[i]);  // checked against the config by the builder
  }
  if (const auto* sc = exact("scale", 1)) s.scale = *sc;
  return s;
}

}  // namespace hb
