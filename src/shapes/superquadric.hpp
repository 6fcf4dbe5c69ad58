// Superquadric |x/a|^n + |y/b|^m + |z/c|^p <= 1 (paper section 5, Eq. SQdef), exponents >= 2,
// semi-axes (a, b, c) along body x, y, z.  Derivations and measurements: docs/superquadrics.md.
//
// Implicit function.  With t_i = |x_i| / a_i, e = (n, m, p), S(x) = sum_i t_i^e_i and
// E = max(e), we use
//     F(x) = S(x)^(1/E) - 1                       (same zero set as the paper's S - 1)
// instead of S - 1.  When all exponents are equal F is the gauge (Minkowski norm) of the body
// minus one: convex, positively homogeneous of degree 1, so F grows linearly away from the
// surface, its gradient is constant along rays and Newton steps along a ray are exact.  With
// mixed exponents it is homogeneous of degree between e_min/E and 1 along every ray (never
// steeper than linear), whereas S - 1 grows like |x|^20 for p = 20 (Newton from outside then
// creeps back 1/20 of the way per step and overshoots wildly from inside).  |grad F| on the
// surface lies in [e_min/(E a_max), 1/a_min]: no scale that grows with the exponent.
//     grad F = rho/S * (e_i/E) sgn(x_i) t_i^(e_i-1) / a_i,                      rho = S^(1/E)
//     hess F = diag( rho/S * e_i (e_i-1) / (E a_i^2) * t_i^(e_i-2) ) - (E-1)/rho * g g^T
// (g = grad F).  The two diagonal terms nearly cancel where one term w_i = t_i^e_i dominates S
// (F is then nearly linear along x_i); the diagonal is evaluated in the equivalent form
//     H_ii = rho/S e_i t_i^(e_i-2) / (E a_i^2) [ (e_i/E - 1) + (E-1)(e_i/E) sigma_i ],
// sigma_i = sum_{j != i} w_j / S, which has no cancellation when e_i = E.  For e_i >= 2 every power t^(e_i-1), t^(e_i-2) is bounded as t_i -> 0 (t^0 = 1
// for e_i = 2), so F, grad F and hess F are finite at and near the coordinate planes.  At a
// point with x_i = 0 and e_i > 2 the i-th diagonal entry is exactly 0: the surface has zero
// curvature there (the flat face centres of a high-exponent body), a genuine property of the
// shape that every f with this zero set shares in its tangential Hessian.  Powers are taken
// with pow() (by squaring for an integer exponent; rho = S^(1/E) as nested square roots when E
// is a power of two) when S lies in [1e-250, 1e250]; outside (only far from the surface or
// within ~1e-250^(1/e) of the centre) the same formulas are evaluated from logarithms, so
// nothing overflows or underflows.  At the centre itself F = -1 and grad, hess are returned as
// 0 (F is not differentiable there when the exponents differ; no solver evaluates it there).
//
// Support function (SupportShape).  max n.x over the body: the Lagrange condition
// n_i = lambda e_i t_i^(e_i-1) sgn(x_i) / a_i gives t_i = (c_i / lambda)^(1/(e_i-1)),
// c_i = |n_i| a_i / e_i, and the constraint sum t_i^e_i = 1 becomes the 1-D equation
//     sum_i (c_i / lambda)^(q_i) = 1,   q_i = e_i / (e_i - 1) in (1, 2],
// solved for s = log lambda by Newton on psi(s) = log sum exp(q_i (log c_i - s)), which is
// convex and decreasing with slope in [-q_max, -q_min]; started left of the root (psi >= 0, at
// the closed-form root of the same equation with every q_i = q_max, sq_detail::log_root) Newton
// increases monotonically to the root (no overshoot, no bracket needed), in ~3 steps; exact at
// once when all exponents are equal.  The support point itself uses the same equation in
// y = 1/lambda with pow instead of exp/log and Halley steps (Superquadric::support_point).  h = n.x.  Support Hessian (dx/dn):
//     (1/lambda) [ diag(a_i^2 t_i^(2-e_i) / (e_i (e_i-1))) - (r.x)(r.x)^T / W ],
//     r_i = 1/(e_i-1),  W = sum q_i t_i^e_i,
// which is infinite at n_i = 0 when e_i > 2 (the support point sweeps across the flat face);
// there the diagonal is capped at 1e12 h / |n|^2 (a large finite value, documented).
//
// Ray from the centre: s u with sum (s |u_i| / a_i)^e_i = 1, the same kind of 1-D equation in
// log s (slopes e_i), solved the same way.
//
// Bounding radius: max |x|^2 over the surface = max sum a_i^2 u_i^(2/e_i) over the simplex
// u_i = t_i^e_i >= 0, sum u_i = 1, a concave maximisation (2/e_i <= 1) solved exactly by its KKT
// conditions (again a 1-D equation of the same kind); returned with a 1e-12 relative margin.
// Inscribed radius: min(a, b, c) exactly (|x|^2 = sum a_i^2 t_i^2 >= a_min^2 sum t_i^e_i).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <queue>
#include <utility>
#include <vector>

#include <Eigen/LU>

#include "math/types.hpp"
#include "shapes/shape.hpp"

