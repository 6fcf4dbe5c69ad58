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

}  // namespace hb
