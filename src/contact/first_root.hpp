// Conservative advancement: the rules of the engine's searches for the first time a moving body
// touches something, and the search `first_root` built on them.
//
// The rules (one place for all searches; each is derived where it is defined below):
//   lipschitz_step  from g >= 0 with |g'| <= K: no zero of g before t + max(g, eps) / K when
//                   g >= eps (the floor eps keeps steps near a root at least eps / K long);
//                   only the fall matters: with g' >= -D (D <= K) the step is max(g, eps) / D;
//   curvature_step  from g >= 0 with rate g' and |g''| <= M: no zero before the positive root
//                   of g + g' dt - M dt^2 / 2;
//   affine_step     from g >= 0 with rate g' and a concave lower bound B(s) of g(t + s): no
//                   zero before the trial point where B > 0, or before the chord's zero;
//   dip_possible    a step [t0, t1] with g > 0 at both ends can hide a zero only if the
//                   Lipschitz lower bound (g0 + g1 - K (t1 - t0)) / 2 is <= 0;
//   find_dip        such a step with g turning inside it (g'(t0) < 0 < g'(t1)) is searched for
//                   its minimum by Brent's minimiser, stopping at the first negative value.
// Their clients:
//   - first_root (below): a body's escape from its neighbour-list box (contact/escape_time.hpp),
//     its contact with a hard planar wall (locals/planar_walls.hpp, through the escape time) and
//     with a spherical container (locals/spherical_container.hpp);
//   - the pair contact time (contact/contact_time.hpp), whose loop steps with lipschitz_step,
//     dip_possible and find_dip but evaluates a warm-started distance solve (the rate comes
//     with it), leaps along separating axes and refines brackets by Newton on the contact
//     system;
//   - the separating-axis advancement (contact/contact_time.hpp, contact/axis_gap.hpp), which
//     steps with lipschitz_step and curvature_step along the gap of a fixed axis.
//
// first_root.
// Input: m component functions d_f(t) (a body's distances from the faces of a box, from a wall,
// ...), each positive while nothing happens and Lipschitz on the window with a known bound,
// |d_f'| <= K_f; the window [t_start, t_max] and the grazing step eps. The functions come as a
// type F with
//     static constexpr int kComponents;                               // m
//     void at(double t, std::array<double, m>& d, std::array<double, m>* dd) const;
//                                         // every d_f(t), and the rates d_f'(t) when dd != null
//     double component_at(int f, double t) const;                     // d_f(t) alone
//     double rate_bound(int f) const;                                 // K_f over the window
// and optionally
//     double approach_bound(int f) const;      // D_f >= -d_f' over the window (<= K_f; the
//                                              // fastest fall: a receding face's is small)
//     double curvature_bound(int f) const;     // M_f >= |d_f''| over the window (kInf: none)
//     bool has_affine_bound(int f) const;      // and, for components without M_f:
//     double affine_bound(int f, double t, double s) const;  // concave B_f(s) <= d_f(t + s),
//                                              // B_f(0) = d_f(t) (t: the last value's time)
//     double affine_curvature(int f) const;    // Q_f: B_f(s) <= d_f + d_f' s - Q_f s^2 / 2
//                                              // (where affine_step tries B first)
// Output: the first time in the window at which some d_f reaches 0 (the left end of a bracket a
// few ulps wide, so d_f >= 0 there), the component, and a status: found, none (no root in the
// window) or negative (some d_f < 0 at t_start: time = t_start, the most negative component).
//
// Algorithm (rigorous except for the grazing search of step 3):
//  1. From t with d_f > 0 no d_f can reach zero before t + d_f / K_f. Step
//     dt = min_f max(d_f, eps) / K_f (at least eps / K_f per step near a root, so the number of
//     steps is bounded by (t_max - t_start) max_f K_f / eps plus a logarithmic far part).
//     One-sided (F's approach_bound, unless FirstRootOptions::one_sided is false: the twin):
//     a zero needs d_f to fall, so the step is max(d_f, eps) / D_f with D_f >= -d_f' the
//     fastest fall (D_f = 0: d_f cannot fall, no zero of it in the window). A face the body
//     recedes from faster than its turn can bring it back then never limits the step; with
//     the symmetric K_f it took a geometric series of steps while it was near (a neighbour-list
//     box led ahead of its body starts with the rear face close; neighbors/obb_neighbors.hpp).
//     Such a step (d_f >= eps) is rigorous, so no dip is searched on it. Only components
//     without a curvature bound take it: the curvature step (below) follows a receding d_f
//     already, and D_f cost an ellipsoid's escape search 3 % more instructions for nothing.
//  2. A component with d_f <= 0 at the end of a step brackets a root on that step.
//  3. A component with d0 + d1 <= K_f dt (the only case in which the Lipschitz bound allows a
//     hidden dip below zero; both ends are then within eps) whose rate goes from - to + inside
//     the step is searched for its minimum by Brent's minimiser, stopping at the first negative
//     value, which brackets the root on [t0, t_min]. The step is shorter than eps / K_f, so d_f
//     is unimodal there in all but pathological cases. A dip it misses is at most
//     (d0 + d1 - K_f dt) / 2 >= -eps / 2 deep (Lipschitz): callers that must never pass a root
//     search for d_f - eps / 2 (a margin; escape_time.hpp, the walls).
//  Second order (components with a finite curvature bound M_f, unless
//  FirstRootOptions::second_order is false: the slow twin): the rates come with every value and
//  each component's step is the longer of the Lipschitz step and curvature_step(d_f, d_f', M_f),
//  which is rigorous (no zero before it). Far from a root the Lipschitz step dominates; near an
//  approaching face the curvature step follows the real rate instead of the worst-case K_f,
//  which is mostly rotation for long bodies, so the search takes a few steps instead of a
//  geometric series of them.
//  Affine steps (components without a curvature bound whose F gives a concave lower bound,
//  unless FirstRootOptions::affine_steps is false: the slow twin): the rates come with every
//  value, and the component with the shortest step takes the longer of its Lipschitz step and
//  affine_step on its bound, which is rigorous too; repeated until the shortest step is one
//  that took it (flat faces, whose support maps have no bounded curvature: a Newton step with
//  a quadratic correction near an approaching face instead of a geometric series).
//  4. Every bracket of the step is shrunk on the sign of d_f (Illinois + bisection) to a width
//     of a few ulps of t (or until d_f at its left end is at most FirstRootOptions::value_tol)
//     and its left end (d_f >= 0) is kept; the earliest component wins. The time returned is
//     therefore never later than the first root found.
//  The window's end (unless FirstRootOptions::skip_covered_end is false: the twin): a step
//  clipped at t_max is not evaluated there when every component is proven positive over all of
//  it, d_f > 0 at t and the step's remaining length h shorter than a rigorous step of d_f (its
//  curvature, affine or one-sided step, or its Lipschitz step from d_f >= eps; a component that
//  cannot fall counts as covered): then no d_f has a zero in [t, t_max], which is what the
//  values at t_max would show (their brackets and dip searches find nothing on such a step),
//  and the search answers none without them. Most searches of the neighbour lists end this way
//  (their window, not an escape, ends them). Measured (callgrind, instructions a collision, the
//  same trajectories; docs/benchmarks/README.md, "Session of 2026-12-07, seventh part"):
//  ellipsoids X0 = 2 at phi = 0.5, N = 256 (e1) -1.5 %, at N = 4096 -1.8 %; X0 = 10 and 0.1 at
//  phi = 0.4 -1.9 % and -1.1 %; superquadrics (2, 2, 2) and (2, 2, 8) -0.7 % and -0.2 %.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>

