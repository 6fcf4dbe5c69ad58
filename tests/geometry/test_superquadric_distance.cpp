// Distance solver on superquadrics: all-exponents-2 equals the ellipsoid, and random pairs
// (exponents 2..16, elongations X0 = 0.5 and 2, the paper's n = m = 2 family and general ones)
// against the exact constructed gap and the independent support-function reference built on
// ref::SlowSuperquadric (paper's f, bisection support).  Fallbacks and failures are counted
// per maximum exponent and printed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <map>

#include "geometry/distance.hpp"
#include "geometry/random_pairs.hpp"
#include "geometry/reference_distance.hpp"
#include "geometry/reference_superquadric.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

ref::SlowSuperquadric slow(const Superquadric& s) {
  return ref::SlowSuperquadric{s.a, s.b, s.c, s.n, s.m, s.p};
}

TEST(SuperquadricDistance, AllExponentsTwoEqualsEllipsoid) {
  Rng r(201);
  double worst = 0;
  int fallbacks = 0;
  const int n = scaled_count(1000, 0.05);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid ea = r.ellipsoid(), eb = r.ellipsoid();
    const Superquadric sa{ea.a, ea.b, ea.c, 2, 2, 2}, sb{eb.a, eb.b, eb.c, 2, 2, 2};
    const Pose pa{r.ball(3.0), r.rotation()};
    const double diam = 2 * std::max(ea.bounding_radius(), eb.bounding_radius());
    const double gap = r.log_uni(1e-6, 3.0 * diam);
    const Pose pb = testing::place_at_distance(ea, pa, eb, r.rotation(), r.unit(), gap);
    const DistanceResult de = distance(ea, pa, eb, pb), ds = distance(sa, pa, sb, pb);
    ASSERT_NE(de.status, DistanceStatus::failed);
    ASSERT_NE(ds.status, DistanceStatus::failed);
    if (ds.status == DistanceStatus::fallback) ++fallbacks;
    const double e = std::abs(de.distance - ds.distance);
    worst = std::max(worst, e / std::max(1.0, gap));
    EXPECT_LE(e, 1e-10 * std::max(1.0, gap)) << "gap " << gap;
    EXPECT_LE((de.point_a - ds.point_a).norm(), 1e-7 * diam);
  }
  std::printf("  exponents 2 vs ellipsoid: %d pairs, max |d_sq - d_ell| %.2e, fallbacks %d\n", n,
              worst, fallbacks);
  EXPECT_EQ(fallbacks, 0);
}

struct Bucket {
  int n = 0, fallback = 0, failed = 0;
  long nr = 0;
  int nr_max = 0;
  double max_rel_ref = 0, max_rel_exact = 0;
};

// Shape families: the paper's (semi-axes X0 b, b, b with the smallest 0.8; n = m = 2 on the
// equal axes, p on the symmetry axis), all exponents equal, and independent random exponents.
Superquadric family_shape(Rng& r, int family, double X0) {
  const double small = 0.8, big = small * (X0 >= 1 ? X0 : 1 / X0);
  const double a = X0 >= 1 ? big : small, bc = X0 >= 1 ? small : big;
  const double pe = std::round(r.uni(2.0, 16.0) * 2) / 2;  // 2, 2.5, ..., 16
  if (family == 0) return Superquadric{bc, bc, a, 2, 2, pe};  // symmetry axis z, exponent p
  if (family == 1) return Superquadric{a, bc, bc, pe, pe, pe};
  return Superquadric{a, bc, bc, r.uni(2.0, 16.0), r.uni(2.0, 16.0), r.uni(2.0, 16.0)};
}

