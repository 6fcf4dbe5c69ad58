// The Motion of one body between events: what the contact-time, axis-gap and escape searches
// ask of a moving body, whatever kind of top it is.
//
//   position(tau), orientation(tau), rotation(tau)   pose at tau = t - t_state
//   angular_velocity(tau)                            lab frame
//   pose(tau, q, w)                                  orientation and angular velocity at once
//   max_angular_speed()                              a bound of |w(tau)| over all tau
//   max_angular_acceleration()                       a bound of |dW/dtau|, W = R^T w
//   spherical()                                      equal principal moments: w constant
// The velocity of a body point x is v + w(tau) x (x - r(tau)); its speed relative to the centre
// is at most max_angular_speed() times the body's bounding radius, the bound every conservative
// step uses.
//
// Spherical tops (equal principal moments; BodyState::top): w constant, the rotation about it
// in closed form with exactly the arithmetic of motion/free_flight.hpp (so the one-species
// spherical-top runs are bit for bit what they were). Other tops: the exact torque-free Euler
// top of motion/free_rotation.hpp (symmetric in closed form, asymmetric with Jacobi elliptic
// functions), set up once when the Motion is made (once per prediction, not per evaluation).
// Growth (Lubachevsky–Stillinger) is not a kind of motion of the centre or the orientation: it
// moves the surface outward; the solvers apply it as a scale law on top of a Motion
// (contact/contact_time.hpp MovingBody, contact/axis_gap.hpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <optional>

#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/free_rotation.hpp"

namespace hb {

// A bound of |dW/dt| (W the body-frame angular velocity) for a free top of principal moments
// `top` whose angular speed stays below wmax. From Euler's equations
// I_i W_i' = (I_j - I_k) W_j W_k: with c the largest |I_j - I_k| / I_i,
// |W'|^2 <= c^2 sum_{j<k} W_j^2 W_k^2 <= c^2 |W|^4 / 3.
inline double angular_acceleration_bound(const Vec3& top, double wmax) {
  const Vec3& I = top;
  const double c = std::max({std::abs(I[1] - I[2]) / I[0], std::abs(I[2] - I[0]) / I[1],
                             std::abs(I[0] - I[1]) / I[2]});
  return c * wmax * wmax / std::sqrt(3.0);
}

// Column k of the rotation matrix of the unit quaternion q: the body axis k in the lab.
inline Vec3 body_axis(const Quat& q, int k) {
  const double x = q.x(), y = q.y(), z = q.z(), s = q.w();
  if (k == 0) return Vec3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + s * z), 2.0 * (x * z - s * y));
  if (k == 1) return Vec3(2.0 * (x * y - s * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + s * x));
  return Vec3(2.0 * (x * z + s * y), 2.0 * (y * z - s * x), 1.0 - 2.0 * (x * x + y * y));
}
// Motion::spin_across's bound from a body's orientation q, lab angular velocity w and principal
// moments `top` at any one time of its flight: |w x e_k| (e_k = q's column k) for a spherical
// top or a symmetric top about k (constant along the flight; see there), times (1 + 1e-14)
// plus 1e-14 wmax (wmax a bound of |w|), a margin for the rounding of e_k and of the poses
// along the flight (a spin nearly along the axis leaves a small cross product of large
// vectors); kInf for other tops (no bound beyond |w|'s).
inline double spin_across_bound(const Quat& q, const Vec3& w, const Vec3& top, int k, double wmax) {
  if (!spherical_top(top) && top[(k + 1) % 3] != top[(k + 2) % 3]) return kInf;
  return w.cross(body_axis(q, k)).norm() * (1.0 + 1e-14) + 1e-14 * wmax;
}

class Motion {
 public:
  explicit Motion(const BodyState& b) : b_(b) {
    if (spherical_top(b.top)) {
      wmax_ = b.w.norm();
    } else {
      if (b.rot) {  // set up already (State's cache): evaluated from b.rot_t on
        rot_ = b.rot, t0_ = b.rot_t;
      } else {
        own_.emplace(FreeRotation::make(b.top, b.q, b.w));
        rot_ = &*own_;
      }
      wmax_ = rot_->max_angular_speed();
      dwmax_ = angular_acceleration_bound(b.top, wmax_);
    }
  }

  // Copies point at their own rotation when they own one.
  Motion(const Motion& o)
      : b_(o.b_), rot_(o.rot_), t0_(o.t0_), own_(o.own_), wmax_(o.wmax_), dwmax_(o.dwmax_),
        across_k_(o.across_k_), across_(o.across_) {
    if (own_) rot_ = &*own_;
  }
  Motion& operator=(const Motion& o) {
    if (this != &o) {
      b_ = o.b_, rot_ = o.rot_, t0_ = o.t0_, own_ = o.own_, wmax_ = o.wmax_, dwmax_ = o.dwmax_;
      across_k_ = o.across_k_, across_ = o.across_;
      if (own_) rot_ = &*own_;
    }
    return *this;
  }

  const BodyState& initial() const { return b_; }
  bool spherical() const { return !rot_; }
  double max_angular_speed() const { return wmax_; }
  // Bound of |dW/dt|, W the body-frame angular velocity (0 for a spherical top).
  double max_angular_acceleration() const { return dwmax_; }
  // A bound over the flight of |w x e|, e the body's own axis k in the lab (k = 0, 1, 2), the
  // part of the angular velocity across that axis (for a body of revolution about k the only
  // part that moves its surface, shapes/shape.hpp revolution_axis); k < 0: max_angular_speed().
  // It is constant along the flight for a spherical top (w and the body-frame W = R^T w are
  // constant, and so is W's part across the body axis) and for a symmetric top about k (Euler's
  // equations keep W_k, and |W| with it), and is taken at the start (spin_across_bound above,
  // with its margin). Any other top: max_angular_speed().
  // Kept for the last k asked (a solve asks once per axis search and per escape search).
  double spin_across(int k) const {
    if (k < 0) return wmax_;
    if (k == across_k_) return across_;
    across_k_ = k;
    return across_ = std::min(wmax_, spin_across_bound(b_.q, b_.w, b_.top, k, wmax_));
  }

  Vec3 position(double tau) const { return b_.r + b_.v * tau; }
  Quat orientation(double tau) const { return rot_ ? rot_->orientation(t0_ + tau) : orientation_at(b_, tau); }
  Mat3 rotation(double tau) const { return orientation(tau).toRotationMatrix(); }
  Vec3 angular_velocity(double tau) const { return rot_ ? rot_->angular_velocity(t0_ + tau) : b_.w; }
  void pose(double tau, Quat& q, Vec3& w) const {
    if (rot_) {
      rot_->evaluate(t0_ + tau, q, w);
    } else {
      q = orientation_at(b_, tau);
      w = b_.w;
    }
  }

 private:
  BodyState b_;
  const FreeRotation* rot_ = nullptr;  // null: spherical top
  double t0_ = 0.0;                    // time of b_ on rot_'s clock
  std::optional<FreeRotation> own_;    // rot_ when b_ brought none
  double wmax_ = 0.0, dwmax_ = 0.0;
  mutable int across_k_ = -1;  // spin_across's cache: the axis asked last (-1: none)
  mutable double across_ = 0.0;
};

}  // namespace hb
