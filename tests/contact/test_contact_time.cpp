// Contact time: contact-system Jacobian vs finite differences, and agreement with the
// independent conservative-advancement reference on random moving pairs (approaching pairs,
// fast spinners, grazing passes just above contact, pairs that just touch).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "contact/contact_time.hpp"
#include "contact/reference_contact_time.hpp"
#include "geometry/random_pairs.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

template <class SA, class SB>
double contact_jacobian_error(const SA& a, const SB& b, Rng& r) {
  const double L = std::max(a.bounding_radius(), b.bounding_radius());
  BodyState sa{r.ball(1.0), r.quat(), r.ball(1.0), r.ball(2.0 / L)};
  BodyState sb{r.ball(3.0 * L), r.quat(), r.ball(1.0), r.ball(2.0 / L)};
  const MovingBody<SA> A{&a, sa, 0.3, sa.r};
  const MovingBody<SB> B{&b, sb, 0.3, sa.r};
  Vec5c y;
  y << r.ball(2.0 * L), r.uni(0.3, 2.0), r.uni(-1.0, 1.0);
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

TEST(ContactJacobian, MatchesFiniteDifferences) {
  Rng r(31);
  double ws = 0, we = 0, wm = 0;
  for (int k = 0; k < 300; ++k) {
    ws = std::max(ws, contact_jacobian_error(Sphere{0.7}, Sphere{1.2}, r));
    we = std::max(we, contact_jacobian_error(Ellipsoid{0.3, 1.7, 1.0}, Ellipsoid{2.0, 0.5, 0.9}, r));
    wm = std::max(wm, contact_jacobian_error(Ellipsoid{2.0, 0.5, 0.5}, Sphere{0.6}, r));
  }
  std::printf("  contact Jacobian max relative column error: spheres %.2e ellipsoids %.2e mixed %.2e\n",
              ws, we, wm);
  EXPECT_LT(ws, 1e-6);
  EXPECT_LT(we, 1e-6);
  EXPECT_LT(wm, 1e-6);
}

TEST(Contact, BoundingSphereWindowAndRate) {
  BodyState a, b;
  b.r = Vec3(10, 0, 0);
  b.v = Vec3(-1, 0, 0);
  double lo = 0, hi = 100;
  ASSERT_TRUE(bounding_sphere_window(a, b, 0.0, 2.0, lo, hi));
  EXPECT_NEAR(lo, 8.0, 1e-12);
  EXPECT_NEAR(hi, 12.0, 1e-12);
  lo = 0, hi = 100;
  b.v = Vec3(0, 1, 0);
  EXPECT_FALSE(bounding_sphere_window(a, b, 0.0, 2.0, lo, hi));
  a.w = Vec3(0, 0, 3);
  EXPECT_NEAR(distance_rate_bound(a, 2.0, b, 1.0), 1.0 + 6.0, 1e-15);
}

// bounding_spheres_may_meet (no roots) gives bounding_sphere_window's answer. Random pairs
// (approaching, half of them aimed roughly at each other, receding, passing, overlapping now;
// finite and infinite spans, a third with no relative velocity along one axis): the same
// answer every time. At the window's edges (the span cut at the entry root to within a few
// ulps; spheres touching now and receding), where rounding may decide either way, a "no" of the
// root-free test is checked in long double: the spheres' smallest gap over the span is zero to
// rounding, 1e-13 R (nothing the solver, whose radius carries its margin, could find).
TEST(Contact, BoundingSpheresMayMeetIsTheWindowsAnswer) {
  Rng r(77);
  const BodyState a;
  int meet = 0, apart = 0, differ = 0;
  const int n = scaled_count(200000);
  for (int k = 0; k < n; ++k) {
    BodyState b;
    const double R = r.uni(0.5, 3.0), span = k % 4 == 0 ? kInf : r.log_uni(1e-3, 10.0);
    b.r = r.ball(3.0 * R);
    b.v = r.ball(2.0);
    if (k % 2 == 0) b.v += -r.uni(0.0, 2.0) * b.r.normalized();  // aimed at A, roughly
    if (k % 3 == 1) b.v[k % 2] = 0.0;
    double lo = 0.0, hi = span;
    const bool win = bounding_sphere_window(a, b, 0.0, R, lo, hi) && lo <= hi;
    const bool may = bounding_spheres_may_meet(b.r - a.r, b.v - a.v, R, span);
    differ += win != may;
    (win ? meet : apart) += 1;
  }
  std::printf("  random pairs: %d meet, %d apart, %d answers differ\n", meet, apart, differ);
  EXPECT_EQ(differ, 0);
  EXPECT_GT(meet, n / 20);
  EXPECT_GT(apart, n / 20);

  // the edges: the smallest gap |p + dv tau| - R over [0, span], in long double
  auto min_gap = [](const Vec3& p, const Vec3& dv, double R, double span) {
    long double A = 0, B = 0, C = 0;
    for (int i = 0; i < 3; ++i) A += (long double)dv[i] * dv[i], B += (long double)p[i] * dv[i], C += (long double)p[i] * p[i];
    long double tau = A > 0 ? -B / A : 0;
    tau = std::clamp<long double>(tau, 0, span);
    return std::sqrt(std::max<long double>(A * tau * tau + 2 * B * tau + C, 0)) - (long double)R;
  };
  int edges = 0, edge_no = 0;
  double worst = 0.0;
  for (int k = 0; k < scaled_count(20000); ++k) {
    BodyState b;
    b.r = r.ball(6.0);
    b.v = r.ball(2.0);
    const double R = r.uni(0.5, 3.0);
    double span;
    if (k % 2 == 0) {  // the span ends at the entry root, to a few ulps
      double lo = 0.0, hi = kInf;
      if (!bounding_sphere_window(a, b, 0.0, R, lo, hi) || !(lo > 0.0)) continue;
      span = lo * (1.0 + (k % 7 - 3) * 2.2e-16);
    } else {  // touching now and receding
      b.r = R * (1.0 + (k % 5 - 2) * 2.2e-16) * r.unit();
      b.v = r.uni(0.1, 2.0) * b.r.normalized() + r.ball(0.05);
      span = r.uni(0.1, 5.0);
    }
    ++edges;
    if (bounding_spheres_may_meet(b.r - a.r, b.v - a.v, R, span)) continue;
    ++edge_no;
    worst = std::min(worst, double(min_gap(b.r, b.v, R, span)) / R);
  }
  std::printf("  edges: %d cases, %d answered no; smallest gap of those %.2e R\n", edges, edge_no, worst);
  EXPECT_GT(edge_no, edges / 10);
  EXPECT_GT(worst, -1e-13);  // rounding, far below the solver's margin (>= 1e-9 L)
}

// The distance-rate bound K = |v_B - v_A| + |w_A| l_A + |w_B| l_B with the shapes' rotation
// levers l (shapes/shape.hpp; l <= L, an ellipsoid's a_max - a_min) against central differences
// of the distance of spinning ellipsoids (prolate, oblate, triaxial; spherical tops, so w is
// constant) at random separations down to near contact, a third of them turning only (no
// translation, where the rotation terms are all of K): |d'| never exceeds K, and the bound with
// the paper's bounding radii is looser. The spheroids' bound with the spin across their axes
// (Motion::spin_across) in place of |w| holds too, and is tighter.
TEST(Contact, DistanceRateBoundWithRotationLeversHolds) {
  Rng r(33);
  const Ellipsoid shapes[] = {Ellipsoid{1.0, 0.5, 0.5}, Ellipsoid{0.5, 1.0, 1.0}, Ellipsoid{0.3, 1.7, 1.0},
                              Ellipsoid{2.0, 0.4, 0.9}};
  double worst = 0.0, worst_spin = 0.0, worst_rev = 0.0;
  int n = 0, tighter = 0;
  const int cases = scaled_count(4000, 0.25);  // cheap: a quarter of the cases in Debug
  for (int k = 0; k < cases; ++k) {
    const Ellipsoid& sa = shapes[k % 4];
    const Ellipsoid& sb = shapes[(k / 4) % 4];
    BodyState a, b;
    a.q = r.quat(), b.q = r.quat();
    a.w = r.ball(5.0), b.w = r.ball(5.0);
    const bool spin_only = k % 3 == 0;
    if (!spin_only) a.v = r.ball(1.0), b.v = r.ball(1.0);
    b.r = r.unit() * r.uni(0.5, 1.0) * (sa.bounding_radius() + sb.bounding_radius());
    const auto d_at = [&](double t) {
      BodyState x = a, y = b;
      advance(x, t), advance(y, t);
      return distance(sa, Pose{x.r, x.q.toRotationMatrix()}, sb, Pose{y.r, y.q.toRotationMatrix()});
    };
    const DistanceResult d0 = d_at(0.0);
    if (d0.status != DistanceStatus::converged || !(d0.distance > 1e-3)) continue;  // separated pairs
    const double h = 1e-6;
    const DistanceResult dp = d_at(h), dm = d_at(-h);
    if (dp.status != DistanceStatus::converged || dm.status != DistanceStatus::converged) continue;
    const double rate = (dp.distance - dm.distance) / (2 * h);
    const double K = distance_rate_bound(a, rotation_lever(sa), b, rotation_lever(sb));
    const double K_paper = distance_rate_bound(a, sa.bounding_radius(), b, sb.bounding_radius());
    // the spheroids' bound: the spin across their axes (shapes/shape.hpp revolution_axis)
    const Motion ma(a), mb(b);
    const double K_rev = distance_rate_bound(ma, rotation_lever(sa), revolution_axis(sa), mb,
                                             rotation_lever(sb), revolution_axis(sb));
    ASSERT_LE(std::abs(rate), K * (1 + 1e-6) + 1e-9) << "case " << k;
    ASSERT_LE(std::abs(rate), K_rev * (1 + 1e-6) + 1e-9) << "case " << k;
    ASSERT_LE(K, K_paper);
    ASSERT_LE(K_rev, K);
    if (revolution_axis(sa) < 0 && revolution_axis(sb) < 0) {
      ASSERT_EQ(K_rev, K);
    }
    worst = std::max(worst, std::abs(rate) / K);
    if (spin_only) worst_spin = std::max(worst_spin, std::abs(rate) / K);
    if (spin_only) worst_rev = std::max(worst_rev, std::abs(rate) / K_rev);
    tighter += K_rev < 0.9 * K;
    ++n;
  }
  std::printf("  %d separated pairs: max |d'| / K %.3f (turning only %.3f; with the spin across "
              "the spheroids' axes %.3f, below 0.9 K in %d)\n", n, worst, worst_spin, worst_rev,
              tighter);
  EXPECT_GT(n, cases / 2);
  EXPECT_GT(worst_spin, 0.5);  // the levers are not a loose bound where rotation is everything
  EXPECT_GT(worst_rev, 0.5);   // nor the spin across the axes,
  EXPECT_GT(tighter, n / 10);  // which is tighter in many cases
}

// Two spheres: the generic solver against the closed form.
TEST(Contact, SpheresMatchClosedForm) {
  Rng r(32);
  for (int k = 0; k < scaled_count(2000); ++k) {
    const Sphere a{r.uni(0.3, 1.5)}, b{r.uni(0.3, 1.5)};
    BodyState sa{r.ball(2.0), r.quat(), r.ball(1.0), r.ball(1.0)};
    BodyState sb{sa.r + (a.radius + b.radius + r.log_uni(1e-3, 3.0)) * r.unit(), r.quat(),
                 r.ball(1.0), r.ball(1.0)};
    sb.v += (sa.r - sb.r).normalized() * r.uni(0.0, 2.0);
    const ContactResult c = contact_time(ContactInput<Sphere, Sphere>{a, b, sa, sb, 0.0, 0.0, 10.0, 1e-6});
    // closed form: |dr + dv t| = a + b
    const Vec3 dr = sb.r - sa.r, dv = sb.v - sa.v;
    const double A = dv.squaredNorm(), B = dr.dot(dv), C = dr.squaredNorm() - std::pow(a.radius + b.radius, 2);
    const double disc = B * B - A * C;
    double t = kInf;
    if (B < 0 && disc >= 0) t = C / (-B + std::sqrt(disc));
    if (t > 10.0) t = kInf;
    ASSERT_NE(c.status, ContactStatus::failed);
    if (t == kInf) {
      EXPECT_EQ(c.status, ContactStatus::none) << k;
    } else {
      ASSERT_EQ(c.status, ContactStatus::hit) << k;
      EXPECT_NEAR(c.time, t, 1e-10 * std::max(1.0, t));
      EXPECT_LE(c.time, t + 1e-12);
      const Vec3 ra = sa.r + sa.v * c.time, rb = sb.r + sb.v * c.time;
      EXPECT_LE((c.normal - (rb - ra).normalized()).norm(), 1e-6);
      EXPECT_NEAR((c.point - ra).norm(), a.radius, 1e-9);
    }
  }
}

struct Scenario {
  Ellipsoid a, b;
  BodyState sa, sb;
  double t_max;
};

// kind 0: approaching pair; 1: fast spinners; 2: grazing pass (closest approach 1e-8..1e-4
// above contact at t = 1), pure translation; 3: the same, rotating; 4: just touching (overlap
// 1e-8..1e-4 at t = 1), translating or rotating.
Scenario make_scenario_once(Rng& r, int kind);
// Scenarios whose bodies are clearly apart at t = 0 (distance > 1e-3, by the reference).
Scenario make_scenario(Rng& r, int kind) {
  for (;;) {
    const Scenario s = make_scenario_once(r, kind);
    const Pose pa{s.sa.r, s.sa.q.toRotationMatrix()}, pb{s.sb.r, s.sb.q.toRotationMatrix()};
    if (ref::reference_distance(s.a, pa, s.b, pb).distance > 1e-3) return s;
  }
}

Scenario make_scenario_once(Rng& r, int kind) {
  Scenario s;
  s.a = r.ellipsoid(10.0);
  s.b = r.ellipsoid(10.0);
  const double L = std::max(s.a.bounding_radius(), s.b.bounding_radius());
  const Pose pa{r.ball(2.0), r.rotation()};
  const Vec3 n = r.unit();
  if (kind <= 1) {
    const double gap = r.log_uni(1e-3, 4.0 * L);
    const Pose pb = testing::place_at_distance(s.a, pa, s.b, r.rotation(), n, gap);
    const double speed = r.uni(0.3, 2.0);
    s.sa = BodyState{pa.r, Quat(pa.R), r.ball(0.5), r.ball(kind == 0 ? 2.0 / L : 40.0 / L)};
    s.sb = BodyState{pb.r, Quat(pb.R), Vec3::Zero(), r.ball(kind == 0 ? 2.0 / L : 40.0 / L)};
    s.sb.v = s.sa.v - speed * (n + 0.8 * r.ball(1.0)).normalized();
    s.t_max = r.uni(0.5, 3.0) * (gap + 2 * L) / speed;
    return s;
  }
  const double gap = (kind <= 3 ? 1.0 : -1.0) * r.log_uni(1e-8, 1e-4);
  const Pose pb = testing::place_at_distance(s.a, pa, s.b, r.rotation(), n, gap);
  BodyState A{pa.r, Quat(pa.R), r.ball(0.5), Vec3::Zero()};
  BodyState B{pb.r, Quat(pb.R), Vec3::Zero(), Vec3::Zero()};
  Vec3 vrel = r.unit();
  vrel = (vrel - n * n.dot(vrel)).normalized() * r.uni(0.3, 2.0);
  B.v = A.v + vrel;
  if (kind == 3 || (kind == 4 && r.uni(0, 1) < 0.5)) {  // add rotation, keeping d'(t*) = 0
    A.w = r.ball(0.3 / L);
    B.w = r.ball(0.3 / L);
    const Vec3 xa = pa.r + pa.R * s.a.support_point(pa.R.transpose() * n);
    const Vec3 xb = xa + gap * n;
    const double rate = n.dot((B.v + B.w.cross(xb - B.r)) - (A.v + A.w.cross(xa - A.r)));
    B.v -= rate * n;
  }
  // back to t = 0 from t* = 1
  const double ts = 1.0;
  s.sa = A;
  s.sb = B;
  s.sa.r -= A.v * ts;
  s.sb.r -= B.v * ts;
  s.sa.q = orientation_at(A, -ts);
  s.sb.q = orientation_at(B, -ts);
  s.t_max = 2.0;
  return s;
}

struct CStats {
  int n = 0, hits = 0, ref_hits = 0, failed = 0, fallbacks = 0, grazing = 0, missed = 0, false_hits = 0;
  long dist_evals = 0, ref_evals = 0, nr = 0;
  double max_err = 0, max_late = -kInf;
  void print(const char* name) const {
    std::printf("  %-10s pairs %5d hits %5d (ref %5d) missed %d false %d failed %d fallbacks %d "
                "grazing searches %d\n"
                "  %-10s max |t - t_ref| %.2e  max (t - t_ref) %.2e  distance evals/pair %.1f "
                "(ref %.0f)  contact NR it/pair %.2f\n",
                name, n, hits, ref_hits, missed, false_hits, failed, fallbacks, grazing, "",
                max_err, max_late, double(dist_evals) / n, double(ref_evals) / n,
                double(nr) / n);
  }
};

void run_kind(int kind, int count, uint64_t seed, CStats& st, double eps_d = 1e-5) {
  Rng r(seed);
  for (int k = 0; k < count; ++k) {
    const Scenario s = make_scenario(r, kind);
    const ContactResult c = contact_time(
        ContactInput<Ellipsoid, Ellipsoid>{s.a, s.b, s.sa, s.sb, 0.0, 0.0, s.t_max, eps_d});
    const ref::RefContact rc = ref::reference_contact_time(s.a, s.sa, s.b, s.sb, s.t_max, 1e-6);
    ++st.n;
    st.dist_evals += c.distance_evals;
    st.ref_evals += rc.evals;
    st.nr += c.nr_iterations;
    st.fallbacks += c.fallbacks;
    st.grazing += c.grazing_searches;
    if (c.status == ContactStatus::failed) ++st.failed;
    if (c.status == ContactStatus::hit) ++st.hits;
    if (rc.hit) ++st.ref_hits;
    EXPECT_NE(c.status, ContactStatus::failed) << "kind " << kind << " k " << k;
    if (rc.hit) {
      if (c.status != ContactStatus::hit) {
        ++st.missed;
        ADD_FAILURE() << "missed: kind " << kind << " k " << k << " t_ref " << rc.time
                      << " ref min d " << rc.min_distance;
        continue;
      }
      const double tol = 1e-9 * std::max(1.0, rc.time);
      st.max_err = std::max(st.max_err, std::abs(c.time - rc.time));
      st.max_late = std::max(st.max_late, c.time - rc.time);
      EXPECT_NEAR(c.time, rc.time, tol) << "kind " << kind << " k " << k;
      EXPECT_LE(c.time, rc.time + tol) << "later than the reference: kind " << kind << " k " << k;
      // the contact point lies on both surfaces, the normal is A's outward normal
      const Pose pa{s.sa.r + s.sa.v * c.time, rotation_at(s.sa, c.time)};
      const Pose pb{s.sb.r + s.sb.v * c.time, rotation_at(s.sb, c.time)};
      const Posed<Ellipsoid> A{&s.a, pa}, B{&s.b, pb};
      EXPECT_LE(std::abs(A.f(c.point)), 1e-6);
      EXPECT_LE(std::abs(B.f(c.point)), 1e-6);
      EXPECT_GT(c.normal.dot(A.grad(c.point).normalized()), 1 - 1e-6);
    } else if (c.status == ContactStatus::hit) {
      ++st.false_hits;
      // a hit the reference did not see: must be within the reference's resolution
      ADD_FAILURE() << "false hit: kind " << kind << " k " << k << " t " << c.time
                    << " ref min d " << rc.min_distance << " solver min d " << c.min_distance;
    }
  }
}

TEST(Contact, ApproachingPairsVsReference) {
  CStats st;
  run_kind(0, scaled_count(4000, 0.005), 41, st);
  st.print("approach");
}
TEST(Contact, FastSpinnersVsReference) {
  CStats st;
  run_kind(1, scaled_count(2000, 0.005, 8), 42, st);
  st.print("spinners");
}
// Translating grazing passes: d(t) is convex (distance of a moving point to a convex set), its
// minimum 1e-8..1e-4 is at t = 1, so none of them may be reported as a hit.
TEST(Contact, GrazingPassesVsReference) {
  CStats st;
  run_kind(2, scaled_count(1000, 0.001, 1), 43, st);
  st.print("grazing");
  EXPECT_EQ(st.hits, 0);
}
TEST(Contact, RotatingGrazingPassesVsReference) {
  CStats st;
  run_kind(3, scaled_count(1000, 0.001, 1), 45, st);
  st.print("graze+rot");
}
TEST(Contact, JustTouchingVsReference) {
  CStats st;
  run_kind(4, scaled_count(2000, 0.0005, 1), 44, st);
  st.print("touching");
  EXPECT_EQ(st.hits, st.n);  // every one overlaps at t = 1
}
// With a coarse eps_d the steps jump over the short overlap window of the shallow touches, so
// the grazing search (Brent on d(t)) must find the negative minimum.
TEST(Contact, JustTouchingCoarseEpsVsReference) {
  CStats st;
  run_kind(4, scaled_count(1000, 0.002, 2), 46, st, 1e-2);
  st.print("touch,eps");
  EXPECT_EQ(st.hits, st.n);
  if (st.n >= 50) {
    EXPECT_GT(st.grazing, 0);  // the path is exercised (Release: ~500 searches)
  }
}
// The same grazing passes with the coarse eps_d: Brent must not invent contacts.
TEST(Contact, GrazingCoarseEpsVsReference) {
  CStats st;
  run_kind(3, scaled_count(500, 0.002, 1), 47, st, 1e-2);
  st.print("graze,eps");
  EXPECT_EQ(st.false_hits, 0);
}


// contact_time(A, B) == contact_time(B, A): same time, same point, opposite normal.
TEST(Contact, SymmetricInAandB) {
  Rng r(48);
  for (int k = 0; k < scaled_count(1000, 0.01); ++k) {
    const Scenario s = make_scenario(r, k % 2);
    const ContactResult ab = contact_time(
        ContactInput<Ellipsoid, Ellipsoid>{s.a, s.b, s.sa, s.sb, 0.0, 0.0, s.t_max, 1e-5});
    const ContactResult ba = contact_time(
        ContactInput<Ellipsoid, Ellipsoid>{s.b, s.a, s.sb, s.sa, 0.0, 0.0, s.t_max, 1e-5});
    ASSERT_EQ(ab.status, ba.status) << k;
    if (ab.status != ContactStatus::hit) continue;
    EXPECT_NEAR(ab.time, ba.time, 1e-10 * std::max(1.0, ab.time));
    EXPECT_LE((ab.point - ba.point).norm(), 1e-6);
    EXPECT_LE((ab.normal + ba.normal).norm(), 1e-6);
  }
}

// Step 4' (Newton ahead of a sample or of the last axis leap, contact_ahead) against the
// bracketed path it shortcuts: every scenario kind (approaching, fast spinners, grazing passes
// with and without rotation, just touching), the same status and the same time, and the
// shortcut taken in most hits.
TEST(Contact, NewtonAheadAgreesWithTheBracketedPath) {
  Rng r(50);
  ContactOptions off;
  off.contact_ahead = false;
  int hits = 0, ahead = 0, n = 0;
  long evals_on = 0, evals_off = 0;
  double worst = 0.0;
  for (int kind = 0; kind <= 4; ++kind)
    for (int k = 0; k < scaled_count(600, 0.01, 4); ++k) {
      const Scenario s = make_scenario(r, kind);
      const ContactInput<Ellipsoid, Ellipsoid> in{s.a, s.b, s.sa, s.sb, 0.0, 0.0, s.t_max, 1e-5};
      const ContactResult on = contact_time(in), ref = contact_time(in, off);
      ++n;
      EXPECT_EQ(ref.ahead, 0);
      ASSERT_EQ(on.status, ref.status) << "kind " << kind << " k " << k;
      evals_on += on.distance_evals;
      evals_off += ref.distance_evals;
      if (on.status != ContactStatus::hit) continue;
      ++hits;
      ahead += on.ahead;
      worst = std::max(worst, std::abs(on.time - ref.time) / std::max(1.0, ref.time));
      EXPECT_LE((on.normal - ref.normal).norm(), 1e-6) << "kind " << kind << " k " << k;
    }
  std::printf("  %d pairs, %d hits, %d found ahead; distance evals %.2f -> %.2f per pair; "
              "max |t_ahead - t_bracket| %.1e\n",
              n, hits, ahead, double(evals_off) / n, double(evals_on) / n, worst);
  EXPECT_LE(worst, 1e-10);
  EXPECT_GE(ahead, hits / 2);  // the shortcut is the usual path
  EXPECT_LT(evals_on, evals_off);
}

// A Newton root certified by its residuals and convexity (certify_newton) against its slow
// twin, the distance solve at the root: every scenario kind (approaching, fast spinners,
// grazing passes with and without rotation, just touching) and asymmetric tops, the same status,
// and hits at the same time, point and normal bit for bit (the certificate only saves the
// distance solve of an acceptance); the certificate is the usual path and saves solves.
// The root offered to the certificate before Newton converges (certify_early, the default)
// against the converged root: the same status, times within 2e-12 L / K of each other (each
// is within the converged Newton's time tolerance, 1e-12 L / K, of the root), points and
// normals to 1e-9, and fewer Newton iterations.
TEST(Contact, CertifiedNewtonRootsAgreeWithTheDistanceSolve) {
  Rng r(51);
  ContactOptions converged, solve;
  converged.certify_early = false;
  solve.certify_newton = false;
  int hits = 0, certified = 0, n = 0;
  long evals_on = 0, evals_off = 0, nr_early = 0, nr_converged = 0;
  double worst_time = 0.0, worst_point = 0.0, worst_normal = 0.0;
  for (int kind = 0; kind <= 4; ++kind)
    for (int k = 0; k < scaled_count(600, 0.01, 4); ++k) {
      Scenario s = make_scenario(r, kind);
      if (k % 5 == 2) {
        s.sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
        s.sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
      }
      const ContactInput<Ellipsoid, Ellipsoid> in{s.a, s.b, s.sa, s.sb, 0.0, 0.0, s.t_max, 1e-5};
      const ContactResult early = contact_time(in), on = contact_time(in, converged),
                          ref = contact_time(in, solve);
      ++n;
      EXPECT_EQ(ref.certified, 0);
      ASSERT_EQ(on.status, ref.status) << "kind " << kind << " k " << k;
      ASSERT_EQ(early.status, on.status) << "kind " << kind << " k " << k;
      evals_on += on.distance_evals;
      evals_off += ref.distance_evals;
      nr_early += early.nr_iterations;
      nr_converged += on.nr_iterations;
      if (on.status != ContactStatus::hit) continue;
      ++hits;
      certified += on.certified;
      EXPECT_EQ(on.time, ref.time) << "kind " << kind << " k " << k;
      EXPECT_EQ(on.point, ref.point) << "kind " << kind << " k " << k;
      EXPECT_EQ(on.normal, ref.normal) << "kind " << kind << " k " << k;
      const double L = std::max(s.a.bounding_radius(), s.b.bounding_radius());
      const double dt = std::abs(early.time - on.time) / ref::time_unit(s.a, s.b, s.sa, s.sb);
      worst_time = std::max(worst_time, dt);
      worst_point = std::max(worst_point, (early.point - on.point).norm() / L);
      worst_normal = std::max(worst_normal, (early.normal - on.normal).norm());
      EXPECT_LE(dt, 2e-12) << "kind " << kind << " k " << k;
      EXPECT_LE((early.point - on.point).norm(), 1e-9 * L) << "kind " << kind << " k " << k;
      EXPECT_LE((early.normal - on.normal).norm(), 1e-9) << "kind " << kind << " k " << k;
    }
  std::printf("  %d pairs, %d hits, %d certified; distance evals %.2f -> %.2f per pair\n", n, hits,
              certified, double(evals_off) / n, double(evals_on) / n);
  std::printf("  early certificate: Newton iterations %.2f -> %.2f per pair; largest differences "
              "time %.2g L/K, point %.2g L, normal %.2g\n",
              double(nr_converged) / n, double(nr_early) / n, worst_time, worst_point, worst_normal);
  EXPECT_GE(certified, hits / 2);  // the certificate is the usual path
  EXPECT_LT(evals_on, evals_off);
  EXPECT_LT(nr_early, nr_converged);
}

// Just after a collision the pair touches (d ~ -1e-15) and separates: no spurious contact at
// t = 0; the same pair approaching is a contact at once (initial overlap).
TEST(Contact, TouchingPairSeparatingIsNotAContact) {
  Rng r(49);
  for (int k = 0; k < 200; ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const Pose pa{r.ball(1.0), r.rotation()};
    const Vec3 n = r.unit();
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), n, -1e-14);
    BodyState sa{pa.r, Quat(pa.R), Vec3::Zero(), Vec3::Zero()};
    BodyState sb{pb.r, Quat(pb.R), 0.5 * n + 0.3 * r.unit().cross(n), Vec3::Zero()};
    const ContactResult leave = contact_time(
        ContactInput<Ellipsoid, Ellipsoid>{a, b, sa, sb, 0.0, 0.0, 10.0, 1e-5});
    EXPECT_EQ(leave.status, ContactStatus::none) << k << " t " << leave.time;
    sb.v = -sb.v;
    const ContactResult come = contact_time(
        ContactInput<Ellipsoid, Ellipsoid>{a, b, sa, sb, 0.0, 0.0, 10.0, 1e-5});
    ASSERT_EQ(come.status, ContactStatus::hit);
    EXPECT_EQ(come.time, 0.0);
    EXPECT_TRUE(come.initial_overlap);
  }
}

