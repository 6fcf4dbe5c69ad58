// Every fast neighbour structure against the slow twin (neighbors/all_pairs.hpp: every body a
// candidate of every other): hard spheres with cell lists and with sphere-shell lists, and
// ellipsoids with oriented-box lists, run the same first collisions (same pairs, same times to
// rounding) as with all pairs.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <tuple>
#include <vector>

#include "neighbors/all_pairs.hpp"
#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "neighbors/shell_neighbors.hpp"
#include "setup/rigid_setup.hpp"
#include "setup/sphere_setup.hpp"
#include "system/hard_spheres.hpp"
#include "system/rigid_bodies.hpp"
#include "system/simulation.hpp"

namespace hb {
namespace {

using Log = std::vector<std::tuple<double, std::uint32_t, std::uint32_t>>;

template <class Sim>
Log collisions(Sim& sim, std::size_t count) {
  Log log;
  while (log.size() < count) {
    const StepInfo s = sim.step(kInf);
    if (s.type == EventType::Collision && !s.stale) {
      const auto [a, b] = std::minmax(s.record.a, s.record.b);
      log.emplace_back(s.record.time, a, b);
    }
  }
  return log;
}

void expect_same(const Log& fast, const Log& twin, const char* what) {
  ASSERT_EQ(fast.size(), twin.size());
  double worst = 0.0;
  for (std::size_t k = 0; k < fast.size(); ++k) {
    ASSERT_EQ(std::get<1>(fast[k]), std::get<1>(twin[k])) << what << " collision " << k;
    ASSERT_EQ(std::get<2>(fast[k]), std::get<2>(twin[k])) << what << " collision " << k;
    worst = std::max(worst, std::abs(std::get<0>(fast[k]) - std::get<0>(twin[k])));
  }
  std::printf("  %s: %zu collisions, same pairs, worst time difference %.2e\n", what, fast.size(), worst);
  EXPECT_LT(worst, 1e-9);
}

TEST(AllPairsTwin, SphereCellsAndShellListsRunTheSameCollisions) {
  SphereSystemSpec spec;
  spec.n = 256;
  spec.phi = 0.4;
  Box box;
  const State st = hard_sphere_start(spec, box);
  const HardSpheres m{spec.sigma, spec.mass};
  Simulation<HardSpheres, AllPairs> twin(box, st, m, AllPairs{});
  Simulation<HardSpheres, CellNeighbors> cells(box, st, m, CellNeighbors(spec.sigma));
  Simulation<HardSpheres, ShellNeighbors> shells(box, st, m, ShellNeighbors(spec.sigma, 0.3));
  const Log t = collisions(twin, 3000);
  expect_same(collisions(cells, 3000), t, "sphere cells");
  expect_same(collisions(shells, 3000), t, "sphere shells");
}

TEST(AllPairsTwin, EllipsoidOrientedBoxListsRunTheSameCollisions) {
  RigidSystemSpec spec;
  spec.n = 108;
  spec.phi = 0.35;
  spec.semi_axes = Vec3(1.5, 0.5, 0.5);
  Box box;
  const State st = ellipsoid_start(spec, box);
  const Ellipsoid e{1.5, 0.5, 0.5};
  const RigidBodies<Ellipsoid> m{e, MassProperties::principal(spec.mass, spec.inertia), spec.eps_d};
  Simulation<RigidBodies<Ellipsoid>, AllPairs> twin(box, st, m, AllPairs{});
  Simulation<RigidBodies<Ellipsoid>, ObbNeighbors<Ellipsoid>> lists(box, st, m, ObbNeighbors<Ellipsoid>(e, 0.15));
  expect_same(collisions(lists, 1000), collisions(twin, 1000), "ellipsoid oriented boxes");
}

}  // namespace
}  // namespace hb
