// Contact time of approaching face-to-face superquadrics (p = 4, 8, 12, 16, 20, X0 = 0.5 and 2,
// all exponents p), where the distance solver meets flat faces at every step.
//
// Pure translation along the common face normal n: B is placed at the exact distance `gap`
// along n (testing::place_at_distance) and moves towards A with the closing speed v.  The
// separation along n, n.(r_B - r_A) - h_A(n) - h_B(-n), then decreases as gap - v t, and n stays
// its maximiser (its gradient, x_B(-n) - x_A(n), does not change under translation), so the
// contact is at exactly t = gap / v, for aligned and for tilted bodies.  Spinning both bodies
// about n through their centres leaves h_A(n) and h_B(-n) unchanged, so that time holds too.
// Small spins about random axes: the conservative-advancement reference
// (tests/contact/reference_contact_time.hpp, support-function distance) gives the time.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>

#include "contact/contact_time.hpp"
#include "contact/reference_contact_time.hpp"
#include "geometry/random_pairs.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

// Semi-axes (1.6, 0.8, 0.8) for X0 = 2 (a bar), (0.8, 1.6, 1.6) for X0 = 0.5 (a slab).
Superquadric body(double p, double X0) {
  return X0 > 1 ? Superquadric{1.6, 0.8, 0.8, p, p, p} : Superquadric{0.8, 1.6, 1.6, p, p, p};
}

struct Approach {
  Superquadric a, b;
  BodyState sa, sb;
  Vec3 n;      // A's face normal, the contact normal
  double gap;  // initial distance
  double v;    // closing speed along n
};

// A with a random pose and drift velocity; B's axes along A's (each turned by a random
// multiple of 90 deg), tilted by `tilt` rad about a random axis, `gap` away along the normal of
// a random face of A, moving towards it at speed v in [0.3, 2].
Approach make_approach(Rng& r, double p, double X0a, double X0b, double tilt, double gap) {
  Approach s{body(p, X0a), body(p, X0b), {}, {}, {}, gap, r.uni(0.3, 2.0)};
  const Pose pa{r.ball(1.0), r.rotation()};
  Mat3 Rb = pa.R;
  for (int i = 0; i < 3; ++i)
    Rb = Rb * Eigen::AngleAxisd(0.5 * kPi * static_cast<int>(r.uni(0, 4)), Vec3::Unit(i))
                  .toRotationMatrix();
  Rb = testing::small_rotation(r, tilt) * Rb;
  s.n = (r.uni(0, 1) < 0.5 ? -1.0 : 1.0) * pa.R.col(static_cast<int>(r.uni(0, 3)));
  const Pose pb = testing::place_at_distance(s.a, pa, s.b, Rb, s.n, gap);
  s.sa = BodyState{pa.r, Quat(pa.R), r.ball(0.5), Vec3::Zero()};
  s.sb = BodyState{pb.r, Quat(pb.R), s.sa.v - s.v * s.n, Vec3::Zero()};
  return s;
}

struct Counts {
  int n = 0, hits = 0, failed = 0, none = 0, distance_fallbacks = 0, contact_fallbacks = 0;
  long distance_evals = 0, distance_nr = 0;
  double max_rel = 0;
  void add(const ContactResult& c) {
    ++n;
    if (c.status == ContactStatus::hit) ++hits;
    if (c.status == ContactStatus::failed) ++failed;
    if (c.status == ContactStatus::none) ++none;
    distance_fallbacks += c.distance_fallbacks;
    contact_fallbacks += c.fallbacks;
    distance_evals += c.distance_evals;
    distance_nr += c.distance_nr_iterations;
  }
  void print(const char* name) const {
    std::printf("  %-12s pairs %4d hit %4d none %d failed %d  max |t - t_exact| / t %.1e  "
                "distance evals/pair %.1f (NR it./eval %.2f, fallbacks %d)  contact-NR "
                "fallbacks %d\n",
                name, n, hits, none, failed, max_rel, double(distance_evals) / std::max(n, 1),
                double(distance_nr) / std::max(distance_evals, 1L), distance_fallbacks,
                contact_fallbacks);
  }
};

