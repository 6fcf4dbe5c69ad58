// Contact time of bodies that are not spherical tops (BodyState::top: symmetric and asymmetric
// Euler tops, w(t) changing along the flight), and of unlike shape pairs, against the
// independent conservative-advancement reference (tests/contact/reference_contact_time.hpp,
// support-function distance, exact free rotation through motion/motion.hpp).
//
// Scenarios, as in test_contact_time.cpp: approaching pairs (slow spins |w| < 2/L), fast
// spinners (|w| < 40/L), rotating grazing passes (closest approach 1e-8..1e-4 above contact,
// d'(t*) = 0 at t* = 1) and just-touching pairs (overlap 1e-8..1e-4 at t* = 1, d'(t*) = 0), the
// last two with slow (|w| < 0.3/L) and fast (|w| < 40/L) spins.  The grazing and touching pairs
// are built at t* with the angular velocities AT t* (the rate is zeroed with them) and moved
// back to t = 0 with advance(state, -1), which for tops also changes w.  L is the larger
// bounding radius.
// Tops: symmetric (two equal moments, the symmetry axis on a random body axis, ratio
// I_s / I_t in [0.2, 5]), asymmetric (three different moments, ratios in [0.2, 5]) and mixed
// pairs (a spherical top against an asymmetric top); asymmetric tops spinning close to their
// intermediate axis (near the separatrix); unlike shape pairs (Sphere-Ellipsoid,
// Ellipsoid-Superquadric with exponents 2 or 4..8, Sphere-Superquadric) with every kind of top.
// Plus contact_time(A, B) == contact_time(B, A) for tops (time to 1e-10 relative).
// Checks per pair: never `failed`, no miss (reference hit => solver hit), no false hit, no late
// contact and |t - t_ref| <= 1e-9 max(1, t) (the tolerance of test_contact_time.cpp), the
// contact point on both surfaces, the normal A's outward normal.  On a failure the pair is
// printed with %.17g (shapes and BodyStates at t = 0, window [0, t_max], eps_d).
// Sample counts: ~40 s in a Release build on 2 cores; HB_TEST_SCALE=k runs k times as many pairs
// (testing::scaled_count; the Debug+sanitizer build runs 1% of them, at least one per case).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>

#include "contact/contact_time.hpp"
#include "contact/reference_contact_time.hpp"
#include "geometry/random_pairs.hpp"
#include "motion/motion.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

// ---------------------------------------------------------------------------------------------
// Random shapes and tops

Sphere random_sphere(Rng& r) { return Sphere{r.uni(0.3, 2.0)}; }
Ellipsoid random_ellipsoid(Rng& r) { return r.ellipsoid(10.0); }
// Semi-axes of a random ellipsoid (aspect up to 5); exponents all 2, all equal in [4, 8], or
// each 2 or in [4, 8].
Superquadric random_superquadric(Rng& r) {
  const Ellipsoid e = r.ellipsoid(5.0);
  const int mode = static_cast<int>(r.uni(0, 3));
  Vec3 p = Vec3::Constant(2.0);
  if (mode == 1) p = Vec3::Constant(r.uni(4.0, 8.0));
  if (mode == 2)
    for (int i = 0; i < 3; ++i) p[i] = r.uni(0, 1) < 0.5 ? 2.0 : r.uni(4.0, 8.0);
  return Superquadric{e.a, e.b, e.c, p[0], p[1], p[2]};
}

enum class Top { spherical, symmetric, asymmetric, any };

