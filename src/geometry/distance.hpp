// Distance between two posed convex bodies (paper section 2.3), generic over shapes.
//
// Unknowns and equations.  With f (body A) and g (body B) the implicit functions in A's body
// frame, the closest points x_A, x_B and the multipliers alpha, beta solve (Eq. dist8)
//     F1 = grad f(x_A) + alpha^2 grad g(x_B) = 0          (antiparallel normals)
//     F2 = f(x_A) = 0,  F3 = g(x_B) = 0                     (points on the surfaces)
//     F4 = x_A + beta grad f(x_A) - x_B = 0                 (x_B - x_A along the normal)
// with the 8x8 Jacobian (H_f, H_g the Hessians)
//     [ H_f                  alpha^2 H_g   2 alpha grad g   0      ]
//     [ grad f^T             0             0                0      ]
//     [ 0                    grad g^T      0                0      ]
//     [ I + beta H_f         -I            0                grad f ]
// Eliminating x_B = x_A + beta grad f(x_A) gives the 5-equation system (Eq. dist5) in
// (x_A, alpha, beta):
//     grad f + alpha^2 grad g(x_B) = 0,  f(x_A) = 0,  g(x_B) = 0,
// whose Jacobian, with dx_B/dx_A = I + beta H_f and dx_B/dbeta = grad f, is
//     [ H_f + alpha^2 H_g (I + beta H_f)   2 alpha grad g   alpha^2 H_g grad f ]
//     [ grad f^T                           0                0                  ]
//     [ grad g^T (I + beta H_f)            0                grad g . grad f    ]
// Newton step: solve J dy = -F (ERRATA 1), y += xi dy with the damping xi of the relaxed NR.
//
// Damping (Eq. xidist, in its step form).  The paper bounds the relative change of alpha^2 and
// beta per step by eps_r.  We use, with eps_r = 0.5 and l = min(inscribed radii) (the typical
// length of the pair: the size of the smaller body),
//     xi = min{ 1, eps_r alpha^2 / |2 alpha d_alpha|,
//                  eps_r (|beta| + l / |grad f|) / |d_beta|,    (beta |grad f| is the distance)
//                  reach eps_r l / max(|dx_A|, |dx_B|) }         (points move < l/2 per step)
// so a step changes alpha^2 by at most 50 %, the signed distance by at most half of max(|d|, l)
// and the points by at most l/2; close to the solution xi = 1 and convergence is quadratic.
// eps_r = 0.5 was chosen on the random-pair tests: smaller values cost iterations without
// reducing failures (there are none on the test set), larger ones let far cold guesses jump.
// reach = 1, divided by 4 when three damped point moves in a row reverse direction (cosine
// < -1/2): the NR is cycling, e.g. round the sharp corner of a high-exponent superquadric, or
// between two points that bracket a root along a flat face (Newton overshoots both ways); its
// steps are then taken in the singular basis (below).  If it cycles again the attempt is given
// up for the next fallback stage, which is cheaper than waiting for max_nr_iter.
//
// Flat faces (superquadrics with exponents > 2, docs/superquadrics.md).  Along a flat face the
// curvature vanishes like u^(p-2) (u the offset from the face centre; exactly 0 on a coordinate
// plane), so J is singular or nearly so along the face: the closest points of parallel faces are
// nearly undetermined, Newton moves them by only u / (p-1) per step, and amplified rounding
// makes LU steps of 1e12.  The distance itself is well determined (it varies like u^p).  Three
// changes make the NR robust there while leaving well-conditioned problems (ellipsoids) alone:
//  * Stopping test: the distance is certified.  At an iterate with x_A, x_B on (near) the
//    surfaces, unit normals n_A, n_B and d = n_A.(x_B - x_A), convexity gives (with
//    delta = |n_A + n_B|, off = |f|/|grad f| + |g|/|grad g| the first-order offsets of the
//    points from the surfaces, D_B = |x_B - c_B| + L_B >= max_{y in B} |y - x_B|):
//      d* >= d - over,   over  = delta min(D_B, |x_A| + L_A + |x_B - x_A|) + off
//    (the plane through x_A normal to n_A supports A, and B's support along -n_A exceeds
//    -n_A.x_B by at most delta D_B; the same from B's side), and for d >= 0
//      d* <= d + under,  under = |x_B - x_A| - d + off.
//    NR stops when max(over, under) <= max(tol |d|, dist_floor L); the points may still slide
//    along a flat face.  Otherwise the old test (a full step moves the points and the distance
//    by less than tol L) still applies, and a certified iterate is polished with its exact LU
//    step when that is shorter than 1e-6 L: on the ellipsoid test sets the iteration counts
//    are the same or lower and the largest errors are unchanged.  The certificate is screened
//    by a cheap necessary condition, |grad f| delta >= |F1 - (F1.n_B) n_B| (no root, no
//    division), evaluated at every iterate.
//  * Singular steps.  When the LU step is non-finite, or would be capped while the LU pivots
//    span more than 1e6 or after the NR was found cycling, the step is taken in the singular
//    basis of J scaled to problem units (svd_step): each singular direction's step is capped
//    separately (one flat direction no longer shrinks the whole step), numerically null
//    directions get no step if only rounding is left along them, else a capped move whose
//    sign follows from convexity.
//  * Backtracking.  A step after which the normal mismatch and the error bound max(over,
//    under) both grew more than 10 times (Newton from the inner side of a flat face overshoots
//    by factors ~(u*/u)^(p-2)) is retried 8 times shorter, at most 3 times in a row.  On the
//    random ellipsoid sets neither this nor the cycling rule nor the singular step ever fires.
//
// Uniqueness and sign.  For convex bodies any solution with beta > 0 is THE distance: the
// planes through x_A and x_B normal to grad f separate the bodies and are |x_B - x_A| apart.
// Solutions with beta < 0 are either the "negative distance" (penetration) of slightly
// overlapping bodies, where x_A lies inside B and x_B inside A, or a spurious stationary point
// (e.g. the two far sides of separated bodies), where they do not; a solution is accepted only
// if it passes that test.  The signed distance is n.(x_B - x_A), n = grad f / |grad f|.
//
// Initial guess (cold): the intersections with the surfaces of the centre line (Fig. ABguess a)
// or of the centre line scaled by the semi-axes (section 3.2, "A better guess"), refined by a few
// steepest-descent steps on |x_A - x_B|^2 with the points held on the surfaces (section 2.3.2).
// alpha = sqrt(|grad f| / |grad g|), beta = (x_B - x_A).grad f / |grad f|^2.  A warm start is
// the previous solution of the same pair (its points in each body's own frame, alpha, beta), or
// a guess flagged as such (DistanceWarmStart::guess): the support points of A along a separating
// axis n and of B along -n.  Their normals are antiparallel, but x_B - x_A need not be along n:
// for long bodies side by side it has a component along their length, of the order of the
// bodies' offset.  The 5-equation system puts x_B at x_A + beta grad f, off B's surface by that
// component, and from there NR often ran to a spurious stationary point (beta < 0, rejected and
// redone cold: 67,782 of 152,328 warm-started solves in 3000 collisions of ellipsoids X0 = 6 at
// phi = 0.4, none at X0 <= 3; docs/benchmarks/README.md).  A guess
// is therefore first slid together by the short steepest descent of the cold guesses (which
// removes the component), then solved with options.warm_system.
//
// Systems: the 8-equation system is used from cold guesses (on the random test set it never
// needed a fallback; the 5-equation one did in 7 of 10,000 pairs), the 5-equation system from
// warm starts, where it converges as reliably and its 5x5 LU makes a call ~30 % cheaper.
//
// Fallbacks (never silent; the result says which attempt succeeded):
//   1. NR (options.warm_system) from the warm start, if one is given;
//   2. NR (options.system) from the cold guess;
//   3. (shapes with a support function) NR (options.system) from the support points along
//      the centre line, after a short steepest descent;
//   4. a long steepest descent (tight angle) from the cold guess, then NR on 8 equations;
//   5. the 5-equation system from the same guess;
//   6. the 8-equation system from the centre-line guess without SD;
//   7. (shapes with a support function) the maximum over directions of the
//      gap along a direction (support_maximum, below): a different algorithm, robust where the
//      contact equations are singular along straight walls and flat faces;
//   8. (shapes with a support function) the same maximum, global and certified by branch and
//      bound (geometry/penetration.hpp): slow, the last resort where stage 7's local Newton
//      stalls (nearly flat faces meeting at a collision).
// If all fail the status is `failed` and the distance is the best upper bound found (the
// separated-bodies SD estimate), never a silent value.
#pragma once
#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "geometry/penetration.hpp"
#include "geometry/posed.hpp"
#include "math/small_lu.hpp"
#include "math/types.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/shape.hpp"
#include "shapes/registry.hpp"

