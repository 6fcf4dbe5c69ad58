// Penetration depth of two convex bodies with support functions: the minimal translation that
// separates them, and its points (the `hardbody distance` answer for overlapping pairs, DESIGN.md).
// The simulation's distance solver (geometry/distance.hpp) finds *a* stationary point of the
// contact equations, which for slight overlaps is this one, but for deep ones may be another
// (crossing needles, coincident bodies); this solver searches globally.  The distance solver
// uses it as its last fallback stage (8), where every local method failed.
//
// Derivation.  For a unit direction n the gap of the pair along n is
//     G(n) = min_{y in B} n.y - max_{x in A} n.x = n.(r_B - r_A) - h_A(n) - h_B(-n),
// h the support functions about the body centres (in the lab: h_A(n) = h_A,body(R_A^T n)).
// G(n) = -h_K(n) with K = A - B (Minkowski difference), whose support point along n is
// w(n) = x_A(n) - x_B(-n), x_A(n) the support point of A along n and x_B(-n) that of B along -n.
// B translated by t is separated from A (touching at most) iff G(n) + n.t >= 0 for some n.
//  * t = -G(n) n does it for any n, with |t| = -G(n).
//  * If |t| < -G(n) for every n then G(n) + n.t <= G(n) + |t| < 0 for every n: still overlapping.
// So the shortest separating translation has length -max_n G(n): the signed distance
//     d = max_{|n|=1} G(n)
// is minus the penetration depth when negative (and the distance when positive, the dual of the
// closest-points problem).  The maximiser n* gives the deepest pair x_A = x_A(n*), x_B = x_B(-n*).
// G extended to R^3 as Phi(v) = -h_K(v) is 1-homogeneous with gradient x_B - x_A, so on the sphere
// the Riemannian gradient is the tangential part of x_B - x_A: at n*, x_B - x_A = d n* (smooth
// shapes; on a flat face the support points are one pair of many, d is unaffected).  Every G(n)
// is a lower bound of d.
//
// Why a global search.  When d < 0, G is not concave on the sphere and has several local maxima:
// crossing needles have one where n is normal to both axes (the true depth, a peak of angular
// width ~ thickness / length) and others along the axes (one of them is what the contact
// equations found: -709.6 for aspect-1000 needles whose depth is 2); coincident ellipsoids have
// G = -2 h(n), maximal on the minor axes, minimal (-4 for semi-axis 2) on the major axis.
//
// Algorithm.
//  1. Starts: the caller's hints (the distance solver's normal), the centre line, both bodies'
//     axes (both signs), the cross products of an axis of A with an axis of B (needles cross
//     there) and the centre line with its component along each body axis removed.  The best
//     few are refined locally (step 3).
//  2. Branch and bound over the sphere: a geodesic triangulation (octahedron in A's frame,
//     cells split in four at the normalised edge midpoints).  Bound over a cell with corners
//     c_i and support points w_j = w(c_j) in K: a direction n in the cell is v / |v| with
//     v = sum lambda_i c_i (lambda_i >= 0, sum 1), and |v| lies in [nu, 1] with
//     nu = min_i c_i.c (c the cell's unit centroid: |v| >= v.c).  Since w_j is in K,
//         h_K(n) = h_K(v) / |v| >= w_j.v / |v|,  and w_j.v >= m_j = min_i w_j.c_i (linear in
//     lambda), so h_K(n) >= m_j if m_j >= 0, else m_j / nu; the best j gives a lower bound of
//     h_K over the cell, i.e. an upper bound U of G there.  (First-order in the support points,
//     so U exceeds max G over the cell by ~ R rho^2, rho the cell size, R the largest radius of
//     curvature.)  Tighter with a rolling ball: if a ball of radius r_A rolls freely inside A
//     (every principal radius of curvature >= r_A, Blaschke; for an ellipsoid r_A =
//     min(a,b,c)^2 / max(a,b,c)), A = A' + ball(r_A), so K = K' + ball(r), r = r_A + r_B, with
//     h_K = h_K' + r and w_K'(n) = w(n) - r n: the bound is applied to K' and r added back.
//     A sphere pair is then bounded exactly (K' is a point), nearly round bodies nearly so.  The cell with the largest U is split first; cells with U <= best + tol are
//     dropped.  When the largest U is within tol of the best G found, d is certified:
//     best <= d <= best + tol.  Every vertex whose G beats the best seen is refined (step 3).
//     A landscape that is flat over a large region (coincident spheres, or needles lying side
//     by side: G is flat along a great circle) needs cells of size sqrt(tol / R) over all of
//     it; the search then stops after max_cells splits with the bracket [best, largest U]
//     reported uncertified (the best found is still a lower bound of d and the local maxima
//     from the starts are exact).
//  3. Local refinement: Newton on the sphere.  With E an orthonormal tangent basis at n,
//     gradient g = E^T (x_B - x_A) and Riemannian Hessian -(E^T H E) - G I (H = H_A(n) + H_B(-n),
//     the support Hessians, positive semi-definite; -G I the curvature of the sphere).  When it
//     is negative definite the step is the Newton step, else a gradient step scaled by its
//     largest eigenvalue; the step is taken whole if it gains a quarter of its first-order
//     prediction, else the best point along the great circle in its direction is found by
//     Brent's minimiser on -G (the superquadrics' flat-face normals are only C^1 points of G,
//     where Newton 2-cycles; a line search cannot).  Stops when no ascent is found.
#pragma once
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <queue>
#include <span>
#include <utility>
#include <vector>