#include "math/brent.hpp"
#include "math/types.hpp"

namespace hb {

// From g with |g'| <= K: g(t + dt) >= g - K dt > 0 for dt < g / K. With the floor eps > 0 the
// step is max(g, eps) / K: when g < eps it may overshoot a zero, which the step's end value or
// the dip test below then catches. eps = 0: the rigorous step max(g, 0) / K.
inline double lipschitz_step(double g, double eps, double K) { return std::max(g, eps) / K; }

// From g >= 0 with rate g' = r and |g''| <= M (M >= 0): g(t + dt) >= g + r dt - M dt^2 / 2, whose
// positive root is dt = (r + q) / M with q = sqrt(r^2 + 2 M g), written without cancellation:
// 2 g / (q - r) when r <= 0 (equal, multiply by (q + r)), and (r + q) / M when r > 0 (M = 0 and
// r > 0: the bound never reaches zero, kInf).
inline double curvature_step(double g, double r, double M) {
  const double q = std::sqrt(std::max(r * r + 2.0 * M * g, 0.0));
  return r <= 0.0 ? 2.0 * g / (q - r) : (M > 0.0 ? (r + q) / M : kInf);
}

// From g >= 0 with rate r at t, and B(s) a concave lower bound of g(t + s) on [0, rest] with
// B(0) = g: a step with no zero of g before it. If B(trial) > 0 the trial is safe (B is concave
// and positive at both ends); otherwise the chord from (0, g) to (trial, B(trial)) reaches zero
// before B does (B lies above its chords), and that is the step. Any trial in (0, rest] is
// therefore rigorous; the trial only decides how long the step is. With Q > 0 such that
// B(s) <= g + r s - Q s^2 / 2 (F's affine_curvature), the trial is that parabola's positive root
// (curvature_step(g, r, Q)): B's own root is no later, and where B is near the parabola the
// chord lands near B's root. Without Q: where g's tangent reaches zero (a Newton step with a
// quadratic correction near a root approached at a finite rate), or, for a receding g, 16 dt1
// (dt1 the first-order step), whose chord is short when B falls fast beyond (measured in a
// fluid of (2, 2, 8) superquadrics: the parabola's root gave 4.3 steps an escape search
// against 5.0; docs/benchmarks/README.md). At most rest.
template <class B>
double affine_step(B&& bound, double g, double r, double rest, double dt1, double Q = 0.0) {
  double s = std::min(Q > 0.0 ? curvature_step(g, r, Q) : r < 0.0 ? g / -r : kInf, rest);
  if (!(s < kInf)) s = 16.0 * dt1;
  const double b = bound(s);
  if (b > 0.0) return s;
  return g > 0.0 ? s * (g / (g - b)) : 0.0;
}

// A step of length h with values g0, g1 > 0 at its ends can hide a zero only if the Lipschitz
// lower bound of g on it, (g0 + g1 - K h) / 2 (the two cones from the ends meet there), is <= 0.
inline bool dip_possible(double g0, double g1, double K, double h) { return g0 + g1 <= K * h; }

// The minimum of g on (t0, t1) from x0 by Brent's minimiser, stopping as soon as a value is
// negative (then x brackets a zero with t0; `stopped` is set). The step is shorter than the
// grazing step eps / K, so g is unimodal there in all but pathological cases; a dip missed
// is at most (g0 + g1 - K h) / 2 >= -eps / 2 deep, which callers that must never pass a zero
// cover with a margin of eps / 2.
template <class G>
BrentMin find_dip(G&& g, double t0, double t1, double x0, double xtol, int max_evals) {
  return brent_minimize(g, t0, t1, x0, xtol, max_evals, [](double v) { return v < 0.0; });
}

enum class RootStatus { found, none, negative };

struct FirstRootOptions {
  long max_steps = 50'000'000;  // guard; exceeding it stops the search (status none, time =
                                // the last safe time, `truncated` set)
  int brent_max_evals = 60;
  bool second_order = true;  // use curvature_bound where F has one (false: Lipschitz steps only)
  // Use F's affine_bound on the components without a curvature bound (false: Lipschitz steps
  // only there, the slow twin).
  bool affine_steps = true;
  // Lipschitz steps on F's approach_bound D_f, the fastest fall of d_f (false: on K_f, the
  // symmetric bound: the twin).
  bool one_sided = true;
  // A bracket stops shrinking once its left end's value is at most this (a length: the time
  // returned is then the root's up to value_tol / |d_f'| earlier, never later). 0: shrink to a
  // few ulps (contacts, where the root itself is the event). The neighbour-list escape uses a
  // fraction of its margin: rebuilding that little earlier is as valid and costs nothing.
  double value_tol = 0.0;
  // A last step that the components' rigorous steps cover to t_max ends the search (none)
  // without the values at t_max (see the header; false: they are evaluated, the twin).
  bool skip_covered_end = true;
};

struct FirstRoot {
  RootStatus status = RootStatus::none;
  double time = kInf;       // found/negative: the time; none: kInf (or last safe time if truncated)
  int component = -1;
  double value = kInf;      // d_f at `time` (>= 0 when found, < 0 when negative)
  long steps = 0;
  long bounds = 0;  // affine bounds evaluated
  long evaluations = 0;  // calls of F::at (every component at once)
  int grazing_searches = 0;
  bool truncated = false;
};

// d_start: the values at t_start when the caller has them already (else they are evaluated).
template <class F>
FirstRoot first_root(const F& fn, double t_start, double t_max, double eps_in,
                     const FirstRootOptions& o = {},
                     const std::array<double, F::kComponents>* d_start = nullptr) {
  constexpr int m = F::kComponents;
  FirstRoot out;
  std::array<double, m> K, d0, d1, dd0{}, dd1{};
  std::array<double, m> M;
  M.fill(kInf);
  std::array<double, m> safe{};  // per component: the rigorous step (curvature or affine) of this step
  std::array<bool, m> aff{};     // per component: affine steps
  double kmax = 0.0;
  for (int f = 0; f < m; ++f) kmax = std::max(kmax, K[f] = fn.rate_bound(f));
  bool curv = false;  // some component takes curvature steps
  if constexpr (requires { fn.curvature_bound(0); }) {
    for (int f = 0; f < m; ++f) {
      M[f] = o.second_order ? fn.curvature_bound(f) : kInf;
      curv = curv || std::isfinite(M[f]);
    }
  }
  // the fastest fall of each d_f (<= K_f), for the components without a curvature bound (the
  // curvature step already follows a receding d_f)
  std::array<double, m> D = K;
  if constexpr (requires { fn.approach_bound(0); }) {
    if (o.one_sided)
      for (int f = 0; f < m; ++f)
        if (!std::isfinite(M[f])) D[f] = std::min(K[f], fn.approach_bound(f));
  }
  bool affine = false;  // some component (without a curvature bound) takes affine steps
  if constexpr (requires { fn.affine_bound(0, 0.0, 0.0); }) {
    if (o.affine_steps)
      for (int f = 0; f < m; ++f) {
        aff[f] = !std::isfinite(M[f]) && fn.has_affine_bound(f);
        affine = affine || aff[f];
      }
  }
  const bool second = curv || affine;  // the rates come with every value
  double t = t_start;
  if (second) fn.at(t, d0, &dd0), ++out.evaluations;  // the same values as d_start, with the rates
  else if (d_start) d0 = *d_start;
  else fn.at(t, d0, nullptr), ++out.evaluations;
  {
    int fmin = 0;
    for (int f = 1; f < m; ++f)
      if (d0[f] < d0[fmin]) fmin = f;
    if (d0[fmin] < 0.0) {
      out.status = RootStatus::negative;
      out.time = t;
      out.component = fmin;
      out.value = d0[fmin];
      return out;
    }
  }
  if (kmax == 0.0 || !(t < t_max)) return out;  // at rest (or empty window): no root
  const double eps = std::max(eps_in, 1e-300);
  auto ttol = [](double x) { return 8.0 * 2.220446049250313e-16 * std::max(1.0, std::abs(x)); };

  while (t < t_max) {
    if (++out.steps > o.max_steps) {
      out.truncated = true;
      out.time = t;
      return out;
    }
    std::array<double, m> step;
    for (int f = 0; f < m; ++f) {
      safe[f] = 0.0;
      step[f] = kInf;
      if (!(K[f] > 0.0)) continue;
      if (!(D[f] > 0.0)) {  // d_f cannot fall: no zero of it in the window
        safe[f] = kInf;
        continue;
      }
      step[f] = lipschitz_step(d0[f], eps, D[f]);
      if (D[f] < K[f] && d0[f] >= eps) safe[f] = step[f];  // rigorous (no dip to search for)
      if (curv && std::isfinite(M[f])) {
        safe[f] = std::max(safe[f], curvature_step(d0[f], dd0[f], M[f]));
        step[f] = std::max(step[f], safe[f]);
      }
    }
    // Affine steps, only where they can lengthen the step: the component with the shortest
    // step takes its affine step, until the shortest one has taken it (at most m bounds).
    if constexpr (requires { fn.affine_bound(0, 0.0, 0.0); }) {
      std::array<bool, m> tried{};
      while (affine) {
        int g = 0;
        for (int f = 1; f < m; ++f)
          if (step[f] < step[g]) g = f;
        if (!aff[g] || tried[g] || !(step[g] < kInf)) break;
        tried[g] = true;
        ++out.bounds;
        double Q = 0.0;
        if constexpr (requires { fn.affine_curvature(0); }) Q = fn.affine_curvature(g);
        safe[g] = std::max(safe[g],
                           affine_step([&](double s) { return fn.affine_bound(g, t, s); }, d0[g],
                                       dd0[g], t_max - t, step[g], Q));
        step[g] = std::max(step[g], safe[g]);
      }
    }
    double dt = kInf;
    for (int f = 0; f < m; ++f) dt = std::min(dt, step[f]);
    const double t1 = std::min(t + dt, t_max);
    const double h = t1 - t;
    if (o.skip_covered_end && t1 == t_max) {
      // every component proven positive on [t, t_max]: no root in the window (see the header)
      bool covered = true;
      for (int f = 0; f < m && covered; ++f)
        covered = d0[f] > 0.0 && (!(K[f] > 0.0) || h < safe[f] || (d0[f] >= eps && h < step[f]));
      if (covered) return out;
    }
    fn.at(t1, d1, second ? &dd1 : nullptr);
    ++out.evaluations;
    // brackets [t, hi_f] of this step, per component
    double best_t = kInf;
    int best_f = -1;
    double best_d = 0.0;
    bool rates = second;  // both ends' rates known
    for (int f = 0; f < m; ++f) {
      double hi = kInf, dhi = 0.0;
      if (d1[f] <= 0.0) {  // (a step of exactly d / K can land on the root: d1 = 0)
        hi = t1, dhi = d1[f];
      } else if (!(h <= safe[f]) &&  // (no dip inside a rigorous curvature or affine step)
                 dip_possible(d0[f], d1[f], K[f], h)) {  // grazing search
        if (!rates) {
          fn.at(t, d0, &dd0);
          fn.at(t1, d1, &dd1);
          out.evaluations += 2;
          rates = true;
        }
        if (dd0[f] < 0.0 && dd1[f] > 0.0) {
          ++out.grazing_searches;
          auto g = [&](double x) { return fn.component_at(f, x); };
          const double x0 = t + h * d0[f] / (d0[f] + d1[f]);
          const double xs = (x0 > t && x0 < t1) ? x0 : 0.5 * (t + t1);
          const BrentMin mn = find_dip(g, t, t1, xs, ttol(t1), o.brent_max_evals);
          if (mn.fx < 0.0) hi = mn.x, dhi = mn.fx;
        }
      }
      if (hi == kInf || !(t < best_t)) continue;
      if (d0[f] == 0.0) {  // touching at the start of the step (only possible at t_start)
        best_t = t, best_f = f, best_d = 0.0;
        continue;
      }
      // shrink [t, hi] on the sign of d_f, keep the left end (d_f > 0)
      const RootBracket br = bracket_root([&](double x) { return fn.component_at(f, x); }, t,
                                          d0[f], hi, dhi, ttol(hi), 200, o.value_tol);
      if (br.lo < best_t) best_t = br.lo, best_f = f, best_d = br.flo;
    }
    if (best_f >= 0) {
      out.status = RootStatus::found;
      out.time = best_t;
      out.component = best_f;
      out.value = best_d;
      return out;
    }
    t = t1;
    d0 = d1;
    if (second) dd0 = dd1;
  }
  return out;
}

}  // namespace hb