namespace hb {

namespace sq_detail {

// Root s of sum_i exp(k_i (v_i - s)) = 1 (k_i > 0; v_i = -inf drops term i; at least one
// finite v_i).  psi(s) = log sum exp(k_i (v_i - s)) is convex and decreasing, so Newton started
// left of the root (psi >= 0) increases monotonically to it.  Start: with k_max = max k_i,
// exp(k_i (v_i - s)) >= exp(k_max (v_i - s)) wherever v_i <= s, so the closed-form root of the
// k_max problem, s0 = log(sum exp(k_max v_i)) / k_max (>= max v_i), has psi(s0) >= 0; it is the
// exact root when all k_i are equal (one evaluation then confirms it) and close to it when they
// differ little, e.g. (2, 2, p) superquadrics: ~3 steps instead of ~5 from max v_i.
inline double log_root(const Vec3& k, const Vec3& v) {
  const double kmax = std::max({k[0], k[1], k[2]});
  double vmax = -kInf;
  for (int i = 0; i < 3; ++i) vmax = std::max(vmax, v[i]);
  double sum0 = 0.0;
  for (int i = 0; i < 3; ++i)
    if (v[i] > -kInf) sum0 += std::exp(kmax * (v[i] - vmax));
  double s = vmax + std::log(sum0) / kmax;
  for (int it = 0; it < 100; ++it) {
    double top = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i)
      if (v[i] > -kInf) top = std::max(top, k[i] * (v[i] - s));
    double sum = 0.0, dsum = 0.0;
    for (int i = 0; i < 3; ++i) {
      if (!(v[i] > -kInf)) continue;
      const double w = std::exp(k[i] * (v[i] - s) - top);
      sum += w;
      dsum += k[i] * w;
    }
    const double psi = top + std::log(sum);
    const double step = psi * sum / dsum;  // -psi / psi'
    if (!(step > 0.0)) break;              // at (or, by rounding, past) the root
    s += step;
    if (step <= 2e-16 * std::max(1.0, std::abs(s))) break;
  }
  return s;
}

// The root of the (2, 2, p) support-point equation (Superquadric::flat_support_point): x(K) in
// (0, 1] with x^p + K x^(2p-2) = 1, K >= 0, tabulated once per integer p in 3..16 to a few ulps,
// so a support point needs no iteration.  x is a smooth function of the one number z = 1 + K,
// cut at the bits of z: each binade [2^E, 2^(E+1)) (1 <= E < kBinades) into 2^kBits segments by
// the leading mantissa bits, the first binade (K < 1) into 2^kBits0, and on each segment x is
// the degree-8 interpolant at 9 Chebyshev nodes of the local coordinate u in [0, 1) (the
// remaining mantissa bits), evaluated by Estrin's scheme: no log, pow or division.  The first
// binade needs the finer cut: x(K) has a branch point at K ~ -0.3 (where G and G' vanish
// together: x^p = (2p-2)/(p-2), |K| = p / ((2p-2) x^(p-2))), 0.3 from it, against ~1.3 binade
// widths for the others.  Beyond kBinades binades, with x0 = z^(-1/(2p-2)) = 2^(-E/(2p-2)) (1 +
// m)^(-1/(2p-2)) (one fitted segment set, scaled), x = x0 (1 - x0^p / (2p-2)): with
// eps = x0^p the root is x0 w, w^(2p-2) + eps w^p = 1, w = 1 - eps / (2p-2) + 3 eps^2 /
// (2 (2p-2)^2) + ..., and eps <= 2^(-56 p / (2p-2)) < 2^-29 there, so the neglected term is
// below 1e-18.  The nodes' roots are solved in long double (Newton from the right, from x0,
// where G(x0) = x0^p - x0^(2p-2) >= 0) and the coefficients fitted in long double, so the
// table's error is its fit (measured below 3e-17 before rounding for p = 3, 8, 16) plus the
// rounding of the stored coefficients and of the evaluation.  Measured over every segment
// (tests/shapes/test_superquadric.cpp, FlatRootTableIsWithinAFewUlps): within 3.3e-16 for every
// p.  This replaced a quartic start within 6e-8 followed by one Halley step (the same accuracy,
// ~40 instructions and a division more per point).  Size: (32 + 55 * 16 + 16) * 9 doubles,
// 66 KB per p, of which a run touches the few binades its directions use.
struct FlatRootTable {
  static constexpr int kBits = 4, kBits0 = 5, kBinades = 56, kCoef = 9;
  static constexpr int kNear = (1 << kBits0) + (kBinades - 1) * (1 << kBits);
  int p = 0;
  double inv_q = 0.0;        // 1 / (2p - 2)
  double near[kNear][kCoef];
  double far[1 << kBits][kCoef];
  double scale[32];  // 2^(-r/(2p-2)), r < 2p - 2 <= 30
  // The row of segment j of binade e < kBinades
  static int segment(int e, int j) { return e == 0 ? j : (1 << kBits0) + ((e - 1) << kBits) + j; }
  static double estrin(const double* c, double u) {
    const double u2 = u * u, u4 = u2 * u2;
    const double a = (c[0] + c[1] * u) + u2 * (c[2] + c[3] * u);
    const double b = (c[4] + c[5] * u) + u2 * (c[6] + c[7] * u);
    return a + u4 * (b + u4 * c[8]);
  }
  double root(double K) const {
    const double z = 1.0 + K;
    std::uint64_t bits;
    std::memcpy(&bits, &z, 8);
    const int e = static_cast<int>(bits >> 52) - 1023;  // >= 0: z >= 1
    const bool first = e == 0;
    const int shift = 52 - (first ? kBits0 : kBits);
    const int j = static_cast<int>((bits & ((std::uint64_t{1} << 52) - 1)) >> shift);
    const double u = static_cast<double>(bits & ((std::uint64_t{1} << shift) - 1)) *
                     (first ? 0x1p-47 : 0x1p-48);
    if (e < kBinades) return estrin(near[segment(e, j)], u);
    // 2^-d from its bits (d <= 1024 / 4: a normal number), not std::ldexp: a call here would
    // make the callers' hot path save registers
    const int q = 2 * p - 2, d = e / q, r = e - d * q;
    const std::uint64_t pow2 = static_cast<std::uint64_t>(1023 - d) << 52;
    double two_d;
    std::memcpy(&two_d, &pow2, 8);
    const double x0 = estrin(far[j], u) * scale[r] * two_d;
    double xp = 1.0;
    for (int k = 0; k < p; ++k) xp *= x0;
    return x0 - x0 * xp * inv_q;
  }
};
inline FlatRootTable make_flat_root_table(int p) {
  using LD = long double;
  FlatRootTable t;
  t.p = p;
  const int q = 2 * p - 2;
  t.inv_q = 1.0 / q;
  constexpr int n = FlatRootTable::kCoef;
  using VecL = Eigen::Matrix<LD, n, 1>;
  using MatL = Eigen::Matrix<LD, n, n>;
  VecL u;
  MatL V;
  for (int i = 0; i < n; ++i) {
    u[i] = 0.5L * (1.0L - std::cos(std::numbers::pi_v<LD> * (i + 0.5L) / n));
    for (int k = 0; k < n; ++k) V(i, k) = std::pow(u[i], LD(k));
  }
  const Eigen::FullPivLU<MatL> lu(V);  // (solved per segment: an explicit inverse loses 1e-14)
  // Newton from the right: G is convex and increasing on [0, 1] and G(x0) >= 0, so the iterates
  // fall monotonically to the root; stop when rounding stops them
  auto root = [p, q](LD K) {
    LD x = std::min(LD(1), std::pow(1.0L + K, LD(-1) / q));
    for (int it = 0; it < 500; ++it) {
      LD xp1 = 1;
      for (int k = 0; k < p - 1; ++k) xp1 *= x;
      const LD w3 = xp1 * x, w12 = K * xp1 * xp1;
      const LD G = w3 + w12 - 1, g1 = p * w3 + q * w12;  // g1 = x G'
      if (!(G > 0) || !(g1 > 0)) break;
      const LD next = x - x * G / g1;
      if (!(next < x)) break;
      x = next;
    }
    return x;
  };
  auto store = [&](double* c, const VecL& v) {
    const VecL cf = lu.solve(v);
    for (int k = 0; k < n; ++k) c[k] = static_cast<double>(cf[k]);
  };
  VecL v;
  for (int E = 0; E < FlatRootTable::kBinades; ++E) {
    const int segs = 1 << (E == 0 ? FlatRootTable::kBits0 : FlatRootTable::kBits);
    for (int j = 0; j < segs; ++j) {
      for (int i = 0; i < n; ++i) v[i] = root(std::ldexp(1.0L + (j + u[i]) / segs, E) - 1.0L);
      store(t.near[FlatRootTable::segment(E, j)], v);
    }
  }
  constexpr int fsegs = 1 << FlatRootTable::kBits;
  for (int j = 0; j < fsegs; ++j) {
    for (int i = 0; i < n; ++i) v[i] = std::pow(1.0L + (j + u[i]) / fsegs, LD(-1) / q);
    store(t.far[j], v);
  }
  for (int r = 0; r < 32; ++r) t.scale[r] = static_cast<double>(std::exp2(-LD(r) / q));
  return t;
}
template <int P>
const FlatRootTable& flat_root_table() {
  static const FlatRootTable t = make_flat_root_table(P);
  return t;
}
// The rotation lever of a superquadric (shapes/shape.hpp): an upper bound of |x x n| over the
// surface points x and their outward unit normals n, by branch and bound.
//
// With t_i = |x_i| / a_i (sum t_i^e_i = 1 on the surface), the outward normal is along
// g_i = (e_i / a_i) t_i^(e_i-1) sgn(x_i), and |x x n| is the distance from x to the line along g:
//     |x x n|^2 = min over mu of |x - mu g|^2 = |x|^2 - (x.g)^2 / |g|^2,
//     x.g = sum e_i t_i^e_i,   |g|^2 = sum (e_i^2 / a_i^2) t_i^(2e_i-2),   |x|^2 = sum a_i^2 t_i^2.
// Charts: chart k holds the surface points with t_k^e_k >= 1/3 (every point is in one: the three
// terms sum to 1), parametrised by the other two, (t_i, t_j) with t_i^e_i + t_j^e_j <= 2/3, and
// t_k = (1 - t_i^e_i - t_j^e_j)^(1/e_k), whose slope is bounded there.  Over a box of a chart
// each t lies in an interval [lo, hi] (t_k's from the box's corners), and two bounds hold:
//  (1) monotone: every power above increases with t (e_i >= 2), so
//      |x x n|^2 <= sum a_i^2 hi_i^2 - max(sum e_i lo_i^e_i, e_min)^2 / sum (e_i^2/a_i^2) hi_i^(2e_i-2)
//      (sum e_i t_i^e_i >= e_min on the surface);
//  (2) envelope: for any mu, |x x n|^2 <= |x - mu g|^2 = sum_i psi_i(t_i)^2 with
//      psi_i(t) = a_i t - mu (e_i / a_i) t^(e_i-1) (x_i and g_i have the same sign), whose
//      largest |psi_i| on [lo, hi] is at an end or where psi_i' = 0,
//      t* = (a_i^2 / (mu e_i (e_i - 1)))^(1/(e_i-2)) (e_i > 2; psi_i is linear when e_i = 2).
//      mu is the minimiser x.g / |g|^2 at the box's centre, so the bound is exact there and
//      close to the function on small boxes (measured on the (2, 2, 8) body of the benchmarks:
//      39 boxes split at rtol = 1e-2 with the least of (1) and (2), 2833 with (1) alone; 266 at
//      rtol = 1e-3).
// The box of the largest bound is split in four and the function evaluated at its centre, until
// the largest bound is within (1 + rtol)^2 of the best value found, or max_boxes boxes have been
// split.  Whatever the stop, the largest bound of the boxes left or dropped bounds the maximum
// (rigorously up to the rounding of the formulas, which the absolute 1e-12 |a|^2 covers: every
// term is at most L^2 <= |a|^2 or its square root).  The caller scales the body to a_max = 1.  Returned: the square root of that bound, within a
// factor 1 + rtol of the lever when the search ends by the tolerance; the caller takes the
// least of it and the generic sqrt(L^2 - r_in^2).  (0.8, 1.6, 1.6) with exponents (2, 2, 8):
// 1.1854 (the lever ~1.1843; the generic bound 1.769); (2, 2, 4): 0.9816 (generic 1.600).
inline double lever_bound(const Vec3& ax, const Vec3& e, double rtol = 1e-3, int max_boxes = 20000) {
  Vec3 ca, cg, pg;  // a_i^2, e_i^2/a_i^2, 2e_i - 2
  for (int i = 0; i < 3; ++i) {
    ca[i] = ax[i] * ax[i];
    cg[i] = e[i] * e[i] / ca[i];
    pg[i] = 2.0 * e[i] - 2.0;
  }
  const double e_min = e.minCoeff();
  struct Box {
    double ub, lo_i, lo_j, hi_i, hi_j;
    int k;
    bool operator<(const Box& o) const { return ub < o.ub; }
  };
  // x.g and |g|^2 at (t_i, t_j, t_k) of chart k; w = t^e of the first two
  auto dot_and_norm = [&](int k, double t_i, double t_j, double t_k, double wi, double wj) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double xg = e[i] * wi + e[j] * wj + e[k] * (1.0 - wi - wj);
    const double gg =
        cg[i] * std::pow(t_i, pg[i]) + cg[j] * std::pow(t_j, pg[j]) + cg[k] * std::pow(t_k, pg[k]);
    return std::pair{xg, gg};
  };
  auto value = [&](int k, double t_i, double t_j) {  // |x x n|^2 (-1: off the surface)
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double wi = std::pow(t_i, e[i]), wj = std::pow(t_j, e[j]);
    if (wi + wj > 1.0) return -1.0;
    const double t_k = std::pow(1.0 - wi - wj, 1.0 / e[k]);
    const auto [xg, gg] = dot_and_norm(k, t_i, t_j, t_k, wi, wj);
    return ca[i] * t_i * t_i + ca[j] * t_j * t_j + ca[k] * t_k * t_k - xg * xg / gg;
  };
  auto psi_max = [&](int i, double mu, double lo, double hi) {  // bound (2), one term
    auto psi = [&](double t) { return ax[i] * t - mu * e[i] / ax[i] * std::pow(t, e[i] - 1.0); };
    double m = std::max(std::abs(psi(lo)), std::abs(psi(hi)));
    if (e[i] > 2.0) {
      const double ts = std::pow(ca[i] / (mu * e[i] * (e[i] - 1.0)), 1.0 / (e[i] - 2.0));
      if (ts > lo && ts < hi) m = std::max(m, std::abs(psi(ts)));
    }
    return m * m;
  };
  auto bound = [&](int k, double lo_i, double lo_j, double hi_i, double hi_j) {  // -1: empty
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const double wi = std::pow(lo_i, e[i]), wj = std::pow(lo_j, e[j]);
    if (wi + wj > 2.0 / 3.0) return -1.0;
    const double wk_lo = 1.0 - std::min(std::pow(hi_i, e[i]) + std::pow(hi_j, e[j]), 2.0 / 3.0);
    const double hi_k = std::pow(1.0 - wi - wj, 1.0 / e[k]), lo_k = std::pow(wk_lo, 1.0 / e[k]);
    // (1)
    const double num = ca[i] * hi_i * hi_i + ca[j] * hi_j * hi_j + ca[k] * hi_k * hi_k;
    const double xg_lo = std::max(e[i] * wi + e[j] * wj + e[k] * wk_lo, e_min);
    const double gg_hi =
        cg[i] * std::pow(hi_i, pg[i]) + cg[j] * std::pow(hi_j, pg[j]) + cg[k] * std::pow(hi_k, pg[k]);
    const double monotone = num - xg_lo * xg_lo / gg_hi;
    // (2), mu from the centre
    const double mi = 0.5 * (lo_i + hi_i), mj = 0.5 * (lo_j + hi_j);
    const double wmi = std::pow(mi, e[i]), wmj = std::pow(mj, e[j]);
    const double mk = std::pow(std::max(0.0, 1.0 - wmi - wmj), 1.0 / e[k]);
    const auto [xg, gg] = dot_and_norm(k, mi, mj, mk, wmi, wmj);
    const double mu = xg / gg;
    const double envelope = psi_max(i, mu, lo_i, hi_i) + psi_max(j, mu, lo_j, hi_j) + psi_max(k, mu, lo_k, hi_k);
    return std::min(monotone, envelope);
  };
  const double slack = (1.0 + rtol) * (1.0 + rtol);
  std::priority_queue<Box> heap;
  for (int k = 0; k < 3; ++k) {
    const double hi_i = std::pow(2.0 / 3.0, 1.0 / e[(k + 1) % 3]);
    const double hi_j = std::pow(2.0 / 3.0, 1.0 / e[(k + 2) % 3]);
    heap.push(Box{bound(k, 0.0, 0.0, hi_i, hi_j), 0.0, 0.0, hi_i, hi_j, k});
  }
  double best = 0.0, dropped = 0.0;  // the best value seen; the largest bound of a dropped box
  for (int n = 0; n < max_boxes && !heap.empty() && heap.top().ub > best * slack; ++n) {
    const Box b = heap.top();
    heap.pop();
    const double mi = 0.5 * (b.lo_i + b.hi_i), mj = 0.5 * (b.lo_j + b.hi_j);
    best = std::max(best, value(b.k, mi, mj));
    const double li[2] = {b.lo_i, mi}, hi[2] = {mi, b.hi_i}, lj[2] = {b.lo_j, mj}, hj[2] = {mj, b.hi_j};
    for (int p = 0; p < 2; ++p)
      for (int q = 0; q < 2; ++q) {
        const double u = bound(b.k, li[p], lj[q], hi[p], hj[q]);
        if (u > best * slack) heap.push(Box{u, li[p], lj[q], hi[p], hj[q], b.k});
        else dropped = std::max(dropped, u);
      }
  }
  const double top = std::max({best, dropped, heap.empty() ? 0.0 : heap.top().ub});
  const double L2 = ax.squaredNorm();  // >= |x|^2 on the surface (t_i <= 1)
  return std::sqrt(std::max(0.0, top) + 1e-12 * L2);
}
}  // namespace sq_detail

