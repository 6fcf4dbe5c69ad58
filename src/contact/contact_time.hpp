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
//  2. Stepping with the distance-rate bound (Eq. distOver; the rules of contact/first_root.hpp)
//        |d'(t)| <= K = |v_B - v_A| + |w_A| l_A + |w_B| l_B :
//     (l the rotation lever of the shape, shapes/shape.hpp: a closest point x with normal n
//     moves along n at |n.(w x (x - r))| = |w.((x - r) x n)| <= |w| l, and l <= L, the paper's
//     bounding radius; an ellipsoid's l is a_max - a_min)
//     (for a top that is not spherical w changes along the flight: |w| is replaced by its
//     maximum over the flight, Motion::max_angular_speed; motion/motion.hpp)
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
//  Steps 2 and 3 are the rules of contact/first_root.hpp (lipschitz_step, dip_possible,
//  find_dip). The loop is not first_root itself: each sample is a warm-started distance solve
//  that gives the rate with the value (first_root evaluates rates only for its dip test), it
//  alternates with the axis leaps below, a bracket is refined by Newton on the contact system
//  (step 4) rather than on the sign of d, and an initial overlap that separates is stepped
//  through (first_root stops at a negative start).
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
//  4'. (beyond the paper; ContactOptions::contact_ahead) A sample with 0 < d < eps_d and d' < 0
//     whose rate step would end past the time d / |d'| ahead tries the Newton of step 4 first,
//     from its own closest points at that time, kept to the step: a root there at which the
//     distance is zero and the bodies approach is the contact (Solver::solve_ahead), and the
//     sample that would have bracketed it is saved. The same Newton runs first from the end of
//     the axis leaps of step a (curved pairs: the gap g < eps_d of the last axis and its rate
//     g' < 0 give the start, the support points the contact point), which saves the first
//     distance solve too (Solver::solve_ahead_of_axis). A Newton root is accepted without a
//     distance solve when its own residuals certify it (ContactOptions::certify_newton,
//     Solver::certified_contact: the point on both surfaces, opposite normals, so by convexity
//     the common tangent plane separates the bodies, and approaching); otherwise by a distance
//     solve from the root's contact point (one NR iteration). A hit from the axis leaps then
//     costs no distance solve at all. The certificate is offered the root once before Newton
//     converges, after its first full step below 1e-6 L (ContactOptions::certify_early), and
//     takes it there only if its gap residual over the approach rate puts the time within the
//     converged Newton's tolerance: a head-on entry needs one iteration instead of two, a
//     grazing one iterates on. Otherwise the step is taken as above.
//  Separating-axis advancement (beyond the paper; shapes with a support function; with growth
//  the gap and its bounds carry the scale law, axis_gap.hpp).
//  The gap g_n(t) along a fixed unit vector n (contact/axis_gap.hpp) is a lower bound of the
//  distance that costs two support functions instead of a distance solve, with the rate bound
//  |g_n'| <= K_n <= K and, for shapes with bounded curvature, |g_n''| <= M.  It is advanced by
//  conservative steps, the larger of g / K_n and the positive root of g + g' dt - M dt^2 / 2
//  (lipschitz_step and curvature_step of contact/first_root.hpp); flat-faced rigid pairs (no
//  M) take the larger of g / K_n and the step on the concave lower bound B(s) of
//  AxisGap::affine_bound (Solver::affine_step: B at the tangent's zero, or the chord to it):
//   a. before the first distance solve, along an axis found by Newton steps on the gap over
//      directions (`separating_axis`: from the line of centres -- for rods, from the closest
//      points of their core segments, geometry/segment.hpp -- until the gap rules the
//      window out or is within axis_rel_tol of the distance), re-aimed from the last axis
//      where the gap runs low; a pair that cannot meet inside the window costs no distance
//      solve, and a pair that meets reaches its first solve within ~eps_d of contact, which
//      starts from the support points of the last axis (a guess, slid together by a short
//      steepest descent before the NR: DistanceWarmStart::guess);
//   b. after every distance sample with d >= eps_d, or with d' > 0 for curved shapes (a pair
//      that just collided and separates), along its normal (there g_n = d, g_n' = d').
//  Each step leaves g > 0, hence d > 0, behind it, so no contact is skipped; near contact
//  (d < eps_d and approaching) the rate-bound stepping of step 2 takes over unchanged.
//  A flat-faced pair left touching and separating by step a (the bound cannot move it: the
//  support point of a face leaves its middle as soon as the axis tilts) jumps eps_d / K ahead,
//  where step 2 would take its first sample, and is certified there by a new axis with a
//  positive gap instead (ContactOptions::leave_jump; Solver::leaving_flat).
//  `ContactOptions::separating_axis = false` gives the paper's algorithm alone (tests compare).
//  Initial overlap (d < 0 at the first evaluated time): if the bodies approach (d' < 0) this is a
//  contact at that time (`hit`, initial_overlap = true); if they separate (just after a
//  collision, rounding) the search continues and only a later sign change counts.
//  A distance solve that fails makes the result `failed` (never a silent `none`).
//
// Growth (Lubachevsky–Stillinger).  `ContactInput::growth` optionally scales both shapes about
// their centres by the common factor s(t) = s + rate (t - t_state) (default s = 1, rate = 0:
// rigid bodies, bit-for-bit the algorithm above).  A body scaled by s has f_s(y) = f(y / s) in
// its frame, grad f_s = grad f(y/s) / s, Hessian H(y/s) / s^2 (`scaled_shape`; ellipsoids and
// spheres scale their semi-axes directly).  Scaling about the centre is the velocity field
// (s'/s) (x - r) on top of the rigid motion, so everything above carries over with the
// material velocity u = v + w x (x - r) replaced by
//     U(x) = v + w x (x - r) + (s'/s) (x - r):
//   - distance rate d' = n.(U_B(x_B) - U_A(x_A)) (envelope theorem, unchanged form);
//   - rate bound over [t0, t1]: |x - r| <= L s(t), so
//        K = |v_B - v_A| + (|w_A| l_A + |w_B| l_B) max(s(t0), s(t1)) + |s'| (L_A + L_B),
//     recomputed per step (s grows): the step dt0 = max(d, eps_d) / K(t, t) is shortened to
//     dt = max(d, eps_d) / K(t, t + dt0), a valid bound on [t, t + dt] since dt <= dt0;
//   - contact system: with y = R^T (x - r), z = y / s, dz/dt = -R^T U / s, so
//        df/dt = -grad f_s . U,    d(grad f_s)/dt = w x grad f_s - H_s U - (s'/s) grad f_s
//     (the last term: the 1/s of grad f_s);
//   - bounding spheres: |r_AB(t)| <= (L_A + L_B) s(t) + margin, a quadratic inequality in t
//     with a linearly growing radius (`bounding_sphere_window` with `radius_rate`).
#pragma once
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "contact/axis_gap.hpp"
#include "contact/first_root.hpp"
#include "geometry/distance.hpp"
#include "geometry/posed.hpp"
#include "math/brent.hpp"
#include "math/small_lu.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/motion.hpp"
#include "shapes/shape.hpp"

