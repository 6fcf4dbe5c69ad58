// Independent reference for the first contact time of two moving convex bodies with a closed-
// form support function (tests only; slow).  It uses the support-function reference distance
// (tests/geometry/reference_distance.hpp), not the Newton-Raphson solver under test.
//
// Conservative advancement: from t with distance d > 0 no contact is possible before t + d / K,
// K = |v_B - v_A| + |w_A| L_A + |w_B| L_B (rigorous).  Advance t by d / K while d > d_fine.
// Pure advancement converges only linearly (and not at all onto a tangential touch), so below
// d_fine the reference walks in fixed sub-steps h = d_fine / K: an interval [t0, t1] with
// d0 + d1 > K h cannot hold a contact (rigorous); otherwise, if the distance rate changes
// sign from - to + inside, a golden-section search finds the minimum of d (the interval is tiny,
// so d is unimodal there).  A negative value brackets the first contact, which is then
// bisected on the sign of the reference distance to 1e-14 relative in time.  The distance rate
// comes from the support points: d' = n.(u_B(x_B) - u_A(x_A)).
// Any tops (BodyState::top): the pose and angular velocity at t come from the exact free rotation
// (motion/motion.hpp; tested on its own against Euler's equations), |w| in K by its maximum.
#pragma once
#include <algorithm>
#include <cmath>

#include "geometry/posed.hpp"
#include "geometry/reference_distance.hpp"
#include "math/types.hpp"
#include "motion/free_flight.hpp"
#include "motion/motion.hpp"

namespace hb::ref {

struct RefContact {
  bool hit = false;
  double time = kInf;
  double min_distance = kInf;  // smallest distance seen
  long evals = 0;
};

template <SupportShape SA, SupportShape SB>
struct RefPair {
  const SA& a;
  const SB& b;
  BodyState sa, sb;  // at time 0
  Motion ma{sa}, mb{sb};
  Vec3 hint = Vec3::Zero();
  long evals = 0;

  // distance and its rate at time t
  std::pair<double, double> at(double t) {
    Quat qa, qb;
    Vec3 wa, wb;
    ma.pose(t, qa, wa);
    mb.pose(t, qb, wb);
    const Pose pa{sa.r + sa.v * t, qa.toRotationMatrix()};
    const Pose pb{sb.r + sb.v * t, qb.toRotationMatrix()};
    // with a hint from the previous (nearby) time, 8 extra starts suffice for the small
    // overlaps met here (bisection and golden search around a first contact)
    const bool h = hint.squaredNorm() > 0;
    const RefDistance r = reference_distance(a, pa, b, pb, h ? &hint : nullptr, h ? 8 : 48);
    ++evals;
    hint = r.n;
    const Vec3 ua = sa.v + wa.cross(r.point_a - pa.r);
    const Vec3 ub = sb.v + wb.cross(r.point_b - pb.r);
    return {r.distance, r.n.dot(ub - ua)};
  }
};

// First contact in [0, t_max] of bodies given at time 0. d_fine: see the header comment.
template <SupportShape SA, SupportShape SB>
RefContact reference_contact_time(const SA& a, const BodyState& sa, const SB& b,
                                  const BodyState& sb, double t_max, double d_fine) {
  RefPair<SA, SB> P{a, b, sa, sb};
  const double K = (sb.v - sa.v).norm() + P.ma.max_angular_speed() * a.bounding_radius() +
                   P.mb.max_angular_speed() * b.bounding_radius();
  RefContact out;
  auto finish_root = [&](double lo, double hi) {  // d(lo) > 0 > d(hi)
    while (hi - lo > 1e-14 * std::max(1.0, hi)) {
      const double m = 0.5 * (lo + hi);
      const double d = P.at(m).first;
      out.min_distance = std::min(out.min_distance, d);
      (d > 0 ? lo : hi) = m;
    }
    out.hit = true;
    out.time = lo;
  };
  double t = 0.0;
  auto [d, dd] = P.at(t);
  out.min_distance = d;
  if (d <= 0.0 && dd < 0.0) {
    out.hit = true;
    out.time = 0.0;
    out.evals = P.evals;
    return out;
  }
  if (K == 0.0) {
    out.evals = P.evals;
    return out;
  }
  const double h = d_fine / K;
  while (t < t_max) {
    const double t1 = std::min(t_max, t + std::max(d, d_fine) / K);
    auto [d1, dd1] = P.at(t1);
    out.min_distance = std::min(out.min_distance, d1);
    if (d1 <= 0.0 && d > 0.0) {
      finish_root(t, t1);
      break;
    }
    if (d > 0.0 && d1 > 0.0 && d + d1 <= K * (t1 - t) && dd < 0.0 && dd1 > 0.0) {
      // golden-section search for the minimum on [t, t1]
      const double g = 0.5 * (std::sqrt(5.0) - 1.0);
      double lo = t, hi = t1;
      double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
      double f1 = P.at(x1).first, f2 = P.at(x2).first;
      double neg_t = -1;
      for (int it = 0; it < 100 && hi - lo > 1e-12 * h; ++it) {
        if (f1 <= 0) { neg_t = x1; break; }
        if (f2 <= 0) { neg_t = x2; break; }
        if (f1 < f2) {
          hi = x2; x2 = x1; f2 = f1; x1 = hi - g * (hi - lo); f1 = P.at(x1).first;
        } else {
          lo = x1; x1 = x2; f1 = f2; x2 = lo + g * (hi - lo); f2 = P.at(x2).first;
        }
      }
      if (neg_t < 0 && std::min(f1, f2) <= 0) neg_t = f1 <= f2 ? x1 : x2;
      out.min_distance = std::min({out.min_distance, f1, f2});
      if (neg_t >= 0) {
        finish_root(t, neg_t);
        break;
      }
    }
    t = t1;
    d = d1;
    dd = dd1;
    (void)h;
  }
  out.evals = P.evals;
  return out;
}

// The time unit L / K of a pair: L the larger bounding radius, K = |v_B - v_A| + |w_A| L_A +
// |w_B| L_B with the states' angular velocities (the header's K, which for tops that are not
// spherical takes their largest |w|). Twin tests give contact-time differences in it.
template <SupportShape SA, SupportShape SB>
double time_unit(const SA& a, const SB& b, const BodyState& sa, const BodyState& sb) {
  const double K = (sb.v - sa.v).norm() + sa.w.norm() * a.bounding_radius() +
                   sb.w.norm() * b.bounding_radius();
  return std::max(a.bounding_radius(), b.bounding_radius()) / K;
}

}  // namespace hb::ref
