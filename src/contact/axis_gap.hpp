// The gap of two moving convex bodies along a fixed direction: a cheap lower bound of their
// distance, used by the contact-time solver (contact_time.hpp) to advance without distance
// solves. Beyond the paper; shapes with a closed-form support function (SupportShape).
//
// For a unit vector n (lab frame) and bodies in free flight (spherical tops: w constant),
//     g_n(t) = n.(r_B(t) - r_A(t)) - h_A(m_A(t)) - h_B(m_B(t)),
//     m_A = R_A(t)^T n,  m_B = -R_B(t)^T n,
// h the support function. g_n > 0 means the plane normal to n separates the bodies, so
// g_n(t) <= d(t) whenever d >= 0, with equality for n the normal at the closest points.
//
// Rate. d/dt R^T n = -R^T (w x n) (R' = [w]x R), and grad h(m) = p(m), the support point, so
//     g_n' = n.(v_B - v_A) + p_A.(W_A x m_A) + p_B.(W_B x m_B),   W = R^T w (body frame,
// constant for a spherical top since R(t) w = w). W x m is normal to m, so only the part of p
// normal to m counts: |p.(W x m)| <= l |m'| with l the shape's rotation lever (shapes/shape.hpp,
// rotation_lever; l <= L, an ellipsoid's a_max - a_min), and
//     |g_n'| <= K_n = |n.(v_B - v_A)| + l_A |w_A x n| + l_B |w_B x n|,
// constant in time because the rotation about w keeps |w x n(t)|.
// Curvature. m(t) turns about a fixed body axis at rate |w|: |m'| = |w x n| =: s,
// |m''| = |w| s. With the support Hessian bounded by the largest principal radius of curvature
// rho (m'^T H m' <= rho |m'|^2) and |p| <= L,
//     |d^2 h(m(t)) / dt^2| <= rho s^2 + L |w| s,
// so |g_n''| <= M = sum over the bodies of s (rho s + L |w|). Shapes whose
// max_curvature_radius() is finite (ellipsoids, spheres, superquadrics with all exponents 2) get
// M; others (superquadrics with an exponent > 2: flat faces, rho unbounded) only K_n, and, for
// rigid bodies, the affine bound (affine_bound below): the support functions evaluated at the
// directions extrapolated to first order, m + s m', less a remainder L |m''| s^2 / 2 -- a
// concave lower bound of g(t + s) that needs no radius of curvature.
// Evaluation: R(t)^T n = R(t_state)^T rot(w, -|w| tau) n (Rodrigues on one vector, tau =
// t - t_state): two sin/cos and two support functions per value.
// Tops that are not spherical (W(t) varies; motion/motion.hpp): m' = -W x m still, so
// |m'| <= max |w| replaces |w x n| in K_n; and m'' = -W' x m - W x m', |m''| <= max |W'| +
// max |w|^2 (Motion::max_angular_acceleration bounds |W'| from Euler's equations), so each body
// adds rho wmax^2 + L (wmax^2 + max |W'|) to M. R(t) and W(t) come from the Motion.
// Growth (both shapes scaled about their centres by s(t) = s0 + sdot tau, contact_time.hpp):
// the support functions scale, g = n.(r_B - r_A) - s(t) (h_A + h_B), so
//     g' = n.dv - sdot (h_A + h_B) + s(t) (p_A.(W_A x m_A) + p_B.(W_B x m_B)),
//     |g'| <= |n.dv| + |sdot| (L_A + L_B) + s_max (l_A |w_A x n| + l_B |w_B x n|),
//     |g''| <= 2 |sdot| (l_A |w_A x n| + l_B |w_B x n|) + s_max M_rigid        (s'' = 0),
// s_max the largest scale over the interval considered (`bounds(s_max)`).
#pragma once
#include <cmath>
#include <algorithm>
#include <bit>
#include <cstdint>
#include <concepts>

#include "geometry/segment.hpp"
#include "math/sin_cos.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/motion.hpp"
#include "shapes/shape.hpp"

namespace hb {

// One body's rotation bounds for a fixed lab direction n (see above): |m'| <= sw and
// |m''| <= mdd for m(t) = R(t)^T n; spherical tops turn m about a fixed body axis.
struct TurnBounds {
  double sw, mdd;
};
inline TurnBounds turn_bounds(const Motion& mo, const Vec3& n) {
  if (mo.spherical()) {
    const double sw = mo.initial().w.cross(n).norm();
    return {sw, mo.initial().w.norm() * sw};
  }
  const double sw = mo.max_angular_speed();
  return {sw, sw * sw + mo.max_angular_acceleration()};
}

template <SupportShape SA, SupportShape SB>
class AxisGap {
 public:
  static constexpr bool kMayCurve = requires(const SA& x, const SB& y) {
    { x.max_curvature_radius() } -> std::convertible_to<double>;
    { y.max_curvature_radius() } -> std::convertible_to<double>;
  };
  // Both curvature radii bounded: second-order steps (M finite).
  static bool curved(const SA& sa, const SB& sb) {
    if constexpr (kMayCurve)
      return std::isfinite(sa.max_curvature_radius()) && std::isfinite(sb.max_curvature_radius());
    else
      return false;
  }

