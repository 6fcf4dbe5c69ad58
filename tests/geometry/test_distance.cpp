// Distance solver: Jacobians vs finite differences, analytic spheres, symmetry, and agreement
// with the independent support-function reference on random ellipsoid pairs.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "geometry/distance.hpp"
#include "geometry/random_pairs.hpp"
#include "geometry/reference_distance.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;
using namespace distance_detail;

// Relative column-wise error of an analytic Jacobian against central differences.
template <int N, class Fn>
double jacobian_error(Fn&& residual, const Eigen::Matrix<double, N, 1>& y,
                      const Eigen::Matrix<double, N, N>& J, const Eigen::Matrix<double, N, 1>& h) {
  double worst = 0.0;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<double, N, 1> yp = y, ym = y, Fp, Fm;
    yp[j] += h[j];
    ym[j] -= h[j];
    residual(yp, Fp);
    residual(ym, Fm);
    const Eigen::Matrix<double, N, 1> col = (Fp - Fm) / (2 * h[j]);
    const double scale = std::max(J.col(j).norm(), 1e-300);
    if (J.col(j).norm() == 0.0 && col.norm() < 1e-9) continue;
    worst = std::max(worst, (col - J.col(j)).norm() / scale);
  }
  return worst;
}

template <class SA, class SB>
void check_jacobians(const SA& a, const SB& b, Rng& r, int samples) {
  const double L = std::max(a.bounding_radius(), b.bounding_radius());
  double worst8 = 0, worst5 = 0;
  for (int k = 0; k < samples; ++k) {
    const Posed<SA> A{&a, Pose{}};
    const Posed<SB> B{&b, Pose{r.ball(3 * L), r.rotation()}};
    Vec8 y;
    y << r.ball(L), B.pose.r + r.ball(L), r.uni(0.3, 2.0), r.uni(-1.0, 1.0);
    Vec8 F;
    Mat8 J;
    dist8_system(A, B, y, F, &J);
    Vec8 h;
    h << Vec3::Constant(1e-6 * L), Vec3::Constant(1e-6 * L), 1e-6, 1e-6;
    worst8 = std::max(worst8, jacobian_error<8>([&](const Vec8& z, Vec8& G) {
                        dist8_system(A, B, z, G, nullptr);
                      }, y, J, h));
    Vec5 y5;
    y5 << y.head<3>(), y[6], y[7];
    Vec5 F5, h5;
    Mat5 J5;
    dist5_system(A, B, y5, F5, &J5);
    h5 << Vec3::Constant(1e-6 * L), 1e-6, 1e-6;
    worst5 = std::max(worst5, jacobian_error<5>([&](const Vec5& z, Vec5& G) {
                        dist5_system(A, B, z, G, nullptr);
                      }, y5, J5, h5));
  }
  EXPECT_LT(worst8, 1e-6);
  EXPECT_LT(worst5, 1e-6);
  std::printf("  jacobian max relative column error: dist8 %.2e, dist5 %.2e\n", worst8, worst5);
}

TEST(DistanceJacobian, MatchesFiniteDifferences) {
  Rng r(11);
  check_jacobians(Sphere{0.8}, Sphere{1.3}, r, 200);
  check_jacobians(Ellipsoid{0.3, 1.7, 1.0}, Ellipsoid{2.0, 0.5, 0.9}, r, 200);
  check_jacobians(Sphere{0.6}, Ellipsoid{2.0, 0.5, 0.5}, r, 200);
}

