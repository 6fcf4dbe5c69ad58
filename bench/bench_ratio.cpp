// Cost ratio of two engines measured in one process (scripts/performance.sh, issue 4 targets):
//   pair=spheres       the hard-sphere engine (diameter 1, cells or shell lists) against the
//                      ellipsoid engine at the same N and phi;
//   pair=superquadric  the ellipsoid engine against the superquadric engine with exponents
//                      (2, 2, 2), i.e. the same bodies, at the same state point.
// Both simulations are built and warmed up, then timed in `rounds` alternating slices (A, B,
// A, B, ...), so that a change of machine load hits both alike.
//
// Usage: bench_ratio pair=spheres|superquadric [rigid point keys of bench_rigid: N phi X0 b
//   inertia eps_d seed method shell] collisions=5000 (rigid bodies) sphere_collisions=
//   20*collisions warmup=1000 (each engine) rounds=10 sphere_shell=0 (0: cells)
//   sphere_engine=generic|fast (fast: the dedicated hard-sphere loop, system/sphere_engine.hpp,
//   with cages of sphere_shell, 0: SphereEngine::default_shell, 0.5 at small N)
// Prints one JSON line: tau_c_us of A and B, ratio B/A, its spread over the rounds.
#include <array>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "bench_rigid.hpp"
#include "system/sphere_engine.hpp"

using namespace hbbench;

namespace {

// The dedicated hard-sphere loop behind the generic loop's counters (for run_collisions).
struct FastSpheres {
  hb::SphereEngine e;
  std::uint64_t collisions() const { return e.collisions(); }
  std::uint64_t stale_events() const { return e.stale_events(); }
  std::array<std::uint64_t, hb::kEventTypes> event_counts() const {
    std::array<std::uint64_t, hb::kEventTypes> counts{};
    counts[int(hb::EventType::Collision)] = e.collisions();
    counts[int(hb::EventType::Rebuild)] = e.cage_exits();
    return counts;
  }
  hb::StepInfo step(double) {
    const hb::SphereEngine::Step s = e.step();
    hb::StepInfo info;
    info.type = s.kind == hb::SphereEngine::Kind::cage ? hb::EventType::Rebuild : hb::EventType::Collision;
    info.stale = s.kind == hb::SphereEngine::Kind::stale;
    return info;
  }
};

template <class SimA, class SimB>
void compare(SimA& a, SimB& b, double coll_a, double coll_b, double warm, int rounds, Json& j) {
  run_collisions(a, warm);
  run_collisions(b, warm);
  Tally ta, tb;
  std::vector<double> ratios;
  for (int r = 0; r < rounds; ++r) {
    const Tally da = run_collisions(a, coll_a / rounds);
    const Tally db = run_collisions(b, coll_b / rounds);
    ta += da;
    tb += db;
    ratios.push_back((db.cpu / db.collisions) / (da.cpu / da.collisions));
  }
  Json ja, jb;
  put_costs(ja, ta);
  put_costs(jb, tb);
  j["A"] = ja;
  j["B"] = jb;
  j["ratio"] = (tb.cpu / tb.collisions) / (ta.cpu / ta.collisions);
  std::sort(ratios.begin(), ratios.end());
  j["ratio_min"] = ratios.front();
  j["ratio_median"] = ratios[ratios.size() / 2];
  j["ratio_max"] = ratios.back();
}

int run(int argc, char** argv) {
  Args args(argc, argv);
  const std::string pair = args.str("pair", "spheres");
  RigidPoint pt = read_point(args);
  const double coll = args.num("collisions", 5000);
  const double sphere_coll = args.num("sphere_collisions", 20 * coll);
  const double warm = args.num("warmup", 1000);
  const int rounds = std::max(1, int(args.num("rounds", 10)));
  const double sphere_shell = args.num("sphere_shell", 0.0);
  const std::string sphere_engine = args.str("sphere_engine", "generic");
  args.check_all_used();
  if (pt.shape != "ellipsoid") throw std::invalid_argument("the rigid point must be an ellipsoid");

  Json j;
  j["bench"] = "ratio";
  j["pair"] = pair;
  const LatticeCheck lat = check_lattice(pt);
  if (!lat.ok) throw std::invalid_argument(lat.reason);
  if (sphere_engine != "generic" && sphere_engine != "fast")
    throw std::invalid_argument("sphere_engine must be generic or fast");
  if (pair == "spheres" && sphere_engine == "fast") {
    const double shell =
        sphere_shell > 0 ? sphere_shell : hb::SphereEngine::default_shell(pt.spec.n, pt.spec.phi);
    j["A_engine"] = "hard spheres, dedicated loop";
    j["A_shell"] = shell;
    j["B_engine"] = "ellipsoids";
    j["B_point"] = describe(pt);
    with_rigid_simulation(pt, lattice_start_of(pt), [&](auto b) {
      hb::assemble(sphere_config(pt.spec.n, pt.spec.phi, 0.0, pt.spec.seed), [&](const auto& as) {
        const hb::Start s = as.start();
        FastSpheres a{hb::SphereEngine(s.box, s.state, 1.0, shell)};
        compare(a, b, sphere_coll, coll, warm, rounds, j);
      });
    });
  } else if (pair == "spheres") {
    j["A_engine"] = sphere_shell > 0 ? "hard spheres, shell lists" : "hard spheres, cells";
    j["A_shell"] = sphere_shell;
    j["B_engine"] = "ellipsoids";
    j["B_point"] = describe(pt);
    with_rigid_simulation(pt, lattice_start_of(pt), [&](auto b) {
      hb::assemble(sphere_config(pt.spec.n, pt.spec.phi, sphere_shell, pt.spec.seed), [&](const auto& as) {
        hb::Start s = as.start();
        auto a = as.simulate(s.box, std::move(s.state));
        compare(a, b, sphere_coll, coll, warm, rounds, j);
      });
    });
  } else if (pair == "superquadric") {
    RigidPoint sq = pt;
    sq.shape = "superquadric";
    sq.spec.exponents = Vec3(2.0, 2.0, 2.0);
    j["A_engine"] = "ellipsoids";
    j["A_point"] = describe(pt);
    j["B_engine"] = "superquadrics (2, 2, 2)";
    j["B_point"] = describe(sq);
    with_rigid_simulation(pt, lattice_start_of(pt), [&](auto a) {
      with_rigid_simulation(sq, lattice_start_of(sq), [&](auto b) { compare(a, b, coll, coll, warm, rounds, j); });
    });
  } else {
    throw std::invalid_argument("pair must be spheres or superquadric");
  }
  std::printf("%s\n", j.dump().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return guarded_main("bench_ratio", run, argc, argv); }
