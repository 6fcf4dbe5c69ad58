// Penetration solver (geometry/penetration.hpp) against a slow, obviously right twin: the gap
// G(n) = n.(r_B - r_A) - h_A(n) - h_B(-n) (through the shapes' `support`, not the support points
// the solver uses) sampled at dense Fibonacci directions, and the best samples polished by a
// zooming grid search on the tangent plane.  Both report G at some direction, a lower bound of
// the signed distance d = max G, so the solver must never be below the twin (beyond rounding);
// it being above means the twin missed the peak.  Plus analytic cases: crossing needles (depth
// = twice the thickness), coincident bodies (depth = twice the smallest support), spheres; the
// minimality of the translation (moved by the depth the bodies touch, by less they overlap);
// agreement with the distance solver on shallow overlaps and separated pairs; symmetry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "geometry/distance.hpp"
#include "geometry/penetration.hpp"
#include "geometry/random_pairs.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

// ---- the twin ------------------------------------------------------------------------------
struct TwinResult {
  double distance = -kInf;
  Vec3 n = Vec3::UnitX();
};

template <SupportShape SA, SupportShape SB>
struct TwinGap {
  const SA& a;
  const SB& b;
  Pose pa, pb;
  double operator()(const Vec3& n) const {
    return n.dot(pb.r - pa.r) - a.support(pa.R.transpose() * n) - b.support(-(pb.R.transpose() * n));
  }
};

// Dense sampling (samples Fibonacci directions), then from each of the best `polish` samples:
// a 9 x 9 grid of spacing h on the tangent plane; move to its best point (and double h again if
// that is on the grid's edge), or halve h when the centre is the best; down to h = 1e-13 rad.
template <SupportShape SA, SupportShape SB>
TwinResult twin(const SA& a, const Pose& pa, const SB& b, const Pose& pb, int samples = 20000,
                int polish = 4) {
  const TwinGap<SA, SB> G{a, b, pa, pb};
  std::vector<std::pair<double, Vec3>> s(samples);
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < samples; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / samples, rxy = std::sqrt(1.0 - z * z);
    const Vec3 n(rxy * std::cos(golden * i), rxy * std::sin(golden * i), z);
    s[i] = {G(n), n};
  }
  std::partial_sort(s.begin(), s.begin() + polish, s.end(),
                    [](const auto& x, const auto& y) { return x.first > y.first; });
  TwinResult out;
  for (int k = 0; k < polish; ++k) {
    Vec3 n = s[k].second;
    const double h0 = 2.0 * std::sqrt(4.0 * kPi / samples);
    double g = s[k].first, h = h0;
    for (int it = 0; it < 5000 && h > 1e-13; ++it) {
      const Vec3 e1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
      const Vec3 e2 = n.cross(e1);
      Vec3 bn = n;
      double bg = g;
      bool edge = false;
      for (int i = -4; i <= 4; ++i)
        for (int j = -4; j <= 4; ++j) {
          const Vec3 m = (n + h * (i * e1 + j * e2)).normalized();
          const double gm = G(m);
          if (gm > bg) {
            bg = gm;
            bn = m;
            edge = std::max(std::abs(i), std::abs(j)) == 4;
          }
        }
      if (bg > g + 1e-15 * (1.0 + std::abs(g))) {  // (not rounding noise)
        n = bn;
        g = bg;
        if (edge) h = std::min(2.0 * h, h0);  // still climbing: widen the grid again
      } else {
        h *= 0.5;
      }
    }
    if (g > out.distance) out = TwinResult{g, n};
  }
  return out;
}

// ---- helpers -------------------------------------------------------------------------------
Pose rotated(const Vec3& r, const Vec3& axis, double angle) {
  return Pose{r, Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix()};
}

Superquadric random_superquadric(Rng& r, double max_aspect, double max_exponent) {
  const double big = r.uni(0.5, 2.0);
  return Superquadric(big, big / r.log_uni(1.0, max_aspect), big / r.log_uni(1.0, max_aspect),
                      r.uni(2.0, max_exponent), r.uni(2.0, max_exponent), r.uni(2.0, max_exponent));
}

// Moved along n by the depth (plus `extra`), B no longer overlaps A: the distance solver (on a
// separated or touching pair) says so.
template <SupportShape SA, SupportShape SB>
double distance_after_push(const SA& a, const Pose& pa, const SB& b, Pose pb,
                           const PenetrationResult& p, double extra) {
  pb.r += (-p.distance + extra) * p.normal;
  return distance(a, pa, b, pb).distance;
}

