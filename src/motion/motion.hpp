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
      : b_(o.b_), rot_(o.rot_), t0_(o.t0_), own_(o.own_), wmax_(o.wmax_), dwmax_(o.dwmax_) {
    if (own_) rot_ = &*own_;
  }
  Motion& operator=(const Motion& o) {
    if (this != &o) {
      b_ = o.b_, rot_ = o.rot_, t0_ = o.t0_, own_ = o.own_, wmax_ = o.wmax_, dwmax_ = o.dwmax_;
      if (own_) rot_ = &*own_;
    }
    return *this;
  }

  const BodyState& initial() const { return b_; }
  bool spherical() const { return !rot_; }
  double max_angular_speed() const { return wmax_; }
  // Bound of |dW/dt|, W the body-frame angular velocity (0 for a spherical top).
  double max_angular_acceleration() const { return dwmax_; }

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
};

}  // namespace hb
