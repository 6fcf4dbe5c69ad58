// Solver-independent overlap check of convex bodies given by an implicit function f (negative
// inside), by dense sampling of the surfaces and a local refinement.  It is the final-state and
// snapshot check of superquadric runs (DESIGN.md: the periodic overlap checks must not use the
// distance solver under test); it works for any Shape and is tested against the Perram–Wertheim
// check on ellipsoids.
//
// Method, for a pair A, B of identical bodies (centres r, body->lab rotations Q):
//  1. Samples, once per shape: p_k = ray_surface(D n_k), k < M, with n_k the Fibonacci sphere
//     (M nearly uniform unit vectors) and D = diag(half-extents).  The pre-stretch by D makes
//     the samples of an ellipsoid the affine image of a uniform set on the sphere, and evens the
//     spacing of elongated bodies.  The spacing h (largest distance from a sample to its
//     nearest neighbour, measured) and G (largest |grad f| over the samples) are recorded.
//  2. Coarse search: every sample of A is mapped into B's body frame,
//     y = Q_B^T (r_A + Q_A p - r_B); those inside B's extent box grown by 2h are evaluated,
//     f_B(y).  The lowest value marks the part of A's surface deepest in (or nearest to) B.
//  3. Refinement, when that value is below tau = 4 G h (the value at a sample exceeds the
//     minimum over the surface by at most ~G h): f_B is minimised over A's surface near the
//     best sample in the chart n -> ray_surface(D n), n on the unit sphere, by a 2-D Newton
//     iteration whose gradient and Hessian come from a 3 x 3 finite-difference stencil of
//     angular step s around the current point (the stencil points and the Newton point are
//     candidates, the lowest is taken; s shrinks by 4 when the centre stays lowest, and follows
//     the Newton step length as it converges) until s < 1e-7 rad.
//  4. Both ways: A's surface against B and B's surface against A.  The gap estimate of a way
//     is f_B(x*) / |grad f_B(x*)| at the minimiser x* (the first-order signed distance of x*
//     from B's surface: negative when x* lies inside B); the pair's gap is the smaller one.
//  Overlap: gap < -tol * inscribed radius.  Pairs are pre-filtered by bounding spheres.
//
// Why it can be trusted.  A reported overlap has a witness: a surface point of one body
// (ray_surface, exact to rounding) at which the other body's f is negative.  Two congruent
// convex bodies that overlap each have boundary points inside the other, and near contact f_B
// restricted to A's surface has one low basin around the contact region; a sample lies within h
// of it and the refinement descends to its bottom.  The refinement evaluates only f and
// ray_surface: no distance or contact solver.  Tests (tests/observers/test_overlap_sampling.cpp):
// pairs placed at signed gaps of +-1e-6 of the size (independent support-function reference),
// near-cubes p = 16 face to face, edge to face and corner to face, and ellipsoids against
// Perram–Wertheim.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "math/types.hpp"
#include "observers/close_pairs.hpp"
#include "observers/overlap.hpp"
#include "shapes/shape.hpp"
#include "shapes/superquadric.hpp"
#include "core/box.hpp"

