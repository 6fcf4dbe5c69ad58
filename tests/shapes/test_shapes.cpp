// Shape concept: f, gradient, Hessian against finite differences; volume; ray intersection;
// support function against its definition; the support Hessian by finite differences and its
// closed-form quadratic forms against it.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"
#include "shapes/shape.hpp"

namespace hb {
namespace {

std::mt19937_64& rng() {
  static std::mt19937_64 g(20240611);
  return g;
}
double uni(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng()); }
Vec3 rand_vec(double s) { return Vec3(uni(-s, s), uni(-s, s), uni(-s, s)); }

template <Shape S>
void check_derivatives(const S& s, int samples) {
  const double L = s.bounding_radius();
  for (int k = 0; k < samples; ++k) {
    const Vec3 x = rand_vec(1.5 * L);
    const double h = 1e-5 * L;
    Vec3 g_fd;
    Mat3 h_fd;
    for (int i = 0; i < 3; ++i) {
      Vec3 e = Vec3::Zero();
      e[i] = h;
      g_fd[i] = (s.f(x + e) - s.f(x - e)) / (2 * h);
      h_fd.col(i) = (s.grad(x + e) - s.grad(x - e)) / (2 * h);
    }
    const Vec3 g = s.grad(x);
    const Mat3 H = s.hessian(x);
    EXPECT_LE((g - g_fd).norm(), 1e-6 * g.norm() + 1e-12) << x.transpose();
    EXPECT_LE((H - h_fd).norm(), 1e-6 * H.norm()) << x.transpose();
  }
}

template <SupportShape S>
void check_support(const S& s, int samples) {
  for (int k = 0; k < samples; ++k) {
    const Vec3 n = rand_vec(1.0);
    const Vec3 p = s.support_point(n);
    EXPECT_NEAR(s.f(p), 0.0, 1e-13);                            // on the surface
    EXPECT_NEAR(p.dot(n), s.support(n), 1e-13 * n.norm() * s.bounding_radius());
    EXPECT_GT(s.grad(p).normalized().dot(n.normalized()), 1.0 - 1e-13);  // normal along n
    // h is the max of n.x over the body: no random surface point does better
    for (int j = 0; j < 20; ++j) {
      const Vec3 q = s.ray_surface(rand_vec(1.0));
      EXPECT_LE(q.dot(n), s.support(n) * (1 + 1e-14));
    }
    // support_point is the gradient of h, support_hessian its Hessian
    const double h = 1e-6;
    Mat3 hfd;
    for (int i = 0; i < 3; ++i) {
      Vec3 e = Vec3::Zero();
      e[i] = h;
      EXPECT_NEAR((s.support(n + e) - s.support(n - e)) / (2 * h), p[i],
                  1e-7 * s.bounding_radius());
      hfd.col(i) = (s.support_point(n + e) - s.support_point(n - e)) / (2 * h);
    }
    EXPECT_LE((hfd - s.support_hessian(n)).norm(), 1e-6 * s.support_hessian(n).norm() + 1e-9);
    // the closed-form quadratic forms (the separating-axis Newton) against support_hessian
    const Vec3 u = rand_vec(1.0), v = rand_vec(1.0);
    const Mat3 H = s.support_hessian(n);
    const Vec3 f = s.support_hessian_forms(n, p, u, v);
    const double scale = H.norm() * u.norm() * v.norm();
    EXPECT_NEAR(f[0], u.dot(H * u), 1e-13 * scale);
    EXPECT_NEAR(f[1], u.dot(H * v), 1e-13 * scale);
    EXPECT_NEAR(f[2], v.dot(H * v), 1e-13 * scale);
  }
}

template <Shape S>
void check_ray(const S& s, int samples) {
  for (int k = 0; k < samples; ++k) {
    const Vec3 u = rand_vec(1.0);
    const Vec3 p = s.ray_surface(u);
    EXPECT_NEAR(s.f(p), 0.0, 1e-13);
    EXPECT_GT(p.normalized().dot(u.normalized()), 1.0 - 1e-14);  // along u, forward
    const Vec3 q = ray_surface_generic(s, u);
    EXPECT_LE((p - q).norm(), 1e-13 * s.bounding_radius());
    EXPECT_LE(p.norm(), s.bounding_radius() * (1 + 1e-14));
    EXPECT_GE(p.norm(), s.inscribed_radius() * (1 - 1e-14));
  }
}

TEST(Shapes, SphereDerivativesRaySupport) {
  const Sphere s{0.7};
  check_derivatives(s, 200);
  check_ray(s, 200);
  check_support(s, 200);
  EXPECT_LT(s.f(Vec3::Zero()), 0.0);
  EXPECT_NEAR(s.f(Vec3(0.7, 0, 0)), 0.0, 1e-15);
}

TEST(Shapes, EllipsoidDerivativesRaySupport) {
  for (const Ellipsoid& e : {Ellipsoid{2.0, 1.0, 1.0}, Ellipsoid{0.5, 1.0, 1.0},
                            Ellipsoid{0.3, 1.7, 4.0}, Ellipsoid{10.0, 1.0, 0.1}}) {
    check_derivatives(e, 200);
    check_ray(e, 200);
    check_support(e, 200);
    EXPECT_NEAR(e.f(Vec3(e.a, 0, 0)), 0.0, 1e-15);
    EXPECT_NEAR(e.f(Vec3(0, e.b, 0)), 0.0, 1e-15);
    EXPECT_NEAR(e.f(Vec3(0, 0, e.c)), 0.0, 1e-15);
    EXPECT_DOUBLE_EQ(e.f(Vec3::Zero()), -1.0);
  }
}

TEST(Shapes, Volume) {
  EXPECT_NEAR(Sphere{2.0}.volume(), 32.0 / 3.0 * kPi, 1e-12);
  EXPECT_NEAR((Ellipsoid{1.0, 2.0, 3.0}.volume()), 8.0 * kPi, 1e-12);
  // Monte Carlo over the bounding box with a fixed seed: the fraction inside.
  const Ellipsoid e{0.4, 1.3, 0.8};
  std::mt19937_64 g(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = 400000;
  int inside = 0;
  for (int i = 0; i < n; ++i)
    if (e.f(Vec3(u(g) * e.a, u(g) * e.b, u(g) * e.c)) < 0) ++inside;
  const double box = 8.0 * e.a * e.b * e.c;
  EXPECT_NEAR(box * inside / n, e.volume(), 0.01 * e.volume());
}

TEST(Shapes, BoundingAndInscribedRadius) {
  const Ellipsoid e{0.3, 1.7, 4.0};
  EXPECT_EQ(e.bounding_radius(), 4.0);
  EXPECT_EQ(e.inscribed_radius(), 0.3);
  for (int k = 0; k < 1000; ++k) {
    const double r = e.ray_surface(rand_vec(1.0)).norm();
    EXPECT_LE(r, 4.0 * (1 + 1e-15));
    EXPECT_GE(r, 0.3 * (1 - 1e-15));
  }
}

// The rotation lever l (shapes/shape.hpp) bounds |p(m) x m| over unit m, the offset of the
// support point from the line along m, which every rotational rate bound uses: sampled over
// random and near-axis directions (where the offset of an ellipsoid peaks: between its longest
// and shortest axes) for ellipsoids, spheres and superquadrics, it is never exceeded; for
// ellipsoids it is tight (a_max - a_min is reached to 1e-4), and for any shape at most L.
template <SupportShape S>
double largest_offset(const S& s, int samples) {
  double worst = 0.0;
  for (int k = 0; k < samples; ++k) {
    Vec3 m = rand_vec(1.0);
    if (k % 2) {  // directions in a coordinate plane, where the extremes lie
      m[k % 3] = 0.0;
    }
    if (!(m.norm() > 1e-3)) continue;
    m.normalize();
    worst = std::max(worst, s.support_point(m).cross(m).norm());
  }
  return worst;
}

TEST(Shapes, RotationLeverBoundsTheSupportPointOffset) {
  for (int k = 0; k < 20; ++k) {
    const Ellipsoid e{uni(0.1, 3.0), uni(0.1, 3.0), uni(0.1, 3.0)};
    const double l = rotation_lever(e), seen = largest_offset(e, 20000);
    EXPECT_LE(seen, l * (1 + 1e-12) + 1e-15) << e.a << " " << e.b << " " << e.c;
    EXPECT_GE(seen, l * (1 - 1e-4)) << e.a << " " << e.b << " " << e.c;
    EXPECT_LE(l, e.bounding_radius());
  }
  EXPECT_EQ(rotation_lever(Ellipsoid{1.0, 0.5, 0.5}), 0.5);
  EXPECT_EQ(rotation_lever(Sphere{1.3}), 0.0);
  EXPECT_LE(largest_offset(Sphere{1.3}, 1000), 1e-15);
  for (const Superquadric& s : {Superquadric{1.0, 0.5, 0.5, 2, 2, 2}, Superquadric{0.5, 0.5, 1.0, 2, 2, 8},
                                Superquadric{1.0, 1.0, 1.0, 8, 8, 8}, Superquadric{0.3, 1.0, 2.0, 4, 3, 20}}) {
    const double l = rotation_lever(s), seen = largest_offset(s, 20000);
    EXPECT_LE(seen, l * (1 + 1e-9)) << s.exponents().transpose();
    EXPECT_LE(l, s.bounding_radius());
    std::printf("  superquadric (%g, %g, %g): lever %.4f, largest offset seen %.4f, L %.4f\n",
                s.exponents()[0], s.exponents()[1], s.exponents()[2], l, seen, s.bounding_radius());
  }
  EXPECT_EQ(rotation_lever(Superquadric{1.0, 0.5, 0.5, 2, 2, 2}), 0.5);  // the ellipsoid's
}

// The superquadric's lever (sq_detail::lever_bound, a branch and bound on the surface) against
// an independent twin: the largest |x x n| over surface points x found along rays from the
// centre (ray_surface) with their normals from the implicit function's gradient, 10^5 random
// rays (half in coordinate planes) then a shrinking random search about the best.  The lever
// must lie above it (it is a bound) and within its tolerance (1e-3) plus the twin's shortfall
// (measured below 1e-5) of it, for named and random shapes (two exponents 2 and one integer p,
// or any exponents in [2, 30]; axes in [0.3, 3]).  And it never exceeds the generic bound.
double largest_offset_on_surface(const Superquadric& s, int samples) {
  auto offset = [&](const Vec3& u) {
    const Vec3 x = s.ray_surface(u);
    return x.cross(s.grad(x).normalized()).norm();
  };
  double best = 0.0;
  Vec3 best_u(1.0, 0.0, 0.0);
  for (int k = 0; k < samples; ++k) {
    Vec3 u = rand_vec(1.0);
    if (k % 2) u[k % 3] = 0.0;
    if (!(u.norm() > 1e-3)) continue;
    if (const double v = offset(u); v > best) best = v, best_u = u.normalized();
  }
  for (double step = 0.1; step > 1e-9; step *= 0.7)
    for (int r = 0; r < 40; ++r) {
      const Vec3 u = (best_u + step * rand_vec(1.0)).normalized();
      if (const double v = offset(u); v > best) best = v, best_u = u;
    }
  return best;
}

TEST(Shapes, SuperquadricLeverIsTheLargestOffsetWithinItsTolerance) {
  std::vector<Superquadric> shapes{{0.8, 1.6, 1.6, 2, 2, 8}, {0.8, 1.6, 1.6, 2, 2, 4},
                                   {0.8, 1.6, 1.6, 2, 2, 16}, {0.5, 0.5, 1.0, 2, 2, 8},
                                   {1.0, 1.0, 1.0, 64, 64, 64}, {1.0, 1.0, 1.0, 2, 2, 40},
                                   {1.0, 2.0, 3.0, 2, 2, 2.0001}, {0.1, 1.0, 3.0, 2.5, 7.3, 64}};
  for (int k = 0; k < 24; ++k) {
    Vec3 a, e;
    for (int i = 0; i < 3; ++i) a[i] = std::exp(uni(std::log(0.3), std::log(3.0)));
    for (int i = 0; i < 3; ++i)
      e[i] = k % 2 ? (i < 2 ? 2.0 : std::floor(uni(3.0, 17.0))) : (uni(0.0, 1.0) < 0.3 ? 2.0 : uni(2.0, 30.0));
    if (e == Vec3(2, 2, 2)) e[0] = 3.0;
    shapes.emplace_back(a[0], a[1], a[2], e[0], e[1], e[2]);
  }
  double most = 0.0;
  for (const Superquadric& s : shapes) {
    const double l = rotation_lever(s), seen = largest_offset_on_surface(s, 100000);
    EXPECT_GE(l, seen) << s.axes().transpose() << " | " << s.exponents().transpose();
    EXPECT_LE(l, seen * (1.0 + 1e-3 + 1e-5)) << s.axes().transpose() << " | " << s.exponents().transpose();
    EXPECT_LE(l, rotation_lever_bound(s.bounding_radius(), s.inscribed_radius()));
    most = std::max(most, l / seen - 1.0);
  }
  std::printf("  %zu superquadrics: lever / largest offset found - 1 at most %.2e\n", shapes.size(), most);
}

// resized (shapes/registry.hpp) scales the lever instead of searching again: the same as a
// fresh construction to the search's tolerance, exactly s times the original's, and every other
// constant as the constructor computes it (bounding radius and support points bit for bit).
TEST(Shapes, SuperquadricResizedScalesTheLever) {
  for (const Superquadric& q : {Superquadric{0.8, 1.6, 1.6, 2, 2, 8}, Superquadric{1.0, 1.3, 0.7, 3, 4, 5},
                                Superquadric{1.0, 0.5, 0.5, 2, 2, 2}}) {
    for (const double s : {0.37, 1.0, 2.9}) {
      const Superquadric r = q.resized(s), fresh{q.a * s, q.b * s, q.c * s, q.n, q.m, q.p};
      EXPECT_EQ(r.bounding_radius(), fresh.bounding_radius());
      EXPECT_NEAR(r.rotation_lever(), q.rotation_lever() * s, 1e-15 * r.rotation_lever());
      EXPECT_NEAR(r.rotation_lever(), fresh.rotation_lever(), 1e-3 * fresh.rotation_lever());
      for (int k = 0; k < 100; ++k) {
        const Vec3 m = rand_vec(1.0);
        EXPECT_EQ(r.support_point(m), fresh.support_point(m));
      }
    }
  }
  EXPECT_EQ(Superquadric(1.0, 0.5, 0.5, 2, 2, 2).resized(3.0).rotation_lever(), 1.5);
  // the search runs on the body scaled to a_max = 1: the same lever, scaled, at any size (its
  // squares would overflow at 1e200 and vanish at 1e-200)
  const Superquadric q{0.8, 1.6, 1.6, 2, 2, 8};
  for (const double s : {1e200, 1e-200, 0x1p1000, 0x1p-1000}) {
    const Superquadric big{0.8 * s, 1.6 * s, 1.6 * s, 2, 2, 8};
    EXPECT_NEAR(big.rotation_lever() / s, q.rotation_lever(), 1e-12 * q.rotation_lever()) << s;
    EXPECT_NEAR(q.resized(s).rotation_lever() / s, q.rotation_lever(), 1e-12 * q.rotation_lever()) << s;
  }
}

}  // namespace
}  // namespace hb
