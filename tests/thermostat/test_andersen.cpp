// The Andersen thermostat (thermostat/andersen.hpp) in the event loop: asymmetric tops started at
// one temperature and coupled to a bath at another end up with Maxwell velocities and angular
// velocities at the bath temperature (Kolmogorov–Smirnov), and the thermostat's events do not
// depend on the order in which they are processed (checkpointable state).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "neighbors/cell_neighbors.hpp"
#include "setup/growth.hpp"
#include "setup/mixture_setup.hpp"
#include "system/rigid_mixture.hpp"
#include "system/simulation.hpp"

namespace hb {
namespace {

// Kolmogorov–Smirnov distance of the sample from the standard normal distribution.
double ks_normal(std::vector<double> x) {
  std::sort(x.begin(), x.end());
  const double n = double(x.size());
  double d = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double F = 0.5 * std::erfc(-x[k] / std::sqrt(2.0));
    d = std::max({d, std::abs(F - double(k) / n), std::abs(double(k + 1) / n - F)});
  }
  return d;
}

TEST(Andersen, VelocitiesAndSpinsBecomeMaxwellianAtTheBathTemperature) {
  Species e{"E", 120, Ellipsoid{1.2, 0.6, 0.4}, 1.3, Vec3(0.08, 0.2, 0.24), {}};
  const SpeciesTable sp{e};
  GrowthOptions go;
  go.phi0 = 0.05;
  go.kT = 1.0;
  const GrowthResult g = grow_rigid_mixture(sp, 0.15, 11, go, 1e-5);
  const RigidMixture m = RigidMixture::of(sp, 1e-5);
  const double kT = 2.5, rate = 1.0;
  Simulation<RigidMixture, CellNeighbors> sim(g.box, g.state, m, CellNeighbors(m.interaction_range()), 0.0,
                                              BodyEvents(PlanarWalls{}, AndersenThermostat(rate, kT, 3)));
  std::vector<double> v[3], w[3];
  const double t_eq = 10.0, dt = 3.0;
  for (double t = t_eq; t <= t_eq + 30 * dt + 1e-9; t += dt) {
    while (sim.step(t).type != EventType::None) {
    }
    sim.synchronize();
    const State& s = sim.state();
    for (std::size_t i = 0; i < s.size(); ++i) {
      const Vec3 W = s.q[i].conjugate() * s.w[i];
      for (int k = 0; k < 3; ++k) {
        v[k].push_back(s.v[i][k] * std::sqrt(e.mass / kT));
        w[k].push_back(W[k] * std::sqrt(e.inertia[k] / kT));
      }
    }
  }
  const double n = double(v[0].size());
  // 0.1 % critical value of the one-sample KS distance (asymptotic: 1.949 / sqrt(n)); samples
  // 3 / rate apart are correlated by at most e^-3 through the thermostat alone
  const double crit = 1.949 / std::sqrt(n);
  for (int k = 0; k < 3; ++k) {
    const double dv = ks_normal(v[k]), dw = ks_normal(w[k]);
    std::printf("  axis %d: KS distance v %.4f, W %.4f (0.1%% critical %.4f, n = %.0f)\n", k, dv, dw, crit, n);
    EXPECT_LT(dv, crit);
    EXPECT_LT(dw, crit);
  }
  // rate x time x N events: a Poisson count
  const double expected = rate * (t_eq + 30 * dt) * 120.0;
  EXPECT_NEAR(double(sim.event_counts()[int(EventType::Thermostat)]), expected, 4.0 * std::sqrt(expected));
  EXPECT_GT(sim.collisions(), 1000u);
}

// The k-th event of body i is a function of (seed, i, k): two thermostats fed the same bodies in
// different orders give the same velocities and times.
TEST(Andersen, EventsDependOnlyOnSeedBodyAndCount) {
  State s;
  s.resize(4);
  AndersenThermostat a(0.7, 1.3, 9), b(0.7, 1.3, 9);
  a.start(4, 0.0);
  b.start(4, 0.0);
  State sa = s, sb = s;
  for (int round = 0; round < 3; ++round) {
    for (std::uint32_t i = 0; i < 4; ++i) a.fire(sa, i, a.next(i), 1.0, Vec3(0.1, 0.2, 0.3), true);
    for (std::uint32_t i = 4; i-- > 0;) b.fire(sb, i, b.next(i), 1.0, Vec3(0.1, 0.2, 0.3), true);
  }
  for (std::uint32_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sa.v[i], sb.v[i]);
    EXPECT_EQ(sa.w[i], sb.w[i]);
    EXPECT_EQ(a.next(i), b.next(i));
    EXPECT_EQ(a.counts()[i], 3u);
  }
  // waiting times are exponential with the rate: mean 1/rate
  AndersenThermostat c(2.0, 1.0, 5);
  c.start(20000, 0.0);
  double mean = 0.0;
  for (std::uint32_t i = 0; i < 20000; ++i) mean += c.next(i) / 20000.0;
  EXPECT_NEAR(mean, 0.5, 4.0 * 0.5 / std::sqrt(20000.0));
}

}  // namespace
}  // namespace hb
