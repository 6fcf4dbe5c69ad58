// The farthest point of a convex body from a point c: F = max_{x in B} |x - c|, the quantity
// that decides whether a body is inside a sphere of radius R centred at c (R - F >= 0;
// locals/spherical_container.hpp).
//
// With B = r + s R(body) B0 (centre r, rotation R, scale s, body-frame shape B0 with support
// function h) and d = r - c,
//     F = max_{x in B} |x - c| = max_{|u| = 1} f(u),   f(u) = u.d + s h(R^T u),
// since |y| = max_{|u|=1} u.y and max_{x in B} u.(x - c) = u.d + s h(R^T u). The gradient of the
// degree-1 extension of f is g(u) = d + s R p(R^T u) = x(u) - c, x(u) the support point; at a
// maximiser u* on the sphere g is parallel to u*, so x(u*) is the farthest point and F = |g|.
//
// Ascent. The iteration u <- g(u) / |g(u)| never decreases f: f is convex and positively
// homogeneous (f(u) = g(u).u), so f(u') >= f(u) + g(u).(u' - u) = g(u).u' = |g(u)| >= f(u).
// Near a maximiser it converges linearly with ratio about rho / F (rho the largest radius of
// curvature of the surface at x(u*), which is <= F at a maximum); a Newton step in the tangent
// plane (the Hessian of f on the sphere is s R H_h R^T projected, minus f, H_h the support
// Hessian) finishes it when it is negative definite and raises f.
//
// Global maximum. f is not concave: a body has several local farthest points (the two tips of
// an ellipsoid, the corners of a superquadric). The ascent starts from d / |d| and from the
// directions of c towards the body's support points along its 6 body axes and 8 body diagonals,
// which lie in the basins of those farthest points for the shapes of this engine (ellipsoids,
// superquadrics); the largest local maximum is returned. tests/geometry/test_farthest_point.cpp
// checks it against dense sampling of the directions on random and adversarial cases.
// One start is enough far from c: a maximiser u* points at a point of B (u* || x* - c), so its
// angle from d is at most theta with sin theta = s L / |d| (L the bounding radius); on that cap
// f >= |d| cos theta - s L, and the Hessian of f along the sphere, s P R H_h R^T P - f P, has
// eigenvalues at most s rho_max - f (H_h's are the principal radii of curvature at the support
// point, at most rho_max). When s rho_max < |d| cos theta - s L, f is strictly concave on the cap
// (a geodesically convex set), so it has one local maximum there and hence one in all; the
// fixed point steps stay in the cap and the ascent from d / |d| finds it. Near a container's wall
// this holds for ellipsoids (rho_max = a_max^2 / a_min) of moderate elongation; superquadrics
// with flat faces (rho_max = inf) always take every start.
#pragma once
#include <array>
#include <cmath>

#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb {

struct FarthestPoint {
  double distance = 0.0;  // F = |x* - c|
  Vec3 u = Vec3::UnitX(); // unit direction from c to x*
  Vec3 lever = Vec3::Zero();  // x* - r (lab frame, scaled): the lever arm of a contact at x*
  int iterations = 0;     // ascent steps over all starts
};

namespace farthest_detail {

// One ascent from u (unit); returns f at the end, u and the lever updated.
template <SupportShape S>
double ascend(const S& shape, const Mat3& R, double s, const Vec3& d, Vec3& u, Vec3& lever,
              int& iterations) {
  auto eval = [&](const Vec3& dir, Vec3& lev) {
    lev = s * (R * shape.support_point(R.transpose() * dir));
    return dir.dot(d + lev);
  };
  double f = eval(u, lever);
  for (int it = 0; it < 200; ++it) {
    ++iterations;
    const Vec3 g = d + lever;
    const double gn = g.norm();
    if (!(gn > 0.0)) return f;
    const Vec3 gt = g - f * u;  // gradient along the sphere
    if (gt.norm() <= 1e-15 * gn) return f;
    Vec3 next = g / gn;  // fixed point step (never lowers f)
    // Newton in the tangent plane when the fixed point step is small (near a maximiser)
    if (gt.norm() < 1e-2 * gn) {
      const Vec3 e1 = (std::abs(u.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(u).normalized();
      const Vec3 e2 = u.cross(e1);
      const Mat3 H = s * (R * shape.support_hessian(R.transpose() * u) * R.transpose());
      const double a11 = e1.dot(H * e1) - f, a12 = e1.dot(H * e2), a22 = e2.dot(H * e2) - f;
      const double det = a11 * a22 - a12 * a12;
      if (a11 < 0.0 && det > 0.0) {
        const double b1 = e1.dot(gt), b2 = e2.dot(gt);
        const double x1 = -(a22 * b1 - a12 * b2) / det, x2 = -(a11 * b2 - a12 * b1) / det;
        const Vec3 un = (u + x1 * e1 + x2 * e2).normalized();
        Vec3 ln;
        const double fn = eval(un, ln);
        if (fn >= gn) {  // at least as good as the fixed point step's guaranteed value
          const double step = (un - u).norm();
          u = un, lever = ln;
          if (step <= 1e-15 || fn == f) return fn;
          f = fn;
          continue;
        }
      }
    }
    Vec3 ln;
    const double fn = eval(next, ln);
    const double step = (next - u).norm();
    u = next, lever = ln;
    if (!(fn > f) || step <= 1e-15) return std::max(f, fn);
    f = fn;
  }
  return f;
}

}  // namespace farthest_detail

// F and its maximiser for the body (shape at scale s, rotation R) whose centre is at d from c.
template <SupportShape S>
FarthestPoint farthest_point(const S& shape, const Mat3& R, double s, const Vec3& d) {
  FarthestPoint best;
  best.distance = -kInf;
  auto try_from = [&](Vec3 u) {
    const double n = u.norm();
    if (!(n > 0.0)) return;
    u /= n;
    Vec3 lever;
    const double f = farthest_detail::ascend(shape, R, s, d, u, lever, best.iterations);
    if (f > best.distance) best.distance = f, best.u = u, best.lever = lever;
  };
  try_from(d);
  const double dn = d.norm(), sL = s * shape.bounding_radius();
  if (dn > sL && s * shape.max_curvature_radius() < dn * std::sqrt(1.0 - (sL / dn) * (sL / dn)) - sL)
    return best;  // the only maximum (see above)
  for (int k = 0; k < 14; ++k) {
    Vec3 b;
    if (k < 6) {
      b = Vec3::Zero();
      b[k >> 1] = (k & 1) ? 1.0 : -1.0;
    } else {
      const int c = k - 6;
      b = Vec3((c & 1) ? 1.0 : -1.0, (c & 2) ? 1.0 : -1.0, (c & 4) ? 1.0 : -1.0);
    }
    try_from(d + s * (R * shape.support_point(b)));
  }
  if (best.distance == -kInf) {  // d = 0 and a point body: nothing to choose
    best.distance = 0.0;
  }
  return best;
}

}  // namespace hb
