// Superquadric shape: derivatives vs finite differences (also next to the coordinate planes and
// for exponents up to 40), zero set vs the paper's function, volume, ray, bounding radius and
// support function against their definitions, and the all-exponents-2 case vs Ellipsoid.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "geometry/random_pairs.hpp"
#include "geometry/reference_superquadric.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

// Exponent drawn from {2} or [3, emax] (for e in (2, 3) the Hessian ~ |x_i|^(e-2) is not
// Lipschitz at the coordinate planes and central differences there are inaccurate).
double random_exponent(Rng& r, double emax) {
  if (r.uni(0, 1) < 0.25) return 2.0;
  return r.uni(0, 1) < 0.5 ? std::round(r.uni(3.0, emax)) : r.uni(3.0, emax);
}

Superquadric random_sq(Rng& r, double emax) {
  return Superquadric{r.log_uni(0.2, 2.0), r.log_uni(0.2, 2.0), r.log_uni(0.2, 2.0),
                      random_exponent(r, emax), random_exponent(r, emax),
                      random_exponent(r, emax)};
}

// A point at radius factor k of the surface along a random ray, with one or two coordinates
// moved to within `near` of their coordinate planes (then rescaled back to the factor k).
Vec3 random_point(Rng& r, const Superquadric& s, double k, double near) {
  Vec3 x = s.ray_surface(r.unit());
  const int first = static_cast<int>(r.uni(0, 3)), count = r.uni(0, 1) < 0.5 ? 1 : 2;
  for (int j = 0; j < count; ++j) {
    const int i = (first + j) % 3;
    x[i] = (r.uni(0, 1) < 0.5 ? -1 : 1) * near * r.uni(0.5, 1.0);
  }
  return k * s.ray_surface(x);  // the near-plane coordinates scale by O(1) factors
}

// Central differences with a per-coordinate step that never crosses a coordinate plane.
struct FdError {
  double grad = 0, hess = 0;
};
FdError fd_error(const Superquadric& s, const Vec3& x) {
  const double L = s.bounding_radius();
  Vec3 g_fd;
  Mat3 h_fd;
  for (int i = 0; i < 3; ++i) {
    // F varies on the scale |x_i| in x_i where t_i^e_i is a sizeable part of S: the step is
    // 1e-4 |x_i| there; coordinates within 1e-5 L of their plane hardly enter F (t_i^e_i <=
    // 1e-10), and a step of 0.1 |x_i| (never crossing the plane) keeps rounding small.
    const double xi = std::abs(x[i]);
    const double h = xi < 1e-5 * L ? 0.1 * xi + 1e-300 : std::min(1e-5 * L, 1e-4 * xi);
    Vec3 e = Vec3::Zero();
    e[i] = h;
    g_fd[i] = (s.f(x + e) - s.f(x - e)) / (2 * h);
    h_fd.col(i) = (s.grad(x + e) - s.grad(x - e)) / (2 * h);
  }
  const Vec3 g = s.grad(x);
  const Mat3 H = s.hessian(x);
  // The Hessian relative to its natural scale (E-1)|g|^2 / (1+F), the size of each of the two
  // terms whose difference it is (F is nearly linear where one power dominates, and there
  // |H| itself is ~0).
  const double scale = std::max(H.norm(), (s.e_max() - 1) * g.squaredNorm() / (1 + s.f(x)));
  return FdError{(g - g_fd).norm() / g.norm(), (H - h_fd).norm() / scale};
}