TEST(Distance, SphereFastPathEqualsGenericPath) {
  Rng r(12);
  DistanceOptions generic;
  generic.analytic_spheres = false;
  for (int k = 0; k < 2000; ++k) {
    const Sphere a{r.uni(0.2, 2.0)}, b{r.uni(0.2, 2.0)};
    const Pose pa{r.ball(5.0), r.rotation()};
    // gaps from 1e-8 to a few diameters, and slight overlaps
    const double gap = (k % 4 == 0 ? -1.0 : 1.0) * r.log_uni(1e-8, k % 4 == 0 ? 1e-2 : 5.0);
    const Vec3 n = r.unit();
    const Pose pb{pa.r + (a.radius + b.radius + gap) * n, r.rotation()};
    const DistanceResult fast = distance(a, pa, b, pb);
    const DistanceResult slow = distance(a, pa, b, pb, generic);
    ASSERT_NE(slow.status, DistanceStatus::failed);
    const double tol = 1e-14 * (a.radius + b.radius + pb.r.norm() + pa.r.norm());
    EXPECT_NEAR(fast.distance, slow.distance, tol + 1e-12 * std::abs(gap));
    EXPECT_NEAR(fast.distance, gap, tol + 1e-12 * std::abs(gap));
    EXPECT_LE((fast.point_a - slow.point_a).norm(), 1e-9);
    EXPECT_LE((fast.point_b - slow.point_b).norm(), 1e-9);
    EXPECT_LE((fast.normal - slow.normal).norm(), 1e-9);
    EXPECT_NEAR(fast.alpha, slow.alpha, 1e-9);
    EXPECT_NEAR(fast.beta, slow.beta, 1e-9);
  }
}

TEST(Distance, SymmetricInAandB) {
  Rng r(13);
  double worst = 0;
  for (int k = 0; k < scaled_count(2000); ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(3.0), r.rotation()};
    const double gap = r.log_uni(1e-6, 5.0);
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    const DistanceResult ab = distance(a, pa, b, pb), ba = distance(b, pb, a, pa);
    ASSERT_NE(ab.status, DistanceStatus::failed);
    ASSERT_NE(ba.status, DistanceStatus::failed);
    const double e = std::abs(ab.distance - ba.distance);
    const double floor = 2e-15 * ((pb.r - pa.r).norm() + a.bounding_radius() + b.bounding_radius());
    worst = std::max(worst, e / gap);
    EXPECT_LE(e, 1e-9 * gap + floor);
    EXPECT_LE((ab.point_a - ba.point_b).norm(), 1e-6 * std::sqrt(gap) + 1e-9);
    EXPECT_LE((ab.normal + ba.normal).norm(), 1e-6);
  }
  std::printf("  symmetry: max |d(A,B) - d(B,A)| / d = %.2e\n", worst);
}

struct Stats {
  int n = 0, failed = 0, fallback = 0;
  long nr = 0, sd = 0;
  int nr_max = 0;
  double max_rel_ref = 0, max_rel_exact = 0, max_abs_ref = 0;
  void print(const char* name) const {
    std::printf(
        "  %-22s pairs %6d  failed %d  fallback %d  NR it mean %.2f max %d  SD it mean %.2f\n"
        "  %-22s max |d-d_ref|/|d_ref| %.2e  max |d-gap|/gap %.2e  max |d-d_ref| %.2e\n",
        name, n, failed, fallback, double(nr) / n, nr_max, double(sd) / n, "", max_rel_ref,
        max_rel_exact, max_abs_ref);
  }
};

// One pair: compare with the reference and (when known) the exact constructed gap.
void check_pair(const Ellipsoid& a, const Pose& pa, const Ellipsoid& b, const Pose& pb,
                double gap, Stats& st, const DistanceOptions& o = {}) {
  const DistanceResult res = distance(a, pa, b, pb, o);
  const ref::RefDistance rd = ref::reference_distance(a, pa, b, pb);
  ++st.n;
  st.nr += res.nr_iterations;
  st.sd += res.sd_iterations;
  st.nr_max = std::max(st.nr_max, res.nr_iterations);
  if (res.status == DistanceStatus::failed) ++st.failed;
  if (res.status == DistanceStatus::fallback) ++st.fallback;
  EXPECT_NE(res.status, DistanceStatus::failed)
      << "a " << a.a << " " << a.b << " " << a.c << " b " << b.a << " " << b.b << " " << b.c
      << " gap " << gap;
  // absolute floor: rounding of coordinates of magnitude |r_B - r_A| + sizes
  const double floor = 2e-15 * ((pb.r - pa.r).norm() + a.bounding_radius() + b.bounding_radius());
  const double err_ref = std::abs(res.distance - rd.distance);
  st.max_abs_ref = std::max(st.max_abs_ref, err_ref);
  st.max_rel_ref = std::max(st.max_rel_ref, err_ref / std::abs(rd.distance));
  EXPECT_LE(err_ref, 1e-9 * std::abs(rd.distance) + floor)
      << "d " << res.distance << " ref " << rd.distance << " gap " << gap;
  if (gap > 0) {
    const double err_exact = std::abs(res.distance - gap);
    st.max_rel_exact = std::max(st.max_rel_exact, err_exact / gap);
    EXPECT_LE(err_exact, 1e-9 * gap + floor);
    // closest points agree with the reference (they are unique for strictly convex bodies)
    EXPECT_LE((res.point_a - rd.point_a).norm(), 1e-6 * (a.bounding_radius() + b.bounding_radius()));
  }
}

