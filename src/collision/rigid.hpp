// Elastic collision of two hard rigid bodies (paper section 2.5, with the corrections of
// ERRATA item 4), optionally with Lubachevsky–Stillinger surface growth.
//
// Derivation.  A frictionless contact exchanges an impulse J n (n: unit normal at the contact
// point x_C, pointing from A into B): B receives +J n, A receives -J n, applied at x_C.  With
// lever arms rA = x_C - r_A and rB = x_C - r_B (r_B taken in the periodic image of B that
// touches A, i.e. r_B = r_A + r_AB):
//     v_A' = v_A - (J/m_A) n           w_A' = w_A - J I_A^-1 (rA x n)
//     v_B' = v_B + (J/m_B) n           w_B' = w_B + J I_B^-1 (rB x n)
// (I^-1 is the lab-frame inverse inertia tensor, Q I_body^-1 Q^T.)  Momentum is conserved by
// construction; so is angular momentum about any point P, because the change
//     m_A (r_A - P) x dv_A + I_A dw_A + (same for B) = -J (x_C - P) x n + J (x_C - P) x n = 0.
// The contact relative velocity u = (v_A + w_A x rA) - (v_B + w_B x rB) changes along n by
//     d(u.n) = -J K,   K = 1/m_A + 1/m_B + (rA x n).I_A^-1(rA x n) + (rB x n).I_B^-1(rB x n),
// since n.(I^-1(r x n) x r) = (r x n).I^-1(r x n).  The kinetic-energy change of the impulse is
// exactly dE = -J (u.n + u'.n) / 2 (each quadratic form changes by the impulse times the mean
// of the old and new velocities), so the energy is conserved iff u'.n = -u.n, i.e.
//     J = 2 (u.n) / K          (ERRATA item 4).
//
// Growth.  When the bodies' surfaces also move outward (Lubachevsky–Stillinger compression),
// let `grow` >= 0 be the sum of the two surfaces' outward normal speeds at the contact point.
// The gap then closes at the rate  u.n + grow  (rigid motion plus growth); a collision is a
// contact with u.n + grow > 0.  We apply the elastic rule in the frame of the moving surfaces
// (a ball bouncing off a moving wall): the gap-closing rate is reversed,
//     u'.n + grow = -(u.n + grow)   =>   u'.n = -u.n - 2 grow,   J = 2 (u.n + grow) / K.
// Consequences (tested): after the collision the gap opens at exactly the rate at which it
// closed; the rigid relative normal velocity is separating faster than the growth rate,
// -u'.n = grow + (u.n + grow) > grow; and the kinetic energy rises by dE = J grow >= 0 (the work
// the growing surfaces do; a growth run rescales velocities/thermostats to remove it).
// With grow = 0 this is the elastic rule above.
//
// If u.n + grow <= 0 the surfaces are not approaching (a numerically grazing or stale event):
// no impulse is applied, the record has J = 0 and dE = 0, and the states are left untouched.
#pragma once
#include "collision/record.hpp"  // CollisionRecord {time, a, b, J, n, r_AB, dE}
#include "math/types.hpp"
#include "motion/free_flight.hpp"

#include <stdexcept>

namespace hb {

// Mass and inertia of one rigid body. The inertia tensor is given in the body frame (the frame
// of the shape's semi-axes) and turned to the lab frame with the body's orientation:
// I_lab = Q I_body Q^T.  A spherical top (I_body = I * identity) takes a cheaper path.
struct MassProperties {
  double mass = 1.0;
  double inv_mass = 1.0;
  Mat3 inertia_body = Mat3::Identity();
  Mat3 inv_inertia_body = Mat3::Identity();
  bool spherical = true;  // inertia_body == I * identity; inv_inertia_body == (1/I) * identity
  double inv_scalar_inertia = 1.0;

  static MassProperties spherical_top(double m, double I) {
    if (!(m > 0.0) || !(I > 0.0) || !std::isfinite(m) || !std::isfinite(I))
      throw std::invalid_argument("MassProperties::spherical_top: mass and inertia must be > 0");
    MassProperties p;
    p.mass = m;
    p.inv_mass = 1.0 / m;
    p.inertia_body = I * Mat3::Identity();
    p.inv_inertia_body = (1.0 / I) * Mat3::Identity();
    p.spherical = true;
    p.inv_scalar_inertia = 1.0 / I;
    return p;
  }

  // General symmetric positive-definite body-frame inertia tensor (need not be diagonal).
  static MassProperties from_tensor(double m, const Mat3& I_body) {
    if (!(m > 0.0) || !std::isfinite(m))
      throw std::invalid_argument("MassProperties::from_tensor: mass must be > 0");
    const Mat3 Is = 0.5 * (I_body + I_body.transpose());
    Eigen::LLT<Mat3> llt(Is);
    if (llt.info() != Eigen::Success || !Is.allFinite())
      throw std::invalid_argument(
          "MassProperties::from_tensor: inertia tensor must be symmetric positive definite");
    MassProperties p;
    p.mass = m;
    p.inv_mass = 1.0 / m;
    p.inertia_body = Is;
    Mat3 inv = llt.solve(Mat3::Identity());
    p.inv_inertia_body = 0.5 * (inv + inv.transpose());
    p.spherical = false;
    p.inv_scalar_inertia = 0.0;
    return p;
  }