// The fields are set by the constructor, which also caches shape constants (the bounding radius,
// which costs a root solve with logs and exps, and the support function's per-axis constants);
// treat them as read-only: build a new Superquadric to change a shape.
struct Superquadric {
  static constexpr const char* kName = "superquadric";
  // |x_i| only: h(-n) = h(n), p(-n) = -p(n) bit for bit (shapes/shape.hpp)
  static constexpr bool kCentrallySymmetric = true;
  static constexpr bool kSupportIsPointDot = true;  // support() below
  double a = 1.0, b = 1.0, c = 1.0;  // semi-axes along body x, y, z
  double n = 2.0, m = 2.0, p = 2.0;  // exponents (>= 2) of |x/a|, |y/b|, |z/c|

  Superquadric() { cache(); }
  Superquadric(double a_, double b_, double c_, double n_, double m_, double p_)
      : a(a_), b(b_), c(c_), n(n_), m(m_), p(p_) {
    cache();
  }

  // The same body scaled by s > 0 about its centre (shapes/registry.hpp, resized): the
  // constants that depend only on the exponents are copied, the bounding radius is solved again
  // (as the constructor does), and the rotation lever, homogeneous of degree 1 in the size, is
  // scaled (its branch and bound is not run again: polydisperse neighbour lists resize a body's
  // shape at every list build).  The ellipsoid's a_max - a_min is taken again from the axes.
  Superquadric resized(double s) const {
    Superquadric r = *this;
    r.a = a * s;
    r.b = b * s;
    r.c = c * s;
    const Vec3 e = exponents(), ax = r.axes();
    for (int i = 0; i < 3; ++i) r.a_over_e_[i] = ax[i] / e[i];
    r.bounding_radius_ = r.farthest_point().norm() * (1.0 + 1e-12);
    const double scaled = lever_ * s;  // searched again only if that is not finite
    r.set_lever(two_[0] && two_[1] && two_[2] ? 0.0
                : std::isfinite(scaled) && scaled > 0.0 ? scaled : r.searched_lever());
    return r;
  }

