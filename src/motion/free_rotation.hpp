// Exact free rotation of a rigid body (torque-free Euler top), in closed form: O(1) in t.
//
// Input: principal moments I = (I1, I2, I3) > 0 along the body x, y, z axes, the orientation q0
// (body -> lab) and the angular velocity w0 (lab frame) at t = 0.  Output at any real t (also
// negative, and far away: the phase is reduced by whole periods): q(t) and w(t).
//
// Three cases, chosen on exact equality of the moments and of components to zero:
//
// 1. Spin: spherical top (I1 = I2 = I3), w0 = 0, or w0 exactly along a principal axis (two body
//    components exactly zero).  w is constant in the lab and q(t) = rot(|w0| t about w0) q0,
//    computed by rotation_increment below (as motion/free_flight.hpp streams spherical tops).
//
// 2. Symmetric top (two equal moments I_t, symmetry axis e_s with moment I_s, on any body axis).
//    With L = I_lab w (constant) and Omega_s = e_s . Omega (constant),
//        R(t) = rot(L t / I_t) R0 rot(nu t e_s),   nu = (I_t - I_s) Omega_s / I_t,
//    since then w = L/I_t + nu R e_s, i.e. Omega = L_body/I_t + nu e_s = I^-1 L_body.  The body
//    angular velocity precesses about e_s at the rate (I_s - I_t) Omega_s / I_t, the body about
//    L at the rate |L| / I_t.
//
// 3. Asymmetric top (all moments different): Landau & Lifshitz, Mechanics, section 37; the
//    orientation in the spirit of van Zon & Schofield, J. Comput. Phys. 225, 145 (2007), with a
//    different (non-singular) choice of the reference rotation, derived here.
//
//    Relabelling.  With 2E = sum I_i W_i^2, L^2 = sum I_i^2 W_i^2 (W: body angular velocity) and
//    I_lo < I_mid < I_hi,
//        D = L^2 - 2E I_mid = I_hi (I_hi - I_mid) W_hi^2 - I_lo (I_mid - I_lo) W_lo^2
//    decides around which axis L circulates in the body: I_hi if D >= 0, I_lo if D < 0.  A proper
//    signed permutation S (body' -> body) makes body' axis 3 that one, axis 2 the intermediate
//    one and axis 1 the remaining one, with moments J1, J2, J3, and W'3 > 0, W'1 >= 0 at t = 0
//    (rotations by pi about a body' axis keep the inertia tensor diagonal).  Then, with the
//    absolute differences d21 = |J2-J1|, d31 = |J3-J1|, d32 = |J3-J2|, every quantity below is
//    a sum of positive terms except D (computed once, in long double):
//        p3 = |2E J3 - L^2| = J1 d31 W1^2 + J2 d32 W2^2,
//        p1 = |L^2 - 2E J1| = J2 d21 W2^2 + J3 d31 W3^2,
//        A^2 = p3/(J1 d31),  B^2 = p3/(J2 d32),  C^2 = p1/(J3 d31),  omega^2 = d32 p1/(J1 J2 J3),
//        m = k^2 = d21 p3/(d32 p1),   m1 = 1 - m = d31 |D|/(d32 p1),
//        W'(t) = (A cn tau, B sn tau, C dn tau),  tau = tau0 + sigma omega t,
//    sigma = sign(J3 - J1) (= -1 when L circulates around the smallest moment; checking Euler's
//    equations J1 dW1/dt = (J2-J3) W2 W3 etc. term by term fixes the sign).  The initial phase
//    is tau0 = F(phi0 | m) with cn = cos phi0 >= 0, sn = sin phi0, phi0 = atan2(W2/B, W1/A);
//    |tau0| <= K.
//
//    Orientation.  Let l(t) = J W'(t) / |L| (unit L in body'), so q'(t) l(t) = L_hat (q' = q s:
//    body' -> lab).  Let M(l) be the minimal rotation taking l to e_z, quaternion
//    (1 + l_z, l_y, -l_x, 0) / sqrt(2 (1 + l_z)); it is regular since l_z = J3 C dn / |L| > 0.
//    Every rotation taking l to e_z is Rz(psi) M(l), so q'(t) = G Rz(psi(t)) M(l(t)) with one
//    constant rotation G taking e_z to L_hat: G = q0 s M(l(0))^-1 and psi(0) = 0.  The z
//    component of the angular velocity of the rotation Rz(psi) M(l) (target frame) equals the
//    component of w along L, 2E/|L|; that of M(l) is (l_x dl_y/dt - l_y dl_x/dt)/(1 + l_z), and
//    with dl/dt = l x W (Euler) this is (l_z 2E/|L| - W3)/(1 + l_z).  Hence
//        dpsi/dt = (2E + |L| W3)/(|L| + J3 W3)
//                = |L|/J3 + (J3-J1) |L| / (J1 J3 (1 + n sn^2)) - (J3-J1) C dn / (J1 (1 + n sn^2)),
//    n = J3 d21/(J1 d32) > 0, using L^2 - J3^2 W3^2 = (2E J3 - L^2) J1 (1 + n sn^2)/(J3 - J1).
//    With dt = dtau/(sigma omega) and phi = am tau:
//        int dtau/(1 + n sn^2) = Pi(-n; phi | m)  (third kind, characteristic -n: no pole),
//        int dn dtau/(1 + n sn^2) = int dphi/(1 + n sin^2 phi) = atan(c tan phi)/c,  c = sqrt(1+n).
//    Writing Pi(-n; phi) = F(phi) - (n/3) sin^3 phi R_J(cos^2 phi, dn^2, 1, 1 + n sin^2 phi)
//    (Carlson) and F(am tau) = tau, the F part adds up with |L|/J3 to a linear term:
//        psi(t) = |L| t / J1 - kappa [sn^3 R_J(cn^2, dn^2, 1, 1 + n sn^2)]_tau0^tau
//                             - (c2/c) [atan2(c sn, cn)]_tau0^tau,
//        kappa = d31 d21 |L| / (3 J1^2 d32 omega),   c2 = d31 C / (J1 omega),
//    where tau = tau_r + 2K j with |tau_r| <= K, the bracket terms are evaluated at tau_r (so
//    phi_r is in [-pi/2, pi/2]) and each half period adds 2 R_J(0, m1, 1, 1 + n) and pi to the
//    two brackets.  Symmetric limit (m, n -> 0): psi = (|L| - (J3 - J1) W3) t / J1.
//    Separatrix m1 = 0 (K infinite): sn = tanh, cn = dn = sech, Pi(-n; gd tau | 1) =
//    (tau + sqrt(n) atan(sqrt(n) tanh tau))/(1 + n), and atan(c tan phi) = atan(c sinh tau).
//
//    Jacobi functions, all with relative accuracy: u is reduced to |u| <= K; for |u| > K/2 the
//    values at K - |u| give them (sn(K - w) = cn w/dn w, cn(K - w) = k' sn w/dn w,
//    dn(K - w) = k'/dn w), since cos(am) near pi/2 would only be absolutely accurate.  For
//    |u| <= K/2: descending Landen transformation (AGM, Abramowitz & Stegun 16.4; the sequence
//    is stored at make()) or, for m1 < 1e-4, where its rounding errors grow ~1/k', the ascending
//    one (A&S 16.14) down to a parameter so close to 1 that the first-order expansion in
//    tanh/sech (A&S 16.15) is exact to rounding.  This matters close to the unstable spin about
//    the intermediate axis, where cn, dn ~ k' and psi depends on them logarithmically.
//    Carlson's duplication algorithms for R_F, R_J, R_C (B. C. Carlson, Numer. Algorithms 10,
//    13 (1995)).
//
//    Bound on |w|: |W'|^2 = A^2 cn^2 + B^2 sn^2 + C^2 dn^2 = A^2 + C^2 + (B^2 - A^2 - m C^2) sn^2
//    is linear in sn^2, which takes all values in [0, 1]:
//        max |w| = max(A^2 + C^2, B^2 + m1 C^2)^(1/2),
//    attained where sn = 0 or sn = +-1 (supremum, approached but not attained, at m1 = 0).
//    max_angular_speed() returns it times (1 + 1e-14) so that it also bounds the rounded
//    |angular_velocity(t)|.  For the spin and symmetric cases |w| is constant (|w0|, with the
//    same margin for the symmetric top).
//
// Accuracy: the phase is tau0 + omega t, so errors grow like 1e-16 (|omega| t): ~1e-11 after
// 1e4 periods.  Near the separatrix the motion itself is ill-conditioned in the data: the period
// depends on m1 = O(D), and a relative change of the data by e changes m1 by ~e |terms of D|/m1.
// make() computes the body angular velocity and D in long double (where long double is wider
// than double), so that this is ~1e-19 |terms|/m1 rather than ~1e-16 |terms|/m1: the result is
// the exact motion for data perturbed by ~1e-16 relative (rounding of the rest in double), but
// its difference from the exact motion of the given data grows like t / m1.  E.g. m1 = 2e-7:
// 1e-11 from a long double reference after 100 periods, 6e-10 after 1e4 (the reference has the
// same limitation).
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "math/sin_cos.hpp"
#include "math/types.hpp"