namespace hb {

namespace sampling_detail {

// n unit vectors nearly uniform on the sphere (Fibonacci lattice).
std::vector<Vec3> fibonacci_sphere(int n);

// Orthonormal e1, e2 with n, e1, e2 right-handed (n unit).
inline void tangent_basis(const Vec3& n, Vec3& e1, Vec3& e2) {
  const Vec3 a = std::abs(n.x()) < 0.6 ? Vec3::UnitX() : Vec3::UnitY();
  e1 = (a - a.dot(n) * n).normalized();
  e2 = n.cross(e1);
}

// Minimises g over unit vectors near n (updated in place; f0 = g(n) on entry), by the stencil
// Newton iteration of the header, from angular step `step` down to `step_min`.  Returns the
// minimum found; `evals` counts the evaluations of g.
template <class G>
double minimise_on_sphere(const G& g, Vec3& n, double f0, double step, double step_min,
                          int& evals) {
  for (int it = 0; it < 200 && step >= step_min; ++it) {
    Vec3 e1, e2;
    tangent_basis(n, e1, e2);
    auto at = [&](double x, double y) { return Vec3((n + x * e1 + y * e2).normalized()); };
    double f[3][3];
    double fb = f0, bx = 0.0, by = 0.0;
    for (int i = -1; i <= 1; ++i)
      for (int j = -1; j <= 1; ++j) {
        double& v = f[i + 1][j + 1];
        if (i == 0 && j == 0) {
          v = f0;
          continue;
        }
        v = g(at(i * step, j * step));
        ++evals;
        if (v < fb) fb = v, bx = i * step, by = j * step;
      }
    const double gx = (f[2][1] - f[0][1]) / (2.0 * step), gy = (f[1][2] - f[1][0]) / (2.0 * step);
    const double s2 = step * step;
    const double hxx = (f[2][1] - 2.0 * f0 + f[0][1]) / s2, hyy = (f[1][2] - 2.0 * f0 + f[1][0]) / s2;
    const double hxy = (f[2][2] - f[2][0] - f[0][2] + f[0][0]) / (4.0 * s2);
    const double det = hxx * hyy - hxy * hxy;
    bool newton = false;
    double len = 0.0;
    if (hxx > 0.0 && det > 0.0) {
      double dx = -(hyy * gx - hxy * gy) / det, dy = -(hxx * gy - hxy * gx) / det;
      len = std::hypot(dx, dy);
      if (len > 4.0 * step) dx *= 4.0 * step / len, dy *= 4.0 * step / len, len = 4.0 * step;
      if (len > 0.0) {
        const double v = g(at(dx, dy));
        ++evals;
        if (v < fb) fb = v, bx = dx, by = dy, newton = true;
      }
    }
    if (fb < f0) {
      n = at(bx, by);
      f0 = fb;
      if (newton) step = std::min(step, len);  // converging: the stencil follows the step
    } else {
      step *= 0.25;
    }
  }
  return f0;
}

}  // namespace sampling_detail

// One way of the check: the surface of one body against the other's inside.
struct SampledSide {
  double f = kInf;        // lowest f of the other body found on this body's surface
  double gap = kInf;      // f / |grad f| there (kInf: no sample near the other body)
  bool refined = false;
  int evaluations = 0;    // evaluations of f
};

struct SampledPair {
  double gap = kInf;      // estimated signed surface gap (negative: overlap)
  bool overlap = false;   // gap < -tol * inscribed radius
  SampledSide ab, ba;     // A's surface against B, B's surface against A
};

template <Shape S>
class SurfaceSampling {
 public:
  static constexpr int kDefaultSamples = 3000;

  explicit SurfaceSampling(const S& shape, int samples = kDefaultSamples, double tol = 1e-10)
      : shape_(shape), tol_(tol) {
    if (samples < 20) samples = 20;
    dirs_ = sampling_detail::fibonacci_sphere(samples);
    const Vec3 D = shape.half_extents();
    pts_.reserve(dirs_.size());
    for (const Vec3& n : dirs_) pts_.push_back(shape.ray_surface(D.cwiseProduct(n)));
    // spacing: the largest nearest-neighbour distance (O(M^2), once per shape)
    for (std::size_t k = 0; k < pts_.size(); ++k) {
      double nn = kInf;
      for (std::size_t l = 0; l < pts_.size(); ++l)
        if (l != k) nn = std::min(nn, (pts_[l] - pts_[k]).squaredNorm());
      h_ = std::max(h_, std::sqrt(nn));
    }
    ext_.setZero();
    for (const Vec3& p : pts_) {
      ext_ = ext_.cwiseMax(p.cwiseAbs());
      G_ = std::max(G_, shape.grad(p).norm());
    }
    ext_.array() += 3.0 * h_;  // the extent (within h) grown by 2h
    tau_ = 4.0 * G_ * h_;
    step0_ = 0.5 * std::sqrt(4.0 * kPi / double(dirs_.size()));
    length_ = shape.inscribed_radius();
  }