  Vec3 axes() const { return Vec3(a, b, c); }
  Vec3 exponents() const { return Vec3(n, m, p); }
  double e_max() const { return std::max({n, m, p}); }

  // rho/S * t_i^(e_i-1), rho/S * t_i^(e_i-2) and rho = S^(1/E) at x (see header).
  struct Powers {
    Vec3 t, d1, d2;  // t_i, rho/S t_i^(e_i-1), rho/S t_i^(e_i-2)
    double rho = 0.0;
    bool centre = false;
  };
  Powers powers(const Vec3& x) const {
    Powers P;
    const Vec3 e = exponents(), ax = axes();
    const double E = e_max();
    P.t = x.cwiseAbs().cwiseQuotient(ax);
    if (P.t.maxCoeff() == 0.0) {
      P.centre = true;
      P.d1.setZero();
      P.d2.setZero();
      return P;
    }
    Vec3 w;
    double S = 0.0;
    for (int i = 0; i < 3; ++i) {
      P.d2[i] = power_e_minus_2(P.t[i], i);
      P.d1[i] = P.d2[i] * P.t[i];
      w[i] = P.d1[i] * P.t[i];
      S += w[i];
    }
    if (S >= 1e-250 && S <= 1e250) {
      P.rho = rho_sqrts_ >= 0 ? nested_sqrt(S, rho_sqrts_) : std::pow(S, 1.0 / E);
      const double k = P.rho / S;
      P.d1 *= k;
      P.d2 *= k;
      return P;
    }
    // Far from the surface: the same quantities from logarithms.
    Vec3 lt, l;
    double lmax = -kInf;
    for (int i = 0; i < 3; ++i) {
      lt[i] = P.t[i] > 0.0 ? std::log(P.t[i]) : -kInf;
      l[i] = P.t[i] > 0.0 ? e[i] * lt[i] : -kInf;
      lmax = std::max(lmax, l[i]);
    }
    double sum = 0.0;
    for (int i = 0; i < 3; ++i) sum += std::exp(l[i] - lmax);
    const double LS = lmax + std::log(sum);  // log S
    const double lk = LS / E - LS;           // log(rho / S)
    P.rho = std::exp(LS / E);
    for (int i = 0; i < 3; ++i) {
      if (P.t[i] > 0.0) {
        P.d1[i] = std::exp((e[i] - 1.0) * lt[i] + lk);
        P.d2[i] = e[i] == 2.0 ? std::exp(lk) : std::exp((e[i] - 2.0) * lt[i] + lk);
      } else {
        P.d1[i] = 0.0;
        P.d2[i] = e[i] == 2.0 ? std::exp(lk) : 0.0;
      }
    }
    return P;
  }

