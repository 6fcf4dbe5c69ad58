// Slow, independent superquadric for the tests (shares no code with shapes/superquadric.hpp).
//
// It uses the paper's own implicit function f = sum |x_i/a_i|^e_i - 1 (Eq. SQdef), and a
// support function computed by plain bisection, in long double, on log lambda of the Lagrange
// condition sum_i (|d_i| a_i / (e_i lambda))^(e_i/(e_i-1)) = 1 (the multiplier equation of
// max d.x over the body).  Bisection cannot fail or overshoot; it is slow, which is fine here.
// The support Hessian (used only to choose steps in ref::reference_distance, never in a
// compared value) is dx/dd from implicit differentiation of the same condition.
//
// polished_distance: ref::reference_distance followed by a compass search on the unit sphere.
// At the normal of a flat face the separation s(n) = n.(r_B - r_A) - h_A(n) - h_B(-n) is C^1
// but not C^2: across the face normal h varies like |n_t|^q, q = p/(p-1) in (1, 2), and a
// Newton step maps the offset n_t to n_t (q-2)/(q-1); for p = 3 that is exactly -n_t, a
// 2-cycle that reference_distance (which accepts steps that do not decrease s) follows until
// its iteration limit, up to 40 % short of the distance.  The compass search moves n by h
// along 8 tangent directions, accepts only increases of s and halves h when none is found,
// down to h = 1e-14 rad; s is C^1, so it converges to the maximum.  Every s(n) is a lower
// bound of the distance of separated bodies (a separating plane), so the result is one too.
#pragma once
#include <algorithm>
#include <cmath>

#include "geometry/reference_distance.hpp"
#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb::ref {

struct SlowSuperquadric {
  double a = 1.0, b = 1.0, c = 1.0;
  double n = 2.0, m = 2.0, p = 2.0;

  double ax(int i) const { return i == 0 ? a : (i == 1 ? b : c); }
  double ex(int i) const { return i == 0 ? n : (i == 1 ? m : p); }

  double f(const Vec3& x) const {
    double s = 0.0;
    for (int i = 0; i < 3; ++i) s += std::pow(std::abs(x[i]) / ax(i), ex(i));
    return s - 1.0;
  }
  Vec3 grad(const Vec3& x) const {
    Vec3 g;
    for (int i = 0; i < 3; ++i)
      g[i] = std::copysign(ex(i) / ax(i) * std::pow(std::abs(x[i]) / ax(i), ex(i) - 1.0), x[i]);
    return g;
  }
  Mat3 hessian(const Vec3& x) const {
    Mat3 h = Mat3::Zero();
    for (int i = 0; i < 3; ++i)
      h(i, i) = ex(i) * (ex(i) - 1.0) / (ax(i) * ax(i)) *
                std::pow(std::abs(x[i]) / ax(i), ex(i) - 2.0);
    return h;
  }
  double volume() const { return 8.0 * a * b * c; }  // an upper bound; not compared
  double bounding_radius() const { return std::sqrt(a * a + b * b + c * c); }  // safe bound
  double inscribed_radius() const { return std::min({a, b, c}); }
  Vec3 half_extents() const { return Vec3(a, b, c); }
  Vec3 ray_surface(const Vec3& u) const { return ray_surface_generic(*this, u); }

