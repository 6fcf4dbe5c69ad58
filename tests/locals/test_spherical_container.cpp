// The hard spherical container (locals/spherical_container.hpp): the contact time of every shape
// against a slow, obviously right conservative advancement on random bodies (fast-spinning,
// grazing, asymmetric tops, growing), and the impulse against the rigid-body rules. The truth's
// distance is the container's own R - F (the farthest point, checked against dense sampling in
// tests/geometry/test_farthest_point.cpp), always evaluated in full; what is tested here is the
// search: its steps, the cheap bound far from the wall, the grazing search and the margins.
// 1000 bodies per shape here (the truth is slow: 1-60 ms per body); scripts/validate.sh walls runs
// 10,000 per shape.
#include <gtest/gtest.h>

#include <cstdio>
#include <type_traits>

#include "contact_tally.hpp"
#include "collision/rigid.hpp"
#include "locals/spherical_container.hpp"
#include "motion/motion.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

namespace hb {
namespace {

using testing::ContactTally;
using testing::Kind;
using testing::Rng;
using testing::random_ellipsoid;
using testing::random_sphere;
using testing::random_superquadric;
using testing::scaled_count;

template <class S>
double gap_at(const SphericalContainer& c, const S& shape, const BodyState& b, const Motion& m,
              double s0, double rate, double t, const Box& box) {
  BodyState x = b;
  x.r = b.r + b.v * t;
  x.q = m.orientation(t);
  return c.distance(shape, x, s0 + rate * t, box);
}

// First t in [0, T] at which R - F falls to `margin`: plain conservative advancement with a step
// floor ~1e4 times finer than the solver's grazing step and no grazing search, then bisection.
// T + 1 when there is none; -1 when the step cap is hit (inconclusive).
template <class S>
double truth(const SphericalContainer& c, const S& shape, const BodyState& b, double s0, double rate,
             const Box& box, double margin, double T) {
  const Motion m(b);
  const double L = shape.bounding_radius(), tiny = 1e-9 * L;
  const double smax = s0 + std::max(rate, 0.0) * T;
  const double spin = std::is_same_v<S, Sphere> ? 0.0 : m.max_angular_speed();
  const double K = b.v.norm() + spin * L * smax + std::abs(rate) * L;
  auto gap = [&](double t) { return gap_at(c, shape, b, m, s0, rate, t, box) - margin; };
  double t = 0.0;
  if (gap(t) <= 0.0) return 0.0;
  long steps = 0;
  while (t < T) {
    if (++steps > 1'000'000) return -1.0;
    const double t1 = std::min(T, t + std::max(gap(t), tiny) / K);
    if (gap(t1) <= 0.0) {
      double lo = t, hi = t1;
      for (int it = 0; it < 200 && hi - lo > 4e-16 * std::max(1.0, hi); ++it) {
        const double mid = 0.5 * (lo + hi);
        (gap(mid) <= 0.0 ? hi : lo) = mid;
      }
      return lo;
    }
    t = t1;
  }
  return T + 1.0;
}


template <class S, class MakeShape>
ContactTally check_shape(const char* name, MakeShape make, std::uint64_t seed) {
  Rng rng(seed);
  ContactTally tally;
  const double eps = 1e-5, R = 8.0;
  const SphericalContainer container(R, eps);
  Box box;
  box.L = Vec3::Constant(2.0 * R);
  box.periodic = {false, false, false};
  const Vec3 centre = box.centre();
  const int n = scaled_count(1000);  // HB_TEST_SCALE=10: the 10,000 of scripts/validate.sh walls
  for (int c = 0; c < n; ++c) {
    const S shape = make(rng);
    const Kind kind = Kind(c % 5);
    const double margin = std::is_same_v<S, Sphere> ? 0.0 : container.margin();
    const double L = shape.bounding_radius();
    BodyState b;
    b.q = rng.quat();
    b.v = Vec3(rng.normal(), rng.normal(), rng.normal());
    b.w = 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
    double s0 = 1.0, rate = 0.0, T = 6.0;
    if (kind == Kind::spinning) b.w = rng.log_uni(10.0, 200.0) * rng.unit();
    if (kind == Kind::top) b.top = Vec3(rng.uni(0.2, 1.0), rng.uni(0.2, 1.0), rng.uni(0.2, 1.0)), b.w *= 3.0;
    if (kind == Kind::growing) s0 = rng.uni(0.6, 1.0), rate = rng.uni(0.0, 0.2), T = 2.0;
    const Vec3 dir = rng.unit();
    if (kind == Kind::grazing) {
      // on a ray from the centre, at R - F = margin + delta (bisection on the distance along it:
      // F grows along the ray beyond the body's own extent), moving almost along the wall
      const double want = margin + rng.log_uni(1e-9, 1e-2) * L;
      double lo = 0.0, hi = R;
      for (int it = 0; it < 200; ++it) {
        const double mid = 0.5 * (lo + hi);
        b.r = centre + mid * dir;
        (container.distance(shape, b, s0, box) > want ? lo : hi) = mid;
      }
      b.r = centre + lo * dir;
      Vec3 t = rng.unit();
      t = (t - dir * dir.dot(t)).normalized();
      b.v = rng.uni(0.2, 2.0) * t +
            (rng.uni(0, 1) < 0.5 ? -1.0 : 1.0) * rng.log_uni(1e-7, 1e-2) * dir;
      b.w *= rng.log_uni(1e-4, 1.0);
    } else {
      b.r = centre + rng.uni(0.0, R - 1.01 * L * s0) * dir;
    }
    if (!(container.distance(shape, b, s0, box) - margin > 0.0)) continue;
    const WallContact ours = container.contact(shape, b, BodyGrowth{s0, rate}, box, 0.0, T);
    const double tt = truth(container, shape, b, s0, rate, box, margin, T);
    ++tally.cases;
    if (tt < 0.0) {
      ++tally.inconclusive;
      continue;
    }
    const bool exists = tt <= T;
    if (ours.face >= 0) {
      ++tally.hits;
      EXPECT_EQ(ours.face, SphericalContainer::kWall);
      const Motion m(b);
      const double d = gap_at(container, shape, b, m, s0, rate, ours.time, box);
      if (d < -1e-12 * L) ++tally.through;
      if (d - margin > 1e-9 * L) ++tally.early;
      double deepest = kInf;
      if (exists && ours.time > tt)
        for (int q = 0; q <= 256; ++q)
          deepest = std::min(deepest, gap_at(container, shape, b, m, s0, rate, tt + (ours.time - tt) * q / 256.0, box) - margin);
      if (exists && ours.time > tt + 1e-12 * std::max(1.0, tt) && deepest < -1e-10 * L) {
        if (tally.late < 3)
          std::printf("  late: %s case %d kind %d ours %.17g truth %.17g\n", name, c, int(kind), ours.time, tt);
        ++tally.late;
        tally.worst_late = std::max(tally.worst_late, ours.time - tt);
      }
    } else if (exists) {
      ++tally.missed;
      if (tally.missed <= 3) std::printf("  missed: %s case %d kind %d truth %.17g\n", name, c, int(kind), tt);
    }
  }
  tally.print(name);
  return tally;
}

TEST(SphericalContainer, SphereContactTimeAgainstConservativeAdvancement) {
  check_shape<Sphere>("sphere", random_sphere, 1).expect_clean();
}
TEST(SphericalContainer, EllipsoidContactTimeAgainstConservativeAdvancement) {
  check_shape<Ellipsoid>("ellipsoid", random_ellipsoid, 2).expect_clean();
}
TEST(SphericalContainer, SuperquadricContactTimeAgainstConservativeAdvancement) {
  check_shape<Superquadric>("superquadric", random_superquadric, 3).expect_clean();
}

// The sphere's closed form against its own definition: at the time it returns the sphere touches
// the wall moving outwards, and before it the sphere was inside (sampled).
TEST(SphericalContainer, SphereClosedFormTouchesMovingOut) {
  Rng rng(4);
  for (int c = 0; c < 2000; ++c) {
    const double R = 5.0, a = rng.uni(0.2, 1.0), B = c % 2 ? rng.uni(0.0, 0.3) : 0.0;
    const Vec3 p = rng.uni(0.0, R - a) * rng.unit(), v = rng.uni(0.0, 3.0) * rng.unit();
    const double A = R - a;
    const double t = SphericalContainer::sphere_contact(p, v, A, B);
    ASSERT_TRUE(std::isfinite(t)) << c;
    const Vec3 x = p + v * t;
    EXPECT_NEAR(x.norm(), A - B * t, 1e-10 * R) << c;
    EXPECT_GT(x.dot(v) / x.norm() + B, 0.0) << c;
    for (int q = 0; q < 64; ++q) {
      const double s = t * q / 64.0;
      EXPECT_LE((p + v * s).norm(), A - B * s + 1e-12 * R) << c;
    }
  }
}

// The impulse at the farthest point: energy conserved, the normal velocity of the contact point
// reversed, the angular momentum about the contact point unchanged, J > 0 along the radial
// direction.
TEST(SphericalContainer, ImpulseIsTheRigidBodyRuleAtTheFarthestPoint) {
  Rng rng(7);
  const double R = 6.0;
  const SphericalContainer container(R, 1e-5);
  Box box;
  box.L = Vec3::Constant(2.0 * R);
  box.periodic = {false, false, false};
  for (int c = 0; c < 200; ++c) {
    const Ellipsoid e = rng.ellipsoid(5.0);
    const Vec3 I(rng.uni(0.1, 1), rng.uni(0.1, 1), rng.uni(0.1, 1));
    const MassProperties m = MassProperties::principal(rng.uni(0.5, 2.0), I);
    BodyState b;
    b.q = rng.quat();
    b.r = box.centre() + rng.uni(0.0, R - e.bounding_radius()) * rng.unit();
    b.w = Vec3(rng.normal(), rng.normal(), rng.normal());
    b.v = Vec3(rng.normal(), rng.normal(), rng.normal());
    const FarthestPoint fp = farthest_point(e, b.q.toRotationMatrix(), 1.0, b.r - box.centre());
    testing::expect_wall_impulse(rng, b, m, fp.u, fp.lever, [&](BodyState& a) {
      const CollisionRecord rec = container.collide(e, a, m, BodyGrowth{}, box);
      EXPECT_EQ(rec.b, std::uint32_t(SphericalContainer::kWall));
      return rec;
    });
  }
}

}  // namespace
}  // namespace hb