// A fast path's solve c of one pair against its slow twin's c0: the same outcome, and hits at
// the same time to 1e-9 relative (the largest difference kept in fast.max_rel).  True if both
// hit.
bool twin_hits_agree(const ContactResult& c, const ContactResult& c0, Counts& fast,
                     const std::string& what) {
  EXPECT_NE(c.status, ContactStatus::failed) << what;
  EXPECT_EQ(c.status, c0.status) << what;
  if (c.status != ContactStatus::hit || c0.status != ContactStatus::hit) return false;
  const double rel = std::abs(c.time - c0.time) / std::max(c0.time, 1e-3);
  fast.max_rel = std::max(fast.max_rel, rel);
  EXPECT_LE(rel, 1e-9) << what;
  return true;
}

// Translation only (tilt 0, 1e-8, 1e-4, 1e-2 rad), and with spins about the normal (aligned
// bodies): a hit at gap / v to 1e-9 relative.
TEST(SuperquadricContact, FaceToFaceHitAtGapOverClosingSpeed) {
  Rng r(311);
  const double exponents[] = {4, 8, 12, 16, 20};
  const double tilts[] = {0.0, 1e-8, 1e-4, 1e-2};
  const int reps = scaled_count(12, 0.25, 4);
  Counts translation, spinning;
  for (double p : exponents)
    for (double tilt : tilts)
      for (int rep = 0; rep < reps; ++rep) {
        const double X0a = rep % 2 ? 2.0 : 0.5, X0b = (rep / 2) % 2 ? 2.0 : 0.5;
        Approach s = make_approach(r, p, X0a, X0b, tilt, r.log_uni(1e-3, 1.0));
        const bool spin = tilt == 0.0 && rep % 3 == 2;
        if (spin) {  // about n through each centre, up to |w| L = 2 v
          const double L = std::max(s.a.bounding_radius(), s.b.bounding_radius());
          s.sa.w = r.uni(-2.0, 2.0) * s.v / L * s.n;
          s.sb.w = r.uni(-2.0, 2.0) * s.v / L * s.n;
        }
        const double t_exact = s.gap / s.v;
        const ContactResult c = contact_time(ContactInput<Superquadric, Superquadric>{
            s.a, s.b, s.sa, s.sb, 0.0, 0.0, 2.0 * t_exact + 1.0, 1e-5});
        Counts& k = spin ? spinning : translation;
        k.add(c);
        const std::string what = "p " + std::to_string(p) + " tilt " + std::to_string(tilt) +
                                 " gap " + std::to_string(s.gap) + (spin ? " spinning" : "");
        EXPECT_NE(c.status, ContactStatus::failed) << what;
        ASSERT_EQ(c.status, ContactStatus::hit) << what;
        const double rel = std::abs(c.time - t_exact) / t_exact;
        k.max_rel = std::max(k.max_rel, rel);
        EXPECT_LE(rel, 1e-9) << what << " t " << c.time << " exact " << t_exact;
        EXPECT_GT(c.normal.dot(s.n), 1.0 - 1e-6) << what;
      }
  translation.print("translation");
  spinning.print("spin about n");
  EXPECT_EQ(translation.failed + spinning.failed, 0);
}

// Small spins about random axes (|w| L up to 0.1..1 of the closing speed): a hit, never
// failed, at the reference time (1e-9 relative, or 1e-9 absolute below t = 1).
TEST(SuperquadricContact, FaceToFaceWithSpinsVsReference) {
  Rng r(312);
  const double exponents[] = {4, 8, 12, 16, 20};
  const double tilts[] = {0.0, 1e-8, 1e-4, 1e-2};
  const int reps = scaled_count(4, 0.25, 1);
  Counts spins;
  for (double p : exponents)
    for (double tilt : tilts)
      for (int rep = 0; rep < reps; ++rep) {
        const double X0a = rep % 2 ? 2.0 : 0.5, X0b = (rep / 2) % 2 ? 2.0 : 0.5;
        Approach s = make_approach(r, p, X0a, X0b, tilt, r.log_uni(1e-3, 1.0));
        const double L = std::max(s.a.bounding_radius(), s.b.bounding_radius());
        s.sa.w = r.log_uni(1e-4, 1.0) * s.v / L * r.unit();
        s.sb.w = r.log_uni(1e-4, 1.0) * s.v / L * r.unit();
        const double t_max = 2.0 * s.gap / s.v + 1.0;
        const ContactResult c = contact_time(
            ContactInput<Superquadric, Superquadric>{s.a, s.b, s.sa, s.sb, 0.0, 0.0, t_max, 1e-5});
        const ref::RefContact rc = ref::reference_contact_time(s.a, s.sa, s.b, s.sb, t_max, 1e-6);
        spins.add(c);
        const std::string what = "p " + std::to_string(p) + " tilt " + std::to_string(tilt) +
                                 " gap " + std::to_string(s.gap);
        EXPECT_NE(c.status, ContactStatus::failed) << what;
        ASSERT_TRUE(rc.hit) << what;  // they approach head on: the spins cannot avoid contact
        ASSERT_EQ(c.status, ContactStatus::hit) << what << " reference t " << rc.time;
        const double tol = 1e-9 * std::max(1.0, rc.time);
        spins.max_rel = std::max(spins.max_rel, std::abs(c.time - rc.time) / rc.time);
        EXPECT_NEAR(c.time, rc.time, tol) << what;
        EXPECT_LE(c.time, rc.time + tol) << "later than the reference: " << what;
      }
  spins.print("random spins");
  EXPECT_EQ(spins.failed, 0);
}

