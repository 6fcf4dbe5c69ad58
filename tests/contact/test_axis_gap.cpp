// The gap along a fixed axis (contact/axis_gap.hpp), the cheap lower bound the contact-time
// solver advances on: its rate against central differences, its curvature against the bound M,
// the lower-bound property against the independent reference distance, and the separating-axis
// search converging to the distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <vector>

#include "contact/axis_gap.hpp"
#include "geometry/random_pairs.hpp"
#include "geometry/reference_distance.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

struct Pair {
  Ellipsoid a, b;
  BodyState sa, sb;
};

// Separated ellipsoids (aspect up to 5), moving and spinning, B at distance `gap` along a
// random direction at t = 0; `tops`: asymmetric tops with random principal moments (their w
// changes along the flight), otherwise spherical tops.
Pair random_pair(Rng& r, double gap, bool tops = false) {
  Pair p;
  p.a = r.ellipsoid(5.0);
  p.b = r.ellipsoid(5.0);
  const double L = std::max(p.a.bounding_radius(), p.b.bounding_radius());
  const Pose pa{r.ball(1.0), r.rotation()};
  const Pose pb = testing::place_at_distance(p.a, pa, p.b, r.rotation(), r.unit(), gap);
  p.sa = BodyState{pa.r, Quat(pa.R), r.ball(1.0), r.ball(3.0 / L)};
  p.sb = BodyState{pb.r, Quat(pb.R), r.ball(1.0), r.ball(3.0 / L)};
  if (tops) {
    p.sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
    p.sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
  }
  return p;
}

template <class SA, class SB>
double reference_distance_at(const SA& a, const Motion& ma, const SB& b, const Motion& mb, double t) {
  return ref::reference_distance(a, Pose{ma.position(t), ma.orientation(t).toRotationMatrix()}, b,
                                 Pose{mb.position(t), mb.orientation(t).toRotationMatrix()})
      .distance;
}

double reference_distance_at(const Pair& p, double t) {
  const Pose pa{p.sa.r + p.sa.v * t, rotation_at(p.sa, t)};
  const Pose pb{p.sb.r + p.sb.v * t, rotation_at(p.sb, t)};
  return ref::reference_distance(p.a, pa, p.b, pb).distance;
}

// Rate of the gap against central differences, |g'| <= Kn and |FD g''| <= M on random axes;
// `growing`: random scale laws s0 + sdot tau, bounds for the largest scale on |tau| <= 1.
void check_rate_and_curvature(std::uint64_t seed, bool growing, bool tops = false) {
  Rng r(seed);
  double worst_rate = 0.0, worst_curv = 0.0, worst_k = 0.0, worst_fd = 0.0;
  const int n = scaled_count(2000, 0.1);
  for (int k = 0; k < n; ++k) {
    const Pair p = random_pair(r, r.log_uni(1e-3, 2.0), tops);
    const double s0 = growing ? r.uni(0.5, 1.5) : 1.0, sdot = growing ? r.uni(-0.2, 0.5) : 0.0;
    const Motion mota(p.sa), motb(p.sb);
    AxisGap<Ellipsoid, Ellipsoid> g(p.a, mota, p.b, motb, 0.0, r.unit(), s0, sdot);
    EXPECT_TRUE(g.is_curved());
    g.bounds(s0 + std::abs(sdot));
    const double t = r.uni(-0.9, 0.9), h = 1e-5;
    double slope;
    Vec3 ma, mb;
    const double g0 = g.value(t, slope, ma, mb);
    const double gp = g.value(t + h), gm = g.value(t - h);
    worst_rate = std::max(worst_rate, std::abs((gp - gm) / (2 * h) - slope) / g.Kn);
    worst_curv = std::max(worst_curv, std::abs((gp - 2 * g0 + gm) / (h * h)) / g.M);
    worst_k = std::max(worst_k, std::abs(slope) / g.Kn);
    worst_fd = std::max(worst_fd, std::abs((gp - gm) / (2 * h)) / g.Kn);
  }
  std::printf("  %d %s%s axes: max |g' - FD| / Kn %.2e, max |g'| / Kn %.3f, max |FD g''| / M %.3f\n",
              n, growing ? "growing" : "rigid", tops ? " asymmetric-top" : "", worst_rate, worst_k,
              worst_curv);
  EXPECT_LT(worst_rate, 1e-6);
  EXPECT_LE(worst_fd, 1.0 + 1e-6);         // the rate bound holds
  EXPECT_LE(worst_k, 1.0 + 1e-12);
  EXPECT_LE(worst_curv, 1.0 + 1e-3);  // FD of g'' is accurate to ~1e-5 relative here
}

TEST(AxisGap, RateAndCurvatureMatchFiniteDifferencesAndBounds) { check_rate_and_curvature(41, false); }

TEST(AxisGap, GrowingShapesRateAndCurvatureMatchFiniteDifferencesAndBounds) {
  check_rate_and_curvature(59, true);
}

// Asymmetric tops: g' against central differences, |g'| <= Kn with the max-|w| bound and
// |g''| <= M with the max-|W'| bound, rigid and growing.
TEST(AxisGap, AsymmetricTopsRateBound) {
  check_rate_and_curvature(61, false, true);
  check_rate_and_curvature(67, true, true);
}

void check_lower_bound(std::uint64_t seed, bool tops) {
  Rng r(seed);
  const int n = scaled_count(1000, 0.1);
  double worst_excess = -kInf, worst_normal = 0.0;
  for (int k = 0; k < n; ++k) {
    const Pair p = random_pair(r, r.log_uni(1e-4, 2.0), tops);
    const Motion ma(p.sa), mb(p.sb);
    const double t = r.uni(0.0, 0.3);
    const double d = reference_distance_at(p, t);
    if (!(d > 0.0)) continue;  // moved into contact: no statement
    // random axes: never above the distance
    for (int m = 0; m < 5; ++m) {
      const AxisGap<Ellipsoid, Ellipsoid> g(p.a, ma, p.b, mb, 0.0, r.unit());
      worst_excess = std::max(worst_excess, g.value(t) - d);
    }
    // the normal at the closest points of t = 0: equal to the distance there
    const Pose pa{p.sa.r, p.sa.q.toRotationMatrix()}, pb{p.sb.r, p.sb.q.toRotationMatrix()};
    const auto rd = ref::reference_distance(p.a, pa, p.b, pb);
    const AxisGap<Ellipsoid, Ellipsoid> g(p.a, ma, p.b, mb, 0.0, rd.n);
    worst_normal = std::max(worst_normal, std::abs(g.value(0.0) - rd.distance));
  }
  std::printf("  %d pairs%s: max (g - d) on random axes %.2e, max |g - d| along the normal %.2e\n",
              n, tops ? " (asymmetric tops)" : "", worst_excess, worst_normal);
  EXPECT_LE(worst_excess, 1e-12);
  EXPECT_LE(worst_normal, 1e-9);
}

