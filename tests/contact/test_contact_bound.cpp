// The contact-time lower bound that orders a body's candidates (contact/contact_bound.hpp):
// never after the first contact the independent reference solver finds, and the angular-speed
// bound of a free top never below |w| along its flight.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "contact/contact_bound.hpp"
#include "geometry/random_pairs.hpp"
#include "motion/motion.hpp"
#include "reference_contact_time.hpp"

namespace hb {
namespace {

using testing::Rng;
using testing::scaled_count;

// Ellipsoids (aspect up to 5) at distance `gap` along a random direction, B moving towards A
// at a random speed on top of random velocities and spins; `tops`: asymmetric tops.
void check_bound_before_contact(std::uint64_t seed, bool tops) {
  Rng r(seed);
  int hits = 0, positive = 0;
  double worst = -kInf;  // largest (bound - contact time) / contact time; must stay <= 0
  const int n = scaled_count(300, 0.2);
  for (int k = 0; k < n; ++k) {
    const Ellipsoid a = r.ellipsoid(5.0), b = r.ellipsoid(5.0);
    const double L = std::max(a.bounding_radius(), b.bounding_radius());
    const Pose pa{r.ball(1.0), r.rotation()};
    const Vec3 dir = r.unit();
    const Pose pb = testing::place_at_distance(a, pa, b, r.rotation(), dir, r.log_uni(1e-4, 1.0));
    BodyState sa{pa.r, Quat(pa.R), r.ball(0.5), r.ball(1.0 / L)};
    BodyState sb{pb.r, Quat(pb.R), r.ball(0.5) - r.uni(0.5, 2.0) * (pb.r - pa.r).normalized(),
                 r.ball(1.0 / L)};
    if (tops) {
      sa.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
      sb.top = Vec3(r.uni(0.2, 1.0), r.uni(0.2, 1.0), r.uni(0.2, 1.0));
    }
    const double t0 = r.uni(-3.0, 3.0);  // the bound's clock: any origin
    const double lb = contact_time_lower_bound(a, sa, b, sb, t0);
    if (lb > t0) ++positive;
    const ref::RefContact c = ref::reference_contact_time(a, sa, b, sb, 4.0, 1e-7);
    if (!c.hit) continue;
    ++hits;
    worst = std::max(worst, (lb - (t0 + c.time)) / std::max(c.time, 1e-300));
    EXPECT_LE(lb, t0 + c.time) << "pair " << k;
  }
  std::printf("[ bound ] %d pairs, %d meet: bound after the contact by at most %.3e relative; "
              "%d bounds after the start\n", n, hits, worst, positive);
  EXPECT_GT(hits, n / 4);         // the pairs approach: most meet inside the reference window
  EXPECT_GT(positive, n / 10);    // and the bound says something for a fair share of them
  EXPECT_LE(worst, 0.0);
}

TEST(ContactBound, NeverAfterTheFirstContactOfSphericalTops) { check_bound_before_contact(5, false); }
TEST(ContactBound, NeverAfterTheFirstContactOfAsymmetricTops) { check_bound_before_contact(6, true); }

// |w(tau)| of torque-free asymmetric tops along their flight never exceeds the bound (the
// rotational kinetic energy over the smallest moment); spherical tops: exactly |w|.
TEST(ContactBound, AngularSpeedBoundHoldsAlongTheFlight) {
  Rng r(7);
  double closest = kInf;  // smallest (bound - max sampled |w|) / bound
  for (int k = 0; k < scaled_count(200, 0.2); ++k) {
    BodyState b{r.ball(1.0), Quat(r.rotation()), r.ball(1.0), r.ball(3.0)};
    b.top = Vec3(r.uni(0.1, 1.0), r.uni(0.1, 1.0), r.uni(0.1, 1.0));
    const double bound = angular_speed_bound(b);
    const Motion m(b);
    double wmax = 0.0;
    for (int s = 0; s <= 400; ++s) wmax = std::max(wmax, m.angular_velocity(0.05 * s).norm());
    EXPECT_LE(wmax, bound * (1.0 + 1e-12)) << k;
    closest = std::min(closest, (bound - wmax) / bound);
  }
  std::printf("[ bound ] asymmetric tops: bound above the largest sampled |w| by >= %.3e relative\n",
              closest);
  BodyState s{Vec3::Zero(), Quat(r.rotation()), Vec3::Zero(), Vec3(0.3, -1.2, 0.7)};
  EXPECT_EQ(angular_speed_bound(s), s.w.norm());
}

}  // namespace
}  // namespace hb