namespace hb {

// Quaternion of the rotation by the angle |w| dt about w (exact, no series truncation).
inline Quat rotation_increment(const Vec3& w, double dt) {
  // The half angle x = |w| dt / 2 enters only through x^2 and sin(x) / x for the usual small
  // angles (|x| <= kSinCosPolyMax): q = (cos x, (dt / 2) (sin(x) / x) w), with no square root and
  // no division (math/sin_cos.hpp, sinc_cos_of_square). w = 0 or dt = 0 give the identity
  // exactly. Larger angles: sin and cos of x itself, sin(x) / |w| the axis factor.
  const double z = 0.25 * w.squaredNorm() * dt * dt;
  if (z <= kSinCosPolyMax * kSinCosPolyMax) {
    const SinCos sc = sinc_cos_of_square(z);
    const double s = 0.5 * dt * sc.s;
    return Quat(sc.c, s * w.x(), s * w.y(), s * w.z());
  }
  const double wn = w.norm();
  const SinCos sc = sin_cos(0.5 * wn * dt);
  const double s = sc.s / wn;
  return Quat(sc.c, s * w.x(), s * w.y(), s * w.z());
}

// Scale q back onto the unit sphere (near_unit_normalized, math/types.hpp: a product of unit
// quaternions is unit to a few ulp, where one Newton step is exact to rounding).
inline void renormalize(Quat& q) { q.coeffs() = near_unit_normalized(Eigen::Vector4d(q.coeffs())); }

// q0 turned by the constant angular velocity w (lab frame) for a time dt: a spherical top's
// orientation (motion/free_flight.hpp, orientation_at) and FreeRotation's exact spins.
[[gnu::always_inline]] inline Quat spun(const Vec3& w, double dt, const Quat& q0) {
  Quat q = rotation_increment(w, dt) * q0;
  renormalize(q);  // keeps |q| = 1 to rounding; the rotation matrix stays orthonormal
  return q;
}

namespace elliptic {

// R_C(1, 1 + e) for e > -1 (Carlson's degenerate integral): atan(sqrt(e))/sqrt(e) for e > 0.
template <class T>
T carlson_rc1(T e) {
  using std::abs;
  using std::sqrt;
  if (abs(e) < T(1e-3)) {
    // 1 - e/3 + e^2/5 - e^3/7 + ... (error < e^8/17), Horner form
    T s = 0;
    for (int k = 7; k >= 0; --k) s = (k % 2 ? T(-1) : T(1)) / T(2 * k + 1) + e * s;
    return s;
  }
  if (e > 0) {
    const T s = sqrt(e);
    return std::atan(s) / s;
  }
  const T s = sqrt(-e);
  return std::atanh(s) / s;
}

// Carlson's R_F(x, y, z), x, y, z >= 0, at most one zero.
template <class T>
T carlson_rf(T x, T y, T z) {
  using std::abs;
  using std::sqrt;
  const T r = std::numeric_limits<T>::epsilon();
  const T a0 = (x + y + z) / 3;
  const T q = std::pow(3 * r, T(-1) / 6) * std::max({abs(a0 - x), abs(a0 - y), abs(a0 - z)});
  T a = a0, f = 1;  // f = 4^-m
  const T x0 = x, y0 = y;
  for (int it = 0; it < 100 && q * f >= abs(a); ++it) {
    const T sx = sqrt(x), sy = sqrt(y), sz = sqrt(z);
    const T lam = sx * sy + sy * sz + sz * sx;
    x = (x + lam) / 4;
    y = (y + lam) / 4;
    z = (z + lam) / 4;
    a = (a + lam) / 4;
    f /= 4;
  }
  const T X = (a0 - x0) * f / a, Y = (a0 - y0) * f / a, Z = -X - Y;
  const T e2 = X * Y - Z * Z, e3 = X * Y * Z;
  return (T(1) - e2 / 10 + e3 / 14 + e2 * e2 / 24 - T(3) * e2 * e3 / 44) / sqrt(a);
}

// Carlson's R_J(x, y, z, p), x, y, z >= 0 (at most one zero), p > 0.
template <class T>
T carlson_rj(T x, T y, T z, T p) {
  using std::abs;
  using std::sqrt;
  const T r = std::numeric_limits<T>::epsilon();
  const T a0 = (x + y + z + 2 * p) / 5;
  const T delta = (p - x) * (p - y) * (p - z);
  const T q =
      std::pow(r / 4, T(-1) / 6) * std::max({abs(a0 - x), abs(a0 - y), abs(a0 - z), abs(a0 - p)});
  T a = a0, f = 1, f3 = 1, sum = 0;  // f = 4^-m, f3 = 4^-3m
  const T x0 = x, y0 = y, z0 = z;
  for (int it = 0; it < 100 && q * f >= abs(a); ++it) {
    const T sx = sqrt(x), sy = sqrt(y), sz = sqrt(z), sp = sqrt(p);
    const T lam = sx * sy + sy * sz + sz * sx;
    const T d = (sp + sx) * (sp + sy) * (sp + sz);
    const T e = f3 * delta / (d * d);
    sum += f * carlson_rc1(e) / d;
    x = (x + lam) / 4;
    y = (y + lam) / 4;
    z = (z + lam) / 4;
    p = (p + lam) / 4;
    a = (a + lam) / 4;
    f /= 4;
    f3 /= 64;
  }
  const T X = (a0 - x0) * f / a, Y = (a0 - y0) * f / a, Z = (a0 - z0) * f / a;
  const T P = -(X + Y + Z) / 2;
  const T e2 = X * Y + X * Z + Y * Z - 3 * P * P;
  const T e3 = X * Y * Z + 2 * e2 * P + 4 * P * P * P;
  const T e4 = (2 * X * Y * Z + e2 * P + 3 * P * P * P) * P;
  const T e5 = X * Y * Z * P * P;
  const T s = T(1) - T(3) * e2 / 14 + e3 / 6 + T(9) * e2 * e2 / 88 - T(3) * e4 / 22 -
              T(9) * e2 * e3 / 52 + T(3) * e5 / 26;
  return f * s / (a * sqrt(a)) + 6 * sum;
}

struct JacobiValues {
  double sn = 0, cn = 1, dn = 1, am = 0;
};

// Jacobi elliptic functions of parameter m = k^2 (0 <= m <= 1).  make() takes m and m1 = 1 - m
// separately so that m1 keeps its relative accuracy near the separatrix (m -> 1).
struct Jacobi {
  // Stored descending steps (used for m1 >= kAscendingBelow, which needs at most 6).
  static constexpr int kMaxSteps = 8;

