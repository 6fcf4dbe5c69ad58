// Hard planar walls (locals/planar_walls.hpp): the contact time of every shape against a slow,
// obviously right conservative advancement on random bodies (fast-spinning, grazing, asymmetric
// tops, growing), and the impulse against the rigid-body rules.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <type_traits>

#include "contact_tally.hpp"
#include "locals/planar_walls.hpp"
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

// The body moved freely from its state b (at t = 0, motion m) to time t, at scale s0 + rate t.
template <class S>
double gap_at(const S& shape, const BodyState& b, const Motion& m, double s0, double rate, double t,
              const Box& box, int face) {
  BodyState x = b;
  x.r = b.r + b.v * t;
  x.q = m.orientation(t);
  return PlanarWalls::distance(shape, x, s0 + rate * t, box, face);
}

// The truth: first t in [0, T] at which some walled face's distance falls to `margin`, by plain
// conservative advancement with a step ~1e4 times finer than the solver's grazing step and no
// grazing search (it misses only dips shallower than `tiny` / 2), then bisection to rounding.
// Returns T + 1 when there is none; `steps` counts the work (a cap marks the case inconclusive).
template <class S>
double truth(const S& shape, const BodyState& b, double s0, double rate, const Box& box,
             const std::array<bool, 3>& axes, double margin, double T, long& steps) {
  const Motion m(b);
  const double L = shape.bounding_radius(), tiny = 1e-9 * L;
  const double smax = s0 + std::max(rate, 0.0) * T;
  auto worst = [&](double t, int& face) {
    double d = kInf;
    for (int f = 0; f < 6; ++f) {
      if (!axes[f >> 1]) continue;
      const double x = gap_at(shape, b, m, s0, rate, t, box, f) - margin;
      if (x < d) d = x, face = f;
    }
    return d;
  };
  // per face: |d_f'| <= K_f (a sphere's turning is not seen by its support function)
  const double spin = std::is_same_v<S, Sphere> ? 0.0 : m.max_angular_speed();
  std::array<double, 3> K{};
  for (int k = 0; k < 3; ++k) K[k] = std::abs(b.v[k]) + spin * L * smax + std::abs(rate) * L;
  auto step = [&](double t) {  // no face can be reached before t + step
    double dt = kInf;
    for (int f = 0; f < 6; ++f)
      if (axes[f >> 1])
        dt = std::min(dt, std::max(gap_at(shape, b, m, s0, rate, t, box, f) - margin, tiny) / K[f >> 1]);
    return dt;
  };
  double t = 0.0;
  int face = -1;
  double d = worst(t, face);
  if (d <= 0.0) return 0.0;
  steps = 0;
  while (t < T) {
    if (++steps > 2'000'000) return -1.0;  // inconclusive
    const double t1 = std::min(T, t + step(t));
    const double d1 = worst(t1, face);
    if (d1 <= 0.0) {  // bisect [t, t1]
      double lo = t, hi = t1;
      for (int it = 0; it < 200 && hi - lo > 4e-16 * std::max(1.0, hi); ++it) {
        const double mid = 0.5 * (lo + hi);
        int f;
        (worst(mid, f) <= 0.0 ? hi : lo) = mid;
      }
      return lo;
    }
    t = t1, d = d1;
  }
  return T + 1.0;
}


template <class S, class MakeShape>
ContactTally check_shape(const char* name, MakeShape make, std::uint64_t seed) {
  Rng rng(seed);
  ContactTally tally;
  const double eps = 1e-5;
  const PlanarWalls all({true, true, true}, eps), slit({false, false, true}, eps);
  Box box;
  box.L = Vec3(8.0, 9.0, 7.0);
  const int n = scaled_count(10000);
  for (int c = 0; c < n; ++c) {
    const S shape = make(rng);
    const Kind kind = Kind(c % 5);
    const PlanarWalls& walls = (c / 5) % 2 ? all : slit;
    box.periodic = {!walls.axes()[0], !walls.axes()[1], !walls.axes()[2]};
    const double margin = std::is_same_v<S, Sphere> ? 0.0 : walls.margin();
    const double L = shape.bounding_radius();
    BodyState b;
    b.q = rng.quat();
    b.v = Vec3(rng.normal(), rng.normal(), rng.normal());
    b.w = 2.0 * Vec3(rng.normal(), rng.normal(), rng.normal());
    double s0 = 1.0, rate = 0.0, T = 3.0;
    if (kind == Kind::spinning) b.w = rng.log_uni(10.0, 200.0) * rng.unit();
    if (kind == Kind::top) b.top = Vec3(rng.uni(0.2, 1.0), rng.uni(0.2, 1.0), rng.uni(0.2, 1.0)), b.w *= 3.0;
    if (kind == Kind::growing) s0 = rng.uni(0.6, 1.0), rate = rng.uni(0.0, 0.2), T = 2.0;
    // centre: anywhere the body is clear of the walls by more than the margin
    int tries = 0;
    do {
      for (int k = 0; k < 3; ++k) b.r[k] = rng.uni(0.0, box.L[k]);
      if (kind == Kind::grazing) {  // just above the bottom wall, moving almost parallel to it
        const Vec3 u(0, 0, -1);
        const double h = s0 * shape.support(b.q.conjugate() * u);
        b.r.z() = h + margin + rng.log_uni(1e-9, 1e-2) * L;
        b.v.z() = (rng.uni(0, 1) < 0.5 ? -1.0 : 1.0) * rng.log_uni(1e-7, 1e-2);
        b.w *= rng.log_uni(1e-4, 1.0);
      }
      const Motion m0(b);
      double dmin = kInf;
      for (int f = 0; f < 6; ++f)
        if (walls.axes()[f >> 1]) dmin = std::min(dmin, gap_at(shape, b, m0, s0, rate, 0.0, box, f) - margin);
      if (dmin > 0.0) break;
    } while (++tries < 1000);
    const WallContact ours = walls.contact(shape, b, BodyGrowth{s0, rate}, box, 0.0, T);
    long steps = 0;
    const double tt = truth(shape, b, s0, rate, box, walls.axes(), margin, T, steps);
    ++tally.cases;
    if (tt < 0.0) {
      ++tally.inconclusive;
      continue;
    }
    const bool exists = tt <= T;
    if (ours.face >= 0) {
      ++tally.hits;
      const double d = gap_at(shape, b, Motion(b), s0, rate, ours.time, box, ours.face);
      if (d < -1e-12 * L) ++tally.through;                    // through the real wall
      if (d - margin > 1e-9 * L) ++tally.early;               // not at the (shrunken) wall
      // later than the truth: past a contact the truth found earlier, by more than the rounding of
      // the distance (a grazing body can stay within 1e-16 of the wall for a long time: such a
      // touch is not a contact that was missed). Deepest point between the two times, sampled:
      double deepest = kInf;
      if (exists && ours.time > tt)
        for (int q = 0; q <= 256; ++q)
          for (int f = 0; f < 6; ++f)
            if (walls.axes()[f >> 1])
              deepest = std::min(deepest, gap_at(shape, b, Motion(b), s0, rate, tt + (ours.time - tt) * q / 256.0, box, f) - margin);
      if (exists && ours.time > tt + 1e-12 * std::max(1.0, tt) && deepest < -1e-10 * L) {
        if (tally.late < 3)
          std::printf("  late: %s case %d kind %d ours %.17g (face %d, d %.3e) truth %.17g (d %.3e)\n", name, c,
                      int(kind), ours.time, ours.face, d - margin, tt,
                      gap_at(shape, b, Motion(b), s0, rate, tt, box, ours.face) - margin);
        ++tally.late;
        tally.worst_late = std::max(tally.worst_late, ours.time - tt);
      }
    } else if (exists) {
      ++tally.missed;
      if (tally.missed <= 3)
        std::printf("  missed: %s case %d kind %d truth %.17g\n", name, c, int(kind), tt);
    }
  }
  tally.print(name);
  return tally;
}

