// Contact time of growing bodies (Lubachevsky–Stillinger, ContactInput::growth): the growing
// contact-system Jacobian vs finite differences, the growing bounding-sphere window, spheres
// vs the closed form, and random ellipsoid pairs vs an independent conservative-advancement
// reference with growing shapes (never later, equal within 1e-9 where they hit).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "contact/contact_time.hpp"
#include "geometry/random_pairs.hpp"
#include "geometry/reference_distance.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

// ---------------------------------------------------------------------------------------------
// Reference: conservative advancement with growing shapes (support-function distance, not the
// solver under test).  From t with distance d no contact is possible before t + d / K, with
// K(t0, t1) = |v_B - v_A| + (|w_A| L_A + |w_B| L_B) s(t1) + s' (L_A + L_B) (s' >= 0).  Below
// d_fine: fixed sub-steps, golden-section search where d' changes sign from - to +, bisection
// of the first sign change (as tests/contact/reference_contact_time.hpp, with growth).
struct GrowRef {
  bool hit = false;
  double time = kInf;
  double min_distance = kInf;
  long evals = 0;
};

struct GrowPair {
  Ellipsoid a, b;  // at scale 1
  BodyState sa, sb;  // at time 0
  ScaleLaw law;      // s(t) = law.s + law.rate t
  Vec3 hint = Vec3::Zero();
  long evals = 0;

  double s(double t) const { return law.s + law.rate * t; }
  std::pair<double, double> at(double t) {
    const double sc = s(t);
    const Ellipsoid ea = scaled_shape(a, sc), eb = scaled_shape(b, sc);
    const Pose pa{sa.r + sa.v * t, rotation_at(sa, t)};
    const Pose pb{sb.r + sb.v * t, rotation_at(sb, t)};
    const bool h = hint.squaredNorm() > 0;
    const ref::RefDistance r = ref::reference_distance(ea, pa, eb, pb, h ? &hint : nullptr, h ? 8 : 48);
    ++evals;
    hint = r.n;
    const double g = law.rate / sc;
    const Vec3 ua = sa.v + sa.w.cross(r.point_a - pa.r) + g * (r.point_a - pa.r);
    const Vec3 ub = sb.v + sb.w.cross(r.point_b - pb.r) + g * (r.point_b - pb.r);
    return {r.distance, r.n.dot(ub - ua)};
  }
};

GrowRef reference_growing_contact(GrowPair P, double t_max, double d_fine) {
  const double La = P.a.bounding_radius(), Lb = P.b.bounding_radius();
  auto K = [&](double t1) {
    return (P.sb.v - P.sa.v).norm() + (P.sa.w.norm() * La + P.sb.w.norm() * Lb) * P.s(t1) +
           P.law.rate * (La + Lb);
  };
  GrowRef out;
  auto finish_root = [&](double lo, double hi) {  // d(lo) > 0 >= d(hi)
    while (hi - lo > 1e-14 * std::max(1.0, hi)) {
      const double m = 0.5 * (lo + hi);
      const double d = P.at(m).first;
      out.min_distance = std::min(out.min_distance, d);
      (d > 0 ? lo : hi) = m;
    }
    out.hit = true;
    out.time = lo;
  };
  double t = 0.0;
  auto [d, dd] = P.at(t);
  out.min_distance = d;
  if (d <= 0.0 && dd < 0.0) {
    out.hit = true;
    out.time = 0.0;
    out.evals = P.evals;
    return out;
  }
  while (t < t_max) {
    const double step0 = std::max(d, d_fine) / K(t);
    const double t1 = std::min(t_max, t + std::max(d, d_fine) / K(t + step0));
    auto [d1, dd1] = P.at(t1);
    out.min_distance = std::min(out.min_distance, d1);
    if (d1 <= 0.0 && d > 0.0) {
      finish_root(t, t1);
      break;
    }
    if (d > 0.0 && d1 > 0.0 && d + d1 <= K(t1) * (t1 - t) && dd < 0.0 && dd1 > 0.0) {
      const double gr = 0.5 * (std::sqrt(5.0) - 1.0);
      double lo = t, hi = t1;
      double x1 = hi - gr * (hi - lo), x2 = lo + gr * (hi - lo);
      double f1 = P.at(x1).first, f2 = P.at(x2).first;
      double neg_t = -1;
      for (int it = 0; it < 100 && hi - lo > 1e-12 * (t1 - t); ++it) {
        if (f1 <= 0) { neg_t = x1; break; }
        if (f2 <= 0) { neg_t = x2; break; }
        if (f1 < f2) {
          hi = x2; x2 = x1; f2 = f1; x1 = hi - gr * (hi - lo); f1 = P.at(x1).first;
        } else {
          lo = x1; x1 = x2; f1 = f2; x2 = lo + gr * (hi - lo); f2 = P.at(x2).first;
        }
      }
      out.min_distance = std::min({out.min_distance, f1, f2});
      if (neg_t >= 0) {
        finish_root(t, neg_t);
        break;
      }
    }
    t = t1;
    d = d1;
    dd = dd1;
  }
  out.evals = P.evals;
  return out;
}

