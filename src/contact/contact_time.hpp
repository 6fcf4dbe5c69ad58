// Contact time of two freely moving convex bodies (paper section 2.4), generic over shapes.
//
// Input: two shapes, their states at a common time t_state (BodyState: centre r, orientation
// q body->lab, velocity v, lab angular velocity w; free flight of motion/free_flight.hpp), the
// search window [t_start, t_max] and eps_d (the paper's epsilon_d).  Output: the first time in
// the window at which the bodies touch, the contact point and the normal, or `none`.
//
// Algorithm.
//  1. Bounding spheres (radii L_A, L_B, Eq. lalb) give the window in which a contact is
//     possible: |r_AB(t)| <= L_A + L_B.  Empty window: `none`, without any distance solve.
//  2. Stepping with the distance-rate bound (Eq. distOver)
//        |d'(t)| <= K = |v_B - v_A| + |w_A| L_A + |w_B| L_B :
//     from t with distance d, no contact is possible before t + d / K.  Step
//     dt = max(d, eps_d) / K (the paper's rule).  Each step evaluates the distance (warm-started
//     from the previous solution of the pair) and its rate d' = n.(u_B(x_B) - u_A(x_A)), u the
//     velocity of the material point (the envelope theorem: the closest points are stationary).
//  3. A step ending with d < 0 brackets a contact.  A step [t0, t1] with both ends positive can
//     still hide a contact only if the Lipschitz lower bound (d0 + d1 - K (t1 - t0)) / 2 is <= 0;
//     that needs d0 + d1 <= eps_d (the paper's grazing case, step 6).  Then, if d decreases at
//     t0 and increases at t1 (a minimum inside), Brent's minimiser (golden section with
//     parabolic interpolation, i.e. the paper's quadratic interpolation then Brent) locates the
//     minimum of d, stopping as soon as a negative value is seen; a negative minimum brackets a
//     contact on [t0, t_min].  If d' has the same sign at both ends the minimum is at an end,
//     where d > 0: no contact (d is smooth and the interval is shorter than eps_d / K).
//  4. On a bracket [t_lo, t_hi] with d(t_lo) > 0 > d(t_hi): Newton-Raphson on the contact
//     system (Eq. contime) in (x, alpha, t),
//        F = ( grad f(x,t) + alpha^2 grad g(x,t),  f(x,t),  g(x,t) ) = 0,
//     started from the secant time of the bracket with x the midpoint of the closest points and
//     alpha of the distance solution.  The Jacobian is derived for any shape: with
//     x_body = R(t)^T (x - r(t)), the material velocity u(x) = v + w x (x - r), H the Hessian,
//        df/dt = -grad f . u,       d(grad f)/dt = w x grad f - H u
//     (for ellipsoids this is ERRATA 5: 2 (Xdot x~ - X v) and -2 v^T X x~ + x~^T Xdot x~), so
//        J = [ H_f + alpha^2 H_g   2 alpha grad g   d(grad f)/dt + alpha^2 d(grad g)/dt ]
//            [ grad f^T            0                df/dt                               ]
//            [ grad g^T            0                dg/dt                               ]
//     The NR result is accepted only if its time lies in the bracket and the distance there is
//     zero to tolerance; otherwise (fallback, counted) the bracket is shrunk on the sign of
//     d(t) (Illinois + bisection) and its left end, where d > 0, is returned: a time never later
//     than the contact.
//  Initial overlap (d < 0 at the first evaluated time): if the bodies approach (d' < 0) this is a
//  contact at that time (`hit`, initial_overlap = true); if they separate (just after a
//  collision, rounding) the search continues and only a later sign change counts.
//  A distance solve that fails makes the result `failed` (never a silent `none`).
#pragma once
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "geometry/distance.hpp"
#include "geometry/posed.hpp"
#include "math/brent.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "shapes/shape.hpp"