// ---- analytic cases ------------------------------------------------------------------------
TEST(Penetration, CrossingNeedlesOfAspect1000) {
  // Needles of semi-axes (1000, 1, 1) along x and y, crossing at their centres (offset dz along
  // z): the shortest separating translation is along z, of length 2 - dz.  The contact
  // equations find a stationary point along an axis instead (-709.6 in issue 13).
  const Ellipsoid needle{1000.0, 1.0, 1.0};
  for (const double dz : {0.0, 0.5, 1.9}) {
    const Pose pa{}, pb = rotated(Vec3(0, 0, dz), Vec3::UnitZ(), kPi / 2);
    const PenetrationResult p = penetration(needle, pa, needle, pb);
    EXPECT_NEAR(p.distance, -(2.0 - dz), 1e-9) << dz;
    EXPECT_NEAR(std::abs(p.normal.z()), 1.0, 1e-9);
    EXPECT_TRUE(p.certified) << p.upper_bound;
    EXPECT_LE((p.point_b - p.point_a - p.distance * p.normal).norm(), 1e-9);
    std::printf("  needles dz = %.1f: distance %.12f (distance solver %.4f), %d evaluations, %d cells\n",
                dz, p.distance, distance(needle, pa, needle, pb).distance, p.evaluations, p.cells);
  }
  // the same needles crossing at 30 degrees, off centre: the normal of both axes again
  const Pose pa = rotated(Vec3(0.3, -0.2, 0.1), Vec3(1, 2, 3), 0.7);
  Pose pb = pa;
  pb.R = pa.R * Eigen::AngleAxisd(kPi / 6, Vec3::UnitZ()).toRotationMatrix();
  pb.r = pa.r + pa.R * Vec3(50.0, 20.0, 0.8);
  const PenetrationResult p = penetration(needle, pa, needle, pb);
  const Vec3 z = pa.R.col(2);
  EXPECT_NEAR(std::abs(p.normal.dot(z)), 1.0, 1e-6);
  EXPECT_LT(p.distance, -1.0);
  EXPECT_GT(p.distance, -1.3);
  EXPECT_NEAR(distance_after_push(needle, pa, needle, pb, p, 0.0), 0.0, 1e-8);
}

TEST(Penetration, CoincidentBodies) {
  // G(n) = -2 h(n): the depth is twice the smallest support, along a minor axis.
  const Ellipsoid e{2.0, 1.0, 1.0};
  const Pose p0 = rotated(Vec3(1, 2, 3), Vec3(1, 1, 0), 0.4);
  const PenetrationResult p = penetration(e, p0, e, p0);
  EXPECT_NEAR(p.distance, -2.0, 1e-12);
  EXPECT_NEAR(p.normal.dot(p0.R.col(0)), 0.0, 1e-9);
  std::printf("  coincident (2,1,1) ellipsoids: distance %.15f (distance solver %.4f), certified %d\n",
              p.distance, distance(e, p0, e, p0).distance, int(p.certified));
  const Ellipsoid tri{3.0, 2.0, 0.5};
  EXPECT_NEAR(penetration(tri, p0, tri, p0).distance, -1.0, 1e-12);
  const Superquadric cube(1.0, 0.7, 0.4, 12, 12, 12);
  EXPECT_NEAR(penetration(cube, p0, cube, p0).distance, -0.8, 1e-9);
  const Sphere s{0.6};
  EXPECT_NEAR(penetration(s, p0, tri, p0).distance, -1.1, 1e-12);
  // flat landscapes: certified through the rolling ball (G is constant for coincident spheres)
  EXPECT_TRUE(penetration(s, p0, s, p0).certified);
  const PenetrationResult se = penetration(s, p0, Ellipsoid{1.0, 1.0, 1.0}, p0);
  EXPECT_NEAR(se.distance, -1.6, 1e-12);
  EXPECT_TRUE(se.certified);
  std::printf("  coincident sphere and unit ellipsoid: %d evaluations\n", se.evaluations);
}