// ---------------------------------------------------------------------------------------------

TEST(GrowthContact, ScaledShapeModelsTheScaledFunction) {
  Rng r(61);
  for (int k = 0; k < 200; ++k) {
    const Ellipsoid e = r.ellipsoid(6.0);
    const double s = r.uni(0.3, 2.0);
    const Ellipsoid es = scaled_shape(e, s);
    const Scaled<Ellipsoid> w{e, s};
    const Vec3 y = r.ball(3.0);
    EXPECT_NEAR(w.f(y), es.f(y), 1e-12 * std::max(1.0, std::abs(es.f(y))));
    EXPECT_LE((w.grad(y) - es.grad(y)).norm(), 1e-12 * es.grad(y).norm() + 1e-15);
    EXPECT_LE((w.hessian(y) - es.hessian(y)).norm(), 1e-12 * es.hessian(y).norm());
    EXPECT_NEAR(w.bounding_radius(), es.bounding_radius(), 1e-14);
    EXPECT_NEAR(w.volume(), es.volume(), 1e-12 * es.volume());
    const Vec3 u = r.unit();
    EXPECT_LE((w.ray_surface(u) - es.ray_surface(u)).norm(), 1e-12 * s);
  }
}

// Finite differences of the growing contact system in x, alpha and t.
double growing_jacobian_error(const Ellipsoid& a, const Ellipsoid& b, Rng& r) {
  const double L = std::max(a.bounding_radius(), b.bounding_radius());
  BodyState sa{r.ball(1.0), r.quat(), r.ball(1.0), r.ball(2.0 / L)};
  BodyState sb{r.ball(3.0 * L), r.quat(), r.ball(1.0), r.ball(2.0 / L)};
  const double s0 = r.uni(0.4, 1.2), sdot = r.uni(0.0, 0.5);
  const MovingBody<Ellipsoid> A{&a, sa, 0.3, sa.r, s0, sdot};
  const MovingBody<Ellipsoid> B{&b, sb, 0.3, sa.r, s0, sdot};
  Vec5c y;
  y << r.ball(2.0 * L), r.uni(0.3, 2.0), r.uni(-0.5, 1.0);
  Vec5c F;
  Mat5c J;
  contact_system(A, B, y, F, &J);
  const double h[5] = {1e-6 * L, 1e-6 * L, 1e-6 * L, 1e-6, 1e-6};
  double worst = 0;
  for (int j = 0; j < 5; ++j) {
    Vec5c yp = y, ym = y, Fp, Fm;
    yp[j] += h[j];
    ym[j] -= h[j];
    contact_system(A, B, yp, Fp, nullptr);
    contact_system(A, B, ym, Fm, nullptr);
    const Vec5c col = (Fp - Fm) / (2 * h[j]);
    worst = std::max(worst, (col - J.col(j)).norm() / J.col(j).norm());
  }
  return worst;
}