  double m = 0, m1 = 1;
  double kprime = 1;                      // k' = sqrt(m1)
  double K = 0.5 * kPi;                   // quarter period; +inf when m1 == 0
  int steps = 0;                          // AGM steps N
  double scale = 1;                       // 2^N a_N
  std::array<double, kMaxSteps> ratio{};  // c_n / a_n, n = 1..N
  // Ascending Landen transformation (m1 < kAscendingBelow): levels, s_n = sqrt(mu1_n), mu_n,
  // the last complement mu1 and 1 / prod(1 + s_n).
  static constexpr double kAscendingBelow = 1e-4;
  static constexpr int kMaxAscending = 4;
  int ascending = 0;
  std::array<double, kMaxAscending> asc_s{}, asc_mu{};
  double asc_mu1 = 0, asc_scale = 1;

  static Jacobi make(double m, double m1) {
    Jacobi j;
    j.m = m;
    j.m1 = m1;
    if (m1 <= 0.0) {
      j.m = 1.0;
      j.m1 = 0.0;
      j.kprime = 0.0;
      j.K = kInf;
      return j;
    }
    j.kprime = std::sqrt(m1);
    const bool descending = m1 >= kAscendingBelow;
    double a = 1.0, b = std::sqrt(m1), c = std::sqrt(m), pw = 1.0;
    // Stop once (c_N/a_N)^2 < 1e-18: the neglected terms are of that relative order (12 steps
    // at most, for the smallest subnormal m1).
    for (int n = 0; c > 1e-9 * a && n < 64; ++n) {
      const double an = 0.5 * (a + b);
      b = std::sqrt(a * b);
      c = c * c / (4.0 * an);  // (a_{n-1} - b_{n-1})/2 without cancellation
      a = an;
      pw *= 2.0;
      if (descending && j.steps < kMaxSteps) j.ratio[j.steps++] = c / a;
    }
    j.scale = pw * a;
    j.K = 0.5 * kPi / a;
    if (!descending) {
      // Ascending Landen (Gauss) transformation: parameters mu_n -> 1 with complements
      // mu1_n = s_n^2, s_n = (1 - k_{n-1})/(1 + k_{n-1}) = mu1_{n-1}/(1 + k_{n-1})^2, until the
      // first-order expansion about m = 1 is exact to rounding for |u| <= K/2 (there
      // e^{2u} <= 4/k', and the neglected terms are O((mu1 e^{2u})^2)).
      double k = std::sqrt(m), c1 = m1, sc = 1.0;
      while (j.ascending < kMaxAscending) {
        const double s = c1 / ((1.0 + k) * (1.0 + k));
        c1 = s * s;
        j.asc_s[j.ascending] = s;
        j.asc_mu[j.ascending] = 1.0 - c1;
        ++j.ascending;
        sc /= 1.0 + s;
        k = std::sqrt(1.0 - c1);
        if (c1 <= 1e-9 * j.kprime) break;
      }
      j.asc_mu1 = c1;
      j.asc_scale = sc;
    }
    return j;
  }

