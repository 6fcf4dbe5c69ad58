// Analytic contact time of two hard spheres in uniform motion (the sphere fast path).
// Separation d(t) = dr + dv t. Contact when |d(t)| = sigma with d.dv < 0 (approaching):
//   a t^2 + 2 b t + c = 0, a = dv.dv, b = dr.dv, c = dr.dr - sigma^2,
//   t = c / (-b + sqrt(b^2 - a c))      (the stable root; no cancellation for b < 0).
// Pairs already touching or slightly overlapping (c <= 0) that approach collide at once (t = 0),
// so rounding never lets a pair pass through each other.
#pragma once
#include <cmath>

#include "math/types.hpp"

namespace hb {

// Returns the time from now to contact, or +inf when the pair never touches.
inline double sphere_contact_time(const Vec3& dr, const Vec3& dv, double sigma) {
  const double b = dr.dot(dv);
  if (b >= 0.0) return kInf;
  const double c = dr.squaredNorm() - sigma * sigma;
  if (c <= 0.0) return 0.0;
  const double a = dv.squaredNorm();
  const double disc = b * b - a * c;
  if (disc < 0.0) return kInf;
  return c / (-b + std::sqrt(disc));
}

}  // namespace hb