  double f(const Vec3& x) const {
    const Powers P = powers(x);
    return P.centre ? -1.0 : P.rho - 1.0;
  }
  Vec3 grad(const Vec3& x) const { return grad_of(x, powers(x)); }
  Mat3 hessian(const Vec3& x) const {
    const Powers P = powers(x);
    if (P.centre) return Mat3::Zero();
    const Vec3 e = exponents(), ax = axes();
    const double E = e_max();
    const Vec3 g = grad_of(x, P);
    Mat3 H = -((E - 1.0) / P.rho) * g * g.transpose();
    // Diagonal without cancellation (see header): with sigma_i = sum_{j != i} w_j / S,
    // H_ii = rho/S e_i t_i^(e_i-2) / (E a_i^2) [(e_i/E - 1) + (E-1) (e_i/E) sigma_i].
    const Vec3 wS = P.t.cwiseProduct(P.d1) / P.rho;  // w_j / S
    for (int i = 0; i < 3; ++i) {
      const double sigma = wS.sum() - wS[i];
      H(i, i) = e[i] * P.d2[i] / (E * ax[i] * ax[i]) *
                ((e[i] / E - 1.0) + (E - 1.0) * (e[i] / E) * sigma);
    }
    return H;
  }

  double volume() const {
    return 8.0 * a * b * c * std::tgamma(1.0 + 1.0 / n) * std::tgamma(1.0 + 1.0 / m) *
           std::tgamma(1.0 + 1.0 / p) / std::tgamma(1.0 + 1.0 / n + 1.0 / m + 1.0 / p);
  }
  // max |x| over the body (exact, see header) with a 1e-12 relative safety margin.
  double bounding_radius() const { return bounding_radius_; }
  double inscribed_radius() const { return std::min({a, b, c}); }
  // shapes/shape.hpp: the ellipsoid's a_max - a_min when all exponents are 2, else the branch
  // and bound of sq_detail::lever_bound (at most 1e-3 above the true lever), capped by the
  // generic sqrt(L^2 - r_in^2).
  double rotation_lever() const { return lever_; }
  // Largest principal radius of curvature (the axis-gap curvature bound, contact/axis_gap.hpp):
  // a_max^2 / a_min when all exponents are 2 (an ellipsoid); +inf otherwise, since an exponent
  // e_i > 2 flattens the surface where it meets the i-th coordinate plane (zero curvature).
  double max_curvature_radius() const {
    if (!(two_[0] && two_[1] && two_[2])) return kInf;
    const double mx = std::max({a, b, c}), mn = std::min({a, b, c});
    return mx * mx / mn;
  }
  Vec3 half_extents() const { return axes(); }

  // The surface point along u (any length, nonzero): s u with sum (s |u_i| / a_i)^e_i = 1.
  Vec3 ray_surface(const Vec3& u) const {
    const Vec3 e = exponents(), ax = axes();
    Vec3 v;  // log(|u_i| / a_i);  the root is log(1/s)
    for (int i = 0; i < 3; ++i) v[i] = u[i] != 0.0 ? std::log(std::abs(u[i]) / ax[i]) : -kInf;
    return u * std::exp(-sq_detail::log_root(e, v));
  }

  // A surface point at distance max |x| from the centre (first octant).  KKT of
  // max sum a_i^2 u_i^(2/e_i) on the simplex: u_i = (2 a_i^2 / (e_i nu))^(e_i/(e_i-2)) for
  // e_i > 2; axes with e_i = 2 have constant slope a_i^2, so the largest of them takes the
  // remaining mass when nu = its a_i^2 leaves some, otherwise they get none.
  Vec3 farthest_point() const {
    const Vec3 e = exponents(), ax = axes();
    Vec3 k, v;
    double a2 = 0.0;  // largest a_i^2 among e_i = 2
    int i2 = -1;
    bool any_high = false;
    for (int i = 0; i < 3; ++i) {
      if (e[i] > 2.0) {
        k[i] = e[i] / (e[i] - 2.0);
        v[i] = std::log(2.0 * ax[i] * ax[i] / e[i]);
        any_high = true;
      } else {
        k[i] = 1.0;
        v[i] = -kInf;
        if (ax[i] * ax[i] > a2) {
          a2 = ax[i] * ax[i];
          i2 = i;
        }
      }
    }
    Vec3 u = Vec3::Zero();
    auto fill = [&](double log_nu) {
      for (int i = 0; i < 3; ++i)
        if (e[i] > 2.0) u[i] = std::exp(k[i] * (v[i] - log_nu));
    };
    if (!any_high) {
      u[i2] = 1.0;
    } else if (i2 >= 0) {
      fill(std::log(a2));
      const double g = u.sum();
      if (g <= 1.0) u[i2] = 1.0 - g;
      else fill(sq_detail::log_root(k, v));
    } else {
      fill(sq_detail::log_root(k, v));
    }
    Vec3 x;
    for (int i = 0; i < 3; ++i) x[i] = ax[i] * std::pow(u[i], 1.0 / e[i]);
    return ray_surface(x);  // exact surface point (removes the rounding of the simplex sum)
  }

