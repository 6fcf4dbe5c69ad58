// HardSphereMixture: for one species it predicts the contact times of HardSpheres (the fast
// path it generalises); growing contact times against a slow scan of the gap; the collision
// conserves momentum and (rigid) energy with unequal masses, and with growth reverses the rate at
// which the gap closed.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "system/hard_sphere_mixture.hpp"
#include "system/hard_spheres.hpp"

using namespace hb;

namespace {

SpeciesTable two_species() {
  return {Species{"A", 1, Sphere{0.5}, 1.0, Vec3::Constant(0.1), {}},
          Species{"B", 1, Sphere{0.2}, 0.3, Vec3::Constant(0.1), {}}};
}

// A random pair (bodies 0 and 1) in a big box, body 1 at time `t1` (delayed state).
State random_pair(std::mt19937_64& rng, const SpeciesTable& sp, double spread, double speed = 1.0) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  State s;
  s.resize(2);
  s.species = {0, std::uint16_t(sp.size() - 1)};
  s.scale = {1.0 + 0.2 * u(rng), 1.0 + 0.2 * u(rng)};
  s.r[0] = Vec3(10, 10, 10);
  s.r[1] = s.r[0] + spread * Vec3(u(rng), u(rng), u(rng));
  s.v[0] = speed * Vec3(u(rng), u(rng), u(rng));
  s.v[1] = speed * Vec3(u(rng), u(rng), u(rng));
  s.t = {0.3, 0.3 * (1 + u(rng))};
  return s;
}

// First time in [0, t_max] at which the gap |dr + dv t| - sigma0 s(now + t) closes: scan in
// steps of h, then bisection (the obviously right, slow twin).
double scan_contact(const HardSphereMixture& m, const State& s, const Box& box, double now, double t_max) {
  const Vec3 dr = box.near_image(s.position_at(1, now) - s.r[0] - s.v[0] * (now - s.t[0]));
  const Vec3 dv = s.v[1] - s.v[0];
  const double sigma0 = m.body_radius(s, 0) + m.body_radius(s, 1);
  auto gap = [&](double t) { return (dr + dv * t).norm() - sigma0 * m.law.scale_at(now + t); };
  if (gap(0.0) <= 0.0) return 0.0;
  const double h = 1e-4;
  for (double t = 0.0; t < t_max; t += h) {
    if (gap(t + h) <= 0.0) {
      double lo = t, hi = t + h;
      for (int k = 0; k < 60; ++k) (gap(0.5 * (lo + hi)) > 0.0 ? lo : hi) = 0.5 * (lo + hi);
      return hi;
    }
  }
  return kInf;
}

}  // namespace

TEST(HardSphereMixture, OneSpeciesGivesTheHardSphereContactTimes) {
  std::mt19937_64 rng(3);
  const SpeciesTable one{Species{"S", 2, Sphere{0.5}, 1.0, Vec3::Constant(0.1), {}}};
  const HardSphereMixture mix = HardSphereMixture::of(one);
  const HardSpheres hs{1.0, 1.0};
  Box box;
  box.L = Vec3::Constant(20.0);
  int hits = 0;
  for (int k = 0; k < 2000; ++k) {
    State s = random_pair(rng, one, 1.8);
    s.scale = {1.0, 1.0};
    s.t[0] = 0.3;
    const std::uint32_t j = 1;
    double a = 0, b = 0;
    mix.contact_times(s, box, 0, &j, nullptr, 1, 0.3, nullptr, &a);
    hs.contact_times(s, box, 0, &j, nullptr, 1, 0.3, nullptr, &b);
    if (std::isinf(b)) {
      EXPECT_TRUE(std::isinf(a)) << k;
    } else {
      ++hits;
      EXPECT_NEAR(a, b, 1e-12 * (1.0 + b)) << k;
    }
  }
  EXPECT_GT(hits, 200);
}

