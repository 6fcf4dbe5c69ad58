// Lubachevsky–Stillinger growth (setup/growth.hpp): the growth collision rule, overlap-free
// growing runs at intermediate times, and grow_to reaching phi = 0.55 for prolate (X0 = 2) and
// oblate (X0 = 0.5) ellipsoids from a dilute lattice, checked by Perram–Wertheim.
#include <gtest/gtest.h>

#include <cstdio>

#include "geometry/random_pairs.hpp"
#include "observers/overlap.hpp"
#include "setup/growth.hpp"
#include "setup/rigid_setup.hpp"

namespace hb {
namespace {

using testing::Rng;

// Two touching ellipsoids at scale s(now), approaching: after the collision the gap opens at
// exactly the rate it closed (u'.n + grow = -(u.n + grow)), the rigid normal velocity
// separates faster than the growth, dE = J grow, momentum is conserved.
TEST(Growth, CollisionAddsTheGrowthSpeed) {
  Rng r(81);
  const Ellipsoid e{1.0, 0.5, 0.5};
  const MassProperties mp = MassProperties::spherical_top(1.0, 0.1);
  const GrowthLaw law{0.7, 0.2, 0.0, 1.0};
  RigidBodies<Ellipsoid> model{e, mp};
  model.law = law;
  const double now = 0.4, s = law.scale_at(now), sdot = law.rate;
  const Ellipsoid es = scaled_shape(e, s);
  Box box;
  box.L = Vec3::Constant(50.0);
  int tested = 0;
  for (int k = 0; k < 500; ++k) {
    const Pose pa{Vec3(25, 25, 25) + r.ball(1.0), r.rotation()};
    const Vec3 n = r.unit();
    const Pose pb = testing::place_at_distance(es, pa, es, r.rotation(), n, 0.0);
    State st;
    st.resize(2);
    st.r[0] = pa.r, st.q[0] = Quat(pa.R), st.v[0] = r.ball(1.0), st.w[0] = r.ball(1.0);
    st.r[1] = pb.r, st.q[1] = Quat(pb.R), st.v[1] = r.ball(1.0), st.w[1] = r.ball(1.0);
    st.t[0] = st.t[1] = now;
    const Vec3 xc = pa.r + pa.R * es.support_point(pa.R.transpose() * n);
    const Vec3 r_ab = pb.r - pa.r;
    const double grow = (sdot / s) * n.dot(r_ab);
    ASSERT_GT(grow, 0.0);
    const BodyState A0 = st.body(0), B0 = st.body(1);
    const double un = contact_relative_velocity(A0, B0, xc, r_ab).dot(n);
    if (un + grow < 1e-3) continue;  // not approaching (no impulse by design)
    ++tested;
    const double k0 = model.kinetic_energy(st);
    const Vec3 p0 = st.v[0] + st.v[1];
    const CollisionRecord rec = model.collide(st, box, 0, 1, now);
    const double un1 = contact_relative_velocity(st.body(0), st.body(1), xc, r_ab).dot(n);
    EXPECT_NEAR(un1 + grow, -(un + grow), 1e-8 * (1.0 + std::abs(un))) << k;
    EXPECT_LT(un1, -grow) << k;  // rigid normal velocity separates faster than the growth
    EXPECT_GT(rec.J, 0.0);
    EXPECT_NEAR(model.kinetic_energy(st) - k0, rec.J * grow, 1e-8 * (1.0 + k0)) << k;
    EXPECT_NEAR(rec.dE, rec.J * grow, 1e-8 * (1.0 + k0)) << k;
    EXPECT_LE((st.v[0] + st.v[1] - p0).norm(), 1e-12);
    EXPECT_LE((rec.n - n).norm(), 1e-6);
  }
  EXPECT_GT(tested, 100);
}

// The growth speed of the model is (s'/s) n.r_AB, and zero after the growth has stopped.
TEST(Growth, GrowthSpeedStopsWithTheLaw) {
  const GrowthLaw law{0.5, 0.1, 2.0, 5.0};
  EXPECT_DOUBLE_EQ(law.scale_at(2.0), 0.5);
  EXPECT_DOUBLE_EQ(law.scale_at(4.0), 0.7);
  EXPECT_DOUBLE_EQ(law.scale_at(7.0), 0.8);
  EXPECT_EQ(law.rate_at(4.0), 0.1);
  EXPECT_EQ(law.rate_at(5.0), 0.0);
  EXPECT_NEAR(growth_normal_speed(0.5, 0.1, Vec3::UnitX(), Vec3(2, 1, 0)), 0.4, 1e-15);
  EXPECT_EQ(growth_normal_speed(0.5, 0.1, Vec3::UnitX(), Vec3(-2, 1, 0)), 0.0);  // clamped
  RigidBodies<Ellipsoid> m{Ellipsoid{1.0, 0.5, 0.5}, MassProperties::spherical_top(1, 0.1)};
  m.law = law;
  EXPECT_NEAR(m.interaction_range(), 1.6, 1e-15);  // covers the final size
}

// A growing run: at several intermediate times every pair is apart at the current scale
// (Perram–Wertheim on the scaled semi-axes), and the kinetic energy only rises between events.
TEST(Growth, GrowingRunStaysOverlapFree) {
#ifdef NDEBUG
  const std::size_t n = 108;
  const double t_end = 10.0;
#else
  const std::size_t n = 32;  // unoptimised Eigen is ~100x slower: a short run
  const double t_end = 3.0;
#endif
  RigidSystemSpec spec;
  spec.n = n;
  spec.phi = 0.1;
  spec.semi_axes = Vec3(1.0, 0.5, 0.5);
  spec.seed = 7;
  Box box;
  State st = ellipsoid_start(spec, box);
  const Ellipsoid e{1.0, 0.5, 0.5};
  // grow from s = 1 (phi 0.1) at rate 0.05
  const GrowthLaw law{1.0, 0.05, 0.0, 10.0};
  RigidBodies<Ellipsoid> model{e, MassProperties::spherical_top(1.0, 0.1)};
  model.law = law;
  Simulation<RigidBodies<Ellipsoid>, CellNeighbors> sim(
      box, std::move(st), model, CellNeighbors(model.interaction_range()));
  double k_prev = sim.model().kinetic_energy(sim.state());
  for (double t = 1.0; t <= t_end; t += 1.0) {
    while (sim.step(t).type != EventType::None) {
    }
    sim.synchronize();
    const double s = law.scale_at(t);
    const OverlapReport ov = ellipsoid_overlaps(sim.state().r, sim.state().q, box, spec.semi_axes * s);
    EXPECT_EQ(ov.overlaps, 0u) << "t " << t;
    const double k = sim.model().kinetic_energy(sim.state());
    EXPECT_GE(k, k_prev * (1 - 1e-12)) << "t " << t;  // growth collisions only heat
    k_prev = k;
  }
  std::printf("  growing run: N %zu, %llu collisions to phi %.3f, kT %.3f\n", n,
              static_cast<unsigned long long>(sim.collisions()),
              0.1 * std::pow(law.scale_at(t_end), 3), k_prev / (3.0 * double(n)));
  EXPECT_GT(sim.collisions(), 0u);
}

void grow_case(const Vec3& axes, const char* name) {
  RigidSystemSpec spec;
#ifdef NDEBUG
  spec.n = 256;
  spec.phi = 0.55;
#else
  spec.n = 32;  // unoptimised Eigen is ~100x slower: a short run
  spec.phi = 0.3;
#endif
  spec.semi_axes = axes;
  spec.seed = 11;
  GrowthOptions opt;
#ifndef NDEBUG
  opt.rate = 0.1;
#endif
  const GrowthResult res = grow_to(spec, opt);
  const double v = 4.0 / 3.0 * kPi * axes.prod();
  std::printf("  grow_to %s: N %zu phi %.4f (from lattice %.2f at s0 %.4f, rate %.3g) in %.2f s "
              "wall, t %.2f, %llu collisions, %llu rescales, heat removed %.1f kT, min PW gap "
              "%.2e, overlaps %llu, solver fallbacks %llu\n",
              name, spec.n, res.phi, opt.phi0, res.s0, opt.rate, res.wall_seconds, res.time,
              static_cast<unsigned long long>(res.collisions),
              static_cast<unsigned long long>(res.rescales), res.heat_removed / opt.kT,
              res.overlaps.min_distance, static_cast<unsigned long long>(res.overlaps.overlaps),
              static_cast<unsigned long long>(res.stats.fallbacks));
  EXPECT_NEAR(res.phi, spec.phi, 1e-12);
  EXPECT_NEAR(double(spec.n) * v / res.box.volume(), spec.phi, 1e-12);
  EXPECT_EQ(res.overlaps.overlaps, 0u);
  // an independent check here as well
  const OverlapReport ov = ellipsoid_overlaps(res.state.r, res.state.q, res.box, axes);
  EXPECT_EQ(ov.overlaps, 0u);
  // synchronized at time 0 of the continuing run, at temperature kT
  for (std::size_t i = 0; i < res.state.size(); ++i) ASSERT_EQ(res.state.t[i], 0.0);
  double kt = 0.0;
  for (const auto& u : res.state.v) kt += 0.5 * u.squaredNorm();
  EXPECT_NEAR(kt / (1.5 * double(spec.n)), opt.kT, 1e-9);

  // plain NVE continues at the target size: a rigid-body simulation from the grown state
  auto model = ellipsoid_model(spec);
  const double range = model.interaction_range();
  EllipsoidCellSim sim(res.box, res.state, std::move(model), CellNeighbors(range));
  const double e0 = sim.model().kinetic_energy(sim.state());
  while (sim.collisions() < 20 * spec.n && sim.step(kInf).type != EventType::None) {
  }
  sim.synchronize();
  EXPECT_EQ(ellipsoid_overlaps(sim.state().r, sim.state().q, sim.box(), axes).overlaps, 0u);
  EXPECT_NEAR(sim.model().kinetic_energy(sim.state()), e0, 1e-8 * e0);
}

TEST(Growth, GrowToProlateX0_2) { grow_case(Vec3(1.0, 0.5, 0.5), "X0=2  "); }

// Issue 13: the growth thermostat sets every degree of freedom to kT on its own. Spheroids with
// the paper's spherical-top inertia: the spin about the symmetry axis (body x) is untouched by
// collisions, so after the growth it must hold exactly N kT / 2 (a common rescaling of w drained
// it, and the run then started hot: T_trans 1.02-1.10); the total kinetic energy is 3 N kT, so
// the NVE run that follows equilibrates at kT. The spin is checked to stay constant in that run.
TEST(Growth, ThermostatSetsEveryDegreeOfFreedom) {
  RigidSystemSpec spec;
  spec.n = 108;
  spec.phi = 0.4;
  spec.semi_axes = Vec3(1.0, 0.5, 0.5);
  spec.inertia = Vec3::Constant(0.1);  // spherical top
  spec.seed = 4;
  GrowthOptions opt;
  opt.rate = 0.1;
  const GrowthResult res = grow_to(spec, opt);
  auto axial = [&](const State& st) {
    double k = 0.0;
    for (std::size_t i = 0; i < st.size(); ++i) {
      const Vec3 W = st.q[i].conjugate() * st.w[i];
      k += 0.5 * spec.inertia.x() * W.x() * W.x();
    }
    return k;
  };
  const double n = double(spec.n);
  EXPECT_NEAR(axial(res.state), 0.5 * n * opt.kT, 1e-9 * n);
  auto model = ellipsoid_model(spec);
  EXPECT_NEAR(model.kinetic_energy(res.state), 3.0 * n * opt.kT, 1e-9 * n);
  const double range = model.interaction_range();
  EllipsoidCellSim sim(res.box, res.state, std::move(model), CellNeighbors(range));
  while (sim.collisions() < 20 * spec.n && sim.step(kInf).type != EventType::None) {
  }
  ASSERT_GE(sim.collisions(), 20 * spec.n);
  sim.synchronize();
  EXPECT_NEAR(axial(sim.state()), 0.5 * n * opt.kT, 1e-9 * n) << "the axial spin is not decoupled";
}

// thermalize_per_dof against the definition: per species, 3 N_a kT / 2 of translation and
// N_a kT / 2 per principal axis (unequal moments, two species of different masses); a degree of
// freedom with no energy stays at zero.
TEST(Growth, ThermalizePerDofMatchesTheDefinition) {
  Rng rng(3);
  State s;
  s.resize(40);
  const Vec3 moments[2] = {Vec3(0.3, 0.2, 0.1), Vec3(1.0, 1.0, 1.0)};
  const double masses[2] = {1.0, 2.5};
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.species[i] = i % 2;
    s.q[i] = rng.quat();
    s.v[i] = Vec3(rng.normal(), rng.normal(), rng.normal()) * (1.0 + double(i % 3));
    const Vec3 W = Vec3(rng.normal(), rng.normal(), rng.normal()).cwiseProduct(Vec3(3.0, 0.5, i % 2 ? 0.0 : 1.0));  // species 1: W_z = 0
    s.w[i] = s.q[i] * W;
  }
  const double kT = 1.7;
  thermalize_per_dof(s, kT, [&](std::size_t i) { return masses[s.species[i]]; },
                     [&](std::size_t i) { return moments[s.species[i]]; });
  for (std::size_t g = 0; g < 2; ++g) {
    double kt = 0.0, na = 0.0;
    Vec3 kr = Vec3::Zero();
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s.species[i] != g) continue;
      const Vec3 W = s.q[i].conjugate() * s.w[i];
      kt += 0.5 * masses[g] * s.v[i].squaredNorm();
      kr += 0.5 * moments[g].cwiseProduct(W.cwiseProduct(W));
      na += 1.0;
    }
    EXPECT_NEAR(kt, 1.5 * na * kT, 1e-12 * na);
    EXPECT_NEAR(kr.x(), 0.5 * na * kT, 1e-12 * na);
    EXPECT_NEAR(kr.y(), 0.5 * na * kT, 1e-12 * na);
    EXPECT_NEAR(kr.z(), g == 1 ? 0.0 : 0.5 * na * kT, 1e-12 * na);
  }
  // per-species factors must not give the system a net momentum (the input had one)
  Vec3 p = Vec3::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) p += masses[s.species[i]] * s.v[i];
  EXPECT_LT(p.norm(), 1e-12) << "net momentum after the per-species rescaling";
  // a species of one body keeps its own velocity direction; the total momentum is still removed
  s.species[7] = 2;
  thermalize_per_dof(s, kT, [&](std::size_t i) { return s.species[i] == 2 ? 3.0 : masses[s.species[i]]; },
                     [&](std::size_t i) { return moments[s.species[i] % 2]; });
  p = Vec3::Zero();
  for (std::size_t i = 0; i < s.size(); ++i) p += (s.species[i] == 2 ? 3.0 : masses[s.species[i]]) * s.v[i];
  EXPECT_LT(p.norm(), 1e-12) << "net momentum with a lone-body species";
}
TEST(Growth, GrowToOblateX0_05) { grow_case(Vec3(0.5, 1.0, 1.0), "X0=0.5"); }

}  // namespace
}  // namespace hb
