// Ellipsoid with semi-axes (a, b, c) along body x, y, z (uniaxial or triaxial), and the sphere.
//
//   f(x) = x^T X x - 1,  X = diag(a^-2, b^-2, c^-2)        (ERRATA 2: squares, and the "- 1")
//   grad f = 2 X x,  Hessian = 2 X  (constant)
//   volume = 4/3 pi a b c,  bounding radius = max(a,b,c),  inscribed radius = min(a,b,c)
//   ray from the centre along u: s u with s = 1 / sqrt(u^T X u)
//   support h(n) = sqrt(n^T M n), M = diag(a^2, b^2, c^2) = X^-1; support point M n / h(n)
//   (the surface point whose outward normal 2 X p = 2 n / h is parallel to n);
//   Hessian of h: (M - (M n)(M n)^T / h^2) / h.
//
// The sphere uses the same scaled form f = |x|^2 / r^2 - 1 so that a sphere and an ellipsoid
// with a = b = c = r are the same function (the generic solvers see identical input).
#pragma once
#include <algorithm>
#include <cmath>

#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb {

struct Ellipsoid {
  static constexpr const char* kName = "ellipsoid";
  static constexpr bool kCentrallySymmetric = true;  // shapes/shape.hpp
  static constexpr bool kBoundedCurvature = true;    // shapes/shape.hpp
  // The semi-axes: set them through the constructor (the squares and inverse squares the
  // solvers use at every evaluation are kept beside them; three divisions per f, grad or
  // Hessian otherwise; and the largest and smallest semi-axes, and the largest radius of
  // curvature, which the prediction's axis pre-filter asks for per candidate: a division each
  // time otherwise). Read-only in practice: a shape is rebuilt, never edited.
  double a = 1.0, b = 1.0, c = 1.0;

  Ellipsoid() = default;
  Ellipsoid(double a_, double b_, double c_)
      : a(a_), b(b_), c(c_), sq_(a_ * a_, b_ * b_, c_ * c_),
        inv_sq_(1.0 / (a_ * a_), 1.0 / (b_ * b_), 1.0 / (c_ * c_)),
        max_(std::max({a_, b_, c_})), min_(std::min({a_, b_, c_})), rho_max_(max_ * max_ / min_) {}

  const Vec3& inv_sq() const { return inv_sq_; }
  const Vec3& sq() const { return sq_; }

  double f(const Vec3& x) const { return x.cwiseProduct(x).dot(inv_sq()) - 1.0; }
  Vec3 grad(const Vec3& x) const { return 2.0 * x.cwiseProduct(inv_sq()); }
  Mat3 hessian(const Vec3& /*x*/) const { return Mat3(2.0 * inv_sq().asDiagonal()); }

  double volume() const { return 4.0 / 3.0 * kPi * a * b * c; }
  double bounding_radius() const { return max_; }
  double inscribed_radius() const { return min_; }
  // max |p x m| over unit m (shapes/shape.hpp, rotation_lever): with weights w_i = m_i^2 and
  // X = a_i^2 with probability w_i, |p x m|^2 = |p|^2 - h^2 = E[X^2] / E[X] - E[X] = Var X / E X,
  // whose largest value for X in [a_min^2, a_max^2] is (a_max - a_min)^2 (attained by two
  // values at the ends of the range).
  double rotation_lever() const { return max_ - min_; }
  // A spheroid (two equal semi-axes) is a body of revolution about its third axis
  // (shapes/shape.hpp). A sphere declares none: its rotation lever is 0, so it would gain
  // nothing for the bound's cost.
  int revolution_axis() const {
    if (a == b && b == c) return -1;
    return b == c ? 0 : a == c ? 1 : a == b ? 2 : -1;
  }
  Vec3 half_extents() const { return Vec3(a, b, c); }
  Vec3 ray_surface(const Vec3& u) const {
    return u / std::sqrt(u.cwiseProduct(u).dot(inv_sq()));
  }