  // s0, sdot: the common scale law of both shapes (growth); s0 = 1, sdot = 0 for rigid bodies.
  // The motions are referenced, not copied: they must outlive the AxisGap.
  AxisGap(const SA& sa, const Motion& ma, const SB& sb, const Motion& mb, double t_state,
          const Vec3& n, double s0 = 1.0, double sdot = 0.0, bool revolution = true)
      : sa_(sa), sb_(sb), ma_(&ma), mb_(&mb), n_(n), dr_(mb.initial().r - ma.initial().r),
        dv_(mb.initial().v - ma.initial().v), t_state_(t_state), s0_(s0), sdot_(sdot),
        curved_(curved(sa, sb)) {
    const BodyState& a = ma.initial();
    const BodyState& b = mb.initial();
    const double La = sa.bounding_radius(), Lb = sb.bounding_radius();
    const TurnBounds ta = turn_bounds(ma, n), tb = turn_bounds(mb, n);
    const double swa = ta.sw, swb = tb.sw;
    wa_ = a.w.norm(), wb_ = b.w.norm();
    ndv_ = std::abs(n.dot(dv_));
    // |dh/dt| <= l |m'|, and <= l |w x e| for a body of revolution about e (shapes/shape.hpp)
    // (revolution = false: |m'| only, the slow twin)
    rot_ = rotation_lever(sa) * std::min(swa, ma.spin_across(revolution ? revolution_axis(sa) : -1)) +
           rotation_lever(sb) * std::min(swb, mb.spin_across(revolution ? revolution_axis(sb) : -1));
    Lsum_ = La + Lb;
    const double mdd_a = ta.mdd, mdd_b = tb.mdd;  // bounds of |m''| per body
    if constexpr (kMayCurve)
      if (curved_)
        Mrigid_ = swa * swa * sa.max_curvature_radius() + La * mdd_a +
                  swb * swb * sb.max_curvature_radius() + Lb * mdd_b;
    Q_ = La * mdd_a + Lb * mdd_b;
    bounds(s0);
    RaT_ = a.q.toRotationMatrix().transpose();
    RbT_ = b.q.toRotationMatrix().transpose();
    Wa_ = RaT_ * a.w, Wb_ = RbT_ * b.w;
    ka_ = wa_ > 0.0 ? Vec3(a.w / wa_) : Vec3::Zero();
    kb_ = wb_ > 0.0 ? Vec3(b.w / wb_) : Vec3::Zero();
  }

  double Kn = 0.0;  // bound of |g'| (for scales up to the s_max of the last `bounds` call)
  double M = kInf;  // bound of |g''| (curved() pairs only; likewise)
  bool is_curved() const { return curved_; }
  const Vec3& axis() const { return n_; }
  double scale_at(double t) const { return s0_ + sdot_ * (t - t_state_); }
  // Set Kn and M for an interval on which the scale stays <= s_max (rigid: s_max = 1).
  void bounds(double s_max) {
    Kn = ndv_ + std::abs(sdot_) * Lsum_ + s_max * rot_;
    if (curved_) M = 2.0 * std::abs(sdot_) * rot_ + s_max * Mrigid_;
  }

  // g(t); slope = g'(t) for curved() pairs, -Kn otherwise; ma, mb the body-frame directions
  // (their support points are the extreme points along the axis).
  // (Kept out of line: inlined into the solver's loops it costs the ellipsoid path ~1 %.)
  [[gnu::noinline]] double value(double t, double& slope, Vec3& ma, Vec3& mb) const {
    const double tau = t - t_state_;
    Vec3 Wa, Wb;
    directions(tau, ma, mb, Wa, Wb);
    if (curved_)
      return from_support(tau, ma, mb, sa_.support_point(ma), sb_.support_point(mb), Wa, Wb, slope);
    slope = -Kn;
    return n_.dot(dr_ + dv_ * tau) - scale_at(t) * (sa_.support(ma) + sb_.support(mb));
  }
  // g(t) and its exact rate g'(t) for every pair (curved or not), with the body-frame
  // directions ma, mb and angular velocities Wa, Wb at t (what affine_bound needs).
  double value_and_rate(double t, double& slope, Vec3& ma, Vec3& mb, Vec3& Wa, Vec3& Wb) const {
    const double tau = t - t_state_;
    directions(tau, ma, mb, Wa, Wb);
    return from_support(tau, ma, mb, sa_.support_point(ma), sb_.support_point(mb), Wa, Wb, slope);
  }
  // The same from the search's support points at t (value(t, ma, mb, pa, pb, slope) below).
  double value_and_rate(double t, const Vec3& ma, const Vec3& mb, const Vec3& pa, const Vec3& pb,
                        double& slope, Vec3& Wa, Vec3& Wb) const {
    const double tau = t - t_state_;
    rates(tau, Wa, Wb);
    return from_support(tau, ma, mb, pa, pb, Wa, Wb, slope);
  }