TEST(PlanarWalls, SphereContactTimeAgainstConservativeAdvancement) {
  check_shape<Sphere>("sphere", random_sphere, 1).expect_clean();
}
TEST(PlanarWalls, EllipsoidContactTimeAgainstConservativeAdvancement) {
  check_shape<Ellipsoid>("ellipsoid", random_ellipsoid, 2).expect_clean();
}
TEST(PlanarWalls, SuperquadricContactTimeAgainstConservativeAdvancement) {
  check_shape<Superquadric>("superquadric", random_superquadric, 3).expect_clean();
}

// The impulse on a wall: energy conserved, the normal velocity of the contact point reversed,
// the tangential one and the angular momentum about the contact point unchanged (the impulse
// passes through it), the wall receives J > 0 along its outward normal.
TEST(PlanarWalls, ImpulseIsTheRigidBodyRuleWithAnImmovableWall) {
  Rng rng(7);
  const PlanarWalls walls({true, true, true}, 1e-5);
  Box box;
  box.L = Vec3(6, 6, 6);
  for (int c = 0; c < 200; ++c) {
    const Ellipsoid e = rng.ellipsoid(5.0);
    const Vec3 I(rng.uni(0.1, 1), rng.uni(0.1, 1), rng.uni(0.1, 1));
    const MassProperties m = MassProperties::principal(rng.uni(0.5, 2.0), I);
    const int face = c % 6;
    BodyState b;
    b.q = rng.quat();
    b.w = Vec3(rng.normal(), rng.normal(), rng.normal());
    b.v = Vec3(rng.normal(), rng.normal(), rng.normal());
    const Vec3 u = PlanarWalls::normal(face);
    const Vec3 lever = b.q * e.support_point(b.q.conjugate() * u);
    testing::expect_wall_impulse(rng, b, m, u, lever, [&](BodyState& a) {
      return walls.collide(e, a, m, BodyGrowth{}, face);
    });
  }
}

// A sphere bouncing between two walls: closed-form times and the mirror rule.
TEST(PlanarWalls, SphereBouncesAtTheClosedFormTimes) {
  const PlanarWalls walls({false, false, true}, 1e-5);
  Box box;
  box.L = Vec3(5, 5, 4);
  box.periodic = {true, true, false};
  BodyState b;
  b.r = Vec3(1, 1, 2);
  b.v = Vec3(0.3, 0, 1.5);
  const Sphere s{0.5};
  const WallContact c = walls.contact(s, b, BodyGrowth{}, box, 10.0, kInf);
  EXPECT_EQ(c.face, 5);
  EXPECT_DOUBLE_EQ(c.time, 10.0 + (4.0 - 2.0 - 0.5) / 1.5);
  b.r += b.v * (c.time - 10.0);
  const CollisionRecord rec =
      walls.collide(s, b, MassProperties::spherical_top(2.0, 0.2), BodyGrowth{}, c.face);
  EXPECT_DOUBLE_EQ(b.v.z(), -1.5);
  EXPECT_DOUBLE_EQ(b.v.x(), 0.3);
  EXPECT_DOUBLE_EQ(rec.J, 2.0 * 2.0 * 1.5);
  const WallContact d = walls.contact(s, b, BodyGrowth{}, box, c.time, kInf);
  EXPECT_EQ(d.face, 4);
  EXPECT_NEAR(d.time, c.time + 3.0 / 1.5, 1e-12);
}

}  // namespace
}  // namespace hb