  // |u| <= K (or any u when m1 == 0): am(u) in [-pi/2, pi/2], cn >= 0.
  JacobiValues reduced(double u) const {
    JacobiValues v;
    if (m1 == 0.0) {
      v.sn = std::tanh(u);
      v.cn = v.dn = 1.0 / std::cosh(u);
      v.am = 2.0 * std::atan(std::tanh(0.5 * u));
      return v;
    }
    const double au = std::abs(u);
    if (au <= 0.5 * K) return landen(u);
    // Near the quarter period cn (and, for m -> 1, dn) is small and cos(am) would only have
    // absolute accuracy: use the values at w = K - |u| and the exact relations
    // sn(K - w) = cn w / dn w, cn(K - w) = k' sn w / dn w, dn(K - w) = k' / dn w.
    const JacobiValues c = landen(K - au);
    const double s = u < 0.0 ? -1.0 : 1.0;
    v.sn = s * c.cn / c.dn;
    v.cn = kprime * c.sn / c.dn;
    v.dn = kprime / c.dn;
    v.am = s * std::atan2(c.cn, kprime * c.sn);
    return v;
  }

  // m1 > 0 and |u| <= K/2: descending Landen transformation or, for m -> 1, ascending.
  JacobiValues landen(double u) const {
    JacobiValues v;
    if (ascending > 0) {
      // A&S 16.15 at the last level, then A&S 16.14 back down to m.
      const double x = u * asc_scale, e = 0.25 * asc_mu1;
      const double t = std::tanh(x), se = 1.0 / std::cosh(x), sh = std::sinh(x);
      double sn = t + e * (t - x * se * se);
      double cn = se - e * (sh - x * se) * t;
      double dn = se + e * (sh + x * se) * t;
      for (int n = ascending - 1; n >= 0; --n) {
        const double s = asc_s[n], mu = asc_mu[n];
        const double sn1 = (1.0 + s) * sn * cn / dn;
        const double cn1 = (1.0 + s) / mu * (dn * dn - s) / dn;
        dn = (1.0 - s) / mu * (dn * dn + s) / dn;
        sn = sn1;
        cn = cn1;
      }
      v.sn = sn;
      v.cn = cn;
      v.dn = dn;
      v.am = std::atan2(sn, cn);
      return v;
    }
    double phi = scale * u;
    for (int n = steps; n > 0; --n) phi = 0.5 * (phi + std::asin(ratio[n - 1] * std::sin(phi)));
    v.am = phi;
    v.sn = std::sin(phi);
    v.cn = std::cos(phi);
    v.dn = std::sqrt(m1 + m * v.cn * v.cn);
    return v;
  }