// Affine axis steps (ContactOptions::affine_steps, the default for flat-faced rigid pairs)
// against their slow twin, first-order axis steps: random flights of superquadric pairs
// (exponents 4, 8 and (2, 2, 8), mixed with an ellipsoid; bars and slabs; random orientations,
// spins up to 3 v / L, spherical and asymmetric tops), aimed at A with an impact parameter up
// to the bodies' size (hits, misses and grazing passes), and pairs that start touching and
// separate (just after a collision). Both give the same outcome, and hits at the same time
// (1e-9 relative); the reference gives it too on a subset. Prints the axis work of both.
template <class SB>
void affine_twin(Rng& r, const Superquadric& a, const SB& b, int n, Counts& fast, Counts& slow,
                 long& fast_axis, long& slow_axis, int& refs, double& worst_ref) {
  const double L = std::max(a.bounding_radius(), b.bounding_radius());
  for (int k = 0; k < n; ++k) {
    const bool touching = k % 5 == 4, tops = k % 2 == 1;
    const Pose pa{r.ball(1.0), r.rotation()};
    const Vec3 u = r.unit();
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), u,
                                               touching ? 0.0 : r.log_uni(1e-4, 1.0) * L);
    const double v = r.uni(0.3, 2.0);
    BodyState sa{pa.r, Quat(pa.R), r.ball(0.5), r.ball(3.0 * v / L)};
    BodyState sb{pb.r, Quat(pb.R), sa.v, r.ball(3.0 * v / L)};
    const Vec3 aim = (pa.r + r.ball(1.0) * L - pb.r).normalized();
    sb.v += (touching ? -1.0 : 1.0) * v * aim;
    if (touching) sb.v += v * u;  // leaving contact, whatever the aim
    if (tops) {
      sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
      sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
    }
    const double t_max = 3.0 * L / v;
    const ContactInput<Superquadric, SB> in{a, b, sa, sb, 0.0, 0.0, t_max, 1e-5};
    ContactOptions first_order;
    first_order.affine_steps = false;
    const ContactResult c = contact_time(in), c0 = contact_time(in, first_order);
    fast.add(c), slow.add(c0);
    fast_axis += c.axis_steps + c.axis_bounds, slow_axis += c0.axis_steps;
    const std::string what = "pair " + std::to_string(k) + (touching ? " touching" : "") +
                             (tops ? " tops" : "") + " t " + std::to_string(c.time) + " vs " +
                             std::to_string(c0.time);
    if (!twin_hits_agree(c, c0, fast, what)) continue;
    if (k % 8 == 0 && !touching) {  // the reference (spherical tops: k even) on a subset
      const ref::RefContact rc = ref::reference_contact_time(a, sa, b, sb, t_max, 1e-6);
      ++refs;
      ASSERT_TRUE(rc.hit) << what;
      worst_ref = std::max(worst_ref, std::abs(c.time - rc.time) / std::max(rc.time, 1.0));
      EXPECT_NEAR(c.time, rc.time, 1e-9 * std::max(1.0, rc.time)) << what;
    }
  }
}

