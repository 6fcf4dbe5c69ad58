// Principal moments of inertia of uniform-density solids of the engine shapes, given the mass.
//
// All three shapes are symmetric under x -> -x, y -> -y and z -> -z separately, so every product
// of inertia int x y dV etc. vanishes and the body axes are principal.  With <x^2> the mean of x^2
// over the solid (second moment / volume) and uniform density,
//     I = m ( <y^2> + <z^2>,  <x^2> + <z^2>,  <x^2> + <y^2> )   (about body x, y, z).
//
// Sphere (radius r):  <x^2> = r^2/5, so I = 2/5 m r^2 about every axis.
// Ellipsoid (a, b, c): the map x = a u, y = b v, z = c w takes the unit ball onto it with constant
//     Jacobian, so <x^2> = a^2 <u^2>_ball = a^2/5 etc. and
//     I = m/5 (b^2 + c^2,  a^2 + c^2,  a^2 + b^2).
//
// Superquadric |x/a|^n + |y/b|^m + |z/c|^p <= 1.  Generalised Dirichlet integral: for a_i, e_i > 0
// and k_i > -1,
//     J(k) = int_{sum |x_i/a_i|^e_i <= 1} prod_i |x_i|^k_i dV
//          = 8 prod_i [ a_i^(k_i+1) Gamma(alpha_i) / e_i ] / Gamma(1 + sum_i alpha_i),
//     alpha_i = (k_i + 1) / e_i.
// Derivation: the integrand and the body are even in each x_i, so J is 8 times the integral over
// the first octant.  There substitute x_i = a_i u_i^(1/e_i), u_i in [0, 1]:
//     dx_i = (a_i / e_i) u_i^(1/e_i - 1) du_i,   x_i^k_i = a_i^k_i u_i^(k_i/e_i),
// and the body becomes the simplex u_i >= 0, sum u_i <= 1, so
//     J = 8 prod_i (a_i^(k_i+1) / e_i) * int_simplex prod_i u_i^(alpha_i - 1) du.
// The Dirichlet integral over the 3-simplex is
//     int_simplex prod u_i^(alpha_i - 1) du = prod Gamma(alpha_i) / Gamma(1 + sum alpha_i)
// (integrate out one variable at a time: int_0^s u^(alpha-1) (s-u)^(beta-1) du
//  = s^(alpha+beta-1) B(alpha, beta), and the Beta functions telescope; the extra "1 +" comes from
// the inequality, i.e. a 4th Dirichlet variable u_0 = 1 - sum u_i with alpha_0 = 1).
// Using alpha Gamma(alpha) = Gamma(1 + alpha) and e_i alpha_i = k_i + 1,
//     J(k) = 8 prod_i [ a_i^(k_i+1) Gamma(1 + alpha_i) / (k_i + 1) ] / Gamma(1 + sum_i alpha_i).
// k = 0 gives the volume 8 abc Gamma(1+1/n) Gamma(1+1/m) Gamma(1+1/p) / Gamma(1+1/n+1/m+1/p)
// (Superquadric::volume()).  k = (2, 0, 0) divided by the volume (only alpha_x changes,
// 1/n -> 3/n) gives, with s = 1/n + 1/m + 1/p,
//     <x^2> = a^2 Gamma(1 + 3/n) / (3 Gamma(1 + 1/n)) * Gamma(1 + s) / Gamma(1 + s + 2/n),
// and likewise for y (b, m) and z (c, p).  Checks: n = m = p = 2 (s = 3/2) gives
// (Gamma(5/2) / (3 Gamma(3/2))) (Gamma(5/2) / Gamma(7/2)) = (1/2)(2/5) = 1/5, the ellipsoid; as
// all exponents -> infinity every Gamma argument -> 1 and <x^2> -> a^2/3, the box
// [-a, a] x [-b, b] x [-c, c] with I = m/3 (b^2 + c^2, ...).  Expanding
// ln Gamma(1 + e) = -gamma e + zeta(2) e^2 / 2 - ..., the O(1/e) terms cancel and, with
// eps_i = 1/e_i, <x^2> = a^2/3 (1 - (pi^2/3) eps_x (eps_y + eps_z) + O(eps^3)): the approach to the
// box is quadratic in 1/exponent (the edges and corners are rounded over a width O(1/e)).
//
// Numerics.  Every Gamma argument above is 1 + (something in (0, 3/2]) for exponents >= 2
// (at most 1 + s + 2/e <= 3.5), so nothing can overflow and no Gamma(1/e) ~ e blow-up occurs for
// large exponents (the naive Gamma(3/n) / Gamma(1/n) would divide two numbers ~n).  The ratios are
// formed as exp of lgamma differences: lgamma is O(1) on [1, 3.5] with an absolute error of a few
// 1e-16 (also near its zeros at 1 and 2), so each ratio has a relative error of a few 1e-16 for
// any exponents >= 2 (also e -> infinity, where 1 + 3/e rounds to 1 and the limit a^2/3 comes out
// exactly), and the formulas stay finite for any positive exponents.  (std::lgamma writes the
// global signgam in glibc: harmless here, the engine is single-threaded.)
#pragma once
#include <cmath>

