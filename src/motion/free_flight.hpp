// Free flight of a rigid body between events: uniform translation and torque-free rotation
// (section 2.2 of the paper; ERRATA item 3 in quaternion form).
//
// For a spherical top the angular velocity w is constant in the lab frame, so the body->lab
// rotation evolves as Q(t) = exp(skew(w) t) Q(0): a rotation by the angle |w| t about w,
// applied on the left.  In quaternions q(t) = [cos(|w|t/2), sin(|w|t/2) w/|w|] * q(0).
// A body whose principal moments differ (BodyState::top) rotates as the exact Euler top of
// motion/free_rotation.hpp instead; w then changes along the flight.  The functions below take
// either path, so every caller that streams a BodyState is right for any top; the solvers'
// inner loops build the rotation once per prediction (motion/motion.hpp) instead of per call.
#pragma once
#include "math/types.hpp"
#include "motion/free_rotation.hpp"

namespace hb {

// State of one body in the lab frame at its own time stamp.
struct BodyState {
  Vec3 r = Vec3::Zero();
  Quat q = Quat::Identity();  // body -> lab
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();      // angular velocity, lab frame
  // Principal moments of inertia along the body x, y, z axes as far as the free rotation is
  // concerned (only their ratios matter); all equal, e.g. the default 0: a spherical top.
  Vec3 top = Vec3::Zero();
  // Optional: the free rotation of this top already set up (a cache, State::free_rotation), whose
  // time rot_t is this state: q, w equal rot->evaluate(rot_t). Whoever changes q or w otherwise
  // (an impulse) must reset it to nullptr.
  const FreeRotation* rot = nullptr;
  double rot_t = 0.0;
};

// Equal principal moments: w is constant in the lab frame.
inline bool spherical_top(const Vec3& I) { return I[0] == I[1] && I[1] == I[2]; }

inline Vec3 position_at(const BodyState& b, double dt) { return b.r + b.v * dt; }

inline Quat orientation_at(const BodyState& b, double dt) {
  if (!spherical_top(b.top))
    return b.rot ? b.rot->orientation(b.rot_t + dt) : FreeRotation::make(b.top, b.q, b.w).orientation(dt);
  return spun(b.w, dt, b.q);
}

// Body -> lab rotation matrix at dt (columns are the body axes in the lab frame).
inline Mat3 rotation_at(const BodyState& b, double dt) {
  return orientation_at(b, dt).toRotationMatrix();
}

// Advance the state in place by dt.
inline void advance(BodyState& b, double dt) {
  b.r += b.v * dt;
  if (spherical_top(b.top)) {
    b.q = orientation_at(b, dt);
  } else if (b.rot) {
    b.rot_t += dt;
    b.rot->evaluate(b.rot_t, b.q, b.w);
  } else {
    FreeRotation::make(b.top, b.q, b.w).evaluate(dt, b.q, b.w);
  }
}

}  // namespace hb