TEST(Superquadric, DerivativesMatchFiniteDifferences) {
  Rng r(101);
  double worst_g = 0, worst_h = 0;
  const int shapes = scaled_count(300, 0.1);
  for (int k = 0; k < shapes; ++k) {
    const Superquadric s = random_sq(r, k % 3 == 0 ? 40.0 : 20.0);
    for (int j = 0; j < 10; ++j) {
      const double near = j < 5 ? 1e-8 * s.inscribed_radius() : 1e-3;
      const Vec3 x = random_point(r, s, r.uni(0.8, 1.5), near);
      const FdError e = fd_error(s, x);
      worst_g = std::max(worst_g, e.grad);
      worst_h = std::max(worst_h, e.hess);
      EXPECT_LE(e.grad, 1e-6) << "shape " << s.a << " " << s.b << " " << s.c << " exps " << s.n
                              << " " << s.m << " " << s.p << " x " << x.transpose();
      EXPECT_LE(e.hess, 1e-6) << "shape " << s.a << " " << s.b << " " << s.c << " exps " << s.n
                              << " " << s.m << " " << s.p << " x " << x.transpose();
    }
  }
  std::printf("  max relative FD error: grad %.2e, Hessian %.2e\n", worst_g, worst_h);
}

TEST(Superquadric, FiniteEverywhereAndOnCoordinatePlanes) {
  for (const Superquadric& s : {Superquadric{1.0, 0.5, 2.0, 20, 2, 40},
                               Superquadric{0.3, 1.0, 1.0, 100, 100, 2.5},
                               Superquadric{1.0, 1.0, 1.0, 2, 2, 2}}) {
    for (const Vec3& x : {Vec3(1e-5, 0, 0), Vec3(0, 0, 1e-5), Vec3(1e-8, 0.5, 0),
                         Vec3(0, 0, 0.99 * s.c), Vec3(1e12, -3e11, 7e10), Vec3(1e200, 1, 1),
                         Vec3(0.5, -0.2, 1e-320), Vec3(3 * s.a, 0, 0)}) {
      EXPECT_TRUE(std::isfinite(s.f(x))) << x.transpose();
      EXPECT_TRUE(s.grad(x).allFinite()) << x.transpose();
      EXPECT_TRUE(s.hessian(x).allFinite()) << x.transpose();
      EXPECT_GT(s.grad(x).norm(), 0.0) << x.transpose();
    }
    // On a coordinate plane the gradient has no component across it and the Hessian is
    // finite (its diagonal entry is 0 for exponents > 2: a flat face centre).
    const Vec3 x(0.3 * s.a, 0.0, 0.4 * s.c);
    EXPECT_EQ(s.grad(x)[1], 0.0);
    EXPECT_TRUE(s.hessian(x).allFinite());
    EXPECT_DOUBLE_EQ(s.f(Vec3::Zero()), -1.0);
    // (towards the centre, mixed exponents make F ~ t_i^(e_i/E) with a Hessian ~ S^(1/E-1) that
    // overflows within ~1e-300^(1/e_max) of the centre, where no solver goes)
    // far away F grows no faster than linearly (|x| / min axis)
    EXPECT_LE(s.f(Vec3(1e6, 1e6, 1e6)), 2e6 / s.inscribed_radius());
  }
}

TEST(Superquadric, ZeroSetIsThePapersFunction) {
  Rng r(102);
  for (int k = 0; k < scaled_count(200, 0.2); ++k) {
    const Superquadric s = random_sq(r, 20.0);
    const ref::SlowSuperquadric paper{s.a, s.b, s.c, s.n, s.m, s.p};
    for (int j = 0; j < 50; ++j) {
      const Vec3 x = r.ball(1.3 * s.bounding_radius());
      const double f = s.f(x), g = paper.f(x);
      if (std::abs(g) > 1e-12) {
        EXPECT_EQ(f < 0, g < 0) << f << " " << g;
      }
      // exactly: F = (f_paper + 1)^(1/E) - 1 (g + 1 = S loses digits when S << 1)
      const double S = g + 1.0;
      EXPECT_NEAR(f, std::pow(S, 1.0 / s.e_max()) - 1.0,
                  1e-13 * (1 + std::abs(f)) + 1e-15 * std::pow(S, 1.0 / s.e_max()) / S);
    }
  }
}

