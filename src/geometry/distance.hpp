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
//                  eps_r l / max(|dx_A|, |dx_B|) }               (points move < l/2 per step)
// so a step changes alpha^2 by at most 50 %, the signed distance by at most half of max(|d|, l)
// and the points by at most l/2; close to the solution xi = 1 and convergence is quadratic.
// eps_r = 0.5 was chosen on the random-pair tests: smaller values cost iterations without
// reducing failures (there are none on the test set), larger ones let far cold guesses jump.
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
// the previous solution of the same pair (its points in each body's own frame, alpha, beta).
//
// Systems: the 8-equation system is used from cold guesses (on the random test set it never
// needed a fallback; the 5-equation one did in 7 of 10,000 pairs), the 5-equation system from
// warm starts, where it converges as reliably and its 5x5 LU makes a call ~30 % cheaper.
//
// Fallbacks (never silent; the result says which attempt succeeded):
//   1. NR (options.warm_system) from the warm start, if one is given;
//   2. NR (options.system) from the cold guess;
//   3. a long steepest descent (tight angle) followed by NR on the 8-equation system;
//   4. the 5-equation system from the same guess;
//   5. the 8-equation system from the centre-line guess without SD.
// If all fail the status is `failed` and the distance is the best upper bound found (the
// separated-bodies SD estimate), never a silent value.
#pragma once
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "geometry/posed.hpp"
#include "math/types.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/shape.hpp"