TEST(Distance, RandomEllipsoidPairsVsReference) {
  Rng r(14);
  Stats st;
  const int n = scaled_count(10000);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(3.0), r.rotation()};
    const double diam = 2 * std::max(a.bounding_radius(), b.bounding_radius());
    const double gap = r.log_uni(1e-6, 3.0 * diam);
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    check_pair(a, pa, b, pb, gap, st);
  }
  st.print("random");
  EXPECT_EQ(st.failed, 0);
}

// Elongated bodies side by side with nearly parallel axes, and crossed at right angles.
TEST(Distance, ElongatedParallelAndCrossedVsReference) {
  Rng r(15);
  Stats par, crossed, oblate;
  const int n = scaled_count(3000);
  for (int k = 0; k < n; ++k) {
    const double X = r.log_uni(3.0, 10.0), s = r.uni(0.2, 0.6);
    const Ellipsoid a{X * s, s, s}, b{X * s * r.uni(0.5, 1.0), s, s};
    const Pose pa{r.ball(2.0), r.rotation()};
    const double gap = r.log_uni(1e-6, 4.0 * X * s);
    // near-parallel: B's long axis = A's long axis tilted by 1e-8..1e-2 rad; n normal to it
    {
      const Mat3 Rb = testing::small_rotation(r, r.log_uni(1e-8, 1e-2)) * pa.R;
      const Vec3 axis = pa.R.col(0);
      Vec3 n2 = r.unit();
      n2 = (n2 - axis * axis.dot(n2)).normalized();
      const Pose pb = testing::place_at_distance(a, pa, b, Rb, n2, gap);
      check_pair(a, pa, b, pb, gap, par);
    }
    // crossed: long axes at right angles, n along their common normal
    {
      const Vec3 axa = pa.R.col(0);
      const Vec3 u = r.unit();
      const Vec3 w = (u - axa * axa.dot(u)).normalized();  // B's long axis
      const Vec3 nrm = axa.cross(w);
      Mat3 Rb;
      Rb.col(0) = w;
      Rb.col(1) = nrm;
      Rb.col(2) = w.cross(nrm);
      const Pose pb = testing::place_at_distance(a, pa, b, Rb, nrm, gap);
      check_pair(a, pa, b, pb, gap, crossed);
    }
    // oblate discs face to face, nearly parallel
    {
      const Ellipsoid da{s, X * s, X * s}, db{s * r.uni(0.5, 1.0), X * s, X * s};
      const Mat3 Rb = testing::small_rotation(r, r.log_uni(1e-8, 1e-1)) * pa.R;
      const Pose pb = testing::place_at_distance(da, pa, db, Rb, pa.R.col(0), gap);
      check_pair(da, pa, db, pb, gap, oblate);
    }
  }
  par.print("near-parallel prolate");
  crossed.print("crossed prolate");
  oblate.print("face-to-face oblate");
  EXPECT_EQ(par.failed + crossed.failed + oblate.failed, 0);
}