TEST(Superquadric, Volume) {
  // closed forms: exponents 2 -> ellipsoid; n = m = p -> large exponents tend to the box
  EXPECT_NEAR((Superquadric{1.0, 2.0, 3.0, 2, 2, 2}.volume()), 8.0 * kPi, 1e-12);
  EXPECT_NEAR((Superquadric{1.0, 2.0, 3.0, 1e6, 1e6, 1e6}.volume()), 48.0, 1e-3);
  Rng r(103);
  for (int k = 0; k < 6; ++k) {
    const Superquadric s = random_sq(r, 20.0);
    std::mt19937_64 g(7 + k);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const int n = scaled_count(400000, 0.05);
    int inside = 0;
    for (int i = 0; i < n; ++i)
      if (s.f(Vec3(u(g) * s.a, u(g) * s.b, u(g) * s.c)) < 0) ++inside;
    const double box = 8.0 * s.a * s.b * s.c, frac = double(inside) / n;
    const double sigma = box * std::sqrt(frac * (1 - frac) / n);
    EXPECT_NEAR(box * frac, s.volume(), 5 * sigma) << s.n << " " << s.m << " " << s.p;
  }
}

TEST(Superquadric, RaySurface) {
  Rng r(104);
  double worst = 0;
  for (int k = 0; k < scaled_count(200, 0.2); ++k) {
    const Superquadric s = random_sq(r, k % 2 ? 40.0 : 16.0);
    const ref::SlowSuperquadric paper{s.a, s.b, s.c, s.n, s.m, s.p};
    for (int j = 0; j < 20; ++j) {
      Vec3 u = r.unit() * r.log_uni(1e-3, 1e3);
      if (j % 4 == 0) u[j % 3] = 0.0;  // rays in the coordinate planes
      const Vec3 x = s.ray_surface(u);
      worst = std::max(worst, std::abs(s.f(x)));
      EXPECT_NEAR(s.f(x), 0.0, 1e-14);
      EXPECT_NEAR(paper.f(x), 0.0, 1e-13 * s.e_max());
      EXPECT_GT(x.normalized().dot(u.normalized()), 1.0 - 1e-14);
      EXPECT_LE((x - ray_surface_generic(s, u)).norm(), 1e-13 * s.bounding_radius());
      EXPECT_LE(x.norm(), s.bounding_radius());
      EXPECT_GE(x.norm(), s.inscribed_radius() * (1 - 1e-14));
    }
  }
  std::printf("  max |F(ray_surface)| %.2e\n", worst);
}

TEST(Superquadric, BoundingRadiusIsTheFarthestSurfacePoint) {
  // closed forms
  EXPECT_NEAR((Superquadric{0.5, 1.5, 1.0, 2, 2, 2}.bounding_radius()), 1.5, 1e-11);
  EXPECT_NEAR((Superquadric{1.0, 1.0, 1.0, 4, 4, 4}.bounding_radius()), std::pow(3.0, 0.25),
              1e-11);  // corner (1,1,1) 3^(-1/4)
  EXPECT_NEAR((Superquadric{1.0, 1.0, 1.0, 2, 2, 1e3}.bounding_radius()), std::sqrt(2.0), 1e-2);
  Rng r(105);
  for (int k = 0; k < scaled_count(100, 0.2); ++k) {
    const Superquadric s = random_sq(r, 20.0);
    const double L = s.bounding_radius();
    const Vec3 xf = s.farthest_point();
    EXPECT_NEAR(s.f(xf), 0.0, 1e-14);
    EXPECT_NEAR(xf.norm(), L, 1e-11 * L);
    // stationary: the outward normal at the farthest point is parallel to x
    EXPECT_GT(s.grad(xf).normalized().dot(xf.normalized()), 1.0 - 1e-9);
    double best = 0;
    for (int j = 0; j < scaled_count(20000, 0.05); ++j) {
      const double d = s.ray_surface(r.unit()).norm();
      best = std::max(best, d);
      ASSERT_LE(d, L);
    }
    // and no nearby surface point is farther (local perturbations of xf)
    for (int j = 0; j < 200; ++j)
      EXPECT_LE(s.ray_surface(xf + 1e-3 * L * r.unit()).norm(), L);
    EXPECT_GE(best, 0.97 * L);
  }
}

