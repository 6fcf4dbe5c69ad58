// Exact second virial coefficient of (mixtures of) hard convex bodies, and the three Minkowski
// functionals of an ellipsoid it needs: a reference for the low-density equation of state,
// independent of the simulation engine (it uses only the Ellipsoid / Sphere structs).
//
// 1. Virial expansion.  For hard bodies the Mayer function of a pair is f_ij = -1 when the two
//    bodies overlap and 0 otherwise.  With number fractions x_i and number density rho,
//        Z = P / (rho kT) = 1 + B2 rho + O(rho^2),
//        B2 = -(1/2) sum_ij x_i x_j  < integral f_ij(r, w_i, w_j) d^3r >_{w_i, w_j}
//           =  (1/2) sum_ij x_i x_j  V_ex,ij,
//    where V_ex,ij is the volume of centre separations r at which j overlaps i, averaged
//    uniformly over both orientations w_i, w_j (isotropic fluid).  (B2 is the coefficient per
//    number density; the per-pair coefficients are B_ij = V_ex,ij / 2.)
//
// 2. Excluded volume of two convex bodies K, L.  At fixed orientations the overlapping
//    separations form the Minkowski sum K + (-L), whose volume expands in mixed volumes:
//        vol(K + L) = V(K) + 3 V(K,K,L) + 3 V(K,L,L) + V(L),
//        3 V(K,K,L) = integral_{S^2} h_L(u) dS_K(u),
//    h_L(u) = max_{x in L} u.x the support function of L and dS_K(u) the area measure of K (area
//    of K's surface whose outward normal lies in du; for a smooth body dS_K = R1 R2 dOmega, the
//    product of the principal radii of curvature).  Rotating L uniformly at random makes the
//    average of h_L(u) the same for every u: the mean of h over the unit sphere, which is half
//    the mean width, the "mean radius of curvature"
//        R = (1/4pi) integral_{S^2} h(u) dOmega = (1/4pi) integral_{dK} H dS,
//    (H = (k1 + k2)/2 the mean curvature; the two integrals are equal by Minkowski's formula).
//    Hence <3 V(K,K,L)> = R_L S_K, likewise <3 V(K,L,L)> = <integral h_K dS_L> = R_K S_L, and
//    -L has the same volume, area and mean width as L:
//        V_ex,ij = v_i + v_j + R_i S_j + R_j S_i            (Isihara, Kihara; Hadwiger).
//    Only the relative orientation matters, so averaging over one body's orientation suffices.
//    Checks: equal spheres give 2v + 2 r 4pi r^2 = 8v = (4pi/3)(2r)^3; spheres r1, r2 give
//    (4pi/3)(r1 + r2)^3; a sphere of radius r with any convex K gives, without any orientation
//    average, the Steiner formula of the parallel body v_K + r S_K + r^2 (4pi R_K) + (4pi/3) r^3.
//    One species: B2 = v + R S, B2 / v = 1 + R S / v.
//
// 3. Per packing fraction.  With phi = rho <v>, <v> = sum_i x_i v_i:
//        Z = 1 + B2* phi + O(phi^2),    B2* = B2 / <v>.
//    B2* = 4 for identical spheres; a mixture of unequal spheres has B2* < 4, because
//    (r_i + r_j)^3 <= 4 (r_i^3 + r_j^3).
//
// 4. Ellipsoid {x : x^2/a^2 + y^2/b^2 + z^2/c^2 <= 1}.  Support h(u) = sqrt(a^2 ux^2 + b^2 uy^2
//    + c^2 uz^2); the area of its shadow on the plane normal to u is pi a b c sqrt(ux^2/a^2 +
//    uy^2/b^2 + uz^2/c^2), and Cauchy's formula S = (1/pi) integral (shadow area) dOmega gives
//        R = <h>_{S^2}          = R_G(a^2, b^2, c^2),
//        S = 4pi abc <h'>_{S^2} = 4pi a b c R_G(a^-2, b^-2, c^-2),   h' the support of the
//    ellipsoid with semi-axes (1/a, 1/b, 1/c), and Carlson's symmetric integral
//        R_G(x,y,z) = (1/4pi) integral_{S^2} sqrt(x ux^2 + y uy^2 + z uz^2) dOmega   (DLMF 19.16.3)
//    evaluated as 2 R_G = z R_F - (x - z)(y - z) R_D / 3 + sqrt(x y / z) (DLMF 19.21.10) with z the
//    middle value, so all three terms are >= 0 (no cancellation), and R_F, R_D by Carlson's
//    duplication algorithm (Numer. Algorithms 10, 13 (1995)) to rounding error (~1e-16).
//    The same averages are also evaluated by quadrature (mean_support_quadrature: Gauss–Legendre
//    in cos(theta) times the trapezoid rule in the azimuth, which is spectrally accurate for the
//    periodic, analytic integrand; node counts doubled until two estimates agree to 1e-15), an
//    independent check of the closed forms.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "shapes/ellipsoid.hpp"

