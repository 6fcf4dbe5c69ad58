// The distance solve at a collision (system/rigid_bodies.hpp, collision_distance): started from
// the support points of a separating axis (touching_guess, contact/contact_time.hpp) instead of
// the solver's cold guess. Its twin is the cold solve itself: on touching, slightly overlapping
// and nearly touching pairs (exact distances by construction, geometry/random_pairs.hpp) of
// elongated ellipsoids, unlike pairs and superquadrics both must give the constructed distance,
// the same normal and, for strictly convex bodies, the same closest points.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "geometry/random_pairs.hpp"
#include "shapes/superquadric.hpp"
#include "system/rigid_bodies.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

struct Tally {
  int n = 0, guessed = 0;
  long nr_guess = 0, nr_cold = 0;
  double dist = 0.0, normal = 0.0, points = 0.0;
};

// One pair at gap `gap` along a random direction; `unique`: the closest points are unique
// (strictly convex shapes), so they are compared too.
template <SupportShape SA, SupportShape SB>
void check_pair(Rng& r, const SA& a, const SB& b, double gap, bool unique, Tally& t) {
  const double L = std::max(a.bounding_radius(), b.bounding_radius());
  const Pose pa{r.ball(1.0), r.rotation()};
  const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
  const DistanceResult g =
      collision_distance(a, Quat(pa.R), pa, b, Quat(pb.R), pb, DistanceOptions{}, true);
  const DistanceResult c =
      collision_distance(a, Quat(pa.R), pa, b, Quat(pb.R), pb, DistanceOptions{}, false);
  ASSERT_NE(g.status, DistanceStatus::failed);
  ASSERT_NE(c.status, DistanceStatus::failed);
  ASSERT_FALSE(c.warm_used);  // the twin is the cold solve
  ++t.n;
  if (g.warm_used && g.attempt == 1) ++t.guessed;
  t.nr_guess += g.nr_iterations + g.sd_iterations;
  t.nr_cold += c.nr_iterations + c.sd_iterations;
  t.dist = std::max({t.dist, std::abs(g.distance - gap) / L, std::abs(c.distance - gap) / L});
  t.normal = std::max(t.normal, (g.normal - c.normal).norm());
  if (unique)
    t.points = std::max({t.points, (g.point_a - c.point_a).norm() / L,
                         (g.point_b - c.point_b).norm() / L});
}

double collision_gap(Rng& r, double L) {
  switch (static_cast<int>(r.uni(0, 4))) {
    case 0: return 0.0;                               // touching
    case 1: return -r.log_uni(1e-14, 1e-10) * L;      // overlapping at rounding level
    case 2: return r.log_uni(1e-14, 1e-9) * L;        // within the re-check's tolerance
    default: return r.log_uni(1e-9, 1e-3) * L;        // a contact that moved (re-check)
  }
}

void report(const char* what, const Tally& t) {
  std::printf("  %s: %d pairs, guess converged in %d; NR+SD iterations %.2f (guess) vs %.2f (cold); "
              "max |d - gap| / L %.1e, max |n_guess - n_cold| %.1e, max point difference / L %.1e\n",
              what, t.n, t.guessed, double(t.nr_guess) / t.n, double(t.nr_cold) / t.n, t.dist,
              t.normal, t.points);
}

TEST(CollisionDistance, TouchingGuessAgreesWithTheColdSolveForEllipsoids) {
  Rng r(83);
  Tally t;
  const int n = scaled_count(4000, 0.05);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(10.0), b = r.ellipsoid(10.0);
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    check_pair(r, a, b, collision_gap(r, L), true, t);
  }
  report("ellipsoids (aspect up to 10)", t);
  EXPECT_LE(t.dist, 1e-11);
  EXPECT_LE(t.normal, 1e-7);
  EXPECT_LE(t.points, 1e-6);
  EXPECT_GE(t.guessed, t.n * 99 / 100);  // the guess is good enough for the warm system
}

TEST(CollisionDistance, TouchingGuessAgreesWithTheColdSolveForUnlikePairs) {
  Rng r(89);
  Tally t;
  const int n = scaled_count(2000, 0.05);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(10.0);
    const Sphere s{r.uni(0.1, 2.0)};
    const double L = std::max(a.bounding_radius(), s.bounding_radius());
    if (k % 2) check_pair(r, a, s, collision_gap(r, L), true, t);
    else check_pair(r, s, a, collision_gap(r, L), true, t);
  }
  report("ellipsoid and sphere", t);
  EXPECT_LE(t.dist, 1e-11);
  EXPECT_LE(t.normal, 1e-7);
  EXPECT_LE(t.points, 1e-6);
}

