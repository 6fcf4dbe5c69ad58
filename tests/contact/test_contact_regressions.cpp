// Regressions found by the engine (each reproduces a state that once misbehaved).
#include <gtest/gtest.h>

#include "contact/contact_time.hpp"
#include "shapes/ellipsoid.hpp"

using namespace hb;

// Two spheres written as ellipsoids (tight bounding spheres), touching to rounding and
// separating just after their collision: the bounding-sphere window used to end exactly at
// touching, a rounding-negative distance there faked a contact at t = 0, and the event loop
// collided the pair at the same instant forever.
TEST(ContactRegression, TouchingSeparatingTightBodiesAreNotAContact) {
  const Ellipsoid e{0.5, 0.5, 0.5};
  BodyState a, b;  // the state the engine met (hardbody run, N = 256, phi = 0.25, X0 = 1, seed 4)
  a.r = Vec3(6.9964738148454524, 6.2325143275958066, 0.97567657823340093); a.q = Quat(0.55270032020078275, 0.097250902658591196, 0.69296961746853614, 0.45261211566588921); a.v = Vec3(1.0515544445416687, -0.32905901267217907, -2.4601123628373998); a.w = Vec3(0.59876926989362045, 4.2665816004479886, 2.7867116770492362);
  b.r = Vec3(7.1217166994049084, 5.247670742774754, 0.85568768998100997); b.q = Quat(0.77211059545390892, -0.24640051278917613, -0.047281904465004979, 0.58386337202739791); b.v = Vec3(0.60016828953882839, -1.2683979117414812, -0.017261118605224515); b.w = Vec3(-1.3906357504456355, -0.26684971534311863, 3.2952093700054434);
  const double now = 0.38401074268554819;
  ContactInput<Ellipsoid, Ellipsoid> in{e, e, a, b, now, now, now + 1.0, 1e-5};
  const ContactResult r = contact_time(in);
  EXPECT_NE(r.time, now) << "a fake contact at the start";
  // the bodies may meet again later (they are in a dense fluid), but not at once
  if (r.status == ContactStatus::hit) {
    EXPECT_GT(r.time - now, 1e-6);
  }
  ContactInput<Ellipsoid, Ellipsoid> sw{e, e, b, a, now, now, now + 1.0, 1e-5};
  const ContactResult r2 = contact_time(sw);
  if (r2.status == ContactStatus::hit) {
    EXPECT_GT(r2.time - now, 1e-6);
  }
}
