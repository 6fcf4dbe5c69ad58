// A hard spherical container: a local event source (a body against a fixed object). The wall is
// the sphere of radius R about the box centre c (the box is the cube of side 2 R, periodic along
// no axis; setup/box_setup.hpp).
//
// Distance. A convex body is inside while its farthest point from c is within R:
//     D(t) = R - F(t),   F = max_{x in B(t)} |x - c| = max_{|u|=1} u.d(t) + s(t) h(R(t)^T u),
// d = r - c, h the support function of the shape, s the growth scale (geometry/farthest_point.hpp
// computes F and its maximiser u*). By the envelope theorem
//     F'(t) = u*.v - s (R p*).(w x u*) + s' h(R^T u*),
// p* the body-frame support point along u*, and since every u.d + s h(R^T u) moves at most that
// fast, |D'| <= K = |v| + max|w| L s_max + |s'| L (L the bounding radius).
//
// Contact time. Spheres: the closed form |d + v t| = R - a s(t) (a quadratic; the first root at
// which the sphere moves outwards). Other shapes: the first root of D - eps / 2 by conservative
// advancement (contact/first_root.hpp), with the cheap bound D >= R - |d| - s L while the body is
// far from the wall (more than L / 4 of it), the farthest point near it. As for the planar walls
// (locals/planar_walls.hpp) the search runs against the wall moved inwards by the margin eps / 2,
// so a grazing dip the search misses never passes the real wall.
//
// Impulse: the rigid-body rule against an immovable wall at the farthest point x*, whose normal
// into the wall is the radial direction u* (locals/wall_impulse.hpp).
#pragma once
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "collision/record.hpp"
#include "contact/first_root.hpp"
#include "core/box.hpp"
#include "geometry/farthest_point.hpp"
#include "locals/planar_walls.hpp"
#include "locals/wall_impulse.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/growth_law.hpp"
#include "motion/motion.hpp"
#include "shapes/ellipsoid.hpp"

namespace hb {

// D(t) - margin of a body in free flight (and growth) against the container, for first_root.
template <SupportShape S>
struct ContainerDistance {
  static constexpr int kComponents = 1;
  const S& shape;
  Vec3 d0, v;            // centre relative to c at t_state, velocity
  double t_state;
  double limit;          // R - margin
  double L;
  Motion motion;
  double s0 = 1.0, sdot = 0.0, smax = 1.0;

  ContainerDistance(const S& sh, const BodyState& b, double ts, const Vec3& centre, double limit_,
                    double scale = 1.0, double scale_rate = 0.0, double t_end = kInf)
      : shape(sh), d0(b.r - centre), v(b.v), t_state(ts), limit(limit_), L(sh.bounding_radius()),
        motion(b), s0(scale), sdot(scale_rate),
        smax(scale_rate > 0.0 ? scale + scale_rate * (t_end - ts) : scale) {}

  double scale_at(double t) const { return sdot == 0.0 ? s0 : s0 + sdot * (t - t_state); }
  // D - margin at t, with its rate when dd is non-null (the rate needs the farthest point; the
  // value alone takes the cheap lower bound far from the wall)
  void at(double t, std::array<double, 1>& d, std::array<double, 1>* dd) const {
    const double tau = t - t_state;
    const Vec3 r = d0 + v * tau;
    const double sc = scale_at(t);
    const double cheap = limit - r.norm() - sc * L;
    if (!dd && cheap > 0.25 * sc * L) {
      d[0] = cheap;
      return;
    }
    Quat q;
    Vec3 w;
    motion.pose(tau, q, w);
    const FarthestPoint fp = farthest_point(shape, q.toRotationMatrix(), sc, r);
    d[0] = limit - fp.distance;
    if (dd) {
      const double h = sc > 0.0 ? fp.u.dot(fp.lever) / sc : 0.0;
      (*dd)[0] = -(fp.u.dot(v) - fp.lever.dot(w.cross(fp.u)) + sdot * h);
    }
  }
  double component_at(int, double t) const {
    std::array<double, 1> d;
    at(t, d, nullptr);
    return d[0];
  }
  double rate_bound(int) const {
    const double wmax = motion.spherical() ? motion.initial().w.norm() : motion.max_angular_speed();
    return v.norm() + wmax * L * smax + std::abs(sdot) * L;
  }
};

class SphericalContainer {
 public:
  static constexpr int kWall = 6;  // its number in wall events and records (0..5: box faces)

  SphericalContainer() = default;
  SphericalContainer(double radius, double eps) : radius_(radius), eps_(eps) {}