namespace hb {

enum class DistanceStatus { converged, fallback, failed };
enum class DistanceSystem { eight, five };
enum class DistanceGuess { scaled, center_line };

struct DistanceOptions {
  DistanceSystem system = DistanceSystem::eight;       // cold starts (0 fallbacks in tests)
  DistanceSystem warm_system = DistanceSystem::five;   // warm starts (~30 % cheaper per call)
  DistanceGuess guess = DistanceGuess::scaled;
  double tol = 1e-12;        // NR converged when a full step moves points < tol * L
  int max_nr_iter = 60;
  double eps_r = 0.5;        // relaxed-NR damping, see above
  int sd_iter = 6;           // SD steps refining a cold guess
  double sd_cos = 0.98;      // ... stopped when both normals are within ~11 deg of x_B - x_A
  int sd_iter_fallback = 500;
  double sd_cos_fallback = 1.0 - 1e-10;
  double sd_lambda = 0.45;   // SD step: each point moves this fraction of the tangential gap
  bool analytic_spheres = true;  // sphere-sphere fast path (tested equal to the generic path)
};

// Previous solution of a pair: closest points in each body's own frame, and the multipliers.
struct DistanceWarmStart {
  Vec3 xa_body = Vec3::Zero();
  Vec3 xb_body = Vec3::Zero();
  double alpha = 1.0, beta = 0.0;
  bool valid = false;
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
  int attempt = 0;              // stage that succeeded: 1 warm, 2 cold, 3-5 fallbacks (header)
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

}  // namespace distance_detail

// Residual and Jacobian of Eq. dist8 at y = (x_A, x_B, alpha, beta). Public for the tests.
template <Shape SA, Shape SB>
void dist8_system(const Posed<SA>& A, const Posed<SB>& B, const distance_detail::Vec8& y,
                  distance_detail::Vec8& F, distance_detail::Mat8* J) {
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
                  distance_detail::Vec5& F, distance_detail::Mat5* J) {
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
};

// Damping factor of the relaxed NR (see header).
inline double damping(double eps_r, const Scales& sc, const Vec3& dxa, const Vec3& dxb,
                      double al, double dal, double be, double dbe, double grad_f_norm) {
  double xi = 1.0;
  const double dx = std::max(dxa.norm(), dxb.norm());
  if (dx * xi > eps_r * sc.l) xi = eps_r * sc.l / dx;
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

// Relaxed Newton-Raphson shared by both systems: solve J dy = -F, damp, stop when a full step
// moves the points and the distance by less than tol * L.
template <int N, class System, class Measure>
bool relaxed_newton(Eigen::Matrix<double, N, 1>& y, System&& system, Measure&& measure,
                    const DistanceOptions& o, const Scales& sc, int& iters) {
  Eigen::Matrix<double, N, 1> F;
  Eigen::Matrix<double, N, N> J;
  for (int it = 0; it < o.max_nr_iter; ++it) {
    ++iters;
    system(y, F, J);
    const Eigen::Matrix<double, N, 1> dy = J.partialPivLu().solve(-F);
    if (!dy.allFinite()) return false;
    const StepInfo s = measure(y, dy);
    const double xi = damping(o.eps_r, sc, s.dxa, s.dxb, s.al, s.dal, s.be, s.dbe, s.grad_f_norm);
    y += xi * dy;
    const double step = std::max(s.dxa.norm(), s.dxb.norm());
    if (xi == 1.0 && step <= o.tol * sc.L && std::abs(s.dbe) * s.grad_f_norm <= o.tol * sc.L)
      return true;
  }
  return false;
}

template <Shape SA, Shape SB>
bool nr8(const Posed<SA>& A, const Posed<SB>& B, Point& p, const DistanceOptions& o,
         const Scales& sc, int& iters) {
  Vec8 y;
  y << p.xa, p.xb, p.alpha, p.beta;
  const bool ok = relaxed_newton<8>(
      y, [&](const Vec8& z, Vec8& F, Mat8& J) { dist8_system(A, B, z, F, &J); },
      [&](const Vec8& z, const Vec8& dz) {
        return StepInfo{dz.template segment<3>(0), dz.template segment<3>(3), z[6], dz[6], z[7],
                        dz[7], A.grad(z.template segment<3>(0)).norm()};
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
      y, [&](const Vec5& z, Vec5& F, Mat5& J) { dist5_system(A, B, z, F, &J); },
      [&](const Vec5& z, const Vec5& dz) {
        // x_B = x_A + beta grad f moves by about dx_A + dbeta grad f
        const Vec3 ga = A.grad(z.template segment<3>(0));
        return StepInfo{dz.template segment<3>(0), dz.template segment<3>(0) + dz[4] * ga, z[3],
                        dz[3], z[4], dz[4], ga.norm()};
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
bool acceptable(const Posed<SA>& A, const Posed<SB>& B, const Point& p) {
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
template <Shape S>
Vec3 project_to_surface(const Posed<S>& P, const Vec3& x, const Vec3& n_prev) {
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
                  std::max(a.bounding_radius(), b.bounding_radius())};
  DistanceResult res;
  Point p;
  bool ok = false;
  int stage = 0;  // 1 warm, 2 cold, 3 long SD + 8 eq, 4 five eq, 5 centre line
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
  // 3. long SD, then 8 equations; 4. 5 equations
  if (!ok) {
    res.sd_iterations += steepest_descent(A, B, xa, xb, o.sd_iter_fallback, o.sd_cos_fallback,
                                          o.sd_lambda);
    const Point s = multipliers(A, B, xa, xb);
    run(3, s, DistanceSystem::eight);
    if (!ok) run(4, s, DistanceSystem::five);
  }
  // 5. centre line, no SD
  if (!ok) {
    Vec3 ca, cb;
    cold_guess(A, B, DistanceGuess::center_line, ca, cb);
    run(5, multipliers(A, B, ca, cb), DistanceSystem::eight);
  }
  if (!ok) {  // report the SD estimate (an upper bound when separated), flagged as failed
    p.xa = xa;
    p.xb = xb;
    res.status = DistanceStatus::failed;
  } else {
    res.status = res.attempt <= 2 ? DistanceStatus::converged : DistanceStatus::fallback;
  }
  const Vec3 n = A.grad(p.xa).normalized();
  res.distance = ok ? n.dot(p.xb - p.xa) : (p.xb - p.xa).norm();
  res.alpha = std::abs(p.alpha);
  res.beta = p.beta;
  res.normal = pa.R * n;
  res.point_a = pa.r + pa.R * p.xa;
  res.point_b = pa.r + pa.R * p.xb;
  res.warm = DistanceWarmStart{p.xa, B.to_body(p.xb), res.alpha, p.beta, ok};
  return res;
}

}  // namespace hb
