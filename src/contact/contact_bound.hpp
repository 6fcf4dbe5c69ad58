// A cheap lower bound of the first contact time of two convex bodies in free flight, from their
// states at one instant: the order in which the prediction loop (system/rigid_bodies.hpp) solves
// a body's candidates, and the candidates it need not solve at all.
//
// At time `now` the gap along the line of centres n = c / |c| (c = r_B - r_A),
//     g = |c| - h_A(R_A^T n) - h_B(-R_B^T n)     (h the support functions),
// is a lower bound of the distance d(now) of separated bodies (axis_gap.hpp), and d changes
// no faster than the distance-rate bound (Eq. distOver)
//     K = |v_B - v_A| + W_A L_A + W_B L_B,
// W a bound of the body's angular speed over the flight, L its bounding radius. So for g > 0
// the bodies cannot touch before now + g / K. For a top that is not spherical |w| varies; its
// kinetic energy does not: I_min |w|^2 <= sum_k I_k W_k^2 (W = R^T w, I the principal
// moments) bounds it. g <= 0 (the planes through the support points do not separate) gives
// `now`: no bound. The bound is lowered by a relative 1e-12 of the pair's size, so rounding
// never puts it after the contact.
#pragma once
#include <algorithm>
#include <cmath>

#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "shapes/shape.hpp"

namespace hb {

// A bound of |w(t)| over the free flight of body b (|w| itself for a spherical top).
inline double angular_speed_bound(const BodyState& b) {
  if (spherical_top(b.top)) return b.w.norm();
  const Vec3 W = b.q.conjugate() * b.w;  // body frame
  const double twice_energy = (b.top.array() * W.array().square()).sum();
  return std::sqrt(twice_energy / b.top.minCoeff());
}

// Lower bound of the first contact time after `now` of bodies a and b (states at `now`, b at
// the image to use), both shapes scaled by `scale` (rigid: fixed in time). kInf if the bodies
// are separated and do not move relative to each other.
template <SupportShape SA, SupportShape SB>
double contact_time_lower_bound(const SA& sa, const BodyState& a, const SB& sb,
                                const BodyState& b, double now, double scale = 1.0) {
  const Vec3 c = b.r - a.r;
  const double dist = c.norm();
  if (!(dist > 0.0)) return now;
  const Vec3 n = c / dist;
  const double La = scale * sa.bounding_radius(), Lb = scale * sb.bounding_radius();
  const double g = dist - scale * (sa.support(a.q.conjugate() * n) + sb.support(-(b.q.conjugate() * n))) -
                   1e-12 * (dist + La + Lb);
  const double K =
      (b.v - a.v).norm() + angular_speed_bound(a) * La + angular_speed_bound(b) * Lb;
  if (!(K > 0.0)) return g > 0.0 ? kInf : now;
  return now + g / K;
}

}  // namespace hb