  // Support function h(d) = max_{x in body} d.x, its gradient and its Hessian (see header).
  double support(const Vec3& d) const { return d.dot(support_point(d)); }
  Vec3 support_point(const Vec3& d) const {
    double lambda;
    return support_point(d, lambda);
  }
  Mat3 support_hessian(const Vec3& d) const {
    double lambda;
    const Vec3 x = support_point(d, lambda);
    const Vec3 e = exponents(), ax = axes();
    if (!(lambda > 0.0)) return Mat3::Zero();
    const double h = d.dot(x), cap = 1e12 * h / d.squaredNorm();
    Vec3 rx;
    double W = 0.0;
    Mat3 H = Mat3::Zero();
    for (int i = 0; i < 3; ++i) {
      const double t = std::abs(x[i]) / ax[i];
      rx[i] = x[i] / (e[i] - 1.0);
      W += e[i] / (e[i] - 1.0) * std::pow(t, e[i]);
      const double diag = ax[i] * ax[i] * std::pow(t, 2.0 - e[i]) / (e[i] * (e[i] - 1.0));
      H(i, i) = std::min(diag / lambda, cap);
    }
    return H - rx * rx.transpose() / (lambda * W);
  }
  // (2, 2, p) bodies with integer p in 3..16: the root of x^p + K x^(2p-2) = 1 their
  // support-point solver takes from a table (sq_detail::FlatRootTable; the tests bound its error)
  bool has_flat_root_table() const { return flat_table_ != nullptr; }
  double flat_root(double K) const { return flat_table_->root(K); }
  // (u^T H u, u^T H v, v^T H v) for H = support_hessian(d), given the support point x =
  // support_point(d): no second root solve and no matrix (contact/axis_gap.hpp).  The multiplier
  // comes from x itself: d_i x_i = lambda e_i t_i^e_i, so lambda = h / sum e_i t_i^e_i (h = d.x).
  // One power per axis with e_i > 2, t_i^(e_i-2) (by squaring when e_i is an integer), gives both
  // t_i^e_i and the diagonal's t_i^(2-e_i); the diagonal has the same cap as support_hessian,
  // which the shape tests compare with.
  Vec3 support_hessian_forms(const Vec3& d, const Vec3& x, const Vec3& u, const Vec3& v) const {
    const Vec3 e = exponents(), ax = axes();
    const double h = d.dot(x);
    Vec3 t, te2, diag;
    double sum_et = 0.0, W = 0.0;
    for (int i = 0; i < 3; ++i) {
      t[i] = std::abs(x[i]) / ax[i];
      te2[i] = power_e_minus_2(t[i], i);
      const double te = te2[i] * t[i] * t[i];  // t_i^e_i
      sum_et += e[i] * te;
      W += q_[i] * te;
    }
    if (!(h > 0.0) || !(sum_et > 0.0)) return Vec3::Zero();
    const double lambda = h / sum_et, cap = 1e12 * h / d.squaredNorm();
    for (int i = 0; i < 3; ++i)
      diag[i] = std::min(ax[i] * ax[i] * inv_em1_[i] / (e[i] * lambda * te2[i]), cap);
    const Vec3 rx = x.cwiseProduct(inv_em1_);
    const double ru = rx.dot(u), rv = rx.dot(v), lW = lambda * W;
    const Vec3 Du = diag.cwiseProduct(u);
    return Vec3(u.dot(Du) - ru * ru / lW, v.dot(Du) - ru * rv / lW,
                v.dot(diag.cwiseProduct(v)) - rv * rv / lW);
  }