#include "geometry/posed.hpp"
#include "math/brent.hpp"
#include "math/types.hpp"
#include "shapes/registry.hpp"
#include "shapes/shape.hpp"
#include "shapes/superquadric.hpp"

namespace hb {

struct PenetrationOptions {
  double rel_tol = 1e-6;    // branch and bound: d certified to rel_tol * l (l: the smaller
                            // inscribed radius of the pair)
  int max_cells = 100000;   // cells split before the search stops uncertified
  int start_refines = 8;    // the best starts refined locally
  int max_refines = 40;     // local refinements in all (starts and improving vertices)
  int max_local_iter = 100;
};

struct PenetrationResult {
  double distance = -kInf;      // max over unit n of G(n): negative = minus the penetration depth
  Vec3 normal = Vec3::UnitX();  // the maximising n (lab frame; from A towards B)
  Vec3 point_a = Vec3::Zero();  // support point of A along n (lab)
  Vec3 point_b = Vec3::Zero();  // support point of B along -n (lab)
  double upper_bound = kInf;    // the signed distance lies in [distance, upper_bound]
  bool certified = false;       // upper_bound - distance <= rel_tol * l
  int evaluations = 0;          // gap evaluations (one support point of each body)
  int cells = 0;                // cells split by the branch and bound
  int refines = 0;              // local refinements run
};

namespace penetration_detail {

// The gap of the pair along n, in A's body frame (A at the origin, B at pose pb).
template <SupportShape SA, SupportShape SB>
struct Gap {
  const SA& a;
  const SB& b;
  Pose pb;
  mutable int evals = 0;

