// Perram–Wertheim contact function: analytic cases, touching by bisection, symmetry,
// monotonicity, and certificates of the answer that do not use the contact function
// (a common interior point when overlapping, a separating plane when disjoint).
#include "geometry/perram_wertheim.hpp"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>

#include <algorithm>
#include <cstdio>
#include <random>

namespace hb {
namespace {

constexpr unsigned kSeed = 987654321u;  // logged in failure messages

Quat random_quat(std::mt19937_64& g) {
  std::normal_distribution<double> N(0.0, 1.0);
  Quat q(N(g), N(g), N(g), N(g));
  q.normalize();
  return q;
}

Vec3 random_unit(std::mt19937_64& g) {
  std::normal_distribution<double> N(0.0, 1.0);
  return Vec3(N(g), N(g), N(g)).normalized();
}

EllipsoidPose random_ellipsoid(std::mt19937_64& g, double lo = 0.2, double hi = 3.0) {
  std::uniform_real_distribution<double> U(lo, hi), P(-5.0, 5.0);
  EllipsoidPose E;
  E.semi_axes = Vec3(U(g), U(g), U(g));
  E.r = Vec3(P(g), P(g), P(g));
  E.q = random_quat(g);
  return E;
}

// Independent of the library: body-frame quadratic form (x - r)^T A (x - r), its lab gradient
// direction, and the support value h(n) = max_{x in E} n.(x - r).
double f_body(const EllipsoidPose& E, const Vec3& x) {
  const Vec3 y = E.q.conjugate() * (x - E.r);
  return sqr(y.x() / E.semi_axes.x()) + sqr(y.y() / E.semi_axes.y()) +
         sqr(y.z() / E.semi_axes.z());
}
Vec3 grad_body(const EllipsoidPose& E, const Vec3& x) {
  const Vec3 y = E.q.conjugate() * (x - E.r);
  const Vec3 gb = y.cwiseQuotient(E.semi_axes.cwiseProduct(E.semi_axes));
  return E.q * gb;  // direction only
}
double support(const EllipsoidPose& E, const Vec3& n) {
  const Vec3 nb = E.q.conjugate() * n;
  return nb.cwiseProduct(E.semi_axes).norm();
}

EllipsoidPose placed(EllipsoidPose E, const Vec3& r) {
  E.r = r;
  return E;
}

TEST(PerramWertheim, SpheresGiveSquaredRatioOfDistanceToContactDistance) {
  std::mt19937_64 g(kSeed);
  std::uniform_real_distribution<double> U(0.1, 5.0), D(0.01, 20.0);
  for (int i = 0; i < 1000; ++i) {
    EllipsoidPose A, B;
    A.semi_axes = Vec3::Constant(U(g));
    B.semi_axes = Vec3::Constant(U(g));
    A.q = random_quat(g);
    B.q = random_quat(g);
    const double d = D(g);
    const Vec3 r = d * random_unit(g);
    const PerramWertheim pw = perram_wertheim(A, B, r);
    const double expect = sqr(d / (A.semi_axes.x() + B.semi_axes.x()));
    EXPECT_NEAR(pw.F, expect, 1e-14 * expect) << "seed " << kSeed << " case " << i;
    EXPECT_NEAR(pw.lambda, A.semi_axes.x() / (A.semi_axes.x() + B.semi_axes.x()), 1e-12);
    EXPECT_EQ(pw.overlap, expect < 1.0 - kPerramWertheimTol);
  }
}

// Two ellipsoids with principal axes along the lab axes and centres on a common axis touch
// when the distance equals the sum of their extents along that axis (a plane separates them).
TEST(PerramWertheim, AlignedEllipsoidsEndToEndSideBySideAndCrossed) {
  const Vec3 a(3.0, 1.0, 0.5), b(2.0, 0.7, 1.3);
  EllipsoidPose A, B;
  A.semi_axes = a;
  B.semi_axes = b;
  const Quat rotz(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitZ()));  // body x -> lab y
  const Quat roty(Eigen::AngleAxisd(0.5 * kPi, Vec3::UnitY()));  // body x -> lab -z
  struct Case {
    const char* name;
    Quat qB;
    Vec3 axis;
    double contact;
  } cases[] = {
      {"end to end (x)", Quat::Identity(), Vec3::UnitX(), a.x() + b.x()},
      {"side by side (y)", Quat::Identity(), Vec3::UnitY(), a.y() + b.y()},
      {"side by side (z)", Quat::Identity(), Vec3::UnitZ(), a.z() + b.z()},
      {"T along x, B turned about z", rotz, Vec3::UnitX(), a.x() + b.y()},
      {"crossed along z, B turned about z", rotz, Vec3::UnitZ(), a.z() + b.z()},
      {"B turned about y, along z", roty, Vec3::UnitZ(), a.z() + b.x()},
      {"B turned about y, along x", roty, Vec3::UnitX(), a.x() + b.z()},
  };
  for (const Case& c : cases) {
    B.q = c.qB;
    for (double d : {0.3, 0.9, 1.0, 1.1, 2.5}) {
      const double dist = d * c.contact;
      const PerramWertheim pw = perram_wertheim(A, B, dist * c.axis);
      EXPECT_NEAR(pw.F, d * d, 1e-14 * d * d) << c.name << " d=" << d;
      // and from the other side, B first
      const PerramWertheim pw2 = perram_wertheim(B, A, -dist * c.axis);
      EXPECT_NEAR(pw2.F, d * d, 1e-14 * d * d) << c.name << " d=" << d;
    }
    EXPECT_NEAR(touching_scale(A, B, c.axis), c.contact, 1e-14 * c.contact) << c.name;
    const PerramWertheim t = perram_wertheim(A, B, c.contact * c.axis);
    EXPECT_LT((t.point - a.cwiseProduct(c.axis).norm() * c.axis).norm(), 1e-13) << c.name;
    EXPECT_LT((t.normal - c.axis).norm(), 1e-14) << c.name;
  }
}

TEST(PerramWertheim, IdenticalParallelEllipsoidsTouchAtTheMidpoint) {
  // C(lambda) = M for all lambda, F = r^T M^-1 r / 4: touching when r/2 is on the surface.
  std::mt19937_64 g(kSeed + 1);
  for (int i = 0; i < 1000; ++i) {
    EllipsoidPose A = random_ellipsoid(g);
    const Vec3 r = random_unit(g) * std::uniform_real_distribution<double>(0.1, 10.0)(g);
    const EllipsoidPose B = placed(A, A.r + r);
    // F = r^T A r / 4 = (r/2)^T A (r/2) = f_A(r_A + r/2)
    const double expect = f_body(A, A.r + 0.5 * r);
    const PerramWertheim pw = perram_wertheim(A, B);
    EXPECT_NEAR(pw.F, expect, 1e-13 * expect) << "seed " << kSeed + 1 << " case " << i;
    EXPECT_NEAR(pw.lambda, 0.5, 1e-12);
  }
}

// Bisection on the scale s of r_AB for F(s r) = 1, using only the overlap predicate at each
// step; compare with the closed form s = 1/sqrt(F) and check the touching geometry with
// library-independent formulas.
TEST(PerramWertheim, RandomPairsScaledToTouch) {
  std::mt19937_64 g(kSeed + 2);
  double max_sym = 0, max_bis = 0, max_F1 = 0, max_surf = 0, max_ang = 0;
  int max_it = 0;
  for (int i = 0; i < 2000; ++i) {
    const EllipsoidPose A = random_ellipsoid(g), B0 = random_ellipsoid(g);
    const Vec3 u = random_unit(g);
    double lo = 0.0, hi = 1.0;
    while (!(perram_wertheim(A, B0, hi * u, 0.0).F > 1.0)) hi *= 2.0;
    for (int k = 0; k < 200 && hi - lo > 1e-15 * hi; ++k) {
      const double mid = 0.5 * (lo + hi);
      (perram_wertheim(A, B0, mid * u, 0.0).F < 1.0 ? lo : hi) = mid;
    }
    const double s_bis = 0.5 * (lo + hi);
    const double s = touching_scale(A, B0, u);
    max_bis = std::max(max_bis, std::abs(s - s_bis) / s);
    ASSERT_NEAR(s, s_bis, 1e-13 * s) << "seed " << kSeed + 2 << " case " << i;

    const Vec3 r = s * u;
    const EllipsoidPose B = placed(B0, A.r + r);
    const PerramWertheim ab = perram_wertheim(A, B);
    const PerramWertheim ba = perram_wertheim(B, A);
    max_F1 = std::max(max_F1, std::abs(ab.F - 1.0));
    max_sym = std::max(max_sym, std::abs(ab.F - ba.F));
    max_it = std::max({max_it, ab.iterations, ba.iterations});
    EXPECT_NEAR(ab.F, 1.0, 1e-13);
    EXPECT_NEAR(ab.F, ba.F, 1e-13);
    EXPECT_NEAR(ab.lambda + ba.lambda, 1.0, 1e-10);
    EXPECT_FALSE(ab.overlap);
    EXPECT_FALSE(ba.overlap);
    // touching point on both surfaces, normals antiparallel and along `normal`
    const double e = std::max(std::abs(f_body(A, ab.point) - 1.0), std::abs(f_body(B, ab.point) - 1.0));
    max_surf = std::max(max_surf, e);
    EXPECT_LT(e, 1e-12);
    const Vec3 nA = grad_body(A, ab.point).normalized();
    const Vec3 nB = grad_body(B, ab.point).normalized();
    const double ang = std::max((nA + nB).norm(), (nA - ab.normal).norm());
    max_ang = std::max(max_ang, ang);
    EXPECT_LT(ang, 1e-10);
    EXPECT_LT((ab.point - ba.point).norm(), 1e-10 * s);
  }
  std::printf("[touching] max |s - s_bisection|/s %.2e  |F-1| %.2e  |F(A,B)-F(B,A)| %.2e  "
              "surface residual %.2e  normal mismatch %.2e  max iterations %d\n",
              max_bis, max_F1, max_sym, max_surf, max_ang, max_it);
}

TEST(PerramWertheim, MonotonicAndQuadraticInTheSeparation) {
  std::mt19937_64 g(kSeed + 3);
  for (int i = 0; i < 200; ++i) {
    const EllipsoidPose A = random_ellipsoid(g), B = random_ellipsoid(g);
    const Vec3 u = random_unit(g);
    const double F1 = perram_wertheim(A, B, u).F;
    double prev = 0.0;
    for (int k = 1; k <= 200; ++k) {
      const double s = 0.05 * k;
      const double F = perram_wertheim(A, B, s * u).F;
      EXPECT_GT(F, prev) << "seed " << kSeed + 3 << " case " << i << " s " << s;
      EXPECT_NEAR(F, s * s * F1, 1e-13 * s * s * F1);
      prev = F;
    }
  }
}

// F(lambda) straight from the definition, in the lab frame (fine for moderate aspect ratios).
double F_lab(const EllipsoidPose& A, const EllipsoidPose& B, const Vec3& r, double lambda) {
  auto M = [](const EllipsoidPose& E) {
    const Mat3 R = E.q.toRotationMatrix();
    return Mat3(R * E.semi_axes.cwiseAbs2().asDiagonal() * R.transpose());
  };
  const Mat3 C = (1.0 - lambda) * M(A) + lambda * M(B);
  return lambda * (1.0 - lambda) * r.dot(C.llt().solve(r));
}

TEST(PerramWertheim, ReducedFormEqualsTheDefinition) {
  std::mt19937_64 g(kSeed + 8);
  for (int i = 0; i < 500; ++i) {
    const EllipsoidPose A = random_ellipsoid(g), B = random_ellipsoid(g);
    const Vec3 r = B.r - A.r;
    for (double l : {0.01, 0.2, 0.5, 0.77, 0.99}) {
      const double ref = F_lab(A, B, r, l);
      EXPECT_NEAR(perram_wertheim_at(A, B, r, l), ref, 1e-12 * ref) << "case " << i;
    }
  }
}

TEST(PerramWertheim, MaximumBeatsABruteForceGridOverLambda) {
  std::mt19937_64 g(kSeed + 4);
  for (int i = 0; i < 100; ++i) {
    const EllipsoidPose A = random_ellipsoid(g), B = random_ellipsoid(g);
    const Vec3 r = B.r - A.r;
    const PerramWertheim pw = perram_wertheim(A, B);
    double best = 0.0;
    for (int k = 1; k < 2000; ++k) best = std::max(best, perram_wertheim_at(A, B, r, k / 2000.0));
    EXPECT_GE(pw.F, best * (1.0 - 1e-15));
    EXPECT_LE(pw.F, best * (1.0 + 1e-5));  // grid spacing 5e-4, F'' bounded: close
    EXPECT_NEAR(perram_wertheim_at(A, B, r, pw.lambda), pw.F, 1e-15 * pw.F);
  }
}

// The answer carries a certificate checkable without the contact function: if F < 1 the point
// x* lies inside both ellipsoids (f = F < 1); if F > 1 the plane through x* normal to `normal`
// separates them (support values of A and B do not reach it).
TEST(PerramWertheim, OverlapVerdictHasAnIndependentCertificate) {
  std::mt19937_64 g(kSeed + 5);
  int overlaps = 0, disjoint = 0;
  for (int i = 0; i < 20000; ++i) {
    const EllipsoidPose A = random_ellipsoid(g, 0.1, 2.0);
    EllipsoidPose B = random_ellipsoid(g, 0.1, 2.0);
    B.r = A.r + random_unit(g) * std::uniform_real_distribution<double>(0.0, 5.0)(g);
    const PerramWertheim pw = perram_wertheim(A, B);
    if (std::abs(pw.F - 1.0) < 1e-9) continue;  // too close to call by a certificate
    if (pw.overlap) {
      ++overlaps;
      EXPECT_LT(f_body(A, pw.point), 1.0) << "seed " << kSeed + 5 << " case " << i;
      EXPECT_LT(f_body(B, pw.point), 1.0) << "seed " << kSeed + 5 << " case " << i;
    } else {
      ++disjoint;
      const Vec3& n = pw.normal;
      EXPECT_LT(n.dot(A.r) + support(A, n), n.dot(pw.point)) << "case " << i;
      EXPECT_GT(n.dot(B.r) - support(B, -n), n.dot(pw.point)) << "case " << i;
    }
  }
  EXPECT_GT(overlaps, 1000);
  EXPECT_GT(disjoint, 1000);
}

TEST(PerramWertheim, ToleranceAroundTouching) {
  std::mt19937_64 g(kSeed + 6);
  for (int i = 0; i < 500; ++i) {
    const EllipsoidPose A = random_ellipsoid(g), B = random_ellipsoid(g);
    const Vec3 u = random_unit(g);
    const double s = touching_scale(A, B, u);
    EXPECT_FALSE(ellipsoids_overlap(A, B, s * u));
    EXPECT_TRUE(ellipsoids_overlap(A, B, (1.0 - 1e-9) * s * u));
    EXPECT_FALSE(ellipsoids_overlap(A, B, (1.0 + 1e-9) * s * u));
    EXPECT_GT(touching_scale(A, B, 0.5 * s * u), 1.0);  // overlapping: must move apart
  }
}

TEST(PerramWertheim, ExtremeAspectRatiosConverge) {
  std::mt19937_64 g(kSeed + 7);
  double max_F1 = 0;
  int max_it = 0;
  const Vec3 shapes[] = {{100.0, 1.0, 1.0}, {1.0, 1.0, 0.01}, {50.0, 0.5, 0.02}, {0.01, 0.01, 1.0}};
  for (const Vec3& sa : shapes) {
    for (const Vec3& sb : shapes) {
      for (int i = 0; i < 200; ++i) {
        EllipsoidPose A, B;
        A.semi_axes = sa;
        B.semi_axes = sb;
        A.q = random_quat(g);
        B.q = random_quat(g);
        const Vec3 u = random_unit(g);
        const double s = touching_scale(A, B, u);
        const PerramWertheim pw = perram_wertheim(A, B, s * u);
        max_F1 = std::max(max_F1, std::abs(pw.F - 1.0));
        max_it = std::max(max_it, pw.iterations);
        EXPECT_LT(pw.iterations, 60);
        EXPECT_NEAR(pw.F, 1.0, 1e-13);
        EXPECT_FALSE(pw.overlap);
        EXPECT_TRUE(ellipsoids_overlap(A, B, (1.0 - 1e-8) * s * u));
      }
    }
  }
  std::printf("[aspect 100] max |F-1| at touching %.2e, max iterations %d\n", max_F1, max_it);
}

TEST(PerramWertheim, MinimumImageSeparationOverridesStoredCentre) {
  EllipsoidPose A, B;
  A.semi_axes = Vec3(2.0, 1.0, 1.0);
  B.semi_axes = Vec3(1.0, 1.0, 1.0);
  B.r = Vec3(2.5 + 10.0, 0.0, 0.0);  // stored one box length away
  EXPECT_FALSE(ellipsoids_overlap(A, B));
  EXPECT_TRUE(ellipsoids_overlap(A, B, Vec3(2.5, 0.0, 0.0)));
  EXPECT_NEAR(touching_scale(A, B, Vec3(2.5, 0.0, 0.0)), 3.0 / 2.5, 1e-15);
}

TEST(PerramWertheim, ConcentricAndInvalidInput) {
  EllipsoidPose A, B;
  const PerramWertheim pw = perram_wertheim(A, B);
  EXPECT_EQ(pw.F, 0.0);
  EXPECT_TRUE(pw.overlap);
  EXPECT_EQ(touching_scale(A, B), kInf);
  EllipsoidPose bad;
  bad.semi_axes = Vec3(1.0, 0.0, 1.0);
  EXPECT_THROW(perram_wertheim(A, bad), std::invalid_argument);
  bad.semi_axes = Vec3(1.0, std::nan(""), 1.0);
  EXPECT_THROW(perram_wertheim(bad, B), std::invalid_argument);
  EXPECT_THROW(perram_wertheim(A, B, Vec3(kInf, 0, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace hb