TEST(AxisGap, IsALowerBoundOfTheDistanceAndExactAlongTheNormal) { check_lower_bound(43, false); }
TEST(AxisGap, AsymmetricTopsLowerBound) { check_lower_bound(71, true); }

// A case for the pre-filters of the prediction loop: a random pair (near contact to 2 apart) at
// B's stored time 0, and `now` = age later, A's orientation and angular velocity streamed there
// (qa, wa), the centre separation c at now; a window of up to 0.5 from now.
struct ClearCase {
  Pair p;
  Motion ma, mb;
  double age, span;
  Vec3 c, wa;
  Quat qa;
};
ClearCase clear_case(Rng& r, bool tops) {
  const Pair p = random_pair(r, r.log_uni(1e-3, 2.0), tops);
  const Motion ma(p.sa), mb(p.sb);
  const double age = r.uni(0.0, 0.3), span = r.log_uni(1e-3, 0.5);
  Quat qa;
  Vec3 wa;
  ma.pose(age, qa, wa);
  return ClearCase{p, ma, mb, age, span, Vec3(mb.position(age) - ma.position(age)), wa, qa};
}

// clear_along_centres, the prediction loop's pre-filter, against the gap along the line of
// centres itself: B's orientation is the one it had `age` before `now`; for sampled times t in
// the window, g_u(t) (true orientations of both at t) must stay above the test's straight line
// g_u(now) - K_u (t - now) (its lower bound of g_u(now), from B's old orientation, and its rate
// bound; spherical tops with w x u, asymmetric tops with their largest angular speed), and the
// distance at t must be positive wherever the test says clear. Pairs from near contact to 2 apart,
// windows up to 0.5.
void check_clear_along_centres(std::uint64_t seed, bool tops) {
  Rng r(seed);
  const int n = scaled_count(2000, 0.1);
  int cleared = 0;
  double worst = -kInf;
  for (int k = 0; k < n; ++k) {
    const ClearCase cc = clear_case(r, tops);
    const auto& [p, ma, mb, age, span, c, wa, qa] = cc;
    const Vec3 u = c.normalized();
    const double wmax_a = tops ? ma.max_angular_speed() : -1.0;
    const double wmax_b = tops ? mb.max_angular_speed() : -1.0;
    const Vec3 dv = p.sb.v - p.sa.v;
    // the test's own lower line, recomputed here from its parts
    auto turn = [&](double l, const Vec3& w, double wmax) { return wmax < 0.0 ? l * w.cross(u).norm() : l * wmax; };
    const double la = rotation_lever(p.a), lb = rotation_lever(p.b);
    const double tb = turn(lb, p.sb.w, wmax_b);
    const double g0 = c.norm() - p.a.support(qa.conjugate() * u) -
                      p.b.support(p.sb.q.conjugate() * Vec3(-u)) - tb * age;
    const double Ku = std::abs(u.dot(dv)) + turn(la, wa, wmax_a) + tb;
    const bool clear = clear_along_centres(p.a, qa, wa, p.b, p.sb.q, p.sb.w, c, dv, age, span,
                                           SpinBound{wmax_a}, SpinBound{wmax_b});
    EXPECT_EQ(clear, g0 - Ku * span > 1e-10 * (p.a.bounding_radius() + p.b.bounding_radius()));
    cleared += clear;
    for (int m = 0; m <= 20; ++m) {
      const double t = age + span * m / 20.0;
      const Vec3 ct = mb.position(t) - ma.position(t);
      const double gu = u.dot(ct) - p.a.support(ma.orientation(t).conjugate() * u) -
                        p.b.support(mb.orientation(t).conjugate() * Vec3(-u));
      worst = std::max(worst, (g0 - Ku * (t - age)) - gu);
      if (clear && (m % 5 == 0)) {
        EXPECT_GT(reference_distance_at(p, t), 0.0) << k << " " << t;
      }
    }
  }
  std::printf("  %d pairs%s: %d clear, max (line - g_u) %.2e\n", n, tops ? " (asymmetric tops)" : "",
              cleared, worst);
  EXPECT_LE(worst, 1e-12);
  EXPECT_GT(cleared, n / 10);
  EXPECT_LT(cleared, n);
}

TEST(AxisGap, ClearAlongCentresIsBelowTheGapAlongThem) { check_clear_along_centres(83, false); }
TEST(AxisGap, ClearAlongCentresIsBelowTheGapAlongThemForAsymmetricTops) {
  check_clear_along_centres(89, true);
}

