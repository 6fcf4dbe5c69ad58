// Body-plane distance via the support function, against sampled surface points and the
// distance solver (a plane approximated by a huge sphere is not needed: we use the definition).
#include <gtest/gtest.h>

#include "geometry/plane.hpp"
#include "geometry/random_pairs.hpp"

namespace hb {
namespace {

TEST(PlaneDistance, MatchesDefinitionOnSampledSurface) {
  testing::Rng r(51);
  for (int k = 0; k < 500; ++k) {
    const Ellipsoid e = r.ellipsoid();
    const Pose p{r.ball(3.0), r.rotation()};
    const Plane pl{r.unit(), r.uni(-5.0, 5.0)};
    const double d = plane_distance(e, p, pl);
    const Vec3 x = plane_contact_point(e, p, pl);
    const Posed<Ellipsoid> P{&e, p};
    EXPECT_NEAR(P.f(x), 0.0, 1e-12);                                  // on the surface
    EXPECT_NEAR(pl.c - pl.n.dot(x), d, 1e-12);                        // at distance d
    EXPECT_GT(P.grad(x).normalized().dot(pl.n), 1 - 1e-12);           // normal along n
    for (int j = 0; j < 200; ++j)                                     // nothing is closer
      EXPECT_GE(pl.c - pl.n.dot(P.to_frame(e.ray_surface(r.unit()))), d - 1e-12);
  }
  // sphere: closed form
  const Sphere s{0.5};
  EXPECT_NEAR(plane_distance(s, Pose{Vec3(1, 2, 3), Mat3::Identity()}, Plane{Vec3::UnitZ(), 4.0}),
              0.5, 1e-15);
}

}  // namespace
}  // namespace hb