  void points(const Vec3& n, Vec3& xa, Vec3& xb) const {
    ++evals;
    xa = a.support_point(n);
    xb = pb.r + pb.R * b.support_point(-(pb.R.transpose() * n));
  }
  double value(const Vec3& n) const {
    Vec3 xa, xb;
    points(n, xa, xb);
    return n.dot(xb - xa);
  }
  Mat3 hessian(const Vec3& n) const {  // H_A(n) + H_B(-n), both positive semi-definite
    return a.support_hessian(n) +
           pb.R * b.support_hessian(-(pb.R.transpose() * n)) * pb.R.transpose();
  }
};

inline Eigen::Matrix<double, 3, 2> tangent_basis(const Vec3& n) {
  const Vec3 e1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
  Eigen::Matrix<double, 3, 2> E;
  E << e1, n.cross(e1);
  return E;
}

// Step 3 of the header: local maximisation of G from n (updated); returns G(n).
template <class Gp>
double refine(const Gp& S, Vec3& n, double scale, int max_iter) {
  n.normalize();
  Vec3 xa, xb;
  S.points(n, xa, xb);
  double G = n.dot(xb - xa);
  for (int it = 0; it < max_iter; ++it) {
    const Eigen::Matrix<double, 3, 2> E = tangent_basis(n);
    const Eigen::Vector2d g = E.transpose() * (xb - xa);
    if (!(g.norm() > 1e-15 * scale)) break;  // stationary to rounding
    Eigen::Matrix2d Hr = -(E.transpose() * S.hessian(n) * E);
    Hr.diagonal().array() -= G;
    Eigen::Vector2d t = g / scale;
    if (Hr.allFinite()) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(Hr);
      const Eigen::Vector2d ev = es.eigenvalues();
      if (ev.maxCoeff() < 0.0)
        t = -Hr.ldlt().solve(g);
      else
        t = g / std::max(ev.cwiseAbs().maxCoeff(), 1e-3 * scale);
    }
    if (!t.allFinite() || !(t.norm() > 0.0)) t = g / scale;
    const double theta = std::min(t.norm(), 0.5);
    const Vec3 u = (E * t).normalized();
    auto along = [&](double th) { return Vec3(std::cos(th) * n + std::sin(th) * u); };
    const double slope = g.dot(t.normalized());  // dG/dtheta at theta = 0 (> 0)
    double th = theta, Gt = S.value(along(theta));
    if (!(Gt - G >= 0.25 * slope * theta)) {
      const BrentMin m = brent_minimize([&](double x) { return -S.value(along(x)); }, 0.0,
                                        2.0 * theta, theta, 1e-4 * theta, 60,
                                        [](double) { return false; });
      th = m.x;
      Gt = -m.fx;
    }
    if (!(Gt > G)) break;  // no ascent along the step: a maximum to rounding
    n = along(th).normalized();
    S.points(n, xa, xb);
    G = n.dot(xb - xa);
  }
  return G;
}

struct Vertex {
  Vec3 n;  // unit direction
  Vec3 w;  // support point of K' along n: that of K = A - B minus r n (rolling ball, header)
  double G;
};

struct Cell {
  int v[3];
  double upper;  // upper bound of G over the cell (step 2 of the header)
  bool operator<(const Cell& o) const { return upper < o.upper; }  // max-heap on the bound
};

// Radius of a ball that rolls freely inside the shape (0: no claim).
inline double rolling_radius(const Sphere& s) { return s.radius; }
inline double rolling_radius(const Ellipsoid& e) {
  const double mn = std::min({e.a, e.b, e.c}), mx = std::max({e.a, e.b, e.c});
  return mn * mn / mx;
}
inline double rolling_radius(const Superquadric& q) {
  return q.n == 2.0 && q.m == 2.0 && q.p == 2.0 ? rolling_radius(Ellipsoid{q.a, q.b, q.c}) : 0.0;
}
template <class S>
double rolling_radius(const S&) { return 0.0; }

// Upper bound of G over the cell; the vertices carry w' = w - r n (support points of K').
inline double cell_upper(const Vertex& p, const Vertex& q, const Vertex& r, double roll,
                         double margin) {
  const Vertex* V[3] = {&p, &q, &r};
  const Vec3 c = (p.n + q.n + r.n).normalized();
  const double nu = std::min({p.n.dot(c), q.n.dot(c), r.n.dot(c)});
  double lower_h = -kInf;
  for (const Vertex* vj : V) {
    double m = kInf;
    for (const Vertex* vi : V) m = std::min(m, vj->w.dot(vi->n));
    lower_h = std::max(lower_h, m >= 0.0 ? m : m / nu);
  }
  return -(lower_h + roll) + margin;
}

}  // namespace penetration_detail