namespace hb {

enum class ContactStatus { hit, none, failed };

template <Shape SA, Shape SB>
struct ContactInput {
  const SA& shape_a;
  const SB& shape_b;
  BodyState a, b;          // both at time t_state
  double t_state = 0.0;
  double t_start = 0.0;    // search window [t_start, t_max] (absolute times)
  double t_max = kInf;
  double eps_d = 1e-5;     // the paper's epsilon_d (length units), << min(L_A, L_B)
  DistanceWarmStart warm{};  // previous distance solution of this pair, if any
};

struct ContactOptions {
  long max_steps = 10'000'000;  // stepping guard; exceeding it gives `failed`
  int max_nr_iter = 30;
  int brent_max_evals = 60;
  double accept_tol = 1e-10;    // NR contact accepted if |d(t_c)| <= accept_tol * L
  DistanceOptions distance{};
};

struct ContactResult {
  ContactStatus status = ContactStatus::none;
  double time = kInf;
  Vec3 point = Vec3::Zero();    // contact point (lab frame)
  Vec3 normal = Vec3::UnitX();  // unit normal at the contact, from A to B
  bool initial_overlap = false;
  double min_distance = kInf;   // smallest distance evaluated (diagnostic)
  long steps = 0;               // rate-bound steps
  int distance_evals = 0;
  int distance_nr_iterations = 0;
  int nr_iterations = 0;        // contact-system NR iterations
  int grazing_searches = 0;     // Brent minimisations
  int fallbacks = 0;            // NR rejected, bracket shrunk on the sign of d(t) instead
  int distance_fallbacks = 0;   // distance solves that needed a fallback stage
  DistanceWarmStart warm;       // last distance solution (warm start for the next prediction)
};

// A body in free flight, coordinates relative to `origin` (to keep the numbers small).
template <Shape S>
struct MovingBody {
  const S* shape;
  BodyState st;
  double t_state;
  Vec3 origin;

  Pose pose_at(double t) const {
    return Pose{st.r - origin + st.v * (t - t_state), rotation_at(st, t - t_state)};
  }
  // f, grad f, Hessian and their time derivatives at the frame point x and time t.
  void eval(const Vec3& x, double t, double& f, Vec3& g, Mat3& H, double& ft, Vec3& gt) const {
    const Pose p = pose_at(t);
    const Vec3 rel = x - p.r;
    const Vec3 y = p.R.transpose() * rel;
    f = shape->f(y);
    g = p.R * shape->grad(y);
    H = p.R * shape->hessian(y) * p.R.transpose();
    const Vec3 u = st.v + st.w.cross(rel);
    ft = -g.dot(u);
    gt = st.w.cross(g) - H * u;
  }
};

using Vec5c = Eigen::Matrix<double, 5, 1>;
using Mat5c = Eigen::Matrix<double, 5, 5>;

// Residual and Jacobian of the contact system (Eq. contime) at y = (x, alpha, t).
template <Shape SA, Shape SB>
void contact_system(const MovingBody<SA>& A, const MovingBody<SB>& B, const Vec5c& y, Vec5c& F,
                    Mat5c* J) {
  const Vec3 x = y.head<3>();
  const double al = y[3], t = y[4];
  double fa, fb, fta, ftb;
  Vec3 ga, gb, gta, gtb;
  Mat3 ha, hb;
  A.eval(x, t, fa, ga, ha, fta, gta);
  B.eval(x, t, fb, gb, hb, ftb, gtb);
  const double al2 = al * al;
  F.head<3>() = ga + al2 * gb;
  F[3] = fa;
  F[4] = fb;
  if (!J) return;
  J->setZero();
  J->block<3, 3>(0, 0) = ha + al2 * hb;
  J->block<3, 1>(0, 3) = 2.0 * al * gb;
  J->block<3, 1>(0, 4) = gta + al2 * gtb;
  J->block<1, 3>(3, 0) = ga.transpose();
  (*J)(3, 4) = fta;
  J->block<1, 3>(4, 0) = gb.transpose();
  (*J)(4, 4) = ftb;
}

// Upper bound of |d'(t)| (Eq. distOver).
inline double distance_rate_bound(const BodyState& a, double La, const BodyState& b, double Lb) {
  return (b.v - a.v).norm() + a.w.norm() * La + b.w.norm() * Lb;
}

// Time window (absolute) in which the bounding spheres overlap, intersected with [lo, hi].
// Returns false if empty.
inline bool bounding_sphere_window(const BodyState& a, const BodyState& b, double t_state,
                                   double R, double& lo, double& hi) {
  const Vec3 p = b.r - a.r, dv = b.v - a.v;
  const double A = dv.squaredNorm(), Bh = p.dot(dv), C = p.squaredNorm() - R * R;
  if (A == 0.0) return C <= 0.0 && lo <= hi;
  const double disc = Bh * Bh - A * C;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  // stable roots of A tau^2 + 2 Bh tau + C = 0
  const double q = -(Bh + std::copysign(sq, Bh));
  double t1 = q / A, t2 = (q != 0.0) ? C / q : t1;
  if (t1 > t2) std::swap(t1, t2);
  lo = std::max(lo, t_state + t1);
  hi = std::min(hi, t_state + t2);
  return lo <= hi;
}

namespace contact_detail {

struct Sample {
  double t = 0.0, d = kInf, dd = 0.0;  // time, distance, its rate
  DistanceResult res;
};

template <Shape SA, Shape SB>
struct Solver {
  const ContactInput<SA, SB>& in;
  const ContactOptions& o;
  ContactResult& out;
  MovingBody<SA> A;
  MovingBody<SB> B;
  double L;   // length scale: max bounding radius
  double K;   // distance-rate bound
  DistanceWarmStart warm;
  bool failed = false;

