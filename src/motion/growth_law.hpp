// Lubachevsky–Stillinger growth of body sizes: every body is scaled about its centre by the
// common factor s(t) = s0 + rate (min(t, t_stop) - t0), linear until t_stop and constant after
// (docs/growth.md). A growing body is a rigid motion plus this outward motion of its surface.
#pragma once
#include <algorithm>

#include "math/types.hpp"

namespace hb {

struct GrowthLaw {
  double s0 = 1.0;
  double rate = 0.0;  // ds/dt (>= 0)
  double t0 = 0.0;
  double t_stop = kInf;

  double scale_at(double t) const { return s0 + rate * (std::min(t, t_stop) - t0); }
  double rate_at(double t) const { return t < t_stop ? rate : 0.0; }
  double final_scale() const { return t_stop == kInf ? kInf : scale_at(t_stop); }
  bool growing() const { return rate != 0.0; }
};

// The collision rule's growth term (docs/growth.md): scaling about the centre moves a surface
// point x of a body with centre r at (s'/s)(x - r). At the contact x_C with normal n (A into B)
// the outward normal speeds of A's and B's surfaces add up to
//   (s'/s) n.(x_C - r_A) - (s'/s) n.(x_C - r_B) = (s'/s) n.r_AB   (r_AB = r_B - r_A),
// >= 0 for convex bodies that contain their centres (clamped at 0 against rounding).
inline double growth_normal_speed(double s, double sdot, const Vec3& n, const Vec3& r_ab) {
  return std::max(0.0, (sdot / s) * n.dot(r_ab));
}

// The growth of one body as a single-body event source sees it (system/body_events.hpp): its
// scale s at the prediction time and ds/dt (1 and 0 for a rigid body).
struct BodyGrowth {
  double s = 1.0;
  double rate = 0.0;
};

}  // namespace hb