namespace hb::ref {

inline constexpr double kVirPi = 3.14159265358979323846;

// ---------------------------------------------------------------- Carlson symmetric integrals

// R_F(x,y,z) = (1/2) integral_0^inf dt / sqrt((t+x)(t+y)(t+z)); x,y,z >= 0, at most one zero.
inline double carlson_rf(double x, double y, double z) {
  if (!(x >= 0.0 && y >= 0.0 && z >= 0.0) || (x == 0.0) + (y == 0.0) + (z == 0.0) > 1)
    throw std::invalid_argument("carlson_rf: need x,y,z >= 0 with at most one zero");
  // Duplication: R_F(x,y,z) = R_F((x+l)/4, (y+l)/4, (z+l)/4), l = sqrt(xy)+sqrt(xz)+sqrt(yz);
  // the arguments contract to their mean A by 1/4 per step.  Stop when the relative spread is
  // below 1e-4: the truncation error of the 5th-order series below is then ~(1e-4)^6.
  double A = (x + y + z) / 3.0;
  for (int it = 0; it < 100; ++it) {
    const double dev = std::max({std::abs(A - x), std::abs(A - y), std::abs(A - z)});
    if (dev < 1e-4 * A) break;
    const double sx = std::sqrt(x), sy = std::sqrt(y), sz = std::sqrt(z);
    const double l = sx * sy + sx * sz + sy * sz;
    x = 0.25 * (x + l), y = 0.25 * (y + l), z = 0.25 * (z + l);
    A = (x + y + z) / 3.0;
  }
  const double X = (A - x) / A, Y = (A - y) / A, Z = -(X + Y);
  const double E2 = X * Y - Z * Z, E3 = X * Y * Z;
  return (1.0 - E2 / 10.0 + E3 / 14.0 + E2 * E2 / 24.0 - 3.0 * E2 * E3 / 44.0) / std::sqrt(A);
}

// R_D(x,y,z) = (3/2) integral_0^inf dt / ((t+z) sqrt((t+x)(t+y)(t+z))); x,y >= 0 (at most one
// zero), z > 0.
inline double carlson_rd(double x, double y, double z) {
  if (!(x >= 0.0 && y >= 0.0 && z > 0.0) || (x == 0.0 && y == 0.0))
    throw std::invalid_argument("carlson_rd: need x,y >= 0 (at most one zero), z > 0");
  // Duplication: R_D(x,y,z) = 3/(sqrt(z)(z+l)) + R_D((x+l)/4, (y+l)/4, (z+l)/4) / 4.
  double sum = 0.0, fac = 1.0;
  double A = (x + y + 3.0 * z) / 5.0;
  for (int it = 0; it < 100; ++it) {
    const double dev = std::max({std::abs(A - x), std::abs(A - y), std::abs(A - z)});
    if (dev < 1e-4 * A) break;
    const double sx = std::sqrt(x), sy = std::sqrt(y), sz = std::sqrt(z);
    const double l = sx * sy + sx * sz + sy * sz;
    sum += fac / (sz * (z + l));
    fac *= 0.25;
    x = 0.25 * (x + l), y = 0.25 * (y + l), z = 0.25 * (z + l);
    A = (x + y + 3.0 * z) / 5.0;
  }
  const double X = (A - x) / A, Y = (A - y) / A, Z = -(X + Y) / 3.0;
  const double XY = X * Y, Z2 = Z * Z;
  const double E2 = XY - 6.0 * Z2, E3 = (3.0 * XY - 8.0 * Z2) * Z, E4 = 3.0 * (XY - Z2) * Z2,
               E5 = XY * Z2 * Z;
  const double series = 1.0 - 3.0 * E2 / 14.0 + E3 / 6.0 + 9.0 * E2 * E2 / 88.0 - 3.0 * E4 / 22.0 -
                        9.0 * E2 * E3 / 52.0 + 3.0 * E5 / 26.0;
  return 3.0 * sum + fac * series / (A * std::sqrt(A));
}

// R_G(x,y,z) = (1/4pi) integral_{S^2} sqrt(x ux^2 + y uy^2 + z uz^2) dOmega; x,y,z >= 0.
inline double carlson_rg(double x, double y, double z) {
  if (!(x >= 0.0 && y >= 0.0 && z >= 0.0))
    throw std::invalid_argument("carlson_rg: need x,y,z >= 0");
  // Sort so that z is the middle value: then (x - z)(y - z) <= 0 and no term cancels.
  double v[3] = {x, y, z};
  std::sort(v, v + 3);
  const double lo = v[0], mid = v[1], hi = v[2];
  if (mid == 0.0) return 0.5 * std::sqrt(hi);  // R_G(0,0,z) = sqrt(z)/2
  return 0.5 * (mid * carlson_rf(lo, hi, mid) - (lo - mid) * (hi - mid) * carlson_rd(lo, hi, mid) / 3.0 +
                std::sqrt(lo * hi / mid));
}

// ---------------------------------------------------------------- ellipsoid functionals

inline void check_axes(double a, double b, double c, const char* who) {
  if (!(a > 0.0 && b > 0.0 && c > 0.0) || !std::isfinite(a) || !std::isfinite(b) ||
      !std::isfinite(c))
    throw std::invalid_argument(std::string(who) + ": semi-axes must be finite and > 0");
}

inline double ellipsoid_volume(double a, double b, double c) {
  check_axes(a, b, c, "ellipsoid_volume");
  return 4.0 / 3.0 * kVirPi * a * b * c;
}

// Mean radius of curvature R = half the mean width = average of the support function over unit
// normals = R_G(a^2, b^2, c^2).  Sphere: R = r.
inline double ellipsoid_mean_radius(double a, double b, double c) {
  check_axes(a, b, c, "ellipsoid_mean_radius");
  return carlson_rg(a * a, b * b, c * c);
}

// Surface area S = 4 pi a b c R_G(a^-2, b^-2, c^-2).  Sphere: 4 pi r^2.
inline double ellipsoid_surface_area(double a, double b, double c) {
  check_axes(a, b, c, "ellipsoid_surface_area");
  return 4.0 * kVirPi * a * b * c * carlson_rg(1.0 / (a * a), 1.0 / (b * b), 1.0 / (c * c));
}

// Gauss–Legendre nodes and weights on [-1, 1] (Newton on P_n from the asymptotic guess).
inline void gauss_legendre(int n, std::vector<double>& t, std::vector<double>& w) {
  t.assign(n, 0.0);
  w.assign(n, 0.0);
  for (int k = 0; k < (n + 1) / 2; ++k) {
    double x = std::cos(kVirPi * (k + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = x;  // P_0, P_1 -> P_{n-1}, P_n by the three-term recurrence
      for (int j = 2; j <= n; ++j) {
        const double p2 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p0) / j;
        p0 = p1, p1 = p2;
      }
      dp = n * (x * p1 - p0) / (x * x - 1.0);
      const double dx = p1 / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16) break;
    }
    // recompute P_n' at the converged root for the weight
    double p0 = 1.0, p1 = x;
    for (int j = 2; j <= n; ++j) {
      const double p2 = ((2.0 * j - 1.0) * x * p1 - (j - 1.0) * p0) / j;
      p0 = p1, p1 = p2;
    }
    dp = n * (x * p1 - p0) / (x * x - 1.0);
    t[k] = -x, t[n - 1 - k] = x;
    w[k] = w[n - 1 - k] = 2.0 / ((1.0 - x * x) * dp * dp);
  }
}

