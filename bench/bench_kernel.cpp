// Micro benchmarks of the geometric kernel: distance (cold and warm start) and contact time,
// for spheres (analytic fast path and the generic solver) and uniaxial ellipsoids X0 = 2, 0.5
// (8-equation system by default; *5eq: the 5-equation system).  The sphere contact-time case
// uses the analytic sphere distance inside the generic contact solver.
// Counters: NR iterations per call (distance), distance evaluations and contact-NR iterations
// per call (contact time).  Fixed seeds; pairs are generated once, outside the timed loop.
// Support points of superquadrics (2, 2, p), semi-axes (1, 0.5, 0.5), along 4096 directions
// uniform on the sphere: p = 2 (closed form), 8 (the (2, 2, p) solver with unrolled powers),
// 20 (the same solver, powers by a loop) and (3, 3, 8) (the general solver).
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "contact/contact_time.hpp"
#include "geometry/distance.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

namespace {

using namespace hb;

struct Gen {
  std::mt19937_64 g{12345};
  double uni(double a, double b) { return std::uniform_real_distribution<double>(a, b)(g); }
  Vec3 unit() {
    std::normal_distribution<double> n;
    return Vec3(n(g), n(g), n(g)).normalized();
  }
  Quat quat() {
    std::normal_distribution<double> n;
    Quat q(n(g), n(g), n(g), n(g));
    q.normalize();
    return q;
  }
};

// B placed so that the pair is exactly `gap` apart along n (support points, see the tests).
template <class S>
Pose place(const S& s, const Pose& pa, const Mat3& Rb, const Vec3& n, double gap) {
  const Vec3 xa = pa.r + pa.R * s.support_point(pa.R.transpose() * n);
  return Pose{xa + gap * n - Rb * s.support_point(-(Rb.transpose() * n)), Rb};
}

struct PairSet {
  std::vector<Pose> a, b, b_moved;  // b_moved: b after a small motion (for warm starts)
};

template <class S>
PairSet make_pairs(const S& s, int n) {
  Gen g;
  PairSet p;
  for (int i = 0; i < n; ++i) {
    const Pose pa{Vec3(g.uni(-2, 2), g.uni(-2, 2), g.uni(-2, 2)), g.quat().toRotationMatrix()};
    const double gap = std::exp(g.uni(std::log(1e-4), std::log(1.0)));
    const Pose pb = place(s, pa, g.quat().toRotationMatrix(), g.unit(), gap);
    const double eps = 0.02 * gap;
    p.a.push_back(pa);
    p.b.push_back(pb);
    p.b_moved.push_back(Pose{pb.r + eps * g.unit(),
                             Eigen::AngleAxisd(eps, g.unit()).toRotationMatrix() * pb.R});
  }
  return p;
}

template <class S>
void distance_bench(benchmark::State& state, const S& s, bool warm, bool analytic,
                    DistanceSystem sys = DistanceSystem::eight) {
  const PairSet p = make_pairs(s, 1024);
  DistanceOptions o;
  o.analytic_spheres = analytic;
  o.system = sys;
  std::vector<DistanceWarmStart> w(p.a.size());
  for (size_t i = 0; i < p.a.size(); ++i) w[i] = distance(s, p.a[i], s, p.b[i], o).warm;
  size_t i = 0;
  long iters = 0, calls = 0;
  for (auto _ : state) {
    const DistanceResult r = distance(s, p.a[i], s, warm ? p.b_moved[i] : p.b[i], o,
                                      warm ? &w[i] : nullptr);
    benchmark::DoNotOptimize(r.distance);
    iters += r.nr_iterations;
    ++calls;
    i = (i + 1) % p.a.size();
  }
  state.counters["nr_iter"] = double(iters) / calls;
}

template <class S>
void contact_bench(benchmark::State& state, const S& s) {
  Gen g;
  struct Case { BodyState a, b; double tmax; };
  std::vector<Case> cases;
  const double L = s.bounding_radius();
  for (int i = 0; i < 256; ++i) {
    const Pose pa{Vec3::Zero(), g.quat().toRotationMatrix()};
    const Vec3 n = g.unit();
    const double gap = std::exp(g.uni(std::log(1e-3), std::log(2.0 * L)));
    const Pose pb = place(s, pa, g.quat().toRotationMatrix(), n, gap);
    BodyState a{pa.r, Quat(pa.R), Vec3::Zero(), g.unit() * g.uni(0, 1.0 / L)};
    BodyState b{pb.r, Quat(pb.R), -(n + 0.8 * g.unit() * g.uni(0, 1)).normalized(),
                g.unit() * g.uni(0, 1.0 / L)};
    cases.push_back({a, b, 2.0 * (gap + 2 * L)});
  }
  size_t i = 0;
  long evals = 0, nr = 0, calls = 0, hits = 0;
  for (auto _ : state) {
    const Case& c = cases[i];
    const ContactResult r = contact_time(ContactInput<S, S>{s, s, c.a, c.b, 0.0, 0.0, c.tmax, 1e-5 * L});
    benchmark::DoNotOptimize(r.time);
    evals += r.distance_evals;
    nr += r.nr_iterations;
    hits += r.status == ContactStatus::hit;
    ++calls;
    i = (i + 1) % cases.size();
  }
  state.counters["dist_evals"] = double(evals) / calls;
  state.counters["contact_nr_iter"] = double(nr) / calls;
  state.counters["hit_fraction"] = double(hits) / calls;
}

// 4096 unit directions (the support benchmarks' inputs)
std::vector<Vec3> support_directions() {
  Gen g;
  std::vector<Vec3> dirs(4096);
  for (Vec3& d : dirs) d = g.unit();
  return dirs;
}

void support_bench(benchmark::State& state, const Superquadric& s) {
  const std::vector<Vec3> dirs = support_directions();
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s.support_point(dirs[i]));
    i = (i + 1) & 4095;
  }
}