TEST(SuperquadricDistance, RandomPairsVsExactGapAndReference) {
  Rng r(202);
  std::map<int, Bucket> by_exp;  // key: ceil of the larger maximum exponent of the pair
  Bucket all;
  const int n = scaled_count(3000, 0.02);
  for (int k = 0; k < n; ++k) {
    const int family = k % 3;
    const double X0a = (k / 3) % 2 ? 2.0 : 0.5, X0b = (k / 6) % 2 ? 2.0 : 0.5;
    const Superquadric a = family_shape(r, family, X0a), b = family_shape(r, family, X0b);
    const Pose pa{r.ball(3.0), r.rotation()};
    const double diam = 2 * std::max(a.bounding_radius(), b.bounding_radius());
    // near contact (1e-6..1e-2 of the size) in a third of the pairs, else up to 3 diameters
    const double gap = k % 3 == 0 ? r.log_uni(1e-6, 1e-2) * diam : r.log_uni(1e-4, 3.0) * diam;
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    const DistanceResult res = distance(a, pa, b, pb);
    const ref::SlowSuperquadric sa = slow(a), sb = slow(b);
    const ref::RefDistance rd = ref::reference_distance(sa, pa, sb, pb);
    const int key = static_cast<int>(std::ceil(std::max(a.e_max(), b.e_max())));
    for (Bucket* B : {&by_exp[key], &all}) {
      ++B->n;
      B->nr += res.nr_iterations;
      B->nr_max = std::max(B->nr_max, res.nr_iterations);
      if (res.status == DistanceStatus::fallback) ++B->fallback;
      if (res.status == DistanceStatus::failed) ++B->failed;
    }
    EXPECT_NE(res.status, DistanceStatus::failed)
        << "a " << a.a << " " << a.b << " " << a.c << " / " << a.n << " " << a.m << " " << a.p
        << "  b " << b.a << " " << b.b << " " << b.c << " / " << b.n << " " << b.m << " " << b.p
        << " gap " << gap;
    if (res.status == DistanceStatus::failed) continue;
    const double floor =
        2e-15 * ((pb.r - pa.r).norm() + a.bounding_radius() + b.bounding_radius());
    const double e_ref = std::abs(res.distance - rd.distance);
    const double e_exact = std::abs(res.distance - gap);
    for (Bucket* B : {&by_exp[key], &all}) {
      B->max_rel_ref = std::max(B->max_rel_ref, e_ref / gap);
      B->max_rel_exact = std::max(B->max_rel_exact, e_exact / gap);
    }
    EXPECT_LE(e_exact, 1e-8 * gap + floor) << "d " << res.distance << " gap " << gap;
    EXPECT_LE(e_ref, 1e-8 * gap + floor) << "d " << res.distance << " ref " << rd.distance;
  }
  std::printf("  e_max  pairs  fallback  failed  NR mean  NR max  max rel err (exact, ref)\n");
  for (const auto& [e, B] : by_exp)
    std::printf("  %5d  %5d  %8d  %6d  %7.2f  %6d  %.2e %.2e\n", e, B.n, B.fallback, B.failed,
                double(B.nr) / B.n, B.nr_max, B.max_rel_exact, B.max_rel_ref);
  std::printf("  all    %5d  %8d  %6d  %7.2f  %6d  %.2e %.2e\n", all.n, all.fallback, all.failed,
              double(all.nr) / all.n, all.nr_max, all.max_rel_exact, all.max_rel_ref);
  EXPECT_EQ(all.failed, 0);
}

// Face to face: two high-exponent bodies with parallel faces (normal along a body axis, tilted
// by 0..1e-3 rad), where both surfaces are nearly flat and the closest points are ill-defined:
// along a face the distance varies like u^p, so Newton on the tangential offset u contracts only
// by (p-2)/(p-1) per step and the point-motion convergence test (tol 1e-12 L) is not reached in
// max_nr_iter = 60.  KNOWN LIMITATION (docs/superquadrics.md): such pairs may end `failed`.
// What is asserted: a converged or fallback result is accurate, and a failed one is flagged and
// reports an upper bound of the distance (never an overlap that is not there).
TEST(SuperquadricDistance, NearlyParallelFacesMeasured) {
  Rng r(203);
  DistanceOptions longer;
  longer.max_nr_iter = 600;
  for (const DistanceOptions& o : {DistanceOptions{}, longer}) {
    std::map<int, Bucket> by_p;
    const int n = scaled_count(500, 0.04);
    for (int k = 0; k < n; ++k) {
      const double pe = 4.0 + 12.0 * (k % 5) / 4.0;  // 4, 7, 10, 13, 16
      const Superquadric a{1.6, 0.8, 0.8, pe, pe, pe}, b{0.8, 1.6, 0.8, pe, pe, pe};
      const Pose pa{r.ball(1.0), r.rotation()};
      const Mat3 Rb = testing::small_rotation(r, k % 2 ? r.log_uni(1e-9, 1e-3) : 0.0) * pa.R;
      const Vec3 nrm = pa.R.col(1);  // A's y face against B's y face
      const double gap = r.log_uni(1e-6, 1.0);
      const Pose pb = testing::place_at_distance(a, pa, b, Rb, nrm, gap);
      const DistanceResult res = distance(a, pa, b, pb, o);
      Bucket& B = by_p[static_cast<int>(pe)];
      ++B.n;
      B.nr += res.nr_iterations;
      B.nr_max = std::max(B.nr_max, res.nr_iterations);
      const double floor = 2e-15 * ((pb.r - pa.r).norm() + 4.0);
      const double e_exact = std::abs(res.distance - gap);
      if (res.status == DistanceStatus::failed) {
        ++B.failed;
        EXPECT_GE(res.distance, gap - floor);  // flagged, and an upper bound
        continue;
      }
      if (res.status == DistanceStatus::fallback) ++B.fallback;
      B.max_rel_exact = std::max(B.max_rel_exact, e_exact / gap);
      EXPECT_LE(e_exact, 1e-8 * gap + floor) << "p " << pe << " d " << res.distance << " gap " << gap;
    }
    std::printf("  parallel faces, max_nr_iter %d:\n", o.max_nr_iter);
    for (const auto& [pe, B] : by_p)
      std::printf("    p %2d pairs %4d fallback %3d failed %3d NR mean %6.1f max %4d err %.2e\n",
                  pe, B.n, B.fallback, B.failed, double(B.nr) / B.n, B.nr_max, B.max_rel_exact);
  }
}

}  // namespace
}  // namespace hb
