// The shape concept: what a convex body must supply to the generic distance and contact-time
// solvers.  Everything is in the body frame (centre at the origin, semi-axes along x, y, z).
//
// A shape is described by a smooth implicit function f(x): f < 0 inside, f = 0 on the surface,
// f > 0 outside, whose sub-level set {f <= 0} is convex.  The solvers need f, its gradient and
// its Hessian (Eqs. dist8, dist5, contime of the paper), a bounding radius L (Eq. lalb, for the
// bounding-sphere bracket and the distance-rate bound, Eq. distOver), an inscribed radius (a
// length scale for tolerances), the half-extents along the body axes (for the scaled initial
// guess of section 3.2) and the intersection of a ray from the centre with the surface (for the
// initial guesses).  Shapes with a closed-form support function h(n) = max_{x in body} n.x
// additionally model `SupportShape`; that gives the analytic body-plane distance and the
// independent reference distance used in the tests.
//
// Adding a shape (e.g. a superquadric) means writing one small struct with these members: no
// virtual calls, the solvers are templates over the concept.
#pragma once
#include <cmath>
#include <concepts>

#include "math/types.hpp"

namespace hb {

template <class S>
concept Shape = requires(const S& s, const Vec3& x) {
  { s.f(x) } -> std::convertible_to<double>;
  { s.grad(x) } -> std::convertible_to<Vec3>;
  { s.hessian(x) } -> std::convertible_to<Mat3>;
  { s.volume() } -> std::convertible_to<double>;
  { s.bounding_radius() } -> std::convertible_to<double>;   // L >= max |x| over the body
  { s.inscribed_radius() } -> std::convertible_to<double>;  // <= min |x| over the surface
  { s.half_extents() } -> std::convertible_to<Vec3>;        // (a, b, c) along body x, y, z
  { s.ray_surface(x) } -> std::convertible_to<Vec3>;        // surface point s*x, s > 0
};

// Closed-form support function h(n) = max_{x in body} n.x (n need not be unit; h is positively
// homogeneous of degree 1), its gradient (the support point, a surface point with outward
// normal parallel to n) and its Hessian (for the reference optimiser in the tests).
template <class S>
concept SupportShape = Shape<S> && requires(const S& s, const Vec3& n) {
  { s.support(n) } -> std::convertible_to<double>;
  { s.support_point(n) } -> std::convertible_to<Vec3>;
  { s.support_hessian(n) } -> std::convertible_to<Mat3>;
};

// Shapes symmetric under x -> -x declare `static constexpr bool kCentrallySymmetric = true`:
// then h(-n) = h(n) and p(-n) = -p(n), bit for bit (every shape of the engine is; the escape
// times of neighbour-list boxes use it, contact/escape_time.hpp).
template <class S>
concept CentrallySymmetric = requires { requires S::kCentrallySymmetric; };

// Shapes whose support(n) is computed as n.dot(support_point(n)) declare
// `static constexpr bool kSupportIsPointDot = true`: a caller that needs both takes the dot
// product itself, the same bits for one support point solve instead of two (superquadrics).
template <class S>
concept SupportIsPointDot = requires { requires S::kSupportIsPointDot; };

// The support point p(n) when the support value h = support(n) is at hand: shapes that form the
// point from the value declare support_point(n, h) (ellipsoids: M n / h, the same bits as
// support_point(n) without its square root); others solve again.
template <SupportShape S>
Vec3 support_point_given(const S& s, const Vec3& n, double h) {
  if constexpr (requires { { s.support_point(n, h) } -> std::convertible_to<Vec3>; }) {
    return s.support_point(n, h);
  } else {
    (void)h;
    return s.support_point(n);
  }
}

// Shapes whose max_curvature_radius() is finite for every valid instance (ellipsoids, spheres)
// declare `static constexpr bool kBoundedCurvature = true`: the contact-time solver then
// compiles only its second-order axis steps for their pairs, not the flat-face ones
// (contact/contact_time.hpp, advance_affine).
template <class S>
concept BoundedCurvature = requires { requires S::kBoundedCurvature; };

// The rotation lever of a shape: an upper bound of |x x m| over the surface points x (from the
// centre) and their outward unit normals m, i.e. of the distance of a support point p(m) from
// the line through the centre along m. A body turning at angular velocity w moves its support
// value along a fixed lab direction at the rate |dh/dt| = |p.(W x m)| = |W.(m x p)| <= |w x n| l
// (m' = m x W is normal to m, so only the part of p normal to m counts), and a surface point
// with normal n, such as a closest point, moves along n at |n.(w x x)| = |w.(x x n)| <= |w| l.
// So l, not the bounding radius L, is the lever of rotation in every rate bound of a distance or
// a gap (contact/contact_time.hpp, contact/axis_gap.hpp, contact/escape_time.hpp). For any
// shape, |x|^2 = (x.m)^2 + |x x m|^2 with x.m = h(m) >= r_in (the ball of the inscribed radius
// about the centre lies in the body) and |x| <= L, so l <= sqrt(L^2 - r_in^2); shapes with a
// closed form declare `rotation_lever()` (ellipsoids: a_max - a_min; spheres: 0), and so do
// superquadrics, from a branch and bound computed once per shape (sq_detail::lever_bound, within
// 1e-3 of the lever: 1.185 against the generic 1.769 for (0.8, 1.6, 1.6) with exponents (2, 2, 8)).
inline double rotation_lever_bound(double L, double r_in) {  // sqrt(L^2 - r_in^2)
  return std::sqrt(std::max(0.0, (L - r_in) * (L + r_in)));
}
// Bodies of revolution. A shape symmetric under every rotation about its own axis k (k = 0, 1,
// 2: body x, y, z) declares `revolution_axis()` = k; -1 (the default) declares nothing. For such
// a body the normal at any surface point x lies in the plane of the axis e and of x (the
// meridian plane), and so does the support point p of any direction m: x x n and m x p are
// normal to e. The part of the angular velocity along e then moves no support value and no
// surface point along its normal (w.(x x n) = w_perp.(x x n), w_perp = w - (w.e) e), and every
// rate bound above may take |w_perp| = |w x e| in place of |w| (Motion::spin_across). The
// curvature bounds (|m''|) keep |w|. Spheroids declare it (Ellipsoid). Superquadrics do not
// yet, though one whose two other semi-axes are equal with exponents 2 is of revolution about
// its third axis (a flat-ended "cylinder" (2, 2, p) with a = b, about z).
template <Shape S>
int revolution_axis(const S& s) {
  if constexpr (requires { { s.revolution_axis() } -> std::convertible_to<int>; }) {
    return s.revolution_axis();
  } else {
    return -1;
  }
}
template <Shape S>
double rotation_lever(const S& s) {
  if constexpr (requires { { s.rotation_lever() } -> std::convertible_to<double>; }) {
    return s.rotation_lever();
  } else {
    return rotation_lever_bound(s.bounding_radius(), s.inscribed_radius());
  }
}

// Ray-surface intersection for any shape: the root s > 0 of phi(s) = f(s u), |u| = 1, on the
// bracket [inscribed_radius, bounding_radius] (phi is negative below and positive above).
// Safeguarded Newton (bisection whenever a Newton step leaves the bracket).  Shapes with a
// closed form (sphere, ellipsoid) do not use it; it is here for shapes that may not have one.
template <Shape S>
Vec3 ray_surface_generic(const S& s, const Vec3& dir) {
  const Vec3 u = dir.normalized();
  double lo = 0.999 * s.inscribed_radius(), hi = 1.001 * s.bounding_radius();
  double x = 0.5 * (lo + hi);
  for (int it = 0; it < 200; ++it) {
    const Vec3 p = x * u;
    const double phi = s.f(p);
    if (phi == 0.0) break;
    (phi < 0.0 ? lo : hi) = x;
    const double dphi = s.grad(p).dot(u);
    double xn = (dphi > 0.0) ? x - phi / dphi : 0.5 * (lo + hi);
    if (!(xn > lo && xn < hi)) xn = 0.5 * (lo + hi);
    if (std::abs(xn - x) <= 1e-15 * hi) { x = xn; break; }
    x = xn;
  }
  return x * u;
}

}  // namespace hb