// <sqrt(p^2 ux^2 + q^2 uy^2 + s^2 uz^2)> over the unit sphere by quadrature (independent of the
// Carlson route): u = (sqrt(1-t^2) cos f, sqrt(1-t^2) sin f, t), dOmega = dt df; n-point
// Gauss–Legendre in t, n-point midpoint/trapezoid rule on f in [0, pi) (the integrand has period
// pi in f).  The largest axis is put on the pole (a prolate spheroid then has a constant
// azimuthal integrand).  n = 16, 32, ... until two estimates agree to rel_tol (or n = max_n);
// *nodes_used receives the final n.
inline double mean_support_quadrature(double p, double q, double s, double rel_tol = 1e-15,
                                      int max_n = 4096, int* nodes_used = nullptr) {
  check_axes(p, q, s, "mean_support_quadrature");
  double v[3] = {p, q, s};
  std::sort(v, v + 3);  // v[2] (largest) is the polar axis
  const double e0 = v[0] * v[0], e1 = v[1] * v[1], e2 = v[2] * v[2];
  std::vector<double> t, w;
  auto estimate = [&](int n) {
    gauss_legendre(n, t, w);
    std::vector<double> c2(n), s2(n);
    for (int j = 0; j < n; ++j) {
      const double f = kVirPi * (j + 0.5) / n;
      c2[j] = std::cos(f) * std::cos(f), s2[j] = std::sin(f) * std::sin(f);
    }
    double total = 0.0;
    for (int k = 0; k < n; ++k) {
      const double st2 = 1.0 - t[k] * t[k], pole = e2 * t[k] * t[k];
      double ring = 0.0;
      for (int j = 0; j < n; ++j) ring += std::sqrt(st2 * (e0 * c2[j] + e1 * s2[j]) + pole);
      total += w[k] * ring / n;
    }
    return 0.5 * total;  // (1/4pi) * integral dt * (2pi * azimuthal mean)
  };
  int n = 16;
  double prev = estimate(n);
  while (n < max_n) {
    n *= 2;
    const double cur = estimate(n);
    const bool done = std::abs(cur - prev) <= rel_tol * std::abs(cur);
    prev = cur;
    if (done) break;
  }
  if (nodes_used) *nodes_used = n;
  return prev;
}