// Signed distance of the pair as max_n G(n) (header): minus the penetration depth when the
// bodies overlap, with the deepest pair of points.  `hints` are extra start directions (lab).
template <SupportShape SA, SupportShape SB>
PenetrationResult penetration(const SA& a, const Pose& pa, const SB& b, const Pose& pb,
                              std::span<const Vec3> hints = {}, const PenetrationOptions& o = {}) {
  using namespace penetration_detail;
  const Pose rel = relative_pose(pa, pb);  // work in A's frame
  const Gap<SA, SB> S{a, b, rel};
  const double l = std::min(a.inscribed_radius(), b.inscribed_radius());
  const double scale = a.bounding_radius() + b.bounding_radius() + rel.r.norm();
  const double tol = o.rel_tol * l;
  // G and w carry rounding of order 1e-16 scale; the bound is widened by far more than that.
  const double margin = 1e-13 * scale;
  const double roll = rolling_radius(a) + rolling_radius(b);

  PenetrationResult res;
  Vec3 best_n = Vec3::UnitX();
  double best = -kInf;
  auto local = [&](Vec3 n) {
    ++res.refines;
    const double G = refine(S, n, scale, o.max_local_iter);
    if (G > best) {
      best = G;
      best_n = n;
    }
  };

  // 1. starts, best first; the top few refined
  std::vector<Vec3> starts;
  for (const Vec3& h : hints) starts.push_back(pa.R.transpose() * h);
  starts.push_back(rel.r);
  for (int i = 0; i < 3; ++i) {
    const Vec3 ea = Vec3::Unit(i), eb = rel.R.col(i);
    for (const double s : {1.0, -1.0}) {
      starts.push_back(s * ea);
      starts.push_back(s * eb);
      starts.push_back(s * (rel.r - rel.r.dot(ea) * ea));
      starts.push_back(s * (rel.r - rel.r.dot(eb) * eb));
      for (int j = 0; j < 3; ++j) starts.push_back(s * ea.cross(rel.R.col(j)));
    }
  }
  std::vector<std::pair<double, Vec3>> scored;
  for (const Vec3& s : starts) {
    if (!(s.squaredNorm() > 1e-24 * std::max(1.0, s.squaredNorm())) || !s.allFinite()) continue;
    const Vec3 n = s.normalized();
    scored.emplace_back(S.value(n), n);
  }
  std::sort(scored.begin(), scored.end(),
            [](const auto& x, const auto& y) { return x.first > y.first; });
  for (int k = 0; k < int(scored.size()) && k < o.start_refines; ++k) local(scored[k].second);

  // 2. branch and bound
  std::vector<Vertex> V;
  auto vertex = [&](const Vec3& dir) {
    const Vec3 n = dir.normalized();
    Vec3 xa, xb;
    S.points(n, xa, xb);
    V.push_back(Vertex{n, xa - xb - roll * n, n.dot(xb - xa)});
    const int id = int(V.size()) - 1;
    if (V[id].G > best) {
      if (res.refines < o.max_refines) local(n);
      if (V[id].G > best) {  // (refinement only increases G)
        best = V[id].G;
        best_n = n;
      }
    }
    return id;
  };
  std::map<std::pair<int, int>, int> midpoint;
  auto mid = [&](int i, int j) {
    const auto key = std::minmax(i, j);
    const auto it = midpoint.find(key);
    if (it != midpoint.end()) return it->second;
    const int id = vertex(V[i].n + V[j].n);
    midpoint.emplace(key, id);
    return id;
  };
  std::priority_queue<Cell> cells;
  auto push = [&](int i, int j, int k) {
    const Cell c{{i, j, k}, cell_upper(V[i], V[j], V[k], roll, margin)};
    if (c.upper > best + tol) cells.push(c);
  };
  int oct[6];
  for (int i = 0; i < 3; ++i) {
    oct[2 * i] = vertex(Vec3::Unit(i));
    oct[2 * i + 1] = vertex(-Vec3::Unit(i));
  }
  for (const int x : {0, 1})
    for (const int y : {2, 3})
      for (const int z : {4, 5}) push(oct[x], oct[y], oct[z]);
  double unresolved = -kInf;  // bound of cells too small to split further
  while (!cells.empty()) {
    const Cell c = cells.top();
    if (c.upper <= best + tol) break;  // every remaining cell is within tol of the best
    if (res.cells >= o.max_cells) break;
    cells.pop();
    if ((V[c.v[0]].n - V[c.v[1]].n).norm() < 1e-12) {  // rounding-sized: its bound stands
      unresolved = std::max(unresolved, c.upper);
      continue;
    }
    ++res.cells;
    const int m01 = mid(c.v[0], c.v[1]), m12 = mid(c.v[1], c.v[2]), m20 = mid(c.v[2], c.v[0]);
    push(c.v[0], m01, m20);
    push(m01, c.v[1], m12);
    push(m20, m12, c.v[2]);
    push(m01, m12, m20);
  }
  const double open = cells.empty() ? -kInf : cells.top().upper;
  res.upper_bound = std::max({best, open, unresolved});
  // separated bodies: any pair of points bounds the distance from above
  Vec3 xa, xb;
  S.points(best_n, xa, xb);
  if (best > 0.0) res.upper_bound = std::min(res.upper_bound, (xb - xa).norm());
  res.certified = res.upper_bound - best <= tol;
  res.distance = best;
  res.normal = pa.R * best_n;
  res.point_a = pa.r + pa.R * xa;
  res.point_b = pa.r + pa.R * xb;
  res.evaluations = S.evals;
  return res;
}

// The same for any pair of engine shapes (compiled once, in geometry/penetration.cpp).
PenetrationResult penetration(const AnyShape& a, const Pose& pa, const AnyShape& b,
                              const Pose& pb, std::span<const Vec3> hints = {},
                              const PenetrationOptions& o = {});

}  // namespace hb