// Principal moments (only ratios matter; an overall scale is drawn too).
Vec3 random_top(Rng& r, Top kind) {
  if (kind == Top::any) kind = static_cast<Top>(static_cast<int>(r.uni(0, 3)));
  const double scale = r.log_uni(0.1, 10.0);
  switch (kind) {
    case Top::spherical:
      return r.uni(0, 1) < 0.5 ? Vec3::Zero() : Vec3::Constant(scale);
    case Top::symmetric: {
      Vec3 I = Vec3::Constant(scale);
      I[static_cast<int>(r.uni(0, 3))] = scale * r.log_uni(0.2, 5.0);
      return I;
    }
    default: {
      Vec3 I(1.0, r.log_uni(0.2, 5.0), r.log_uni(0.2, 5.0));
      for (int i = 2; i > 0; --i) std::swap(I[i], I[static_cast<int>(r.uni(0, i + 1))]);
      return scale * I;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Reproducers

std::string describe(const Sphere& s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "Sphere{%.17g}", s.radius);
  return buf;
}
std::string describe(const Ellipsoid& e) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "Ellipsoid{%.17g, %.17g, %.17g}", e.a, e.b, e.c);
  return buf;
}
std::string describe(const Superquadric& e) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "Superquadric{%.17g, %.17g, %.17g, %.17g, %.17g, %.17g}", e.a,
                e.b, e.c, e.n, e.m, e.p);
  return buf;
}
std::string describe(const BodyState& b) {
  char buf[1024];
  std::snprintf(buf, sizeof buf,
                "BodyState{r (%.17g, %.17g, %.17g), q (w x y z) (%.17g, %.17g, %.17g, %.17g), "
                "v (%.17g, %.17g, %.17g), w (%.17g, %.17g, %.17g), top (%.17g, %.17g, %.17g)}",
                b.r.x(), b.r.y(), b.r.z(), b.q.w(), b.q.x(), b.q.y(), b.q.z(), b.v.x(), b.v.y(),
                b.v.z(), b.w.x(), b.w.y(), b.w.z(), b.top.x(), b.top.y(), b.top.z());
  return buf;
}

// ---------------------------------------------------------------------------------------------
// Scenarios

template <class SA, class SB>
struct Scn {
  SA a;
  SB b;
  BodyState sa, sb;  // at t = 0
  double t_max = 0.0;

  std::string repro(double eps_d) const {
    char buf[128];
    std::snprintf(buf, sizeof buf, "\n  window [0, %.17g] eps_d %.17g", t_max, eps_d);
    return "\n  A " + describe(a) + " " + describe(sa) + "\n  B " + describe(b) + " " +
           describe(sb) + buf;
  }
};

// kind 0: approaching; 1: fast spinners (approaching); 3: rotating grazing pass (closest
// approach 1e-8..1e-4 at t* = 1 when the spins are slow); 4: just touching (overlap 1e-8..1e-4
// at t* = 1).  fast: |w| up to 40/L (kinds 3, 4; kind 1 always fast, kind 0 always slow).
// near_separatrix: asymmetric tops spin about their intermediate axis, perturbed by a relative
// 1e-6..1e-1 (close to the separatrix: elliptic parameter m near 1, w(t) far from periodic-looking).
struct Spec {
  int kind = 0;
  bool fast = false;
  Top top_a = Top::any, top_b = Top::any;
  bool near_separatrix = false;
};

// Angular velocity (lab) of magnitude up to wm; near the intermediate body axis if asked (and
// the top is asymmetric).
Vec3 random_spin(Rng& r, double wm, const Vec3& I, const Quat& q, bool near_separatrix) {
  if (!near_separatrix || spherical_top(I) || I[0] == I[1] || I[1] == I[2] || I[0] == I[2])
    return r.ball(wm);
  int lo = 0, hi = 0;
  for (int i = 1; i < 3; ++i) {
    if (I[i] < I[lo]) lo = i;
    if (I[i] > I[hi]) hi = i;
  }
  const int mid = 3 - lo - hi;
  const Vec3 W = (Vec3::Unit(mid) + r.log_uni(1e-6, 1e-1) * r.unit()).normalized();
  return r.uni(0.2, 1.0) * wm * (q * W);
}

