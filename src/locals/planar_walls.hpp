// Hard planar walls: a local event source (a body against a fixed object). On every walled axis k
// of the box two immovable planes sit at x_k = 0 and x_k = L_k (engine coordinates; -L_k/2 and
// +L_k/2 from the box centre); faces are numbered as the box faces of geometry/obb.hpp,
// 2k (the plane x_k = 0, outward normal -e_k) and 2k + 1 (x_k = L_k, normal +e_k).
//
// Contact time. The signed distance of a convex body from face f, outward normal u, is closed
// form through the support function h of its shape (DESIGN.md "Performance principles"):
//     d_f(t) = c_f - u.r(t) - s(t) h(R(t)^T u),
// c_f = 0 or L_k along u, s(t) the growth scale (1 for rigid bodies). The walls of a box are
// the faces of an oriented box with the walled axes' half-extents L_k / 2 and the others
// unbounded, so the first contact is the escape time of contact/escape_time.hpp (conservative
// advancement, Lipschitz steps, grazing searches). It runs against the walls moved inwards by
// `margin` = eps / 2: a grazing dip the search could miss is at most eps / 2 deep, so a body never
// passes a real wall; its contacts happen at d = margin (to rounding), i.e. against walls
// displaced by eps / 2, a relative volume change of order eps / L. Spheres take the closed form
// t = (c_f - u.r - a s) / (u.v + a s') with no margin.
//
// Impulse: the rigid-body rule against an immovable wall at the support point along the face's
// normal (locals/wall_impulse.hpp).
#pragma once
#include <array>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include "collision/record.hpp"
#include "contact/escape_time.hpp"
#include "core/box.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/growth_law.hpp"
#include "locals/wall_impulse.hpp"
#include "shapes/ellipsoid.hpp"

namespace hb {

struct WallContact {
  double time = kInf;  // absolute
  int face = -1;       // 0..5
};

class PlanarWalls {
 public:
  PlanarWalls() = default;
  PlanarWalls(std::array<bool, 3> axes, double eps) : axes_(axes), eps_(eps) {}

  bool active() const { return axes_[0] || axes_[1] || axes_[2]; }
  const std::array<bool, 3>& axes() const { return axes_; }
  double margin() const { return 0.5 * eps_; }

  static Vec3 normal(int face) {
    Vec3 u = Vec3::Zero();
    u[face >> 1] = (face & 1) ? 1.0 : -1.0;
    return u;
  }
  // Signed distance of a body (shape at scale s, state b) from face f of the box.
  template <SupportShape S>
  static double distance(const S& shape, const BodyState& b, double s, const Box& box, int face) {
    const Vec3 u = normal(face);
    const double c = (face & 1) ? box.L[face >> 1] : 0.0;
    return c - u.dot(b.r) - s * shape.support(b.q.conjugate() * u);
  }

  // First contact of a body with a wall in [now, t_end]: body state b at `now`.
  template <SupportShape S>
  WallContact contact(const S& shape, const BodyState& b, const BodyGrowth& g, const Box& box,
                      double now, double t_end) const {
    WallContact out;
    if constexpr (std::is_same_v<S, Sphere>) {
      for (int k = 0; k < 3; ++k) {
        if (!axes_[k]) continue;
        const double a = shape.radius * g.s, ar = shape.radius * g.rate;
        for (int side = 0; side < 2; ++side) {
          const double gap = side ? box.L[k] - b.r[k] - a : b.r[k] - a;
          const double closing = (side ? b.v[k] : -b.v[k]) + ar;
          if (!(closing > 0.0)) continue;
          const double t = now + std::max(gap, 0.0) / closing;
          if (t < out.time && t <= t_end) out.time = t, out.face = 2 * k + side;
        }
      }
      return out;
    } else {
      EscapeInput<S> in{shape, b, now, now, t_end, Obb{}, 0.0, eps_, g.s, g.rate};
      in.box.centre = box.centre();
      for (int k = 0; k < 3; ++k) in.box.half[k] = axes_[k] ? 0.5 * box.L[k] : kFar;
      in.margin = margin();
      // A body that has just bounced off a face sits on the shrunken face, to rounding on either
      // side; when it is not moving into it the search starts from the face as it is.
      const BoxDistance<S> D(shape, b, now, in.box, in.margin, g.s, g.rate, t_end);
      std::array<double, 6> d;
      D.at(now, d, nullptr);
      double worst = 0.0;
      for (int f = 0; f < 6; ++f) {
        if (!axes_[f >> 1] || !(d[f] < 0.0)) continue;
        if (D.face_rate(f, now) < 0.0) return WallContact{now, f};  // into the wall: touching now
        worst = std::min(worst, d[f]);
      }
      if (worst == 0.0) {  // the usual case: the search starts from the values just computed
        const FirstRoot r = first_root(D, now, t_end, eps_, {}, &d);
        if (r.status != RootStatus::none) out.time = r.time, out.face = r.component;
        return out;
      }
      if (worst < -margin())
        throw std::runtime_error("a body is through a wall (distance " + std::to_string(worst + margin()) + ")");
      // shrink the box less, by twice the overshoot and some ulps of the coordinates (the face
      // sits at L/2 - margin from the centre: a change below its rounding is lost)
      in.margin = margin() + 2.0 * worst - 16.0 * 2.220446049250313e-16 * box.L.maxCoeff();
      const EscapeResult r = escape_time(in);
      if (r.status != EscapeStatus::inside) out.time = r.time, out.face = r.face;
      return out;
    }
  }

  // The impulse of body b (state at the contact, mass m, shape at scale g.s) on face f; b's
  // velocities are updated. Returns the record (a, time left to the caller).
  template <SupportShape S>
  CollisionRecord collide(const S& shape, BodyState& b, const MassProperties& m,
                          const BodyGrowth& g, int face) const {
    return wall_impulse(shape, b, m, g, normal(face), face);
  }

 private:
  static constexpr double kFar = 1e300;  // half-extent of an axis without walls
  std::array<bool, 3> axes_{false, false, false};
  double eps_ = 1e-5;
};

}  // namespace hb