// A window that excludes the contact gives none; t_start/t_state offsets are honoured.
TEST(Contact, WindowAndStateTime) {
  const Ellipsoid a{1.0, 0.5, 0.5}, b{0.5, 0.5, 1.0};
  BodyState sa, sb;
  sb.r = Vec3(5.0, 0, 0);
  sb.v = Vec3(-1.0, 0, 0);  // contact when the centre gap is 1.5: at t = 3.5 after t_state
  const double ts = 10.0;
  ContactResult c = contact_time(ContactInput<Ellipsoid, Ellipsoid>{a, b, sa, sb, ts, ts, ts + 100, 1e-6});
  ASSERT_EQ(c.status, ContactStatus::hit);
  EXPECT_NEAR(c.time, ts + 3.5, 1e-12);
  EXPECT_LE((c.point - Vec3(1.0, 0, 0)).norm(), 1e-6);
  EXPECT_LE((c.normal - Vec3::UnitX()).norm(), 1e-9);
  c = contact_time(ContactInput<Ellipsoid, Ellipsoid>{a, b, sa, sb, ts, ts, ts + 3.4, 1e-6});
  EXPECT_EQ(c.status, ContactStatus::none);
  c = contact_time(ContactInput<Ellipsoid, Ellipsoid>{a, b, sa, sb, ts, ts + 3.6, ts + 100, 1e-6});
  // starting inside the overlap while still approaching: contact at once
  ASSERT_EQ(c.status, ContactStatus::hit);
  EXPECT_EQ(c.time, ts + 3.6);
  EXPECT_TRUE(c.initial_overlap);
}

}  // namespace
}  // namespace hb
