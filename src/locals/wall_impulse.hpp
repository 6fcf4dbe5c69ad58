// The impulse of a hard wall (immovable: infinite mass and inertia) on a body touching it at the
// support point x_C = r + s R p(R^T u), u the unit normal from the body into the wall (a planar
// wall's normal, the container's radial direction at x_C). With lever arm a = x_C - r the rule
// of collision/rigid.hpp reduces to
//     J = 2 (u.(v + w x a) + g) / (1/m + (a x u).I^-1 (a x u)),   v' = v - (J/m) u,
//     w' = w - J I^-1 (a x u),
// g = (s'/s) u.a the outward speed of the growing surface at x_C (0 for rigid bodies). A contact
// that is not closing within rounding is given the minimum separation speed of
// system/rigid_bodies.hpp (collide_separating), so that the same contact cannot come up again at
// the same instant. The record's J is the impulse the wall receives (> 0), n = u, r_AB = a; b is
// the wall's number (the caller's).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "collision/record.hpp"
#include "collision/rigid.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/growth_law.hpp"
#include "shapes/shape.hpp"

namespace hb {

template <SupportShape S>
CollisionRecord wall_impulse(const S& shape, BodyState& b, const MassProperties& m,
                             const BodyGrowth& g, const Vec3& u, int wall) {
  const Vec3 lever = g.s * (b.q * shape.support_point(b.q.conjugate() * u));
  const double grow = g.s > 0.0 ? (g.rate / g.s) * u.dot(lever) : 0.0;
  const double closing = u.dot(b.v + b.w.cross(lever)) + grow;
  const double rate = std::abs(u.dot(b.v)) + b.w.norm() * shape.bounding_radius() * g.s +
                      std::abs(g.rate) * shape.bounding_radius();
  const double eps_v = 1e-8 * rate;
  const double g_eff = closing < eps_v ? grow + (eps_v - closing) * 0.5 : grow;
  BodyState at_contact;
  at_contact.r = b.r + lever;  // the wall "body" at the contact point, at rest
  MassProperties immovable;
  immovable.inv_mass = 0.0;
  immovable.spherical = true;
  immovable.inv_scalar_inertia = 0.0;
  CollisionRecord rec = hb::collide(b, m, at_contact, immovable, b.r + lever, u, lever, std::max(g_eff, 0.0));
  rec.b = static_cast<std::uint32_t>(wall);
  rec.n = u;
  rec.r_AB = lever;
  return rec;
}

}  // namespace hb