  bool active() const { return radius_ > 0.0; }
  double radius() const { return radius_; }
  double margin() const { return 0.5 * eps_; }

  // R - F of a body (shape at scale s, state b): >= 0 inside, < 0 through the wall.
  template <SupportShape S>
  double distance(const S& shape, const BodyState& b, double s, const Box& box) const {
    const Vec3 d = b.r - box.centre();
    if constexpr (std::is_same_v<S, Sphere>) return radius_ - d.norm() - s * shape.radius;
    return radius_ - farthest_point(shape, b.q.toRotationMatrix(), s, d).distance;
  }

  // First contact of a body with the container in [now, t_end]: body state b at `now`.
  template <SupportShape S>
  WallContact contact(const S& shape, const BodyState& b, const BodyGrowth& g, const Box& box,
                      double now, double t_end) const {
    WallContact out;
    const Vec3 p = b.r - box.centre();
    if constexpr (std::is_same_v<S, Sphere>) {
      const double t = sphere_contact(p, b.v, radius_ - shape.radius * g.s, shape.radius * g.rate);
      if (now + t <= t_end) out.time = now + t, out.face = kWall;
      return out;
    } else {
      ContainerDistance<S> D(shape, b, now, box.centre(), radius_ - margin(), g.s, g.rate, t_end);
      std::array<double, 1> d, dd;
      D.at(now, d, &dd);
      if (d[0] < 0.0) {
        // a body that has just bounced sits on the shrunken wall, to rounding on either side
        if (dd[0] < 0.0) return WallContact{now, kWall};  // into the wall: touching now
        if (d[0] < -margin())
          throw std::runtime_error("a body is through the spherical container (distance " +
                                   std::to_string(d[0] + margin()) + ")");
        // search from the wall moved out by twice the overshoot and some ulps of R
        D.limit = radius_ - margin() - 2.0 * d[0] + 16.0 * 2.220446049250313e-16 * radius_;
      }
      const FirstRoot r = first_root(D, now, t_end, eps_);
      if (r.status != RootStatus::none) out.time = r.time, out.face = kWall;
      return out;
    }
  }

  // The impulse of the container on body b at contact (velocities updated).
  template <SupportShape S>
  CollisionRecord collide(const S& shape, BodyState& b, const MassProperties& m, const BodyGrowth& g,
                          const Box& box) const {
    const Vec3 d = b.r - box.centre();
    Vec3 u;
    if constexpr (std::is_same_v<S, Sphere>) u = d.normalized();
    else u = farthest_point(shape, b.q.toRotationMatrix(), g.s, d).u;
    return wall_impulse(shape, b, m, g, u, kWall);
  }

  // Time from now at which a sphere (centre p from c, velocity v, radius a(t) = R - A + B t, i.e.
  // A = R - a(0), B = a') first touches the wall moving outwards: |p + v t| = A - B t; kInf if
  // never. g(t) = |p + v t| - (A - B t) crosses zero upwards at the root; squaring gives
  // (v.v - B^2) t^2 + 2 (p.v + A B) t + p.p - A^2 = 0, whose roots with A - B t >= 0 and
  // g' > 0 are the contacts.
  static double sphere_contact(const Vec3& p, const Vec3& v, double A, double B) {
    const double pn = p.norm();
    const double outward = (pn > 0.0 ? p.dot(v) / pn : v.norm()) + B;
    if (A - pn <= 0.0 && outward > 0.0) return 0.0;  // touching (to rounding) and moving out
    const double c2 = v.squaredNorm() - B * B, b = p.dot(v) + A * B;
    const double c0 = (pn - A) * (pn + A);
    double roots[2] = {kInf, kInf};
    if (c2 == 0.0) {
      if (b != 0.0) roots[0] = -c0 / (2.0 * b);
    } else {
      const double disc = b * b - c2 * c0;
      if (disc < 0.0) return kInf;
      const double q = -(b + std::copysign(std::sqrt(disc), b));
      roots[0] = q / c2;
      roots[1] = q != 0.0 ? c0 / q : kInf;
    }
    double best = kInf;
    for (double t : roots) {
      if (!(t >= 0.0) || !(t < best) || A - B * t < 0.0) continue;
      const Vec3 x = p + v * t;
      const double xn = x.norm();
      const double rate = (xn > 0.0 ? x.dot(v) / xn : v.norm()) + B;
      if (rate > 0.0) best = t;
    }
    return best;
  }

 private:
  double radius_ = 0.0;
  double eps_ = 1e-5;
};

}  // namespace hb