 private:
  double bounding_radius_ = 0.0, q_max_ = 2.0, lever_ = 0.0;
  Vec3 q_, inv_em1_, a_over_e_;  // e_i/(e_i-1), 1/(e_i-1), a_i/e_i
  bool two_[3] = {true, true, true};  // e_i == 2
  int ie_[3] = {0, 0, 0};             // e_i - 2 when it is an integer <= 62, else -1
  int flat_axis_ = -1;  // (2, 2, p) with integer p in [3, 64]: the axis k of p, else -1
  int rho_sqrts_ = -1;            // k when e_max = 2^k (k <= 6), else -1
  double inv_2p_2_ = 0.0;  // 1 / (2p - 2)
  // flat_support_point for this p (unrolled powers for p <= 16), or null: not (2, 2, p)
  using FlatSolver = bool (Superquadric::*)(const Vec3&, const Vec3&, Vec3&, double&) const;
  FlatSolver flat_ = nullptr;
  const sq_detail::FlatRootTable* flat_table_ = nullptr;  // p <= 16: the solver's root
  bool equal_q_ = true;
  // t^k for 0 <= k <= 62 by repeated squaring (at most 11 multiplications, no pow)
  static double int_power(double t, int k) {
    double r = 1.0;
    for (; k > 0; k >>= 1, t *= t)
      if (k & 1) r *= t;
    return r;
  }
  // S^(1/2^k) as k square roots (E = 2^k: rho = S^(1/E) of powers() without pow)
  static double nested_sqrt(double S, int k) {
    for (; k > 0; --k) S = std::sqrt(S);
    return S;
  }
  // t^(e_i - 2): 1 for e_i = 2, by squaring for an integer e_i, else pow
  double power_e_minus_2(double t, int i) const {
    if (two_[i]) return 1.0;
    return ie_[i] > 0 ? int_power(t, ie_[i]) : std::pow(t, exponents()[i] - 2.0);
  }
  void cache() {
    const Vec3 e = exponents(), ax = axes();
    for (int i = 0; i < 3; ++i) {
      q_[i] = e[i] / (e[i] - 1.0);
      inv_em1_[i] = 1.0 / (e[i] - 1.0);
      a_over_e_[i] = ax[i] / e[i];
      two_[i] = e[i] == 2.0;
      ie_[i] = e[i] == std::floor(e[i]) && e[i] <= 64.0 ? static_cast<int>(e[i]) - 2 : -1;
    }
    q_max_ = q_.maxCoeff();
    rho_sqrts_ = -1;
    for (int k = 1; k <= 6; ++k)
      if (e_max() == double(1 << k)) rho_sqrts_ = k;
    flat_axis_ = -1;
    for (int k = 0; k < 3; ++k)
      if (ie_[k] >= 1 && two_[(k + 1) % 3] && two_[(k + 2) % 3]) flat_axis_ = k;
    flat_ = nullptr;
    flat_table_ = nullptr;
    if (flat_axis_ >= 0) {
      inv_2p_2_ = 1.0 / (2.0 * e[flat_axis_] - 2.0);
      pick_flat_solver(ie_[flat_axis_] + 2, flat_axis_);
    }
    equal_q_ = q_[0] == q_[1] && q_[1] == q_[2];
    bounding_radius_ = farthest_point().norm() * (1.0 + 1e-12);
    set_lever(two_[0] && two_[1] && two_[2] ? 0.0 : searched_lever());
  }
  // The branch and bound for the body scaled to a_max = 1 (its squares stay finite at any
  // size), scaled back.
  double searched_lever() const {
    const Vec3 ax = axes();
    const double mx = ax.maxCoeff();
    return mx * sq_detail::lever_bound(ax / mx, exponents());
  }
  // The ellipsoid's closed form, else the searched lever capped by the generic bound (when the
  // bounding radius is finite: at 1e200 it is not, and the generic bound would read 0).
  void set_lever(double searched) {
    const Vec3 ax = axes();
    const double mx = ax.maxCoeff(), mn = ax.minCoeff();
    if (two_[0] && two_[1] && two_[2]) {
      lever_ = mx - mn;
    } else if (std::isfinite(bounding_radius_)) {
      lever_ = std::min(searched, rotation_lever_bound(bounding_radius_, mn));
    } else {
      lever_ = searched;
    }
  }
  Vec3 grad_of(const Vec3& x, const Powers& P) const {
    if (P.centre) return Vec3::Zero();
    const Vec3 e = exponents(), ax = axes();
    const double E = e_max();
    Vec3 g;
    for (int i = 0; i < 3; ++i)
      g[i] = std::copysign(e[i] / (E * ax[i]) * P.d1[i], x[i]);
    return g;
  }
  // The Halley start above p = 16: (1 + K)^(-1/(2p-2)) in single precision (within a factor
  // 2^(-1/p) of the root; about 2.2 evaluations of G per point).
  double flat_start(double K) const {
    if (K < 1e37) return std::pow(static_cast<float>(1.0 + K), -static_cast<float>(inv_2p_2_));
    return std::pow(1.0 + K, -inv_2p_2_);
  }
  // The support point of a (2, 2, p) body with integer p (axis k = flat_axis_ has exponent p)
  // without a power per iteration.  The Lagrange conditions t_i = (c_i y)^(1/(e_i-1)) give, in
  // x = t_k, y = x^(p-1) / c_k and t_i = c_i y on the two exponent-2 axes, so the constraint
  // t_i^2 + t_j^2 + x^p = 1 becomes the polynomial equation
  //     G(x) = x^p + K x^(2p-2) - 1 = 0,     K = (c_i^2 + c_j^2) / c_k^2,
  // convex and increasing on [0, 1].  For p <= 16 the root is read from a table to a few ulps
  // (sq_detail::FlatRootTable; pick_flat_solver picks the instance, with x^(p-1) unrolled, once
  // per shape): no iteration.  Above p = 16 Halley steps with x-scaled derivatives (they come
  // back from either side of the root) from the closed-form start (flat_start: G(x0) >= 0 since
  // x^(2p-2) <= x^p on [0, 1], the root within a factor 2^(-1/p) below), stopped as in the
  // general solver after a step below 1e-6 x.  Then y = 1/lambda = x^(p-1) / c_k multiplies by
  // 1 / c_k (taken beside K) and lambda = 1/y comes from the root itself, so the only division
  // on the chain is K's.  Returns false (the caller takes the general path) when d_k = 0 (or
  // subnormal) or K is beyond 1e250.  The axis of exponent p is a template parameter too
  // (AX = flat_axis_), so the three axes are indexed at compile time.  Measured on the (2, 2, 8)
  // protocol (docs/benchmarks/README.md, "Session of 2026-12-06, third part"): the quartic start
  // and one Halley step cost 151 instructions a point, the table's root alone 112 (no call is
  // left in this function, so it saves no registers).
  template <int PM1, int AX>  // p - 1 (0: p - 1 read from ie_ at run time); the axis of p
  bool flat_support_point(const Vec3& d, const Vec3& cc, Vec3& x_out, double& lambda) const {
    constexpr int k = AX, i = (AX + 1) % 3, j = (AX + 2) % 3;
    const double ck = cc[k];
    if (!(ck >= std::numeric_limits<double>::min())) return false;  // 1 / c_k finite
    const double rk = 1.0 / ck;  // off the chain: y = x^(p-1) / c_k below is a product
    const double K = (cc[i] * cc[i] + cc[j] * cc[j]) / (ck * ck);
    if (!(K <= 1e250)) return false;
    double x, xp1;  // the root and x^(p-1)
    if constexpr (PM1 > 0) {
      x = flat_table_->root(K);
      xp1 = int_power_of<PM1>(x);
    } else {
      const int pm1 = ie_[k] + 1;
      const double p = static_cast<double>(pm1 + 1);
      x = flat_start(K);
      xp1 = 0.0;
      for (int it = 0; it < 100; ++it) {
        // one Halley step from x: G(x) and its x-scaled derivatives, the step in units of x
        // (Newton's step G / g1 instead where Halley's is over half of x: G / g1 < 1 keeps
        // x > 0)
        xp1 = int_power(x, pm1);
        const double w3 = xp1 * x, w12 = K * xp1 * xp1;
        const double G = w3 + w12 - 1.0;
        const double g1 = p * w3 + (2.0 * p - 2.0) * w12;  // x G'
        const double g2 = p * (p - 1.0) * w3 + (2.0 * p - 2.0) * (2.0 * p - 3.0) * w12;
        double delta = 2.0 * G * g1 / (2.0 * g1 * g1 - G * g2);
        if (!(std::abs(delta) < 0.5)) delta = G / g1;
        if (!(std::abs(delta) > 0.0)) break;
        const double step = delta * x;
        x -= step;
        if (std::abs(step) <= 1e-6 * x) break;
      }
      xp1 = int_power(x, pm1);
    }
    // y = 1/lambda = x^(p-1) / c_k, and lambda without a division: dividing G(x) = 0 by
    // x^(p-1) gives 1 / x^(p-1) = x + K x^(p-1) at the root
    const double y = xp1 * rk;
    lambda = ck * (x + K * xp1);
    x_out[k] = std::copysign(semi_axis<k>() * x, d[k]);
    x_out[i] = std::copysign(semi_axis<i>() * cc[i] * y, d[i]);
    x_out[j] = std::copysign(semi_axis<j>() * cc[j] * y, d[j]);
    return true;
  }
  template <int I>
  double semi_axis() const {
    if constexpr (I == 0) return a;
    else if constexpr (I == 1) return b;
    else return c;
  }
  // The solver instance and the root table for p and the axis k of p (flat_support_point<p - 1,
  // k> and the table of p for p = 3..16; above, the run-time instance and no table), picked once
  // per shape.
  template <int AX>
  void pick_flat_solver_on(int p) {
    flat_ = &Superquadric::flat_support_point<0, AX>;
    flat_table_ = nullptr;
    [&]<int... I>(std::integer_sequence<int, I...>) {
      ((p == I + 3 ? (flat_ = &Superquadric::flat_support_point<I + 2, AX>,
                      flat_table_ = &sq_detail::flat_root_table<I + 3>(), 0)
                   : 0),
       ...);
    }(std::make_integer_sequence<int, 14>{});
  }
  void pick_flat_solver(int p, int k) {
    if (k == 0) pick_flat_solver_on<0>(p);
    else if (k == 1) pick_flat_solver_on<1>(p);
    else pick_flat_solver_on<2>(p);
  }
  template <int K>
  static double int_power_of(double t) {
    if constexpr (K == 1) return t;
    else if constexpr (K % 2 == 0) { const double h = int_power_of<K / 2>(t); return h * h; }
    else return t * int_power_of<K - 1>(t);
  }
  // Support point and the multiplier lambda (0 for d = 0).  Solved for y = 1/lambda:
  // G(y) = sum_i (c_i y)^(q_i) - 1 is convex and increasing; started right of the root (G >= 0),
  // the iteration below moves down to it.  Start: the closed-form root of the problem with every
  // q_i = q_max (each c_i y <= 1 there, so (c_i y)^(q_i) >= (c_i y)^(q_max) and G >= 0); it is the
  // root when all exponents are equal.  Every c_i y stays in [0, 1] (no overflow); q_i = 2 terms
  // (exponent 2) need no pow.  Same root as the log-space form of the header (sq_detail::log_root,
  // kept for the rare ray and bounding-radius solves); about 4x fewer transcendental calls.
  Vec3 support_point(const Vec3& d, double& lambda) const {
    Vec3 cc;
    double cmax = 0.0;
    for (int i = 0; i < 3; ++i) {
      cc[i] = std::abs(d[i]) * a_over_e_[i];
      cmax = std::max(cmax, cc[i]);
    }
    if (!(cmax > 0.0)) {
      lambda = 0.0;
      return Vec3::Zero();
    }
    if (flat_) {
      Vec3 x;
      if ((this->*flat_)(d, cc, x, lambda)) return x;
    }
    double y;
    if (q_max_ == 2.0) {
      y = 1.0 / cc.norm();
    } else {
      double sum = 0.0;
      for (int i = 0; i < 3; ++i) sum += std::pow(cc[i] / cmax, q_max_);
      y = std::pow(sum, -1.0 / q_max_) / cmax;
    }
    // v_i = (c_i y)^(1/(e_i-1)) = t_i (the support point's |x_i| / a_i); (c_i y)^(q_i) = c_i y v_i.
    Vec3 v = Vec3::Zero();
    bool have_v = false;
    if (!equal_q_) {
      // Halley's iteration (cubic; G'' costs no extra pow): ~2.6 steps for (2, 2, p) against
      // ~4.6 Newton steps.  With y-scaled derivatives g1 = y G', g2 = y^2 G'' (both sums of
      // q_i w_i, q_i (q_i - 1) w_i, q_i in (1, 2]) the error constant is O(1) in units of y, so a
      // step below 1e-6 y leaves an error ~1e-18 y: stop without a confirming evaluation.  The
      // last powers v_i are carried over that final step by their Taylor series in
      // delta = -step / y to second order (error ~delta^3 < 1e-18): one pow per axis fewer.
      for (int it = 0; it < 100; ++it) {
        double G = -1.0, g1 = 0.0, g2 = 0.0;
        for (int i = 0; i < 3; ++i) {
          if (cc[i] == 0.0) continue;
          const double u = cc[i] * y;
          v[i] = two_[i] ? u : std::pow(u, inv_em1_[i]);
          const double w = u * v[i];
          G += w;
          g1 += q_[i] * w;
          g2 += q_[i] * (q_[i] - 1.0) * w;
        }
        // Halley need not stay right of the root (an overshoot gives a negative step, which
        // comes back); far from the root (a step over half of y) Newton's step, G y / g1 < y
        // since g1 >= sum w_i = G + 1, keeps y positive
        double step = 2.0 * G * g1 / (2.0 * g1 * g1 - G * g2) * y;
        if (!(std::abs(step) < 0.5 * y)) step = G * y / g1;
        if (!(std::abs(step) > 0.0)) {
          have_v = true;
          break;
        }
        const double delta = -step / y;
        y -= step;
        if (std::abs(step) <= 1e-6 * y) {
          for (int i = 0; i < 3; ++i) {
            const double k = inv_em1_[i];
            v[i] *= 1.0 + k * delta * (1.0 + 0.5 * (k - 1.0) * delta);
          }
          have_v = true;
          break;
        }
      }
    }
    lambda = 1.0 / y;
    const Vec3 ax = axes();
    Vec3 x;
    for (int i = 0; i < 3; ++i) {
      const double u = cc[i] * y;  // t_i^(e_i - 1)
      const double t = have_v ? v[i] : two_[i] ? u : std::pow(u, inv_em1_[i]);
      x[i] = std::copysign(ax[i] * t, d[i]);
    }
    return x;
  }
};

static_assert(SupportShape<Superquadric>);

}  // namespace hb