TEST(SuperquadricContact, AffineAxisStepsAgreeWithFirstOrderSteps) {
  Rng r(313);
  const int n = scaled_count(120, 0.1, 10);
  Counts fast, slow;
  long fast_axis = 0, slow_axis = 0;
  int refs = 0;
  double worst_ref = 0.0;
  for (double p : {4.0, 8.0}) {
    affine_twin(r, body(p, 2.0), body(p, 0.5), n, fast, slow, fast_axis, slow_axis, refs, worst_ref);
    affine_twin(r, body(p, 2.0), body(p, 2.0), n, fast, slow, fast_axis, slow_axis, refs, worst_ref);
  }
  const Superquadric cyl{0.8, 0.8, 1.6, 2, 2, 8};  // (2, 2, 8): round in x, y, flat along z
  affine_twin(r, cyl, cyl, n, fast, slow, fast_axis, slow_axis, refs, worst_ref);
  affine_twin(r, cyl, Ellipsoid{1.6, 0.8, 0.8}, n, fast, slow, fast_axis, slow_axis, refs, worst_ref);
  fast.print("affine");
  slow.print("first order");
  std::printf("  axis values + bounds per pair: affine %.1f, first order %.1f; reference on %d "
              "hits, max |t - t_ref| %.1e\n",
              double(fast_axis) / fast.n, double(slow_axis) / slow.n, refs, worst_ref);
  EXPECT_EQ(fast.failed + slow.failed, 0);
  EXPECT_GT(fast.hits, fast.n / 4);  // the flights do meet (and miss: none > 0)
  EXPECT_GT(fast.none, fast.n / 10);
  EXPECT_GT(refs, 5);
}

// Newton roots certified by their residuals and convexity (ContactOptions::certify_newton)
// against the slow twin, a distance solve at each root: face-to-face approaches with spins
// (exponents 4 to 20, tilts down to 0: flat faces meeting), and random flights of bars and slabs
// (p = 4, 8, spherical and asymmetric tops). The same outcome, and hits at the same time, point
// and normal bit for bit (the certificate only saves the distance solve of an acceptance).
// The root offered to the certificate before Newton converges (certify_early, the default)
// against the converged root: the same outcome, times within 2e-12 L / K of each other (each
// is within the converged Newton's time tolerance, 1e-12 L / K, of the root), points and
// normals to 1e-9, and fewer Newton iterations.
TEST(SuperquadricContact, CertifiedNewtonRootsAgreeWithTheDistanceSolve) {
  Rng r(318);
  ContactOptions converged, solve;
  converged.certify_early = false;
  solve.certify_newton = false;
  Counts fast, slow;
  int certified = 0;
  long nr_early = 0, nr_converged = 0;
  double worst_time = 0.0;
  auto twin = [&](const Superquadric& a, const Superquadric& b, const BodyState& sa,
                  const BodyState& sb, double t_max, const std::string& what) {
    const ContactInput<Superquadric, Superquadric> in{a, b, sa, sb, 0.0, 0.0, t_max, 1e-5};
    const ContactResult e = contact_time(in), c = contact_time(in, converged),
                        c0 = contact_time(in, solve);
    fast.add(c), slow.add(c0);
    certified += c.certified;
    nr_early += e.nr_iterations;
    nr_converged += c.nr_iterations;
    EXPECT_EQ(c0.certified, 0);
    ASSERT_EQ(c.status, c0.status) << what;
    ASSERT_EQ(e.status, c.status) << what;
    if (c.status != ContactStatus::hit) return;
    EXPECT_EQ(c.time, c0.time) << what;
    EXPECT_EQ(c.point, c0.point) << what;
    EXPECT_EQ(c.normal, c0.normal) << what;
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    const double dt = std::abs(e.time - c.time) / ref::time_unit(a, b, sa, sb);
    worst_time = std::max(worst_time, dt);
    EXPECT_LE(dt, 2e-12) << what;
    EXPECT_LE((e.point - c.point).norm(), 1e-9 * L) << what;
    EXPECT_LE((e.normal - c.normal).norm(), 1e-9) << what;
  };
  const int reps = scaled_count(4, 0.25, 1);
  for (double p : {4.0, 8.0, 12.0, 20.0})
    for (double tilt : {0.0, 1e-8, 1e-4, 1e-2})
      for (int rep = 0; rep < reps; ++rep) {
        Approach s = make_approach(r, p, rep % 2 ? 2.0 : 0.5, (rep / 2) % 2 ? 2.0 : 0.5, tilt,
                                   r.log_uni(1e-3, 1.0));
        const double L = std::max(s.a.bounding_radius(), s.b.bounding_radius());
        s.sa.w = r.log_uni(1e-4, 1.0) * s.v / L * r.unit();
        s.sb.w = r.log_uni(1e-4, 1.0) * s.v / L * r.unit();
        twin(s.a, s.b, s.sa, s.sb, 2.0 * s.gap / s.v + 1.0,
             "face p " + std::to_string(p) + " tilt " + std::to_string(tilt));
      }
  const int n = scaled_count(100, 0.1, 10);
  for (int k = 0; k < n; ++k) {
    const Superquadric a = body(k % 3 == 0 ? 4.0 : 8.0, 2.0), b = body(k % 3 == 0 ? 4.0 : 8.0, k % 2 ? 0.5 : 2.0);
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    const Pose pa{r.ball(1.0), r.rotation()};
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), r.unit(), r.log_uni(1e-4, 1.0) * L);
    const double v = r.uni(0.3, 2.0);
    BodyState sa{pa.r, Quat(pa.R), r.ball(0.5), r.ball(3.0 * v / L)};
    BodyState sb{pb.r, Quat(pb.R), sa.v, r.ball(3.0 * v / L)};
    sb.v += v * (pa.r + r.ball(1.0) * L - pb.r).normalized();
    if (k % 4 == 1) {
      sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
      sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
    }
    twin(a, b, sa, sb, 3.0 * L / v, "flight " + std::to_string(k));
  }
  fast.print("certified");
  slow.print("distance solve");
  std::printf("  %d roots certified; early certificate: Newton iterations %ld -> %ld, largest "
              "time difference %.2g L/K\n", certified, nr_converged, nr_early, worst_time);
  EXPECT_EQ(fast.failed + slow.failed, 0);
  EXPECT_GE(certified, fast.hits / 2);  // the usual path
  EXPECT_LT(fast.distance_evals, slow.distance_evals);
  EXPECT_LT(nr_early, nr_converged);
}