  Solver(const ContactInput<SA, SB>& i, const ContactOptions& op, ContactResult& r)
      : in(i), o(op), out(r),
        A{&i.shape_a, i.a, i.t_state, i.a.r},
        B{&i.shape_b, i.b, i.t_state, i.a.r},
        L(std::max(i.shape_a.bounding_radius(), i.shape_b.bounding_radius())),
        K(distance_rate_bound(i.a, i.shape_a.bounding_radius(), i.b,
                              i.shape_b.bounding_radius())),
        warm(i.warm) {}

  Sample eval(double t) {
    Sample s;
    s.t = t;
    const Pose pa = A.pose_at(t), pb = B.pose_at(t);
    s.res = distance(*A.shape, pa, *B.shape, pb, o.distance, warm.valid ? &warm : nullptr);
    ++out.distance_evals;
    out.distance_nr_iterations += s.res.nr_iterations;
    if (s.res.status == DistanceStatus::fallback) ++out.distance_fallbacks;
    if (s.res.status == DistanceStatus::failed) {
      failed = true;
      s.d = s.res.distance;
      return s;
    }
    warm = s.res.warm;
    s.d = s.res.distance;
    const Vec3 ua = A.st.v + A.st.w.cross(s.res.point_a - pa.r);
    const Vec3 ub = B.st.v + B.st.w.cross(s.res.point_b - pb.r);
    s.dd = s.res.normal.dot(ub - ua);
    out.min_distance = std::min(out.min_distance, s.d);
    return s;
  }

  void report_hit(double t, const Vec3& x, const Vec3& n) {
    out.status = ContactStatus::hit;
    out.time = t;
    out.point = x + A.origin;
    out.normal = n;
  }

  // Contact NR from the bracket [lo, hi] (d(lo) > 0 > d(hi)); fallback: shrink the bracket.
  void solve_bracket(const Sample& lo, const Sample& hi) {
    const double t0 = lo.t + (hi.t - lo.t) * lo.d / (lo.d - hi.d);
    const Sample g = eval(t0);
    if (failed) return;
    if (g.d == 0.0) {
      report_hit(g.t, 0.5 * (g.res.point_a + g.res.point_b), g.res.normal);
      return;
    }
    // the smaller sub-bracket around the secant point
    const Sample& l = g.d > 0 ? g : lo;
    const Sample& h = g.d > 0 ? hi : g;
    Vec5c y;
    y << 0.5 * (g.res.point_a + g.res.point_b), std::max(g.res.alpha, 1e-3), g.t;
    const double dt_tol = 1e-12 * L / std::max(K, 1e-300);
    bool ok = false;
    for (int it = 0; it < o.max_nr_iter; ++it) {
      ++out.nr_iterations;
      Vec5c F;
      Mat5c J;
      contact_system(A, B, y, F, &J);
      Vec5c dy = J.partialPivLu().solve(-F);
      if (!dy.allFinite()) break;
      const double dx = dy.head<3>().norm();
      double xi = 1.0;
      if (dx > 0.5 * L) xi = 0.5 * L / dx;
      if (std::abs(dy[3]) > 0.5 * std::abs(y[3])) xi = std::min(xi, 0.5 * std::abs(y[3] / dy[3]));
      y += xi * dy;
      if (y[4] < l.t - dt_tol || y[4] > h.t + dt_tol) break;  // left the bracket
      if (xi == 1.0 && dx <= 1e-12 * L && std::abs(dy[4]) <= dt_tol) {
        ok = true;
        break;
      }
    }
    if (ok) {
      const double tc = std::clamp(y[4], l.t, h.t);
      const Sample c = eval(tc);
      if (failed) return;
      if (std::abs(c.d) <= o.accept_tol * L) {
        double f_, ft_;
        Vec3 g_, gt_;
        Mat3 h_;
        A.eval(y.head<3>(), tc, f_, g_, h_, ft_, gt_);
        report_hit(tc, y.head<3>(), g_.normalized());
        return;
      }
    }
    // Fallback: shrink the bracket on the sign of d(t); return its left end (d > 0).
    ++out.fallbacks;
    Sample best = l;
    const double xtol = 1e-14 * std::max(std::abs(h.t), L / std::max(K, 1e-300));
    const RootBracket br = bracket_root(
        [&](double t) {
          Sample s = eval(t);
          if (failed) return 0.0;
          if (s.d > 0.0) best = s;
          return s.d;
        },
        l.t, l.d, h.t, h.d, xtol, 200);
    if (failed) return;
    if (best.t != br.lo) best = eval(br.lo);
    report_hit(best.t, 0.5 * (best.res.point_a + best.res.point_b), best.res.normal);
  }