  // u = u_r + 2 K j with |u_r| <= K; j = 0 when K is infinite.
  double reduce(double u, double& j) const {
    if (!(K < kInf)) {
      j = 0.0;
      return u;
    }
    j = std::nearbyint(u / (2.0 * K));
    return u - 2.0 * K * j;
  }

  // Any real u.
  JacobiValues operator()(double u) const {
    double j;
    JacobiValues v = reduced(reduce(u, j));
    if (std::fmod(j, 2.0) != 0.0) {
      v.sn = -v.sn;
      v.cn = -v.cn;
    }
    v.am += j * kPi;
    return v;
  }
};

}  // namespace elliptic

struct FreeRotation {
  enum class Kind : unsigned char { Spin, Symmetric, Asymmetric };

  static FreeRotation make(const Vec3& I_principal, const Quat& q0, const Vec3& w0_lab);

  Quat orientation(double t) const {  // body -> lab at time t after the start, normalised
    Quat q;
    Vec3 w;
    evaluate(t, q, w);
    return q;
  }
  Vec3 angular_velocity(double t) const {  // lab frame
    Quat q;
    Vec3 w;
    evaluate(t, q, w);
    return w;
  }
  Vec3 angular_velocity_body(double t) const;
  // Both at once (one evaluation of the elliptic functions).
  void evaluate(double t, Quat& q, Vec3& w_lab) const;

  Vec3 angular_momentum() const { return L_; }  // lab, constant
  double kinetic_energy() const { return E_; }  // rotational, constant
  // Upper bound of |angular_velocity(t)| over all t (exact up to a 1e-14 relative margin).
  double max_angular_speed() const { return wmax_; }
  Kind kind() const { return kind_; }
  // Elliptic parameter m = k^2 and period of the body angular velocity (asymmetric top; the
  // period is +inf on the separatrix, 0 for the other kinds).
  double parameter() const { return jac_.m; }
  double body_period() const {
    return kind_ == Kind::Asymmetric ? 4.0 * jac_.K / std::abs(omega_) : 0.0;
  }

