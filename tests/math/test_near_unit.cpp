// near_unit_normalized (math/types.hpp) against its slow twin, the long double normalisation:
// vectors and quaternions a few roundings off the unit sphere (the Newton step) and far from it
// (normalized() itself, bit for bit).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <pcg_random.hpp>
#include <random>

#include "math/types.hpp"

namespace {

using LD = long double;

// Largest component error of near_unit_normalized(u) against u / |u| in long double.
template <class V>
double error_against_long_double(const V& u) {
  LD n2 = 0;
  for (int k = 0; k < u.size(); ++k) n2 += LD(u[k]) * LD(u[k]);
  const LD n = std::sqrt(n2);
  const V got = hb::near_unit_normalized(u);
  double e = 0.0;
  for (int k = 0; k < u.size(); ++k) e = std::max(e, double(std::abs(LD(got[k]) - LD(u[k]) / n)));
  return e;
}

TEST(NearUnit, NewtonStepIsWithinRoundingOfLongDouble) {
  pcg64 rng(20261203);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> off(-1e-8, 1e-8);
  double w3 = 0.0, w4 = 0.0, wn3 = 0.0;
  for (int i = 0; i < 100000; ++i) {
    hb::Vec3 u(g(rng), g(rng), g(rng));
    u.normalize();
    // |u|^2 up to 2e-8 off 1 (every fourth), else up to 2e-16 (a few roundings)
    const double s = 1.0 + (i % 4 == 0 ? 1.0 : 1e-8) * off(rng);
    w3 = std::max(w3, error_against_long_double(hb::Vec3(s * u)));
    // the same vector through normalized(): the twin's own rounding, for scale
    wn3 = std::max(wn3, double((hb::Vec3(s * u).normalized() - hb::near_unit_normalized(hb::Vec3(s * u)))
                                   .cwiseAbs()
                                   .maxCoeff()));
    Eigen::Vector4d q(g(rng), g(rng), g(rng), g(rng));
    q.normalize();
    w4 = std::max(w4, error_against_long_double(Eigen::Vector4d(s * q)));
  }
  // normalized() itself is off the long double result by up to 2.5e-16 over 10^6 such vectors
  // (the Newton step by up to 2.3e-16): both round a few times near 1
  EXPECT_LT(w3, 3e-16);
  EXPECT_LT(w4, 3e-16);
  std::printf("max error: Vec3 %.2e, quaternion %.2e (differs from normalized() by %.2e)\n", w3, w4,
              wn3);
}

TEST(NearUnit, FarFromTheSphereIsNormalizedItself) {
  pcg64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int i = 0; i < 1000; ++i) {
    const hb::Vec3 u = (1.0 + 1e-7 + std::abs(g(rng))) * hb::Vec3(g(rng), g(rng), g(rng)).normalized();
    EXPECT_EQ(hb::near_unit_normalized(u), u.normalized());
  }
  EXPECT_EQ(hb::near_unit_normalized(hb::Vec3(0.0, 0.0, 3.0)), hb::Vec3(0.0, 0.0, 1.0));
  EXPECT_EQ(hb::near_unit_normalized(hb::Vec3(1.0, 0.0, 0.0)), hb::Vec3(1.0, 0.0, 0.0));
}

}  // namespace
