// Re-check before running a collision (system/simulation.hpp): on healthy runs it changes no
// trajectory and reschedules nothing; a pair model whose predictions come up early (a fault
// injected on purpose) is caught: every such collision is rescheduled to the true contact, none
// runs apart and none overlaps.
#include <gtest/gtest.h>

#include <cstdio>
#include <tuple>
#include <vector>

#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "setup/rigid_setup.hpp"
#include "setup/sphere_setup.hpp"
#include "system/hard_spheres.hpp"
#include "system/rigid_bodies.hpp"
#include "system/simulation.hpp"
#include "geometry/distance.hpp"

namespace hb {
namespace {

using Log = std::vector<std::tuple<double, std::uint32_t, std::uint32_t>>;

template <class Sim>
Log run(Sim& sim, int events) {
  Log log;
  for (int k = 0; k < events; ++k) {
    const StepInfo s = sim.step(kInf);
    if (s.type == EventType::Collision && !s.stale) log.emplace_back(s.record.time, s.record.a, s.record.b);
  }
  return log;
}

TEST(Recheck, HealthySpheresRunTheSameTrajectoryAndRescheduleNothing) {
  SphereSystemSpec spec;
  spec.n = 500;
  spec.phi = 0.45;
  auto a = make_hard_sphere_cell_simulation(spec);
  auto b = make_hard_sphere_cell_simulation(spec);
  b.set_recheck(false);
  const Log la = run(a, 30000), lb = run(b, 30000);
  ASSERT_EQ(la.size(), lb.size());
  for (std::size_t k = 0; k < la.size(); ++k) ASSERT_EQ(la[k], lb[k]) << k;
  EXPECT_EQ(a.rescheduled_events(), 0u);
  EXPECT_GT(la.size(), 10000u);
}

TEST(Recheck, HealthyEllipsoidsRunTheSameTrajectoryAndRescheduleNothing) {
  RigidSystemSpec spec;
  spec.n = 108;
  spec.phi = 0.4;
  spec.semi_axes = Vec3(1.0, 0.5, 0.5);
  auto a = make_ellipsoid_list_simulation(spec, 0.15);
  auto b = make_ellipsoid_list_simulation(spec, 0.15);
  b.set_recheck(false);
  const Log la = run(a, 6000), lb = run(b, 6000);
  ASSERT_EQ(la.size(), lb.size());
  for (std::size_t k = 0; k < la.size(); ++k) ASSERT_EQ(la[k], lb[k]) << k;
  std::printf("  ellipsoids: %zu collisions, %llu rescheduled\n", la.size(),
              (unsigned long long)a.rescheduled_events());
  EXPECT_EQ(a.rescheduled_events(), 0u);
}

// Hard spheres whose predicted contact times are, for one pair in seven, 20 % early: the fault.
struct EarlySpheres : HardSpheres {
  void contact_times(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                     const Vec3* shifts, std::size_t n, double now, const double* horizons,
                     double* out) const {
    HardSpheres::contact_times(s, box, i, js, shifts, n, now, horizons, out);
    for (std::size_t k = 0; k < n; ++k)
      if ((i + js[k]) % 7 == 0 && out[k] < kInf) out[k] *= 0.8;
  }
};

template <class Model>
void check_faulty(bool recheck, std::uint64_t* rescheduled, double* worst_gap) {
  SphereSystemSpec spec;
  spec.n = 500;
  spec.phi = 0.45;
  Box box;
  State st = hard_sphere_start(spec, box);
  Model m;
  m.sigma = spec.sigma;
  Simulation<Model, CellNeighbors> sim(box, std::move(st), m, CellNeighbors(spec.sigma));
  sim.set_recheck(recheck);
  double worst = 0.0;
  for (int k = 0; k < 30000; ++k) {
    const StepInfo s = sim.step(kInf);
    if (s.type != EventType::Collision || s.stale) continue;
    // the pair's centre distance when the impulse is applied
    const double d = box.minimum_image(sim.state().r[s.record.b] - sim.state().r[s.record.a]).norm();
    worst = std::max(worst, std::abs(d - spec.sigma));
  }
  *rescheduled = sim.rescheduled_events();
  *worst_gap = worst;
}

TEST(Recheck, EarlyPredictionsAreCaughtAndRescheduled) {
  std::uint64_t r_on, r_off;
  double g_on, g_off;
  check_faulty<EarlySpheres>(true, &r_on, &g_on);
  check_faulty<EarlySpheres>(false, &r_off, &g_off);
  std::printf("  early predictions: with re-check %llu rescheduled, worst |r - sigma| %.2e; without %.2e\n",
              (unsigned long long)r_on, g_on, g_off);
  EXPECT_GT(g_off, 1e-3) << "the injected fault should make collisions run apart";
  EXPECT_GT(r_on, 100u);
  EXPECT_LT(g_on, 1e-8) << "a collision ran away from contact despite the re-check";
}

// Ellipsoids whose predicted contact times are, for one pair in seven, 20 % early: the rigid
// models re-check on the gap their collision's distance solve finds (recheck_moved).
struct EarlyEllipsoids : RigidBodies<Ellipsoid> {
  void contact_times(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                     const Vec3* shifts, std::size_t n, double now, const double* horizons,
                     double* out) const {
    RigidBodies<Ellipsoid>::contact_times(s, box, i, js, shifts, n, now, horizons, out);
    for (std::size_t k = 0; k < n; ++k)
      if ((i + js[k]) % 7 == 0 && out[k] < kInf) out[k] *= 0.8;
  }
};

// The worst gap between the pairs of the collisions that ran (the distance solve at each impulse).
double faulty_ellipsoids(bool recheck, std::uint64_t* rescheduled) {
  RigidSystemSpec spec;
  spec.n = 108;
  spec.phi = 0.4;
  spec.semi_axes = Vec3(1.0, 0.5, 0.5);
  Box box;
  State st = ellipsoid_start(spec, box);
  EarlyEllipsoids m;
  static_cast<RigidBodies<Ellipsoid>&>(m) = ellipsoid_model(spec);
  Simulation<EarlyEllipsoids, ObbNeighbors<Ellipsoid>> sim(box, std::move(st), m,
                                                           ObbNeighbors<Ellipsoid>(m.shape, 0.15));
  sim.set_recheck(recheck);
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const StepInfo e = sim.step(kInf);
    if (e.type != EventType::Collision || e.stale) continue;
    const State& x = sim.state();
    const BodyState a = x.body_at(e.record.a, e.record.time), b = x.body_at(e.record.b, e.record.time);
    const Pose pa{a.r, a.q.toRotationMatrix()};
    const Pose pb{a.r + box.near_image(b.r - a.r), b.q.toRotationMatrix()};
    worst = std::max(worst, std::abs(distance(m.shape, pa, m.shape, pb).distance));
  }
  *rescheduled = sim.rescheduled_events();
  return worst;
}

TEST(Recheck, EarlyEllipsoidPredictionsAreCaughtOnTheGap) {
  std::uint64_t r_on = 0, r_off = 0;
  const double g_on = faulty_ellipsoids(true, &r_on), g_off = faulty_ellipsoids(false, &r_off);
  std::printf("  early ellipsoid predictions: with re-check %llu rescheduled, worst |gap| at the impulse %.2e; "
              "without %.2e\n", (unsigned long long)r_on, g_on, g_off);
  EXPECT_GT(g_off, 1e-3) << "the injected fault should make collisions run apart";
  EXPECT_GT(r_on, 100u);
  EXPECT_LT(g_on, 1e-6) << "a collision ran away from contact despite the re-check";
}

}  // namespace
}  // namespace hb