template <class SA, class SB, class GA, class GB>
Scn<SA, SB> make_once(Rng& r, const Spec& sp, GA gen_a, GB gen_b) {
  Scn<SA, SB> s{gen_a(r), gen_b(r), {}, {}, 0.0};
  const double L = std::max(s.a.bounding_radius(), s.b.bounding_radius());
  const Pose pa{r.ball(2.0), r.rotation()};
  const Vec3 n = r.unit();
  const Vec3 Ia = random_top(r, sp.top_a), Ib = random_top(r, sp.top_b);
  if (sp.kind <= 1) {
    const double gap = r.log_uni(1e-3, 4.0 * L);
    const Pose pb = testing::place_at_distance(s.a, pa, s.b, r.rotation(), n, gap);
    const double speed = r.uni(0.3, 2.0);
    const double wm = sp.kind == 0 ? 2.0 / L : 40.0 / L;
    s.sa = BodyState{pa.r, Quat(pa.R), r.ball(0.5), Vec3::Zero(), Ia};
    s.sa.w = random_spin(r, wm, Ia, s.sa.q, sp.near_separatrix);
    s.sb = BodyState{pb.r, Quat(pb.R), Vec3::Zero(), Vec3::Zero(), Ib};
    s.sb.w = random_spin(r, wm, Ib, s.sb.q, sp.near_separatrix);
    s.sb.v = s.sa.v - speed * (n + 0.8 * r.ball(1.0)).normalized();
    s.t_max = r.uni(0.5, 3.0) * (gap + 2 * L) / speed;
    return s;
  }
  const double gap = (sp.kind == 3 ? 1.0 : -1.0) * r.log_uni(1e-8, 1e-4);
  const Pose pb = testing::place_at_distance(s.a, pa, s.b, r.rotation(), n, gap);
  // the states at t* = 1
  BodyState A{pa.r, Quat(pa.R), r.ball(0.5), Vec3::Zero(), Ia};
  BodyState B{pb.r, Quat(pb.R), Vec3::Zero(), Vec3::Zero(), Ib};
  Vec3 vrel = r.unit();
  vrel = (vrel - n * n.dot(vrel)).normalized() * r.uni(0.3, 2.0);
  B.v = A.v + vrel;
  const double wm = sp.fast ? 40.0 / L : 0.3 / L;
  A.w = random_spin(r, wm, Ia, A.q, sp.near_separatrix);  // the angular velocities at t*
  B.w = random_spin(r, wm, Ib, B.q, sp.near_separatrix);
  // d'(t*) = 0: the closest points are x_A = support point of A along n and x_B = x_A + gap n
  const Vec3 xa = pa.r + pa.R * s.a.support_point(pa.R.transpose() * n);
  const Vec3 xb = xa + gap * n;
  const double rate = n.dot((B.v + B.w.cross(xb - B.r)) - (A.v + A.w.cross(xa - A.r)));
  B.v -= rate * n;
  // back to t = 0 (for tops this also changes w)
  s.sa = A;
  s.sb = B;
  advance(s.sa, -1.0);
  advance(s.sb, -1.0);
  s.t_max = 2.0;
  return s;
}

// Scenarios whose bodies are clearly apart at t = 0 (distance > 1e-3, by the reference).
template <class SA, class SB, class GA, class GB>
Scn<SA, SB> make_scenario(Rng& r, const Spec& sp, GA gen_a, GB gen_b) {
  for (;;) {
    const Scn<SA, SB> s = make_once<SA, SB>(r, sp, gen_a, gen_b);
    const Pose pa{s.sa.r, s.sa.q.toRotationMatrix()}, pb{s.sb.r, s.sb.q.toRotationMatrix()};
    if (ref::reference_distance(s.a, pa, s.b, pb).distance > 1e-3) return s;
  }
}

// ---------------------------------------------------------------------------------------------
// Comparison with the reference

