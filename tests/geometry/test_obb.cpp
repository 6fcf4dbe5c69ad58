// The 15-axis SAT (geometry/obb.hpp) against an independent brute force: two convex polytopes
// intersect iff an edge of one meets the other solid (the intersection, if not empty, has a
// vertex, which is a vertex of one inside the other or an edge of one crossing a face of the
// other). Each of the 24 edges is clipped against the other box's three slabs (Liang-Barsky).
// No tolerance bands are needed: the compared pairs are either generic (random centres and
// orientations: touching has probability zero) or built at a relative distance of 1e-7 from an
// exact touch found by bisection on the brute force, which both tests decide without rounding
// trouble (rounding acts at ~1e-15). The near-touching pairs include nearly parallel boxes
// (angles 1e-12 .. 1e-3), the case in which the skipped cross-product axes could matter.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <utility>

#include "geometry/obb.hpp"
#include "geometry/random_pairs.hpp"

namespace hb {
namespace {

// Does the segment p0-p1 meet the solid box b?
bool segment_hits_box(const Vec3& p0, const Vec3& p1, const Obb& b) {
  const Vec3 q0 = b.axes.transpose() * (p0 - b.centre);
  const Vec3 dq = b.axes.transpose() * (p1 - p0);
  double lo = 0.0, hi = 1.0;
  for (int k = 0; k < 3; ++k) {
    if (dq[k] == 0.0) {
      if (std::abs(q0[k]) > b.half[k]) return false;
      continue;
    }
    double s1 = (-b.half[k] - q0[k]) / dq[k], s2 = (b.half[k] - q0[k]) / dq[k];
    if (s1 > s2) std::swap(s1, s2);
    lo = std::max(lo, s1);
    hi = std::min(hi, s2);
    if (lo > hi) return false;
  }
  return true;
}

std::array<Vec3, 8> vertices(const Obb& b) {
  std::array<Vec3, 8> v;
  for (int m = 0; m < 8; ++m) {
    Vec3 p = b.centre;
    for (int k = 0; k < 3; ++k) p += ((m >> k) & 1 ? 1.0 : -1.0) * b.half[k] * b.axes.col(k);
    v[m] = p;
  }
  return v;
}

bool edges_hit(const Obb& a, const Obb& b) {
  const auto v = vertices(a);
  for (int m = 0; m < 8; ++m)
    for (int k = 0; k < 3; ++k)
      if (!((m >> k) & 1) && segment_hits_box(v[m], v[m | (1 << k)], b)) return true;
  return false;
}

bool brute_overlap(const Obb& a, Obb b, const Vec3& shift) {
  b.centre += shift;
  return edges_hit(a, b) || edges_hit(b, a);
}

Obb random_box(testing::Rng& r, double max_aspect = 10.0) {
  Obb b;
  b.axes = r.rotation();
  const double big = r.uni(0.3, 2.0);
  b.half = Vec3(big, big / r.log_uni(1.0, max_aspect), big / r.log_uni(1.0, max_aspect));
  return b;
}

// Rotation by a small angle about a random axis.
Mat3 tilt(testing::Rng& r, double angle) {
  return Eigen::AngleAxisd(angle, r.unit()).toRotationMatrix();
}

// Where b, moved from a's centre along dir, just touches a: bisection on the brute force.
double touch_distance(const Obb& a, Obb b, const Vec3& dir) {
  double lo = 0.0, hi = 2.0 * (a.circumradius() + b.circumradius());
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    b.centre = a.centre + mid * dir;
    (brute_overlap(a, b, Vec3::Zero()) ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

struct Tally {
  long pairs = 0, overlap = 0, false_disjoint = 0, false_overlap = 0;
  void add(bool sat, bool ref) {
    ++pairs;
    overlap += ref;
    false_disjoint += (!sat && ref);
    false_overlap += (sat && !ref);
  }
};

TEST(Obb, FacesAreTheSixFaceCentrePlanes) {
  testing::Rng r(7);
  for (int k = 0; k < 100; ++k) {
    Obb b = random_box(r);
    b.centre = r.ball(5.0);
    const auto faces = obb_faces(b);
    for (int f = 0; f < 6; ++f) {
      const Vec3 x = obb_face_centre(b, f);
      EXPECT_NEAR(faces[f].n.dot(x), faces[f].c, 1e-12);        // face centre on the plane
      EXPECT_LT(faces[f].n.dot(b.centre), faces[f].c);            // box on the n.x < c side
      for (const Vec3& v : vertices(b)) EXPECT_LE(faces[f].n.dot(v), faces[f].c + 1e-12);
    }
  }
}

TEST(Obb, SatAgreesWithEdgeClippingBruteForce) {
  testing::Rng r(20240611);
  const Vec3 L(7.0, 8.0, 9.0);
  Tally crossed, nested, parallel, touching, touching_parallel;
  // 1. crossed: random orientations and centres (about half overlap), with periodic shifts
  for (int k = 0; k < hb::testing::scaled_count(60000, 0.03); ++k) {
    Obb a = random_box(r), b = random_box(r);
    a.centre = r.ball(2.0);
    b.centre = r.ball(2.0);
    Vec3 shift = Vec3::Zero();
    if (k % 4 == 0) {  // b stored one period away, shifted back
      const int ax = k % 3;
      b.centre[ax] += L[ax];
      shift[ax] = -L[ax];
    }
    const Vec3 s = shift;
    crossed.add(obb_overlap(a, b, s), brute_overlap(a, b, s));
    EXPECT_EQ(obb_overlap(a, b, s), obb_overlap(b, a, Vec3(-s)));  // symmetric
  }
  // 2. nested: b strictly inside a (no edge crossings at all: only vertex containment)
  for (int k = 0; k < hb::testing::scaled_count(10000, 0.03); ++k) {
    Obb a = random_box(r, 3.0), b;
    b.axes = r.rotation();
    b.half = a.half.minCoeff() * Vec3(r.uni(0.01, 0.5), r.uni(0.01, 0.5), r.uni(0.01, 0.5));
    b.centre = a.centre + 0.3 * a.half.minCoeff() * r.ball(1.0);
    const bool ref = brute_overlap(a, b, Vec3::Zero());
    ASSERT_TRUE(ref);
    nested.add(obb_overlap(a, b, Vec3::Zero()), ref);
    nested.add(obb_overlap(b, a, Vec3::Zero()), brute_overlap(b, a, Vec3::Zero()));
  }
  // 3. near-parallel: b's axes are a's tilted by 1e-12 .. 1e-3 (cross axes nearly degenerate)
  for (int k = 0; k < hb::testing::scaled_count(20000, 0.03); ++k) {
    Obb a = random_box(r), b = random_box(r);
    b.axes = tilt(r, r.log_uni(1e-12, 1e-3)) * a.axes;
    if (k % 2) b.axes.col(0).swap(b.axes.col(1));  // also parallel but permuted
    a.centre = r.ball(3.0);
    b.centre = r.ball(3.0);
    parallel.add(obb_overlap(a, b, Vec3::Zero()), brute_overlap(a, b, Vec3::Zero()));
  }
  // 4. near-touching: b moved along a random direction to an exact touch s* (bisection on the
  // brute force), then placed at s* (1 -+ 1e-7): overlapping and disjoint by a hair.
  auto touch_pair = [&](Obb a, Obb b, Tally& t) {
    const Vec3 dir = r.unit();
    const double s = touch_distance(a, b, dir);
    for (double f : {1.0 - 1e-7, 1.0 + 1e-7}) {
      b.centre = a.centre + f * s * dir;
      t.add(obb_overlap(a, b, Vec3::Zero()), brute_overlap(a, b, Vec3::Zero()));
    }
  };
  for (int k = 0; k < hb::testing::scaled_count(10000, 0.03); ++k) touch_pair(random_box(r), random_box(r), touching);
  for (int k = 0; k < hb::testing::scaled_count(10000, 0.03); ++k) {
    Obb a = random_box(r), b = random_box(r);
    b.axes = tilt(r, r.log_uni(1e-12, 1e-3)) * a.axes;
    touch_pair(a, b, touching_parallel);
  }
  long total = 0;
  for (const auto& [name, t] : {std::pair{"crossed", crossed}, std::pair{"nested", nested},
                                std::pair{"near-parallel", parallel},
                                std::pair{"touching", touching},
                                std::pair{"touching near-parallel", touching_parallel}}) {
    std::printf("[ SAT ] %-24s pairs %6ld  overlapping %6ld  false disjoint %ld  false overlap %ld\n",
                name, t.pairs, t.overlap, t.false_disjoint, t.false_overlap);
    EXPECT_EQ(t.false_disjoint, 0) << name;
    EXPECT_EQ(t.false_overlap, 0) << name;
    total += t.pairs;
  }
  EXPECT_GE(total, hb::testing::scaled_count(100000, 0.03));  // 140,000 pairs in Release
  EXPECT_GT(touching.overlap, 0);
  EXPECT_LT(touching.overlap, touching.pairs);
}

// Exactly parallel boxes (all cross axes skipped) and an edge-edge separation, the case that
// only a cross axis decides.
TEST(Obb, ParallelAndEdgeEdgeCases) {
  Obb a, b;
  a.half = Vec3(1, 1, 1);
  b.half = Vec3(1, 1, 1);
  b.centre = Vec3(2.0 + 1e-9, 0.5, 0.0);
  EXPECT_FALSE(obb_overlap(a, b));
  b.centre.x() = 2.0 - 1e-9;
  EXPECT_TRUE(obb_overlap(a, b));
  // b rotated 45 degrees about z and about x: its edge faces a's edge along the diagonal
  b.axes = (Eigen::AngleAxisd(kPi / 4, Vec3::UnitZ()) * Eigen::AngleAxisd(kPi / 4, Vec3::UnitX()))
               .toRotationMatrix();
  for (double gap : {-1e-6, 1e-6}) {
    const Vec3 dir = Vec3(1, 1, 0).normalized();
    // a's edge at x = y = 1 has support along dir sqrt(2); b's support along -dir:
    const double hb = b.half.dot((b.axes.transpose() * dir).cwiseAbs());
    b.centre = (std::sqrt(2.0) + hb + gap) * dir;
    EXPECT_EQ(obb_overlap(a, b), brute_overlap(a, b, Vec3::Zero())) << gap;
  }
}

// The capsule pre-test (obb_capsules_apart) rules out only disjoint boxes. Each box lies in the
// capsule around its long axis's central segment of radius sqrt(h1^2 + h2^2): checked on random
// points of random boxes. Against the brute force: random needles (aspect up to 20), nearly
// parallel ones (tilts 1e-12 .. 0.1, across the 1e-12 cut of 1 - (u.v)^2) and pairs a hair from
// touching (bisection on the brute force, then 1 -+ 1e-7), some of them exactly parallel (the
// tangent-plane bound of the test, not its starting point, must carry those); and the
// adversarial case where the capsules touch exactly where the boxes do, corner to corner (the
// boxes' corners lie on their capsules; a quarter of them nearly parallel): overlapping by 1e-6 of their size it must not rule the pair out, apart by as much it
// does (the rounding slack is ~1e-9 of the scale). It also rules out most disjoint random needles.
// The random and the touching pairs of the capsule tests below: `apart` (a test that may only
// rule out disjoint boxes) against the edge-clipping brute force. Random needles with centres in
// a ball of radius 3 (counting the disjoint pairs and those apart rules out), then pairs 1e-7
// from touching along a random direction (b tilted from a, or parallel to it, in a quarter each).
template <class Apart>
void tally_random_pairs(testing::Rng& r, const Apart& apart, Tally& t, long& decided, long& disjoint) {
  for (int k = 0; k < hb::testing::scaled_count(40000, 0.05); ++k) {
    Obb a = random_box(r, 20.0), b = random_box(r, 20.0);
    a.centre = r.ball(3.0);
    b.centre = r.ball(3.0);
    const bool ref = brute_overlap(a, b, Vec3::Zero());
    t.add(!apart(a, b), ref);  // "not apart" plays "overlap": a false disjoint is an error
    disjoint += !ref;
    decided += !ref && apart(a, b);
  }
}
template <class Apart>
void tally_touching_pairs(testing::Rng& r, const Apart& apart, Tally& t) {
  for (int k = 0; k < hb::testing::scaled_count(10000, 0.05); ++k) {
    Obb a = random_box(r, 20.0), b = random_box(r, 20.0);
    if (k % 4 == 1) b.axes = tilt(r, r.log_uni(1e-12, 0.1)) * a.axes;
    if (k % 4 == 3) b.axes = a.axes;
    const Vec3 dir = r.unit();
    const double s = touch_distance(a, b, dir);
    for (double f : {1.0 - 1e-7, 1.0 + 1e-7}) {
      b.centre = a.centre + f * s * dir;
      t.add(!apart(a, b), brute_overlap(a, b, Vec3::Zero()));
    }
  }
}

// Both sets at once: the random needles (with their counts) and the touching pairs.
struct PairTallies {
  Tally random, touching;
  long random_decided = 0, random_disjoint = 0;
};
template <class Apart>
PairTallies tally_pairs(testing::Rng& r, const Apart& apart) {
  PairTallies p;
  tally_random_pairs(r, apart, p.random, p.random_decided, p.random_disjoint);
  tally_touching_pairs(r, apart, p.touching);
  return p;
}

// The checks and the printed counts of the capsule tests below: no overlapping pair ruled out in
// any set, all of the disjoint corner pairs and none of the overlapping ones ruled out, and at
// least 1 / `share` of the random disjoint pairs ruled out (not a vacuous test).
void check_apart_tallies(const char* tag, std::initializer_list<std::pair<const char*, Tally>> sets,
                         long corner_pairs, long corner_apart_disjoint, long corner_apart_overlapping,
                         long random_decided, long random_disjoint, long share) {
  for (const auto& [name, t] : sets) {
    std::printf("[ %s ] %-16s pairs %6ld  overlapping %6ld  ruled out %6ld  wrongly %ld\n", tag,
                name, t.pairs, t.overlap, t.pairs - t.overlap - t.false_overlap, t.false_disjoint);
    EXPECT_EQ(t.false_disjoint, 0) << name;
  }
  std::printf("[ %s ] corner to corner: %ld pairs, ruled out %ld of the disjoint, %ld of the "
              "overlapping; random needles: %ld of %ld disjoint ruled out\n",
              tag, corner_pairs, corner_apart_disjoint, corner_apart_overlapping, random_decided,
              random_disjoint);
  EXPECT_EQ(corner_apart_overlapping, 0);
  EXPECT_EQ(corner_apart_disjoint, corner_pairs / 2);  // a gap of 1e-6 is beyond the slack
  EXPECT_GT(random_decided, random_disjoint / share);
}

TEST(Obb, CapsuleTestRulesOutOnlyDisjointBoxes) {
  testing::Rng r(20261130);
  auto long_axis = [](const Vec3& h) {
    int k = 0;
    for (int i = 1; i < 3; ++i)
      if (h[i] > h[k]) k = i;
    return k;
  };
  auto apart = [&](const Obb& a, const Obb& b) {
    const ObbCore ca = obb_core(a.half), cb = obb_core(b.half);
    EXPECT_EQ(ca.axis, long_axis(a.half));
    return obb_capsules_apart(a, ca, b, cb, Vec3(b.centre - a.centre));
  };
  // containment: box points within rho of the core segment
  double worst = -kInf;
  for (int k = 0; k < hb::testing::scaled_count(2000, 0.1); ++k) {
    const Obb b = random_box(r, 20.0);
    const int ax = long_axis(b.half);
    const double rho = std::sqrt(b.half.squaredNorm() - b.half[ax] * b.half[ax]);
    for (int m = 0; m < 8; ++m) {
      Vec3 x = b.centre;
      for (int i = 0; i < 3; ++i) x += r.uni(-1.0, 1.0) * b.half[i] * b.axes.col(i);
      const Vec3 rel = x - b.centre;
      const double s = std::clamp(rel.dot(b.axes.col(ax)), -b.half[ax], b.half[ax]);
      worst = std::max(worst, (rel - s * b.axes.col(ax)).norm() - rho);
    }
  }
  EXPECT_LE(worst, 1e-12);
  Tally random, parallel, touching;
  long random_decided = 0, random_disjoint = 0;
  auto add = [&](Tally& t, const Obb& a, const Obb& b) {
    const bool ref = brute_overlap(a, b, Vec3::Zero());
    t.add(!apart(a, b), ref);  // "not apart" plays "overlap": a false disjoint is an error
    return ref;
  };
  tally_random_pairs(r, apart, random, random_decided, random_disjoint);
  for (int k = 0; k < hb::testing::scaled_count(20000, 0.05); ++k) {
    Obb a = random_box(r, 20.0), b = random_box(r, 20.0);
    b.axes = k % 8 ? Mat3(tilt(r, r.log_uni(1e-12, 0.1)) * a.axes) : a.axes;
    a.centre = r.ball(2.0);
    b.centre = r.ball(2.0);
    add(parallel, a, b);
  }
  tally_touching_pairs(r, apart, touching);
  // corner to corner: a's corner c = centre + h0 u0 + h1 u1 + h2 u2 is its support point along
  // n = (h1 u1 + h2 u2) / rho_a (normal to u0); b (long axis v0 normal to n, turned about v0 so
  // that its corner offset h1' v1 + h2' v2 is -rho_b n) has its corner at c + gap n. The plane
  // n.x = n.c + gap / 2 separates them for gap > 0; for gap < 0 the corners cut into each other.
  // The segments' closest points are their ends, rho_a + rho_b + gap apart.
  long corner_pairs = 0, corner_apart_overlapping = 0, corner_apart_disjoint = 0;
  for (int k = 0; k < hb::testing::scaled_count(4000, 0.05); ++k) {
    Obb a = random_box(r, 20.0), b = random_box(r, 20.0);
    const Vec3 h = a.half, hb_ = b.half;
    const double rho_a = std::hypot(h[1], h[2]), rho_b = std::hypot(hb_[1], hb_[2]);
    const Vec3 n = (h[1] * a.axes.col(1) + h[2] * a.axes.col(2)) / rho_a;
    const Vec3 c = a.centre + h[0] * a.axes.col(0) + rho_a * n;
    Vec3 v0;
    if (k % 4) {  // normal to n: at random
      v0 = r.unit();
      v0 = (v0 - v0.dot(n) * n).normalized();
    } else {  // normal to n, within 1e-12 .. 1e-2 rad of a's axis (nearly parallel needles)
      const double eps = r.log_uni(1e-12, 1e-2);
      v0 = std::cos(eps) * a.axes.col(0) + std::sin(eps) * n.cross(a.axes.col(0));
    }
    const Vec3 m = -n, p = v0.cross(m);
    const double ca = hb_[1] / rho_b, sa = -hb_[2] / rho_b;
    b.axes.col(0) = v0;
    b.axes.col(1) = ca * m + sa * p;
    b.axes.col(2) = -sa * m + ca * p;
    for (double sgn : {-1.0, 1.0}) {
      const double gap = sgn * 1e-6 * (h.norm() + hb_.norm());
      b.centre = c + gap * n - hb_[0] * v0 + rho_b * n;  // corner = centre + h0' v0 - rho_b n
      const bool ref = brute_overlap(a, b, Vec3::Zero());
      ASSERT_EQ(ref, sgn < 0.0) << k;  // the construction itself
      ++corner_pairs;
      (ref ? corner_apart_overlapping : corner_apart_disjoint) += apart(a, b);
    }
  }
  check_apart_tallies("capsule", {{"random needles", random}, {"near-parallel", parallel}, {"touching", touching}},
                      corner_pairs, corner_apart_disjoint, corner_apart_overlapping, random_decided,
                      random_disjoint, 2);
}

// obb_capsule_ball_apart (box a's capsule against box b's circumsphere, the cheap test ahead of
// obb_capsules_apart in the neighbour-list rebuilds) against the edge-clipping brute force: random
// pairs, pairs 1e-7 from touching, and pairs built so that the ball and the capsule touch where
// the boxes do (b's corner on the line from its centre normal to a's segment, at a's corner).
TEST(Obb, CapsuleBallTestRulesOutOnlyDisjointBoxes) {
  testing::Rng r(20261201);
  auto apart = [](const Obb& a, const Obb& b) {
    return obb_capsule_ball_apart(a, obb_core(a.half), b.circumradius(), Vec3(b.centre - a.centre));
  };
  const auto [random, touching, random_decided, random_disjoint] = tally_pairs(r, apart);
  // a's corner c = centre + h0 u0 + rho_a n (n = (h1 u1 + h2 u2) / rho_a, normal to u0) is
  // rho_a from the segment's end; b turned so that its corner offset b.axes b.half is -rb n, its
  // centre at c + (gap + rb) n: the centre is rho_a + rb + gap from a's segment, and the plane
  // n.x = n.c + gap / 2 separates the boxes for gap > 0; for gap < 0 b's corner is inside a.
  long corner_pairs = 0, corner_apart_overlapping = 0, corner_apart_disjoint = 0;
  for (int k = 0; k < hb::testing::scaled_count(4000, 0.05); ++k) {
    Obb a = random_box(r, 20.0), b = random_box(r, 20.0);
    const Vec3 h = a.half;
    const double rho_a = std::hypot(h[1], h[2]), rb = b.circumradius();
    const Vec3 n = (h[1] * a.axes.col(1) + h[2] * a.axes.col(2)) / rho_a;
    const Vec3 c = a.centre + h[0] * a.axes.col(0) + rho_a * n;
    const Vec3 o = b.axes * b.half;
    b.axes = Eigen::Quaterniond::FromTwoVectors(o, -n).toRotationMatrix() * b.axes;
    for (double sgn : {-1.0, 1.0}) {
      const double gap = sgn * 1e-6 * (h.norm() + rb);
      b.centre = c + (gap + rb) * n;
      const bool ref = brute_overlap(a, b, Vec3::Zero());
      ASSERT_EQ(ref, sgn < 0.0) << k;  // the construction itself
      ++corner_pairs;
      (ref ? corner_apart_overlapping : corner_apart_disjoint) += apart(a, b);
    }
  }
  check_apart_tallies("capsule-ball", {{"random needles", random}, {"touching", touching}}, corner_pairs,
                      corner_apart_disjoint, corner_apart_overlapping, random_decided, random_disjoint, 4);
}

// obb_inner_capsules_meet (the neighbour-list rebuilds' test ahead of obb_overlap: true proves the
// boxes overlap) against the edge-clipping brute force. Each box holds the capsule around its
// inner segment (long half-extent h less the thinner of the other two, m) of radius m: checked on
// random points of those capsules. Random needles (it may call no disjoint pair overlapping, and
// must decide a fair share of the overlapping ones), pairs 1e-7 from touching (boxes), and the
// adversarial pairs whose inner capsules touch: a's segment end e_a, b's segment end at
// e_a + (m_a + m_b + gap) n with n normal to both axes, so the segments are m_a + m_b + gap apart
// (e_a and e_b are their closest points): at gap = -1e-6 of the size the test must find the
// overlap, at +1e-6 it must not claim one (its slack is ~1e-9 of the scale).
TEST(Obb, InnerCapsuleTestFindsOnlyOverlappingBoxes) {
  testing::Rng r(20261207);
  auto meet = [](const Obb& a, const Obb& b) {
    return obb_inner_capsules_meet(a, obb_core(a.half), b, obb_core(b.half), Vec3(b.centre - a.centre));
  };
  // containment: points of the inner capsule lie in the box
  double worst = -kInf;
  for (int k = 0; k < hb::testing::scaled_count(2000, 0.1); ++k) {
    const Obb b = random_box(r, 20.0);
    const ObbCore c = obb_core(b.half);
    for (int m = 0; m < 8; ++m) {
      const Vec3 x = r.uni(-1.0, 1.0) * (c.half - c.thin) * b.axes.col(c.axis) + c.thin * r.uni(0.0, 1.0) * r.unit();
      worst = std::max(worst, ((b.axes.transpose() * x).cwiseAbs() - b.half).maxCoeff());
    }
  }
  EXPECT_LE(worst, 1e-12);
  // the random and touching pairs of the capsule tests, with "not meeting" as the test that
  // rules pairs out: a pair it keeps is one it calls overlapping (Tally: false_overlap is then
  // the error, overlap - false_disjoint the overlapping pairs found)
  auto apart = [&](const Obb& a, const Obb& b) { return !meet(a, b); };
  const PairTallies tallies = tally_pairs(r, apart);
  const Tally &random = tallies.random, &touching = tallies.touching;
  long edge_pairs = 0, found_when_meeting = 0, claimed_when_apart = 0;
  for (int k = 0; k < hb::testing::scaled_count(4000, 0.05); ++k) {
    Obb a = random_box(r, 20.0), b = random_box(r, 20.0);
    const ObbCore ca = obb_core(a.half), cb = obb_core(b.half);
    const Vec3 u = a.axes.col(ca.axis);
    Vec3 n = r.unit();
    n = (n - n.dot(u) * u).normalized();
    Vec3 v;  // b's axis normal to n: at random, or within 1e-12 .. 1e-2 rad of u
    if (k % 4) {
      v = r.unit();
      v = (v - v.dot(n) * n).normalized();
    } else {
      const double e = r.log_uni(1e-12, 1e-2);
      v = std::cos(e) * u + std::sin(e) * n.cross(u);
    }
    // b's axes: the long one along v, the others turned at random about it
    const Mat3 turn = Eigen::AngleAxisd(r.uni(0.0, 6.283185307179586), v).toRotationMatrix();
    const Vec3 p = v.unitOrthogonal();
    Mat3 axes;
    axes.col(cb.axis) = v;
    axes.col((cb.axis + 1) % 3) = turn * p;
    axes.col((cb.axis + 2) % 3) = turn * v.cross(p);
    b.axes = axes;
    const Vec3 ea = a.centre + (ca.half - ca.thin) * u;
    for (double sgn : {-1.0, 1.0}) {
      const double gap = sgn * 1e-6 * (a.half.norm() + b.half.norm());
      // b's segment end -(h - m) v sits at ea + (m_a + m_b + gap) n
      b.centre = ea + (ca.thin + cb.thin + gap) * n + (cb.half - cb.thin) * v;
      ++edge_pairs;
      if (sgn < 0.0) {
        found_when_meeting += meet(a, b);
        ASSERT_TRUE(brute_overlap(a, b, Vec3::Zero())) << k;  // the construction itself
      } else {
        claimed_when_apart += meet(a, b);
      }
    }
  }
  std::printf("[ inner ] random needles: %ld of %ld overlapping found, %ld claimed wrongly; touching "
              "boxes: %ld pairs, %ld claimed wrongly; inner capsules 1e-6 from touching: %ld pairs, "
              "%ld of the meeting found, %ld of the apart claimed\n",
              random.overlap - random.false_disjoint, random.overlap, random.false_overlap,
              touching.pairs, touching.false_overlap, edge_pairs, found_when_meeting, claimed_when_apart);
  EXPECT_EQ(random.false_overlap, 0);
  EXPECT_EQ(touching.false_overlap, 0);
  EXPECT_EQ(found_when_meeting, edge_pairs / 2);
  EXPECT_EQ(claimed_when_apart, 0);
  EXPECT_GT(random.overlap - random.false_disjoint, random.overlap / 4);  // not a vacuous test
}

}  // namespace
}  // namespace hb
