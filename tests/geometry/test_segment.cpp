// Closest points of two segments (geometry/segment.hpp) against a dense grid of parameter pairs
// refined by coordinate descent (the slow, obviously right twin), and against the optimality
// conditions of the box-constrained minimum; the core segment of a body by its half extents.
#include <gtest/gtest.h>

#include <cstdio>

#include "geometry/random_pairs.hpp"
#include "geometry/segment.hpp"

namespace hb {
namespace {

double seg_dist2(const Vec3& p, const Vec3& u, double s, const Vec3& q, const Vec3& v, double t) {
  return (p + s * u - q - t * v).squaredNorm();
}

// Brute force: the best of an n x n grid over [-hp, hp] x [-hq, hq], then golden-section line
// searches along s and t in turn around it (F is convex, so the result is the minimum to
// rounding once the grid cell is bracketed).
double brute_min(const Vec3& p, const Vec3& u, double hp, const Vec3& q, const Vec3& v, double hq) {
  const int n = 120;
  double best = kInf, bs = 0.0, bt = 0.0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double s = -hp + 2.0 * hp * i / n, t = -hq + 2.0 * hq * j / n;
      const double f = seg_dist2(p, u, s, q, v, t);
      if (f < best) best = f, bs = s, bt = t;
    }
  auto golden = [](auto f, double lo, double hi) {
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    for (int k = 0; k < 100; ++k) {
      const double a = hi - g * (hi - lo), b = lo + g * (hi - lo);
      if (f(a) < f(b)) hi = b; else lo = a;
    }
    return 0.5 * (lo + hi);
  };
  for (int sweep = 0; sweep < 200; ++sweep) {
    bs = golden([&](double s) { return seg_dist2(p, u, s, q, v, bt); }, -hp, hp);
    bt = golden([&](double t) { return seg_dist2(p, u, bs, q, v, t); }, -hq, hq);
  }
  return std::min(best, seg_dist2(p, u, bs, q, v, bt));
}

TEST(Segment, ClosestPointsMatchBruteForceAndOptimality) {
  testing::Rng r(61);
  double worst_gap = 0.0, worst_kkt = 0.0;
  int n_parallel = 0;
  for (int k = 0; k < 400; ++k) {
    const Vec3 p = r.ball(2.0), q = r.ball(2.0);
    const Vec3 u = r.unit();
    Vec3 v = r.unit();
    const int kind = k % 4;  // general, parallel, nearly parallel, a point (zero length)
    if (kind == 1) v = (r.uni(0.0, 1.0) < 0.5 ? 1.0 : -1.0) * u, ++n_parallel;
    if (kind == 2) v = (u + 1e-7 * r.unit()).normalized();
    const double hp = r.uni(0.0, 3.0), hq = kind == 3 ? 0.0 : r.uni(0.0, 3.0);
    const SegmentPoints sp = closest_segment_points(p, u, hp, q, v, hq);
    ASSERT_LE(std::abs(sp.s), hp);
    ASSERT_LE(std::abs(sp.t), hq);
    const double f = seg_dist2(p, u, sp.s, q, v, sp.t);
    worst_gap = std::max(worst_gap, f - brute_min(p, u, hp, q, v, hq));
    // optimality on the box: each gradient component vanishes inside, points outward at a bound
    const Vec3 w = p + sp.s * u - q - sp.t * v;
    const double gs = 2.0 * u.dot(w), gt = -2.0 * v.dot(w);
    auto violation = [](double g, double x, double h) {
      if (h == 0.0) return 0.0;
      if (x >= h) return std::max(0.0, g);    // at the upper bound: g <= 0 (decreasing would leave)
      if (x <= -h) return std::max(0.0, -g);  // at the lower bound: g >= 0
      return std::abs(g);
    };
    worst_kkt = std::max({worst_kkt, violation(gs, sp.s, hp), violation(gt, sp.t, hq)});
  }
  std::printf("  400 segment pairs (%d parallel): max F - F_brute %.2e, max optimality violation %.2e\n",
              n_parallel, worst_gap, worst_kkt);
  EXPECT_LE(worst_gap, 1e-12);
  EXPECT_LE(worst_kkt, 1e-9);
}

TEST(Segment, CoreSegmentOfBodies) {
  const CoreSegment sphere = core_segment(Vec3(0.5, 0.5, 0.5));
  EXPECT_EQ(sphere.half, 0.0);
  EXPECT_FALSE(sphere.rod());
  const CoreSegment needle = core_segment(Vec3(0.5, 5.0, 0.5));
  EXPECT_EQ(needle.axis, 1);
  EXPECT_DOUBLE_EQ(needle.half, 4.5);
  EXPECT_TRUE(needle.rod());
  const CoreSegment disk = core_segment(Vec3(5.0, 5.0, 0.5));  // oblate: no rod
  EXPECT_EQ(disk.half, 0.0);
  EXPECT_FALSE(disk.rod());
  const CoreSegment short_rod = core_segment(Vec3(1.0, 0.5, 0.5));  // aspect 2: not a rod
  EXPECT_DOUBLE_EQ(short_rod.half, 0.5);
  EXPECT_FALSE(short_rod.rod());
  const CoreSegment triaxial = core_segment(Vec3(0.5, 1.0, 3.0));
  EXPECT_EQ(triaxial.axis, 2);
  EXPECT_DOUBLE_EQ(triaxial.half, 2.0);
  EXPECT_DOUBLE_EQ(triaxial.thick, 1.0);
  EXPECT_TRUE(triaxial.rod());
}

}  // namespace
}  // namespace hb