// The second-order bound of clear_along_axis (second_order = true), against the gap along its
// axis itself. The test rebuilds the parabola Q from independent parts: the support functions'
// rates by central differences of h(R(t)^T u) (A at now, B at its own time, `age` before), and
// the curvature bound M = rho |m'|^2 + L |m''| of the header; Q(tau) must stay below g_u(now +
// tau) over the window (the Taylor bound and M hold), and wherever the test says clear, g_u
// and the distance stay positive. Axes: the line of centres, or one tilted from it by up to 0.3
// rad (as a remembered axis is); ellipsoids of aspect up to 5, spherical or asymmetric tops.
// The second order must clear every pair the first order clears, and more. The clear time of
// the same bound (axis_clear_time, by which the prediction loop orders its candidates) agrees
// with the test, and g_u and the distance stay positive before it.
void check_second_order_clear(std::uint64_t seed, bool tops) {
  Rng r(seed);
  const int n = scaled_count(2000, 0.1);
  int first = 0, second = 0, clear_times = 0, shortcut = 0;
  double worst = -kInf, frame_worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const ClearCase cc = clear_case(r, tops);
    const auto& [p, ma, mb, age, span, c, wa, qa] = cc;
    Vec3 u = c.normalized();
    if (k % 2) u = (Eigen::AngleAxisd(r.uni(0.0, 0.3), r.unit()) * u).normalized();
    auto spin = [tops](const Motion& m) {
      return tops ? SpinBound{m.max_angular_speed(), m.max_angular_acceleration()} : SpinBound{};
    };
    const Vec3 dv = p.sb.v - p.sa.v;
    auto clear = [&](bool second_order) {
      return clear_along_axis(p.a, qa, wa, p.b, p.sb.q, p.sb.w, c, u, dv, age, span, spin(ma),
                              spin(mb), second_order);
    };
    const bool lin = clear(false), quad = clear(true);
    if (lin) {
      EXPECT_TRUE(quad) << k;
    }
    first += lin, second += quad;
    // the support values along u (A's) and -u (B's) at time t
    auto ha = [&](double t) { return p.a.support(ma.orientation(t).conjugate() * u); };
    auto hb = [&](double t) { return p.b.support(mb.orientation(t).conjugate() * Vec3(-u)); };
    // the clear time itself (the prediction loop's order, span kInf: the whole bound): g_u and
    // the distance positive before it, sampled up to 1.5 spans beyond the window
    const double tc = axis_clear_time(p.a, qa, wa, p.b, p.sb.q, p.sb.w, c, u, dv, age, kInf,
                                      spin(ma), spin(mb), true);
    EXPECT_EQ(quad, tc > span) << k;
    clear_times += tc > 0.0;
    // With the window's span, a time just past it where Q covers the window (no root formed),
    // else the same time as the whole bound's (the root, or t1)
    const double ts = axis_clear_time(p.a, qa, wa, p.b, p.sb.q, p.sb.w, c, u, dv, age, span,
                                      spin(ma), spin(mb), true);
    if (ts > span && tc > span) {
      EXPECT_LE(ts, tc) << k;
      shortcut += ts == std::nextafter(span, kInf) && tc > ts;
    } else {
      EXPECT_EQ(ts, tc) << k;
    }
    // A's rotation as a matrix (RotationFrame: the prediction loop's form) gives the same time
    // to rounding
    const double tf = axis_clear_time(p.a, RotationFrame(qa), wa, p.b, p.sb.q, p.sb.w, c, u, dv,
                                      age, kInf, spin(ma), spin(mb), true);
    if (std::isinf(tc)) {
      EXPECT_EQ(tf, tc) << k;
    } else {
      EXPECT_NEAR(tf, tc, 1e-9 * (span + tc)) << k;
    }
    frame_worst = std::max(frame_worst, std::isinf(tc) ? 0.0 : std::abs(tf - tc) / (span + tc));
    for (int m = 0; m < 20 && tc > 0.0; ++m) {
      const double t = age + std::min(tc, 2.5 * span) * m / 20.0;
      const Vec3 ct = mb.position(t) - ma.position(t);
      EXPECT_GT(u.dot(ct) - ha(t) - hb(t), 0.0) << k << " " << t;
      if (m % 5 == 0) {
        EXPECT_GT(reference_distance_at(p, t), 0.0) << k << " " << t;
      }
    }
    // Q from central differences of the support functions and the header's M
    const double d = 1e-6;
    const double ra = (ha(age + d) - ha(age - d)) / (2 * d), rb = (hb(d) - hb(-d)) / (2 * d);
    auto M = [&](const Ellipsoid& e, const Vec3& w, const Motion& m) {
      const double sw = tops ? m.max_angular_speed() : w.cross(u).norm();
      const double mdd = tops ? sw * sw + m.max_angular_acceleration() : w.norm() * sw;
      return e.max_curvature_radius() * sw * sw + e.bounding_radius() * mdd;
    };
    const double Ma = M(p.a, wa, ma), Mb = M(p.b, p.sb.w, mb);
    for (int m = 0; m <= 40; ++m) {
      const double tau = span * m / 40.0, t = age + tau;
      const Vec3 ct = mb.position(t) - ma.position(t);
      const double gu = u.dot(ct) - ha(t) - hb(t);
      const double Q = u.dot(c) + u.dot(dv) * tau - (ha(age) + ra * tau + 0.5 * Ma * tau * tau) -
                       (hb(0.0) + rb * (age + tau) + 0.5 * Mb * (age + tau) * (age + tau));
      worst = std::max(worst, Q - gu);
      if (quad) {
        EXPECT_GT(gu, 0.0) << k << " " << t;
        if (m % 10 == 0) {
          EXPECT_GT(reference_distance_at(p, t), 0.0) << k << " " << t;
        }
      }
    }
  }
  std::printf("  %d pairs%s: %d clear to first order, %d with the second (%d without the root), "
              "%d with a clear time > 0, max (Q - g_u) %.2e, matrix vs quaternion %.1e\n", n,
              tops ? " (asymmetric tops)" : "", first, second, shortcut, clear_times, worst,
              frame_worst);
  EXPECT_GT(clear_times, second);
  EXPECT_GT(shortcut, 0);  // the window answered without the root is exercised
  EXPECT_LE(worst, 1e-8);  // central differences: rates to ~1e-10
  EXPECT_GT(second, first + n / 50);
  EXPECT_LT(second, n);
}

TEST(AxisGap, SecondOrderClearIsBelowTheGapAlongItsAxis) { check_second_order_clear(97, false); }
TEST(AxisGap, SecondOrderClearIsBelowTheGapAlongItsAxisForAsymmetricTops) {
  check_second_order_clear(101, true);
}

// next_up, the time just past a window that both the second order and the affine bound return,
// against its slow twin std::nextafter(x, +inf), bit for bit: zero, subnormals, the ends of the
// binades, ordinary spans, the largest finite double (-> inf).
TEST(AxisGap, NextUpIsNextafterTowardsInfinity) {
  const double big = std::numeric_limits<double>::max();
  std::vector<double> xs = {0.0, std::numeric_limits<double>::denorm_min(), 1e-310,
                            std::numeric_limits<double>::min(), 1e-300, 0.5, 1.0,
                            std::nextafter(1.0, 0.0), 2.0, 3.0, 1e300, big};
  for (int k = 1; k <= 1000; ++k) xs.push_back(std::ldexp(1.0 + k * 0.000999, k % 61 - 30));
  for (const double x : xs)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(next_up(x)),
              std::bit_cast<std::uint64_t>(std::nextafter(x, kInf)))
        << x;
  EXPECT_TRUE(std::isinf(next_up(big)));
}

