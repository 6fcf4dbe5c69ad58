// Uniform-density moments of inertia (shapes/inertia.hpp): closed forms (sphere, ellipsoid,
// octahedron, paraboloid pair), the superquadric's Dirichlet integral vs Superquadric::volume()
// and vs the ellipsoid at exponents 2, an independent nested tanh-sinh quadrature of the second
// moments over the body, and the large-exponent (box) limit with its 1/e^2 approach.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "shapes/ellipsoid.hpp"
#include "shapes/inertia.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

double rel_err(double got, double want) { return std::abs(got - want) / std::abs(want); }
double max_rel_err(const Vec3& got, const Vec3& want) {
  double e = 0.0;
  for (int i = 0; i < 3; ++i) e = std::max(e, rel_err(got[i], want[i]));
  return e;
}

// ---- 1. closed forms --------------------------------------------------------------------------

TEST(Inertia, SphereAndEllipsoidClosedForms) {
  // 2/5 m r^2 with m = 5, r = 2: 8.
  const Vec3 Is = uniform_inertia(Sphere{2.0}, 5.0);
  EXPECT_LT(max_rel_err(Is, Vec3(8.0, 8.0, 8.0)), 1e-15) << Is.transpose();
  // m/5 (b^2+c^2, a^2+c^2, a^2+b^2) with m = 5, (a, b, c) = (1, 2, 3): (13, 10, 5).
  const Vec3 Ie = uniform_inertia(Ellipsoid{1.0, 2.0, 3.0}, 5.0);
  EXPECT_LT(max_rel_err(Ie, Vec3(13.0, 10.0, 5.0)), 1e-15) << Ie.transpose();
  // A sphere and the ellipsoid a = b = c = r agree.
  EXPECT_LT(max_rel_err(uniform_inertia(Ellipsoid{0.7, 0.7, 0.7}, 1.3),
                        uniform_inertia(Sphere{0.7}, 1.3)),
            1e-15);
}

TEST(Inertia, SuperquadricExponentsTwoIsTheEllipsoid) {
  double worst = 0.0;
  for (const Vec3& ax : {Vec3(1, 1, 1), Vec3(0.7, 1.3, 2.1), Vec3(3.0, 0.2, 0.9)}) {
    const Superquadric q(ax[0], ax[1], ax[2], 2.0, 2.0, 2.0);
    const Ellipsoid e{ax[0], ax[1], ax[2]};
    const double err = max_rel_err(uniform_inertia(q, 2.5), uniform_inertia(e, 2.5));
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-13) << ax.transpose();
  }
  std::printf("superquadric(2,2,2) vs ellipsoid: max rel err %.2e\n", worst);
}

TEST(Inertia, DirichletIntegralVolumeMatchesSuperquadricVolume) {
  double worst = 0.0;
  const double shapes[][6] = {{1, 1, 1, 2, 2, 2},       {0.7, 1.3, 2.1, 2, 2, 4},
                              {0.7, 1.3, 2.1, 3, 5, 12}, {1.5, 0.4, 0.9, 2, 2, 40},
                              {1, 2, 3, 100, 7.5, 2.5},  {0.3, 0.5, 0.2, 400, 400, 400}};
  for (const auto& s : shapes) {
    const Superquadric q(s[0], s[1], s[2], s[3], s[4], s[5]);
    const double V = superquadric_moment(q, Vec3::Zero());
    const double err = rel_err(V, q.volume());
    worst = std::max(worst, err);
    EXPECT_LT(err, 1e-13) << q.exponents().transpose();
    // The second moments from J(2,0,0)/J(0) (a different code path) equal the mean squares used
    // by uniform_inertia.
    const Vec3 msq = superquadric_mean_squares(q.axes(), q.exponents());
    for (int i = 0; i < 3; ++i) {
      Vec3 k = Vec3::Zero();
      k[i] = 2.0;
      EXPECT_LT(rel_err(superquadric_moment(q, k) / V, msq[i]), 1e-13) << i;
    }
  }
  std::printf("Dirichlet volume vs Superquadric::volume(): max rel err %.2e\n", worst);
}

