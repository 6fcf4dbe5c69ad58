// Escape time of a freely moving convex body from a fixed oriented box (the NNL rebuild time,
// paper section 3.3 "Prediction of the collision time" of an ellipsoid with its parallelepiped).
//
// Input: a shape with a closed-form support function h, the body's state at t_state, the box,
// the window [t_start, t_max] and two lengths: `margin` (the box is shrunk by it on every face,
// the paper's trick, see below) and `eps` (the grazing step, the paper's epsilon_d^nnl).
// Output: the first time in the window at which the body touches the SHRUNKEN box, the face,
// and a status: escapes (time found), inside (no contact in the window) or outside (already
// through a face of the shrunken box at t_start: time = t_start).
//
// Per face f (outward unit normal n, plane n.x = c, faces as in geometry/obb.hpp) the signed
// distance of the body is closed form (DESIGN.md, geometry/plane.hpp):
//     d_f(t) = c - margin - n.r(t) - h(R(t)^T n),
// with r(t) = r + v (t - t_state) and R(t) = exp(skew(w) (t - t_state)) R (free_flight.hpp;
// for a top that is not spherical R(t) and w(t) of motion/motion.hpp, and |w x n| below bounded
// by max |w(t)|).
// Its rate: d/dt R^T n = -R^T (w x n), and grad h = p (the support point), so
//     d_f'(t) = -n.v + (R p).(w x n),   |d_f'| <= K_f = |n.v| + |w x n| l,
// l the shape's rotation lever (shapes/shape.hpp, rotation_lever: |p x m| <= l, and w x n is
// normal to n). This is the paper's Eq. distplover (which has the bounding radius L >= l),
// tightened by using only the part of w normal to the face and of p normal to n.
//
// Algorithm: the first root of the six d_f by conservative advancement (contact/first_root.hpp:
// Lipschitz steps max(d_f, eps) / K_f, a grazing search where a hidden dip is possible, brackets
// shrunk to a few ulps, the left end kept), so the time returned is never later than the first
// contact with the shrunken box. Shapes of bounded curvature also give |d_f''| <= M_f
// (curvature_bound), and the search then takes second-order steps where they are longer; flat
// faces of rigid bodies (no curvature bound) take steps on a concave lower bound instead
// (affine_bound), and their Lipschitz steps use the fastest fall D_f (approach_bound) instead
// of K_f: a face the body recedes from does not limit them.
// Growth: with scale s(t) = scale + scale_rate (t - t_state) the body is its shape scaled by s(t)
// about its centre (Lubachevsky–Stillinger starts against walls, locals/planar_walls.hpp):
// d_f(t) = c - margin - n.r(t) - s(t) h(R(t)^T n), d_f' gains -s' h and its rotational part the
// factor s(t), and K_f = |n.v| + |w x n| l s_max + |s'| L with s_max the larger scale of the window
// (a growing body needs a finite t_max).
// Shrunken box: the search runs against the box shrunk by `margin`. A dip that step 3 missed
// is at most (d0 + d1 - K_f dt) / 2 >= -eps / 2 deep (Lipschitz), so with margin >= eps / 2 the
// body is still inside the real box, and every returned time precedes the first contact with
// the real box by construction (d_real = d_f + margin > 0 up to it). Callers (the NNL) rebuild
// at the returned time; bodies are therefore never outside their real box.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include "contact/axis_gap.hpp"
#include "contact/first_root.hpp"
#include "geometry/obb.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/motion.hpp"
#include "shapes/shape.hpp"