  // Principal moments I along the body x, y, z axes: a spherical top when all three are equal.
  static MassProperties principal(double m, const Vec3& I) {
    if (I[0] == I[1] && I[1] == I[2]) return spherical_top(m, I[0]);
    return from_tensor(m, Mat3(I.asDiagonal()));
  }
  // The principal moments that govern the free rotation (BodyState::top): 0 for a spherical top.
  Vec3 top() const { return spherical ? Vec3::Zero() : Vec3(inertia_body.diagonal()); }

  // I_lab^-1 x for a body with orientation q (body -> lab).
  Vec3 apply_inv_inertia(const Quat& q, const Vec3& x) const {
    if (spherical) return inv_scalar_inertia * x;
    const Mat3 R = q.toRotationMatrix();
    return R * (inv_inertia_body * (R.transpose() * x));
  }

  // I_lab x for a body with orientation q (body -> lab).
  Vec3 apply_inertia(const Quat& q, const Vec3& x) const {
    if (spherical) return inertia_body(0, 0) * x;
    const Mat3 R = q.toRotationMatrix();
    return R * (inertia_body * (R.transpose() * x));
  }
};

// Translational + rotational kinetic energy: m v^2/2 + w.I_lab w/2.
inline double kinetic_energy(const BodyState& b, const MassProperties& p) {
  return 0.5 * p.mass * b.v.squaredNorm() + 0.5 * b.w.dot(p.apply_inertia(b.q, b.w));
}

// Angular momentum about the point P, using the body's position b.r:
// m (r - P) x v + I_lab w.
inline Vec3 angular_momentum(const BodyState& b, const MassProperties& p, const Vec3& P) {
  return p.mass * (b.r - P).cross(b.v) + p.apply_inertia(b.q, b.w);
}

// Contact relative velocity u = (v_A + w_A x rA) - (v_B + w_B x rB) with rA = x_C - r_A,
// rB = x_C - (r_A + r_AB).  x_C is given in A's periodic image (near A.r).
inline Vec3 contact_relative_velocity(const BodyState& A, const BodyState& B, const Vec3& x_C,
                                      const Vec3& r_AB) {
  const Vec3 rA = x_C - A.r;
  const Vec3 rB = rA - r_AB;
  return (A.v + A.w.cross(rA)) - (B.v + B.w.cross(rB));
}

// Resolve a collision in place (v and w of A and B change; r and q do not).
// Returns the record with J, n, r_AB, dE filled (J >= 0 on B along n; dE: 0 to rounding if
// grow = 0, else J*grow); time, a, b are left for the caller.
//   x_C   contact point, in A's periodic image (i.e. near A.r; B is taken at A.r + r_AB).
//   n     normal from A into B (normalised here; must be non-zero and finite).
//   r_AB  minimum-image separation r_B - r_A.  B.r itself is NOT used, so B may be stored
//         in any periodic image; the lever arm of B is rB = x_C - A.r - r_AB.
//   grow  >= 0: sum of the surfaces' outward normal speeds at x_C (growth); 0 for plain EDMD.
// Throws std::invalid_argument for a zero/non-finite normal or a negative/non-finite grow.
inline CollisionRecord collide(BodyState& A, const MassProperties& mA, BodyState& B,
                               const MassProperties& mB, const Vec3& x_C, const Vec3& n_in,
                               const Vec3& r_AB, double grow = 0.0) {
  const double nn = n_in.norm();
  if (!(nn > 0.0) || !std::isfinite(nn))
    throw std::invalid_argument("collide: the contact normal must be non-zero and finite");
  if (!(grow >= 0.0) || !std::isfinite(grow))
    throw std::invalid_argument("collide: grow must be finite and >= 0");
  const Vec3 n = n_in / nn;

  CollisionRecord rec;
  rec.n = n;
  rec.r_AB = r_AB;

  const Vec3 rA = x_C - A.r;
  const Vec3 rB = rA - r_AB;
  const Vec3 u = (A.v + A.w.cross(rA)) - (B.v + B.w.cross(rB));
  const double closing = u.dot(n) + grow;  // rate at which the gap closes
  if (!(closing > 0.0)) return rec;        // not approaching: no impulse

  const Vec3 tA = rA.cross(n);
  const Vec3 tB = rB.cross(n);
  const Vec3 dwA = mA.apply_inv_inertia(A.q, tA);  // I_A^-1 (rA x n)
  const Vec3 dwB = mB.apply_inv_inertia(B.q, tB);  // I_B^-1 (rB x n)
  const double K = mA.inv_mass + mB.inv_mass + tA.dot(dwA) + tB.dot(dwB);
  const double J = 2.0 * closing / K;

  A.v -= (J * mA.inv_mass) * n;
  B.v += (J * mB.inv_mass) * n;
  A.w -= J * dwA;
  B.w += J * dwB;
  A.rot = B.rot = nullptr;  // a new free rotation

  // Exact energy change of this impulse: -J (u.n + u'.n)/2, with u' from the updated states.
  const Vec3 u_after = (A.v + A.w.cross(rA)) - (B.v + B.w.cross(rB));
  rec.J = J;
  rec.dE = -0.5 * J * (u.dot(n) + u_after.dot(n));
  return rec;
}

}  // namespace hb