inline double ellipsoid_mean_radius_quadrature(double a, double b, double c) {
  return mean_support_quadrature(a, b, c);
}

inline double ellipsoid_surface_area_quadrature(double a, double b, double c) {
  return 4.0 * kVirPi * a * b * c * mean_support_quadrature(1.0 / a, 1.0 / b, 1.0 / c);
}

// ---------------------------------------------------------------- bodies and mixtures

// The three functionals that fix the orientation-averaged excluded volume of a convex body.
struct ConvexBody {
  double volume = 0.0;
  double surface = 0.0;      // S
  double mean_radius = 0.0;  // R = mean width / 2
};

inline ConvexBody ellipsoid_body(double a, double b, double c) {
  return {ellipsoid_volume(a, b, c), ellipsoid_surface_area(a, b, c),
          ellipsoid_mean_radius(a, b, c)};
}

// Exact sphere values (identical to ellipsoid_body(r, r, r) up to rounding).
inline ConvexBody sphere_body(double r) {
  check_axes(r, r, r, "sphere_body");
  return {4.0 / 3.0 * kVirPi * r * r * r, 4.0 * kVirPi * r * r, r};
}

inline ConvexBody convex_body(const hb::Ellipsoid& e) { return ellipsoid_body(e.a, e.b, e.c); }
inline ConvexBody convex_body(const hb::Sphere& s) { return sphere_body(s.radius); }

// Orientation-averaged excluded volume V_ex = v_i + v_j + R_i S_j + R_j S_i (symmetric).
inline double excluded_volume(const ConvexBody& i, const ConvexBody& j) {
  return i.volume + j.volume + i.mean_radius * j.surface + j.mean_radius * i.surface;
}

// One component: B2 / v = 1 + R S / v (Z = 1 + (B2/v) phi).
inline double b2_star(const ConvexBody& k) { return 1.0 + k.mean_radius * k.surface / k.volume; }

struct Component {
  ConvexBody body;
  double amount = 1.0;  // number fraction, or a particle count (normalised by mixture_b2)
};

struct MixtureB2 {
  double b2 = 0.0;           // Z = 1 + b2 * rho (rho = total number density)
  double mean_volume = 0.0;  // <v> = sum x_i v_i
  double b2_star = 0.0;      // Z = 1 + b2_star * phi, phi = rho <v>
};

// B2 = (1/2) sum_ij x_i x_j V_ex,ij with x_i = amount_i / sum amount.
inline MixtureB2 mixture_b2(const std::vector<Component>& comps) {
  double total = 0.0;
  for (const auto& c : comps) {
    if (!(c.amount >= 0.0) || !std::isfinite(c.amount))
      throw std::invalid_argument("mixture_b2: amounts must be finite and >= 0");
    total += c.amount;
  }
  if (!(total > 0.0)) throw std::invalid_argument("mixture_b2: no particles");
  MixtureB2 out;
  for (const auto& ci : comps) {
    const double xi = ci.amount / total;
    out.mean_volume += xi * ci.body.volume;
    for (const auto& cj : comps)
      out.b2 += 0.5 * xi * (cj.amount / total) * excluded_volume(ci.body, cj.body);
  }
  out.b2_star = out.b2 / out.mean_volume;
  return out;
}

}  // namespace hb::ref