// The affine clear time of flat-faced pairs (axis_clear_time with second_order = true where a
// radius of curvature is unbounded: superquadrics with an exponent > 2), against the gap along
// its axis. The test rebuilds the header's F from independent parts: the rates m' of the
// body-frame directions m_A(t) = R_A(t)^T u and m_B(t) = -R_B(t)^T u by central differences
// (A at now, B at its own time, `age` before), their second derivatives by second differences
// against the header's bound of |m''|, and F(tau) must stay below g_u(now + tau) over the
// window. The test's own F gives the same decisions and chord times as the header's (away from
// rounding). Wherever the test says clear, g_u and the distance stay positive over the window;
// below a clear time short of the window, g_u stays positive. Superquadrics with exponents
// (2, 2, p), (4, 4, 4), (8, 8, 8) and (2, 3, 6) on ellipsoids' semi-axes of aspect up to 5,
// spherical or asymmetric tops, axes on or up to 0.3 rad off the line of centres. The affine
// bound must clear every pair the first order clears, and more; A's rotation as a matrix gives
// the same time to rounding.
void check_affine_clear(std::uint64_t seed, bool tops) {
  Rng r(seed);
  // all 1000 pairs in the sanitizer build too (~0.5 s): the chord path is rare (about 1 %)
  const int n = 1000;
  int first = 0, affine = 0, partial = 0, judged = 0;
  double worst = -kInf, worst_mdd = 0.0, frame_worst = 0.0;
  for (int k = 0; k < n; ++k) {
    auto shape = [&r, k](const Ellipsoid& e) {
      static constexpr double kExp[4][3] = {{2, 2, 8}, {4, 4, 4}, {8, 8, 8}, {2, 3, 6}};
      const double* x = kExp[(k + r.g() % 4) % 4];
      return Superquadric(e.a, e.b, e.c, x[0], x[1], x[2]);
    };
    const Superquadric A = shape(r.ellipsoid(5.0)), B = shape(r.ellipsoid(5.0));
    const double L = std::max(A.bounding_radius(), B.bounding_radius());
    const Pose pa{r.ball(1.0), r.rotation()};
    const Pose pb = testing::place_at_distance(A, pa, B, r.rotation(), r.unit(), r.log_uni(1e-3, 2.0));
    BodyState sa{pa.r, Quat(pa.R), r.ball(1.0), r.ball(3.0 / L)};
    BodyState sb{pb.r, Quat(pb.R), r.ball(1.0), r.ball(3.0 / L)};
    if (tops) {
      sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
      sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
    }
    const Motion ma(sa), mb(sb);
    const double age = r.uni(0.0, 0.3), span = r.log_uni(1e-3, 0.5);
    Quat qa;
    Vec3 wa;
    ma.pose(age, qa, wa);
    const Vec3 c = mb.position(age) - ma.position(age), dv = sb.v - sa.v;
    Vec3 u = c.normalized();
    if (k % 2) u = (Eigen::AngleAxisd(r.uni(0.0, 0.3), r.unit()) * u).normalized();
    auto spin = [tops](const Motion& m) {
      return tops ? SpinBound{m.max_angular_speed(), m.max_angular_acceleration()} : SpinBound{};
    };
    auto clear_time = [&](bool second_order) {
      return axis_clear_time(A, qa, wa, B, sb.q, sb.w, c, u, dv, age, span, spin(ma), spin(mb),
                             second_order);
    };
    const double t_lin = clear_time(false), tc = clear_time(true);
    EXPECT_GE(tc, t_lin) << k;
    first += t_lin > span, affine += tc > span, partial += tc > t_lin && tc <= span;
    const double tf = axis_clear_time(A, RotationFrame(qa), wa, B, sb.q, sb.w, c, u, dv, age, span,
                                      spin(ma), spin(mb), true);
    EXPECT_NEAR(tf, tc, 1e-9 * (span + tc)) << k;
    frame_worst = std::max(frame_worst, std::abs(tf - tc) / (span + tc));
    // the body-frame directions and the gap along u at time t (both bodies' true orientations)
    auto m_a = [&](double t) { return Vec3(ma.orientation(t).conjugate() * u); };
    auto m_b = [&](double t) { return Vec3(mb.orientation(t).conjugate() * Vec3(-u)); };
    auto gap = [&](double t) {
      return u.dot(mb.position(t) - ma.position(t)) - A.support(m_a(t)) - B.support(m_b(t));
    };
    for (int m = 0; m < 20 && tc > 0.0; ++m) {
      const double t = age + std::min(tc, span) * m / 20.0;
      EXPECT_GT(gap(t), 0.0) << k << " " << t;
      if (tc > span && m % 5 == 0) {
        EXPECT_GT(reference_distance_at(A, ma, B, mb, t), 0.0) << k << " " << t;
      }
    }
    // F from central differences of m(t) and the header's bound of |m''|, checked here too
    const double d = 1e-5;
    const Vec3 da = (m_a(age + d) - m_a(age - d)) / (2 * d), db = (m_b(d) - m_b(-d)) / (2 * d);
    auto mdd = [&](const Motion& m, const Vec3& w) {
      const double sw = tops ? m.max_angular_speed() : w.cross(u).norm();
      return tops ? sw * sw + m.max_angular_acceleration() : w.norm() * sw;
    };
    const double mdd_a = mdd(ma, wa), mdd_b = mdd(mb, sb.w);
    for (double t : {0.0, age, age + 0.5 * span}) {
      const double h = 1e-4;
      const Vec3 fa = (m_a(t + h) - 2.0 * m_a(t) + m_a(t - h)) / (h * h);
      const Vec3 fb = (m_b(t + h) - 2.0 * m_b(t) + m_b(t - h)) / (h * h);
      worst_mdd = std::max({worst_mdd, fa.norm() / mdd_a, fb.norm() / mdd_b});
    }
    auto F = [&](double tau) {
      const double tb = age + tau;
      return u.dot(c) + u.dot(dv) * tau - A.support(m_a(age) + tau * da) -
             B.support(m_b(0.0) + tb * db) -
             0.5 * (A.bounding_radius() * mdd_a * tau * tau + B.bounding_radius() * mdd_b * tb * tb);
    };
    for (int m = 0; m <= 40; ++m) {
      const double tau = span * m / 40.0;
      worst = std::max(worst, F(tau) - gap(age + tau));
    }
    // the test's decision from its own F: ends above the margin (the start end from below, as
    // the header takes it), else the chord's zero; not judged within 1e-7 L of the margin
    const double margin = 1e-10 * (A.bounding_radius() + B.bounding_radius());
    const double f0 = u.dot(c) - A.support(m_a(age)) - B.support(m_b(0.0)) -
                      age * (B.bounding_radius() * db.norm() + 0.5 * B.bounding_radius() * mdd_b * age) -
                      margin;
    const double fs = F(span) - margin;
    if (std::min(std::abs(f0), std::abs(fs)) > 1e-7 * L && !(t_lin > span)) {
      ++judged;
      EXPECT_EQ(tc > span, f0 > 0.0 && fs > 0.0) << k;
      if (f0 > 0.0 && fs <= 0.0 && tc > t_lin) {
        EXPECT_NEAR(tc, span * f0 / (f0 - fs), 1e-6 * span) << k;
      }
    }
  }
  std::printf("  %d superquadric pairs%s: %d clear to first order, %d with the affine bound, %d "
              "with a longer clear time short of the window, %d decisions re-derived; max (F - g_u) "
              "%.2e, max |FD m''| / bound %.3f, matrix vs quaternion %.1e\n",
              n, tops ? " (asymmetric tops)" : "", first, affine, partial, judged, worst, worst_mdd,
              frame_worst);
  EXPECT_GT(judged, n / 2);
  EXPECT_LE(worst, 1e-7);                 // central differences: rates to ~1e-9
  EXPECT_LE(worst_mdd, 1.0 + 1e-3);       // second differences to ~1e-6 relative
  EXPECT_GT(affine, first + n / 50);
  EXPECT_GT(partial, 0);  // the chord path is exercised (measured: 9 and 14 of 1000)
  EXPECT_LT(affine, n);
}