  const S& shape() const { return shape_; }
  const std::vector<Vec3>& points() const { return pts_; }  // body frame
  double spacing() const { return h_; }
  double tolerance() const { return tol_; }
  // For the two-shape check (sampled_pair below): the unit directions of the samples (the
  // chart n -> ray_surface(D n)), the largest |grad f| over the samples, the sample extent
  // grown by 3 h (max |p_i| + 3 h per body axis) and the first step of the refinement.
  const std::vector<Vec3>& directions() const { return dirs_; }
  double gradient_bound() const { return G_; }
  const Vec3& grown_extent() const { return ext_; }
  double initial_step() const { return step0_; }

  // Body A with rotation qa at the origin, body B with rotation qb at r_ab.
  SampledPair pair(const Quat& qa, const Quat& qb, const Vec3& r_ab) const {
    const Mat3 Ra = qa.toRotationMatrix(), Rb = qb.toRotationMatrix();
    const Mat3 M = Rb.transpose() * Ra;  // A's body frame -> B's body frame (rotation part)
    SampledPair out;
    out.ab = side(M, Rb.transpose() * r_ab);
    out.ba = side(M.transpose(), Vec3(-(Ra.transpose() * r_ab)));
    out.gap = std::min(out.ab.gap, out.ba.gap);
    out.overlap = out.gap < -tol_ * length_;
    return out;
  }

 private:
  // The surface of X against the inside of Y: X's surface point p lies at M p - c in Y's frame.
  SampledSide side(const Mat3& M, const Vec3& c) const {
    SampledSide out;
    std::size_t best = pts_.size();
    for (std::size_t k = 0; k < pts_.size(); ++k) {
      const Vec3 y = M * pts_[k] - c;
      if (std::abs(y.x()) > ext_.x() || std::abs(y.y()) > ext_.y() || std::abs(y.z()) > ext_.z())
        continue;
      const double v = shape_.f(y);
      ++out.evaluations;
      if (v < out.f) out.f = v, best = k;
    }
    if (best == pts_.size()) return out;
    const Vec3 D = shape_.half_extents();
    auto point = [&](const Vec3& n) { return Vec3(M * shape_.ray_surface(D.cwiseProduct(n)) - c); };
    Vec3 n = dirs_[best];
    if (out.f < tau_) {
      auto g = [&](const Vec3& u) { return shape_.f(point(u)); };
      out.f = sampling_detail::minimise_on_sphere(g, n, out.f, step0_, 1e-7, out.evaluations);
      out.refined = true;
    }
    const Vec3 y = point(n);
    const double gn = shape_.grad(y).norm();
    out.gap = gn > 0.0 ? out.f / gn : (out.f < 0.0 ? -kInf : kInf);
    return out;
  }