// The leaving jump (ContactOptions::leave_jump) against its slow twin, distance samples: flat-
// faced pairs that start touching, most of them separating as just after a collision (face to
// face with spins, and touching at random points), with a drift that brings some back into
// contact within the window.  Both give the same outcome, and hits at the same time
// (1e-9 relative); the jump saves distance solves (it is exercised).
TEST(SuperquadricContact, LeavingJumpAgreesWithDistanceSamples) {
  Rng r(317);
  const int n = scaled_count(400, 0.1, 40);
  Counts fast, slow;
  for (int k = 0; k < n; ++k) {
    const double p = k % 3 == 0 ? 4.0 : 8.0;
    const Superquadric a = body(p, k % 2 == 0 ? 0.5 : 2.0);
    const Superquadric b = k % 4 == 1 ? Superquadric{0.8, 0.8, 1.6, 2, 2, 8} : a;
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    const bool faces = k % 2 == 0;
    const Pose pa{r.ball(1.0), faces ? Mat3(Mat3::Identity()) : r.rotation()};
    const Vec3 u = faces ? Vec3(Vec3::UnitX()) : r.unit();
    const Mat3 Rb = faces ? Mat3(Mat3::Identity()) : r.rotation();
    const Pose pb = testing::place_at_distance(a, pa, b, Rb, u, 0.0);
    const double v = r.uni(0.3, 2.0);
    const double spin = (k % 5 == 0 ? 0.1 : 3.0) * v / L;
    BodyState sa{pa.r, Quat(pa.R), r.ball(0.5), r.ball(spin)};
    BodyState sb{pb.r, Quat(pb.R), sa.v, r.ball(spin)};
    sb.v += r.uni(0.05, 1.0) * v * u + r.ball(v);  // leaving, and drifting
    if (k % 7 == 3) {
      sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
      sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
    }
    const ContactInput<Superquadric, Superquadric> in{a, b, sa, sb, 0.0, 0.0, 3.0 * L / v, 1e-5};
    ContactOptions sampled;
    sampled.leave_jump = false;
    const ContactResult c = contact_time(in), c0 = contact_time(in, sampled);
    fast.add(c), slow.add(c0);
    const std::string what = "pair " + std::to_string(k) + (faces ? " faces" : "") + " t " +
                             std::to_string(c.time) + " vs " + std::to_string(c0.time);
    twin_hits_agree(c, c0, fast, what);
  }
  fast.print("jump");
  slow.print("samples");
  EXPECT_EQ(fast.failed + slow.failed, 0);
  EXPECT_GT(fast.hits, 0);  // some come back into contact
  EXPECT_GT(fast.none, fast.n / 4);
  EXPECT_LT(fast.distance_evals, slow.distance_evals);  // the jump is taken
}

}  // namespace
}  // namespace hb