// The same with each direction depending on the previous point (d (1 + 0 x_0): IEEE keeps the
// product), so the calls do not overlap: the latency of one support point, as in the engine's
// searches, where each step's direction comes from the last step's points.
void support_chain_bench(benchmark::State& state, const Superquadric& s) {
  const std::vector<Vec3> dirs = support_directions();
  size_t i = 0;
  double carry = 0.0;
  for (auto _ : state) {
    const Vec3 x = s.support_point(dirs[i] * (1.0 + carry));
    carry = 0.0 * x[0];
    benchmark::DoNotOptimize(carry);
    i = (i + 1) & 4095;
  }
}

const Sphere kSphere{0.5};
const Ellipsoid kProlate{1.0, 0.5, 0.5};  // X0 = 2 (symmetry axis along x)
const Ellipsoid kOblate{0.25, 0.5, 0.5};  // X0 = 0.5

void BM_DistanceSphereAnalytic(benchmark::State& s) { distance_bench(s, kSphere, false, true); }
void BM_DistanceSphereGenericCold(benchmark::State& s) { distance_bench(s, kSphere, false, false); }
void BM_DistanceSphereGenericWarm(benchmark::State& s) { distance_bench(s, kSphere, true, false); }
void BM_DistanceEllipsoidX2Cold(benchmark::State& s) { distance_bench(s, kProlate, false, true); }
void BM_DistanceEllipsoidX2Warm(benchmark::State& s) { distance_bench(s, kProlate, true, true); }
void BM_DistanceEllipsoidX2Cold5eq(benchmark::State& s) {
  distance_bench(s, kProlate, false, true, DistanceSystem::five);
}
void BM_DistanceEllipsoidX2Warm5eq(benchmark::State& s) {
  distance_bench(s, kProlate, true, true, DistanceSystem::five);
}
void BM_DistanceEllipsoidX05Cold(benchmark::State& s) { distance_bench(s, kOblate, false, true); }
void BM_DistanceEllipsoidX05Warm(benchmark::State& s) { distance_bench(s, kOblate, true, true); }
void BM_ContactTimeSphere(benchmark::State& s) { contact_bench(s, kSphere); }
void BM_ContactTimeEllipsoidX2(benchmark::State& s) { contact_bench(s, kProlate); }
void BM_ContactTimeEllipsoidX05(benchmark::State& s) { contact_bench(s, kOblate); }
void BM_SupportSuperquadricP2(benchmark::State& s) { support_bench(s, {1.0, 0.5, 0.5, 2, 2, 2}); }
void BM_SupportSuperquadricP8(benchmark::State& s) { support_bench(s, {1.0, 0.5, 0.5, 2, 2, 8}); }
void BM_SupportSuperquadricP20(benchmark::State& s) { support_bench(s, {1.0, 0.5, 0.5, 2, 2, 20}); }
void BM_SupportSuperquadric338(benchmark::State& s) { support_bench(s, {1.0, 0.5, 0.5, 3, 3, 8}); }
void BM_SupportChainSuperquadricP2(benchmark::State& s) {
  support_chain_bench(s, {1.0, 0.5, 0.5, 2, 2, 2});
}
void BM_SupportChainSuperquadricP8(benchmark::State& s) {
  support_chain_bench(s, {1.0, 0.5, 0.5, 2, 2, 8});
}

BENCHMARK(BM_DistanceSphereAnalytic);
BENCHMARK(BM_DistanceSphereGenericCold);
BENCHMARK(BM_DistanceSphereGenericWarm);
BENCHMARK(BM_DistanceEllipsoidX2Cold);
BENCHMARK(BM_DistanceEllipsoidX2Warm);
BENCHMARK(BM_DistanceEllipsoidX2Cold5eq);
BENCHMARK(BM_DistanceEllipsoidX2Warm5eq);
BENCHMARK(BM_DistanceEllipsoidX05Cold);
BENCHMARK(BM_DistanceEllipsoidX05Warm);
BENCHMARK(BM_ContactTimeSphere);
BENCHMARK(BM_ContactTimeEllipsoidX2);
BENCHMARK(BM_ContactTimeEllipsoidX05);
BENCHMARK(BM_SupportSuperquadricP2);
BENCHMARK(BM_SupportSuperquadricP8);
BENCHMARK(BM_SupportSuperquadricP20);
BENCHMARK(BM_SupportSuperquadric338);
BENCHMARK(BM_SupportChainSuperquadricP2);
BENCHMARK(BM_SupportChainSuperquadricP8);

}  // namespace

BENCHMARK_MAIN();