namespace hb {

enum class ContactStatus { hit, none, failed };

// Common scale factor of both shapes: s(t) = s + rate (t - t_state) (t_state of the input).
// Must stay positive over the search window.
struct ScaleLaw {
  double s = 1.0;
  double rate = 0.0;  // ds/dt
  bool active() const { return !(s == 1.0 && rate == 0.0); }
};

// A shape scaled about its centre by s (models Shape): f_s(y) = f(y / s).
template <Shape S>
struct Scaled {
  S base;
  double s = 1.0;
  double f(const Vec3& y) const { return base.f(y / s); }
  Vec3 grad(const Vec3& y) const { return base.grad(y / s) / s; }
  Mat3 hessian(const Vec3& y) const { return base.hessian(y / s) / (s * s); }
  double volume() const { return base.volume() * s * s * s; }
  double bounding_radius() const { return base.bounding_radius() * s; }
  double inscribed_radius() const { return base.inscribed_radius() * s; }
  double rotation_lever() const { return hb::rotation_lever(base) * s; }
  Vec3 half_extents() const { return base.half_extents() * s; }
  Vec3 ray_surface(const Vec3& u) const { return base.ray_surface(u) * s; }
};

// The shape scaled by s. Ellipsoids and spheres scale their semi-axes (same type: the sphere
// fast path and the closed forms stay available); any other shape is wrapped in Scaled.
inline Ellipsoid scaled_shape(const Ellipsoid& e, double s) { return Ellipsoid{e.a * s, e.b * s, e.c * s}; }
inline Sphere scaled_shape(const Sphere& e, double s) { return Sphere{e.radius * s}; }
template <Shape S>
Scaled<S> scaled_shape(const S& e, double s) { return Scaled<S>{e, s}; }

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
  ScaleLaw growth{};         // both shapes scaled by s(t) (growth); default: rigid
  // A lab-frame axis to start the first separating-axis search from (zero: the line of
  // centres); e.g. the pair's axis of its last solve (ContactResult::axis).  Any unit vector
  // is a valid start: it only changes how many steps the search takes.
  Vec3 axis_start = Vec3::Zero();
  // The solver's first test, the bounding spheres' window in [t_start, t_max] (radius L_A + L_B
  // plus bounding_window_margin, no growth), already done by the caller on these same numbers
  // with this answer [window_lo, window_hi] (non-empty): not repeated (predict_contacts' first
  // pre-filter, system/rigid_bodies.hpp).
  bool window_given = false;
  double window_lo = 0.0, window_hi = 0.0;
};

struct ContactOptions {
  long max_steps = 10'000'000;  // stepping guard; exceeding it gives `failed`
  int max_nr_iter = 30;
  int brent_max_evals = 60;
  double accept_tol = 1e-10;    // NR contact accepted if |d(t_c)| <= accept_tol * L
  bool separating_axis = true;  // separating-axis advancement (false: the paper's stepping only)
  // Newton on the contact system from a sample within eps_d of contact, before the sample that
  // would bracket it (step 4' of the header; false: always bracket first, the paper's way).
  bool contact_ahead = true;
  // The axis search before the first distance solve (step a of the header): at most this many
  // gap evaluations per search, stopped once the gap is within axis_rel_tol of the distance.
  int axis_evals = 12;
  double axis_rel_tol = 0.3;
  // Axis steps of flat-faced rigid pairs (no curvature bound) on the concave bound of
  // AxisGap::affine_bound instead of first order only (false: first order, the slow twin).
  bool affine_steps = true;
  // Flat-faced rigid pairs left touching and separating by the affine steps: jump eps_d / K
  // ahead and certify it by a new axis (Solver::leaving_flat) instead of sampling the distance
  // (false: the samples, the slow twin).
  bool leave_jump = true;
  // A contact-system Newton root accepted by its own residuals and convexity
  // (Solver::certified_contact) instead of a distance solve at the root (false: the distance
  // solve, the slow twin). Only acceptances are shortcut; what it cannot certify is checked by
  // the distance solve as before.
  bool certify_newton = true;
  // The contact-system Newton offers its root to that certificate after its first full step
  // below 1e-6 L (Solver::contact_newton), and stops there if the root is certified with a
  // gap residual that, over the approach rate, is within the converged Newton's time
  // tolerance 1e-12 L / K (false: Newton converges to that tolerance first, the slow twin).
  bool certify_early = true;
  // At a collision of the rigid models, the contact read off the pair's memo axis when that is
  // the contact normal the prediction stored (touching_along, system/rigid_bodies.hpp: the
  // support points coincide to accept_tol) instead of a distance solve (false: the distance
  // solve from the axis' touching guess, the slow twin).
  bool touch_from_memo = true;
  // Rate bounds of bodies of revolution (shapes/shape.hpp revolution_axis) from the spin across
  // their axes, Motion::spin_across, in K and the axis gaps' K_n, and in the rigid models'
  // pre-filters for tops that are not spherical (SpinBound::across, system/rigid_bodies.hpp)
  // (false: from |w|, the slow twin).
  bool revolution_bounds = true;
  DistanceOptions distance{};
};

struct ContactResult {
  ContactStatus status = ContactStatus::none;
  double time = kInf;
  Vec3 point = Vec3::Zero();    // contact point (lab frame)
  Vec3 normal = Vec3::UnitX();  // unit normal at the contact, from A to B
  Vec3 axis = Vec3::Zero();     // the last separating axis found (lab frame, A to B; zero: none)
  bool initial_overlap = false;
  double min_distance = kInf;   // smallest distance evaluated (diagnostic)
  long steps = 0;               // rate-bound steps
  int distance_evals = 0;
  int distance_nr_iterations = 0;
  int nr_iterations = 0;        // contact-system NR iterations
  int grazing_searches = 0;     // Brent minimisations
  int fallbacks = 0;            // NR rejected, bracket shrunk on the sign of d(t) instead
  int distance_fallbacks = 0;   // distance solves that needed a fallback stage
  int axis_steps = 0;           // separating-axis gap values (the first after a search is its own)
  int axis_bounds = 0;          // evaluations of the affine gap bound (flat-faced pairs)
  int ahead = 0;                // contacts found by Newton ahead of a sample (step 4')
  int certified = 0;            // Newton roots accepted without a distance solve (certify_newton)
  DistanceWarmStart warm;       // last distance solution (warm start for the next prediction)
};

// A body in free flight (any top: motion/motion.hpp), coordinates relative to `origin` (to keep
// the numbers small), optionally scaled about its centre by s(t) = s0 + sdot (t - t_state): the
// growth decorator on top of the Motion.
template <Shape S>
struct MovingBody {
  const S* shape;
  BodyState st;
  double t_state;
  Vec3 origin;
  double s0 = 1.0;    // scale at t_state
  double sdot = 0.0;  // ds/dt
  Motion motion;

