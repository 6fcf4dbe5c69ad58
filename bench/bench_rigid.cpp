// Whole-simulation benchmark of hard ellipsoids or superquadrics for the performance study
// (scripts/performance.sh): CPU time per collision and where it goes, for one state point.
//
// Usage: bench_rigid key=value ...
//   shape=ellipsoid|superquadric  N=256  phi=0.5  X0=2  b=0.5  p=2  inertia=2/5 m min(a,b)^2
//   (a number: a spherical top; solid: the uniform solid's principal moments)
//   method=nnl|cells  shell=0.15  eps_d=1e-5  seed=1  revolution=1 (0: the spheroids' rate
//   bounds from |w|, not from the spin across their axes: the slow twin)  box_test=1 (0: the
//   neighbour lists' axis-aligned box pre-test off, where it would be on: the slow twin)
//   short_windows=1 (0: the neighbour lists' escape searches over 8 circumradii' flight, with a
//   rebuild at the window's end, not over a quarter and keeping the box: the slow twin)
//   mean_free_cap=2 (short windows cut at this many times the body's mean time between
//   collisions; 0: not cut, the slow twin)  memo=1
//   (0: no pair's last separating axis kept after the start, every search cold: the slow twin)
//   shuffle=0 (1: the lattice start's bodies numbered at random, not along its Morton curve)
//   resort=0 (1: where a scan rebuilds the simulation from the state the point before ended
//   in, the bodies are renumbered along the Morton curve first)
//   collisions=5000  warmup=1000  warmup_per_particle=0 (warm-up at least this many times N)
//   budget=inf (CPU s; stop measuring once spent, after at least
//   min_collisions=500)  auto_n=0 (1: raise N until the lattice start reaches phi in a box of
//   side >= 4 circumradii)  check=1 (independent overlap check after each measurement)  split=0
//   (1: wall-clock share of collisions / neighbour events / stale events)
//   scan=KEY:V1,V2,...  (KEY = method, shell or eps_d) one measurement per value on one
//   trajectory: the first value is warmed up from the lattice start (warmup collisions), each
//   later one starts from the state where the previous one ended (the simulation is rebuilt
//   with the new value, then rewarm=1000 collisions are run untimed).
// Bodies: semi-axes (X0 b, b, b) along body x, y, z; superquadric exponents (2, 2, p) as in the
// paper's section 5.  Prints one JSON line per measurement; status "ok", "skipped" (state not
// reachable by the lattice start, with the reason) or "failed" (a solver failure or an overlap,
// with the message; the next point of a scan then starts afresh from the lattice, with the full
// warm-up).
#include <cstdio>
#include <exception>
#include <regex>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "io/checkpoint.hpp"
#include "observers/overlap.hpp"
#include "observers/overlap_sampling.hpp"
#include "observers/structure.hpp"
#include "shapes/codec.hpp"

#include "bench_rigid.hpp"

using namespace hbbench;