TEST(GrowthContact, JacobianMatchesFiniteDifferences) {
  Rng r(62);
  double worst = 0;
  for (int k = 0; k < 300; ++k)
    worst = std::max(worst, growing_jacobian_error(r.ellipsoid(6.0), r.ellipsoid(6.0), r));
  std::printf("  growing contact Jacobian max relative column error %.2e\n", worst);
  EXPECT_LT(worst, 1e-6);
}

// The rate of the growing distance from finite differences of the distance.
TEST(GrowthContact, DistanceRateIncludesGrowth) {
  Rng r(63);
  for (int k = 0; k < 100; ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const ScaleLaw law{r.uni(0.5, 1.0), r.uni(0.05, 0.5)};
    BodyState sa{r.ball(1.0), r.quat(), r.ball(1.0), r.ball(1.0)};
    BodyState sb{sa.r + 5.0 * r.unit(), r.quat(), r.ball(1.0), r.ball(1.0)};
    const MovingBody<Ellipsoid> A{&a, sa, 0.0, Vec3::Zero(), law.s, law.rate};
    const MovingBody<Ellipsoid> B{&b, sb, 0.0, Vec3::Zero(), law.s, law.rate};
    auto dist = [&](double t) {
      return distance(scaled_shape(a, A.scale_at(t)), A.pose_at(t), scaled_shape(b, B.scale_at(t)),
                      B.pose_at(t));
    };
    const double t = 0.2, h = 1e-6;
    const DistanceResult d = dist(t);
    const double fd = (dist(t + h).distance - dist(t - h).distance) / (2 * h);
    const double rate = d.normal.dot(B.point_velocity(d.point_b, B.pose_at(t), t) -
                                     A.point_velocity(d.point_a, A.pose_at(t), t));
    EXPECT_NEAR(rate, fd, 1e-6 * std::max(1.0, std::abs(fd))) << k;
  }
}

TEST(GrowthContact, GrowingBoundingSphereWindow) {
  BodyState a, b;
  b.r = Vec3(10, 0, 0);
  double lo = -100, hi = 100;
  // at rest, radius 2 + tau: touching from tau = 8 on
  ASSERT_TRUE(bounding_sphere_window(a, b, 0.0, 2.0, 1.0, lo, hi));
  EXPECT_NEAR(lo, 8.0, 1e-10);
  EXPECT_EQ(hi, 100.0);
  // approaching at 1: |10 - tau| <= 2 + tau from tau = 4 on, forever
  b.v = Vec3(-1, 0, 0);
  lo = -100, hi = 100;
  ASSERT_TRUE(bounding_sphere_window(a, b, 1.0, 2.0, 1.0, lo, hi));
  EXPECT_NEAR(lo, 5.0, 1e-10);
  EXPECT_EQ(hi, 100.0);
  // receding at 3 > growth 1: never (the mirror branch tau <= -4 has a negative radius)
  b.v = Vec3(3, 0, 0);
  lo = -100, hi = 100;
  EXPECT_FALSE(bounding_sphere_window(a, b, 0.0, 2.0, 1.0, lo, hi));
  // receding at 0.5 < growth 1: |10 + 0.5 tau| <= 2 + tau from tau = 16 on
  b.v = Vec3(0.5, 0, 0);
  lo = -100, hi = 100;
  ASSERT_TRUE(bounding_sphere_window(a, b, 0.0, 2.0, 1.0, lo, hi));
  EXPECT_NEAR(lo, 16.0, 1e-10);
  // passing by at speed 2 > growth 1 with impact parameter 3: a finite window
  b.r = Vec3(-10, 3, 0);
  b.v = Vec3(2, 0, 0);
  lo = -100, hi = 100;
  ASSERT_TRUE(bounding_sphere_window(a, b, 0.0, 2.0, 1.0, lo, hi));
  for (double t = -5; t < 40; t += 0.01) {
    const bool inside = (b.r + b.v * t).norm() <= 2.0 + t && 2.0 + t >= 0;
    if (inside) EXPECT_TRUE(t >= lo && t <= hi) << t;
    else EXPECT_FALSE(t > lo + 1e-9 && t < hi - 1e-9) << t;
  }
  // rate 0 is the rigid window, widened by the relative rounding guard (1e-12)
  double lo2 = -100, hi2 = 100;
  lo = -100, hi = 100;
  ASSERT_TRUE(bounding_sphere_window(a, b, 0.0, 4.0, 0.0, lo, hi));
  ASSERT_TRUE(bounding_sphere_window(a, b, 0.0, 4.0, lo2, hi2));
  EXPECT_LE(lo, lo2);
  EXPECT_GE(hi, hi2);
  EXPECT_NEAR(lo, lo2, 1e-10);
  EXPECT_NEAR(hi, hi2, 1e-10);
}