  MovingBody(const S* sh, const BodyState& b, double ts, const Vec3& o, double s0_ = 1.0,
             double sdot_ = 0.0)
      : shape(sh), st(b), t_state(ts), origin(o), s0(s0_), sdot(sdot_), motion(b) {}

  double scale_at(double t) const { return s0 + sdot * (t - t_state); }
  Pose pose_at(double t) const {
    return Pose{st.r - origin + st.v * (t - t_state), motion.rotation(t - t_state)};
  }
  // The pose and the angular velocity w at time t (one evaluation of the free rotation).
  Pose pose_at(double t, Vec3& w) const {
    Quat q;
    motion.pose(t - t_state, q, w);
    return Pose{st.r - origin + st.v * (t - t_state), q.toRotationMatrix()};
  }
  // Velocity of the surface point at frame point x (rigid motion + growth), pose p and angular
  // velocity w at time t.
  Vec3 point_velocity(const Vec3& x, const Pose& p, double t, const Vec3& w) const {
    const Vec3 rel = x - p.r;
    if (sdot == 0.0) return st.v + w.cross(rel);
    return st.v + w.cross(rel) + (sdot / scale_at(t)) * rel;
  }
  Vec3 point_velocity(const Vec3& x, const Pose& p, double t) const {
    return point_velocity(x, p, t, motion.angular_velocity(t - t_state));
  }
  // The frame point x seen from the body at time t: its pose p, angular velocity w, x - r in
  // the lab (rel) and in the body frame (y, at scale 1: divided by s(t) for growth).
  struct Local {
    Pose p;
    Vec3 w, rel, y;
  };
  Local local(const Vec3& x, double t) const {
    Local l;
    l.p = pose_at(t, l.w);
    l.rel = x - l.p.r;
    l.y = l.p.R.transpose() * l.rel;
    return l;
  }
  // f, grad f and the material velocity u (point_velocity) at the frame point x and time t, of
  // the shape at scale s(t): the first-order part of eval, for tests that need no Jacobian
  // (Solver::certified_contact). The same arithmetic as eval's, so the same bits.
  void eval_first(const Vec3& x, double t, double& f, Vec3& g, Vec3& u) const {
    const Local l = local(x, t);
    if (sdot == 0.0 && s0 == 1.0) {
      f = shape->f(l.y);
      g = l.p.R * shape->grad(l.y);
      u = st.v + l.w.cross(l.rel);
      return;
    }
    const double s = scale_at(t);
    const Vec3 z = l.y / s;
    f = shape->f(z);
    g = l.p.R * shape->grad(z) / s;
    u = st.v + l.w.cross(l.rel) + (sdot / s) * l.rel;
  }
  // f, grad f, Hessian and their time derivatives at the frame point x and time t (of the
  // shape at scale s(t); see the header for the growth terms). dR/dt = [w(t)]x R for any top,
  // so the formulas hold with the instantaneous angular velocity.
  void eval(const Vec3& x, double t, double& f, Vec3& g, Mat3& H, double& ft, Vec3& gt) const {
    const Local l = local(x, t);
    const Mat3& R = l.p.R;
    if (sdot == 0.0 && s0 == 1.0) {
      f = shape->f(l.y);
      g = R * shape->grad(l.y);
      H = R * shape->hessian(l.y) * R.transpose();
      const Vec3 u = st.v + l.w.cross(l.rel);
      ft = -g.dot(u);
      gt = l.w.cross(g) - H * u;
      return;
    }
    const double s = scale_at(t), gr = sdot / s;
    const Vec3 z = l.y / s;
    f = shape->f(z);
    g = R * shape->grad(z) / s;
    H = R * shape->hessian(z) * R.transpose() / (s * s);
    const Vec3 u = st.v + l.w.cross(l.rel) + gr * l.rel;
    ft = -g.dot(u);
    gt = l.w.cross(g) - H * u - gr * g;
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

// Upper bound of |d'(t)| (Eq. distOver) for spherical tops (|w| constant). la, lb: the rotation
// levers of the shapes (shapes/shape.hpp, rotation_lever): a closest point x with normal n
// moves along n at |n.(w x (x - r))| <= |w| l, so l replaces the paper's bounding radius L
// (l <= L; an ellipsoid's a_max - a_min, a sphere's 0).
inline double distance_rate_bound(const BodyState& a, double la, const BodyState& b, double lb) {
  return (b.v - a.v).norm() + a.w.norm() * la + b.w.norm() * lb;
}
// The same for any tops, |w(t)| <= max_angular_speed() (equal to |w| for spherical tops), with
// the shapes' axes of revolution ka, kb (shapes/shape.hpp revolution_axis; -1: none, |w|): only
// the part of w across that axis moves the surface, |w x e| <= spin_across(k).
inline double distance_rate_bound(const Motion& a, double la, int ka, const Motion& b, double lb,
                                  int kb) {
  return (b.initial().v - a.initial().v).norm() + a.spin_across(ka) * la + b.spin_across(kb) * lb;
}

// Upper bound of |d'| over [t0, t1] for bodies scaled by law s(t) (growth; see the header): the
// levers la, lb for the rotation, the bounding radii La, Lb for the radial swelling.
inline double distance_rate_bound(const Motion& a, double la, double La, const Motion& b,
                                  double lb, double Lb, double s_max, double sdot) {
  return (b.initial().v - a.initial().v).norm() +
         (a.max_angular_speed() * la + b.max_angular_speed() * lb) * s_max +
         std::abs(sdot) * (La + Lb);
}

// Time window (absolute) in which the growing bounding spheres overlap, |r_AB(t)| <= R(t),
// R(t) = R + R_rate (t - t_state) >= 0, intersected with [lo, hi]; false if empty.  With
// tau = t - t_state:  (|dv|^2 - R_rate^2) tau^2 + 2 (p.dv - R R_rate) tau + |p|^2 - R^2 <= 0
// and R(tau) >= 0 (the squared inequality also admits the mirror branch |r_AB| <= -R(t)).
// The true set is an interval (|r_AB(t)| convex, R(t) linear).  Roots are widened by a
// relative 1e-12 of the window scale so that rounding never cuts a contact off.
inline bool bounding_sphere_window(const BodyState& a, const BodyState& b, double t_state,
                                   double R, double R_rate, double& lo, double& hi) {
  const Vec3 p = b.r - a.r, dv = b.v - a.v;
  const double A = dv.squaredNorm() - R_rate * R_rate;
  const double Bh = p.dot(dv) - R * R_rate;
  const double C = p.squaredNorm() - R * R;
  double tl = -kInf, th = kInf;  // tau interval
  if (R_rate > 0.0) tl = -R / R_rate;
  else if (R_rate < 0.0) th = -R / R_rate;
  double q1 = -kInf, q2 = kInf;  // the quadratic's solution set, as an interval
  if (A == 0.0) {  // linear: 2 Bh tau + C <= 0
    if (Bh > 0.0) q2 = -C / (2.0 * Bh);
    else if (Bh < 0.0) q1 = -C / (2.0 * Bh);
    else if (C > 0.0) return false;
  } else {
    const double disc = Bh * Bh - A * C;
    if (disc < 0.0) {
      if (A > 0.0) return false;  // convex, always positive
      // concave, always negative: every tau of the R >= 0 branch
    } else {
      const double sq = std::sqrt(disc);
      const double q = -(Bh + std::copysign(sq, Bh));
      double t1 = q / A, t2 = (q != 0.0) ? C / q : t1;
      if (t1 > t2) std::swap(t1, t2);
      const double w = 1e-12 * (std::abs(t1) + std::abs(t2));
      if (A > 0.0) {
        q1 = t1 - w, q2 = t2 + w;
      } else {
        // concave: (-inf, t1] U [t2, inf); the branch with R >= 0 is the one that is kept
        if (R_rate > 0.0) q1 = t2 - w;
        else q2 = t1 + w;
      }
    }
  }
  tl = std::max(tl, q1);
  th = std::min(th, q2);
  if (!(tl <= th)) return false;
  lo = std::max(lo, t_state + tl);
  hi = std::min(hi, t_state + th);
  return lo <= hi;
}

// The margin contact_time adds to the sum of the bounding radii for its first test (run():
// L the larger bounding radius): callers that run the same test ahead of it use this.
inline double bounding_window_margin(double L, double eps_d) { return std::max(eps_d, 1e-9 * L); }

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

// The answer of bounding_sphere_window above (no growth) for the window [t_state, t_state + span]
// without its roots: can spheres of radius sum R, centre separation p = r_B - r_A and relative
// velocity dv at t_state (tau = 0) meet for some tau in [0, span] (span may be kInf)? With
// P(tau) = A tau^2 + 2 Bh tau + C (A = |dv|^2, Bh = p.dv, C = |p|^2 - R^2), the set P <= 0 meets
// [0, span] iff C <= 0 (they overlap now), or C > 0, Bh < 0 (they approach: the vertex
// -Bh / A is ahead), Bh^2 >= A C (P has roots: the same test as the window's) and the
// entry root t1 <= span, which fails iff P(span) > 0 with the vertex beyond span (P falls all
// the way). No square root and no division: the prediction loop (system/rigid_bodies.hpp,
// predict_contacts) runs it on every candidate and forms the window, with its roots, only for
// the few that pass its axis test too. It agrees with the window up to rounding at the window's
// edges (tau = span, or C = 0 while they recede; tests/contact/test_contact_time.cpp), where
// the pair's bounding spheres, which carry the solver's margin, are apart at every time of the
// window but one: the solver answers none there either.
inline bool bounding_spheres_may_meet(const Vec3& p, const Vec3& dv, double R, double span) {
  const double C = p.squaredNorm() - R * R;
  if (C <= 0.0) return true;
  const double Bh = p.dot(dv);
  if (!(Bh < 0.0)) return false;
  const double A = dv.squaredNorm();
  if (Bh * Bh - A * C < 0.0) return false;
  if (span < kInf && A * span + Bh < 0.0 && (A * span + 2.0 * Bh) * span + C > 0.0) return false;
  return true;
}

// The start of the distance solve at a collision (bodies touching to within the solvers'
// tolerance; orientations qa, qb, centre separation c = r_B - r_A): the support points of A
// along the separating axis of separating_axis_at and of B along its opposite, as a guess
// (DistanceWarmStart::guess, geometry/distance.hpp), in each body's own frame. The axis search
// converges quadratically on the contact normal, so the guess is close to the closest points;
// the cold guess (the centre line through the semi-axes) is not, for elongated bodies.
// `evals` gap evaluations at most; the search stops once the gap is within tol of the distance.
// `start` (lab frame, A to B), if given, is where the search starts (else the line of centres).
template <SupportShape SA, SupportShape SB>
DistanceWarmStart touching_guess(const SA& sa, const Quat& qa, const SB& sb, const Quat& qb,
                                 const Vec3& c, int evals = 12, const Vec3* start = nullptr) {
  const double tol = 1e-9 * std::max(sa.bounding_radius(), sb.bounding_radius());
  double gap;
  const Vec3 n = separating_axis_at(sa, qa, sb, qb, c, evals, gap, kInf, 1.0, start, tol, 0.0);
  if (!(n.squaredNorm() > 0.0)) return DistanceWarmStart{};  // coincident centres: no guess
  return DistanceWarmStart{sa.support_point(qa.conjugate() * n),
                           sb.support_point(-(qb.conjugate() * n)), 1.0, 0.0, true, /*guess=*/true};
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
  bool grow;  // shapes scaled by in.growth
  double L;   // length scale: max bounding radius (at the scale of t_start)
  double K;   // distance-rate bound (with growth: at t_start; steps use rate_bound)
  DistanceWarmStart warm;
  double warm_scale;  // scale of the shapes at which `warm` was found
  bool failed = false;

  Solver(const ContactInput<SA, SB>& i, const ContactOptions& op, ContactResult& r)
      : in(i), o(op), out(r),
        A{&i.shape_a, i.a, i.t_state, i.a.r, i.growth.s, i.growth.rate},
        B{&i.shape_b, i.b, i.t_state, i.a.r, i.growth.s, i.growth.rate},
        grow(i.growth.active()),
        L(std::max(i.shape_a.bounding_radius(), i.shape_b.bounding_radius()) *
          (grow ? A.scale_at(i.t_start) : 1.0)),
        K(grow ? rate_bound(i.t_start, i.t_start)
               : distance_rate_bound(A.motion, rotation_lever(i.shape_a),
                                     op.revolution_bounds ? revolution_axis(i.shape_a) : -1, B.motion,
                                     rotation_lever(i.shape_b),
                                     op.revolution_bounds ? revolution_axis(i.shape_b) : -1)),
        warm(i.warm), warm_scale(grow ? A.scale_at(i.t_start) : 1.0) {}

  // Rate bound over [t0, t1] (growth: the scale is largest at one end).
  double rate_bound(double t0, double t1) const {
    if (!grow) return K;
    return distance_rate_bound(A.motion, rotation_lever(in.shape_a), in.shape_a.bounding_radius(),
                               B.motion, rotation_lever(in.shape_b), in.shape_b.bounding_radius(),
                               std::max(A.scale_at(t0), A.scale_at(t1)), in.growth.rate);
  }

  DistanceResult solve_distance(double t, const Pose& pa, const Pose& pb) {
    if (!grow)
      return distance(*A.shape, pa, *B.shape, pb, o.distance, warm.valid ? &warm : nullptr);
    const double s = A.scale_at(t);
    if (warm.valid && warm_scale != s) {  // the warm points scale with the shapes
      warm.xa_body *= s / warm_scale;
      warm.xb_body *= s / warm_scale;
    }
    warm_scale = s;
    return distance(scaled_shape(*A.shape, s), pa, scaled_shape(*B.shape, s), pb, o.distance,
                    warm.valid ? &warm : nullptr);
  }

  Sample eval(double t) {
    Sample s;
    s.t = t;
    Vec3 wa, wb;
    const Pose pa = A.pose_at(t, wa), pb = B.pose_at(t, wb);
    s.res = solve_distance(t, pa, pb);
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
    const Vec3 ua = A.point_velocity(s.res.point_a, pa, t, wa);
    const Vec3 ub = B.point_velocity(s.res.point_b, pb, t, wb);
    s.dd = s.res.normal.dot(ub - ua);
    out.min_distance = std::min(out.min_distance, s.d);
    return s;
  }

  static constexpr bool kAxis = SupportShape<SA> && SupportShape<SB>;
  // Second-order axis steps (both curvature radii finite, AxisGap::curved).
  bool curved_axes() const {
    if constexpr (kAxis)
      return AxisGap<SA, SB>::curved(in.shape_a, in.shape_b);
    else return false;
  }

  // Axis steps that converge on the gap's zero and leave a touching pair that separates:
  // curved pairs, or flat-faced rigid pairs with affine steps.
  static constexpr bool kMayBeFlat = kAxis && !(BoundedCurvature<SA> && BoundedCurvature<SB>);
  bool second_order_axes() const {
    return curved_axes() || (kMayBeFlat && o.affine_steps && !grow);
  }

  // Separating-axis advancement from sample s (d >= eps_d, see the header): the time up to
  // which no contact is possible, >= hi if none in the window.
  double advance_on_axis(const Sample& s, double hi) { return advance_on_axis(s.res.normal, s.t, hi); }

  Vec3 axis_ma = Vec3::Zero(), axis_mb = Vec3::Zero();  // body-frame axes of the last gap
  double axis_g = kInf, axis_slope = 0.0;  // the last gap and its rate (second-order pairs)
  bool axis_second_order = false;  // curved or affine steps: axis_slope is the exact rate
  bool axis_affine = false;        // the last leaps were affine steps (a flat-faced rigid pair)

  // A flat-faced pair that the affine steps left touching (gap in [-1e-12 L, eps_d): the noise
  // guard of the steps, which count a gap negative at rounding level as touching) and separating
  // (rate > 0; just after its collision): the bound cannot move it, because a face's support
  // point leaves the face's middle as soon as the axis tilts.  With leave_jump the search then
  // jumps eps_d / K ahead, where the sampled stepping would take its first distance sample, and
  // takes a new axis there: if its gap is positive, it certifies what that sample would have
  // shown (d > 0), and the leaps go on from there without any distance solve.  The sampled
  // stepping would not have looked for a dip in between either: it does so only from an
  // approaching sample, and this pair separates (d >= g with g ~ d ~ 0 touching, so
  // d' >= g' > 0).  A gap below the noise guard keeps the samples: such a pair may really
  // overlap, which the sampled stepping handles apart.
  bool leaving_flat() const {
    return o.leave_jump && axis_affine && axis_slope > 0.0 && axis_g >= touching_noise() &&
           axis_g < in.eps_d && K > 0.0;
  }
  // The axis steps' noise guard: a gap down to this (negative, rounding level) counts as touching.
  double touching_noise() const { return -1e-12 * L; }

  // The same along the unit vector n from time t0 (gap, rate and curvature bounds:
  // contact/axis_gap.hpp); `at`: the search's support points of n at t0 (no gap evaluation
  // there).
  double advance_on_axis(const Vec3& n, double t0, double hi, const AxisSupport* at = nullptr) {
    using Gap = AxisGap<SA, SB>;
    Gap G(in.shape_a, A.motion, in.shape_b, B.motion, in.t_state, n, grow ? in.growth.s : 1.0,
          grow ? in.growth.rate : 0.0, o.revolution_bounds);
    // Flat-faced pairs (not curved) of rigid bodies: steps on the affine bound instead.
    if constexpr (kMayBeFlat)
      if (o.affine_steps && !G.is_curved() && G.has_affine_bound()) return advance_affine(G, t0, hi, at);
    // Second-order steps converge on the gap's zero: follow it closer than eps_d. They also
    // leave a touching pair that separates (g ~ 0, g' > 0: just after its collision): the
    // parabola g + g' dt - M dt^2 / 2 stays positive up to (g' + q) / M. A gap negative at
    // rounding level (-1e-12 L, the solver's noise guard) counts as touching.
    const double floor = G.is_curved() ? 1e-3 * in.eps_d : in.eps_d;
    const double noise = touching_noise();
    double t = t0, slope = 0.0;
    double g;
    if (at) {
      axis_ma = at->ma, axis_mb = at->mb;
      g = G.value(t, at->ma, at->mb, at->pa, at->pb, slope);
    } else {
      g = G.value(t, slope, axis_ma, axis_mb);
    }
    ++out.axis_steps;
    for (int k = 0; k < 64; ++k) {
      const bool leaving = G.is_curved() && slope > 0.0 && g >= noise;
      if (!(g >= floor || leaving)) break;
      // no zero of g before t + dt: first order g - Kn dt > 0, or second order
      // g + g' dt - M dt^2 / 2 > 0 (the positive root, written without cancellation)
      // Growth: the bounds hold for scales up to s_max, the larger end of [t, t + span]
      // (span: the rest of the window, or 10 first-order steps if it is unbounded); the step
      // stays inside the span.
      double span = kInf;
      if (grow) {
        G.bounds(G.scale_at(t));
        span = hi < kInf ? hi - t : 10.0 * std::max(g, in.eps_d) / G.Kn;
        G.bounds(std::max(G.scale_at(t), G.scale_at(t + span)));
      }
      double dt = lipschitz_step(g, 0.0, G.Kn);  // Kn = 0: the gap never changes, no contact
      if (G.is_curved()) dt = std::max(dt, curvature_step(g, slope, G.M));
      dt = std::min(dt, span);
      if (!(dt > 0.0)) break;
      const double t1 = t + dt;
      if (!(t1 < hi)) return hi;
      t = t1;
      g = G.value(t, slope, axis_ma, axis_mb);
      ++out.axis_steps;
    }
    axis_g = g, axis_slope = slope, axis_second_order = G.is_curved(), axis_affine = false;
    return t;
  }

  // advance_on_axis for flat-faced rigid pairs: the larger of the first-order step and the
  // step on the concave bound of AxisGap::affine_bound (affine_step), which needs the exact
  // rate and the angular velocities at each value. The steps converge on the gap's zero like
  // second-order ones (the same floor, 1e-3 eps_d) and leave a touching pair that separates.
  template <class Gap>
  [[gnu::noinline]] double advance_affine(const Gap& G, double t0, double hi, const AxisSupport* at) {
    const double floor = 1e-3 * in.eps_d;
    const double noise = touching_noise();
    double t = t0, slope = 0.0;
    Vec3 Wa, Wb;
    double g;
    if (at) {
      axis_ma = at->ma, axis_mb = at->mb;
      g = G.value_and_rate(t, at->ma, at->mb, at->pa, at->pb, slope, Wa, Wb);
    } else {
      g = G.value_and_rate(t, slope, axis_ma, axis_mb, Wa, Wb);
    }
    ++out.axis_steps;
    for (int k = 0; k < 64; ++k) {
      const bool leaving = slope > 0.0 && g >= noise;
      if (!(g >= floor || leaving)) break;
      double dt = lipschitz_step(g, 0.0, G.Kn);  // Kn = 0: the gap never changes, no contact
      if (t + dt < hi) {
        const double sa = affine_step(G, t, g, slope, hi - t, dt, floor, Wa, Wb);
        if (!(sa > 0.0) && g < floor) break;  // a leaving pair the bound cannot move: sampled
        dt = std::max(dt, sa);
      }
      if (!(dt > 0.0)) break;
      const double t1 = t + dt;
      if (!(t1 < hi)) return hi;
      t = t1;
      g = G.value_and_rate(t, slope, axis_ma, axis_mb, Wa, Wb);
      ++out.axis_steps;
    }
    axis_g = g, axis_slope = slope, axis_second_order = true, axis_affine = true;
    return t;
  }

  // The step from gap g >= 0 (rate slope) at t that the concave lower bound B of
  // AxisGap::affine_bound allows, at most `rest` (the rest of the window); dt1 the first-order
  // step, floor the gap below which the pair counts as touching. Trial: where the tangent of
  // g reaches zero (or the window's end; 16 dt1 when neither is finite). If B stays above the
  // noise level there, the trial step is safe; otherwise the chord from (0, g) to the trial
  // point reaches that level before B does (B concave), and that is the step. Near contact the step is Newton's with a quadratic correction: the gap
  // falls quadratically instead of by the factor 1 - |g'| / K_n of a first-order step.
  // A touching pair that separates (g at noise level, g' > 0: just after its collision) has no
  // chord to follow: a second trial at half the root of the parabola through B(0), B'(0) = g'
  // and the first trial, kept if B is above the noise level there.
  template <class Gap>
  double affine_step(const Gap& G, double t, double g, double slope, double rest, double dt1,
                     double floor, const Vec3& Wa, const Vec3& Wb) {
    double s = std::min(slope < 0.0 ? g / -slope : kInf, rest);
    if (!(s < kInf)) s = 16.0 * std::max(dt1, in.eps_d / G.Kn);
    const double b = G.affine_bound(t, s, axis_ma, axis_mb, Wa, Wb);
    ++out.axis_bounds;
    const double noise = 1e-12 * L;
    if (b > noise) return s;
    if (g > floor || !(slope > 0.0)) return g > noise ? s * ((g - noise) / (g - b)) : 0.0;
    const double C = 2.0 * (g + slope * s - b) / (s * s);  // >= 0 (B concave)
    if (!(C > 0.0)) return 0.0;
    const double s2 = 0.5 * (slope + std::sqrt(slope * slope + 2.0 * C * std::max(g, 0.0))) / C;
    if (!(s2 > 0.0 && s2 < s)) return 0.0;
    ++out.axis_bounds;
    return G.affine_bound(t, s2, axis_ma, axis_mb, Wa, Wb) > noise ? s2 : 0.0;
  }

  void report_hit(double t, const Vec3& x, const Vec3& n) {
    out.status = ContactStatus::hit;
    out.time = t;
    out.point = x + A.origin;
    out.normal = n;
  }

  // How the contact-system Newton ended: no root in its interval, a converged root (still to
  // be accepted, accept_newton), or a root certified and reported already (certify_early).
  enum class NewtonEnd { failed, converged, certified };

  // Newton-Raphson on the contact system from y = (x, alpha, t), time kept to [t_lo, t_hi] (a
  // step that leaves it ends the iteration). It converges when a full step is below 1e-12 L
  // in x and 1e-12 L / K in time. With ContactOptions::certify_newton and certify_early, the
  // first full step below 1e-6 L (and 1e-6 L / K) offers its root once to certified_contact
  // with the time criterion: Newton converges quadratically, so that root is usually within
  // rounding of the converged one, and the certificate checks that it is (its gap residual
  // over the approach rate within the time tolerance); `entering` is accept_newton's.
  NewtonEnd contact_newton(Vec5c& y, double t_lo, double t_hi, bool entering) {
    const double dt_tol = 1e-12 * L / std::max(K, 1e-300);
    bool offered = !(o.certify_newton && o.certify_early);
    for (int it = 0; it < o.max_nr_iter; ++it) {
      ++out.nr_iterations;
      Vec5c F;
      Mat5c J;
      contact_system(A, B, y, F, &J);
      Vec5c dy = SmallLU<5>(J).solve(-F);
      if (!dy.allFinite()) return NewtonEnd::failed;
      const double dx = dy.head<3>().norm();
      double xi = 1.0;
      if (dx > 0.5 * L) xi = 0.5 * L / dx;
      if (std::abs(dy[3]) > 0.5 * std::abs(y[3])) xi = std::min(xi, 0.5 * std::abs(y[3] / dy[3]));
      y += xi * dy;
      if (y[4] < t_lo - dt_tol || y[4] > t_hi + dt_tol) return NewtonEnd::failed;  // left it
      if (xi == 1.0 && dx <= 1e-12 * L && std::abs(dy[4]) <= dt_tol) return NewtonEnd::converged;
      if (!offered && xi == 1.0 && dx <= 1e-6 * L && std::abs(dy[4]) <= 1e6 * dt_tol) {
        offered = true;
        if (certified_contact(y.head<3>(), std::clamp(y[4], t_lo, t_hi), entering, dt_tol))
          return NewtonEnd::certified;
      }
    }
    return NewtonEnd::failed;
  }

  // The Newton result y (time in [t_lo, t_hi]) checked by a distance solve there: a contact if
  // the distance is zero to accept_tol and, with `entering`, the bodies approach (d' < 0).
  // Reports the hit and returns true; false otherwise (or if the solve failed: `failed`).
  // With ContactOptions::certify_newton the root is first certified without the distance solve
  // (certified_contact); what that cannot certify goes to the distance solve as before.
  bool accept_newton(const Vec5c& y, double t_lo, double t_hi, bool entering) {
    const double tc = std::clamp(y[4], t_lo, t_hi);
    if (o.certify_newton && certified_contact(y.head<3>(), tc, entering)) return true;
    // The distance solve starts from the Newton point: both closest points there (touching),
    // the multiplier alpha of the contact system (the distance solver's own, beta = 0).
    if (!grow) {
      const Pose pa = A.pose_at(tc), pb = B.pose_at(tc);
      const Vec3 x = y.head<3>();
      warm = DistanceWarmStart{pa.R.transpose() * (x - pa.r), pb.R.transpose() * (x - pb.r),
                               std::abs(y[3]), 0.0, true};
    }
    const Sample c = eval(tc);
    if (failed) return false;
    if (!(std::abs(c.d) <= o.accept_tol * L) || (entering && !(c.dd < 0.0))) return false;
    double f_;
    Vec3 g_, u_;
    A.eval_first(y.head<3>(), tc, f_, g_, u_);
    report_hit(tc, y.head<3>(), g_.normalized());
    return true;
  }

  // The Newton root certified by convexity, without a distance solve: the point x lies on both
  // surfaces at tc (first-order distances |f| / |grad f| within accept_tol L) and their outward
  // normals n_A, n_B are opposite (|n_A + n_B| <= accept_tol). Then the common tangent plane
  // at x has A on one side and B on the other (both convex), so the bodies touch: the distance
  // is zero to the tolerance the distance solve would check, and no overlap is possible beyond
  // the normals' misfit over the bodies' size (accept_tol L). With `entering`, the rate of the
  // gap at the touching point, n_A . (u_B(x) - u_A(x)) (u the surface point's velocity, as
  // eval computes d' at the closest points), must be below -accept_tol K: a grazing pair whose
  // rate is within rounding of zero is left to the distance solve, so that the sign is decided
  // as before. Reports the hit (the same time, point and normal as the distance-solve path)
  // and returns true; false: not certified (nothing reported, nothing changed).
  // With time_tol > 0 (a Newton root before convergence, certify_early), the root's time must
  // also be within time_tol of the converged one: the gap residual |f_A| / |grad f_A| +
  // |f_B| / |grad f_B| + |n_A + n_B|^2 L over the approach rate |n_A . (u_B - u_A)| within
  // time_tol. (Two surfaces through x whose normals misfit by e cross; for curved bodies the
  // overlap is of order e^2 times their radii, so e^2 L bounds it at the bodies' size. Flat
  // faces have no such radius and the term is an estimate there, not a bound: the
  // superquadric twin test, faces meeting at tilts down to 0, measures the times against the
  // converged Newton's, 1.2e-12 L / K apart at most.)
  bool certified_contact(const Vec3& x, double tc, bool entering, double time_tol = 0.0) {
    double fa, fb;
    Vec3 ga, gb, ua, ub;
    A.eval_first(x, tc, fa, ga, ua);
    B.eval_first(x, tc, fb, gb, ub);
    const double na = ga.norm(), nb = gb.norm();
    const double tol = o.accept_tol * L;
    if (!(na > 0.0 && nb > 0.0 && std::abs(fa) <= tol * na && std::abs(fb) <= tol * nb)) return false;
    const Vec3 n = ga / na;
    const double misfit = (n + gb / nb).norm();
    if (!(misfit <= o.accept_tol)) return false;
    const double rate = n.dot(ub - ua);
    if (entering && !(rate < -o.accept_tol * K)) return false;
    if (time_tol > 0.0 &&
        !(std::abs(fa) / na + std::abs(fb) / nb + misfit * misfit * L <= time_tol * std::abs(rate)))
      return false;
    report_hit(tc, x, ga.normalized());
    ++out.certified;
    return true;
  }

  // Step 4' from the end of the axis leaps (curved or affine steps, no growth): the gap g < eps_d of the
  // last axis at lo, approaching (g' < 0), and no contact before lo. The Newton starts from
  // the midpoint of the support points along the axis, alpha from their gradients, at
  // lo + g / |g'|, kept to [lo, lo + eps_d / K] (the rate step from a distance below eps_d); the
  // root is accepted as in solve_ahead. Saves the distance solve at lo.
  bool solve_ahead_of_axis(double lo, double hi) {
    if constexpr (kAxis) {
      if (grow || !axis_second_order || !(axis_g >= 0.0 && axis_g < in.eps_d && axis_slope < 0.0))
        return false;
      const double t1 = std::min(lo + in.eps_d / K, hi);
      const Pose pa = A.pose_at(lo), pb = B.pose_at(lo);
      const Vec3 ya = in.shape_a.support_point(axis_ma), yb = in.shape_b.support_point(axis_mb);
      const double ga = in.shape_a.grad(ya).norm(), gb = in.shape_b.grad(yb).norm();
      if (!(ga > 0.0 && gb > 0.0)) return false;
      Vec5c y;
      y << 0.5 * (pa.r + pa.R * ya + pb.r + pb.R * yb), std::sqrt(ga / gb),
          std::min(lo + axis_g / -axis_slope, t1);
      const NewtonEnd e = contact_newton(y, lo, t1, true);
      if (e == NewtonEnd::failed || (e == NewtonEnd::converged && !accept_newton(y, lo, t1, true)))
        return false;
      ++out.ahead;
      return true;
    }
    return false;
  }

  // Step 4' (beyond the paper): from a sample s with 0 < d < eps_d, approaching, whose rate step
  // ends at t1, Newton on the contact system from s's closest points and multiplier at the
  // time the rate extrapolates to (t = s.t + d / |d'|), without the distance sample at t1
  // that would bracket the contact first. Accepted as solve_bracket accepts a root (time in
  // the step, distance there zero to tolerance) and only if the bodies approach there (d' < 0:
  // the entry into contact, not the exit from a dip). No contact can start before
  // s.t + d / K, so like a bracket's root the time is the first contact up to roots closer
  // together than the step (eps_d / K). Anything else: false, and the caller steps as before.
  bool solve_ahead(const Sample& s, double t1) {
    const double t0 = s.t + s.d / -s.dd;
    if (!(t0 <= t1)) return false;  // the rate does not reach contact within the step
    Vec5c y;
    y << 0.5 * (s.res.point_a + s.res.point_b), std::max(s.res.alpha, 1e-3), t0;
    const NewtonEnd e = contact_newton(y, s.t, t1, true);
    if (e == NewtonEnd::failed || (e == NewtonEnd::converged && !accept_newton(y, s.t, t1, true)))
      return false;
    ++out.ahead;
    return true;
  }

  // Contact NR from the bracket [lo, hi] (d(lo) > 0 > d(hi)); fallback: shrink the bracket.
  // The NR starts at the secant time with the closest points and multiplier of the end nearer
  // to contact (no distance solve: the bracket is at most one rate step eps_d / K wide).
  void solve_bracket(const Sample& l, const Sample& h) {
    const double t0 = l.t + (h.t - l.t) * l.d / (l.d - h.d);
    const Sample& g = l.d <= -h.d ? l : h;
    Vec5c y;
    y << 0.5 * (g.res.point_a + g.res.point_b), std::max(g.res.alpha, 1e-3), t0;
    const NewtonEnd e = contact_newton(y, l.t, h.t, false);
    if (e == NewtonEnd::certified) return;
    if (e == NewtonEnd::converged) {
      if (accept_newton(y, l.t, h.t, false)) return;
      if (failed) return;
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
    const double margin = bounding_window_margin(L, in.eps_d);
    const double Lab = in.shape_a.bounding_radius() + in.shape_b.bounding_radius();
    if (grow && !(A.scale_at(lo) > 0.0 && (hi == kInf ? in.growth.rate >= 0.0 : A.scale_at(hi) > 0.0))) {
      failed = true;  // the scale law must stay positive over the window
      return;
    }
    bool window = true;
    if (in.window_given && !grow)
      lo = in.window_lo, hi = in.window_hi;  // the caller's answer to the same test
    else if (grow)
      window = bounding_sphere_window(in.a, in.b, in.t_state, Lab * in.growth.s + margin,
                                      Lab * in.growth.rate, lo, hi);
    else
      window = bounding_sphere_window(in.a, in.b, in.t_state, Lab + margin, lo, hi);
    if (!(lo <= hi) || !window) {
      out.status = ContactStatus::none;
      return;
    }
    if constexpr (kAxis) {
      // Before any distance solve: advance along the best axis found from the line of centres
      // (a pair that cannot meet inside the window costs no distance solve at all).
      // Re-aim the axis, from the last one, where the gap ran low, as long as that makes progress.
      Vec3 axis = Vec3::Zero();
      double jumped_from = -1.0;  // >= 0: lo moved ahead by a leaving jump, not yet certified
      for (int k = 0; k < 8 && o.separating_axis; ++k) {
        // a gap of K (hi - lo) already rules out any contact in the window
        const double reach = hi < kInf ? (grow ? rate_bound(lo, hi) : K) * (hi - lo) : kInf;
        double g0;
        AxisSupport at;
        const Vec3 n = separating_axis(in.shape_a, A.motion, in.shape_b, B.motion, lo - in.t_state,
                                       o.axis_evals, g0, reach, grow ? A.scale_at(lo) : 1.0,
                                       k > 0 ? &axis
                                             : (in.axis_start.squaredNorm() > 0.0 ? &in.axis_start
                                                                                  : nullptr),
                                       1e-3 * in.eps_d, o.axis_rel_tol, &at);
        if (!(n.squaredNorm() > 0.0)) break;
        out.axis = n;
        if (jumped_from >= 0.0 && !(g0 > 0.0)) break;  // the jump is not certified (below)
        jumped_from = -1.0;
        axis = n;
        if (g0 >= reach) return;  // none
        const double t = advance_on_axis(n, lo, hi, &at);
        if (!(t < hi)) return;  // none
        if (!(t > lo)) {
          if (!leaving_flat()) break;
          jumped_from = lo;
          lo = std::min(lo + in.eps_d / K, hi);
          continue;
        }
        lo = t;
      }
      if (jumped_from >= 0.0) lo = jumped_from;  // an uncertified jump: sample from before it
      // The support points along the last axis are close to the closest points: the first
      // distance solve starts from them instead of the cold guess.
      if (o.separating_axis && !warm.valid && axis_ma.squaredNorm() > 0.0) {
        const double sc = grow ? A.scale_at(lo) : 1.0;
        warm = DistanceWarmStart{sc * in.shape_a.support_point(axis_ma),
                                 sc * in.shape_b.support_point(axis_mb), 1.0, 0.0, true,
                                 /*guess=*/true};
        warm_scale = sc;
      }
      if (o.separating_axis && o.contact_ahead && solve_ahead_of_axis(lo, hi)) return;
      if (failed) return;
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
      if constexpr (kAxis) {
        if (o.separating_axis && (s.d >= in.eps_d || (s.dd > 0.0 && second_order_axes()))) {
          const double t = advance_on_axis(s, hi);
          if (!(t < hi)) break;
          if (t > s.t) {
            s = eval(t);
            if (failed) return;
            continue;
          }
        }
      }
      if (++out.steps > o.max_steps) {
        failed = true;
        return;
      }
      double Ks = K;
      double dt = lipschitz_step(s.d, in.eps_d, K);
      if (grow) {  // K over [s.t, s.t + dt0], then the (shorter) step that bound allows
        Ks = rate_bound(s.t, s.t);
        dt = lipschitz_step(s.d, in.eps_d, Ks);
        Ks = rate_bound(s.t, s.t + dt);
        dt = lipschitz_step(s.d, in.eps_d, Ks);
      }
      // d >= eps_d: the step is the rate bound itself, no contact before s.t + dt; if that
      // reaches the window's end there is nothing left to look at (saves the last solve).
      if (s.d >= in.eps_d && s.t + dt >= hi) break;
      const double t1 = std::min(s.t + dt, hi);
      if (o.contact_ahead && s.d > 0.0 && s.d < in.eps_d && s.dd < 0.0) {
        if (solve_ahead(s, t1)) return;
        if (failed) return;
      }
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
      } else if (dip_possible(s.d, s1.d, Ks, t1 - s.t) && s.dd < 0.0 && s1.dd > 0.0 && s.d > 0.0) {
        // grazing: a minimum inside [s.t, t1] that may dip below zero
        ++out.grazing_searches;
        Sample neg;
        bool found = false;
        const double width = t1 - s.t;
        // start from the minimum of the cubic Hermite model's quadratic part (secant of d')
        double x0 = s.t + width * (-s.dd) / (s1.dd - s.dd);
        x0 = std::clamp(x0, s.t + 0.05 * width, t1 - 0.05 * width);
        find_dip(
            [&](double t) {
              const Sample q = eval(t);
              if (failed) return -1.0;
              if (q.d < 0.0) {
                neg = q;
                found = true;
              }
              return q.d;
            },
            s.t, t1, x0, 1e-9 * width, o.brent_max_evals);
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

// Compiled once for the engine's shape pairs (src/contact/contact_time_*.cpp; see the end of
// geometry/distance.hpp).
#define HB_CONTACT_INSTANCE(EXTERN, SA, SB) \
  EXTERN template ContactResult contact_time<SA, SB>(const ContactInput<SA, SB>&, const ContactOptions&);
#define HB_CONTACT_INSTANCES(EXTERN, SA) HB_FOR_EACH_ENGINE_SHAPE(HB_CONTACT_INSTANCE, EXTERN, SA)
#ifndef HB_CONTACT_INSTANTIATE
HB_CONTACT_INSTANCES(extern, Sphere)  // (not nested in HB_FOR_EACH_ENGINE_SHAPE: a macro cannot expand itself)
HB_CONTACT_INSTANCES(extern, Ellipsoid)
HB_CONTACT_INSTANCES(extern, Superquadric)
#endif

}  // namespace hb