TEST(HardSphereMixture, ContactTimesMatchAScanOfTheGap) {
  std::mt19937_64 rng(5);
  const SpeciesTable sp = two_species();
  Box box;
  box.L = Vec3::Constant(20.0);
  int hits = 0, receding_hits = 0;
  for (int growing = 0; growing < 2; ++growing) {
    HardSphereMixture m = HardSphereMixture::of(sp, growing ? GrowthLaw{0.5, 0.4, 0.0, 1.2} : GrowthLaw{});
    for (int k = 0; k < 1500; ++k) {
      const double speed = growing ? 0.2 : 1.0;
      State s = random_pair(rng, sp, 1.5, speed);
      const double now = 0.3, t_max = growing ? m.law.t_stop - now : 3.0;
      while (scan_contact(m, s, box, now, 0.0) == 0.0) s = random_pair(rng, sp, 1.5, speed);  // start apart
      const std::uint32_t j = 1;
      double t = 0;
      m.contact_times(s, box, 0, &j, nullptr, 1, now, nullptr, &t);
      const double ref = scan_contact(m, s, box, now, t_max);
      if (std::isinf(ref)) {
        EXPECT_TRUE(std::isinf(t) || t > t_max - 1e-4) << "growing " << growing << " case " << k << " t " << t;
        continue;
      }
      ++hits;
      EXPECT_NEAR(t, ref, 1e-9) << "growing " << growing << " case " << k;
      const Vec3 dr = s.position_at(1, now) - s.r[0] - s.v[0] * (now - s.t[0]);
      if (growing && dr.dot(s.v[1] - s.v[0]) > 0.0) ++receding_hits;  // caught while moving apart
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(receding_hits, 5);
}

TEST(HardSphereMixture, CollisionConservesMomentumAndEnergyAndReversesTheClosingRate) {
  std::mt19937_64 rng(7);
  const SpeciesTable sp = two_species();
  Box box;
  box.L = Vec3::Constant(20.0);
  for (int growing = 0; growing < 2; ++growing) {
    const HardSphereMixture m = HardSphereMixture::of(sp, growing ? GrowthLaw{0.5, 0.4, 0.0, 1.2} : GrowthLaw{});
    for (int k = 0; k < 200; ++k) {
      State s = random_pair(rng, sp, 2.0);
      const double now = 0.3;
      for (auto& t : s.t) t = now;
      // place body 1 at contact, approaching
      const double sigma = (m.body_radius(s, 0) + m.body_radius(s, 1)) * m.law.scale_at(now);
      const Vec3 n = (s.r[1] - s.r[0]).normalized();
      s.r[1] = s.r[0] + sigma * n;
      if ((s.v[1] - s.v[0]).dot(n) > 0.0) std::swap(s.v[0], s.v[1]);
      const double grow = (m.body_radius(s, 0) + m.body_radius(s, 1)) * m.law.rate_at(now);
      const double closing = -(s.v[1] - s.v[0]).dot(n) + grow;
      if (closing <= 0.0) continue;
      const Vec3 p0 = m.body_mass(s, 0) * s.v[0] + m.body_mass(s, 1) * s.v[1];
      const double e0 = m.kinetic_energy(s);
      const CollisionRecord rec = m.collide(s, box, 0, 1, now);
      const Vec3 p1 = m.body_mass(s, 0) * s.v[0] + m.body_mass(s, 1) * s.v[1];
      EXPECT_LT((p1 - p0).norm(), 1e-13 * (1 + p0.norm()));
      const double opening = (s.v[1] - s.v[0]).dot(n) - grow;
      EXPECT_NEAR(opening, closing, 1e-12 * (1 + closing));
      EXPECT_NEAR(rec.dE, m.kinetic_energy(s) - e0, 1e-12 * (1 + e0));
      if (!growing) EXPECT_NEAR(m.kinetic_energy(s), e0, 1e-13 * e0);
      else EXPECT_NEAR(rec.dE, rec.J * grow, 1e-12 * (1 + e0));  // the growing surfaces' work
    }
  }
}