TEST(AxisGap, AffineClearOfFlatFacesIsBelowTheGapAlongItsAxis) { check_affine_clear(127, false); }
TEST(AxisGap, AffineClearOfFlatFacesIsBelowTheGapAlongItsAxisForAsymmetricTops) {
  check_affine_clear(131, true);
}

// support_point_given (shapes/shape.hpp): the support point from the value at hand is the one
// support_point computes, bit for bit (ellipsoids form it from the value; superquadrics solve
// again); the second-order clear test uses it.
TEST(AxisGap, SupportPointGivenItsValueIsTheSupportPoint) {
  Rng r(113);
  const Superquadric sq(1.0, 0.7, 0.4, 2.0, 4.0, 8.0);
  for (int k = 0; k < 200; ++k) {
    const Ellipsoid e = r.ellipsoid(10.0);
    const Vec3 m = r.unit();
    EXPECT_EQ(support_point_given(e, m, e.support(m)), e.support_point(m)) << k;
    EXPECT_EQ(support_point_given(sq, m, sq.support(m)), sq.support_point(m)) << k;
  }
}

TEST(AxisGap, SeparatingAxisSearchApproachesTheDistance) {
  Rng r(47);
  const int n = scaled_count(1000, 0.1);
  std::vector<double> ratio3;
  double worst_excess = -kInf, worst_long = 0.0;
  for (int k = 0; k < n; ++k) {
    const Pair p = random_pair(r, r.log_uni(1e-3, 1.0));
    const double d = reference_distance_at(p, 0.0);
    double g3, g200;
    const Motion ma(p.sa), mb(p.sb);
    separating_axis(p.a, ma, p.b, mb, 0.0, 3, g3);
    separating_axis(p.a, ma, p.b, mb, 0.0, 400, g200);
    worst_excess = std::max({worst_excess, g3 - d, g200 - d});
    worst_long = std::max(worst_long, (d - g200) / d);
    ratio3.push_back(g3 / d);
  }
  std::sort(ratio3.begin(), ratio3.end());
  std::printf("  %d pairs: gap / distance after 3 evaluations: median %.3f, 10%% quantile %.3f; after "
              "400 evaluations max relative shortfall %.2e\n",
              n, ratio3[ratio3.size() / 2], ratio3[ratio3.size() / 10], worst_long);
  EXPECT_LE(worst_excess, 1e-12);   // a lower bound whatever the axis
  EXPECT_LE(worst_long, 1e-6);      // the ascent converges to the distance
}

// The search takes Newton steps on the sphere of directions (the support Hessians: the radii of
// curvature, which differ by (a/b)^2 between directions on an elongated body). Prolate, oblate
// and triaxial ellipsoids of aspect up to 10 at exact distances 1e-6 L .. L (place_at_distance):
// with the engine's budget of 12 gap evaluations the gap reaches the distance to 1e-9 relative
// in every pair, and never exceeds it; with the engine's stopping rule (within 30 % of
// the distance, or 1e-8 absolute) the stop is honest: the gap is then at least d / 1.3.
TEST(AxisGap, NewtonSearchReachesTheDistanceOfElongatedBodies) {
  Rng r(59);
  const int n = scaled_count(4000, 0.1);
  std::vector<double> short12, short6;
  double worst_excess = -kInf, worst_stop = kInf;
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(10.0), b = r.ellipsoid(10.0);
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    const Pose pa{r.ball(1.0), r.rotation()};
    const double d = r.log_uni(1e-6, 1.0) * L;
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), d);
    const Motion ma(BodyState{pa.r, Quat(pa.R), Vec3::Zero(), Vec3::Zero()});
    const Motion mb(BodyState{pb.r, Quat(pb.R), Vec3::Zero(), Vec3::Zero()});
    double g12, g6, gs;
    separating_axis(a, ma, b, mb, 0.0, 12, g12);
    separating_axis(a, ma, b, mb, 0.0, 6, g6);
    separating_axis(a, ma, b, mb, 0.0, 12, gs, kInf, 1.0, nullptr, 1e-8, 0.3);
    worst_excess = std::max({worst_excess, (g12 - d) / L, (g6 - d) / L, (gs - d) / L});
    short12.push_back((d - g12) / d);
    short6.push_back((d - g6) / d);
    worst_stop = std::min(worst_stop, gs / (d - 1e-8));
  }
  std::sort(short12.begin(), short12.end());
  std::sort(short6.begin(), short6.end());
  auto q = [](const std::vector<double>& v, double f) { return v[static_cast<size_t>(f * (v.size() - 1))]; };
  std::printf("  %d pairs: relative shortfall of the gap after 6 evaluations: median %.1e, 99%% %.1e, "
              "max %.1e; after 12: median %.1e, 99%% %.1e, max %.1e; stopping rule: min gap / d %.3f\n",
              n, q(short6, 0.5), q(short6, 0.99), short6.back(), q(short12, 0.5), q(short12, 0.99),
              short12.back(), worst_stop);
  EXPECT_LE(worst_excess, 1e-12);      // a lower bound whatever the axis
  EXPECT_LE(short12.back(), 1e-8);     // converged (measured: 7.9e-10 at most)
  EXPECT_GE(worst_stop, 1.0 / 1.3 - 1e-9);
}