#include "math/types.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/registry.hpp"
#include "shapes/superquadric.hpp"

namespace hb {

// J(k) = int prod_i |x_i|^k_i dV over sum_i |x_i / axes_i|^exponents_i <= 1 (see header): any
// axes_i > 0, exponents_i > 0, k_i > -1 (real).  k = 0 is the volume.
inline double superquadric_moment(const Vec3& axes, const Vec3& exponents, const Vec3& k) {
  double log_j = std::log(8.0), sum_alpha = 0.0;
  for (int i = 0; i < 3; ++i) {
    const double alpha = (k[i] + 1.0) / exponents[i];
    sum_alpha += alpha;
    log_j += (k[i] + 1.0) * std::log(axes[i]) + std::lgamma(1.0 + alpha) - std::log(k[i] + 1.0);
  }
  return std::exp(log_j - std::lgamma(1.0 + sum_alpha));
}
inline double superquadric_moment(const Superquadric& s, const Vec3& k) {
  return superquadric_moment(s.axes(), s.exponents(), k);
}

// (<x^2>, <y^2>, <z^2>): second moments over the solid divided by its volume (see header), formed
// directly as Gamma ratios (not as two J's) so that a^3 b c and the common factors cancel exactly.
inline Vec3 superquadric_mean_squares(const Vec3& axes, const Vec3& exponents) {
  const Vec3 eps = exponents.cwiseInverse();
  const double s = eps.sum(), lg_s = std::lgamma(1.0 + s);
  Vec3 r;
  for (int i = 0; i < 3; ++i) {
    const double log_ratio = std::lgamma(1.0 + 3.0 * eps[i]) - std::lgamma(1.0 + eps[i]) + lg_s -
                             std::lgamma(1.0 + s + 2.0 * eps[i]);
    r[i] = axes[i] * axes[i] / 3.0 * std::exp(log_ratio);
  }
  return r;
}

// Principal moments about body x, y, z from the mean squares of a body symmetric about its three
// coordinate planes: m (<y^2> + <z^2>, <x^2> + <z^2>, <x^2> + <y^2>).
inline Vec3 inertia_from_mean_squares(const Vec3& msq, double mass) {
  return mass * Vec3(msq[1] + msq[2], msq[0] + msq[2], msq[0] + msq[1]);
}

// Principal moments of inertia (about body x, y, z, through the centre) of the uniform solid.
inline Vec3 uniform_inertia(const Sphere& s, double mass) {
  return Vec3::Constant(0.4 * mass * s.radius * s.radius);
}
inline Vec3 uniform_inertia(const Ellipsoid& e, double mass) {
  return inertia_from_mean_squares(e.sq() / 5.0, mass);
}
inline Vec3 uniform_inertia(const Superquadric& q, double mass) {
  return inertia_from_mean_squares(superquadric_mean_squares(q.axes(), q.exponents()), mass);
}

// Principal moments of the uniform solid of any engine shape (the species default inertia).
inline Vec3 uniform_inertia(const AnyShape& s, double mass) {
  return std::visit([&](const auto& x) { return uniform_inertia(x, mass); }, s);
}

}  // namespace hb