namespace hb {

enum class DistanceStatus { converged, fallback, failed };
enum class DistanceSystem { eight, five };
enum class DistanceGuess { scaled, center_line };

struct DistanceOptions {
  DistanceSystem system = DistanceSystem::eight;       // cold starts (0 fallbacks in tests)
  DistanceSystem warm_system = DistanceSystem::five;   // warm starts (~30 % cheaper per call)
  DistanceGuess guess = DistanceGuess::scaled;
  double tol = 1e-12;        // NR converged: a full step moves points < tol * L, or the
                             // distance is certified to tol relative (see header) ...
  double dist_floor = 3e-15; // ... or to dist_floor * L absolute
  double polish = 1e-6;      // a certified iterate takes its exact step if < polish * L
  double lu_pivot = 1e-6;    // LU pivots spanning more than 1/lu_pivot: singular-basis step
  double singular = 1e-14;   // ... singular values below this fraction of the largest are null
  double rounding = 1e-14;   // ... residual along them ignored below this (relative, header)
  double blowup = 10.0;      // a step that made the normal mismatch and the error bound this
  double backtrack = 0.125;  // ... many times larger is retried this many times shorter,
  int max_backtracks = 3;    // ... at most this many times in a row
  int cycle_iter = 3;        // this many damped point moves in a row reversing direction:
  double cycle_shrink = 0.25;  // ... the cap of the point moves is multiplied by this,
  int max_cycle_shrinks = 1;   // ... and when it happens again the attempt is given up
  int max_nr_iter = 60;
  double eps_r = 0.5;        // relaxed-NR damping, see above
  int sd_iter = 6;           // SD steps refining a cold guess
  double sd_cos = 0.98;      // ... stopped when both normals are within ~11 deg of x_B - x_A
  int sd_iter_fallback = 500;
  double sd_cos_fallback = 1.0 - 1e-10;
  double sd_lambda = 0.45;   // SD step: each point moves this fraction of the tangential gap
  bool analytic_spheres = true;  // sphere-sphere fast path (tested equal to the generic path)
  bool global_stage = true;  // fallback stage 8, the certified global gap maximum (header)
};

// Previous solution of a pair: closest points in each body's own frame, and the multipliers.
struct DistanceWarmStart {
  Vec3 xa_body = Vec3::Zero();
  Vec3 xb_body = Vec3::Zero();
  double alpha = 1.0, beta = 0.0;
  bool valid = false;
  // The points are a guess on the surfaces, not a solution of this pair: the support points
  // of a separating axis (contact/contact_time.hpp).  They are refined by a short steepest
  // descent before the NR (see the header, "Initial guess").
  bool guess = false;
};

struct DistanceResult {
  DistanceStatus status = DistanceStatus::failed;
  double distance = kInf;      // signed: negative when the bodies overlap slightly
  Vec3 point_a = Vec3::Zero();  // closest points (lab frame); deepest pair when overlapping
  Vec3 point_b = Vec3::Zero();
  Vec3 normal = Vec3::UnitX();  // unit outward normal of A at point_a (points from A to B)
  double alpha = 0.0, beta = 0.0;
  int nr_iterations = 0;        // total over all attempts
  int sd_iterations = 0;
  int attempt = 0;              // stage that succeeded: 1 warm, 2 cold, 3-8 fallbacks (header);
                                // 0 with status converged: no solve (touching_along)
  bool warm_used = false;
  DistanceWarmStart warm;       // feed back as the warm start of the next call for this pair
};

namespace distance_detail {

using Vec8 = Eigen::Matrix<double, 8, 1>;
using Mat8 = Eigen::Matrix<double, 8, 8>;
using Vec5 = Eigen::Matrix<double, 5, 1>;
using Mat5 = Eigen::Matrix<double, 5, 5>;

struct Point {  // one iterate of either system, in A's body frame
  Vec3 xa = Vec3::Zero(), xb = Vec3::Zero();
  double alpha = 1.0, beta = 0.0;
};

// The points of an iterate with f, g and their gradients there (the stopping test's input).
struct Iterate {
  Vec3 xa, xb, ga, gb;
  double fa, fb;
};

}  // namespace distance_detail

// Residual and Jacobian of Eq. dist8 at y = (x_A, x_B, alpha, beta). Public for the tests.
template <Shape SA, Shape SB>
void dist8_system(const Posed<SA>& A, const Posed<SB>& B, const distance_detail::Vec8& y,
                  distance_detail::Vec8& F, distance_detail::Mat8* J,
                  distance_detail::Iterate* at = nullptr) {
  const Vec3 xa = y.template segment<3>(0), xb = y.template segment<3>(3);
  const double al = y[6], be = y[7];
  double fa, gb;
  Vec3 ga, gg;
  Mat3 ha, hb;
  A.eval(xa, fa, ga, ha);
  B.eval(xb, gb, gg, hb);
  const double al2 = al * al;
  F.template segment<3>(0) = ga + al2 * gg;
  F[3] = fa;
  F[4] = gb;
  F.template segment<3>(5) = xa + be * ga - xb;
  if (at) *at = distance_detail::Iterate{xa, xb, ga, gg, fa, gb};
  if (!J) return;
  J->setZero();
  J->template block<3, 3>(0, 0) = ha;
  J->template block<3, 3>(0, 3) = al2 * hb;
  J->template block<3, 1>(0, 6) = 2.0 * al * gg;
  J->template block<1, 3>(3, 0) = ga.transpose();
  J->template block<1, 3>(4, 3) = gg.transpose();
  J->template block<3, 3>(5, 0) = Mat3::Identity() + be * ha;
  J->template block<3, 3>(5, 3) = -Mat3::Identity();
  J->template block<3, 1>(5, 7) = ga;
}

// Residual and Jacobian of Eq. dist5 at y = (x_A, alpha, beta). Public for the tests.
template <Shape SA, Shape SB>
void dist5_system(const Posed<SA>& A, const Posed<SB>& B, const distance_detail::Vec5& y,
                  distance_detail::Vec5& F, distance_detail::Mat5* J,
                  distance_detail::Iterate* at = nullptr) {
  const Vec3 xa = y.template segment<3>(0);
  const double al = y[3], be = y[4];
  double fa, gb;
  Vec3 ga, gg;
  Mat3 ha, hb;
  A.eval(xa, fa, ga, ha);
  const Vec3 xb = xa + be * ga;
  B.eval(xb, gb, gg, hb);
  const double al2 = al * al;
  F.template segment<3>(0) = ga + al2 * gg;
  F[3] = fa;
  F[4] = gb;
  if (at) *at = distance_detail::Iterate{xa, xb, ga, gg, fa, gb};
  if (!J) return;
  const Mat3 dxb = Mat3::Identity() + be * ha;
  J->setZero();
  J->template block<3, 3>(0, 0) = ha + al2 * hb * dxb;
  J->template block<3, 1>(0, 3) = 2.0 * al * gg;
  J->template block<3, 1>(0, 4) = al2 * hb * ga;
  J->template block<1, 3>(3, 0) = ga.transpose();
  J->template block<1, 3>(4, 0) = gg.transpose() * dxb;
  (*J)(4, 4) = gg.dot(ga);
}

namespace distance_detail {

struct Scales {
  double l;   // typical length: smaller inscribed radius (damping)
  double L;   // larger bounding radius (tolerances)
  double La = 0.0, Lb = 0.0;  // bounding radii of A and B (the certificate's reach)
  Vec3 cb = Vec3::Zero();     // B's centre in A's frame
};

// Damping factor of the relaxed NR (see header); dx = max(|dx_A|, |dx_B|), the point moves,
// capped at reach * eps_r * l (reach < 1 after cycling).
inline double damping(double eps_r, const Scales& sc, double dx, double al, double dal, double be,
                      double dbe, double grad_f_norm, double reach = 1.0) {
  double xi = 1.0;
  if (dx * xi > reach * eps_r * sc.l) xi = reach * eps_r * sc.l / dx;
  const double da2 = std::abs(2.0 * al * dal);
  if (da2 * xi > eps_r * al * al) xi = eps_r * al * al / da2;
  const double bscale = std::abs(be) + sc.l / grad_f_norm;
  if (std::abs(dbe) * xi > eps_r * bscale) xi = eps_r * bscale / std::abs(dbe);
  return xi;
}

// What a Newton step does to the quantities the damping and the convergence test look at.
struct StepInfo {
  Vec3 dxa, dxb;          // moves of the two points
  double al, dal, be, dbe;
  double grad_f_norm;     // |grad f(x_A)|: beta * grad_f_norm is the signed distance
};

// Bounds on the error of the signed distance d = n_A.(x_B - x_A) at an iterate (see header):
// d - over <= d* and, when d >= 0, d* <= d + under.
struct Certificate {
  double d = 0.0, over = kInf, under = kInf;
};

inline Certificate certify(const Iterate& it, const Scales& sc) {
  const double gan = it.ga.norm(), gbn = it.gb.norm();
  Certificate c;
  if (!(gan > 0.0) || !(gbn > 0.0)) return c;
  const Vec3 na = it.ga / gan, nb = it.gb / gbn, v = it.xb - it.xa;
  const double vn = v.norm();
  c.d = na.dot(v);
  const double off = std::abs(it.fa) / gan + std::abs(it.fb) / gbn;  // first order
  const double reach = std::min((it.xb - sc.cb).norm() + sc.Lb, it.xa.norm() + sc.La + vn);
  c.over = (na + nb).norm() * reach + off;
  c.under = (vn - std::abs(c.d)) + off;
  return c;
}

inline double bound(const Certificate& c) { return std::max(c.over, c.under); }

inline bool certified(const Certificate& c, const DistanceOptions& o, const Scales& sc) {
  return bound(c) <= std::max(o.tol * std::abs(c.d), o.dist_floor * sc.L);
}

// Lower bound of the normal mismatch |n_A + n_B| from the residual F1 = grad f + alpha^2 grad g:
// |grad f| (n_A + n_B) differs from F1 by a multiple of n_B, so |n_A + n_B|^2 >= num / den with
// num = |F1|^2 |grad g|^2 - (F1.grad g)^2, den = |grad f|^2 |grad g|^2.  No square root or
// division: the merit of the backtracking test and a cheap necessary condition of the
// certificate (over >= mismatch * min(L_A, L_B)).
struct Mismatch {
  double num = kInf, den = 1.0;
};

inline Mismatch mismatch(const Vec3& F1, const Iterate& it) {
  const double gb2 = it.gb.squaredNorm(), c = F1.dot(it.gb);
  return Mismatch{std::max(0.0, F1.squaredNorm() * gb2 - c * c), it.ga.squaredNorm() * gb2};
}

inline bool may_certify(const Mismatch& m, const Iterate& it, const DistanceOptions& o,
                        const Scales& sc) {
  const double tol2 = std::max(o.tol * o.tol * (it.xb - it.xa).squaredNorm(),
                               o.dist_floor * o.dist_floor * sc.L * sc.L);
  const double reach = std::min(sc.La, sc.Lb);
  return m.num * reach * reach <= tol2 * m.den;
}

// m grew more than `factor` times (in |n_A + n_B|) since m_prev (mismatches below 1e-15 count
// as 1e-15).
inline bool grew(const Mismatch& m, const Mismatch& m_prev, double factor) {
  const double prev = std::max(m_prev.num, 1e-30 * m_prev.den);
  return !(m.num * m_prev.den <= factor * factor * prev * m.den);
}

// Size of a residual in units of the solution's own rounding: the normal rows relative to
// |grad f|, the surface rows as lengths (f / |grad f|) relative to L, the 8-equation
// system's offset rows relative to L.
template <int N>
double residual_size(const Eigen::Matrix<double, N, 1>& r, const Iterate& at, const Scales& sc) {
  const double gan = at.ga.norm(), gbn = at.gb.norm();
  double m = r.template head<3>().norm() / gan;
  m = std::max(m, std::abs(r[3]) / (gan * sc.L));
  m = std::max(m, std::abs(r[4]) / (gbn * sc.L));
  if constexpr (N == 8) m = std::max(m, r.template tail<3>().norm() / sc.L);
  return m;
}

// Newton step in the singular basis, for a Jacobian singular to working precision (see header).
// J is first put in units of the problem, J' = R J C: rows of the normal equations times
// 1/|grad f|, the offset rows (8 equations) times 1/L; columns of the points times L, of beta
// times L/|grad f| (fixed scales: scaling by column norms would inflate a column that is zero
// up to rounding, at a flat face, into a spurious direction).  With J' = U S V^T the step is
// sum_i c_i C v_i, c_i = u_i.(-R F) / s_i, each term shortened so that it moves the points by
// at most `cap`.  The directions with s_i below o.singular * s_0 (numerically null; within them
// U and V are unrelated) get no step if the residual left along them, F_0 = R^-1 U_0 U_0^T R F,
// is at rounding level.  Otherwise they get one move of length `cap`, chosen by convexity: a
// move w of x_A changes the normal mismatch F1 = grad f + alpha^2 grad g by
// (H_f + alpha^2 H_g) w, positive semi-definite, so among the null moves C V_0 a (x_A part M a)
// the one with a = M^T g, g = -(F1 part of F_0), has (M a).g >= 0 and reduces the mismatch.
// `exact`: no term was shortened or left unsolved.
template <int N, class PointMove>
[[gnu::noinline, gnu::cold]] Eigen::Matrix<double, N, 1> svd_step(
    const Eigen::Matrix<double, N, N>& J, const Eigen::Matrix<double, N, 1>& F, const Iterate& at,
    const Scales& sc, const DistanceOptions& o, double cap, PointMove&& point_move, bool& exact) {
  using Vec = Eigen::Matrix<double, N, 1>;
  const double gan = at.ga.norm();
  Vec row = Vec::Ones(), col = Vec::Constant(sc.L);
  row.template head<3>().setConstant(1.0 / gan);
  if constexpr (N == 8) row.template tail<3>().setConstant(1.0 / sc.L);
  col[N - 2] = 1.0;             // alpha
  col[N - 1] = sc.L / gan;      // beta
  const Eigen::JacobiSVD<Eigen::Matrix<double, N, N>> svd(
      row.asDiagonal() * J * col.asDiagonal(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec& s = svd.singularValues();  // decreasing
  const Vec RF = row.cwiseProduct(F);
  int rank = 0;
  while (rank < N && s[rank] > o.singular * s[0]) ++rank;
  Vec dy = Vec::Zero();
  exact = true;
  for (int i = 0; i < rank; ++i) {
    Vec d = (-svd.matrixU().col(i).dot(RF) / s[i]) * col.cwiseProduct(svd.matrixV().col(i));
    const double m = point_move(d);
    if (m > cap) {
      d *= cap / m;
      exact = false;
    }
    dy += d;
  }
  if (rank == N) return dy;
  const auto U0 = svd.matrixU().rightCols(N - rank);
  const Vec F0 = (U0 * (U0.transpose() * RF)).cwiseQuotient(row);
  if (residual_size<N>(F0, at, sc) <= o.rounding) return dy;
  exact = false;
  const Eigen::Matrix<double, N, Eigen::Dynamic> W =
      col.asDiagonal() * svd.matrixV().rightCols(N - rank);
  const Vec3 g = -F0.template head<3>();
  const Vec d = W * (W.template topRows<3>().transpose() * g);
  const double m = point_move(d);
  if (m > 0.0) dy += d * (cap / m);
  return dy;
}

// Relaxed Newton-Raphson shared by both systems (see header): solve J dy = -F (in the singular
// basis where J is singular to working precision), damp; stop when the distance at the iterate
// is certified, or when an exact full step moves the points and the distance by less than
// tol * L; backtrack after a step that made things much worse; shorten the moves when cycling
// (give up if it goes on).
template <int N, class System, class Measure>
bool relaxed_newton(Eigen::Matrix<double, N, 1>& y, System&& system, Measure&& measure,
                    const DistanceOptions& o, const Scales& sc, int& iters) {
  using Vec = Eigen::Matrix<double, N, 1>;
  using Mat = Eigen::Matrix<double, N, N>;
  Vec F, dy_prev = Vec::Zero();
  Mat J;
  Iterate at_buf[2];  // this iterate and the previous one (alternating)
  Mismatch mis_prev;
  double xi_prev = 0.0, reach = 1.0;
  int backtracks = 0, reversals = 0, shrinks = 0, cur = 0;
  bool damped_prev = false;
  Vec3 dxa_prev = Vec3::Zero(), dxb_prev = Vec3::Zero();  // last point moves, if damped
  for (int it = 0; it < o.max_nr_iter; ++it) {
    ++iters;
    Iterate& at = at_buf[cur];
    system(y, F, J, at);
    // Stop if the distance is certified; retry a step that made things much worse with a
    // shorter one (the mismatch is a cheap screen, the error bounds decide: both must grow).
    const Mismatch mis = mismatch(F.template head<3>(), at);
    const bool done = may_certify(mis, at, o, sc) && certified(certify(at, sc), o, sc);
    if (!done && backtracks < o.max_backtracks && grew(mis, mis_prev, o.blowup) &&
        !(bound(certify(at, sc)) <= o.blowup * bound(certify(at_buf[1 - cur], sc)))) {
      ++backtracks;
      y -= (1.0 - o.backtrack) * xi_prev * dy_prev;
      xi_prev *= o.backtrack;
      continue;
    }
    backtracks = 0;
    const SmallLU<N> lu(J);  // Eigen's PartialPivLU to the bit, unrolled (math/small_lu.hpp)
    Vec dy = lu.solve(-F);
    bool exact = dy.allFinite();
    StepInfo s = measure(y, dy, at);
    double move = std::max(s.dxa.norm(), s.dxb.norm());
    if (done) {  // certified; polish with a last Newton step if it is exact and short
      if (exact && move <= o.polish * sc.L) {
        const auto u = lu.matrixLU().diagonal().cwiseAbs();
        if (u.minCoeff() >= o.lu_pivot * u.maxCoeff()) y += dy;
      }
      return true;
    }
    // J singular to working precision (small LU pivots), or NR cycling: the step in the
    // singular basis.  Only steps that the cap would shorten are examined (amplified rounding
    // makes them long).
    const double cap = reach * o.eps_r * sc.l;
    if (!exact || move > cap) {
      const auto u = lu.matrixLU().diagonal().cwiseAbs();
      if (!exact || reach < 1.0 || !(u.minCoeff() >= o.lu_pivot * u.maxCoeff())) {
        dy = svd_step<N>(J, F, at, sc, o, cap,
                         [&](const Vec& d) {
                           const StepInfo m = measure(y, d, at);
                           return std::max(m.dxa.norm(), m.dxb.norm());
                         },
                         exact);
        if (!dy.allFinite()) return false;
        s = measure(y, dy, at);
        move = std::max(s.dxa.norm(), s.dxb.norm());
      }
    }
    const double xi = damping(o.eps_r, sc, move, s.al, s.dal, s.be, s.dbe, s.grad_f_norm, reach);
    // Cycling: damped (or capped) point moves that keep reversing; shorten the moves, then
    // give up.
    if (xi < 1.0 || !exact) {
      if (damped_prev && s.dxa.dot(dxa_prev) + s.dxb.dot(dxb_prev) <
                             -0.5 * std::sqrt((s.dxa.squaredNorm() + s.dxb.squaredNorm()) *
                                              (dxa_prev.squaredNorm() + dxb_prev.squaredNorm()))) {
        if (++reversals >= o.cycle_iter) {
          if (++shrinks > o.max_cycle_shrinks) return false;  // to the next fallback stage
          reach *= o.cycle_shrink;
          reversals = 0;
        }
      } else {
        reversals = 0;
      }
      dxa_prev = xi * s.dxa;
      dxb_prev = xi * s.dxb;
      damped_prev = true;
    } else {
      reversals = 0;
      damped_prev = false;
    }
    dy_prev = dy;
    xi_prev = xi;
    mis_prev = mis;
    cur = 1 - cur;
    y += xi * dy;
    if (exact && xi == 1.0 && move <= o.tol * sc.L &&
        std::abs(s.dbe) * s.grad_f_norm <= o.tol * sc.L) {
      return true;
    }
  }
  return false;
}

template <Shape SA, Shape SB>
bool nr8(const Posed<SA>& A, const Posed<SB>& B, Point& p, const DistanceOptions& o,
         const Scales& sc, int& iters) {
  Vec8 y;
  y << p.xa, p.xb, p.alpha, p.beta;
  const bool ok = relaxed_newton<8>(
      y, [&](const Vec8& z, Vec8& F, Mat8& J, Iterate& at) { dist8_system(A, B, z, F, &J, &at); },
      [&](const Vec8& z, const Vec8& dz, const Iterate& at) {
        return StepInfo{dz.template segment<3>(0), dz.template segment<3>(3), z[6], dz[6], z[7],
                        dz[7], at.ga.norm()};
      },
      o, sc, iters);
  if (ok) p = Point{y.template segment<3>(0), y.template segment<3>(3), y[6], y[7]};
  return ok;
}

template <Shape SA, Shape SB>
bool nr5(const Posed<SA>& A, const Posed<SB>& B, Point& p, const DistanceOptions& o,
         const Scales& sc, int& iters) {
  Vec5 y;
  y << p.xa, p.alpha, p.beta;
  const bool ok = relaxed_newton<5>(
      y, [&](const Vec5& z, Vec5& F, Mat5& J, Iterate& at) { dist5_system(A, B, z, F, &J, &at); },
      [&](const Vec5& z, const Vec5& dz, const Iterate& at) {
        // x_B = x_A + beta grad f moves by about dx_A + dbeta grad f
        return StepInfo{dz.template segment<3>(0), dz.template segment<3>(0) + dz[4] * at.ga,
                        z[3], dz[3], z[4], dz[4], at.ga.norm()};
      },
      o, sc, iters);
  if (ok) {
    const Vec3 xa = y.template segment<3>(0);
    p = Point{xa, xa + y[4] * A.grad(xa), y[3], y[4]};
  }
  return ok;
}

// Accept a converged point only if it is the distance (beta > 0: certified by convexity) or a
// genuine penetration solution (beta < 0 with each point inside the other body).
template <Shape SA, Shape SB>
[[gnu::flatten]] bool acceptable(const Posed<SA>& A, const Posed<SB>& B, const Point& p) {
  if (!p.xa.allFinite() || !p.xb.allFinite() || !std::isfinite(p.alpha) ||
      !std::isfinite(p.beta))
    return false;
  const Vec3 ga = A.grad(p.xa), gb = B.grad(p.xb);
  if (!(ga.dot(gb) < 0.0)) return false;
  if (std::abs(A.f(p.xa)) > 1e-9 || std::abs(B.f(p.xb)) > 1e-9) return false;
  const double d = ga.normalized().dot(p.xb - p.xa);
  if (d >= 0.0) return true;
  return B.f(p.xa) <= 1e-12 && A.f(p.xb) <= 1e-12;
}

// Move x onto the surface along the gradient: f(x + xi grad f(x)) = 0 by 1-D Newton.  Falls
// back to the radial projection (ray from the centre) if Newton fails or lands where the
// outward normal has turned against n_prev (the normal at the point the move started from).
// (flatten: GCC stopped inlining Posed::grad here when the solver grew; it costs 12 % of the
// steepest descent on ellipsoids.  Same below for `acceptable`.)
template <Shape S>
[[gnu::flatten]] Vec3 project_to_surface(const Posed<S>& P, const Vec3& x, const Vec3& n_prev) {
  const Vec3 g = P.grad(x);
  double xi = 0.0;
  for (int it = 0; it < 30; ++it) {
    const Vec3 p = x + xi * g;
    const double fx = P.f(p);
    const double dfx = P.grad(p).dot(g);
    if (!(dfx > 0.0)) break;
    const double step = fx / dfx;
    xi -= step;
    if (std::abs(step) * g.norm() <= 1e-15 * P.shape->bounding_radius()) {
      const Vec3 q = x + xi * g;
      if (std::abs(P.f(q)) <= 1e-12 && P.grad(q).dot(n_prev) > 0.0) return q;
      break;
    }
  }
  return P.ray_surface(x - P.pose.r);
}

// Steepest descent on |x_A - x_B|^2 with both points held on their surfaces (section 2.3.2):
// move each point along the tangential part of the joining vector (lambda times it, capped at
// half the body's bounding radius), put it back on the surface, and accept the step only if the
// separation decreased (otherwise halve lambda, up to 6 times).  Returns the number of accepted
// steps; stops when both normals are within acos(cos_stop) of the joining line, when no
// decreasing step is found, or when the bodies turn out to overlap (x_A inside B).
template <Shape SA, Shape SB>
int steepest_descent(const Posed<SA>& A, const Posed<SB>& B, Vec3& xa, Vec3& xb, int max_iter,
                     double cos_stop, double lambda0) {
  const double capA = 0.5 * A.shape->bounding_radius();
  const double capB = 0.5 * B.shape->bounding_radius();
  double lambda = lambda0;
  int k = 0;
  for (; k < max_iter; ++k) {
    const Vec3 dv = xb - xa;
    const double dn = dv.norm();
    if (!(dn > 0.0) || B.f(xa) < 0.0) break;
    const Vec3 u = dv / dn;
    const Vec3 na = A.grad(xa).normalized(), nb = B.grad(xb).normalized();
    if (na.dot(u) >= cos_stop && -nb.dot(u) >= cos_stop) break;
    const Vec3 ta0 = dv - dv.dot(na) * na, tb0 = -dv + dv.dot(nb) * nb;
    bool accepted = false;
    for (int half = 0; half < 7 && !accepted; ++half, lambda *= 0.5) {
      Vec3 ta = lambda * ta0, tb = lambda * tb0;
      if (ta.norm() > capA) ta *= capA / ta.norm();
      if (tb.norm() > capB) tb *= capB / tb.norm();
      const Vec3 ya = project_to_surface(A, xa + ta, na);
      const Vec3 yb = project_to_surface(B, xb + tb, nb);
      if ((yb - ya).norm() < dn) {
        xa = ya;
        xb = yb;
        accepted = true;
      }
    }
    if (!accepted) break;
    lambda = std::min(lambda0, 4.0 * lambda);  // undo the last halving, and recover
  }
  return k;
}

template <Shape SA, Shape SB>
Point multipliers(const Posed<SA>& A, const Posed<SB>& B, const Vec3& xa, const Vec3& xb) {
  Point p;
  p.xa = xa;
  p.xb = xb;
  const Vec3 ga = A.grad(xa), gb = B.grad(xb);
  p.alpha = std::sqrt(ga.norm() / gb.norm());
  p.beta = (xb - xa).dot(ga) / ga.squaredNorm();
  return p;
}

template <Shape SA, Shape SB>
void cold_guess(const Posed<SA>& A, const Posed<SB>& B, DistanceGuess guess, Vec3& xa,
                Vec3& xb) {
  const Vec3 rab = B.pose.r - A.pose.r;  // A sits at the origin of its own frame
  Vec3 da = A.pose.R.transpose() * rab;  // in A's body frame
  Vec3 db = B.pose.R.transpose() * (-rab);
  if (!(da.squaredNorm() > 0.0)) {  // coincident centres: any direction
    da = Vec3::UnitX();
    db = -(B.pose.R.transpose() * A.pose.R * Vec3::UnitX());
  }
  if (guess == DistanceGuess::scaled) {  // section 3.2: scale by the semi-axes
    da = da.cwiseProduct(A.shape->half_extents());
    db = db.cwiseProduct(B.shape->half_extents());
  }
  xa = A.to_frame(A.shape->ray_surface(da));
  xb = B.to_frame(B.shape->ray_surface(db));
}

// Support points of A along the centre line and of B along its reverse (shapes with a support
// function; fallback stage 3).  On flat-sided bodies they lie on the face or rim turned towards
// the other body, where the (scaled) centre-line guess may sit mid-face far from the contact:
// side-by-side (2,2,16) cylinders with axes 0.05 rad apart touch near a rim, and NR from
// mid-wall follows the straight walls to where they would meet, far outside the bodies.
template <SupportShape SA, SupportShape SB>
void support_guess(const Posed<SA>& A, const Posed<SB>& B, Vec3& xa, Vec3& xb) {
  Vec3 rab = B.pose.r - A.pose.r;
  if (!(rab.squaredNorm() > 0.0)) rab = Vec3::UnitX();
  xa = A.to_frame(A.shape->support_point(A.pose.R.transpose() * rab));
  xb = B.to_frame(B.shape->support_point(-(B.pose.R.transpose() * rab)));
}

// Fallback stage 7 (shapes with a support function): the distance of separated bodies as the
// maximum over unit n of the gap along n (the dual of the closest-points problem, a different
// algorithm from the NR on the contact equations),
//     G(n) = -h_A(n) - h_B'(-n),   h_B'(u) = u.r_B + h_B(R_B^T u)   (A's frame),
// Phi(n) = G(n) extended to R^3 is concave and 1-homogeneous, grad Phi = x_B - x_A (support
// points of A along n and of B along -n) and Hess Phi = -(H_A(n) + R_B H_B(-R_B^T n) R_B^T), the
// support Hessians (positive semi-definite).  Damped Newton on the sphere: with E an orthonormal
// basis of the tangent plane, the step E delta solves
//     (E^T (H_A + H_B') E + G I) delta = E^T (x_B - x_A)
// (the Riemannian Hessian of G is -(E^T H E) - G I, negative definite while G > 0), capped at
// 0.5 rad and halved until G does not decrease.  Certificate: G(n) <= d <= |x_B - x_A|, and G
// is accurate to second order in the error of n even where the support point is not (the
// flat faces of high-exponent superquadrics, where the NR on the contact equations stalls:
// sliding along straight walls leaves J nearly singular).  Converged when the bounds meet to
// tol (relative) or the step is below 1e-14 rad (G then exact to rounding).  For overlapping
// bodies the maximum is negative: minus the penetration depth (the shortest translation that
// separates them), also a signed distance that vanishes at contact; this matters at a contact
// (collisions, just-collided pairs), where G is zero to rounding and may come out -1e-14.
template <SupportShape SA, SupportShape SB>
bool support_maximum(const Posed<SA>& A, const Posed<SB>& B, Vec3 n, const DistanceOptions& o,
                     const Scales& sc, int& iters, Point& out, double& G_out, Vec3& n_out) {
  const Mat3& R = B.pose.R;
  auto eval = [&](const Vec3& u, Vec3& xa, Vec3& xb) {
    xa = A.shape->support_point(u);
    xb = B.to_frame(B.shape->support_point(-(R.transpose() * u)));
    return u.dot(xb - xa);
  };
  if (!(n.squaredNorm() > 0.0) || !n.allFinite()) n = B.pose.r;
  if (!(n.squaredNorm() > 0.0)) n = Vec3::UnitX();
  n.normalize();
  Vec3 xa, xb;
  double G = eval(n, xa, xb);
  bool ok = false;
  for (int it = 0; it < o.max_nr_iter; ++it) {  // the NR's budget
    ++iters;
    const double upper = (xb - xa).norm();
    if (G > 0.0 && upper - G <= std::max(o.tol * G, o.dist_floor * sc.L)) {
      ok = true;
      break;
    }
    // tangent basis
    const Vec3 e1 = (std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(n).normalized();
    const Vec3 e2 = n.cross(e1);
    Eigen::Matrix<double, 3, 2> E;
    E << e1, e2;
    const Mat3 H = A.shape->support_hessian(n) +
                   R * B.shape->support_hessian(-(R.transpose() * n)) * R.transpose();
    Eigen::Matrix2d M = E.transpose() * H * E;
    M.diagonal().array() += std::max(G, 1e-3 * sc.l);
    const Eigen::Vector2d gt = E.transpose() * (xb - xa);
    Eigen::Vector2d delta = M.ldlt().solve(gt);
    if (!delta.allFinite()) delta = gt / std::max(M.diagonal().maxCoeff(), sc.l);
    if (delta.norm() > 0.5) delta *= 0.5 / delta.norm();
    bool moved = false;
    for (int half = 0; half < 40; ++half, delta *= 0.5) {
      const Vec3 m = (n + E * delta).normalized();
      Vec3 ya, yb;
      const double Gm = eval(m, ya, yb);
      if (Gm >= G) {
        moved = Gm > G || delta.norm() > 0.0;
        n = m;
        G = Gm;
        xa = ya;
        xb = yb;
        break;
      }
    }
    if (!moved || delta.norm() <= 1e-14) {  // converged: G is the maximum to rounding
      ok = true;
      break;
    }
  }
  if (!ok) return false;
  out = multipliers(A, B, xa, xb);
  G_out = G;
  n_out = n;
  return true;
}

}  // namespace distance_detail

// Analytic sphere-sphere distance (fast path), in the same result form as the generic solver.
inline DistanceResult sphere_distance(const Sphere& a, const Pose& pa, const Sphere& b,
                                      const Pose& pb) {
  DistanceResult r;
  const Vec3 rab = pb.r - pa.r;
  const double c = rab.norm();
  const Vec3 n = c > 0.0 ? Vec3(rab / c) : Vec3(Vec3::UnitX());
  r.status = DistanceStatus::converged;
  r.distance = c - a.radius - b.radius;
  r.normal = n;
  r.point_a = pa.r + a.radius * n;
  r.point_b = pb.r - b.radius * n;
  r.alpha = std::sqrt(b.radius / a.radius);      // |grad f| / |grad g| = r_B / r_A
  r.beta = 0.5 * r.distance * a.radius;          // d / |grad f|, |grad f| = 2 / r_A
  r.attempt = 1;
  r.warm = DistanceWarmStart{pa.R.transpose() * (a.radius * n), pb.R.transpose() * (-b.radius * n),
                             r.alpha, r.beta, true};
  return r;
}

// Signed distance between shape a at pose pa and shape b at pose pb (lab frame).
template <Shape SA, Shape SB>
DistanceResult distance(const SA& a, const Pose& pa, const SB& b, const Pose& pb,
                        const DistanceOptions& o = {}, const DistanceWarmStart* warm = nullptr) {
  using namespace distance_detail;
  if constexpr (std::is_same_v<SA, Sphere> && std::is_same_v<SB, Sphere>) {
    if (o.analytic_spheres) return sphere_distance(a, pa, b, pb);
  }
  const Posed<SA> A{&a, Pose{}};
  const Posed<SB> B{&b, relative_pose(pa, pb)};
  const Scales sc{std::min(a.inscribed_radius(), b.inscribed_radius()),
                  std::max(a.bounding_radius(), b.bounding_radius()), a.bounding_radius(),
                  b.bounding_radius(), B.pose.r};
  DistanceResult res;
  Point p;
  bool ok = false;
  int stage = 0;  // 1 warm, 2 cold, 3 support points, 4 long SD + 8 eq, 5 five eq, 6 centre line,
                  // 7 gap maximum over directions (local), 8 the same, global and certified
  auto run = [&](int st, Point start, DistanceSystem sys) {
    stage = st;
    p = start;
    const bool conv = sys == DistanceSystem::eight ? nr8(A, B, p, o, sc, res.nr_iterations)
                                                   : nr5(A, B, p, o, sc, res.nr_iterations);
    ok = conv && acceptable(A, B, p);
    if (ok) res.attempt = stage;
  };
  // 1. warm start
  if (warm && warm->valid) {
    res.warm_used = true;
    Point w;
    w.xa = warm->xa_body;
    w.xb = B.to_frame(warm->xb_body);
    if (warm->guess)
      res.sd_iterations += steepest_descent(A, B, w.xa, w.xb, o.sd_iter, o.sd_cos, o.sd_lambda);
    w = multipliers(A, B, w.xa, w.xb);
    run(1, w, o.warm_system);
  }
  // 2. cold guess + short SD
  Vec3 xa, xb;
  if (!ok) {
    cold_guess(A, B, o.guess, xa, xb);
    res.sd_iterations += steepest_descent(A, B, xa, xb, o.sd_iter, o.sd_cos, o.sd_lambda);
    run(2, multipliers(A, B, xa, xb), o.system);
  }
  // 3. (shapes with a support function) support points along the centre line + short SD
  if constexpr (SupportShape<SA> && SupportShape<SB>) {
    if (!ok) {
      Vec3 sa, sb;
      support_guess(A, B, sa, sb);
      res.sd_iterations += steepest_descent(A, B, sa, sb, o.sd_iter, o.sd_cos, o.sd_lambda);
      run(3, multipliers(A, B, sa, sb), o.system);
    }
  }
  // 4. long SD, then 8 equations; 5. 5 equations
  if (!ok) {
    res.sd_iterations += steepest_descent(A, B, xa, xb, o.sd_iter_fallback, o.sd_cos_fallback,
                                          o.sd_lambda);
    const Point s = multipliers(A, B, xa, xb);
    run(4, s, DistanceSystem::eight);
    if (!ok) run(5, s, DistanceSystem::five);
  }
  // 6. centre line, no SD
  if (!ok) {
    Vec3 ca, cb;
    cold_guess(A, B, DistanceGuess::center_line, ca, cb);
    run(6, multipliers(A, B, ca, cb), DistanceSystem::eight);
  }
  // 7. (shapes with a support function) maximum of the gap over directions,
  // from the best direction seen: the SD estimate's joining line
  bool dual = false;
  double G = 0.0;
  Vec3 n_dual = Vec3::UnitX();
  if constexpr (SupportShape<SA> && SupportShape<SB>) {
    if (!ok) {
      stage = 7;
      dual = ok = support_maximum(A, B, Vec3(xb - xa), o, sc, res.nr_iterations, p, G, n_dual);
      if (ok) res.attempt = 7;
    }
  }
  // 8. (shapes with a support function) the same maximum found globally and certified by branch
  // and bound over the sphere of directions (geometry/penetration.hpp), from the SD estimate's
  // joining line and the failed NR's last normal.  Slow (hundreds to thousands of gap
  // evaluations) and reached only when every local method failed: seen where nearly flat faces
  // meet (superquadrics (2, 2, 16) face to face at a collision), where the contact equations are
  // nearly singular and stage 7's Newton on the sphere stalls on the C^1 kink of G at a face
  // normal.  For a flat contact the support points are one pair of many on the touching faces.
  if constexpr (SupportShape<SA> && SupportShape<SB>) {
    if (!ok && o.global_stage) {
      stage = 8;
      Vec3 hints[2] = {Vec3(xb - xa), A.grad(p.xa)};
      const int nh = hints[1].allFinite() && hints[1].squaredNorm() > 0.0 ? 2 : 1;
      const PenetrationResult g =
          penetration(a, Pose{}, b, B.pose, std::span<const Vec3>(hints, std::size_t(nh)));
      if (g.certified) {
        dual = ok = true;
        res.attempt = 8;
        p = multipliers(A, B, g.point_a, g.point_b);
        G = g.distance;
        n_dual = g.normal;
      }
    }
  }
  if (!ok) {  // report the SD estimate (an upper bound when separated), flagged as failed
    p.xa = xa;
    p.xb = xb;
    res.status = DistanceStatus::failed;
  } else {
    res.status = res.attempt <= 2 ? DistanceStatus::converged : DistanceStatus::fallback;
  }
  const Vec3 n = dual ? n_dual : Vec3(A.grad(p.xa).normalized());
  res.distance = dual ? G : ok ? n.dot(p.xb - p.xa) : (p.xb - p.xa).norm();
  res.alpha = std::abs(p.alpha);
  res.beta = p.beta;
  res.normal = pa.R * n;
  res.point_a = pa.r + pa.R * p.xa;
  res.point_b = pa.r + pa.R * p.xb;
  res.warm = DistanceWarmStart{p.xa, B.to_body(p.xb), res.alpha, p.beta, ok};
  return res;
}

// The solver for the engine's shape pairs (shapes/registry.hpp) is compiled once, in
// src/geometry/distance_*.cpp, and linked by every other translation unit: instantiated in each of
// them, it made the build (above all the sanitizer build) several times slower.
#define HB_DISTANCE_INSTANCE(EXTERN, SA, SB)                                                    \
  EXTERN template DistanceResult distance<SA, SB>(const SA&, const Pose&, const SB&, const Pose&, \
                                                  const DistanceOptions&, const DistanceWarmStart*);
#define HB_DISTANCE_INSTANCES(EXTERN, SA) HB_FOR_EACH_ENGINE_SHAPE(HB_DISTANCE_INSTANCE, EXTERN, SA)
#ifndef HB_DISTANCE_INSTANTIATE
HB_DISTANCE_INSTANCES(extern, Sphere)  // (not nested in HB_FOR_EACH_ENGINE_SHAPE: a macro cannot expand itself)
HB_DISTANCE_INSTANCES(extern, Ellipsoid)
HB_DISTANCE_INSTANCES(extern, Superquadric)
#endif

}  // namespace hb