TEST(Penetration, ParallelNeedlesAndCubes) {
  // Needles side by side, overlapping by 0.5 across their thickness: G is flat along the great
  // circle normal to the axes, the hard case for the bound (see the header); the value must be
  // exact all the same, certified or not.
  const Ellipsoid needle{1000.0, 1.0, 1.0};
  const Pose pa{}, pb{Vec3(0.0, 1.5, 0.0), Mat3::Identity()};
  const PenetrationResult p = penetration(needle, pa, needle, pb);
  EXPECT_NEAR(p.distance, -0.5, 1e-9);
  EXPECT_LE(p.distance, p.upper_bound);
  std::printf("  parallel needles: distance %.12f, bound %.3g, certified %d, %d evaluations\n",
              p.distance, p.upper_bound, int(p.certified), p.evaluations);
  // Near-cubes (exponent 20) face to face and tilted: the depth along the face normal.
  const Superquadric cube(1.0, 1.0, 1.0, 20, 20, 20);
  const PenetrationResult c = penetration(cube, Pose{}, cube, Pose{Vec3(1.7, 0.3, -0.2), Mat3::Identity()});
  EXPECT_NEAR(c.distance, -0.3, 1e-6);
  EXPECT_NEAR(std::abs(c.normal.x()), 1.0, 1e-3);
  const Pose tilted = rotated(Vec3(0.2, 1.6, 0.1), Vec3(1, 0, 1), 0.3);
  const TwinResult t = twin(cube, Pose{}, cube, tilted, 40000);
  const PenetrationResult ct = penetration(cube, Pose{}, cube, tilted);
  EXPECT_GE(ct.distance, t.distance - 1e-9);
  std::printf("  cubes (exponent 20): face to face %.9f, tilted %.9f (twin %.9f)\n", c.distance,
              ct.distance, t.distance);
}

TEST(Penetration, SpheresAreAnalytic) {
  Rng r(31);
  for (int k = 0; k < 50; ++k) {
    const Sphere a{r.uni(0.2, 2.0)}, b{r.uni(0.2, 2.0)};
    const Pose pa{r.ball(1.0), r.rotation()}, pb{pa.r + r.ball(a.radius + b.radius), r.rotation()};
    const double exact = (pb.r - pa.r).norm() - a.radius - b.radius;
    EXPECT_NEAR(penetration(a, pa, b, pb).distance, exact, 1e-12);
  }
}

// ---- random overlaps against the twin ------------------------------------------------------
struct Stats {
  int n = 0, twin_better = 0, solver_better = 0, uncertified = 0;
  double worst_below = 0.0, worst_above = 0.0;
  long evals = 0;
  void print(const char* what) const {
    std::printf("  %s: %d overlapping pairs, solver below twin by at most %.2e (%d > 1e-9), above "
                "by at most %.2e (%d > 1e-9), uncertified %d, mean evaluations %.0f\n",
                what, n, worst_below, twin_better, worst_above, solver_better, uncertified,
                double(evals) / std::max(n, 1));
  }
};

template <SupportShape SA, SupportShape SB>
void compare(const SA& a, const Pose& pa, const SB& b, const Pose& pb, Stats& st) {
  const TwinResult t = twin(a, pa, b, pb);
  if (!(t.distance < 0.0)) return;  // keep the overlapping pairs
  const PenetrationResult p = penetration(a, pa, b, pb);
  ++st.n;
  st.evals += p.evaluations;
  if (!p.certified) ++st.uncertified;
  const double diff = p.distance - t.distance;
  const double scale = std::max(1.0, std::abs(t.distance));
  st.worst_below = std::max(st.worst_below, -diff / scale);
  st.worst_above = std::max(st.worst_above, diff / scale);
  if (diff < -1e-9 * scale) ++st.twin_better;
  if (diff > 1e-9 * scale) ++st.solver_better;
  EXPECT_GE(diff, -1e-9 * scale) << "solver " << p.distance << " twin " << t.distance;
  EXPECT_LE(p.distance, p.upper_bound);
  EXPECT_LE(t.distance, p.upper_bound + 1e-9 * scale) << "the twin beat the certified bound";
  // B moved along the normal by the depth touches A
  EXPECT_NEAR(distance_after_push(a, pa, b, pb, p, 0.0), 0.0, 1e-7 * scale);
}

TEST(Penetration, RandomEllipsoidOverlapsVsTwin) {
  Rng r(7);
  Stats st;
  const int n = scaled_count(150, 0.1, 10);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const Pose pa{r.ball(1.0), r.rotation()};
    const Pose pb{pa.r + r.ball(0.8 * (a.bounding_radius() + b.bounding_radius())), r.rotation()};
    compare(a, pa, b, pb, st);
  }
  st.print("ellipsoids");
  EXPECT_GT(st.n, n / 3);
  EXPECT_EQ(st.uncertified, 0);
}