// Slightly overlapping pairs: the negative-distance solution equals minus the penetration depth
// (the reference's maximum of the separation function, which is negative).
TEST(Distance, SlightOverlapNegativeDistance) {
  Rng r(16);
  Stats st;
  for (int k = 0; k < scaled_count(3000); ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const Pose pa{r.ball(3.0), r.rotation()};
    const double depth = r.log_uni(1e-8, 1e-3) * std::min(a.inscribed_radius(), b.inscribed_radius());
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), -depth);
    check_pair(a, pa, b, pb, -depth, st);
    EXPECT_LT(distance(a, pa, b, pb).distance, 0.0);
  }
  st.print("slight overlap");
  EXPECT_EQ(st.failed, 0);
}

// Warm start from the previous solution after a small motion: same answer, fewer iterations.
TEST(Distance, WarmStartAgreesAndIsCheaper) {
  Rng r(17);
  long cold_it = 0, warm_it = 0;
  int n = scaled_count(3000);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(3.0), r.rotation()};
    const double gap = r.log_uni(1e-6, 2.0);
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    const DistanceResult first = distance(a, pa, b, pb);
    const double eps = 0.02 * std::min(gap, 0.5);
    const Pose pa2{pa.r + eps * r.unit(), testing::small_rotation(r, eps) * pa.R};
    const Pose pb2{pb.r + eps * r.unit(), testing::small_rotation(r, eps) * pb.R};
    const DistanceResult cold = distance(a, pa2, b, pb2);
    const DistanceResult warm = distance(a, pa2, b, pb2, {}, &first.warm);
    ASSERT_NE(warm.status, DistanceStatus::failed);
    EXPECT_EQ(warm.attempt, 1);
    EXPECT_NEAR(warm.distance, cold.distance, 1e-9 * std::abs(cold.distance) + 1e-14);
    cold_it += cold.nr_iterations;
    warm_it += warm.nr_iterations;
  }
  std::printf("  NR iterations per call: cold %.2f, warm %.2f\n", double(cold_it) / n,
              double(warm_it) / n);
  EXPECT_LT(warm_it, cold_it);
}

// The alternative choices (5 equations, centre-line guess, no SD) reach the same distance.
TEST(Distance, AlternativeSystemsAndGuessesAgree) {
  Rng r(18);
  DistanceOptions five, centre, nosd;
  five.system = DistanceSystem::five;
  centre.guess = DistanceGuess::center_line;
  nosd.sd_iter = 0;
  Stats s5, sc, sn;
  for (int k = 0; k < scaled_count(2000); ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const Pose pa{r.ball(3.0), r.rotation()};
    const double gap = r.log_uni(1e-6, 4.0);
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    check_pair(a, pa, b, pb, gap, s5, five);
    check_pair(a, pa, b, pb, gap, sc, centre);
    check_pair(a, pa, b, pb, gap, sn, nosd);
  }
  s5.print("5 equations");
  sc.print("centre-line guess");
  sn.print("no SD refinement");
}

// Deep overlap (coincident centres) is outside the method's domain: the result must not be a
// silent positive distance: either a valid negative solution or the failed status.
TEST(Distance, DeepOverlapIsNeverSilentlyPositive) {
  Rng r(19);
  for (int k = 0; k < 200; ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(1.0), r.rotation()};
    const Pose pb{pa.r + r.ball(0.2 * std::min(a.inscribed_radius(), b.inscribed_radius())),
                  r.rotation()};
    const DistanceResult d = distance(a, pa, b, pb);
    EXPECT_TRUE(d.status == DistanceStatus::failed || d.distance < 0.0);
  }
}


// A useless warm start (points on the far sides) is detected and the cold guess takes over.
TEST(Distance, BadWarmStartFallsBackToColdGuess) {
  Rng r(20);
  for (int k = 0; k < 200; ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(3.0), r.rotation()};
    const double gap = r.log_uni(1e-4, 2.0);
    const Vec3 n = r.unit();
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), n, gap);
    DistanceWarmStart bad;
    bad.valid = true;
    bad.xa_body = a.support_point(-(pa.R.transpose() * n));  // far side of A
    bad.xb_body = b.support_point(pb.R.transpose() * n);     // far side of B
    const DistanceResult d = distance(a, pa, b, pb, {}, &bad);
    ASSERT_NE(d.status, DistanceStatus::failed);
    EXPECT_TRUE(d.warm_used);
    EXPECT_NEAR(d.distance, gap, 1e-9 * gap + 1e-13);
  }
}

