// Oriented bounding boxes (the paper's "parallelepipeds", section 3.3): centre, three unit axes
// and half-extents along them.
//
//   * obb_overlap: the 15-axis separating-axis test (ERRATA 7). Two boxes are DISJOINT iff
//     SOME axis among the 3 face normals of A, the 3 of B and the 9 edge cross products
//     a_i x b_j separates their projections; they overlap iff the projections overlap on all 15.
//     A cross product of (nearly) parallel edges has length ~0 and carries no information
//     (for exactly parallel a_i, b_j the problem reduces to 2D, which the face normals decide);
//     such axes are skipped. Skipping an axis can only turn "disjoint" into "overlap", never the
//     reverse, and the test also widens every projection by a relative 1e-12: the result errs,
//     if at all, on the side of "overlap" (safe for neighbour lists).
//   * obb_face / obb_face_centre: the six face planes of a box (ERRATA 6: the printed "vertices"
//     v_alpha are the face centres r + sigma (s_k + Delta) u_k), face 2k + s with outward normal
//     (s ? +1 : -1) u_k, i.e. faces 0..5 = -u0, +u0, -u1, +u1, -u2, +u2.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include "geometry/plane.hpp"
#include "geometry/segment.hpp"
#include "math/types.hpp"

namespace hb {

struct Obb {
  Vec3 centre = Vec3::Zero();
  Mat3 axes = Mat3::Identity();  // columns = unit axes
  Vec3 half = Vec3::Ones();      // half-extents along the axes

  double circumradius() const { return half.norm(); }
};

// Outward normal of face f (0..5 = -u0, +u0, -u1, +u1, -u2, +u2).
inline Vec3 obb_face_normal(const Obb& b, int f) {
  const Vec3 u = b.axes.col(f >> 1);
  return (f & 1) ? Vec3(u) : Vec3(-u);
}
// Face f as a plane {x : n.x = c}, the box on the side n.x < c.
inline Plane obb_face(const Obb& b, int f) {
  const Vec3 n = obb_face_normal(b, f);
  return Plane{n, n.dot(b.centre) + b.half[f >> 1]};
}
inline Vec3 obb_face_centre(const Obb& b, int f) {
  return b.centre + b.half[f >> 1] * obb_face_normal(b, f);
}
inline std::array<Plane, 6> obb_faces(const Obb& b) {
  std::array<Plane, 6> p;
  for (int f = 0; f < 6; ++f) p[f] = obb_face(b, f);
  return p;
}

// Do boxes a and b overlap when b is translated by shift_of_b (a periodic image shift)?
// Touching boxes count as overlapping.
inline bool obb_overlap(const Obb& a, const Obb& b, const Vec3& shift_of_b = Vec3::Zero()) {
  constexpr double kRel = 1e-12;     // relative widening of every projection (rounding)
  constexpr double kParallel = 1e-14;  // skip cross axes with |a_i x b_j|^2 below this
  // Everything in A's frame: t = centre offset, R(i, j) = a_i . b_j.
  const Vec3 d = b.centre + shift_of_b - a.centre;
  const Vec3 t = a.axes.transpose() * d;
  const Mat3 R = a.axes.transpose() * b.axes;
  const Mat3 AR = R.cwiseAbs();
  const Vec3& ea = a.half;
  const Vec3& eb = b.half;
  const double scale = ea.sum() + eb.sum() + d.norm();
  const double slack = kRel * scale;
  // face normals of A
  for (int i = 0; i < 3; ++i) {
    const double rb = eb[0] * AR(i, 0) + eb[1] * AR(i, 1) + eb[2] * AR(i, 2);
    if (std::abs(t[i]) > ea[i] + rb + slack) return false;
  }
  // face normals of B: projection of t on b_j is (R^T t)_j
  for (int j = 0; j < 3; ++j) {
    const double ra = ea[0] * AR(0, j) + ea[1] * AR(1, j) + ea[2] * AR(2, j);
    const double tb = t[0] * R(0, j) + t[1] * R(1, j) + t[2] * R(2, j);
    if (std::abs(tb) > ra + eb[j] + slack) return false;
  }
  // edge cross products a_i x b_j (in A's frame a_i = e_i, b_j = column j of R)
  for (int i = 0; i < 3; ++i) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3;
    for (int j = 0; j < 3; ++j) {
      const int j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      // |e_i x b_j|^2 = 1 - R(i, j)^2, written without cancellation
      const double len2 = R(i1, j) * R(i1, j) + R(i2, j) * R(i2, j);
      if (len2 < kParallel) continue;
      // axis e_i x b_j = (0, -b_j[i2], b_j[i1]) rotated into components i1, i2
      const double tp = t[i2] * R(i1, j) - t[i1] * R(i2, j);
      const double ra = ea[i1] * AR(i2, j) + ea[i2] * AR(i1, j);
      const double rb = eb[j1] * AR(i, j2) + eb[j2] * AR(i, j1);
      if (std::abs(tp) > ra + rb + slack * std::sqrt(len2)) return false;
    }
  }
  return true;
}