 private:
  Kind kind_ = Kind::Spin;
  Quat q0_ = Quat::Identity();
  Vec3 w0_ = Vec3::Zero();
  Vec3 L_ = Vec3::Zero();
  double E_ = 0.0;
  double wmax_ = 0.0;
  // Symmetric top.
  Vec3 wL_ = Vec3::Zero();   // L / I_t (lab)
  Vec3 es_ = Vec3::UnitZ();  // symmetry axis (body)
  Vec3 Wb0_ = Vec3::Zero();  // initial body angular velocity
  double nu_ = 0.0;          // body-frame rotation rate about es_
  double Ws_ = 0.0;          // es_ . Wb0_
  // Asymmetric top (body' frame).
  Quat G_ = Quat::Identity();     // q0 s M(l0)^-1
  Quat sinv_ = Quat::Identity();  // body -> body'
  // body' -> body: body component axis_[k] = sign_[k] * body' component k.
  std::array<signed char, 3> axis_{{0, 1, 2}}, sign_{{1, 1, 1}};
  Vec3 J_ = Vec3::Ones();  // moments in body'
  double Lmag_ = 0.0;
  double A_ = 0.0, B_ = 0.0, C_ = 0.0;
  double omega_ = 0.0;  // signed: dtau/dt
  double tau0_ = 0.0;
  double n_ = 0.0, c_ = 1.0, sqrt_n_ = 0.0;
  double lin_ = 0.0;    // |L|/J1 (or |L|/J3 on the separatrix)
  double kappa_ = 0.0;  // coefficient of the R_J bracket (c1 on the separatrix)
  double c2c_ = 0.0;    // c2 / c
  double S0_ = 0.0;     // sn0^3 R_J(...) at tau0 (separatrix: sqrt(n) atan(sqrt(n) tanh tau0))
  double G0_ = 0.0;     // atan2(c sn0, cn0)
  double RJc_ = 0.0;    // R_J(0, m1, 1, 1 + n)
  elliptic::Jacobi jac_;

  static Quat spin(const Vec3& w, double dt, const Quat& q0) { return spun(w, dt, q0); }

  // Body' angular velocity and (if psi != nullptr) the rotation angle psi about L at time t
  // (asymmetric top).
  void asym_state(double t, Vec3& W, double* psi) const {
    const double tau = tau0_ + omega_ * t;
    if (jac_.m1 == 0.0) {  // separatrix
      const double sn = std::tanh(tau), sech = 1.0 / std::cosh(tau);
      W = Vec3(A_ * sech, B_ * sn, C_ * sech);
      if (psi == nullptr) return;
      *psi = lin_ * t +
             kappa_ * ((tau - tau0_) + (sqrt_n_ * std::atan(sqrt_n_ * sn) - S0_)) / (1.0 + n_) -
             c2c_ * (std::atan(c_ * std::sinh(tau)) - G0_);
      return;
    }
    double j;
    const double tr = jac_.reduce(tau, j);
    const elliptic::JacobiValues v = jac_.reduced(tr);
    const double sgn = (std::fmod(j, 2.0) != 0.0) ? -1.0 : 1.0;
    W = Vec3(sgn * A_ * v.cn, sgn * B_ * v.sn, C_ * v.dn);
    if (psi == nullptr) return;
    const double s2 = v.sn * v.sn;
    const double rj = elliptic::carlson_rj(v.cn * v.cn, v.dn * v.dn, 1.0, 1.0 + n_ * s2);
    *psi = lin_ * t - kappa_ * (s2 * v.sn * rj - S0_ + 2.0 * j * RJc_) -
           c2c_ * (std::atan2(c_ * v.sn, v.cn) - G0_ + j * kPi);
  }