TEST(AxisGap, SuperquadricsUseTheFirstOrderBound) {
  static_assert(AxisGap<Ellipsoid, Sphere>::kMayCurve);
  const Superquadric q{1.0, 0.5, 0.5, 8.0, 8.0, 8.0};
  EXPECT_FALSE((AxisGap<Superquadric, Superquadric>::curved(q, q)));  // flat faces
  EXPECT_FALSE((AxisGap<Superquadric, Superquadric>::curved(q, Superquadric{1, 1, 1, 2, 2, 3})));
  Rng r(53);
  const int n = scaled_count(500, 0.1);
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const BodyState a{Vec3::Zero(), r.quat(), r.ball(1.0), r.ball(3.0)};
    const BodyState b{Vec3(2.5, 0, 0) + r.ball(0.3), r.quat(), r.ball(1.0), r.ball(3.0)};
    const Motion ma(a), mb(b);
    const AxisGap<Superquadric, Superquadric> g(q, ma, q, mb, 0.0, r.unit());
    EXPECT_FALSE(g.is_curved());
    const double t = r.uni(-0.2, 0.2), h = 1e-6;
    worst = std::max(worst, std::abs(g.value(t + h) - g.value(t - h)) / (2 * h) / g.Kn);
  }
  std::printf("  %d superquadric axes: max |FD g'| / Kn %.3f\n", n, worst);
  EXPECT_LE(worst, 1.0 + 1e-6);
}

// The gap at the search's own time from the support points the search found (AxisSupport, the
// first value of the contact-time solver's axis leaps) against the gap evaluated from scratch
// (value(t): rotations and support points again): the same gap and rate on random pairs,
// spherical and asymmetric tops, rigid and growing, ellipsoids (second order) and
// superquadrics with exponent 4 (first order).
TEST(AxisGap, SearchSupportPointsGiveTheSameGapAsAFreshEvaluation) {
  Rng r(73);
  const int n = scaled_count(1000, 0.1);
  double worst_gap = 0.0, worst_rate = 0.0, worst_sq = 0.0;
  for (int k = 0; k < n; ++k) {
    const bool tops = k % 2 == 1, growing = k % 3 == 2;
    const Pair p = random_pair(r, r.log_uni(1e-4, 2.0), tops);
    const double s0 = growing ? r.uni(0.8, 1.2) : 1.0, sdot = growing ? r.uni(-0.1, 0.3) : 0.0;
    const double tau = k % 4 == 0 ? 0.0 : r.uni(0.0, 0.3);
    const Motion ma(p.sa), mb(p.sb);
    double gap;
    AxisSupport at;
    const Vec3 axis = separating_axis(p.a, ma, p.b, mb, tau, 12, gap, kInf, s0 + sdot * tau,
                                      nullptr, 0.0, 0.3, &at);
    ASSERT_GT(axis.squaredNorm(), 0.0);
    const AxisGap<Ellipsoid, Ellipsoid> g(p.a, ma, p.b, mb, 0.0, axis, s0, sdot);
    double slope, slope_at;
    Vec3 va, vb;
    const double g_fresh = g.value(tau, slope, va, vb);
    const double g_at = g.value(tau, at.ma, at.mb, at.pa, at.pb, slope_at);
    const double L = std::max(p.a.bounding_radius(), p.b.bounding_radius());
    worst_gap = std::max({worst_gap, std::abs(g_at - g_fresh) / L, std::abs(g_at - gap) / L});
    worst_rate = std::max(worst_rate, std::abs(slope_at - slope) / g.Kn);
    // flat faces (first order: the rate is -Kn either way)
    const Superquadric qa{p.a.a, p.a.b, p.a.c, 4, 4, 4}, qb{p.b.a, p.b.b, p.b.c, 4, 4, 4};
    double gq;
    AxisSupport aq;
    const Vec3 nq = separating_axis(qa, ma, qb, mb, tau, 12, gq, kInf, 1.0, nullptr, 0.0, 0.3, &aq);
    const AxisGap<Superquadric, Superquadric> G(qa, ma, qb, mb, 0.0, nq);
    double sq_fresh, sq_at;
    const double q_fresh = G.value(tau, sq_fresh, va, vb);
    const double q_at = G.value(tau, aq.ma, aq.mb, aq.pa, aq.pb, sq_at);
    worst_sq = std::max({worst_sq, std::abs(q_at - q_fresh) / L, std::abs(q_at - gq) / L});
    EXPECT_EQ(sq_at, sq_fresh);
  }
  std::printf("  %d pairs: max |g_at - g| / L %.2e, max |g'_at - g'| / Kn %.2e, superquadrics "
              "max |g_at - g| / L %.2e\n", n, worst_gap, worst_rate, worst_sq);
  EXPECT_LE(worst_gap, 1e-13);
  EXPECT_LE(worst_rate, 1e-12);
  EXPECT_LE(worst_sq, 1e-13);
}