// The core of a box for the capsule tests below: its long axis k, the half-extent along it, the
// radius sqrt(h_i^2 + h_j^2) of the other two and the smaller of them (obb_core; computed once per
// shape where every box has the same extents).
struct ObbCore {
  int axis = 0;
  double half = 0.0, rho = 0.0;
  double thin = 0.0;  // the smaller of the other two half-extents
};
inline ObbCore obb_core(const Vec3& half) {
  const int k = core_segment(half).axis;  // the largest half-extent (the first of equal ones)
  const double thin = std::min(half[(k + 1) % 3], half[(k + 2) % 3]);
  return {k, half[k], std::sqrt(half.squaredNorm() - half[k] * half[k]), thin};
}

// The cheapest test of the three for elongated boxes, ahead of obb_capsules_apart below: true
// only when the boxes are proven disjoint. Box a lies inside the capsule around its core segment
// (core ca, radius ca.rho, see below); box b lies inside the ball of radius rb around its centre
// (rb >= its circumradius |b.half|). If b's centre (d: b's centre at its image minus a's) is more
// than ca.rho + rb from the segment, the capsule and the ball are apart, and so are the boxes.
// The distance is to the clamped projection s = clamp(u.d, -h, h), the segment's nearest point
// (exact up to rounding, ~1e-15 (h + |d|)^2); the test asks for the same 2e-9 (h^2 + |d|^2) beyond
// (rho + rb)^2 as obb_capsules_apart. About 20 instructions against ~150: at X0 = 10 the ball
// reaches fewer than half the pairs within the circumspheres' reach (docs/benchmarks/README.md,
// "Session of 2026-12-01").
[[gnu::always_inline]] inline bool obb_capsule_ball_apart(const Obb& a, const ObbCore& ca, double rb, const Vec3& d) {
  const Vec3 u = a.axes.col(ca.axis);
  const double s = std::clamp(u.dot(d), -ca.half, ca.half);
  const double reach = ca.rho + rb;
  return (d - s * u).squaredNorm() > reach * reach + 2e-9 * (ca.half * ca.half + d.squaredNorm());
}

// A point pair of the segments s u (|s| <= hp) and d + t v (|t| <= hq) near their closest pair:
// Ericson's clamped alternation (as closest_segment_points, geometry/segment.hpp), exact for
// segments that are not parallel; for (nearly) parallel ones a pair near the valley's bottom.
// The capsule tests below bound the segments' distance from it, each in its own direction.
struct SegmentPair {
  double s, t;
};
inline SegmentPair segment_pair(const Vec3& u, double hp, const Vec3& v, double hq, const Vec3& d) {
  const double uv = u.dot(v), den = 1.0 - uv * uv;
  const double du = -u.dot(d), dv = -v.dot(d);  // w = P(0) - Q(0) = -d: u.w, v.w
  double s = den > 1e-12 ? std::clamp((uv * dv - du) / den, -hp, hp) : 0.0;
  const double t = std::clamp(dv + uv * s, -hq, hq);
  s = std::clamp(uv * t - du, -hp, hp);
  return {s, t};
}