namespace {

// Overlaps of a synchronized state by the independent test of the shape (Perram–Wertheim for
// ellipsoids, surface sampling for superquadrics).
hb::OverlapReport overlaps_of(const hb::State& s, const hb::Box& box, const RigidPoint& pt) {
  if (pt.shape == "ellipsoid") return hb::ellipsoid_overlaps(s.r, s.q, box, pt.spec.semi_axes);
  return hb::superquadric_overlaps(s.r, s.q, box, hb::superquadric_shape(pt.spec));
}

// A `hardbody distance` input line for the pair that a failure message names ("... i and j"),
// in the state where the run stopped (both bodies at the failure time), or "" if none is named.
template <class Shape>
std::string pair_reproducer(const std::string& msg, const Start& st, const Shape& shape) {
  static const std::regex ids("(\\d+) and (\\d+)");
  std::smatch m;
  if (!std::regex_search(msg, m, ids)) return "";
  const std::size_t i = std::stoul(m[1]), j = std::stoul(m[2]);
  if (i >= st.state.size() || j >= st.state.size()) return "";
  auto body = [&](const Vec3& r, const hb::Quat& q) {
    return fmt::format("{{\"shape\": {}, \"position\": [{:.17g}, {:.17g}, {:.17g}], "
                       "\"orientation\": [{:.17g}, {:.17g}, {:.17g}, {:.17g}]}}",
                       hb::shape_json(shape), r.x(), r.y(), r.z(), q.w(), q.x(), q.y(), q.z());
  };
  const Vec3 rj = st.state.r[i] + st.box.near_image(st.state.r[j] - st.state.r[i]);
  return fmt::format("{{\"a\": {}, \"b\": {}}}", body(st.state.r[i], st.state.q[i]), body(rj, st.state.q[j]));
}

struct Scan {
  std::string key;                  // "" (one measurement), method, shell or eps_d
  std::vector<std::string> values;  // as given
};
Scan parse_scan(const std::string& text) {
  Scan sc;
  if (text.empty()) return sc;
  const auto colon = text.find(':');
  if (colon == std::string::npos) throw std::invalid_argument("scan must be KEY:V1,V2,...");
  sc.key = text.substr(0, colon);
  if (sc.key != "method" && sc.key != "shell" && sc.key != "eps_d")
    throw std::invalid_argument("scan key must be method, shell or eps_d");
  std::stringstream ss(text.substr(colon + 1));
  for (std::string v; std::getline(ss, v, ',');)
    if (!v.empty()) sc.values.push_back(v);
  if (sc.values.empty()) throw std::invalid_argument("empty scan");
  return sc;
}
RigidPoint with_value(RigidPoint pt, const Scan& sc, const std::string& v) {
  if (sc.key == "method") {
    if (v != "nnl" && v != "cells") throw std::invalid_argument("method must be nnl or cells");
    pt.method = v;
  } else if (sc.key == "shell") {
    pt.shell = std::stod(v);
  } else if (sc.key == "eps_d") {
    pt.spec.eps_d = std::stod(v);
  }
  return pt;
}

int run(int argc, char** argv) {
  Args args(argc, argv);
  RigidPoint pt = read_point(args);
  const double coll = args.num("collisions", 5000);
  const double warm_given = args.num("warmup", 1000);
  const double warm_pp = args.num("warmup_per_particle", 0);
  const double rewarm = args.num("rewarm", 1000);
  const double budget = args.num("budget", hb::kInf);
  const double min_coll = args.num("min_collisions", 500);
  const bool auto_n = args.num("auto_n", 0) != 0;
  const bool check = args.num("check", 1) != 0;
  const bool split = args.num("split", 0) != 0;
  const Scan scan = parse_scan(args.str("scan", ""));
  args.check_all_used();
  const std::vector<std::string> values = scan.key.empty() ? std::vector<std::string>{""} : scan.values;

  const std::size_t n_requested = pt.spec.n;
  // The lattice must suit every point of the scan: the shell enters the box-size condition,
  // which the largest shell of a scan implies for the others.
  RigidPoint probe = pt;
  if (scan.key == "shell")
    for (const std::string& v : values) probe.shell = std::max(probe.shell, std::stod(v));
  const LatticeCheck lat = auto_n ? fit_particle_number(probe) : check_lattice(probe);
  pt.spec.n = probe.spec.n;
  const double warm = std::max(warm_given, warm_pp * double(pt.spec.n));
  Start st;
  if (lat.ok) st = lattice_start_of(pt);
  bool fresh = true;  // st is the lattice start: warm up in full
  for (std::size_t k = 0; k < values.size(); ++k) {
    const RigidPoint q = scan.key.empty() ? pt : with_value(pt, scan, values[k]);
    Json j;
    j["bench"] = "rigid";
    j.update(describe(q));
    j["N_requested"] = n_requested;
    if (!scan.key.empty()) j["scan"] = scan.key, j["scan_index"] = k;
    if (!lat.ok) {
      j["status"] = "skipped";
      j["reason"] = lat.reason;
      std::printf("%s\n", j.dump().c_str());
      continue;
    }
    j["box"] = {st.box.L.x(), st.box.L.y(), st.box.L.z()};
    std::string failure;
    with_rigid_simulation(q, std::move(st), [&](auto sim) {
      Tally warm_t, meas_t;
      Split sp;
      const Tally start = tally(sim);
      try {
        warm_t = run_collisions(sim, fresh ? warm : rewarm);
        meas_t = run_collisions(sim, coll, budget, min_coll, split ? &sp : nullptr);
        j["status"] = "ok";
      } catch (const std::exception& e) {
        j["status"] = "failed";
        failure = std::string(e.what()).substr(0, 4000);
        j["reason"] = failure;
      }
      const Tally all = tally(sim) - start;
      j["warmup_collisions"] = warm_t.collisions;
      j["warmup_cpu_seconds"] = warm_t.cpu;
      put_costs(j, meas_t);
      j["fallbacks_total"] = all.fallbacks();  // warm-up included
      j["collisions_total"] = all.collisions;
      if (split) {
        const double w = std::max(sp.collision + sp.neighbour + sp.stale, 1e-300);
        j["time_share"] = {{"collisions", sp.collision / w}, {"neighbour_events", sp.neighbour / w},
                           {"stale", sp.stale / w}};
      }
      st = Start{sim.box(), hb::synchronized_state(sim), sim.now()};
      j["S2"] = hb::nematic_order(st.state.q, Vec3::UnitX()).S2;
      if (!failure.empty()) j["reproducer"] = pair_reproducer(failure, st, sim.model().shape);
      if (check) {
        const hb::OverlapReport rep = overlaps_of(st.state, st.box, q);
        j["overlaps"] = rep.overlaps;
        j["min_distance"] = rep.min_distance;
        if (rep.overlaps > 0 && failure.empty()) {
          j["status"] = "failed";
          failure = "overlapping pairs";
          j["reason"] = failure;
        }
      }
      if (q.resort) st.state = morton_sorted(st.state, st.box);
    });
    std::printf("%s\n", j.dump().c_str());
    std::fflush(stdout);
    fresh = !failure.empty();
    if (fresh) st = lattice_start_of(pt);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return guarded_main("bench_rigid", run, argc, argv); }