// The first solve of a contact prediction starts from the support points of a separating axis
// (DistanceWarmStart::guess).  Long bodies nearly parallel and staggered, the axis a few degrees
// off the true normal: the support points then lie far apart along the bodies' length.  With the
// guess flag they are slid together by a short steepest descent before the 5-equation NR; the
// same points used as a plain warm start (the twin, the code before the flag) often lead NR to
// a rejected spurious solution and a cold restart.  Both give the exact distance.
TEST(Distance, SupportPointGuessOfStaggeredLongBodies) {
  Rng r(22);
  const int n = scaled_count(3000);
  long iters[2] = {0, 0}, first_failed[2] = {0, 0};
  for (int k = 0; k < n; ++k) {
    const double X = r.log_uni(3.0, 10.0), s = r.uni(0.2, 0.6);
    const Ellipsoid a{X * s, s, s}, b{X * s * r.uni(0.5, 1.0), s, s};
    const Pose pa{r.ball(2.0), r.rotation()};
    const Mat3 Rb = testing::small_rotation(r, r.log_uni(1e-6, 1e-1)) * pa.R;
    const Vec3 nrm = r.unit();  // staggered: n has a component along the long axis
    const double gap = r.log_uni(1e-5, 2.0 * s);
    const Pose pb = testing::place_at_distance(a, pa, b, Rb, nrm, gap);
    // The axis of a prediction's first solve is where the separating-axis advancement stopped:
    // a direction whose gap has just run down to ~0 while the bodies are still gap apart (they
    // turned since the axis was chosen).  Such a direction: tilt the normal about a random
    // axis to the edge of the cone of separating directions (bisection on the gap's sign).
    auto axis_gap = [&](const Vec3& m) {
      const Vec3 sa = pa.r + pa.R * a.support_point(pa.R.transpose() * m);
      const Vec3 sb = pb.r + Rb * b.support_point(-(Rb.transpose() * m));
      return m.dot(sb - sa);
    };
    Vec3 tilt = r.unit();
    tilt = (tilt - nrm * nrm.dot(tilt)).normalized();
    auto tilted = [&](double angle) { return Vec3(Eigen::AngleAxisd(angle, tilt) * nrm); };
    double lo = 0.0, hi = 1.5;
    if (axis_gap(tilted(hi)) > 0.0) continue;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (axis_gap(tilted(mid)) > 0.0 ? lo : hi) = mid;
    }
    const Vec3 axis = tilted(lo);
    for (int g = 0; g < 2; ++g) {
      DistanceWarmStart w;
      w.xa_body = a.support_point(pa.R.transpose() * axis);
      w.xb_body = b.support_point(-(Rb.transpose() * axis));
      w.valid = true;
      w.guess = g == 1;
      const DistanceResult d = distance(a, pa, b, pb, {}, &w);
      ASSERT_NE(d.status, DistanceStatus::failed);
      EXPECT_NEAR(d.distance, gap, 1e-9 * gap + 1e-13);
      iters[g] += d.nr_iterations;
      first_failed[g] += d.attempt != 1;
    }
  }
  std::printf("  %d pairs: first attempt failed %ld (plain warm start) vs %ld (guess), "
              "NR iterations per call %.2f vs %.2f\n",
              n, first_failed[0], first_failed[1], double(iters[0]) / n, double(iters[1]) / n);
  // (the plain start fails a few first attempts in the full sample, 5 of 3000; the reduced
  // Debug sample may hold none of them, so only the guess's count is asserted exactly)
  EXPECT_EQ(first_failed[1], 0);
  EXPECT_LE(first_failed[1], first_failed[0]);
  EXPECT_LT(iters[1], iters[0]);
}

