// sin and cos of one angle together, fast for the small angles of event-driven steps.
//
// The free rotation turns a body by half its angle per step (motion/free_rotation.hpp) and the
// axis gap turns its axis back by the angle a body spins in a window (contact/axis_gap.hpp);
// both angles are almost always well below 1 rad, and libm's sincos was 3 % of an ellipsoid
// run's instructions.  For |x| <= kSinCosPolyMax this takes the Taylor polynomials of sin
// through x^17 and cos through x^18 in Horner form: the first omitted terms are
// |x|^19 / 19! <= 1.2e-19 and |x|^20 / 20! <= 5e-21, well below half an ulp of the results
// (sin(0.8) = 0.717, cos(0.8) = 0.697), so what is left is the rounding of a dozen
// multiply-adds, a few ulp at most (tests/math/test_sin_cos.cpp measures it against long
// double).  Beyond, std::sin and std::cos.
#pragma once
#include <cmath>

namespace hb {

struct SinCos {
  double s, c;
};

inline constexpr double kSinCosPolyMax = 0.8;

namespace sin_cos_detail {
// The Horner parts of the two Taylor polynomials in z = x^2: sin x = x (1 + z ps), cos x =
// 1 + z pc.
[[gnu::always_inline]] inline SinCos series(double z) {
  // sin x = x + x z (-1/3! + z (1/5! - ...)): the correction is below x/6, so its rounding
  // error is a fraction of an ulp of the result
  const double ps =
      -1.0 / 6.0 +
      z * (1.0 / 120.0 +
           z * (-1.0 / 5040.0 +
                z * (1.0 / 362880.0 +
                     z * (-1.0 / 39916800.0 +
                          z * (1.0 / 6227020800.0 +
                               z * (-1.0 / 1307674368000.0 + z * (1.0 / 355687428096000.0)))))));
  // cos x = 1 + z (-1/2! + z (1/4! - ...))
  const double pc =
      -0.5 +
      z * (1.0 / 24.0 +
           z * (-1.0 / 720.0 +
                z * (1.0 / 40320.0 +
                     z * (-1.0 / 3628800.0 +
                          z * (1.0 / 479001600.0 +
                               z * (-1.0 / 87178291200.0 +
                                    z * (1.0 / 20922789888000.0 +
                                         z * (-1.0 / 6402373705728000.0))))))));
  return {ps, pc};
}
}  // namespace sin_cos_detail

inline SinCos sin_cos(double x) {
  if (!(std::abs(x) <= kSinCosPolyMax)) return {std::sin(x), std::cos(x)};
  const double z = x * x;
  const SinCos p = sin_cos_detail::series(z);
  return {x + (x * z) * p.s, 1.0 + z * p.c};
}

// sin(x) / x and cos(x) from z = x^2 alone, for z <= kSinCosPolyMax^2 (the caller checks): the
// same polynomials, without the square root that x would cost (a rotation by the angle
// |w| dt / 2 needs only |w|^2, motion/free_rotation.hpp). s = 1 + z ps, a few ulp like sin_cos.
inline SinCos sinc_cos_of_square(double z) {
  const SinCos p = sin_cos_detail::series(z);
  return {1.0 + z * p.s, 1.0 + z * p.c};
}

}  // namespace hb
