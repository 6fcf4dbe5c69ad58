// sin_cos (math/sin_cos.hpp) against its slow twin, the long double std::sin and std::cos: the
// error in ulp of the double result over the polynomial's whole range, near zero, at its edge and
// beyond it (where it must be std::sin and std::cos bit for bit).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <pcg_random.hpp>
#include <random>

#include "math/sin_cos.hpp"

namespace {

// |got - want| in units of the last place of the double nearest to want.
double ulp_error(double got, long double want) {
  const double w = static_cast<double>(want);
  const double ulp = std::nextafter(std::abs(w), std::numeric_limits<double>::infinity()) - std::abs(w);
  return static_cast<double>(std::abs(static_cast<long double>(got) - want) / ulp);
}

struct Worst {
  double s = 0.0, c = 0.0;
  void add(double x) {
    const hb::SinCos r = hb::sin_cos(x);
    const long double lx = x;
    s = std::max(s, ulp_error(r.s, std::sin(lx)));
    c = std::max(c, ulp_error(r.c, std::cos(lx)));
  }
};

TEST(SinCos, PolynomialIsWithinTwoUlpOfLongDouble) {
  pcg64 rng(20261129);
  std::uniform_real_distribution<double> u(-hb::kSinCosPolyMax, hb::kSinCosPolyMax);
  Worst w;
  for (int i = 0; i < 200000; ++i) w.add(u(rng));
  // near zero (log-uniform down to 1e-300, both signs) and at the edge of the range
  std::uniform_real_distribution<double> e(-300.0, 0.0);
  for (int i = 0; i < 20000; ++i) {
    const double x = std::pow(10.0, e(rng));
    w.add(x), w.add(-x);
  }
  double x = hb::kSinCosPolyMax;
  for (int i = 0; i < 1000; ++i, x = std::nextafter(x, 0.0)) w.add(x), w.add(-x);
  w.add(0.0);
  EXPECT_LE(w.s, 2.0);
  EXPECT_LE(w.c, 2.0);
  std::printf("max error: sin %.3f ulp, cos %.3f ulp\n", w.s, w.c);
}

TEST(SinCos, ExactAtZeroAndLibmBeyondTheRange) {
  EXPECT_EQ(hb::sin_cos(0.0).s, 0.0);
  EXPECT_EQ(hb::sin_cos(0.0).c, 1.0);
  pcg64 rng(7);
  std::uniform_real_distribution<double> u(hb::kSinCosPolyMax, 50.0);
  for (int i = 0; i < 1000; ++i) {
    const double x = std::nextafter(u(rng), 100.0) * (i % 2 ? -1.0 : 1.0);
    EXPECT_EQ(hb::sin_cos(x).s, std::sin(x));
    EXPECT_EQ(hb::sin_cos(x).c, std::cos(x));
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(hb::sin_cos(nan).s) && std::isnan(hb::sin_cos(nan).c));
}

}  // namespace