// Growing spheres: |dr + dv tau| = (r_a + r_b)(s + s' tau), solved in closed form.
TEST(GrowthContact, SpheresMatchClosedForm) {
  Rng r(64);
  int hits = 0;
  for (int k = 0; k < scaled_count(2000, 0.05); ++k) {
    const Sphere a{r.uni(0.3, 1.5)}, b{r.uni(0.3, 1.5)};
    const ScaleLaw law{r.uni(0.3, 1.0), r.uni(0.0, 0.5)};
    const double R = (a.radius + b.radius) * law.s, Rr = (a.radius + b.radius) * law.rate;
    BodyState sa{r.ball(2.0), r.quat(), r.ball(1.0), r.ball(1.0)};
    BodyState sb{sa.r + (R + r.log_uni(1e-3, 3.0)) * r.unit(), r.quat(), r.ball(1.0), r.ball(1.0)};
    if (k % 3 == 0) sb.v = sa.v + 0.1 * r.ball(1.0);  // growth dominates
    ContactInput<Sphere, Sphere> in{a, b, sa, sb, 0.0, 0.0, 10.0, 1e-6};
    in.growth = law;
    const ContactResult c = contact_time(in);
    const Vec3 dr = sb.r - sa.r, dv = sb.v - sa.v;
    const double A = dv.squaredNorm() - Rr * Rr, B = dr.dot(dv) - R * Rr, C = dr.squaredNorm() - R * R;
    // first root tau >= 0 of A tau^2 + 2 B tau + C = 0 (C > 0: apart at 0)
    double t = kInf;
    if (A == 0.0) {
      if (B < 0) t = -C / (2 * B);
    } else {
      const double disc = B * B - A * C;
      if (disc >= 0) {
        const double sq = std::sqrt(disc);
        const double q = -(B + std::copysign(sq, B));
        double t1 = q / A, t2 = C / q;
        if (t1 > t2) std::swap(t1, t2);
        if (t1 >= 0) t = t1;
        else if (t2 >= 0) t = t2;
      }
    }
    if (t > 10.0) t = kInf;
    ASSERT_NE(c.status, ContactStatus::failed) << k;
    if (t == kInf) {
      EXPECT_EQ(c.status, ContactStatus::none) << k;
      continue;
    }
    ++hits;
    ASSERT_EQ(c.status, ContactStatus::hit) << k;
    EXPECT_NEAR(c.time, t, 1e-10 * std::max(1.0, t)) << k;
    EXPECT_LE(c.time, t + 1e-12) << k;
    const Vec3 ra = sa.r + sa.v * c.time;
    EXPECT_NEAR((c.point - ra).norm(), a.radius * (law.s + law.rate * c.time), 1e-8);
  }
  EXPECT_GT(hits, 0);
}