// The affine bound B(s) of flat-faced pairs (AxisGap::affine_bound): on random pairs and axes
// (superquadrics with exponents 8, 4 and (2, 2, 8), ellipsoids, spherical and asymmetric tops,
// spins up to 6 v / L, steps up to 2 time units: many turns) B(0) is the gap, the exact rate of
// value_and_rate matches central differences, B never exceeds the gap g(t + s) on a grid of s
// (the lower-bound property the steps rely on), and B is concave on that grid (its second
// differences are <= 0 up to rounding: the chord rule of affine_step). Without the remainder
// term Q s^2 / 2 the bound is violated on these pairs (checked: the test can fail).
template <SupportShape S>
void check_affine_bound(const S& qa, const S& qb, const BodyState& sa, const BodyState& sb,
                        Rng& r, double& worst_excess, double& worst_excess_noq,
                        double& worst_concavity, double& worst_start, double& worst_rate) {
  const Motion ma(sa), mb(sb);
  const AxisGap<S, S> g(qa, ma, qb, mb, 0.0, r.unit());
  EXPECT_TRUE(g.has_affine_bound());
  const double L = std::max(qa.bounding_radius(), qb.bounding_radius());
  // (h: the support map of a flat face varies fast near its centre, so the central
  // difference's h^2 g''' error needs a short step)
  const double t = r.uni(0.0, 0.3), h = 1e-7;
  double slope;
  Vec3 va, vb, Wa, Wb;
  const double g0 = g.value_and_rate(t, slope, va, vb, Wa, Wb);
  worst_start = std::max(worst_start, std::abs(g.affine_bound(t, 0.0, va, vb, Wa, Wb) - g0) / L);
  worst_rate = std::max(worst_rate, std::abs((g.value(t + h) - g.value(t - h)) / (2 * h) - slope) / g.Kn);
  const double S_max = r.log_uni(1e-3, 2.0);
  const int m = 64;
  double prev2 = 0.0, prev1 = 0.0;
  for (int k = 0; k <= m; ++k) {
    const double s = S_max * k / m;
    const double b = g.affine_bound(t, s, va, vb, Wa, Wb);
    const double gt = g.value(t + s);
    worst_excess = std::max(worst_excess, (b - gt) / L);
    // the same bound without its remainder term
    worst_excess_noq = std::max(worst_excess_noq, (b + 0.5 * g.affine_remainder() * s * s - gt) / L);
    if (k >= 2) worst_concavity = std::max(worst_concavity, (b - 2.0 * prev1 + prev2) / L);
    prev2 = prev1, prev1 = b;
  }
}

TEST(AxisGap, AffineBoundIsConcaveAndBelowTheGap) {
  Rng r(79);
  const int n = scaled_count(1500, 0.1);
  double excess = -kInf, excess_noq = -kInf, concavity = -kInf, start = 0.0, rate = 0.0;
  for (int k = 0; k < n; ++k) {
    const bool tops = k % 2 == 1;
    Pair p = random_pair(r, r.log_uni(1e-4, 1.0), tops);
    p.sa.w *= 2.0, p.sb.w *= 2.0;  // up to 6 / L
    switch (k % 4) {
      case 0:
        check_affine_bound(p.a, p.b, p.sa, p.sb, r, excess, excess_noq, concavity, start, rate);
        break;
      default: {
        const double e[3][3] = {{8, 8, 8}, {4, 4, 4}, {2, 2, 8}};
        const double* x = e[k % 4 - 1];
        const Superquadric qa{p.a.a, p.a.b, p.a.c, x[0], x[1], x[2]};
        const Superquadric qb{p.b.a, p.b.b, p.b.c, x[2], x[1], x[0]};
        check_affine_bound(qa, qb, p.sa, p.sb, r, excess, excess_noq, concavity, start, rate);
      }
    }
  }
  std::printf("  %d pairs: max (B - g) / L %.2e (without the remainder term %.2e), max second "
              "difference of B / L %.2e, |B(0) - g| / L %.2e, |g' - FD| / Kn %.2e\n",
              n, excess, excess_noq, concavity, start, rate);
  EXPECT_LE(excess, 1e-12);        // a lower bound of the gap
  EXPECT_GT(excess_noq, 1e-6);     // and the remainder term is needed for that
  EXPECT_LE(concavity, 1e-12);     // concave
  EXPECT_LE(start, 1e-14);
  EXPECT_LE(rate, 1e-6);
}

// A superquadric with all exponents 2 is an ellipsoid: finite curvature radius, second-order
// steps; its gap, rate and curvature bound equal the ellipsoid's on random axes.
TEST(AxisGap, SuperquadricWithExponentsTwoIsCurvedLikeTheEllipsoid) {
  Rng r(61);
  const int n = scaled_count(1000, 0.1);
  double worst_gap = 0.0, worst_rate = 0.0, worst_curv = 0.0;
  for (int k = 0; k < n; ++k) {
    const Pair p = random_pair(r, r.log_uni(1e-3, 2.0));
    const Superquadric qa{p.a.a, p.a.b, p.a.c, 2, 2, 2}, qb{p.b.a, p.b.b, p.b.c, 2, 2, 2};
    ASSERT_NEAR(qa.max_curvature_radius(), p.a.max_curvature_radius(), 1e-15);
    const Vec3 axis = r.unit();
    const Motion ma0(p.sa), mb0(p.sb);
    const AxisGap<Superquadric, Superquadric> g(qa, ma0, qb, mb0, 0.0, axis);
    const AxisGap<Ellipsoid, Ellipsoid> ge(p.a, ma0, p.b, mb0, 0.0, axis);
    ASSERT_TRUE(g.is_curved());
    const double t = r.uni(-0.9, 0.9), h = 1e-5;
    double slope, slope_e;
    Vec3 ma, mb;
    const double g0 = g.value(t, slope, ma, mb), ge0 = ge.value(t, slope_e, ma, mb);
    const double L = std::max(p.a.bounding_radius(), p.b.bounding_radius());
    worst_gap = std::max(worst_gap, std::abs(g0 - ge0) / L);
    worst_rate = std::max(worst_rate, std::abs(slope - slope_e) / g.Kn);
    const double gp = g.value(t + h), gm = g.value(t - h);
    worst_curv = std::max(worst_curv, std::abs((gp - 2 * g0 + gm) / (h * h)) / g.M);
    EXPECT_NEAR(g.M, ge.M, 1e-12 * ge.M);
  }
  std::printf("  %d axes: max |g_sq - g_ell| / L %.2e, max |g'_sq - g'_ell| / Kn %.2e, "
              "max |FD g''| / M %.3f\n", n, worst_gap, worst_rate, worst_curv);
  EXPECT_LE(worst_gap, 1e-13);
  EXPECT_LE(worst_rate, 1e-12);
  EXPECT_LE(worst_curv, 1.0 + 1e-3);
}