struct TStats {
  int n = 0, hits = 0, ref_hits = 0, failed = 0, fallbacks = 0, grazing = 0, missed = 0,
      false_hits = 0, late = 0;
  long dist_evals = 0, ref_evals = 0, nr = 0, axis_steps = 0;
  double max_err = 0, max_late = -kInf, max_f = 0, max_wratio = 1.0, seconds = 0;
  void print(const char* name) const {
    std::printf("  %-16s pairs %4d hits %4d (ref %4d) missed %d false %d late %d failed %d "
                "fallbacks %d grazing searches %d\n"
                "  %-16s max |t - t_ref| %.2e  max (t - t_ref) %.2e  max |f| %.1e  distance "
                "evals/pair %.1f (ref %.0f)  axis steps/pair %.1f  contact NR it/pair %.2f  "
                "max wmax/|w0| %.2f  %.1f s\n",
                name, n, hits, ref_hits, missed, false_hits, late, failed, fallbacks, grazing, "",
                max_err, max_late, max_f, double(dist_evals) / std::max(n, 1),
                double(ref_evals) / std::max(n, 1), double(axis_steps) / std::max(n, 1),
                double(nr) / std::max(n, 1), max_wratio, seconds);
  }
};

template <class SA, class SB>
void compare(const Scn<SA, SB>& s, const std::string& what, TStats& st, double eps_d) {
  const ContactResult c = contact_time(
      ContactInput<SA, SB>{s.a, s.b, s.sa, s.sb, 0.0, 0.0, s.t_max, eps_d});
  const ref::RefContact rc = ref::reference_contact_time(s.a, s.sa, s.b, s.sb, s.t_max, 1e-6);
  ++st.n;
  st.dist_evals += c.distance_evals;
  st.ref_evals += rc.evals;
  st.nr += c.nr_iterations;
  st.fallbacks += c.fallbacks;
  st.grazing += c.grazing_searches;
  st.axis_steps += c.axis_steps;
  for (const BodyState* b : {&s.sa, &s.sb})
    if (b->w.norm() > 0.0)
      st.max_wratio = std::max(st.max_wratio, Motion(*b).max_angular_speed() / b->w.norm());
  if (c.status == ContactStatus::failed) ++st.failed;
  if (c.status == ContactStatus::hit) ++st.hits;
  if (rc.hit) ++st.ref_hits;
  EXPECT_NE(c.status, ContactStatus::failed) << what << s.repro(eps_d);
  if (rc.hit) {
    if (c.status != ContactStatus::hit) {
      ++st.missed;
      ADD_FAILURE() << "missed: " << what << " t_ref " << rc.time << " ref min d "
                    << rc.min_distance << " solver min d " << c.min_distance << s.repro(eps_d);
      return;
    }
    const double tol = 1e-9 * std::max(1.0, rc.time);
    st.max_err = std::max(st.max_err, std::abs(c.time - rc.time));
    st.max_late = std::max(st.max_late, c.time - rc.time);
    if (c.time > rc.time + tol) ++st.late;
    EXPECT_NEAR(c.time, rc.time, tol) << what << s.repro(eps_d);
    EXPECT_LE(c.time, rc.time + tol) << "later than the reference: " << what << s.repro(eps_d);
    // the contact point lies on both surfaces, the normal is A's outward normal
    const Pose pa{s.sa.r + s.sa.v * c.time, rotation_at(s.sa, c.time)};
    const Pose pb{s.sb.r + s.sb.v * c.time, rotation_at(s.sb, c.time)};
    const Posed<SA> A{&s.a, pa};
    const Posed<SB> B{&s.b, pb};
    const double fa = std::abs(A.f(c.point)), fb = std::abs(B.f(c.point));
    st.max_f = std::max({st.max_f, fa, fb});
    EXPECT_LE(fa, 1e-6) << what << s.repro(eps_d);
    EXPECT_LE(fb, 1e-6) << what << s.repro(eps_d);
    EXPECT_GT(c.normal.dot(A.grad(c.point).normalized()), 1 - 1e-6) << what << s.repro(eps_d);
  } else if (c.status == ContactStatus::hit) {
    ++st.false_hits;
    ADD_FAILURE() << "false hit: " << what << " t " << c.time << " ref min d "
                  << rc.min_distance << " solver min d " << c.min_distance << s.repro(eps_d);
  }
}