// When every attempt is starved of iterations (and the global stage 8 is off) the status says
// so (never a silent value), and the reported distance is the steepest-descent estimate: an
// upper bound of the true gap.
TEST(Distance, ExhaustedSolverReportsFailure) {
  Rng r(21);
  DistanceOptions starved;
  starved.max_nr_iter = 1;
  starved.global_stage = false;
  int failed = 0;
  for (int k = 0; k < 100; ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(3.0), r.rotation()};
    const double gap = r.log_uni(1e-3, 2.0);
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    const DistanceResult d = distance(a, pa, b, pb, starved);
    if (d.status == DistanceStatus::failed) {
      ++failed;
      EXPECT_GE(d.distance, gap * (1 - 1e-12));
      EXPECT_FALSE(d.warm.valid);
    }
  }
  EXPECT_GT(failed, 50);
}

// Stage 8 alone (every local stage starved of iterations: max_nr_iter = 0) against the full
// solver, its twin: separated, near-contact and slightly overlapping pairs of unlike ellipsoids
// (elongated ones included) all succeed at attempt 8 with the same signed distance and normal.
TEST(Distance, GlobalStageAgreesWithTheSolver) {
  Rng r(23);
  DistanceOptions starved;
  starved.max_nr_iter = 0;
  const int n = testing::scaled_count(200, 0.1);
  double worst_d = 0.0, worst_n = 0.0;
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(), b = r.ellipsoid();
    const Pose pa{r.ball(3.0), r.rotation()};
    const double gap = k % 4 == 0 ? -r.log_uni(1e-9, 1e-3) : r.log_uni(1e-9, 2.0);
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), gap);
    const DistanceResult full = distance(a, pa, b, pb);
    const DistanceResult global = distance(a, pa, b, pb, starved);
    ASSERT_EQ(full.status, DistanceStatus::converged) << k;
    ASSERT_EQ(global.status, DistanceStatus::fallback) << k;
    ASSERT_EQ(global.attempt, 8) << k;
    worst_d = std::max(worst_d, std::abs(global.distance - full.distance) / std::max(1.0, std::abs(full.distance)));
    worst_n = std::max(worst_n, (global.normal - full.normal).norm());
    // the points are the support points along the normal, |x_B - x_A| = |d| for smooth bodies
    EXPECT_NEAR((global.point_b - global.point_a).norm(), std::abs(global.distance), 1e-6) << k;
  }
  std::printf("  %d pairs: stage 8 vs the solver, distances differ by %.2e (relative), normals by %.2e\n",
              n, worst_d, worst_n);
  EXPECT_LT(worst_d, 1e-12);
  EXPECT_LT(worst_n, 1e-6);
}

// The pair on which every local stage failed in the performance study (superquadrics
// (2, 2, 16), X0 = 0.5, seed 2, 2026-11-25: bodies 342 and 298 at their collision, flat faces
// nearly parallel): stage 8 gives a certified contact, normal from A towards B.
TEST(Distance, FlatFacesAtContactWhereTheLocalStagesFailed) {
  const Superquadric s(0.80000000000000004, 1.6000000000000001, 1.6000000000000001, 2, 2, 16);
  const Pose pa{Vec3(26.159365281801541, 7.1597810322088264, 25.501821049657678),
                Quat(-0.60233414401125251, -0.49527350520021574, -0.54170812933772483,
                     -0.31376748814105382).toRotationMatrix()};
  const Pose pb{Vec3(27.036079784998247, 7.2208103575392055, 23.122696642719234),
                Quat(0.42631978893954209, -0.64579428584313336, -0.24178532135459932,
                     0.58544089053324144).toRotationMatrix()};
  const DistanceResult d = distance(s, pa, s, pb);
  std::printf("  attempt %d, distance %.2e, normal (%.4f, %.4f, %.4f)\n", d.attempt, d.distance,
              d.normal.x(), d.normal.y(), d.normal.z());
  ASSERT_NE(d.status, DistanceStatus::failed);
  EXPECT_LT(std::abs(d.distance), 1e-9);
  EXPECT_NEAR(d.normal.norm(), 1.0, 1e-12);
  EXPECT_GT(d.normal.dot(pb.r - pa.r), 0.0);
  // without stage 8 this pair fails (the reason the stage exists)
  DistanceOptions local;
  local.global_stage = false;
  EXPECT_EQ(distance(s, pa, s, pb, local).status, DistanceStatus::failed);
}

}  // namespace
}  // namespace hb
