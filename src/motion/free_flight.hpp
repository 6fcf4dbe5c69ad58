// Free flight of a rigid body between events: uniform translation and free rotation of a
// spherical top (section 2.2 of the paper; ERRATA item 3 in quaternion form).
//
// For a spherical top the angular velocity w is constant in the lab frame, so the body->lab
// rotation evolves as Q(t) = exp(skew(w) t) Q(0): a rotation by the angle |w| t about w,
// applied on the left.  In quaternions q(t) = [cos(|w|t/2), sin(|w|t/2) w/|w|] * q(0).
#pragma once
#include "math/types.hpp"

namespace hb {

// State of one body in the lab frame at its own time stamp.
struct BodyState {
  Vec3 r = Vec3::Zero();
  Quat q = Quat::Identity();  // body -> lab
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();      // angular velocity, lab frame
};

// Quaternion of the rotation by the angle |w| dt about w (exact, no series truncation).
inline Quat rotation_increment(const Vec3& w, double dt) {
  const double wn = w.norm();
  const double half = 0.5 * wn * dt;
  if (half == 0.0) return Quat::Identity();
  // sin(half)/wn is finite even for tiny wn: use sinc form to stay accurate.
  const double s = (std::abs(half) < 1e-4) ? 0.5 * dt * (1.0 - half * half / 6.0)
                                            : std::sin(half) / wn;
  return Quat(std::cos(half), s * w.x(), s * w.y(), s * w.z());
}

inline Vec3 position_at(const BodyState& b, double dt) { return b.r + b.v * dt; }

inline Quat orientation_at(const BodyState& b, double dt) {
  Quat q = rotation_increment(b.w, dt) * b.q;
  q.normalize();  // keeps |q| = 1 to rounding; the rotation matrix stays orthonormal
  return q;
}

// Body -> lab rotation matrix at dt (columns are the body axes in the lab frame).
inline Mat3 rotation_at(const BodyState& b, double dt) {
  return orientation_at(b, dt).toRotationMatrix();
}

// Advance the state in place by dt.
inline void advance(BodyState& b, double dt) {
  b.r += b.v * dt;
  b.q = orientation_at(b, dt);
}

}  // namespace hb