  // Rigid pairs (no growth: has_affine_bound()): a lower bound of g(t + s) for every s >= 0,
  //     B(s) = n.(c(t) + dv s) - s0 [h_A(m_A + s m_A') + h_B(m_B + s m_B')] - s0 Q s^2 / 2,
  // m = m(t), m' = m x W (W the body-frame angular velocity at t), Q = L_A |m_A''|max +
  // L_B |m_B''|max. Derivation: m(t + s) = m + s m' + r(s) with |r| <= s^2 |m''|max / 2, and a
  // support function is sublinear, h(u + r) <= h(u) + h(r) <= h(u) + L |r|. B is concave in s
  // (linear minus convex functions of an affine argument minus a parabola) and B(0) = g(t), so
  // B(s1) > 0 rules out any zero of g on [t, t + s1], and the zero of the chord from (0, g) to
  // (s1, B(s1) < 0) lies before the first zero of B. Unlike the curvature bound M, Q needs no
  // radius of curvature: flat faces (superquadrics with exponents > 2) get steps beyond first
  // order. Two support functions per bound, of the non-unit directions m + s m'.
  bool has_affine_bound() const { return sdot_ == 0.0; }
  double affine_remainder() const { return s0_ * Q_; }  // the coefficient of s^2 / 2 in B
  double affine_bound(double t, double s, const Vec3& ma, const Vec3& mb, const Vec3& Wa,
                      const Vec3& Wb) const {
    const double tau = t - t_state_;
    const Vec3 ua = ma + s * ma.cross(Wa), ub = mb + s * mb.cross(Wb);
    return n_.dot(dr_ + dv_ * (tau + s)) - s0_ * (sa_.support(ua) + sb_.support(ub) + 0.5 * Q_ * s * s);
  }
  double value(double t) const {
    double s;
    Vec3 ma, mb;
    return value(t, s, ma, mb);
  }
  // The same from the body-frame directions ma, mb of the axis at time t and their support
  // points pa, pb, found already (the end of separating_axis at that time: AxisSupport). Saves
  // the rotations and the two support points of value(t). The gap is n.c - s (pa.ma + pb.mb)
  // for every pair (exact support points: pa.ma is the support function).
  double value(double t, const Vec3& ma, const Vec3& mb, const Vec3& pa, const Vec3& pb,
               double& slope) const {
    const double tau = t - t_state_;
    if (!curved_) {
      slope = -Kn;
      return n_.dot(dr_ + dv_ * tau) - (s0_ + sdot_ * tau) * (pa.dot(ma) + pb.dot(mb));
    }
    Vec3 Wa, Wb;
    rates(tau, Wa, Wb);
    return from_support(tau, ma, mb, pa, pb, Wa, Wb, slope);
  }

 private:
  // The body-frame directions ma = R_A^T n, mb = -R_B^T n and angular velocities at tau.
  void directions(double tau, Vec3& ma, Vec3& mb, Vec3& Wa, Vec3& Wb) const {
    Wa = Wa_, Wb = Wb_;
    if (ma_->spherical()) {
      ma = RaT_ * back(ka_, wa_, tau);
    } else {
      Quat q;
      Vec3 w;
      ma_->pose(tau, q, w);
      const Mat3 RT = q.toRotationMatrix().transpose();
      ma = RT * n_, Wa = RT * w;
    }
    if (mb_->spherical()) {
      mb = -(RbT_ * back(kb_, wb_, tau));
    } else {
      Quat q;
      Vec3 w;
      mb_->pose(tau, q, w);
      const Mat3 RT = q.toRotationMatrix().transpose();
      mb = -(RT * n_), Wb = RT * w;
    }
  }
  // The body-frame angular velocities alone (constant for spherical tops).
  void rates(double tau, Vec3& Wa, Vec3& Wb) const {
    Wa = Wa_, Wb = Wb_;
    Quat q;
    Vec3 w;
    if (!ma_->spherical()) ma_->pose(tau, q, w), Wa = q.conjugate() * w;
    if (!mb_->spherical()) mb_->pose(tau, q, w), Wb = q.conjugate() * w;
  }
  // g and its exact rate g' from the support points pa, pb along the body-frame directions
  // ma, mb, the body-frame angular velocities Wa, Wb at tau = t - t_state.
  double from_support(double tau, const Vec3& ma, const Vec3& mb, const Vec3& pa, const Vec3& pb,
                      const Vec3& Wa, const Vec3& Wb, double& slope) const {
    const double sc = s0_ + sdot_ * tau;
    const double h = pa.dot(ma) + pb.dot(mb);
    slope = n_.dot(dv_) - sdot_ * h + sc * (pa.dot(Wa.cross(ma)) + pb.dot(Wb.cross(mb)));
    return n_.dot(dr_ + dv_ * tau) - sc * h;
  }
  // n rotated by -|w| tau about the unit axis k (Rodrigues; tau = 0: n itself, no trigonometry)
  Vec3 back(const Vec3& k, double w, double tau) const {
    if (w == 0.0 || tau == 0.0) return n_;
    const SinCos sc = sin_cos(-w * tau);
    return n_ * sc.c + k.cross(n_) * sc.s + k * (k.dot(n_) * (1.0 - sc.c));
  }