// Exponents below 2 are not engine shapes, but the integral holds for any positive exponents and
// has textbook closed forms there, away from the ellipsoid point:
//   |x/a| + |y/b| + |z/c| <= 1 (octahedron): V = 4/3 abc, <x^2> = a^2/10;
//   (x/a)^2 + (y/b)^2 + |z/c| <= 1 (two paraboloids): V = pi abc, <x^2> = a^2/6, <z^2> = c^2/6
//   (slices of area pi ab (1 - |z|/c); the regular octahedron a = b = c gives I = m a^2/5).
TEST(Inertia, DirichletIntegralOtherClosedForms) {
  const Vec3 ax(0.8, 1.7, 2.3);
  const double a = ax[0], b = ax[1], c = ax[2];
  const Vec3 oct(1, 1, 1), par(2, 2, 1);
  EXPECT_LT(rel_err(superquadric_moment(ax, oct, Vec3::Zero()), 4.0 / 3.0 * a * b * c), 1e-14);
  EXPECT_LT(max_rel_err(superquadric_mean_squares(ax, oct), ax.cwiseAbs2() / 10.0), 1e-14);
  EXPECT_LT(rel_err(superquadric_moment(ax, par, Vec3::Zero()), kPi * a * b * c), 1e-14);
  EXPECT_LT(max_rel_err(superquadric_mean_squares(ax, par), ax.cwiseAbs2() / 6.0), 1e-14);
  EXPECT_LT(max_rel_err(inertia_from_mean_squares(superquadric_mean_squares(Vec3(2, 2, 2), oct),
                                                  3.0),
                        Vec3::Constant(3.0 * 4.0 / 5.0)),
            1e-14);
}

// ---- 2. independent quadrature ----------------------------------------------------------------
//
// Nested tanh-sinh (double-exponential) quadrature over the first octant, multiplied by 8:
//     x = a s,  y = y_max(x) w,  y_max = b r^(1/m),  r = 1 - s^n,
//     z_max(x, y) = c (r (1 - w^m))^(1/p),
//     V   = 8 a int int y_max z_max ds dw,          M_x = 8 a int int y_max (a s)^2 z_max,
//     M_y = 8 a int int y_max (y_max w)^2 z_max,    M_z = 8 a int int y_max z_max^3 / 3,
// with no Gamma functions and no Dirichlet substitution.  The integrands are analytic inside
// (0, 1)^2 and have algebraic endpoint singularities ((1 - w)^(1/p), (1 - s)^(1/m + 1/p), s^n
// for non-integer n), exactly the case where tanh-sinh converges like exp(-c / h).  The nodes carry
// both s and 1 - s (computed separately) so that 1 - s^n near s = 1 is formed without
// cancellation.  The truncation |t| <= 4 leaves weights below 1e-36 (the integrands are bounded).
struct TsNode {
  double s, cs, w;  // abscissa in (0, 1), 1 - s, weight
};
std::vector<TsNode> tanh_sinh(double h) {
  std::vector<TsNode> nodes;
  const int K = static_cast<int>(std::ceil(4.0 / h));
  for (int k = -K; k <= K; ++k) {
    const double t = k * h, u = 0.5 * kPi * std::sinh(t);
    const double ch = std::cosh(u);
    nodes.push_back({1.0 / (1.0 + std::exp(-2.0 * u)), 1.0 / (1.0 + std::exp(2.0 * u)),
                     h * 0.25 * kPi * std::cosh(t) / (ch * ch)});
  }
  return nodes;
}
// 1 - s^e from s and cs = 1 - s, accurate at both ends.
double one_minus_pow(double s, double cs, double e) {
  const double ls = s < 0.5 ? std::log(s) : std::log1p(-cs);
  return -std::expm1(e * ls);
}

struct Moments {
  double V;
  Vec3 M;  // int x^2, y^2, z^2 dV
};
Moments quadrature(const Superquadric& q, double h) {
  const auto nodes = tanh_sinh(h);
  Moments R{0.0, Vec3::Zero()};
  for (const TsNode& X : nodes) {
    const double r = one_minus_pow(X.s, X.cs, q.n);
    if (!(r > 0.0)) continue;
    const double x = q.a * X.s, ymax = q.b * std::pow(r, 1.0 / q.m);
    double v = 0.0, mx = 0.0, my = 0.0, mz = 0.0;
    for (const TsNode& Y : nodes) {
      const double r2 = r * one_minus_pow(Y.s, Y.cs, q.m);
      if (!(r2 > 0.0)) continue;
      const double zmax = q.c * std::pow(r2, 1.0 / q.p), y = ymax * Y.s;
      v += Y.w * zmax;
      mx += Y.w * x * x * zmax;
      my += Y.w * y * y * zmax;
      mz += Y.w * zmax * zmax * zmax / 3.0;
    }
    const double f = 8.0 * q.a * ymax * X.w;
    R.V += f * v;
    R.M += f * Vec3(mx, my, mz);
  }
  return R;
}

