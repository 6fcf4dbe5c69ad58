// The farthest point of a body from a point (geometry/farthest_point.hpp) against a slow,
// obviously right search: f(u) = u.d + s h(R^T u) on 20,000 directions spread evenly over the
// sphere, then from each of the best 8 a grid of 21 x 21 directions about it, re-centred on its
// best point and shrunk 4x per level down to 1e-11 radians. The farthest point's value is f at the direction it
// returns, so it can only fall short of the true maximum (a local maximum, an unconverged
// ascent): it must not be below the brute force, and it must be a stationary point. (The brute
// force falls short itself where the maximum is a nearly flat ridge: an oblate body centred on
// the point to 1e-12; those cases are printed, not failed.) Random and adversarial cases: centres at the
// point, on it to rounding, far from it; elongated, flat and cube-like bodies.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <vector>

#include "geometry/farthest_point.hpp"
#include "random_pairs.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

const std::vector<Vec3>& fibonacci_directions() {
  static const std::vector<Vec3> dirs = [] {
    const int n = 20000;
    std::vector<Vec3> v(n);
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    for (int i = 0; i < n; ++i) {
      const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z);
      v[i] = Vec3(r * std::cos(golden * i), r * std::sin(golden * i), z);
    }
    return v;
  }();
  return dirs;
}

template <SupportShape S>
double brute_farthest(const S& shape, const Mat3& R, double s, const Vec3& d) {
  auto f = [&](const Vec3& u) { return u.dot(d) + s * shape.support(R.transpose() * u); };
  const auto& dirs = fibonacci_directions();
  std::vector<std::pair<double, int>> vals(dirs.size());
  for (std::size_t i = 0; i < dirs.size(); ++i) vals[i] = {f(dirs[i]), int(i)};
  std::partial_sort(vals.begin(), vals.begin() + 8, vals.end(), std::greater<>());
  double best = vals[0].first;
  for (int k = 0; k < 8; ++k) {  // local grids of 21 x 21 directions, shrunk 4x per level
    Vec3 u = dirs[vals[k].second];
    double fu = vals[k].first;
    for (double span = 0.05; span > 1e-10; span *= 0.25) {
      const Vec3 e1 = (std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(u).normalized();
      const Vec3 e2 = u.cross(e1);
      Vec3 centre = u;
      for (int i = -10; i <= 10; ++i)
        for (int j = -10; j <= 10; ++j) {
          const Vec3 x = (centre + span * 0.1 * (i * e1 + j * e2)).normalized();
          const double fx = f(x);
          if (fx > fu) u = x, fu = fx;
        }
    }
    best = std::max(best, fu);
  }
  return best;
}

struct Tally {
  int cases = 0, low = 0, high = 0;
  double worst = 0.0;
  long iterations = 0;
  std::array<long, 5> by_kind{};  // ascent steps per kind of case
};

template <SupportShape S, class Make>
Tally check(const char* name, Make make, std::uint64_t seed, int cases) {
  Rng rng(seed);
  Tally t;
  const int n = scaled_count(cases, 0.05);
  for (int c = 0; c < n; ++c) {
    const S shape = make(rng);
    const double L = shape.bounding_radius();
    const Mat3 R = rng.rotation();
    const double s = c % 3 == 0 ? rng.uni(0.3, 1.0) : 1.0;
    Vec3 d;
    switch (c % 5) {
      case 0: d = Vec3::Zero(); break;                          // the body centred on the point
      case 1: d = rng.log_uni(1e-12, 1e-3) * L * rng.unit(); break;  // nearly centred
      case 2: d = rng.uni(0.0, 1.0) * L * rng.unit(); break;    // the point inside the body
      case 3: d = rng.uni(1.0, 3.0) * L * rng.unit(); break;    // a body near a container wall
      default: d = rng.uni(3.0, 30.0) * L * rng.unit(); break;  // far from the centre
    }
    const FarthestPoint fp = farthest_point(shape, R, s, d);
    const double truth = brute_farthest(shape, R, s, d);
    const double tol = 1e-12 * (d.norm() + s * L);
    ++t.cases;
    t.iterations += fp.iterations;
    t.by_kind[c % 5] += fp.iterations;
    const double err = fp.distance - truth;
    t.worst = std::max(t.worst, std::abs(err) / (d.norm() + s * L));
    if (err < -tol) {  // a local maximum, not the global one: the container could be passed
      if (t.low < 3)
        std::printf("  low: %s case %d F %.17g truth %.17g\n", name, c, fp.distance, truth);
      ++t.low;
    }
    if (err > tol && t.high++ < 4) std::printf("  above: %s case %d kind %d err %.3e F %.6g\n", name, c, c % 5, err, fp.distance);  // the brute force fell short
    // a maximiser: the gradient along the sphere vanishes
    const Vec3 g = d + fp.lever;
    EXPECT_LT((g - g.dot(fp.u) * fp.u).norm(), 1e-7 * g.norm()) << name << " case " << c;
    // the returned maximiser is consistent: |x* - c| = F along u*
    EXPECT_NEAR((d + fp.lever).norm(), fp.distance, 1e-10 * (d.norm() + s * L)) << name << " case " << c;
    EXPECT_NEAR(fp.u.dot(d + fp.lever), fp.distance, 1e-10 * (d.norm() + s * L)) << name << " case " << c;
  }
  std::printf("  %s: %d cases, below the brute force %d, above %d, worst relative difference %.2e, "
              "%.1f ascent steps per call\n", name, t.cases, t.low, t.high, t.worst,
              double(t.iterations) / std::max(t.cases, 1));
  std::printf("    ascent steps per call: centred %.1f, nearly centred %.1f, point inside %.1f, near a wall %.1f, far %.1f\n",
              5.0 * t.by_kind[0] / t.cases, 5.0 * t.by_kind[1] / t.cases, 5.0 * t.by_kind[2] / t.cases,
              5.0 * t.by_kind[3] / t.cases, 5.0 * t.by_kind[4] / t.cases);
  return t;
}

TEST(FarthestPoint, SphereIsClosedForm) {
  Rng rng(1);
  for (int c = 0; c < 100; ++c) {
    const Sphere s{rng.uni(0.2, 2.0)};
    const Vec3 d = rng.uni(0.0, 5.0) * rng.unit();
    const FarthestPoint fp = farthest_point(s, rng.rotation(), 0.7, d);
    EXPECT_NEAR(fp.distance, d.norm() + 0.7 * s.radius, 1e-13 * (1.0 + d.norm()));
  }
}

TEST(FarthestPoint, EllipsoidsAgainstDenseSampling) {
  const Tally t = check<Ellipsoid>("ellipsoid", [](Rng& r) { return r.ellipsoid(10.0); }, 2, 1000);
  EXPECT_EQ(t.low, 0);
}

TEST(FarthestPoint, SuperquadricsAgainstDenseSampling) {
  const Tally t = check<Superquadric>(
      "superquadric",
      [](Rng& r) {
        return Superquadric(r.uni(0.3, 1.5), r.uni(0.3, 1.5), r.uni(0.3, 1.5), r.log_uni(2.0, 16.0),
                            r.log_uni(2.0, 16.0), r.log_uni(2.0, 16.0));
      },
      3, 500);
  EXPECT_EQ(t.low, 0);
}

}  // namespace
}  // namespace hb