  // Minimal rotation taking the unit vector l (l_z > -1) to e_z.
  template <class T>
  static Eigen::Quaternion<T> to_z(const Eigen::Matrix<T, 3, 1>& l) {
    Eigen::Quaternion<T> m(T(1) + l.z(), l.y(), -l.x(), T(0));
    m.normalize();
    return m;
  }
};

inline FreeRotation FreeRotation::make(const Vec3& I, const Quat& q0in, const Vec3& w0) {
  using LD = long double;
  using V = Eigen::Matrix<LD, 3, 1>;
  using Q = Eigen::Quaternion<LD>;
  FreeRotation f;
  f.q0_ = q0in;  // as given: spin() normalises after the product, as orientation_at does
  f.w0_ = w0;
  const Q ql = q0in.cast<LD>().normalized();
  const V Il = I.cast<LD>();
  const V Wb = ql.conjugate() * w0.cast<LD>();
  const V Lb = Il.cwiseProduct(Wb);
  f.L_ = (ql * Lb).cast<double>();
  f.E_ = static_cast<double>(0.5L * Wb.dot(Lb));
  f.Wb0_ = Wb.cast<double>();
  const int zeros = (Wb.x() == 0) + (Wb.y() == 0) + (Wb.z() == 0);
  const bool e01 = I.x() == I.y(), e12 = I.y() == I.z(), e02 = I.x() == I.z();

  if ((e01 && e12) || zeros >= 2) {
    f.kind_ = Kind::Spin;
    f.wmax_ = w0.norm();  // angular_velocity(t) returns w0 itself
    return f;
  }
  if (e01 || e12 || e02) {
    f.kind_ = Kind::Symmetric;
    const int s = e01 ? 2 : (e12 ? 0 : 1);
    const LD Is = Il(s), It = Il((s + 1) % 3);
    f.es_ = Vec3::Unit(s);
    f.Ws_ = static_cast<double>(Wb(s));
    f.nu_ = static_cast<double>((It - Is) / It * Wb(s));
    f.wL_ = (ql * Lb / It).cast<double>();
    f.wmax_ = w0.norm() * (1.0 + 1e-14);  // |w| is constant; margin for the rounding
    return f;
  }

  f.kind_ = Kind::Asymmetric;
  // Sort the axes and pick the regime.
  int lo = 0, mid = 1, hi = 2;
  if (Il(lo) > Il(mid)) std::swap(lo, mid);
  if (Il(mid) > Il(hi)) std::swap(mid, hi);
  if (Il(lo) > Il(mid)) std::swap(lo, mid);
  const LD d_ml = Il(mid) - Il(lo), d_hm = Il(hi) - Il(mid), d_hl = Il(hi) - Il(lo);
  const LD D = Il(hi) * d_hm * Wb(hi) * Wb(hi) - Il(lo) * d_ml * Wb(lo) * Wb(lo);
  const bool around_hi = D >= 0;
  const int i1 = around_hi ? lo : hi, i3 = around_hi ? hi : lo;
  // Body' axes as columns of S (in body coordinates), right-handed.
  using M3 = Eigen::Matrix<LD, 3, 3>;
  M3 S;
  V e1 = V::Unit(i1), e2 = V::Unit(mid);
  V e3 = e1.cross(e2);
  V W = V(e1.dot(Wb), e2.dot(Wb), e3.dot(Wb));
  if (W.z() < 0) {  // rotate by pi about e1
    e2 = -e2;
    e3 = -e3;
    W.y() = -W.y();
    W.z() = -W.z();
  }
  if (W.x() < 0) {  // rotate by pi about e3
    e1 = -e1;
    e2 = -e2;
    W.x() = -W.x();
    W.y() = -W.y();
  }
  S.col(0) = e1;
  S.col(1) = e2;
  S.col(2) = e3;
  const V J(Il(i1), Il(mid), Il(i3));
  const LD d31 = d_hl, d32 = around_hi ? d_hm : d_ml, d21 = around_hi ? d_ml : d_hm;
  const LD W1 = W.x(), W2 = W.y(), W3 = W.z();
  const LD p3 = J(0) * d31 * W1 * W1 + J(1) * d32 * W2 * W2;
  const LD p1 = J(1) * d21 * W2 * W2 + J(2) * d31 * W3 * W3;
  const LD Lm = J.cwiseProduct(W).norm();
  const LD A = std::sqrt(p3 / (J(0) * d31)), B = std::sqrt(p3 / (J(1) * d32)),
           C = std::sqrt(p1 / (J(2) * d31));
  const LD omega = std::sqrt(d32 * p1 / (J(0) * J(1) * J(2)));
  const LD m = d21 * p3 / (d32 * p1), m1 = d31 * std::abs(D) / (d32 * p1);
  const LD n = J(2) * d21 / (J(0) * d32), c = std::sqrt(1 + n);
  // Initial phase: cn0 = W1/A >= 0, sn0 = W2/B (scale-free form).
  const LD y = W2 * std::sqrt(J(1) * d32), x = W1 * std::sqrt(J(0) * d31);
  const LD r = std::hypot(x, y);
  const LD sn0 = r > 0 ? y / r : 0, cn0 = r > 0 ? x / r : 1;

  f.J_ = J.cast<double>();
  for (int k = 0; k < 3; ++k) {
    int i = 0;
    while (S(i, k) == 0) ++i;
    f.axis_[k] = static_cast<signed char>(i);
    f.sign_[k] = static_cast<signed char>(S(i, k) > 0 ? 1 : -1);
  }
  const Q s(S);
  f.sinv_ = s.conjugate().cast<double>();
  f.Lmag_ = static_cast<double>(Lm);
  f.A_ = static_cast<double>(A);
  f.B_ = static_cast<double>(B);
  f.C_ = static_cast<double>(C);
  f.omega_ = static_cast<double>(around_hi ? omega : -omega);
  f.n_ = static_cast<double>(n);
  f.c_ = static_cast<double>(c);
  f.sqrt_n_ = static_cast<double>(std::sqrt(n));
  f.jac_ = elliptic::Jacobi::make(static_cast<double>(m), static_cast<double>(m1));
  const LD c2 = d31 * C / (J(0) * omega);
  f.c2c_ = static_cast<double>(c2 / c);
  if (f.jac_.m1 == 0.0) {
    const LD tau0 = std::asinh(y / x);  // x > 0 here (else W1 = W3 = 0: a pure spin)
    f.tau0_ = static_cast<double>(tau0);
    f.lin_ = static_cast<double>(Lm / J(2));
    f.kappa_ = static_cast<double>(d31 * Lm / (J(0) * J(2) * omega));
    const LD sq = std::sqrt(n);
    f.S0_ = static_cast<double>(sq * std::atan(sq * std::tanh(tau0)));
    f.G0_ = static_cast<double>(std::atan(c * std::sinh(tau0)));
  } else {
    // The elliptic integrals in double (their errors are not amplified), with the rounded m1
    // that the Jacobi functions use.
    const double s0 = static_cast<double>(sn0), c0 = static_cast<double>(cn0);
    const double m1d = f.jac_.m1, nd = f.n_;
    const double d0sq = c0 * c0 + m1d * s0 * s0;
    f.tau0_ = s0 * elliptic::carlson_rf(c0 * c0, d0sq, 1.0);
    f.lin_ = static_cast<double>(Lm / J(0));
    f.kappa_ = static_cast<double>(d31 * d21 * Lm / (3 * J(0) * J(0) * d32 * omega));
    f.S0_ = s0 * s0 * s0 * elliptic::carlson_rj(c0 * c0, d0sq, 1.0, 1.0 + nd * s0 * s0);
    f.G0_ = std::atan2(f.c_ * s0, c0);
    f.RJc_ = elliptic::carlson_rj(0.0, m1d, 1.0, 1.0 + nd);
  }
  // G = q0 s M(l0)^-1, l0 = J W / |L|.
  const V l0 = J.cwiseProduct(W) / Lm;
  const Q G = ql * s * to_z<LD>(l0).conjugate();
  f.G_ = G.normalized().cast<double>();
  f.wmax_ =
      static_cast<double>(std::sqrt(std::max(A * A + C * C, B * B + m1 * C * C))) * (1.0 + 1e-14);
  return f;
}

inline void FreeRotation::evaluate(double t, Quat& q, Vec3& w) const {
  switch (kind_) {
    case Kind::Spin:
      q = spin(w0_, t, q0_);
      w = w0_;
      return;
    case Kind::Symmetric: {
      q = spin(wL_, t, q0_) * spin(nu_ * es_, t, Quat::Identity());
      q.normalize();
      w = wL_ + nu_ * (q * es_);
      return;
    }
    case Kind::Asymmetric: {
      Vec3 W;
      double psi;
      asym_state(t, W, &psi);
      // W from the elliptic functions keeps 2E = sum J_k W_k^2 to a few ulps only; a run
      // evaluates the motion at every event, and those errors would random-walk the energy
      // (~1e-12 after 10^6 collisions). W is scaled back onto the exact energy (a change of a few
      // ulps, far inside the motion's accuracy).
      const double e2 = W.dot(J_.cwiseProduct(W));
      if (e2 > 0.0) W *= std::sqrt(2.0 * E_ / e2);
      const Vec3 l = J_.cwiseProduct(W) / Lmag_;
      const Quat z(std::cos(0.5 * psi), 0.0, 0.0, std::sin(0.5 * psi));
      Quat qp = G_ * z * to_z<double>(l);
      qp.normalize();
      w = qp * W;
      q = qp * sinv_;
      q.normalize();
      return;
    }
  }
}

inline Vec3 FreeRotation::angular_velocity_body(double t) const {
  switch (kind_) {
    case Kind::Spin:
      return Wb0_;
    case Kind::Symmetric: {
      // The transverse part rotates about e_s by -nu t.
      const Vec3 perp = Wb0_ - Ws_ * es_;
      return spin(nu_ * es_, -t, Quat::Identity()) * perp + Ws_ * es_;
    }
    case Kind::Asymmetric: {
      Vec3 W, Wb;
      asym_state(t, W, nullptr);
      for (int k = 0; k < 3; ++k) Wb(axis_[k]) = sign_[k] * W(k);
      return Wb;
    }
  }
  return Wb0_;
}

}  // namespace hb