// A cheaper test ahead of obb_overlap for elongated boxes: true only when the boxes are proven
// disjoint (false: not decided here). Box a lies inside the capsule around the central segment of
// its long axis (core ca: half-length ca.half) of radius ca.rho: a point c + s u_k + y u_i + z u_j
// of the box (|s| <= h_k) is sqrt(y^2 + z^2) <= rho from the segment's point c + s u_k. Capsules
// whose segments are more than rho_a + rho_b apart hold disjoint boxes. d: b's centre (at its
// image) minus a's.
// The segments' squared distance is the minimum over the rectangle |s| <= h_a, |t| <= h_b of
//     F(s, t) = |s u - t v - d|^2,
// a convex quadratic. Its minimum is bounded below from any point x0 of the rectangle by the
// tangent plane: F(x) >= F(x0) + grad F(x0).(x - x0), whose minimum over the rectangle is
// F(x0) + sum_k min(g_k (lo_k - x0_k), g_k (hi_k - x0_k)) (g = grad F: 2 u.r, -2 v.r with
// r = s u - t v - d). At the minimiser the sum is 0 (the optimality conditions); x0 comes from
// segment_pair above, exact for segments that are not parallel and near the valley's bottom
// for (nearly) parallel ones, where its unconstrained step loses digits (then the sum is the
// small price). So the bound holds however x0 was found, up to the rounding of F and g
// (~1e-14 S^2, S = h_a + h_b + |d|); the test asks for 2e-9 ((h_a + h_b)^2 + |d|^2) beyond
// (rho_a + rho_b)^2.
inline bool obb_capsules_apart(const Obb& a, const ObbCore& ca, const Obb& b, const ObbCore& cb,
                               const Vec3& d) {
  const Vec3 u = a.axes.col(ca.axis), v = b.axes.col(cb.axis);
  const double hp = ca.half, hq = cb.half;
  const auto [s, t] = segment_pair(u, hp, v, hq, d);
  const Vec3 r = s * u - t * v - d;
  const double gs = 2.0 * u.dot(r), gt = -2.0 * v.dot(r);
  const double lower = r.squaredNorm() + std::min(gs * (-hp - s), gs * (hp - s)) +
                       std::min(gt * (-hq - t), gt * (hq - t));
  const double reach = ca.rho + cb.rho, h = hp + hq;
  return lower > reach * reach + 2e-9 * (h * h + d.squaredNorm());
}

// The converse test, ahead of obb_overlap (the neighbour lists run it on elongated boxes, ahead
// of the two above): true only when the boxes are proven to overlap (false: not decided here).
// Box a holds the capsule around the inner segment of its long axis, c +- (h_k - m) u_k, of
// radius m = ca.thin (the smaller of the other two half-extents): a point s u_k + x with
// |s| <= h_k - m and |x| <= m has |coordinate| <= |s| + m <= h_k along u_k and <= m along the
// other two axes. So capsules that meet hold boxes that meet. Any point pair (s, t) of the two
// segments bounds their distance from above: |s u - t v - d|; the pair comes from segment_pair,
// as obb_capsules_apart's. The test asks for 2e-9 ((h_a + h_b)^2 + |d|^2) below (m_a + m_b)^2
// against rounding. About 30 instructions against ~500 for the full 15-axis test on overlapping
// boxes (every axis tried). Boxes that are not elongated have segments of length ~0: the test is
// then that of the inscribed spheres. d: b's centre (at its image) minus a's.
inline bool obb_inner_capsules_meet(const Obb& a, const ObbCore& ca, const Obb& b, const ObbCore& cb,
                                    const Vec3& d) {
  const Vec3 u = a.axes.col(ca.axis), v = b.axes.col(cb.axis);
  const double hp = ca.half - ca.thin, hq = cb.half - cb.thin;
  const auto [s, t] = segment_pair(u, hp, v, hq, d);
  const double reach = ca.thin + cb.thin, h = hp + hq;
  return (s * u - t * v - d).squaredNorm() < reach * reach - 2e-9 * (h * h + d.squaredNorm());
}

}  // namespace hb