namespace hb {

enum class EscapeStatus { escapes, inside, outside };

template <SupportShape S>
struct EscapeInput {
  const S& shape;
  BodyState body;         // at time t_state
  double t_state = 0.0;
  double t_start = 0.0;   // search window [t_start, t_max] (absolute times)
  double t_max = kInf;
  Obb box;
  double margin = 0.0;    // the box is shrunk by this on every face (>= eps / 2, see above)
  double eps = 1e-3;      // grazing step length (the paper's epsilon_d^nnl), << body size
  double scale = 1.0;     // growth: the body's scale at t_state and its rate (see above)
  double scale_rate = 0.0;
  // The turn bounds of a body of revolution from the spin across its axis (BoxDistance::sr;
  // false: from |w|, the slow twin).
  bool revolution = true;
};

using EscapeOptions = FirstRootOptions;  // max_steps exceeded: status inside, `truncated` set

struct EscapeResult {
  EscapeStatus status = EscapeStatus::inside;
  double time = kInf;        // escapes/outside: the time; inside: kInf (or last safe time if truncated)
  int face = -1;             // 0..5 (obb.hpp numbering)
  double distance = kInf;    // d_f at `time` (>= 0 for escapes, < 0 for outside)
  long steps = 0;
  long bounds = 0;  // affine bounds evaluated (flat faces)
  int grazing_searches = 0;
  bool truncated = false;
};

// The six closed-form face distances of a body in free flight (shrunken box), and their rates.
template <SupportShape S>
struct BoxDistance {
  static constexpr int kComponents = 6;  // the faces (contact/first_root.hpp)
  const S& shape;
  BodyState st;          // position relative to the box centre
  double t_state;
  Mat3 axes;
  Vec3 lim;              // half - margin
  double L;
  double lever;          // the shape's rotation lever (shapes/shape.hpp): |dh/dt| <= lever |m'|
  Motion motion;         // the rotation (any top; motion/motion.hpp)
  double s0 = 1.0, sdot = 0.0;  // growth: scale s(t) = s0 + sdot (t - t_state)
  double smax = 1.0;            // bound of s(t) over the search window
  Vec3 Q;                       // affine_bound's remainder coefficients L |m_k''|max per box axis
  // The turn bounds of each box axis in the body frame (turn_bounds, contact/axis_gap.hpp):
  // |m_k'| <= sw[k], |m_k''| <= mdd[k]. They are constant over the search, so the set-up of
  // first_root (six faces, three bounds each) reads them instead of forming one per face and
  // bound (3 square roots instead of 21; the same numbers).
  Vec3 sw, mdd;
  // The turn speed that moves the support value of face k: sw[k], or the spin across the axis
  // of a body of revolution if that is smaller (shapes/shape.hpp revolution_axis,
  // Motion::spin_across). The first-order bounds take it; the curvature keeps sw.
  Vec3 sr;
  // The body frame at the time of the last evaluation with rates (affine_bound's start):
  // column k of Rn is box axis k in the body frame, W the body-frame angular velocity.
  mutable double frame_tau = kInf;
  mutable Mat3 frame_Rn;
  mutable Vec3 frame_W;

