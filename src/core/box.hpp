// Orthorhombic box [0, L) with the minimum-image convention along its periodic axes. An axis
// that is not periodic is bounded by hard walls at 0 and L (locals/walls.hpp): separations along
// it are never wrapped, and positions along it stay in [0, L] because the walls keep them there.
#pragma once
#include <array>
#include <cmath>

#include "math/types.hpp"

namespace hb {

// One periodic axis of length L (half = L / 2), for loops over raw coordinates: the minimum
// image of a separation known to lie within (-1.5 L, 1.5 L), and a coordinate known to lie within
// [-L, 2 L) wrapped into [0, L).  One compare each way, no division.
inline double image_once(double d, double L, double half) {
  if (d > half) return d - L;
  if (d < -half) return d + L;
  return d;
}
inline double wrap_once(double x, double L) {
  if (x >= L) return x - L;
  if (x < 0.0) return x + L;
  return x;
}

struct Box {
  Vec3 L = Vec3::Ones();
  std::array<bool, 3> periodic{true, true, true};

  double volume() const { return L.x() * L.y() * L.z(); }
  bool fully_periodic() const { return periodic[0] && periodic[1] && periodic[2]; }
  Vec3 centre() const { return 0.5 * L; }

  // Minimum image of a separation vector; valid for any |d| (not only |d| < 1.5 L).
  Vec3 minimum_image(Vec3 d) const {
    for (int k = 0; k < 3; ++k)
      if (periodic[k]) d[k] -= L[k] * std::nearbyint(d[k] / L[k]);
    return d;
  }
  // Minimum image by repeated subtraction: exact for any d, and one compare per axis in the
  // usual case of centres stored inside or near the box (no division). Hot path of prediction;
  // always inlined: GCC's choice flips with unrelated changes to its callers, and out of line it
  // costs ~2.5k instructions a collision (callgrind, ellipsoids at phi = 0.4). (Measured and
  // dropped: the first step each way as arithmetic instead of a branch, x -= L ((x > L/2) -
  // (x < -L/2)): +1.2 % instructions, and slower in alternating runs at X0 = 10 and X0 = 1.)
  [[gnu::always_inline]] inline Vec3 near_image(Vec3 d) const {
    for (int k = 0; k < 3; ++k) {
      if (!periodic[k]) continue;
      while (d[k] > 0.5 * L[k]) d[k] -= L[k];
      while (d[k] < -0.5 * L[k]) d[k] += L[k];
    }
    return d;
  }
  // Wrap a position into [0, L) along the periodic axes; returns the image shift applied (in box
  // lengths).
  Eigen::Vector3i wrap(Vec3& r) const {
    Eigen::Vector3i shift(0, 0, 0);
    for (int k = 0; k < 3; ++k) {
      if (!periodic[k]) continue;
      const double s = std::floor(r[k] / L[k]);
      if (s != 0.0) {
        r[k] -= s * L[k];
        if (r[k] >= L[k]) r[k] -= L[k];  // rounding of r - s L can land on L itself
        if (r[k] < 0.0) r[k] = 0.0;
        shift[k] = static_cast<int>(s);
      }
    }
    return shift;
  }
};

}  // namespace hb