TEST(Penetration, RandomSuperquadricAndUnlikeOverlapsVsTwin) {
  Rng r(11);
  Stats st;
  const int n = scaled_count(150, 0.1, 10);
  for (int k = 0; k < n; ++k) {
    const Superquadric a = random_superquadric(r, 3.0, 8.0);
    const Pose pa{r.ball(1.0), r.rotation()};
    const int kind = k % 3;
    if (kind == 0) {
      const Superquadric b = random_superquadric(r, 3.0, 8.0);
      compare(a, pa, b, Pose{pa.r + r.ball(0.8 * (a.bounding_radius() + b.bounding_radius())), r.rotation()}, st);
    } else if (kind == 1) {
      const Ellipsoid b = r.ellipsoid(5.0);
      compare(b, pa, a, Pose{pa.r + r.ball(0.8 * (a.bounding_radius() + b.bounding_radius())), r.rotation()}, st);
    } else {
      const Sphere b{r.uni(0.3, 1.5)};
      compare(a, pa, b, Pose{pa.r + r.ball(0.8 * (a.bounding_radius() + b.radius)), r.rotation()}, st);
    }
  }
  st.print("superquadrics, unlike shapes");
  EXPECT_GT(st.n, n / 3);
}

TEST(Penetration, ElongatedAndCoincidentCentresVsTwin) {
  // aspect 10 ellipsoids and superquadric rods crossing near their centres (peaks of width ~0.1)
  Rng r(13);
  Stats st;
  const int n = scaled_count(40, 0.25, 6);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a{2.0, 0.2, r.uni(0.2, 0.5)}, b{r.uni(1.0, 2.0), 0.2, 0.2};
    const Superquadric q(2.0, 0.2, 0.2, 2.0, r.uni(2.0, 6.0), r.uni(2.0, 6.0));
    const Pose pa{Vec3::Zero(), r.rotation()};
    const Pose pb{r.ball(k % 4 == 0 ? 0.0 : 0.3), r.rotation()};
    compare(a, pa, b, pb, st);
    compare(q, pa, b, pb, st);
  }
  st.print("elongated, near-coincident centres");
}

// ---- consistency with the distance solver --------------------------------------------------
TEST(Penetration, ShallowOverlapsAndSeparatedPairsAgreeWithDistanceSolver) {
  Rng r(17);
  double worst = 0.0;
  const int n = scaled_count(200, 0.1, 10);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(5.0);
    const Superquadric b = random_superquadric(r, 2.0, 4.0);
    const Pose pa{r.ball(1.0), r.rotation()};
    const double l = std::min(a.inscribed_radius(), b.inscribed_radius());
    const double gap = (k % 2 ? 1.0 : -1.0) * r.log_uni(1e-8, 1e-2) * l;
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    const PenetrationResult p = penetration(a, pa, b, pb);
    const DistanceResult d = distance(a, pa, b, pb);
    worst = std::max(worst, std::abs(p.distance - gap) / l);
    EXPECT_NEAR(p.distance, gap, 1e-9 * l);
    EXPECT_NEAR(p.distance, d.distance, 1e-9 * l);
    // symmetric in A and B (the normal reversed)
    const PenetrationResult q = penetration(b, pb, a, pa);
    EXPECT_NEAR(q.distance, p.distance, 1e-9 * l);
    EXPECT_NEAR(q.normal.dot(p.normal), -1.0, 1e-6);
  }
  std::printf("  shallow overlaps and gaps: %d pairs, max |d - gap| / l = %.2e\n", n, worst);
}

TEST(Penetration, DepthIsMinimal) {
  // Pushed by 99.9 % of the depth along any direction the bodies still overlap: in particular
  // along the solver's normal and along the twin's.
  Rng r(19);
  for (int k = 0; k < scaled_count(30, 0.2, 5); ++k) {
    const Ellipsoid a = r.ellipsoid(4.0), b = r.ellipsoid(4.0);
    const Pose pa{Vec3::Zero(), r.rotation()}, pb{r.ball(0.3), r.rotation()};
    const PenetrationResult p = penetration(a, pa, b, pb);
    ASSERT_LT(p.distance, 0.0);
    for (int j = 0; j < 20; ++j) {
      Pose moved = pb;
      moved.r += -0.999 * p.distance * (j == 0 ? p.normal : r.unit());
      EXPECT_LT(penetration(a, pa, b, moved).distance, 0.0);
    }
  }
}

}  // namespace
}  // namespace hb