  BoxDistance(const S& s, const BodyState& b, double ts, const Obb& box, double margin,
              double scale = 1.0, double scale_rate = 0.0, double t_end = kInf,
              bool revolution = true)
      : shape(s), st(b), t_state(ts), axes(box.axes), lim(box.half.array() - margin),
        L(s.bounding_radius()), lever(rotation_lever(s)), motion(b), s0(scale), sdot(scale_rate),
        smax(scale_rate > 0.0 ? scale + scale_rate * (t_end - ts) : scale) {
    st.r = b.r - box.centre;
    const double across = motion.spin_across(revolution ? revolution_axis(s) : -1);
    for (int k = 0; k < 3; ++k) {
      const TurnBounds tb = turn_bounds(motion, Vec3(axes.col(k)));
      sw[k] = tb.sw, mdd[k] = tb.mdd;
      sr[k] = std::min(tb.sw, across);
      Q[k] = L * mdd[k];
    }
  }
  double scale_at(double t) const { return sdot == 0.0 ? s0 : s0 + sdot * (t - t_state); }
  // d_f at t for every face; with rates when dd is non-null.
  void at(double t, std::array<double, 6>& d, std::array<double, 6>* dd = nullptr) const {
    const double tau = t - t_state;
    const Vec3 r = st.r + st.v * tau;
    Quat q;
    Vec3 w;
    motion.pose(tau, q, w);
    const Mat3 R = q.toRotationMatrix();
    const Vec3 x = axes.transpose() * r;        // centre along the box axes
    const Mat3 Rn = R.transpose() * axes;       // column k: box axis k in the body frame
    const double sc = scale_at(t);
    if (dd) frame_tau = tau, frame_Rn = Rn, frame_W = R.transpose() * w;
    for (int k = 0; k < 3; ++k) {
      const Vec3 nb = Rn.col(k);
      // A centrally symmetric shape has h(-n) = h(n) and p(-n) = -p(n) bit for bit: one
      // support value (and point) per box axis instead of two, the same numbers. (h is taken
      // from support(), not as n.p, so that the values with and without the rates stay equal
      // bit for bit: first_root compares them.) Other shapes: both directions (the twin,
      // tests/contact/test_escape_time.cpp).
      double hm, hp;
      Vec3 pm, pp;
      if constexpr (CentrallySymmetric<S>) {
        if constexpr (SupportIsPointDot<S>) {  // one support point gives both, the same bits
          if (dd) {
            const Vec3 pb = shape.support_point(nb);
            hp = hm = nb.dot(pb);
            pp = R * pb, pm = -pp;
          } else {
            hp = hm = shape.support(nb);
          }
        } else {
          hp = hm = shape.support(nb);
          if (dd) pp = R * shape.support_point(nb), pm = -pp;
        }
      } else {
        hm = shape.support(-nb), hp = shape.support(nb);
        if (dd) pm = R * shape.support_point(-nb), pp = R * shape.support_point(nb);
      }
      d[2 * k] = lim[k] + x[k] - sc * hm;
      d[2 * k + 1] = lim[k] - x[k] - sc * hp;
      if (dd) {
        const Vec3 u = axes.col(k);
        const Vec3 wxu = w.cross(u);
        const double vn = st.v.dot(u);
        (*dd)[2 * k] = vn - sc * pm.dot(wxu) - sdot * hm;
        (*dd)[2 * k + 1] = -vn + sc * pp.dot(wxu) - sdot * hp;
      }
    }
  }
  double face_at(int f, double t) const {
    const double tau = t - t_state;
    const int k = f >> 1;
    const Vec3 u = (f & 1) ? Vec3(axes.col(k)) : Vec3(-axes.col(k));
    const Vec3 r = st.r + st.v * tau;
    const Mat3 R = motion.rotation(tau);
    return lim[k] - u.dot(r) - scale_at(t) * shape.support(R.transpose() * u);
  }
  double face_rate(int f, double t) const {
    const double tau = t - t_state;
    const int k = f >> 1;
    const Vec3 u = (f & 1) ? Vec3(axes.col(k)) : Vec3(-axes.col(k));
    Quat q;
    Vec3 w;
    motion.pose(tau, q, w);
    const Mat3 R = q.toRotationMatrix();
    const Vec3 nb = R.transpose() * u;
    return -u.dot(st.v) + scale_at(t) * (R * shape.support_point(nb)).dot(w.cross(u)) -
           sdot * shape.support(nb);
  }
  double component_at(int f, double t) const { return face_at(f, t); }
  // |d_f''| <= M_f, for shapes of bounded curvature (kInf otherwise: Lipschitz steps, or for
  // rigid bodies the affine steps of affine_bound below).
  // With m(t) = R(t)^T u (u the face's axis) and h the support function of the shape at scale 1,
  // d_f = lim_k -+ x_k(t) - s(t) h(+-m(t)) and x_k'' = 0 (free flight), so
  //     |d_f''| <= 2 |s'| |dh/dt| + s |d^2 h/dt^2|,   |dh/dt| <= l |m'| (l the lever),
  //     |d^2 h/dt^2| <= rho |m'|^2 + L |m''|
  // (rho the largest principal radius of curvature bounds the support Hessian on tangent
  // vectors, |p| <= L), with |m'| = |w x u| and |m''| = |w| |w x u| for a spherical top (m turns
  // about a fixed body axis), |m'| <= max |w| and |m''| <= max |w|^2 + max |W'| otherwise: the
  // bounds of contact/axis_gap.hpp for one body.
  double curvature_bound(int f) const {
    if constexpr (requires { shape.max_curvature_radius(); }) {
      const double rho = shape.max_curvature_radius();
      if (!std::isfinite(rho) || !std::isfinite(smax)) return kInf;
      const int k = f >> 1;
      return 2.0 * std::abs(sdot) * lever * sw[k] + smax * (rho * sw[k] * sw[k] + L * mdd[k]);
    } else {
      return kInf;
    }
  }
  // Rigid bodies (no growth): a concave lower bound of d_f(t + s) for every s >= 0, as the
  // pair's (contact/axis_gap.hpp, AxisGap::affine_bound) for one body. With m(t) = R(t)^T u_k
  // and W the body-frame angular velocity, m' = m x W and m(t + s) = m + s m' + r(s),
  // |r| <= s^2 |m''|max / 2; support functions are sublinear and h(r) <= L |r|, so
  //     d_f(t + s) >= lim_k -+ x_k(t + s) - s0 [h(+-(m + s m')) + L |m''|max s^2 / 2] = B_f(s),
  // linear minus a convex function of an affine argument minus a parabola: concave, B_f(0) =
  // d_f(t). It needs no radius of curvature, so flat faces (superquadric exponents > 2) get
  // steps beyond first order (first_root's affine_step). One support function per bound.
  bool has_affine_bound(int) const { return sdot == 0.0; }  // (a scale s(t) breaks concavity)
  double affine_bound(int f, double t, double s) const {
    const double tau = t - t_state;
    if (tau != frame_tau) {
      Quat q;
      Vec3 w;
      motion.pose(tau, q, w);
      const Mat3 R = q.toRotationMatrix();
      frame_tau = tau, frame_Rn = R.transpose() * axes, frame_W = R.transpose() * w;
    }
    const int k = f >> 1;
    const Vec3 m = frame_Rn.col(k);
    const Vec3 mm = m + s * m.cross(frame_W);
    const double x = axes.col(k).dot(st.r + st.v * (tau + s));
    const double h = (f & 1) ? shape.support(mm) : shape.support(Vec3(-mm));
    return lim[k] + ((f & 1) ? -x : x) - s0 * (h + 0.5 * Q[k] * s * s);
  }
  // B_f(s) <= d_f + d_f' s - Q_f s^2 / 2 (first_root's trial for affine_step): h is convex, so
  // h(+-(m + s m')) >= h(+-m) + s p.(+-m') (p the support point, a subgradient), and the linear
  // part of that is the exact rate d_f' (the rates of at(), the same support point).
  double affine_curvature(int f) const { return s0 * Q[f >> 1]; }
  // The turn's part of |d_f'|: |w x u| lever s_max (a top that is not spherical: |w x u| <=
  // max |w(t)|; turn_bounds)
  double turn_rate_bound(int f) const { return sr[f >> 1] * lever * smax; }
  // |d_f'| <= K_f
  double rate_bound(int f) const {
    return std::abs(st.v.dot(axes.col(f >> 1))) + turn_rate_bound(f) + std::abs(sdot) * L;
  }
  // -d_f' <= D_f, the fastest fall: d_f' is the translation's -+u.v (constant in free flight)
  // plus the turn's and the growth's parts, each bounded as in K_f, so D_f = max(0, +-u.v +
  // turn + growth) (face 2k: lim + x_k - ..., falls as the centre moves along -u; 2k + 1 along
  // +u). A face the centre recedes from faster than the turn can bring it back has D_f = 0.
  double approach_bound(int f) const {
    const double vn = st.v.dot(axes.col(f >> 1));
    return std::max(0.0, ((f & 1) ? vn : -vn) + turn_rate_bound(f) + std::abs(sdot) * L);
  }
};

template <SupportShape S>
EscapeResult escape_time(const EscapeInput<S>& in, const EscapeOptions& o = {}) {
  const BoxDistance<S> D(in.shape, in.body, in.t_state, in.box, in.margin, in.scale,
                         in.scale_rate, in.t_max, in.revolution);
  const FirstRoot r = first_root(D, in.t_start, in.t_max, in.eps, o);
  EscapeResult out;
  out.status = r.status == RootStatus::found  ? EscapeStatus::escapes
               : r.status == RootStatus::none ? EscapeStatus::inside
                                              : EscapeStatus::outside;
  out.time = r.time;
  out.face = r.component;
  out.distance = r.value;
  out.steps = r.steps;
  out.bounds = r.bounds;
  out.grazing_searches = r.grazing_searches;
  out.truncated = r.truncated;
  return out;
}

}  // namespace hb