TEST(Inertia, SuperquadricSecondMomentsMatchQuadrature) {
  // Tolerances.  Level h = 1/16 is compared with h = 1/32 (about twice as many correct digits, so
  // |Q_16 - Q_32| bounds the error of Q_16 and Q_32 is much better): measured |Q_16/Q_32 - 1| is
  // <= ~1e-15 for these shapes, i.e. the reference is at the rounding level (~1e-14 for
  // ~10^5 terms), so the analytic moments must agree with Q_32 to 1e-12 relative (two orders
  // above the rounding of the quadrature and the lgamma ratios; any error in a formula factor is
  // >= 1e-3 here).  The test asserts the self-convergence bound too, so a quadrature that failed
  // to converge would show up as such rather than as a formula error.
  const double shapes[][6] = {
      {1.0, 0.6, 1.4, 2, 2, 4},     {0.9, 1.3, 0.5, 2, 2, 8},     {1.2, 0.7, 0.9, 3, 5, 12},
      {0.8, 1.1, 1.6, 2, 2, 40},    {1.6, 1.1, 0.8, 40, 2, 2},    {0.5, 1.0, 1.5, 2.5, 7.3, 3.7},
      {1.0, 1.4, 0.6, 20, 6, 100},  {0.3, 0.5, 0.2, 400, 400, 400}};
  double worst_conv = 0.0, worst_vol = 0.0, worst_msq = 0.0, worst_I = 0.0;
  for (const auto& s : shapes) {
    const Superquadric q(s[0], s[1], s[2], s[3], s[4], s[5]);
    const Moments Q1 = quadrature(q, 1.0 / 16.0), Q2 = quadrature(q, 1.0 / 32.0);
    double conv = rel_err(Q1.V, Q2.V);
    for (int i = 0; i < 3; ++i) conv = std::max(conv, rel_err(Q1.M[i], Q2.M[i]));
    worst_conv = std::max(worst_conv, conv);
    EXPECT_LT(conv, 1e-13) << "quadrature not converged for " << q.exponents().transpose();

    const double ev = rel_err(q.volume(), Q2.V);
    const Vec3 msq_q = Q2.M / Q2.V;
    const double em = max_rel_err(superquadric_mean_squares(q.axes(), q.exponents()), msq_q);
    const double mass = 1.7;
    const Vec3 I_q = mass * Vec3(msq_q[1] + msq_q[2], msq_q[0] + msq_q[2], msq_q[0] + msq_q[1]);
    const double eI = max_rel_err(uniform_inertia(q, mass), I_q);
    worst_vol = std::max(worst_vol, ev);
    worst_msq = std::max(worst_msq, em);
    worst_I = std::max(worst_I, eI);
    EXPECT_LT(ev, 1e-12) << q.exponents().transpose();
    EXPECT_LT(em, 1e-12) << q.exponents().transpose();
    EXPECT_LT(eI, 1e-12) << q.exponents().transpose();
  }
  std::printf(
      "quadrature: self-convergence %.2e, volume %.2e, mean squares %.2e, inertia %.2e (max rel)\n",
      worst_conv, worst_vol, worst_msq, worst_I);
}

