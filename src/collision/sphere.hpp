// Elastic collision of two smooth hard spheres: ERRATA item 4 with the contact point on the
// line of centres, so the lever arms are parallel to n and the spins are untouched.
//   u = v_A - v_B, J = 2 (u.n) / (1/m_A + 1/m_B), v_A -= (J/m_A) n, v_B += (J/m_B) n.
// `grow` is the extra normal separation speed of growing spheres (Lubachevsky–Stillinger):
// the surfaces recede at grow, so the post-collision approach speed u'.n must be -(u.n) - 2 grow.
#pragma once
#include "collision/record.hpp"

namespace hb {

inline double sphere_impulse(const Vec3& vA, const Vec3& vB, const Vec3& n, double inv_mA,
                             double inv_mB, double grow = 0.0) {
  const double un = (vA - vB).dot(n);
  return 2.0 * (un + grow) / (inv_mA + inv_mB);
}

// Updates vA, vB; returns J (> 0 for approaching spheres).
inline double collide_spheres(Vec3& vA, Vec3& vB, const Vec3& n, double inv_mA, double inv_mB,
                              double grow = 0.0) {
  const double J = sphere_impulse(vA, vB, n, inv_mA, inv_mB, grow);
  vA -= (J * inv_mA) * n;
  vB += (J * inv_mB) * n;
  return J;
}

}  // namespace hb
