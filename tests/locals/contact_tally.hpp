// What the wall and container contact-time tests count against their slow truths (a plain
// conservative advancement), the verdict they share, and the random shapes they draw.
#pragma once
#include <gtest/gtest.h>

#include <cstdio>

#include "../geometry/random_pairs.hpp"
#include "collision/record.hpp"
#include "collision/rigid.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

namespace hb::testing {

struct ContactTally {
  // late: contacts reported after the body had gone more than 1e-10 L past a contact the truth
  // found earlier; through: the body is past the real wall at the reported time; early: the
  // reported contact is not at the (shrunken) wall
  int cases = 0, hits = 0, missed = 0, late = 0, through = 0, early = 0, inconclusive = 0;
  double worst_late = 0.0;

  void print(const char* name) const {
    std::printf("  %s: %d cases, %d contacts, missed %d, late %d (worst %.2e), through %d, early %d, inconclusive %d\n",
                name, cases, hits, missed, late, worst_late, through, early, inconclusive);
  }
  // at least a quarter of the bodies meet a wall; none missed, late, through or early; at most
  // one in a thousand truths gave up
  void expect_clean() const {
    EXPECT_GT(hits, cases / 4);
    EXPECT_EQ(missed, 0);
    EXPECT_EQ(late, 0);
    EXPECT_EQ(through, 0);
    EXPECT_EQ(early, 0);
    EXPECT_LE(inconclusive, cases / 1000);
  }
};

// The kinds of body motion the tests cycle through.
enum class Kind { generic, spinning, grazing, top, growing };

inline Sphere random_sphere(Rng& r) { return Sphere{r.uni(0.3, 1.0)}; }
inline Ellipsoid random_ellipsoid(Rng& r) { return r.ellipsoid(10.0); }
inline Superquadric random_superquadric(Rng& r) {
  return Superquadric(r.uni(0.3, 1.5), r.uni(0.3, 1.5), r.uni(0.3, 1.5), r.log_uni(2.0, 16.0),
                      r.log_uni(2.0, 16.0), r.log_uni(2.0, 16.0));
}

// The impulse of an immovable wall touching body b at b.r + lever with normal u (from the body
// into the wall), applied by collide(BodyState&) -> CollisionRecord: b is first made to approach
// the wall; then energy is conserved, the normal velocity of the contact point reversed, the
// angular momentum about the contact point unchanged (the impulse passes through it), and the
// wall receives J > 0 along u.
template <class Collide>
void expect_wall_impulse(Rng& rng, BodyState b, const MassProperties& m, const Vec3& u, const Vec3& lever,
                         Collide collide) {
  const double un = u.dot(b.v + b.w.cross(lever));
  if (un < 0.1) b.v += (0.1 - un + rng.uni(0, 1)) * u;
  const Vec3 xc = b.r + lever;
  const double e0 = kinetic_energy(b, m);
  const Vec3 L0 = angular_momentum(b, m, xc);
  const Vec3 u0 = b.v + b.w.cross(lever);
  BodyState a = b;
  const CollisionRecord rec = collide(a);
  const Vec3 u1 = a.v + a.w.cross(lever);
  EXPECT_GT(rec.J, 0.0);
  EXPECT_NEAR(u1.dot(u), -u0.dot(u), 1e-12 * (1 + u0.norm()));
  EXPECT_NEAR(kinetic_energy(a, m), e0, 1e-12 * e0);
  EXPECT_LT((angular_momentum(a, m, xc) - L0).norm(), 1e-12 * (1 + L0.norm()));
  EXPECT_NEAR((m.mass * (a.v - b.v)).dot(u), -rec.J, 1e-12 * (1 + rec.J));
  EXPECT_NEAR(rec.dE, 0.0, 1e-12 * e0);
}

}  // namespace hb::testing
