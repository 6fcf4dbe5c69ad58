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

// sinc_cos_of_square(x^2) against the long double sin(x) / x and cos(x): the same bound as
// sin_cos over the polynomial's range, near zero (where sin(x) / x -> 1) and at its edge.
TEST(SinCos, SincOfTheSquareIsWithinTwoUlpOfLongDouble) {
  pcg64 rng(20261203);
  double ws = 0.0, wc = 0.0;
  auto add = [&](double x) {
    const double z = x * x;
    if (!(z <= hb::kSinCosPolyMax * hb::kSinCosPolyMax)) return;
    const hb::SinCos r = hb::sinc_cos_of_square(z);
    const long double lx = std::sqrt(static_cast<long double>(z));  // the x of the rounded z
    const long double sinc = lx == 0.0L ? 1.0L : std::sin(lx) / lx;
    ws = std::max(ws, ulp_error(r.s, sinc));
    wc = std::max(wc, ulp_error(r.c, std::cos(lx)));
  };
  std::uniform_real_distribution<double> u(0.0, hb::kSinCosPolyMax);
  for (int i = 0; i < 200000; ++i) add(u(rng));
  std::uniform_real_distribution<double> e(-150.0, 0.0);
  for (int i = 0; i < 20000; ++i) add(std::pow(10.0, e(rng)));
  double x = hb::kSinCosPolyMax;
  for (int i = 0; i < 1000; ++i, x = std::nextafter(x, 0.0)) add(x);
  add(0.0);
  EXPECT_EQ(hb::sinc_cos_of_square(0.0).s, 1.0);
  EXPECT_EQ(hb::sinc_cos_of_square(0.0).c, 1.0);
  EXPECT_LE(ws, 2.0);
  EXPECT_LE(wc, 2.0);
  std::printf("max error: sin(x)/x %.3f ulp, cos %.3f ulp\n", ws, wc);
}

}  // namespace
