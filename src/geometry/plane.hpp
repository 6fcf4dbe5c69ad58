// Distance from a posed body to a plane {x : n.x = c} (unit n), the body on the side n.x < c.
// For shapes with a closed-form support function it is analytic (DESIGN.md):
//     d = c - n.r - h(R^T n),
// positive when the body is clear of the plane, negative when it crosses it.  The touching
// point (the body's farthest point along n) is r + R p(R^T n), p the support point.
// The distance along n to the plane is what neighbour lists (box faces) and walls need.
#pragma once
#include "geometry/posed.hpp"
#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb {

struct Plane {
  Vec3 n = Vec3::UnitX();  // unit normal, pointing away from the body's side
  double c = 0.0;          // plane: n.x = c
};

template <SupportShape S>
double plane_distance(const S& s, const Pose& p, const Plane& pl) {
  return pl.c - pl.n.dot(p.r) - s.support(p.R.transpose() * pl.n);
}

// The body's point closest to (or deepest through) the plane.
template <SupportShape S>
Vec3 plane_contact_point(const S& s, const Pose& p, const Plane& pl) {
  return p.r + p.R * s.support_point(p.R.transpose() * pl.n);
}

}  // namespace hb