TEST(Superquadric, SupportFunction) {
  Rng r(106);
  double worst_f = 0, worst_dot = 0;
  for (int k = 0; k < scaled_count(200, 0.1); ++k) {
    const Superquadric s = random_sq(r, k % 2 ? 30.0 : 16.0);
    const ref::SlowSuperquadric slow{s.a, s.b, s.c, s.n, s.m, s.p};
    const double L = s.bounding_radius();
    for (int j = 0; j < 10; ++j) {
      Vec3 d = r.unit() * r.log_uni(0.1, 10.0);
      if (j == 0) d[k % 3] = 0.0;
      const Vec3 x = s.support_point(d);
      worst_f = std::max(worst_f, std::abs(s.f(x)));
      EXPECT_NEAR(s.f(x), 0.0, 1e-13);
      EXPECT_NEAR(s.support(d), x.dot(d), 1e-15 * L * d.norm());
      const double par = s.grad(x).normalized().dot(d.normalized());
      worst_dot = std::max(worst_dot, 1 - par);
      EXPECT_GT(par, 1.0 - 1e-13);
      // agrees with the independent bisection
      EXPECT_NEAR(s.support(d), slow.support(d), 1e-14 * L * d.norm());
      EXPECT_LE((x - slow.support_point(d)).norm(), 1e-12 * L);
      // maximises d.x: dense sampling of the surface never does better
      for (int q = 0; q < 200; ++q)
        EXPECT_LE(s.ray_surface(r.unit()).dot(d), s.support(d) * (1 + 1e-14));
      // support_point = grad h, support_hessian = Hessian of h (central differences)
      if (j == 0) continue;  // on a coordinate plane with e > 2 the Hessian is infinite
      // x_i ~ |d_i|^(1/(e_i-1)) varies on the scale |d_i|: the step is at most 1e-4 |d_i|
      Mat3 hfd;
      for (int i = 0; i < 3; ++i) {
        const double h = std::min(1e-6 * d.norm(), 1e-4 * std::abs(d[i]));
        Vec3 e = Vec3::Zero();
        e[i] = h;
        // truncation ~1e-8 relative; rounding: each support value is good to the 1e-14 L |d|
        // asserted above, so the quotient to 1e-14 L |d| / h
        EXPECT_NEAR((s.support(d + e) - s.support(d - e)) / (2 * h), x[i],
                    1e-8 * L + 1e-14 * L * d.norm() / h);
        hfd.col(i) = (s.support_point(d + e) - s.support_point(d - e)) / (2 * h);
      }
      const Mat3 H = s.support_hessian(d);
      EXPECT_LE((hfd - H).norm(), 1e-5 * H.norm()) << s.n << " " << s.m << " " << s.p;
      EXPECT_LE((H * d).norm(), 1e-9 * H.norm() * d.norm());  // h is 1-homogeneous
    }
  }
  std::printf("  support: max |F(x)| %.2e, max 1 - cos(normal, d) %.2e\n", worst_f, worst_dot);
}

// The closed form of the support Hessian's quadratic forms (multiplier from the support point,
// powers by squaring for integer exponents) against the matrix support_hessian: random shapes
// with integer and non-integer exponents up to 40, directions in general position, next to a
// coordinate plane (|d_i| down to 1e-12 |d|, where t_i^(2-e_i) is huge) and on one (the cap).
TEST(Superquadric, SupportHessianFormsMatchTheSupportHessian) {
  Rng r(108);
  double worst = 0;
  for (int k = 0; k < scaled_count(400, 0.1); ++k) {
    const Superquadric s = random_sq(r, k % 2 ? 40.0 : 12.0);
    for (int j = 0; j < 10; ++j) {
      Vec3 d = r.unit() * r.log_uni(0.1, 10.0);
      if (j == 1) d[k % 3] = 0.0;
      if (j == 2) d[k % 3] *= r.log_uni(1e-12, 1e-3);
      const Vec3 x = s.support_point(d);
      const Vec3 u = r.unit(), v = r.unit();
      const Mat3 H = s.support_hessian(d);
      const Vec3 want(u.dot(H * u), v.dot(H * u), v.dot(H * v));
      const double err = (s.support_hessian_forms(d, x, u, v) - want).norm() / H.norm();
      worst = std::max(worst, err);
      EXPECT_LE(err, 1e-12) << s.n << " " << s.m << " " << s.p << " j=" << j;
    }
  }
  std::printf("  support Hessian forms vs matrix: max error %.2e of |H|\n", worst);
}

