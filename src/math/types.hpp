// Small fixed-size types used everywhere: aliases over Eigen, no operators of our own.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

namespace hb {

using Vec3 = Eigen::Matrix<double, 3, 1>;
using Mat3 = Eigen::Matrix<double, 3, 3>;
using Quat = Eigen::Quaternion<double>;  // scalar-first [w,x,y,z] in files; rotates body -> lab

inline constexpr double kInf = std::numeric_limits<double>::infinity();
inline constexpr double kPi = 3.14159265358979323846;

// Cross-product matrix: skew(w) * y == w.cross(y).
inline Mat3 skew(const Vec3& w) {
  Mat3 m;
  m << 0.0, -w.z(), w.y(), w.z(), 0.0, -w.x(), -w.y(), w.x(), 0.0;
  return m;
}

inline double sqr(double x) { return x * x; }

// u scaled onto the unit sphere. For |u|^2 = 1 + e with |e| <= 1e-8 (a unit vector or
// quaternion after a few roundings) by one Newton step for 1 / sqrt(|u|^2) from 1, applied as
// u - (e / 2) u: its error 3 e^2 / 8 is below rounding, and it needs neither the square root nor
// the division of normalized() (both on the critical path of the rotation and axis code;
// e = |u|^2 - 1 is exact, and only the last addition rounds). Farther from 1, normalized().
template <class V>
[[gnu::noinline]] V normalized_out_of_line(const V& u) {
  return u.normalized();
}
template <class V>
[[gnu::always_inline]] inline V near_unit_normalized(const V& u) {
  const double e = u.squaredNorm() - 1.0;
  if (std::abs(e) <= 1e-8) [[likely]] return u - (0.5 * e) * u;
  return normalized_out_of_line(u);  // the rare path kept out of the callers' loops
}

}  // namespace hb
