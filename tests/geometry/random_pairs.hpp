// Random shapes, orientations and pairs at a prescribed exact distance (tests only).
//
// place_at_distance: given A's pose, B's orientation and a unit direction n, put B so that its
// support point along -n sits at x_A(n) + gap n, x_A(n) the support point of A along n.  Then
// x_B - x_A = gap n with antiparallel normals: for gap > 0 the planes through the two points
// normal to n separate the bodies, so the distance is exactly `gap` (up to the rounding of the
// construction); for gap < 0 it is a penetration stationary point of depth |gap|.
#pragma once
#include <cmath>
#include <cstdlib>
#include <random>

#include "geometry/posed.hpp"
#include "math/types.hpp"
#include "shapes/ellipsoid.hpp"

namespace hb::testing {

// Sample counts: full in optimised builds, the fraction debug_fraction of it (at least
// min_count) under Debug/sanitizers (unoptimised Eigen is ~100x slower); HB_TEST_SCALE (a
// positive number) multiplies them in both.
inline int scaled_count(int release_count, double debug_fraction = 0.02, int min_count = 20) {
#ifdef NDEBUG
  double f = 1.0;
  (void)debug_fraction;
#else
  double f = debug_fraction;
#endif
  if (const char* s = std::getenv("HB_TEST_SCALE")) f *= std::atof(s);
  const int n = static_cast<int>(release_count * f);
  return n < min_count ? min_count : n;
}

struct Rng {
  std::mt19937_64 g;
  explicit Rng(uint64_t seed) : g(seed) {}
  double uni(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(g); }
  double log_uni(double lo, double hi) { return std::exp(uni(std::log(lo), std::log(hi))); }
  double normal() { return std::normal_distribution<double>(0.0, 1.0)(g); }
  Vec3 unit() { return Vec3(normal(), normal(), normal()).normalized(); }
  Vec3 ball(double r) { return r * std::cbrt(uni(0, 1)) * unit(); }
  Quat quat() {
    Quat q(normal(), normal(), normal(), normal());
    q.normalize();
    return q;
  }
  Mat3 rotation() { return quat().toRotationMatrix(); }
  // Ellipsoid with aspect ratio (max/min semi-axis) up to max_aspect, largest semi-axis in
  // [0.5, 2]: prolate, oblate or triaxial with equal probability.
  Ellipsoid ellipsoid(double max_aspect = 10.0) {
    const double X = log_uni(1.0, max_aspect);
    const double big = uni(0.5, 2.0), small = big / X;
    const int kind = static_cast<int>(uni(0, 3));
    Vec3 ax;
    if (kind == 0) ax = Vec3(big, small, small);
    else if (kind == 1) ax = Vec3(small, big, big);
    else ax = Vec3(big, log_uni(small, big), small);
    // random permutation of the axes
    for (int i = 2; i > 0; --i) std::swap(ax[i], ax[std::uniform_int_distribution<int>(0, i)(g)]);
    return Ellipsoid{ax[0], ax[1], ax[2]};
  }
};

// Rotation by a small random angle (radians) about a random axis.
inline Mat3 small_rotation(Rng& r, double angle) {
  return Eigen::AngleAxisd(angle, r.unit()).toRotationMatrix();
}

template <SupportShape SA, SupportShape SB>
Pose place_at_distance(const SA& a, const Pose& pa, const SB& b, const Mat3& Rb, const Vec3& n,
                       double gap) {
  const Vec3 xa = pa.r + pa.R * a.support_point(pa.R.transpose() * n);
  const Vec3 pb = Rb * b.support_point(-(Rb.transpose() * n));  // relative to B's centre
  return Pose{xa + gap * n - pb, Rb};
}

}  // namespace hb::testing