// ---- 3. large exponents: the box limit --------------------------------------------------------
//
// As all exponents -> infinity the body fills [-a, a] x [-b, b] x [-c, c], I -> m/3 (b^2 + c^2,
// a^2 + c^2, a^2 + b^2).  The approach is quadratic: with eps_i = 1/e_i and
// ln Gamma(1 + e) = -gamma e + sum_{k>=2} (-1)^k zeta(k) e^k / k, the header's Gamma ratio gives
//     ln(<x^2> / (a^2/3))
//         = sum_{k>=2} (-1)^k zeta(k)/k [(3 eps_x)^k - eps_x^k + s^k - (s + 2 eps_x)^k]
// (s = sum eps_i; the k = 1 terms cancel) = -(pi^2/3) eps_x (eps_y + eps_z) + O(eps^3).  At
// exponents 400 the relative deficit of each moment is therefore ~4e-5, not ~1e-2: a 1 % tolerance
// would also pass a formula missing the Gamma(1 + s) / Gamma(1 + s + 2/n) factor (a deficit
// 2 gamma / n = 2.9e-3) or one with an O(1/n) error of any kind.  Here the deficit must lie in
// (0, 1e-4] (above 0: the body is strictly inside the box; 1e-4 = 2.4x the leading term), and it
// must equal the series above summed to k = 8 (remainder ~ zeta(9)/9 (s + 2 eps_x)^9 < 1e-16)
// to 1e-12.
double box_log_deficit_series(const Vec3& e, int i) {
  static const double zeta[] = {0.0,                  0.0,
                                kPi * kPi / 6.0,      1.2020569031595943,
                                std::pow(kPi, 4) / 90, 1.0369277551433699,
                                1.0173430619844491,   1.0083492773819228,
                                1.0040773561979443};  // zeta(k), k = 0..8 (0, 1 unused)
  const Vec3 eps = e.cwiseInverse();
  const double s = eps.sum(), x = eps[i];
  double sum = 0.0;
  for (int k = 2; k <= 8; ++k)
    sum += (k % 2 == 0 ? 1.0 : -1.0) * zeta[k] / k *
           (std::pow(3.0 * x, k) - std::pow(x, k) + std::pow(s, k) - std::pow(s + 2.0 * x, k));
  return sum;
}

TEST(Inertia, LargeExponentsApproachTheBox) {
  const Vec3 ax(0.6, 1.1, 1.9);
  const double mass = 2.3;
  const Vec3 I_box = mass / 3.0 *
                     Vec3(ax[1] * ax[1] + ax[2] * ax[2], ax[0] * ax[0] + ax[2] * ax[2],
                          ax[0] * ax[0] + ax[1] * ax[1]);
  double max_def = 0.0, min_def = 1.0, worst_series = 0.0;
  for (const Vec3& e : {Vec3(400, 400, 400), Vec3(300, 500, 400), Vec3(1e4, 1e4, 1e4)}) {
    const Superquadric q(ax[0], ax[1], ax[2], e[0], e[1], e[2]);
    const Vec3 I = uniform_inertia(q, mass);
    const Vec3 msq = superquadric_mean_squares(q.axes(), q.exponents());
    for (int i = 0; i < 3; ++i) {
      const double def = 1.0 - I[i] / I_box[i];
      max_def = std::max(max_def, def);
      min_def = std::min(min_def, def);
      EXPECT_GT(def, 0.0) << e.transpose() << " axis " << i;
      EXPECT_LT(def, 1e-4) << e.transpose() << " axis " << i;
      // Same deficit in the mean square, against the independent series (absolute error of the
      // log, i.e. relative error of <x_i^2>).
      const double series = box_log_deficit_series(e, i);
      const double err = std::abs(std::log(msq[i] / (ax[i] * ax[i] / 3.0)) - series);
      worst_series = std::max(worst_series, err);
      EXPECT_LT(err, 1e-12) << e.transpose() << " axis " << i;
    }
  }
  // The limit itself: exponents so large that every Gamma argument rounds to 1.
  const Superquadric huge(ax[0], ax[1], ax[2], 1e300, 1e300, 1e300);
  EXPECT_LT(max_rel_err(uniform_inertia(huge, mass), I_box), 1e-15);
  std::printf("box limit: deficit 1 - I/I_box in [%.2e, %.2e], series max err %.2e\n", min_def,
              max_def, worst_series);
}

}  // namespace
}  // namespace hb

TEST(Inertia, DispatchThroughTheRegistry) {
  using namespace hb;
  EXPECT_EQ(uniform_inertia(AnyShape(Ellipsoid{1, 2, 3}), 5.0), uniform_inertia(Ellipsoid{1, 2, 3}, 5.0));
  const Superquadric q{1.0, 0.8, 0.5, 2.0, 3.5, 12.0};
  EXPECT_EQ(uniform_inertia(AnyShape(q), 2.0), uniform_inertia(q, 2.0));
}
