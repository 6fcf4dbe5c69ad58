// Closest points of two line segments, and the core segment of an elongated body: the cheap
// "rod" picture of a long body that gives the separating-axis search a starting direction
// (contact/axis_gap.hpp, separating_axis).
//
// Segments P(s) = p + s u, s in [-hp, hp], and Q(t) = q + t v, t in [-hq, hq], u and v unit.
// With w = p - q, b = u.v, d = u.w, e = v.w, the squared distance
//     F(s, t) = |w + s u - t v|^2
// is convex; its stationarity conditions are
//     dF/ds = 0:  s = b t - d,         dF/dt = 0:  t = e + b s,
// so the unconstrained minimum is s = (b e - d) / (1 - b^2). On the box [-hp, hp] x [-hq, hq]:
// clamp s, take the best t for it (t = e + b s, clamped), then the best s for that t
// (s = b t - d, clamped) -- the order of the standard derivation (Ericson, Real-Time Collision
// Detection, section 5.1.9). When t was not clamped the last step returns the same s. Nearly parallel segments (1 - b^2 <= 1e-12), where
// that formula loses its digits and one pass of the alternation does not converge, take the best
// of the four edges of the box instead. The tests compare with a dense grid and the optimality
// conditions.
#pragma once
#include <algorithm>
#include <cmath>

#include "math/types.hpp"

namespace hb {

struct SegmentPoints {
  double s = 0.0, t = 0.0;  // parameters of the closest points P(s), Q(t)
};

inline SegmentPoints closest_segment_points(const Vec3& p, const Vec3& u, double hp, const Vec3& q,
                                            const Vec3& v, double hq) {
  const Vec3 w = p - q;
  const double b = u.dot(v), d = u.dot(w), e = v.dot(w);
  const double den = 1.0 - b * b;
  if (den > 1e-12) {
    double s = std::clamp((b * e - d) / den, -hp, hp);
    const double t = std::clamp(e + b * s, -hq, hq);
    s = std::clamp(b * t - d, -hp, hp);
    return {s, t};
  }
  // (Nearly) parallel: the minima form a valley along the segments that meets the boundary of
  // the box, up to F changing by (angle x length)^2 along it; the best of the four edges
  // (s = +-hp with its best t, t = +-hq with its best s) is the minimum to that accuracy.
  SegmentPoints best;
  double fbest = kInf;
  auto consider = [&](double s, double t) {
    const double f = (w + s * u - t * v).squaredNorm();
    if (f < fbest) fbest = f, best = {s, t};
  };
  for (const double s : {-hp, hp}) consider(s, std::clamp(e + b * s, -hq, hq));
  for (const double t : {-hq, hq}) consider(std::clamp(b * t - d, -hp, hp), t);
  return best;
}

// The core segment of a body with half extents (a, b, c) along its body axes: along the axis of
// the largest half extent, of half-length (largest - second largest). Zero for spheres and for
// oblate bodies (two equal largest extents): their core is a point or a disk, not a rod. A
// body is a rod when its core is longer than its thickness (the second largest half extent):
// a prolate ellipsoid of aspect ratio above 2.
struct CoreSegment {
  int axis = 0;          // body axis (0, 1, 2) of the segment
  double half = 0.0;     // half-length
  double thick = 0.0;    // second largest half extent
  bool rod() const { return half > thick; }
};

inline CoreSegment core_segment(const Vec3& half_extents) {
  int k = 0;
  for (int i = 1; i < 3; ++i)
    if (half_extents[i] > half_extents[k]) k = i;
  double second = 0.0;
  for (int i = 0; i < 3; ++i)
    if (i != k) second = std::max(second, half_extents[i]);
  return {k, half_extents[k] - second, second};
}

}  // namespace hb