  // sum_i (|d_i| a_i / (e_i lambda))^(e_i/(e_i-1)) - 1 at log lambda = s (decreasing in s).
  long double excess(const Vec3& d, long double s) const {
    long double sum = 0.0L;
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0.0) continue;
      const long double ci = std::abs(static_cast<long double>(d[i])) * ax(i) / ex(i);
      sum += std::exp(ex(i) / (ex(i) - 1.0L) * (std::log(ci) - s));
    }
    return sum - 1.0L;
  }
  long double log_lambda(const Vec3& d) const {
    long double lo = std::log(static_cast<long double>(d.cwiseAbs().maxCoeff()) *
                              std::min({a, b, c}) / std::max({n, m, p})) - 1.0L;
    long double hi = lo + 2.0L;
    while (excess(d, lo) < 0.0L) lo -= 1.0L;
    while (excess(d, hi) > 0.0L) hi += 1.0L;
    for (int it = 0; it < 80; ++it) {
      const long double mid = 0.5L * (lo + hi);
      (excess(d, mid) > 0.0L ? lo : hi) = mid;
    }
    return 0.5L * (lo + hi);
  }
  Vec3 support_point(const Vec3& d) const {
    const long double s = log_lambda(d);
    Vec3 x;
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0.0) {
        x[i] = 0.0;
        continue;
      }
      const long double ci = std::abs(static_cast<long double>(d[i])) * ax(i) / ex(i);
      const long double t = std::exp((std::log(ci) - s) / (ex(i) - 1.0L));
      x[i] = static_cast<double>(std::copysign(ax(i) * t, static_cast<long double>(d[i])));
    }
    return x;
  }
  double support(const Vec3& d) const {
    const Vec3 x = support_point(d);
    long double h = 0.0L;
    for (int i = 0; i < 3; ++i) h += static_cast<long double>(d[i]) * x[i];
    return static_cast<double>(h);
  }
  // x_i = sgn(d_i) a_i (c_i/lambda)^(1/(e_i-1)):  dx_i = x_i/(e_i-1) (dd_i/d_i - dlog lambda),
  // and dlog lambda = sum_j w_j dd_j/d_j / sum_j w_j with w_j = q_j t_j^e_j.
  Mat3 support_hessian(const Vec3& d) const {
    const Vec3 x = support_point(d);
    Vec3 u = Vec3::Zero(), diag = Vec3::Zero();
    double wsum = 0.0;
    Vec3 wd = Vec3::Zero();  // w_j / d_j
    for (int i = 0; i < 3; ++i) {
      if (d[i] == 0.0) {
        diag[i] = ex(i) == 2.0 ? ax(i) * ax(i) / (2.0 * std::exp(double(log_lambda(d)))) : 1e12;
        continue;
      }
      const double t = std::abs(x[i]) / ax(i);
      const double w = ex(i) / (ex(i) - 1.0) * std::pow(t, ex(i));
      wsum += w;
      wd[i] = w / d[i];
      u[i] = x[i] / (ex(i) - 1.0);
      diag[i] = u[i] / d[i];
    }
    Mat3 H = Mat3(diag.asDiagonal());
    H -= u * wd.transpose() / wsum;
    return 0.5 * (H + H.transpose());
  }
};

static_assert(SupportShape<SlowSuperquadric>);

// See the header.  `evaluations` (optional) receives the number of s(n) evaluations.
template <SupportShape SA, SupportShape SB>
RefDistance polished_distance(const SA& a, const Pose& pa, const SB& b, const Pose& pb,
                              const Vec3* hint = nullptr, int* evaluations = nullptr) {
  RefDistance out = reference_distance(a, pa, b, pb, hint);
  const Separation<SA, SB> S{a, b, pa, pb};
  Vec3 n = out.n.normalized();
  double s = S.value(n), h = 1e-2;
  int evals = 0;
  while (h > 1e-14 && evals < 100000) {
    const Vec3 e1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    const Vec3 e2 = n.cross(e1);
    bool moved = false;
    for (int k = 0; k < 8 && !moved; ++k) {
      const double angle = 0.25 * kPi * k;
      const Vec3 m = (n + h * (std::cos(angle) * e1 + std::sin(angle) * e2)).normalized();
      const double sm = S.value(m);
      ++evals;
      if (sm > s) {
        n = m;
        s = sm;
        moved = true;
      }
    }
    if (!moved) h *= 0.5;
  }
  out.distance = s;
  out.n = n;
  out.point_a = S.xa(n);
  out.point_b = S.xb(n);
  if (evaluations) *evaluations = evals;
  return out;
}

}  // namespace hb::ref