  void run() {
    double lo = in.t_start, hi = in.t_max;
    // The window is widened by a margin: for bodies whose bounding sphere is tight (spheres)
    // the window would end exactly at touching, where the distance is zero up to rounding and
    // a rounding-negative sample would fake a contact.
    const double margin = std::max(in.eps_d, 1e-9 * L);
    if (!(lo <= hi) ||
        !bounding_sphere_window(in.a, in.b, in.t_state,
                                in.shape_a.bounding_radius() + in.shape_b.bounding_radius() + margin,
                                lo, hi)) {
      out.status = ContactStatus::none;
      return;
    }
    Sample s = eval(lo);
    if (failed) return;
    if (s.d <= 0.0 && (s.dd < 0.0 || K == 0.0)) {  // overlapping and approaching
      out.initial_overlap = true;
      report_hit(s.t, 0.5 * (s.res.point_a + s.res.point_b), s.res.normal);
      return;
    }
    if (K == 0.0) return;  // no relative motion: the distance never changes
    while (s.t < hi) {
      if (++out.steps > o.max_steps) {
        failed = true;
        return;
      }
      const double dt = std::max(s.d, in.eps_d) / K;
      const double t1 = std::min(s.t + dt, hi);
      const Sample s1 = eval(t1);
      if (failed) return;
      // A negative sample at rounding level between two samples where d increases is noise
      // (a touching pair that separates), not a contact: d cannot dip within such a step.
      const bool noise = s1.d < 0.0 && s1.d > -1e-12 * L && s.dd > 0.0 && s1.dd > 0.0;
      if (s1.d < 0.0 && !noise) {
        if (s.d > 0.0) {
          solve_bracket(s, s1);
          return;
        }
        if (s1.dd < 0.0) {  // still overlapping from the start, and now approaching again
          out.initial_overlap = true;
          report_hit(s.t, 0.5 * (s.res.point_a + s.res.point_b), s.res.normal);
          return;
        }
      } else if (s.d + s1.d <= K * (t1 - s.t) && s.dd < 0.0 && s1.dd > 0.0 && s.d > 0.0) {
        // grazing: a minimum inside [s.t, t1] that may dip below zero
        ++out.grazing_searches;
        Sample neg;
        bool found = false;
        const double width = t1 - s.t;
        // start from the minimum of the cubic Hermite model's quadratic part (secant of d')
        double x0 = s.t + width * (-s.dd) / (s1.dd - s.dd);
        x0 = std::clamp(x0, s.t + 0.05 * width, t1 - 0.05 * width);
        brent_minimize(
            [&](double t) {
              const Sample q = eval(t);
              if (failed) return -1.0;
              if (q.d < 0.0) {
                neg = q;
                found = true;
              }
              return q.d;
            },
            s.t, t1, x0, 1e-9 * width, o.brent_max_evals, [&](double v) { return v < 0.0; });
        if (failed) return;
        if (found) {
          solve_bracket(s, neg);
          return;
        }
      }
      s = s1;
    }
    out.status = ContactStatus::none;
  }
};

}  // namespace contact_detail

template <Shape SA, Shape SB>
ContactResult contact_time(const ContactInput<SA, SB>& in, const ContactOptions& o = {}) {
  ContactResult out;
  contact_detail::Solver<SA, SB> solver(in, o, out);
  solver.run();
  if (solver.failed) {
    out.status = ContactStatus::failed;
    out.time = kInf;
  }
  out.warm = solver.warm;
  return out;
}

}  // namespace hb