const char* top_name(Top t) {
  switch (t) {
    case Top::spherical: return "spherical";
    case Top::symmetric: return "symmetric";
    case Top::asymmetric: return "asymmetric";
    default: return "any";
  }
}

template <class SA, class SB, class GA, class GB>
TStats run_case(const Spec& sp, int count, uint64_t seed, GA gen_a, GB gen_b,
                double eps_d = 1e-5) {
  const auto t0 = std::chrono::steady_clock::now();
  Rng r(seed);
  TStats st;
  for (int k = 0; k < count; ++k) {
    const Scn<SA, SB> s = make_scenario<SA, SB>(r, sp, gen_a, gen_b);
    const std::string what = "kind " + std::to_string(sp.kind) + (sp.fast ? " fast" : " slow") +
                             " tops " + top_name(sp.top_a) + "/" + top_name(sp.top_b) +
                             " seed " + std::to_string(seed) + " k " + std::to_string(k);
    compare(s, what, st, eps_d);
  }
  st.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return st;
}

// Ellipsoid pairs with the given tops: approaching (slow), fast spinners, rotating grazing
// passes (slow, fast), just touching (slow, fast).
const auto kEll = [](Rng& r) { return random_ellipsoid(r); };
const auto kSph = [](Rng& r) { return random_sphere(r); };
const auto kSq = [](Rng& r) { return random_superquadric(r); };

void approaching_tops(Top ta, Top tb, uint64_t seed, const char* label) {
  const std::string l(label);
  TStats s0 = run_case<Ellipsoid, Ellipsoid>({0, false, ta, tb}, scaled_count(600, 0.01, 4),
                                             seed, kEll, kEll);
  s0.print((l + " approach").c_str());
  TStats s1 = run_case<Ellipsoid, Ellipsoid>({1, true, ta, tb}, scaled_count(300, 0.01, 3),
                                             seed + 1, kEll, kEll);
  s1.print((l + " spinners").c_str());
}
void grazing_tops(Top ta, Top tb, uint64_t seed, const char* label) {
  const std::string l(label);
  TStats s0 = run_case<Ellipsoid, Ellipsoid>({3, false, ta, tb}, scaled_count(60, 0.01, 1),
                                             seed, kEll, kEll);
  s0.print((l + " graze").c_str());
  TStats s1 = run_case<Ellipsoid, Ellipsoid>({3, true, ta, tb}, scaled_count(50, 0.01, 1),
                                             seed + 1, kEll, kEll);
  s1.print((l + " graze,fast").c_str());
}
void touching_tops(Top ta, Top tb, uint64_t seed, const char* label) {
  const std::string l(label);
  TStats s0 = run_case<Ellipsoid, Ellipsoid>({4, false, ta, tb}, scaled_count(60, 0.01, 1),
                                             seed, kEll, kEll);
  s0.print((l + " touch").c_str());
  EXPECT_EQ(s0.hits, s0.n);  // every one overlaps at t* = 1
  TStats s1 = run_case<Ellipsoid, Ellipsoid>({4, true, ta, tb}, scaled_count(50, 0.01, 1),
                                             seed + 1, kEll, kEll);
  s1.print((l + " touch,fast").c_str());
  EXPECT_EQ(s1.hits, s1.n);
}