// A constant scale s (rate 0) is the same as the ellipsoids with scaled semi-axes.
TEST(GrowthContact, ConstantScaleEqualsScaledShapes) {
  Rng r(65);
  for (int k = 0; k < scaled_count(300, 0.1); ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const double s = r.uni(0.4, 1.5);
    const double L = std::max(a.bounding_radius(), b.bounding_radius()) * s;
    BodyState sa{r.ball(1.0), r.quat(), r.ball(0.5), r.ball(1.0 / L)};
    BodyState sb{sa.r + r.uni(2.2, 4.0) * L * r.unit(), r.quat(), Vec3::Zero(), r.ball(1.0 / L)};
    sb.v = sa.v - r.uni(0.5, 2.0) * (sb.r - sa.r).normalized() + 0.3 * r.ball(1.0);
    ContactInput<Ellipsoid, Ellipsoid> g{a, b, sa, sb, 0.0, 0.0, 20.0, 1e-6};
    g.growth = ScaleLaw{s, 0.0};
    const Ellipsoid as = scaled_shape(a, s), bs = scaled_shape(b, s);
    const ContactResult cg = contact_time(g);
    const ContactResult cs =
        contact_time(ContactInput<Ellipsoid, Ellipsoid>{as, bs, sa, sb, 0.0, 0.0, 20.0, 1e-6});
    ASSERT_EQ(cg.status, cs.status) << k;
    if (cg.status == ContactStatus::hit) {
      EXPECT_NEAR(cg.time, cs.time, 1e-10 * std::max(1.0, cs.time)) << k;
    }
  }
}

// Random growing pairs. kind 0: approaching; 1: fast spinners; 2: translation slower than the
// growth (the growth closes the gap); 3: just touching at t = 1 (overlap 1e-8..1e-4 with
// d'(1) = 0, so the contact window is short), rotating or not.
struct GScenario {
  GrowPair p;
  double t_max;
};

GScenario make_growing(Rng& r, int kind) {
  for (;;) {
    GScenario g;
    GrowPair& p = g.p;
    p.a = r.ellipsoid(8.0);
    p.b = r.ellipsoid(8.0);
    p.law = ScaleLaw{r.uni(0.5, 1.0), r.log_uni(0.01, 0.5)};
    const Pose pa{r.ball(2.0), r.rotation()};
    const Vec3 n = r.unit();
    if (kind <= 2) {
      const Ellipsoid as = scaled_shape(p.a, p.law.s), bs = scaled_shape(p.b, p.law.s);
      const double L = std::max(as.bounding_radius(), bs.bounding_radius());
      const double gap = r.log_uni(1e-3, 3.0 * L);
      const Pose pb = testing::place_at_distance(as, pa, bs, r.rotation(), n, gap);
      const double speed = kind == 2 ? r.uni(0.0, 0.05) : r.uni(0.3, 2.0);
      const double spin = kind == 1 ? 40.0 / L : (kind == 2 ? 0.2 / L : 2.0 / L);
      p.sa = BodyState{pa.r, Quat(pa.R), r.ball(0.5), r.ball(spin)};
      p.sb = BodyState{pb.r, Quat(pb.R), Vec3::Zero(), r.ball(spin)};
      p.sb.v = p.sa.v - speed * (n + 0.8 * r.ball(1.0)).normalized();
      if (kind == 2) p.law.rate = r.uni(0.1, 0.5);
      g.t_max = kind == 2 ? 5.0 : r.uni(0.5, 3.0) * (gap + 2 * L) / speed;
    } else {
      // state at t* = 1, then streamed back to t = 0
      const double ts = 1.0, s1 = p.law.s + p.law.rate * ts;
      const Ellipsoid as = scaled_shape(p.a, s1), bs = scaled_shape(p.b, s1);
      const double L = std::max(as.bounding_radius(), bs.bounding_radius());
      const double gap = -r.log_uni(1e-8, 1e-4);
      const Pose pb = testing::place_at_distance(as, pa, bs, r.rotation(), n, gap);
      BodyState A{pa.r, Quat(pa.R), r.ball(0.5), Vec3::Zero()};
      BodyState B{pb.r, Quat(pb.R), Vec3::Zero(), Vec3::Zero()};
      Vec3 vrel = r.unit();
      vrel = (vrel - n * n.dot(vrel)).normalized() * r.uni(0.3, 2.0);
      B.v = A.v + vrel;
      if (r.uni(0, 1) < 0.5) {
        A.w = r.ball(0.3 / L);
        B.w = r.ball(0.3 / L);
      }
      // d'(t*) = 0 including growth: remove the normal closing rate
      const Vec3 xa = pa.r + pa.R * as.support_point(pa.R.transpose() * n);
      const Vec3 xb = xa + gap * n;
      const double gr = p.law.rate / s1;
      const double rate = n.dot((B.v + B.w.cross(xb - B.r) + gr * (xb - B.r)) -
                                (A.v + A.w.cross(xa - A.r) + gr * (xa - A.r)));
      B.v -= rate * n;
      p.sa = A;
      p.sb = B;
      p.sa.r -= A.v * ts;
      p.sb.r -= B.v * ts;
      p.sa.q = orientation_at(A, -ts);
      p.sb.q = orientation_at(B, -ts);
      g.t_max = 2.0;
    }
    // clearly apart at t = 0
    const Ellipsoid a0 = scaled_shape(p.a, p.law.s), b0 = scaled_shape(p.b, p.law.s);
    const Pose q0{p.sa.r, p.sa.q.toRotationMatrix()}, q1{p.sb.r, p.sb.q.toRotationMatrix()};
    if (ref::reference_distance(a0, q0, b0, q1).distance > 1e-3) return g;
  }
}