// (2, 2, p) bodies with integer p take their own support-point solver (a polynomial in t_p,
// no power per iteration): against the long-double bisection for every p in 3..64, the flat
// axis on x, y or z, directions in general position, near the flat axis (K down to 1e-24) and
// near its plane (K up to 1e24, and d_p = 0, which takes the general solver).
TEST(Superquadric, FlatAxisSupportPointMatchesBisection) {
  Rng r(109);
  double worst_x = 0, worst_f = 0, worst_par = 0, worst_h = 0;
  for (int p = 3; p <= 64; ++p) {
    for (int k = 0; k < 3; ++k) {
      Vec3 ax(r.log_uni(0.2, 2.0), r.log_uni(0.2, 2.0), r.log_uni(0.2, 2.0)), e(2, 2, 2);
      e[k] = p;
      const Superquadric s{ax[0], ax[1], ax[2], e[0], e[1], e[2]};
      const ref::SlowSuperquadric slow{s.a, s.b, s.c, s.n, s.m, s.p};
      const double L = s.bounding_radius();
      for (int j = 0; j < 12; ++j) {
        Vec3 d = r.unit() * r.log_uni(0.1, 10.0);
        if (j % 4 == 1) d[k] *= r.log_uni(1e-12, 1e-2);           // near the plane of axis k
        if (j % 4 == 2) d[(k + 1) % 3] *= r.log_uni(1e-12, 1e-2),  // near axis k
                        d[(k + 2) % 3] *= r.log_uni(1e-12, 1e-2);
        if (j == 3) d[k] = 0.0;
        const Vec3 x = s.support_point(d);
        worst_x = std::max(worst_x, (x - slow.support_point(d)).norm() / L);
        worst_f = std::max(worst_f, std::abs(s.f(x)));
        EXPECT_LE((x - slow.support_point(d)).norm(), 1e-12 * L) << p << " " << k << " " << j;
        EXPECT_NEAR(s.f(x), 0.0, 1e-13);
        if (j == 3) continue;  // the normal is not defined at the flat face's rim when d_k = 0
        const double par = s.grad(x).normalized().dot(d.normalized());
        worst_par = std::max(worst_par, 1 - par);
        EXPECT_GT(par, 1.0 - 1e-13) << p << " " << k << " " << j;
        // the solver's multiplier lambda (from the root: 1 / x^(p-1) = x + K x^(p-1)) scales
        // the support Hessian; the forms take theirs from x (lambda = d.x / sum e_i t_i^e_i)
        const Vec3 u = r.unit(), v = r.unit();
        const Mat3 H = s.support_hessian(d);
        const Vec3 want(u.dot(H * u), v.dot(H * u), v.dot(H * v));
        const double herr = (s.support_hessian_forms(d, x, u, v) - want).norm() / H.norm();
        worst_h = std::max(worst_h, herr);
        EXPECT_LE(herr, 1e-12) << p << " " << k << " " << j;
      }
    }
  }
  std::printf("  (2, 2, p) support point: max |x - bisection| %.2e L, |F(x)| %.2e, "
              "1 - cos(normal, d) %.2e, Hessian forms vs matrix %.2e\n", worst_x, worst_f,
              worst_par, worst_h);
}

