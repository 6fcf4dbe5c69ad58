// Brent's one-dimensional minimiser (golden-section search with parabolic interpolation) and a
// bracketed root finder (Illinois regula falsi with a bisection safeguard).  Header-only.
#pragma once
#include <cmath>
#include <utility>

namespace hb {

struct BrentMin {
  double x = 0.0, fx = 0.0;  // best point found and its value
  int evals = 0;
  bool stopped = false;       // the caller's stop predicate fired at x
};

// Minimise f on (a, b) starting from x0 in (a, b).  Terminates when the bracket around the
// best point is below 2 * (xtol + 2 eps |x|), after max_evals evaluations, or as soon as
// stop(fx) is true for an evaluated point (e.g. "the distance went negative").
template <class F, class Stop>
BrentMin brent_minimize(F&& f, double a, double b, double x0, double xtol, int max_evals,
                        Stop&& stop) {
  constexpr double cgold = 0.3819660112501051;  // (3 - sqrt 5) / 2
  constexpr double eps = 2.220446049250313e-16;
  BrentMin out;
  double x = x0, w = x0, v = x0;
  double fx = f(x);
  ++out.evals;
  if (stop(fx)) return BrentMin{x, fx, out.evals, true};
  double fw = fx, fv = fx;
  double d = 0.0, e = 0.0;
  while (out.evals < max_evals) {
    const double m = 0.5 * (a + b);
    const double tol1 = xtol + 2.0 * eps * std::abs(x), tol2 = 2.0 * tol1;
    if (std::abs(x - m) <= tol2 - 0.5 * (b - a)) break;
    bool golden = true;
    if (std::abs(e) > tol1) {  // parabola through (x, fx), (w, fw), (v, fv)
      const double r = (x - w) * (fx - fv);
      double q = (x - v) * (fx - fw);
      double p = (x - v) * q - (x - w) * r;
      q = 2.0 * (q - r);
      if (q > 0.0) p = -p; else q = -q;
      const double e_prev = e;
      e = d;
      if (std::abs(p) < std::abs(0.5 * q * e_prev) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < tol2 || b - u < tol2) d = (x < m) ? tol1 : -tol1;
        golden = false;
      }
    }
    if (golden) {
      e = (x < m) ? b - x : a - x;
      d = cgold * e;
    }
    const double u = std::abs(d) >= tol1 ? x + d : x + (d > 0 ? tol1 : -tol1);
    const double fu = f(u);
    ++out.evals;
    if (stop(fu)) return BrentMin{u, fu, out.evals, true};
    if (fu <= fx) {
      (u < x ? b : a) = x;
      v = w; fv = fw;
      w = x; fw = fx;
      x = u; fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w; fv = fw;
        w = u; fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u; fv = fu;
      }
    }
  }
  out.x = x;
  out.fx = fx;
  return out;
}

struct RootBracket {
  double lo, flo, hi, fhi;  // f(lo) and f(hi) of opposite signs; lo < hi
  int evals = 0;
};

// Shrink a sign-change bracket of f to width <= xtol: Illinois steps, with bisection whenever
// the bracket did not at least halve in two steps.  Keeps both ends (the caller chooses one).
// flo_tol > 0: stop also once |f(lo)| <= flo_tol (the left end is then close enough to the root
// for a caller that keeps it; 0: shrink to xtol).
template <class F>
RootBracket bracket_root(F&& f, double lo, double flo, double hi, double fhi, double xtol,
                         int max_evals, double flo_tol = 0.0) {
  RootBracket br{lo, flo, hi, fhi, 0};
  int side = 0;  // which end was kept last time (for the Illinois halving)
  double width_before = hi - lo;
  int since_check = 0;
  while (br.hi - br.lo > xtol && br.evals < max_evals &&
         !(flo_tol > 0.0 && std::abs(br.flo) <= flo_tol)) {
    double t = br.lo + (br.hi - br.lo) * br.flo / (br.flo - br.fhi);
    if (++since_check == 3) {  // bisection safeguard
      if (br.hi - br.lo > 0.5 * width_before) t = 0.5 * (br.lo + br.hi);
      width_before = br.hi - br.lo;
      since_check = 0;
    }
    if (!(t > br.lo && t < br.hi)) t = 0.5 * (br.lo + br.hi);
    const double ft = f(t);
    ++br.evals;
    if ((ft > 0) == (br.flo > 0)) {
      br.lo = t;
      br.flo = ft;
      if (side == -1) br.fhi *= 0.5;
      side = -1;
    } else {
      br.hi = t;
      br.fhi = ft;
      if (side == 1) br.flo *= 0.5;
      side = 1;
    }
    if (ft == 0.0) {
      br.lo = br.hi = t;
      br.flo = br.fhi = 0.0;
      break;
    }
  }
  return br;
}

}  // namespace hb