struct GStats {
  int n = 0, hits = 0, ref_hits = 0, failed = 0, missed = 0, false_hits = 0, fallbacks = 0, grazing = 0;
  long evals = 0, ref_evals = 0;
  double max_err = 0, max_late = -kInf;
  void print(const char* name) const {
    std::printf("  %-9s pairs %5d hits %5d (ref %5d) missed %d false %d failed %d fallbacks %d "
                "grazing %d  max|t-t_ref| %.2e  max(t-t_ref) %.2e  evals/pair %.1f (ref %.0f)\n",
                name, n, hits, ref_hits, missed, false_hits, failed, fallbacks, grazing, max_err,
                max_late, double(evals) / n, double(ref_evals) / n);
  }
};

void run_growing(int kind, int count, std::uint64_t seed, GStats& st, double eps_d = 1e-5) {
  Rng r(seed);
  for (int k = 0; k < count; ++k) {
    const GScenario g = make_growing(r, kind);
    ContactInput<Ellipsoid, Ellipsoid> in{g.p.a, g.p.b, g.p.sa, g.p.sb, 0.0, 0.0, g.t_max, eps_d};
    in.growth = g.p.law;
    const ContactResult c = contact_time(in);
    const GrowRef rc = reference_growing_contact(g.p, g.t_max, 1e-6);
    ++st.n;
    st.evals += c.distance_evals;
    st.ref_evals += rc.evals;
    st.fallbacks += c.fallbacks;
    st.grazing += c.grazing_searches;
    if (c.status == ContactStatus::failed) ++st.failed;
    if (c.status == ContactStatus::hit) ++st.hits;
    if (rc.hit) ++st.ref_hits;
    EXPECT_NE(c.status, ContactStatus::failed) << "kind " << kind << " k " << k;
    if (rc.hit) {
      if (c.status != ContactStatus::hit) {
        ++st.missed;
        ADD_FAILURE() << "missed: kind " << kind << " k " << k << " t_ref " << rc.time;
        continue;
      }
      const double tol = 1e-9 * std::max(1.0, rc.time);
      st.max_err = std::max(st.max_err, std::abs(c.time - rc.time));
      st.max_late = std::max(st.max_late, c.time - rc.time);
      EXPECT_NEAR(c.time, rc.time, tol) << "kind " << kind << " k " << k;
      EXPECT_LE(c.time, rc.time + tol) << "later than the reference: kind " << kind << " k " << k;
      // the point lies on both grown surfaces; the normal is A's outward normal
      const double sc = g.p.s(c.time);
      const Ellipsoid as = scaled_shape(g.p.a, sc), bs = scaled_shape(g.p.b, sc);
      const Posed<Ellipsoid> A{&as, Pose{g.p.sa.r + g.p.sa.v * c.time, rotation_at(g.p.sa, c.time)}};
      const Posed<Ellipsoid> B{&bs, Pose{g.p.sb.r + g.p.sb.v * c.time, rotation_at(g.p.sb, c.time)}};
      EXPECT_LE(std::abs(A.f(c.point)), 1e-6);
      EXPECT_LE(std::abs(B.f(c.point)), 1e-6);
      EXPECT_GT(c.normal.dot(A.grad(c.point).normalized()), 1 - 1e-6);
    } else if (c.status == ContactStatus::hit) {
      ++st.false_hits;
      ADD_FAILURE() << "false hit: kind " << kind << " k " << k << " t " << c.time
                    << " ref min d " << rc.min_distance << " solver min d " << c.min_distance;
    }
  }
}