// The (2, 2, p) solver's root (sq_detail::FlatRootTable) against a long-double bisection of
// x^p + K x^(2p-2) = 1, for every p it is fitted for (3..16), at 6 points of every segment
// of the fitted binades (K from 0 to 2^56: 32 segments in the first, 16 in the others), and
// of every segment of binades far beyond (up to K ~ 1e250, where the root is the scaled
// asymptote with its first correction).  The support point takes this root without an
// iteration, so it must be within a few ulps: the bound is 8 ulps of 1 (8 * 2^-53 = 8.9e-16),
// the fit's error being ~1e-17 and the rest the rounding of 9 stored coefficients and of their
// evaluation.
TEST(Superquadric, FlatRootTableIsWithinAFewUlps) {
  auto root = [](int p, long double K) {
    long double lo = 0, hi = 1;  // (x down to ~2^-210: up to ~280 halvings)
    for (int it = 0; it < 2000; ++it) {
      const long double mid = 0.5L * (lo + hi);
      if (!(mid > lo && mid < hi)) break;
      long double xp1 = 1;
      for (int k = 0; k < p - 1; ++k) xp1 *= mid;
      (xp1 * mid + K * xp1 * xp1 - 1 > 0 ? hi : lo) = mid;
    }
    return 0.5L * (lo + hi);
  };
  double worst = 0.0;
  int worst_p = 0;
  for (int p = 3; p <= 16; ++p) {
    const Superquadric s{1.0, 0.7, 0.5, 2, 2, double(p)};
    ASSERT_TRUE(s.has_flat_root_table()) << p;
    std::vector<int> binades;
    for (int E = 0; E < 64; ++E) binades.push_back(E);
    for (int E = 64; E < 830; E += 37) binades.push_back(E);
    for (const int E : binades) {
      const int segs = E == 0 ? 32 : 16;
      for (int j = 0; j < segs; ++j)
        for (int i = 0; i <= 5; ++i) {
          // 1 + K = 2^E (1 + (j + i/5) / segs), the last point just below the segment's end
          const double m = (j + std::min(i / 5.0, 1.0 - 1e-12)) / segs;
          const double K = std::ldexp(1.0 + m, E) - 1.0;
          const long double x = root(p, K);
          const double err = double(std::abs(s.flat_root(K) - x) / x);
          if (err > worst) worst = err, worst_p = p;
          EXPECT_LE(err, 8.9e-16) << "p " << p << " E " << E << " j " << j << " i " << i;
        }
    }
  }
  EXPECT_FALSE((Superquadric{1.0, 0.7, 0.5, 2, 2, 17}.has_flat_root_table()));
  EXPECT_FALSE((Superquadric{1.0, 0.7, 0.5, 2, 3, 8}.has_flat_root_table()));
  std::printf("  (2, 2, p) tabulated root: max relative error %.2e (p = %d)\n", worst, worst_p);
}

TEST(Superquadric, AllExponentsTwoIsTheEllipsoid) {
  Rng r(107);
  for (int k = 0; k < scaled_count(100, 0.2); ++k) {
    const Ellipsoid e = r.ellipsoid();
    const Superquadric s{e.a, e.b, e.c, 2, 2, 2};
    EXPECT_DOUBLE_EQ(s.bounding_radius() / (1 + 1e-12), e.bounding_radius());
    EXPECT_EQ(s.inscribed_radius(), e.inscribed_radius());
    EXPECT_NEAR(s.volume(), e.volume(), 1e-13 * e.volume());
    for (int j = 0; j < 50; ++j) {
      const Vec3 x = r.ball(1.5 * e.bounding_radius());
      EXPECT_NEAR(s.f(x), std::sqrt(e.f(x) + 1) - 1, 1e-14 * (1 + std::abs(s.f(x))));
      // same zero set, same normal direction
      EXPECT_GT(s.grad(x).normalized().dot(e.grad(x).normalized()), 1 - 1e-14);
      const Vec3 u = r.unit();
      EXPECT_LE((s.ray_surface(u) - e.ray_surface(u)).norm(), 1e-14 * e.bounding_radius());
      EXPECT_NEAR(s.support(u), e.support(u), 1e-14 * e.bounding_radius());
      EXPECT_LE((s.support_point(u) - e.support_point(u)).norm(), 1e-13 * e.bounding_radius());
      EXPECT_LE((s.support_hessian(u) - e.support_hessian(u)).norm(),
                1e-11 * e.support_hessian(u).norm());
    }
  }
}

}  // namespace
}  // namespace hb