  double support(const Vec3& n) const { return std::sqrt(n.cwiseProduct(n).dot(sq())); }
  Vec3 support_point(const Vec3& n) const { return support_point(n, support(n)); }
  Vec3 support_point(const Vec3& n, double h) const { return n.cwiseProduct(sq()) / h; }  // h = support(n)
  // Largest principal radius of curvature of the surface, max(a,b,c)^2 / min(a,b,c): it bounds
  // the support Hessian, |m^T (d^2 h) m| <= rho_max |m|^2 for unit n (used by the contact solver).
  double max_curvature_radius() const { return rho_max_; }
  Mat3 support_hessian(const Vec3& n) const {
    const double h = support(n);
    const Vec3 mn = n.cwiseProduct(sq());
    return (Mat3(sq().asDiagonal()) - mn * mn.transpose() / (h * h)) / h;
  }
  // (u^T H u, u^T H v, v^T H v) for H = support_hessian(n) = (M - p p^T) / h, given the support
  // point p = M n / h (h = p.n): no matrix formed (contact/axis_gap.hpp).
  Vec3 support_hessian_forms(const Vec3& n, const Vec3& p, const Vec3& u, const Vec3& v) const {
    const double h = p.dot(n), pu = p.dot(u), pv = p.dot(v);
    const Vec3 Mu = u.cwiseProduct(sq());
    return Vec3(u.dot(Mu) - pu * pu, v.dot(Mu) - pu * pv, v.dot(v.cwiseProduct(sq())) - pv * pv) / h;
  }

 private:
  Vec3 sq_ = Vec3::Ones(), inv_sq_ = Vec3::Ones();
  double max_ = 1.0, min_ = 1.0, rho_max_ = 1.0;
};

struct Sphere {
  static constexpr const char* kName = "sphere";
  static constexpr bool kCentrallySymmetric = true;  // shapes/shape.hpp
  static constexpr bool kBoundedCurvature = true;    // shapes/shape.hpp
  double radius = 1.0;

  double f(const Vec3& x) const { return x.squaredNorm() / (radius * radius) - 1.0; }
  Vec3 grad(const Vec3& x) const { return (2.0 / (radius * radius)) * x; }
  Mat3 hessian(const Vec3& /*x*/) const {
    return Mat3::Identity() * (2.0 / (radius * radius));
  }

  double volume() const { return 4.0 / 3.0 * kPi * radius * radius * radius; }
  double bounding_radius() const { return radius; }
  double inscribed_radius() const { return radius; }
  double rotation_lever() const { return 0.0; }  // a support point lies on the line along m
  Vec3 half_extents() const { return Vec3::Constant(radius); }
  Vec3 ray_surface(const Vec3& u) const { return u * (radius / u.norm()); }

  double support(const Vec3& n) const { return radius * n.norm(); }
  double max_curvature_radius() const { return radius; }
  Vec3 support_point(const Vec3& n) const { return n * (radius / n.norm()); }
  Mat3 support_hessian(const Vec3& n) const {
    const double nn = n.norm();
    return (radius / nn) * (Mat3::Identity() - n * n.transpose() / (nn * nn));
  }
  // (u^T H u, u^T H v, v^T H v) for H = support_hessian(n) (p unused: it is r n / |n|).
  Vec3 support_hessian_forms(const Vec3& n, const Vec3& /*p*/, const Vec3& u, const Vec3& v) const {
    const double nn2 = n.squaredNorm(), k = radius / std::sqrt(nn2), nu = n.dot(u), nv = n.dot(v);
    return k * Vec3(u.dot(u) - nu * nu / nn2, u.dot(v) - nu * nv / nn2, v.dot(v) - nv * nv / nn2);
  }
};

static_assert(SupportShape<Ellipsoid>);
static_assert(SupportShape<Sphere>);

}  // namespace hb