// Bodies of revolution (shapes/shape.hpp revolution_axis): spheroids turning only, as spherical
// tops and as symmetric tops about their own axis, at random separations: the gap's rate
// against central differences never exceeds K_n with the spin across the axis in place of |w|
// (Motion::spin_across), that K_n is at most its twin's (revolution = false: |w x n|, max |w|),
// and the bound is not loose (the largest |g'| / K_n comes near 1).
TEST(AxisGap, BodiesOfRevolutionRateBoundHolds) {
  Rng r(131);
  double worst = 0.0, worst_twin = 0.0;
  int tighter = 0;
  const int n = scaled_count(3000, 0.1);
  for (int k = 0; k < n; ++k) {
    const double big = r.uni(0.5, 2.0), small = big / r.log_uni(1.5, 10.0);
    const int axis = k % 3;
    Vec3 ax = Vec3::Constant(k % 2 ? big : small);
    ax[axis] = k % 2 ? small : big;  // prolate (even k) or oblate about `axis`
    const Ellipsoid e{ax[0], ax[1], ax[2]};
    ASSERT_EQ(revolution_axis(e), axis);
    const Pose pa{Vec3::Zero(), r.rotation()};
    const Pose pb = testing::place_at_distance(e, pa, e, r.rotation(), r.unit(), r.log_uni(1e-3, 1.0));
    BodyState sa{pa.r, Quat(pa.R), Vec3::Zero(), r.ball(5.0)};
    BodyState sb{pb.r, Quat(pb.R), Vec3::Zero(), r.ball(5.0)};
    if (k % 4 >= 2) {  // symmetric tops about the shape's axis
      Vec3 top = Vec3::Constant(0.3);
      top[axis] = r.uni(0.05, 0.6);
      sa.top = sb.top = top;
    }
    const Motion ma(sa), mb(sb);
    const Vec3 dir = r.unit();
    const AxisGap<Ellipsoid, Ellipsoid> g(e, ma, e, mb, 0.0, dir);
    const AxisGap<Ellipsoid, Ellipsoid> twin(e, ma, e, mb, 0.0, dir, 1.0, 0.0, false);
    ASSERT_LE(g.Kn, twin.Kn);
    tighter += g.Kn < 0.9 * twin.Kn;
    const double h = 1e-5;
    for (const double t : {0.0, r.uni(-1.0, 1.0)}) {
      const double fd = std::abs((g.value(t + h) - g.value(t - h)) / (2 * h));
      ASSERT_LE(fd, g.Kn * (1 + 1e-6) + 1e-9) << "case " << k << " t " << t;
      worst = std::max(worst, fd / g.Kn);
      worst_twin = std::max(worst_twin, fd / twin.Kn);
    }
  }
  std::printf("  %d spheroid pairs, turning only: max |g'| / K_n %.4f (with |w|: %.4f), K_n below "
              "0.9 of |w|'s in %d\n", n, worst, worst_twin, tighter);
  EXPECT_GT(worst, 0.9);
  EXPECT_GT(tighter, n / 10);
}

// The pre-filter's clear time with the spin across the axes of bodies of revolution
// (SpinBound::across, spin_across_of: the first-order turn rate l min(|m'|, |w x e|)) against
// the gap along its axis: spheroids (two in three pairs of random ellipsoids) as spherical tops
// and as symmetric tops about their own axis, B's orientation `age` old, axes along the line of
// centres or tilted from it. g_u and the distance stay positive before the clear time, first
// and second order; the clear time is never shorter than without `across`, and longer for many.
TEST(AxisGap, ClearTimeOfBodiesOfRevolutionIsBelowTheGap) {
  Rng r(137);
  const int n = scaled_count(2000, 0.1);
  int longer = 0, revolution = 0;
  for (int k = 0; k < n; ++k) {
    Pair p = random_pair(r, r.log_uni(1e-3, 2.0));
    if (k % 2) {  // symmetric tops about the shapes' axes (triaxial shapes: asymmetric tops)
      for (auto [e, st] : {std::pair{&p.a, &p.sa}, std::pair{&p.b, &p.sb}}) {
        Vec3 top(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
        if (const int ax = revolution_axis(*e); ax >= 0) top[(ax + 1) % 3] = top[(ax + 2) % 3];
        st->top = top;
      }
    }
    revolution += revolution_axis(p.a) >= 0 || revolution_axis(p.b) >= 0;
    const Motion ma(p.sa), mb(p.sb);
    const double age = r.uni(0.0, 0.3), span = r.log_uni(1e-3, 0.5);
    Quat qa;
    Vec3 wa;
    ma.pose(age, qa, wa);
    const Vec3 c = mb.position(age) - ma.position(age), dv = p.sb.v - p.sa.v;
    Vec3 u = c.normalized();
    if (k % 3) u = (Eigen::AngleAxisd(r.uni(0.0, 0.3), r.unit()) * u).normalized();
    auto spin = [](const Motion& m) {
      return m.spherical() ? SpinBound{} : SpinBound{m.max_angular_speed(), m.max_angular_acceleration()};
    };
    SpinBound sa = spin(ma), sb = spin(mb);
    const SpinBound plain_a = sa, plain_b = sb;
    sa.across = spin_across_of(p.a, qa, wa, p.sa.top, ma.max_angular_speed());
    sb.across = spin_across_of(p.b, p.sb.q, p.sb.w, p.sb.top, mb.max_angular_speed());
    for (const bool second : {false, true}) {
      const double tc = axis_clear_time(p.a, qa, wa, p.b, p.sb.q, p.sb.w, c, u, dv, age, kInf,
                                        sa, sb, second);
      const double t0 = axis_clear_time(p.a, qa, wa, p.b, p.sb.q, p.sb.w, c, u, dv, age, kInf,
                                        plain_a, plain_b, second);
      EXPECT_GE(tc, t0) << k;
      longer += tc > 1.01 * t0;
      for (int m = 0; m < 20 && tc > 0.0; ++m) {
        const double t = age + std::min(tc, 2.5 * span) * m / 20.0;
        const double gu = u.dot(mb.position(t) - ma.position(t)) -
                          p.a.support(ma.orientation(t).conjugate() * u) -
                          p.b.support(mb.orientation(t).conjugate() * Vec3(-u));
        ASSERT_GT(gu, 0.0) << k << " " << t << (second ? " second order" : " first order");
        if (m % 5 == 0) {
          EXPECT_GT(reference_distance_at(p, t), 0.0) << k << " " << t;
        }
      }
    }
  }
  std::printf("  %d pairs (%d with a body of revolution): %d clear times longer by > 1 %% with "
              "the spin across the axes\n", n, revolution, longer);
  EXPECT_GT(longer, n / 10);
}

}  // namespace
}  // namespace hb