  S shape_;
  double tol_;
  std::vector<Vec3> dirs_, pts_;
  double h_ = 0.0, G_ = 0.0, tau_ = 0.0, step0_ = 0.1, length_ = 1.0;
  Vec3 ext_ = Vec3::Zero();
};

// Two unlike bodies (mixtures, polydispersity): A is the shape of sampling `a` scaled by sa > 0
// about its centre, B the shape of `b` scaled by sb.  A scaled body {x : f(x / s) <= 0} has the
// samples s p_k, and its f is evaluated at x / s, so one SurfaceSampling per shape serves every
// scale.  One way, X's surface against Y's inside, works in Y's unscaled body frame
// y = (M s_X p - c) / s_Y, where X's sample spacing is h' = h_X s_X / s_Y:
//   - samples of X are kept inside Y's extent grown by 2 h' (Y's grown_extent + 2 (h' - h_Y));
//   - the refinement runs when the lowest f_Y is below tau = 4 G_Y h', from X's initial step;
//   - the gap estimate is s_Y f_Y(y*) / |grad f_Y(y*)| (lab lengths).
// The pair's gap is the smaller of the two ways; overlap when gap < -tol min(s_A l_A, s_B l_B),
// l the inscribed radius.  Two overlapping convex bodies either cross each other's surface or
// one contains the other; either way a surface point of one lies inside the other, so the two
// ways cover bodies of unlike shape and size.  For one sampling at unit scales every number is
// that of SurfaceSampling::pair, bit for bit (tested).
namespace sampling_detail {
template <Shape SX, Shape SY>
SampledSide sampled_side(const SurfaceSampling<SX>& X, double sx, const SurfaceSampling<SY>& Y,
                         double sy, const Mat3& M, const Vec3& c) {
  SampledSide out;
  const SX& xs = X.shape();
  const SY& ys = Y.shape();
  const double h = X.spacing() * sx / sy;
  const Vec3 ext = (Y.grown_extent().array() + 2.0 * (h - Y.spacing())).matrix();
  const Mat3 Ms = (sx / sy) * M;
  const Vec3 cs = c / sy;
  const std::vector<Vec3>& pts = X.points();
  std::size_t best = pts.size();
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const Vec3 y = Ms * pts[k] - cs;
    if (std::abs(y.x()) > ext.x() || std::abs(y.y()) > ext.y() || std::abs(y.z()) > ext.z())
      continue;
    const double v = ys.f(y);
    ++out.evaluations;
    if (v < out.f) out.f = v, best = k;
  }
  if (best == pts.size()) return out;
  const Vec3 D = xs.half_extents();
  auto point = [&](const Vec3& n) { return Vec3(Ms * xs.ray_surface(D.cwiseProduct(n)) - cs); };
  Vec3 n = X.directions()[best];
  if (out.f < 4.0 * Y.gradient_bound() * h) {
    auto g = [&](const Vec3& u) { return ys.f(point(u)); };
    out.f = minimise_on_sphere(g, n, out.f, X.initial_step(), 1e-7, out.evaluations);
    out.refined = true;
  }
  const Vec3 y = point(n);
  const double gn = ys.grad(y).norm();
  out.gap = gn > 0.0 ? sy * out.f / gn : (out.f < 0.0 ? -kInf : kInf);
  return out;
}
}  // namespace sampling_detail

// Body A (sampling a, scale sa, rotation qa) at the origin, body B (b, sb, qb) at r_ab.
template <Shape SA, Shape SB>
SampledPair sampled_pair(const SurfaceSampling<SA>& a, double sa, const Quat& qa,
                         const SurfaceSampling<SB>& b, double sb, const Quat& qb, const Vec3& r_ab,
                         double tol = 1e-10) {
  const Mat3 Ra = qa.toRotationMatrix(), Rb = qb.toRotationMatrix();
  const Mat3 M = Rb.transpose() * Ra;  // A's body frame -> B's body frame (rotation part)
  SampledPair out;
  out.ab = sampling_detail::sampled_side(a, sa, b, sb, M, Rb.transpose() * r_ab);
  out.ba = sampling_detail::sampled_side(b, sb, a, sa, M.transpose(), Vec3(-(Ra.transpose() * r_ab)));
  out.gap = std::min(out.ab.gap, out.ba.gap);
  const double length = std::min(sa * a.shape().inscribed_radius(), sb * b.shape().inscribed_radius());
  out.overlap = out.gap < -tol * length;
  return out;
}

// Every pair of identical bodies (positions r, orientations q) closer than the bounding
// diameter, checked by `check`.  min_distance is the smallest gap estimate.
template <Shape S>
OverlapReport sampled_overlaps(FieldView<Vec3> r, FieldView<Quat> q,
                               const Box& box, const SurfaceSampling<S>& check) {
  OverlapReport rep;
  const double range = 2.0 * check.shape().bounding_radius();
  for_close_pairs(r, box, range, [&](std::uint32_t i, std::uint32_t j, const Vec3& d) {
    const SampledPair p = check.pair(q[i], q[j], d);
    ++rep.pairs_checked;
    rep.min_distance = std::min(rep.min_distance, p.gap);
    if (p.overlap) ++rep.overlaps;
  });
  return rep;
}

// Superquadrics (all with the same shape): sampled_overlaps with the default sampling.
OverlapReport superquadric_overlaps(FieldView<Vec3> r, FieldView<Quat> q,
                                    const Box& box, const Superquadric& shape, double tol = 1e-10);

}  // namespace hb