// Superquadrics with flat faces: the closest points of two faces touching flat are not unique,
// so only the distance and the normal are compared, and only on curved patches the normal is
// unique too: the distance alone is asserted here (both solves land on a valid solution).
TEST(CollisionDistance, TouchingGuessAgreesWithTheColdSolveForSuperquadrics) {
  Rng r(97);
  Tally t;
  const int n = scaled_count(1000, 0.05);
  for (int k = 0; k < n; ++k) {
    const double e = k % 2 ? 4.0 : 8.0;
    const Superquadric a{r.uni(0.5, 2.0), r.uni(0.5, 2.0), r.uni(0.3, 1.0), e, e, e};
    const Superquadric b{r.uni(0.5, 2.0), r.uni(0.3, 1.0), r.uni(0.3, 1.0), 2.0, 2.0, e};
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    check_pair(r, a, b, collision_gap(r, L), false, t);
  }
  report("superquadrics (exponents 4 and 8)", t);
  EXPECT_LE(t.dist, 1e-10);
}

// The contact read off an axis (touching_along, the collision's shortcut when the pair's memo
// holds its contact normal) against the cold solve: on touching pairs and pairs within rounding
// of touching, along their exact normal, it must certify and give the same distance (to
// 1e-11 L), normal and, for strictly convex bodies, closest points; for pairs apart by more than
// its tolerance, or along an axis tilted off the normal, it must decline (the distance solve
// then runs). Ellipsoids up to aspect 10, ellipsoid and sphere, superquadrics (exponents 4, 8).
template <SupportShape SA, SupportShape SB>
void check_touch(Rng& r, const SA& a, const SB& b, bool unique, int k, Tally& t, int& declined) {
  const double L = std::max(a.bounding_radius(), b.bounding_radius());
  const Pose pa{r.ball(1.0), r.rotation()};
  const Vec3 n = r.unit();
  const int kind = k % 4;  // 0, 1: touching to rounding; 2: apart; 3: tilted axis
  const double gap = kind == 0 ? 0.0 : kind == 1 ? r.uni(-1.0, 1.0) * r.log_uni(1e-15, 1e-12) * L
                                     : kind == 2 ? r.log_uni(1e-9, 1e-3) * L : 0.0;
  const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), n, gap);
  const Vec3 axis = kind == 3 ? Vec3(testing::small_rotation(r, r.log_uni(1e-6, 1e-2)) * n) : n;
  DistanceResult d;
  const bool took = touching_along(a, Quat(pa.R), pa, b, Quat(pb.R), pb, axis, 1e-10, d);
  if (kind >= 2) {
    EXPECT_FALSE(took) << "kind " << kind << " pair " << k;
    declined += !took;
    return;
  }
  ASSERT_TRUE(took) << "pair " << k << " gap " << gap;
  const DistanceResult c =
      collision_distance(a, Quat(pa.R), pa, b, Quat(pb.R), pb, DistanceOptions{}, false);
  ASSERT_NE(c.status, DistanceStatus::failed);
  ++t.n;
  t.dist = std::max({t.dist, std::abs(d.distance - gap) / L, std::abs(d.distance - c.distance) / L});
  t.normal = std::max(t.normal, (d.normal - c.normal).norm());
  if (unique)
    t.points = std::max({t.points, (d.point_a - c.point_a).norm() / L, (d.point_b - c.point_b).norm() / L});
}

TEST(CollisionDistance, ContactReadOffTheNormalAgreesWithTheColdSolve) {
  Rng r(101);
  Tally ell, mix, sq;
  int declined = 0, asked = 0;
  const int n = scaled_count(2000, 0.05);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(10.0), b = r.ellipsoid(10.0);
    check_touch(r, a, b, true, k, ell, declined);
    const Sphere s{r.uni(0.1, 2.0)};
    if (k % 2) check_touch(r, a, s, true, k, mix, declined);
    else check_touch(r, s, a, true, k, mix, declined);
    const double e = k % 8 < 4 ? 4.0 : 8.0;
    const Superquadric qa{r.uni(0.5, 2.0), r.uni(0.5, 2.0), r.uni(0.3, 1.0), e, e, e};
    const Superquadric qb{r.uni(0.5, 2.0), r.uni(0.3, 1.0), r.uni(0.3, 1.0), 2.0, 2.0, e};
    check_touch(r, qa, qb, false, k, sq, declined);
    asked += k % 4 >= 2 ? 3 : 0;
  }
  report("read off the normal: ellipsoids", ell);
  report("read off the normal: ellipsoid and sphere", mix);
  report("read off the normal: superquadrics", sq);
  std::printf("  declined %d of %d pairs apart or along a tilted axis\n", declined, asked);
  for (const Tally* t : {&ell, &mix}) {
    EXPECT_LE(t->dist, 1e-11);
    EXPECT_LE(t->normal, 1e-7);
    EXPECT_LE(t->points, 1e-6);
  }
  EXPECT_LE(sq.dist, 1e-10);
  EXPECT_EQ(declined, asked);
}

}  // namespace
}  // namespace hb