TEST(GrowthContact, ApproachingPairsVsReference) {
  GStats st;
  run_growing(0, scaled_count(1000, 0.01), 71, st);
  st.print("approach");
}
TEST(GrowthContact, FastSpinnersVsReference) {
  GStats st;
  run_growing(1, scaled_count(500, 0.01, 8), 72, st);
  st.print("spinners");
}
TEST(GrowthContact, GrowthClosesTheGapVsReference) {
  GStats st;
  run_growing(2, scaled_count(500, 0.01), 73, st);
  st.print("growth");
  EXPECT_GT(st.hits, st.n / 2);
}
TEST(GrowthContact, JustTouchingVsReference) {
  GStats st;
  run_growing(3, scaled_count(500, 0.01, 8), 74, st);
  st.print("touching");
  EXPECT_EQ(st.hits, st.n);  // every one overlaps at t = 1
}
TEST(GrowthContact, JustTouchingCoarseEpsVsReference) {
  GStats st;
  run_growing(3, scaled_count(300, 0.01, 8), 75, st, 1e-2);
  st.print("touch,eps");
  EXPECT_EQ(st.hits, st.n);
}

// contact_time(A, B) == contact_time(B, A) with growth.
TEST(GrowthContact, SymmetricInAandB) {
  Rng r(76);
  for (int k = 0; k < scaled_count(500, 0.02); ++k) {
    const GScenario g = make_growing(r, k % 3);
    ContactInput<Ellipsoid, Ellipsoid> ab{g.p.a, g.p.b, g.p.sa, g.p.sb, 0.0, 0.0, g.t_max, 1e-5};
    ContactInput<Ellipsoid, Ellipsoid> ba{g.p.b, g.p.a, g.p.sb, g.p.sa, 0.0, 0.0, g.t_max, 1e-5};
    ab.growth = ba.growth = g.p.law;
    const ContactResult cab = contact_time(ab), cba = contact_time(ba);
    ASSERT_EQ(cab.status, cba.status) << k;
    if (cab.status != ContactStatus::hit) continue;
    EXPECT_NEAR(cab.time, cba.time, 1e-10 * std::max(1.0, cab.time));
    EXPECT_LE((cab.point - cba.point).norm(), 1e-6);
    EXPECT_LE((cab.normal + cba.normal).norm(), 1e-6);
  }
}

}  // namespace
}  // namespace hb