  const SA& sa_;
  const SB& sb_;
  const Motion* ma_;
  const Motion* mb_;
  Vec3 n_, dr_, dv_;
  double t_state_, s0_, sdot_;
  bool curved_;
  double wa_ = 0.0, wb_ = 0.0, ndv_ = 0.0, rot_ = 0.0, Lsum_ = 0.0, Mrigid_ = 0.0, Q_ = 0.0;
  Mat3 RaT_, RbT_;
  Vec3 Wa_, Wb_, ka_, kb_;
};

// The support Hessian H(m) of a shape in the two tangent directions u, v: (u^T H u, u^T H v,
// v^T H v), given the support point p = support_point(m). Shapes with a closed form provide
// support_hessian_forms (ellipsoids and spheres: from p, without forming H); any other shape
// goes through support_hessian, the twin the shape tests compare with.
template <SupportShape S>
Vec3 support_hessian_forms(const S& s, const Vec3& m, const Vec3& p, const Vec3& u,
                           const Vec3& v) {
  if constexpr (requires { { s.support_hessian_forms(m, p, u, v) } -> std::convertible_to<Vec3>; }) {
    return s.support_hessian_forms(m, p, u, v);
  } else {
    const Mat3 H = s.support_hessian(m);
    const Vec3 Hu = H * u;
    return Vec3(u.dot(Hu), v.dot(Hu), v.dot(H * v));
  }
}

// A separating direction at time t without a distance solve. The gap along n,
// G(n) = n.c - h_A(R_A^T n) - h_B(-R_B^T n) (c the centre separation), has the gradient
// sep = x_B - x_A + c (x_A, x_B the support points of A along n and of B along -n); its maximum
// over unit n is the distance of separated bodies, and |sep| bounds it from above (the distance
// of two surface points), so G(n) <= d <= |sep|. G is concave on R^3 (a linear term minus two
// support functions), and on the unit sphere its Hessian is -(H_A + H_B) - G P, with H the
// lab-frame support Hessians (the principal radii of curvature at the support points) and P
// the tangential projection. Newton steps on the sphere, from `start` (or the line of centres;
// for rods the direction between their core segments, geometry/segment.hpp):
//     (H_A + H_B + max(G, l) P) delta = P sep,   n <- normalise(n + delta),
// delta tangent and at most 1/2 rad, halved until G increases (l: a small length that keeps
// the system definite where G < 0 or a radius of curvature vanishes). For elongated bodies the
// radii differ by (a/b)^2 between directions, which is why plain gradient ascent needs many
// steps there. Stops once the gap reaches `enough`, once |sep| - G <= max(tol, rel_tol G) (the
// gap is within that of the distance), for flat-faced pairs (a curvature radius unbounded) also
// once the Newton model's gain is below rel_tol G, or after `iterations` evaluations of G (each
// two support points). The search runs in A's body frame (two matrix-vector products per evaluation
// instead of four). The same Newton step, in the relative frame and run to convergence, is the
// distance solver's support stage (geometry/distance.hpp, support_maximum);
// returns the best axis and its gap in `gap`; `scale` scales both shapes (growth). Zero vector
// if the centres coincide.
// The search for bodies at rest in orientations rot_a, rot_b (body -> lab) with centre
// separation c_lab = r_B - r_A; separating_axis below places moving bodies at time tau and calls
// it, and a collision's distance solve starts from its support points (touching_guess).
// `at`, if given, receives the body-frame directions and support points of the returned axis
// (AxisSupport: AxisGap::value takes them for the gap at the search's time).
struct AxisSupport {
  Vec3 ma, mb;  // the axis in A's body frame, its opposite in B's
  Vec3 pa, pb;  // their support points (shapes at scale 1)
};
template <SupportShape SA, SupportShape SB>
Vec3 separating_axis_at(const SA& sa, const Quat& rot_a, const SB& sb, const Quat& rot_b,
                        const Vec3& c_lab, int iterations, double& gap, double enough = kInf,
                        double scale = 1.0, const Vec3* start = nullptr, double tol = 0.0,
                        double rel_tol = 0.0, AxisSupport* at = nullptr) {
  gap = -kInf;
  if (!(c_lab.squaredNorm() > 0.0)) return Vec3::Zero();
  // Everything in A's body frame: directions n there are A's support directions themselves,
  // B's are -Rab^T n (Rab = Ra^T Rb takes B's frame to A's), and the gradient is
  // sep = c + Rab x_B - x_A (c the centre separation in A's frame).
  const Quat rot_a_inv = rot_a.conjugate();
  const Mat3 Rab = (rot_a_inv * rot_b).toRotationMatrix();
  const Vec3 c = rot_a_inv * c_lab;
  const double l = 1e-3 * scale * std::min(sa.inscribed_radius(), sb.inscribed_radius());
  const bool flat = !AxisGap<SA, SB>::curved(sa, sb);
  // B's body-frame direction and the support points of the last accepted evaluation
  Vec3 mb, pa, pb;
  auto eval = [&](const Vec3& n, Vec3& sep, Vec3& ub, Vec3& qa, Vec3& qb) {
    ub = -(Rab.transpose() * n);
    qa = sa.support_point(n);
    qb = sb.support_point(ub);
    sep = c + scale * (Rab * qb - qa);
    return n.dot(sep);
  };
  Vec3 best;
  if (start && start->squaredNorm() > 0.0) {
    best = near_unit_normalized(Vec3(rot_a_inv * *start));  // a unit axis, turned: unit to rounding
  } else {
    best = c.normalized();
    // Rods (a body whose core segment is longer than its thickness, geometry/segment.hpp):
    // start from the direction between the closest points of the core segments instead of
    // the line of centres. It needs fewer Newton steps for long bodies (ellipsoids at
    // phi = 0.4: 3.0 gap evaluations per search instead of 4.5 at X0 = 10), not for short ones
    // (X0 = 2: the line of centres is as good and the segments cost more than they save).
    const CoreSegment ka = core_segment(sa.half_extents()), kb = core_segment(sb.half_extents());
    if (ka.rod() || kb.rod()) {
      const Vec3 u = Vec3::Unit(ka.axis), v = Rab.col(kb.axis);
      const SegmentPoints sp =
          closest_segment_points(Vec3::Zero(), u, scale * ka.half, c, v, scale * kb.half);
      const Vec3 dir = c + sp.t * v - sp.s * u;
      if (dir.squaredNorm() > 1e-6 * c.squaredNorm()) best = dir.normalized();
    }
  }
  Vec3 sep;
  gap = eval(best, sep, mb, pa, pb);
  int evals = 1;
  while (evals < iterations && gap < enough && sep.norm() - gap > std::max(tol, rel_tol * gap)) {
    // tangent basis (e1, e2) at n; the support Hessians in it, each body in its own frame
    const Vec3 e1 =
        (std::abs(best.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(best).normalized();
    const Vec3 e2 = best.cross(e1);
    const Vec3 b1 = Rab.transpose() * e1, b2 = Rab.transpose() * e2;
    const Vec3 fa = support_hessian_forms(sa, best, pa, e1, e2);
    const Vec3 fb = support_hessian_forms(sb, mb, pb, b1, b2);
    const double shift = std::max(gap, l);
    const double m11 = scale * (fa[0] + fb[0]) + shift;
    const double m12 = scale * (fa[1] + fb[1]);
    const double m22 = scale * (fa[2] + fb[2]) + shift;
    const double g1 = e1.dot(sep), g2 = e2.dot(sep);  // tangential gradient
    const double det = m11 * m22 - m12 * m12;
    double d1, d2;
    if (det > 0.0 && m11 > 0.0) {
      d1 = (m22 * g1 - m12 * g2) / det;
      d2 = (m11 * g2 - m12 * g1) / det;
    } else {  // not definite (rounding): a gradient step
      const double k = 1.0 / (shift + scale * (sa.bounding_radius() + sb.bounding_radius()));
      d1 = k * g1, d2 = k * g2;
    }
    // Flat-faced pairs: |sep| joins support points that slide far apart across facing faces, a
    // loose bound of the distance; stop also once the Newton model's own gain g.delta / 2 (the
    // rise of the quadratic model to its maximum) is within rel_tol of the gap.
    if (flat && gap > 0.0 && 0.5 * (g1 * d1 + g2 * d2) <= rel_tol * gap) break;
    Vec3 delta = d1 * e1 + d2 * e2;
    if (delta.norm() > 0.5) delta *= 0.5 / delta.norm();
    bool moved = false;
    while (evals < iterations) {
      const Vec3 n = (best + delta).normalized();
      Vec3 s, ub, qa, qb;
      const double g = eval(n, s, ub, qa, qb);
      ++evals;
      if (g > gap) {
        best = n, sep = s, gap = g, mb = ub, pa = qa, pb = qb;
        moved = true;
        break;
      }
      delta *= 0.5;
      if (delta.norm() <= 1e-14) break;
    }
    if (!moved) break;  // no increase along the Newton direction: G is at its maximum to rounding
  }
  if (at) *at = AxisSupport{best, mb, pa, pb};
  return rot_a * best;
}

// A test that needs no orientation streamed to `now` (the rigid prediction loop runs it before
// it streams a candidate's orientation and sets up a solver, system/rigid_bodies.hpp): can
// bodies A and B, of fixed shape, touch in [now, now + span]? A is at `now` (orientation qa,
// lab angular velocity wa); B's centre is streamed to `now` (separation c = r_B - r_A) but its
// orientation qb and angular velocity wb are the stored ones, `age` = now - t_B before;
// dv = v_B - v_A. Each body's rotation enters through SpinBound: a spherical top (wmax < 0)
// turns a fixed lab direction u in its frame at |m'| = |w x u| =: s with |m''| = |w| s; any
// other top at |m'| <= wmax, |m''| <= wmax^2 + dwmax (its largest angular speed and the bound
// of |dW/dt|, motion/motion.hpp; AxisGap above derives both).
//
// First order. A support value along u changes at most at l |m'| (the rate bound of AxisGap
// above, l the rotation lever; a body of revolution's at l |w x e| too, SpinBound::across), so
// with these turn rates T_A, T_B,
//     g_u(now) >= g1 := u.c - h_A(R_A^T u) - h_B(-R_B(t_B)^T u) - T_B age,
// and g_u falls at most at K_u = |u.dv| + T_A + T_B: g_u(now + tau) >= g1 - K_u tau.
//
// Second order (second_order = true, pairs whose curvature radii are bounded: ellipsoids,
// spheres). The support function's rate is exact at one instant: dh/dt = (w x p).u for the
// lab support point p (envelope theorem: h = max (R x).u, R' = [w]x R), and |d^2h/dt^2| <=
// M = rho |m'|^2 + L |m''| (rho the largest radius of curvature, L the bounding radius; AxisGap's
// curvature bound). Taylor's theorem for A from `now` and for B from t_B, whose orientation is
// the stored one:
//     g_u(now + tau) >= Q(tau) := u.c + u.dv tau - [h_A + r_A tau + M_A tau^2 / 2]
//                                 - [h_B(t_B) + r_B (age + tau) + M_B (age + tau)^2 / 2],
// r_A = (w_A x p_A).u at now, r_B = -(w_B x p_B).u at t_B. Q is a concave parabola in tau.
//
// Affine (second_order = true, pairs with an unbounded radius of curvature: superquadrics with
// an exponent > 2, whose flat faces leave Q without its M). AxisGap's affine bound (below),
// written for A from `now` and for B from t_B: with m' the exact rate of a body-frame direction
// at one instant (m_A = R_A^T u: m_A' = R_A^T (u x w_A); m_B = -R_B^T u: m_B' = R_B^T (w_B x u)),
// m(t + s) = m + s m' + r, |r| <= s^2 |m''|max / 2, and h sublinear (h(x + r) <= h(x) + L |r|),
//     g_u(now + tau) >= F(tau) := u.c + u.dv tau - h_A(m_A + tau m_A') - L_A mdd_A tau^2 / 2
//                                 - h_B(m_B + (age + tau) m_B') - L_B mdd_B (age + tau)^2 / 2,
// mdd the |m''| bounds of the second order. F is concave (a linear function less convex
// functions of affine arguments), so F > margin at tau = 0 and at tau = span holds it above
// the margin over the window, and otherwise the chord between them stays below F: its zero
// bounds the first zero of F from below. The end at tau = 0 is taken below F(0) without a
// support function, h_B(m_B + age m_B') <= h_B(m_B) + age L_B |m_B'| (a lower end point only
// lowers the chord), so the test costs one support function per body (of a non-unit
// direction) beyond the first order's.
//
// Both lines bound g_u over the whole window, so g_u stays positive where either does: the
// first-order line up to t1 = g1 / K_u, Q beyond it (a concave Q is above a level on [t1, span]
// if it is at both ends; F likewise on [0, span]). True means g_u, hence the distance, stays
// positive over the window: no contact there (the answer the contact-time solver would give;
// false: not decided). The margin 1e-10 (L_A + L_B) covers rounding. The first-order test
// along the line of centres alone rules out 42 % of the candidates that pass the bounding
// spheres in an ellipsoid fluid (phi = 0.5, X0 = 2, NNL, spherical tops); the second order
// along the pair's last axis (the memo) rules out half of those left for the solver at X0 = 10
// (phi = 0.4), where the turn of a long body spoils the first-order line; the affine bound
// answers 36.4 instead of 28.8 of 46 predictions a collision for superquadrics (2, 2, 8) at
// X0 = 0.5, phi = 0.256 (docs/benchmarks/README.md).
struct SpinBound {
  double wmax = -1.0;  // < 0: a spherical top (w constant); else the largest angular speed
  double dwmax = 0.0;  // a bound of |dW/dt| (not spherical tops)
  // A bound of |w x e| over the flight for a body of revolution about e (shapes/shape.hpp
  // revolution_axis; motion/motion.hpp spin_across_bound): the first-order turn rate T is
  // l min(|m'|, across). kInf: none.
  double across = kInf;
};
// SpinBound::across of a body of shape `sh` from its stored orientation, angular velocity and
// principal moments, wmax a bound of |w| (kInf unless a body of revolution whose spin across
// the axis is constant).
template <Shape S>
double spin_across_of(const S& sh, const Quat& q, const Vec3& w, const Vec3& top, double wmax) {
  const int k = revolution_axis(sh);
  return k < 0 ? kInf : spin_across_bound(q, w, top, k, wmax);
}
// Body A's rotation for a run of axis tests against many candidates (one prediction,
// system/rigid_bodies.hpp): its matrix, formed once; a direction then turns into A's frame and
// back by a matrix-vector product, half the arithmetic of a quaternion rotation. The tests take
// A's rotation as either (to_body, to_lab); rounding differs, not the bound.
struct RotationFrame {
  Mat3 R;
  explicit RotationFrame(const Quat& q) : R(q.toRotationMatrix()) {}
};
inline Vec3 to_body(const Quat& q, const Vec3& u) { return q.conjugate() * u; }
inline Vec3 to_lab(const Quat& q, const Vec3& p) { return q * p; }
inline Vec3 to_body(const RotationFrame& f, const Vec3& u) { return f.R.transpose() * u; }
inline Vec3 to_lab(const RotationFrame& f, const Vec3& p) { return f.R * p; }

// The next double above x >= 0 (finite): std::nextafter(x, kInf) without the library call.
inline double next_up(double x) {
  return std::bit_cast<double>(std::bit_cast<std::uint64_t>(x) + 1);
}

// axis_clear_time: how long the gap along u is proven positive, a duration tau_c >= 0 from `now`
// (kInf: for ever): g_u > margin on [now, now + tau_c) by the first-order line or, beyond its
// end t1, by Q. The line stays above the margin up to t1 = (g1 - margin) / K_u; Q is concave,
// so where Q(t1) > margin it stays above the margin up to its larger root r2 of Q = margin
// (and tau_c = r2; when Q is above the margin at a finite span too, Q covers [t1, span] and
// tau_c is a time just past span: the root is not formed), else tau_c = t1. Pairs without a
// bounded curvature take the affine F instead of Q (a finite span only): F > margin at both
// ends gives a time just past span (the window is covered; F says nothing beyond it), else the
// larger of t1 and the chord's zero. A first-order t1 beyond `span` (the caller's window) is
// returned as it is: the second order is not needed. clear_along_axis is tau_c > span. The
// prediction loop (system/rigid_bodies.hpp, predict_contacts) orders its candidates by tau_c.
template <SupportShape SA, SupportShape SB, class RA = Quat>
double axis_clear_time(const SA& sa, const RA& qa, const Vec3& wa, const SB& sb, const Quat& qb,
                       const Vec3& wb, const Vec3& c, const Vec3& u, const Vec3& dv, double age,
                       double span, SpinBound spin_a = {}, SpinBound spin_b = {},
                       bool second_order = false) {
  auto turn_speed = [&u](const Vec3& w, SpinBound spin) {  // a bound of |m'|
    return spin.wmax < 0.0 ? w.cross(u).norm() : spin.wmax;
  };
  const double sw_a = turn_speed(wa, spin_a), sw_b = turn_speed(wb, spin_b);
  // the first-order turn rates: a body of revolution's spin across its axis if smaller (the
  // curvature bounds below keep |m'| <= sw)
  const double turn_a = rotation_lever(sa) * std::min(sw_a, spin_a.across);
  const double turn_b = rotation_lever(sb) * std::min(sw_b, spin_b.across);
  const Vec3 ma = to_body(qa, u), mb = to_body(qb, Vec3(-u));
  const double ha = sa.support(ma), hb = sb.support(mb);
  const double g_old = u.dot(c) - ha - hb;  // B as it was at t_B
  const double g = g_old - turn_b * age;
  const double Ku = std::abs(u.dot(dv)) + turn_a + turn_b;
  const double margin = 1e-10 * (sa.bounding_radius() + sb.bounding_radius());
  // the first-order line stays above the margin up to t1
  const double t1 = !(g > margin) ? 0.0 : Ku > 0.0 ? (g - margin) / Ku : kInf;
  if (t1 > span) return t1;  // the window is covered: no second order needed
  // Turn rates 0 (spheres: rotation levers 0): the first-order line is as good; no second order.
  if (!second_order || !(turn_a + turn_b > 0.0)) return t1;
  auto turn_acceleration = [](const Vec3& w, SpinBound spin, double sw) {  // a bound of |m''|
    return spin.wmax < 0.0 ? w.norm() * sw : sw * sw + spin.dwmax;
  };
  if (!AxisGap<SA, SB>::curved(sa, sb)) {  // flat faces: the affine bound F
    if (!(span < kInf)) return t1;
    const double Qa = sa.bounding_radius() * turn_acceleration(wa, spin_a, sw_a);
    const double Qb = sb.bounding_radius() * turn_acceleration(wb, spin_b, sw_b);
    const Vec3 da = to_body(qa, u.cross(wa)), db = to_body(qb, wb.cross(u));  // m_A', m_B'
    const double uc = u.dot(c), udv = u.dot(dv);
    auto F = [&](double tau) {  // F - margin
      const double sb_tau = age + tau;
      return uc + udv * tau - sa.support(ma + tau * da) - sb.support(mb + sb_tau * db) -
             0.5 * (Qa * tau * tau + Qb * sb_tau * sb_tau) - margin;
    };
    // F(0) from below without a support function: h_B(m_B + age m_B') <= h_B(m_B) + age L_B
    // |m_B'| (sublinear); a lower end point only lowers the chord
    const double f0 = g_old - age * (sb.bounding_radius() * db.norm() + 0.5 * Qb * age) - margin;
    if (!(f0 > 0.0)) return t1;
    const double fs = F(span);
    if (fs > 0.0) return std::max(t1, next_up(span));  // span >= t1 >= 0, finite here
    return std::max(t1, span * (f0 / (f0 - fs)));
  }
  if constexpr (AxisGap<SA, SB>::kMayCurve) {
    const Vec3 pa = to_lab(qa, support_point_given(sa, ma, ha));
    const Vec3 pb = to_lab(qb, support_point_given(sb, mb, hb));
    const double ra = wa.cross(pa).dot(u), rb = -wb.cross(pb).dot(u);
    auto curvature = [&](const auto& shape, const Vec3& w, SpinBound spin, double sw) {
      return shape.max_curvature_radius() * sw * sw +
             shape.bounding_radius() * turn_acceleration(w, spin, sw);
    };
    const double Ma = curvature(sa, wa, spin_a, sw_a), Mb = curvature(sb, wb, spin_b, sw_b);
    const double q0 = g_old - age * (rb + 0.5 * Mb * age) - margin;  // Q - margin
    const double q1 = u.dot(dv) - ra - rb - Mb * age;
    const double q2 = 0.5 * (Ma + Mb);
    if (!(q0 + t1 * (q1 - q2 * t1) > 0.0)) return t1;  // Q(t1) <= margin: the line's t1
    // Q above the margin at both ends of [t1, span] (concave: over all of it) covers the window:
    // a time just past span, without the root (its square root and division; span >= t1 >= 0
    // here). Measured (e1, alternating runs): 0.99 of the time, the same trajectory.
    if (span < kInf && q0 + span * (q1 - q2 * span) > 0.0) return next_up(span);
    // Q - margin > 0 at t1: its larger root, written without cancellation
    if (!(q2 > 0.0)) return q1 < 0.0 ? std::max(t1, q0 / -q1) : kInf;
    const double s = std::sqrt(q1 * q1 + 4.0 * q2 * q0);
    return std::max(t1, q1 >= 0.0 ? (q1 + s) / (2.0 * q2) : 2.0 * q0 / (s - q1));
  }
  return t1;
}
template <SupportShape SA, SupportShape SB>
bool clear_along_axis(const SA& sa, const Quat& qa, const Vec3& wa, const SB& sb, const Quat& qb,
                      const Vec3& wb, const Vec3& c, const Vec3& u, const Vec3& dv, double age,
                      double span, SpinBound spin_a = {}, SpinBound spin_b = {},
                      bool second_order = false) {
  return span < kInf &&
         axis_clear_time(sa, qa, wa, sb, qb, wb, c, u, dv, age, span, spin_a, spin_b, second_order) >
             span;
}
template <SupportShape SA, SupportShape SB, class RA = Quat>
double centres_clear_time(const SA& sa, const RA& qa, const Vec3& wa, const SB& sb,
                          const Quat& qb, const Vec3& wb, const Vec3& c, const Vec3& dv,
                          double age, double span, SpinBound spin_a = {},
                          SpinBound spin_b = {}, bool second_order = false) {
  const double cn = c.norm();
  if (!(cn > 0.0)) return 0.0;
  return axis_clear_time(sa, qa, wa, sb, qb, wb, c, Vec3(c / cn), dv, age, span, spin_a, spin_b,
                         second_order);
}
template <SupportShape SA, SupportShape SB>
bool clear_along_centres(const SA& sa, const Quat& qa, const Vec3& wa, const SB& sb,
                         const Quat& qb, const Vec3& wb, const Vec3& c, const Vec3& dv,
                         double age, double span, SpinBound spin_a = {}, SpinBound spin_b = {},
                         bool second_order = false) {
  return span < kInf &&
         centres_clear_time(sa, qa, wa, sb, qb, wb, c, dv, age, span, spin_a, spin_b,
                            second_order) > span;
}

template <SupportShape SA, SupportShape SB>
Vec3 separating_axis(const SA& sa, const Motion& a, const SB& sb, const Motion& b, double tau,
                     int iterations, double& gap, double enough = kInf, double scale = 1.0,
                     const Vec3* start = nullptr, double tol = 0.0, double rel_tol = 0.0,
                     AxisSupport* at = nullptr) {
  const Vec3 c_lab = (b.initial().r - a.initial().r) + (b.initial().v - a.initial().v) * tau;
  // At tau = 0 (the usual first search: the window starts at the states' time) a spherical top
  // is at its initial orientation; no rotation increment to form.
  auto orientation = [tau](const Motion& m) {
    return tau == 0.0 && m.spherical() ? m.initial().q : m.orientation(tau);
  };
  return separating_axis_at(sa, orientation(a), sb, orientation(b), c_lab, iterations, gap, enough,
                            scale, start, tol, rel_tol, at);
}

}  // namespace hb