TEST(ContactTops, SymmetricApproachingVsReference) {
  approaching_tops(Top::symmetric, Top::symmetric, 501, "sym");
}
TEST(ContactTops, SymmetricGrazingVsReference) {
  grazing_tops(Top::symmetric, Top::symmetric, 503, "sym");
}
TEST(ContactTops, SymmetricTouchingVsReference) {
  touching_tops(Top::symmetric, Top::symmetric, 505, "sym");
}
TEST(ContactTops, AsymmetricApproachingVsReference) {
  approaching_tops(Top::asymmetric, Top::asymmetric, 511, "asym");
}
TEST(ContactTops, AsymmetricGrazingVsReference) {
  grazing_tops(Top::asymmetric, Top::asymmetric, 513, "asym");
}
TEST(ContactTops, AsymmetricTouchingVsReference) {
  touching_tops(Top::asymmetric, Top::asymmetric, 515, "asym");
}
TEST(ContactTops, SphericalVsAsymmetricApproachingVsReference) {
  approaching_tops(Top::spherical, Top::asymmetric, 521, "sph/asym");
}
TEST(ContactTops, SphericalVsAsymmetricGrazingVsReference) {
  grazing_tops(Top::asymmetric, Top::spherical, 523, "asym/sph");
}
TEST(ContactTops, SphericalVsAsymmetricTouchingVsReference) {
  touching_tops(Top::spherical, Top::asymmetric, 525, "sph/asym");
}
// With a coarse eps_d the steps jump over the short overlap window of the shallow touches: the
// grazing search (Brent on d(t)) must find the negative minimum, with w(t) varying.
TEST(ContactTops, TouchingCoarseEpsVsReference) {
  TStats st = run_case<Ellipsoid, Ellipsoid>({4, false, Top::any, Top::any},
                                             scaled_count(80, 0.01, 1), 531, kEll, kEll, 1e-2);
  st.print("any touch,eps");
  EXPECT_EQ(st.hits, st.n);
  TStats sg = run_case<Ellipsoid, Ellipsoid>({3, false, Top::any, Top::any},
                                             scaled_count(50, 0.01, 1), 532, kEll, kEll, 1e-2);
  sg.print("any graze,eps");
}

// Asymmetric tops spinning close to their intermediate axis (near the separatrix): approaching,
// fast spinners, just touching (slow and fast).
TEST(ContactTops, NearSeparatrixVsReference) {
  const Top as = Top::asymmetric;
  TStats s0 = run_case<Ellipsoid, Ellipsoid>({0, false, as, as, true}, scaled_count(200, 0.01, 2),
                                             581, kEll, kEll);
  s0.print("sep approach");
  TStats s1 = run_case<Ellipsoid, Ellipsoid>({1, true, as, as, true}, scaled_count(150, 0.01, 2),
                                             582, kEll, kEll);
  s1.print("sep spinners");
  TStats s4 = run_case<Ellipsoid, Ellipsoid>({4, false, as, as, true}, scaled_count(40, 0.01, 1),
                                             583, kEll, kEll);
  s4.print("sep touch");
  EXPECT_EQ(s4.hits, s4.n);
  TStats s4f = run_case<Ellipsoid, Ellipsoid>({4, true, as, as, true}, scaled_count(40, 0.01, 1),
                                              584, kEll, kEll);
  s4f.print("sep touch,fast");
  EXPECT_EQ(s4f.hits, s4f.n);
}

// Unlike shape pairs, every kind of top on either body.
template <class SA, class SB, class GA, class GB>
void unlike_pairs(GA gen_a, GB gen_b, uint64_t seed, const char* label) {
  const std::string l(label);
  auto count = [](int n, double frac) { return scaled_count(n, frac, 1); };
  TStats s0 = run_case<SA, SB>({0, false, Top::any, Top::any}, count(300, 0.01), seed, gen_a, gen_b);
  s0.print((l + " approach").c_str());
  TStats s1 = run_case<SA, SB>({1, true, Top::any, Top::any}, count(150, 0.01), seed + 1, gen_a, gen_b);
  s1.print((l + " spinners").c_str());
  TStats s3 = run_case<SA, SB>({3, false, Top::any, Top::any}, count(40, 0.01), seed + 2, gen_a, gen_b);
  s3.print((l + " graze").c_str());
  TStats s3f = run_case<SA, SB>({3, true, Top::any, Top::any}, count(30, 0.01), seed + 3, gen_a, gen_b);
  s3f.print((l + " graze,fast").c_str());
  TStats s4 = run_case<SA, SB>({4, false, Top::any, Top::any}, count(40, 0.01), seed + 4, gen_a, gen_b);
  s4.print((l + " touch").c_str());
  EXPECT_EQ(s4.hits, s4.n);
  TStats s4f = run_case<SA, SB>({4, true, Top::any, Top::any}, count(30, 0.01), seed + 5, gen_a, gen_b);
  s4f.print((l + " touch,fast").c_str());
  EXPECT_EQ(s4f.hits, s4f.n);
}

