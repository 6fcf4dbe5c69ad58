// Walls in the event loop: bodies of every kind grown inside walls (the start) and then run;
// every wall event conserves energy, no body crosses a wall or overlaps another (independent
// checks), and the brute-force queue runs the same events as the indexed heap.
#include <gtest/gtest.h>

#include <cstdio>

#include "events/calendar_queue.hpp"
#include "events/queue.hpp"
#include "locals/planar_walls.hpp"
#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "observers/overlap_check.hpp"
#include "setup/growth.hpp"
#include "setup/mixture_setup.hpp"
#include "system/hard_sphere_mixture.hpp"
#include "system/rigid_mixture.hpp"
#include "system/simulation.hpp"

namespace hb {
namespace {

// The largest penetration of any body into any wall (support-function distance; > 0 means
// through a wall), for a synchronised state.
double worst_penetration(const RigidMixture& m, const State& s, const Box& box) {
  double worst = -kInf;
  for (std::uint32_t i = 0; i < s.size(); ++i)
    std::visit(
        [&](const auto& shape) {
          for (int f = 0; f < 6; ++f)
            if (!box.periodic[f >> 1])
              worst = std::max(worst, -PlanarWalls::distance(shape, s.body(i), 1.0, box, f));
        },
        m.body_shape(s, i));
  return worst;
}

Box walled_box(double lx, double ly, double lz, std::array<bool, 3> walls) {
  Box b;
  b.L = Vec3(lx, ly, lz);
  b.periodic = {!walls[0], !walls[1], !walls[2]};
  return b;
}

// The unlike-shape mixture grown to phi in a box of side ratios `aspect` with walls on `walls`.
GrowthResult grow_inside(const SpeciesTable& sp, double phi, std::uint64_t seed, const Vec3& aspect,
                         std::array<bool, 3> walls) {
  GrowthOptions go;
  go.rate = 0.1;
  go.phi0 = 0.05;
  const double L = std::cbrt(body_volume(sp, species_state(sp, seed)) / phi / aspect.prod());
  go.box = walled_box(aspect.x() * L, aspect.y() * L, aspect.z() * L, walls);
  return grow_rigid_mixture(sp, phi, seed, go, 1e-5);
}

SpeciesTable unlike_species() {
  Species a{"S", 30, Sphere{0.4}, 0.5, Vec3::Constant(0.032), {}};
  Species b{"E", 40, Ellipsoid{1.5, 0.5, 0.5}, 1.0, Vec3(0.1, 0.3, 0.3), {}};
  Species c{"Q", 20, Superquadric(0.6, 0.5, 0.5, 4.0, 4.0, 4.0), 1.2, Vec3(0.1, 0.11, 0.12), {}};
  return {a, b, c};
}

template <class Queue>
std::vector<std::tuple<double, std::uint32_t, std::uint32_t, int>> run_mixture(
    const GrowthResult& g, const RigidMixture& m, int events, double* drift, double* penetration,
    std::uint64_t* walls, std::uint64_t* overlaps) {
  Simulation<RigidMixture, CellNeighbors, Queue> sim(
      g.box, g.state, m, CellNeighbors(m.interaction_range()), 0.0,
      BodyEvents(PlanarWalls({!g.box.periodic[0], !g.box.periodic[1], !g.box.periodic[2]}, m.eps_d)));
  const double e0 = m.kinetic_energy(sim.state());
  std::vector<std::tuple<double, std::uint32_t, std::uint32_t, int>> log;
  double worst = -kInf;
  for (int k = 0; k < events; ++k) {
    const StepInfo ev = sim.step(kInf);
    if (ev.type == EventType::Collision || ev.type == EventType::Wall)
      log.emplace_back(ev.record.time, ev.record.a, ev.record.b, int(ev.type));
    if (k % 500 == 0) {
      sim.synchronize();
      worst = std::max(worst, worst_penetration(m, sim.state(), sim.box()));
    }
  }
  sim.synchronize();
  worst = std::max(worst, worst_penetration(m, sim.state(), sim.box()));
  *drift = (m.kinetic_energy(sim.state()) - e0) / e0;
  *penetration = worst;
  *walls = sim.event_counts()[int(EventType::Wall)];
  *overlaps = mixture_overlap_check(m.shape)(sim.state(), sim.box()).overlaps;
  return log;
}

// Spheres, ellipsoids and superquadrics (asymmetric tops) grown inside walls on all three axes,
// then 20000 events: energy conserved, no body through a wall or into another.
TEST(WallsInTheLoop, UnlikeShapesInAClosedBoxConserveAndStayInside) {
  const SpeciesTable sp = unlike_species();
  const GrowthResult g = grow_inside(sp, 0.3, 5, Vec3(1.0, 1.2, 1.0 / 1.2), {true, true, true});
  const RigidMixture m = RigidMixture::of(sp, 1e-5);
  EXPECT_EQ(mixture_overlap_check(m.shape)(g.state, g.box).overlaps, 0u);
  EXPECT_LE(worst_penetration(m, g.state, g.box), 0.0) << "the grown start is through a wall";
  double drift, pen;
  std::uint64_t walls, overlaps;
  run_mixture<CalendarQueue>(g, m, 20000, &drift, &pen, &walls, &overlaps);
  std::printf("  closed box: %llu wall events, drift %.2e, worst penetration %.3e\n",
              (unsigned long long)walls, drift, pen);
  EXPECT_GT(walls, 500u);
  EXPECT_LT(std::abs(drift), 1e-12);
  // Spheres meet a wall by the closed form, with no margin: at a bounce the sphere touches the
  // wall to the rounding of its position (a few ulps of the box side), on either side.
  EXPECT_LE(pen, 1e-14 * g.box.L.maxCoeff());
  EXPECT_EQ(overlaps, 0u);
}

// The twins: the brute-force queue and the indexed heap pop the same events as the calendar
// (the loop's default queue) in a slit.
TEST(WallsInTheLoop, BruteForceQueueRunsTheSameEvents) {
  const SpeciesTable sp = unlike_species();
  const GrowthResult g = grow_inside(sp, 0.25, 6, Vec3::Ones(), {false, false, true});
  const RigidMixture m = RigidMixture::of(sp, 1e-5);
  double d1, d2, d3, p1, p2, p3;
  std::uint64_t w1, w2, w3, o1, o2, o3;
  const auto a = run_mixture<CalendarQueue>(g, m, 5000, &d1, &p1, &w1, &o1);
  const auto b = run_mixture<BruteQueue>(g, m, 5000, &d2, &p2, &w2, &o2);
  const auto c = run_mixture<IndexedHeap>(g, m, 5000, &d3, &p3, &w3, &o3);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  for (std::size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a[k], b[k]) << k;
  for (std::size_t k = 0; k < a.size(); ++k) ASSERT_EQ(a[k], c[k]) << k;
  EXPECT_GT(w1, 50u);
  EXPECT_EQ(w1, w2);
  EXPECT_EQ(w1, w3);
}

// Hard spheres in a slit (the monomorphic sphere path of the mixture model): the momentum
// parallel to the walls is conserved exactly, the normal one is not.
TEST(WallsInTheLoop, SpheresInASlitKeepTheirParallelMomentum) {
  Species s{"A", 200, Sphere{0.5}, 1.0, Vec3::Constant(0.1), {}};
  const SpeciesTable sp{s};
  GrowthOptions go;
  go.rate = 0.2;
  go.phi0 = 0.05;
  State probe = species_state(sp, 7);
  const double L = std::cbrt(body_volume(sp, probe) / 0.3);
  go.box = walled_box(L, L, L, {false, false, true});
  const GrowthResult g = grow_sphere_mixture(sp, 0.3, 7, go);
  const HardSphereMixture m = HardSphereMixture::of(sp);
  Simulation<HardSphereMixture, CellNeighbors> sim(g.box, g.state, m, CellNeighbors(1.0), 0.0,
                                                   BodyEvents(PlanarWalls({false, false, true}, 1e-5)));
  auto momentum = [&] {
    Vec3 p = Vec3::Zero();
    for (const Vec3& v : sim.state().v) p += v;
    return p;
  };
  const Vec3 p0 = momentum();
  const double e0 = m.kinetic_energy(sim.state());
  double zmin = kInf, zmax = -kInf;
  for (int k = 0; k < 20000; ++k) {
    sim.step(kInf);
    if (k % 100 == 0) {
      sim.synchronize();
      for (const Vec3& r : sim.state().r) zmin = std::min(zmin, r.z()), zmax = std::max(zmax, r.z());
    }
  }
  sim.synchronize();
  const Vec3 p1 = momentum();
  EXPECT_GT(sim.event_counts()[int(EventType::Wall)], 1000u);
  EXPECT_NEAR(p1.x(), p0.x(), 1e-10);
  EXPECT_NEAR(p1.y(), p0.y(), 1e-10);
  EXPECT_NEAR(m.kinetic_energy(sim.state()), e0, 1e-12 * e0);
  EXPECT_GE(zmin, 0.5 - 1e-12);
  EXPECT_LE(zmax, L - 0.5 + 1e-12);
}

}  // namespace
}  // namespace hb
