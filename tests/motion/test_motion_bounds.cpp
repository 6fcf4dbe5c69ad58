// Motion's flight-long rotation bounds (motion/motion.hpp): spin_across(k), the bound of
// |w(t) x e_k(t)| (e_k the body's own axis k in the lab), against the flight sampled over many
// turns: a bound at every sample, tight (reached at the start) for spherical tops and for
// symmetric tops about k, and |w|'s bound for the other tops and axes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "motion/motion.hpp"

namespace hb {
namespace {

struct TopCase {
  const char* name;
  Vec3 top;
  int symmetric_about;  // -1: asymmetric; 3: spherical
};

TEST(Motion, SpinAcrossBoundsTheSpinAcrossEachAxisAlongTheFlight) {
  const TopCase tops[] = {{"spherical", Vec3(0.1, 0.1, 0.1), 3},
                          {"prolate about x", Vec3(0.05, 0.2, 0.2), 0},
                          {"oblate about y", Vec3(0.3, 0.5, 0.3), 1},
                          {"about z", Vec3(0.2, 0.2, 0.07), 2},
                          {"asymmetric", Vec3(0.1, 0.25, 0.22), -1}};
  std::mt19937_64 g(2026);
  std::normal_distribution<double> nrm(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (const TopCase& c : tops) {
    double worst = 0.0;  // max over the samples of |w x e_k| / spin_across(k)
    int tight = 0, cases = 0;
    for (int k = 0; k < 40; ++k) {
      BodyState b;
      b.top = c.top;
      b.q = Quat(nrm(g), nrm(g), nrm(g), nrm(g)).normalized();
      b.w = Vec3(nrm(g), nrm(g), nrm(g)) * std::pow(10.0, u(g));
      if (k % 8 == 0) b.w = b.q * Vec3::Unit(k / 8 % 3) * 3.0 + b.q * Vec3(1e-3, 2e-3, -1e-3);
      const Motion m(b);
      const double wmax = m.max_angular_speed();
      for (int axis = 0; axis < 3; ++axis) {
        const double bound = m.spin_across(axis);
        ASSERT_LE(bound, wmax);
        const bool exact = c.symmetric_about == 3 || c.symmetric_about == axis;
        if (!exact) {
          EXPECT_EQ(bound, wmax) << c.name << " axis " << axis;
        }
        // the flight over ~20 turns of the fastest spin
        const double T = 20.0 * 2.0 * M_PI / wmax;
        double seen = 0.0;
        for (int s = 0; s <= 2000; ++s) {
          const double tau = T * s / 2000.0;
          const Vec3 e = m.rotation(tau).col(axis);
          const double across = m.angular_velocity(tau).cross(e).norm();
          ASSERT_LE(across, bound) << c.name << " axis " << axis << " tau " << tau;
          seen = std::max(seen, across);
        }
        worst = std::max(worst, seen / bound);
        if (exact) {
          // constant along the flight: reached at the start (to the margin of 1e-14) and after
          EXPECT_NEAR(b.w.cross(b.q * Vec3::Unit(axis)).norm(), bound, 1e-12 * wmax);
          EXPECT_GT(seen, bound - 1e-12 * wmax) << c.name << " axis " << axis;
          tight += bound < 0.99 * wmax;
        }
        ++cases;
        // the cache: asked again after another axis, the same number
        EXPECT_EQ(m.spin_across((axis + 1) % 3), m.spin_across((axis + 1) % 3));
        EXPECT_EQ(m.spin_across(axis), bound);
      }
      EXPECT_EQ(m.spin_across(-1), wmax);
    }
    std::printf("  %-16s %d axes: max |w x e| / spin_across %.15f, %d bounds below 0.99 |w|max\n",
                c.name, cases, worst, tight);
    if (c.symmetric_about >= 0) {
      EXPECT_GT(tight, 10) << c.name;  // the bound does tighten
    }
  }
}

// A spin about the axis itself has nothing across it; a copy keeps the cached bound.
TEST(Motion, SpinAboutTheAxisHasNothingAcrossIt) {
  BodyState b;
  b.top = Vec3(0.05, 0.2, 0.2);
  b.q = Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  b.w = b.q * Vec3(4.0, 0.0, 0.0);
  const Motion m(b);
  EXPECT_LT(m.spin_across(0), 1e-13);
  EXPECT_NEAR(m.spin_across(1), 4.0, 1e-12);
  const Motion copy = m;
  EXPECT_EQ(copy.spin_across(1), m.spin_across(1));
  EXPECT_LT(copy.spin_across(0), 1e-13);
}

}  // namespace
}  // namespace hb