TEST(ContactUnlikeTops, SphereEllipsoidVsReference) {
  unlike_pairs<Sphere, Ellipsoid>(kSph, kEll, 541, "sph-ell");
}
TEST(ContactUnlikeTops, EllipsoidSuperquadricVsReference) {
  unlike_pairs<Ellipsoid, Superquadric>(kEll, kSq, 551, "ell-sq");
}
TEST(ContactUnlikeTops, SphereSuperquadricVsReference) {
  unlike_pairs<Sphere, Superquadric>(kSph, kSq, 561, "sph-sq");
}

// contact_time(A, B) == contact_time(B, A) for tops: same status, time to 1e-10 relative, same
// point, opposite normal.
template <class SA, class SB>
void check_swap(const Scn<SA, SB>& s, const std::string& what, double& worst) {
  const ContactResult ab =
      contact_time(ContactInput<SA, SB>{s.a, s.b, s.sa, s.sb, 0.0, 0.0, s.t_max, 1e-5});
  const ContactResult ba =
      contact_time(ContactInput<SB, SA>{s.b, s.a, s.sb, s.sa, 0.0, 0.0, s.t_max, 1e-5});
  ASSERT_EQ(ab.status, ba.status) << what << s.repro(1e-5);
  if (ab.status != ContactStatus::hit) return;
  worst = std::max(worst, std::abs(ab.time - ba.time) / std::max(1.0, ab.time));
  EXPECT_NEAR(ab.time, ba.time, 1e-10 * std::max(1.0, ab.time)) << what << s.repro(1e-5);
  EXPECT_LE((ab.point - ba.point).norm(), 1e-6) << what << s.repro(1e-5);
  EXPECT_LE((ab.normal + ba.normal).norm(), 1e-6) << what << s.repro(1e-5);
}

TEST(ContactTops, SymmetricInAandB) {
  Rng r(571);
  const Top kinds[3][2] = {{Top::symmetric, Top::symmetric},
                           {Top::asymmetric, Top::asymmetric},
                           {Top::spherical, Top::asymmetric}};
  double worst = 0.0;
  int pairs = 0;
  const int count = scaled_count(600, 0.01, 6);
  for (int k = 0; k < count; ++k) {
    const Spec sp{k % 2, k % 2 == 1, kinds[(k / 2) % 3][0], kinds[(k / 2) % 3][1]};
    const std::string what = "k " + std::to_string(k);
    if (k % 4 < 2)
      check_swap(make_scenario<Ellipsoid, Ellipsoid>(r, sp, kEll, kEll), what, worst);
    else if (k % 4 == 2)
      check_swap(make_scenario<Ellipsoid, Superquadric>(r, sp, kEll, kSq), what, worst);
    else
      check_swap(make_scenario<Sphere, Ellipsoid>(r, sp, kSph, kEll), what, worst);
    if (::testing::Test::HasFatalFailure()) return;
    ++pairs;
  }
  std::printf("  swap A<->B: pairs %d  max |t_AB - t_BA| / max(1, t) %.2e\n", pairs, worst);
}

}  // namespace
}  // namespace hb
