// Checks of the exact second-virial reference for hard convex bodies (convex_virial.hpp): the
// Carlson integrals against published values, the ellipsoid surface area and mean radius of
// curvature against quadrature, the spheroid closed forms and the reference table, and the
// excluded volume of unlike bodies against Monte Carlo with the Perram–Wertheim overlap test.
// No simulation: the whole suite takes about a second.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/perram_wertheim.hpp"
#include "physics/convex_virial.hpp"

namespace ref = hb::ref;

namespace {

constexpr double kPi = ref::kVirPi;

double rel(double x, double y) { return std::abs(x - y) / std::abs(y); }

// Spheroid closed forms of ../shared/reference/README.md: symmetry semi-axis a, equatorial b.
struct Spheroid {
  double S, R;
};
Spheroid spheroid_closed_form(double a, double b) {
  if (a > b) {
    const double e = std::sqrt(1.0 - b * b / (a * a));
    return {2.0 * kPi * b * b * (1.0 + a / (b * e) * std::asin(e)),
            0.5 * a * (1.0 + (1.0 - e * e) / (2.0 * e) * std::log((1.0 + e) / (1.0 - e)))};
  }
  const double e = std::sqrt(1.0 - a * a / (b * b)), g = std::sqrt(b * b - a * a);
  return {2.0 * kPi * b * b * (1.0 + (1.0 - e * e) / e * std::atanh(e)),
          0.5 * (a + b * b / g * std::asin(g / b))};
}

// Reproducible uniform doubles in [0, 1) (53 bits of a 64-bit Mersenne twister).
struct Uniform {
  std::mt19937_64 g;
  explicit Uniform(std::uint64_t seed) : g(seed) {}
  double operator()() { return static_cast<double>(g() >> 11) * 0x1.0p-53; }
};

// Uniformly distributed rotation (Shoemake's method).
hb::Quat random_rotation(Uniform& u) {
  const double u1 = u(), u2 = 2.0 * kPi * u(), u3 = 2.0 * kPi * u();
  const double s1 = std::sqrt(1.0 - u1), s2 = std::sqrt(u1);
  return hb::Quat(s2 * std::cos(u3), s1 * std::sin(u2), s1 * std::cos(u2), s2 * std::sin(u3));
}

hb::Vec3 random_direction(Uniform& u) {
  const double z = 2.0 * u() - 1.0, f = 2.0 * kPi * u(), s = std::sqrt(1.0 - z * z);
  return hb::Vec3(s * std::cos(f), s * std::sin(f), z);
}

struct Estimate {
  double mean, se;
};

}  // namespace

// Carlson, Numer. Algorithms 10, 13 (1995), table of test values.
TEST(ConvexVirial, CarlsonIntegralsMatchPublishedValues) {
  EXPECT_NEAR(ref::carlson_rf(1, 2, 0), 1.3110287771461, 1e-13);
  EXPECT_NEAR(ref::carlson_rf(2, 3, 4), 0.58408284167715, 1e-13);
  EXPECT_NEAR(ref::carlson_rd(0, 2, 1), 1.7972103521034, 1e-13);
  EXPECT_NEAR(ref::carlson_rd(2, 3, 4), 0.16510527294261, 1e-13);
  EXPECT_NEAR(ref::carlson_rg(0, 16, 16), 3.1415926535898, 1e-13);
  EXPECT_NEAR(ref::carlson_rg(2, 3, 4), 1.7255030280692, 1e-13);
  EXPECT_NEAR(ref::carlson_rg(0, 0.0796, 4), 1.0284758090288, 1e-13);
  // symmetric in its arguments, homogeneous of degree 1/2
  EXPECT_NEAR(ref::carlson_rg(4, 2, 3), ref::carlson_rg(2, 3, 4), 1e-15);
  EXPECT_NEAR(ref::carlson_rg(8, 12, 16), 2.0 * ref::carlson_rg(2, 3, 4), 1e-14);
  EXPECT_NEAR(ref::carlson_rg(5, 5, 5), std::sqrt(5.0), 1e-15);
  EXPECT_THROW(ref::carlson_rf(0, 0, 1), std::invalid_argument);
  EXPECT_THROW(ref::carlson_rd(1, 1, 0), std::invalid_argument);
}

TEST(ConvexVirial, SphereFunctionals) {
  for (double r : {0.5, 1.0, 2.7}) {
    EXPECT_NEAR(ref::ellipsoid_surface_area(r, r, r), 4.0 * kPi * r * r, 1e-14 * r * r);
    EXPECT_NEAR(ref::ellipsoid_mean_radius(r, r, r), r, 1e-15 * r);
    EXPECT_NEAR(ref::ellipsoid_surface_area_quadrature(r, r, r), 4.0 * kPi * r * r, 1e-14 * r * r);
    EXPECT_NEAR(ref::ellipsoid_mean_radius_quadrature(r, r, r), r, 1e-15 * r);
    const auto s = ref::sphere_body(r), e = ref::ellipsoid_body(r, r, r);
    EXPECT_NEAR(ref::b2_star(s), 4.0, 1e-15);
    EXPECT_NEAR(ref::b2_star(e), 4.0, 1e-14);
    EXPECT_NEAR(ref::mixture_b2({{s, 1.0}}).b2_star, 4.0, 1e-15);
    // equal spheres: V_ex = (4 pi / 3) (2r)^3
    EXPECT_NEAR(ref::excluded_volume(s, s), 4.0 / 3.0 * kPi * std::pow(2.0 * r, 3), 1e-13);
    const auto from_struct = ref::convex_body(hb::Sphere{r});
    EXPECT_EQ(from_struct.surface, s.surface);
  }
}

// Closed forms (Carlson) against the independent quadrature, 1e-12 relative, including
// aspect ratios 10 and 1/10 and triaxial bodies; and against mpmath (30 digits, elliprg).
TEST(ConvexVirial, EllipsoidFunctionalsMatchQuadrature) {
  const double axes[][3] = {{3, 1, 1},   {1, 1, 3},   {1.0 / 3, 1, 1}, {10, 1, 1}, {0.1, 1, 1},
                            {1, 0.6, 0.3}, {0.3, 0.6, 0.9}, {5, 2, 0.5}, {1, 0.5, 0.5}, {2, 1.01, 1}};
  for (const auto& x : axes) {
    int nr = 0, ns = 0;
    const double R = ref::ellipsoid_mean_radius(x[0], x[1], x[2]);
    const double S = ref::ellipsoid_surface_area(x[0], x[1], x[2]);
    const double Rq = ref::mean_support_quadrature(x[0], x[1], x[2], 1e-15, 4096, &nr);
    const double Sq = 4.0 * kPi * x[0] * x[1] * x[2] *
                      ref::mean_support_quadrature(1 / x[0], 1 / x[1], 1 / x[2], 1e-15, 4096, &ns);
    EXPECT_LT(rel(R, Rq), 1e-12) << x[0] << " " << x[1] << " " << x[2] << " nodes " << nr;
    EXPECT_LT(rel(S, Sq), 1e-12) << x[0] << " " << x[1] << " " << x[2] << " nodes " << ns;
    EXPECT_LT(nr, 4096);
    EXPECT_LT(ns, 4096);
  }
  // mpmath: R = elliprg(a^2,b^2,c^2), S = 4 pi abc elliprg(a^-2,b^-2,c^-2) at 30 digits
  EXPECT_LT(rel(ref::ellipsoid_surface_area(1, 0.6, 0.3), 4.83443544955003876269497), 1e-14);
  EXPECT_LT(rel(ref::ellipsoid_mean_radius(1, 0.6, 0.3), 0.671987682626081893276122), 1e-14);
  EXPECT_LT(rel(ref::ellipsoid_surface_area(0.3, 0.6, 0.9), 4.39939316723238528752698), 1e-14);
  EXPECT_LT(rel(ref::ellipsoid_mean_radius(0.3, 0.6, 0.9), 0.630369536240269836775328), 1e-14);
  // invariant under permutation of the axes
  EXPECT_LT(rel(ref::ellipsoid_surface_area(0.6, 0.3, 1), ref::ellipsoid_surface_area(1, 0.6, 0.3)),
            1e-15);
  EXPECT_THROW(ref::ellipsoid_surface_area(1, 0, 1), std::invalid_argument);
}

TEST(ConvexVirial, SpheroidsMatchClosedForms) {
  for (double X0 : {1.5, 2.0, 3.0, 5.0, 10.0, 100.0}) {
    for (double a : {X0, 1.0 / X0}) {
      const Spheroid cf = spheroid_closed_form(a, 1.0);
      EXPECT_LT(rel(ref::ellipsoid_surface_area(a, 1, 1), cf.S), 1e-13) << a;
      EXPECT_LT(rel(ref::ellipsoid_mean_radius(a, 1, 1), cf.R), 1e-13) << a;
    }
    // B2/v is invariant under X0 -> 1/X0 for spheroids
    EXPECT_NEAR(ref::b2_star(ref::ellipsoid_body(X0, 1, 1)),
                ref::b2_star(ref::ellipsoid_body(1.0 / X0, 1, 1)), 1e-12);
  }
}

// README.md of the reference data: B2* = 4.538487 (X0 = 2, 1/2), 5.453749 (3, 1/3),
// 7.552003 (5, 1/5), printed to 6 decimals.
TEST(ConvexVirial, SpheroidB2MatchesReferenceValues) {
  const auto prolate = ref::ellipsoid_body(3, 1, 1), oblate = ref::ellipsoid_body(1.0 / 3, 1, 1);
  EXPECT_NEAR(ref::b2_star(prolate), 5.453749, 1e-6);
  EXPECT_NEAR(ref::b2_star(oblate), 5.453749, 1e-6);
  EXPECT_NEAR(ref::b2_star(ref::ellipsoid_body(2, 1, 1)), 4.538487, 1e-6);
  EXPECT_NEAR(ref::b2_star(ref::ellipsoid_body(0.5, 1, 1)), 4.538487, 1e-6);
  EXPECT_NEAR(ref::b2_star(ref::ellipsoid_body(5, 1, 1)), 7.552003, 1e-6);
  EXPECT_NEAR(ref::b2_star(ref::ellipsoid_body(0.2, 1, 1)), 7.552003, 1e-6);
  // the same body through the engine's struct, in any axis order
  EXPECT_NEAR(ref::b2_star(ref::convex_body(hb::Ellipsoid{1, 3, 1})), 5.453749, 1e-6);
  EXPECT_NEAR(ref::mixture_b2({{prolate, 7.0}}).b2_star, ref::b2_star(prolate), 1e-15);
  std::printf("X0=3:   S=%.12f R=%.12f B2*=%.9f\nX0=1/3: S=%.12f R=%.12f B2*=%.9f\n",
              prolate.surface, prolate.mean_radius, ref::b2_star(prolate), oblate.surface,
              oblate.mean_radius, ref::b2_star(oblate));
}

// Every row of spheroid_virial_computed.csv (V, S, R to 8 decimals, B2/V to 6).
TEST(ConvexVirial, SpheroidTableMatches) {
  std::ifstream in(std::string(HB_SHARED_DIR) + "/reference/spheroid_virial_computed.csv");
  if (!in) GTEST_SKIP() << "reference table not found";
  // the table prints X0 rounded; these are the exact aspect ratios it was made for
  const double exact[] = {0.1, 0.2, 0.25, 1.0 / 3, 0.5, 1.0 / std::sqrt(3.0), 2.0 / 3, 1.0,
                          1.5, std::sqrt(3.0), 2.0, 3.0, 5.0, 10.0};
  std::string line;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'X') continue;
    std::stringstream ss(line);
    std::vector<double> col;
    std::string cell;
    for (int k = 0; k < 7 && std::getline(ss, cell, ','); ++k) col.push_back(std::stod(cell));
    ASSERT_EQ(col.size(), 7u) << line;
    double X0 = col[0];
    for (double e : exact)
      if (std::abs(e - X0) < 1e-6) X0 = e;
    const auto b = ref::ellipsoid_body(X0, 1, 1);
    EXPECT_NEAR(b.volume, col[1], 1e-8) << X0;
    EXPECT_NEAR(b.surface, col[2], 1e-8) << X0;
    EXPECT_NEAR(b.mean_radius, col[3], 1e-8) << X0;
    EXPECT_NEAR(ref::b2_star(b), col[6], 6e-7) << X0;
    ++rows;
  }
  EXPECT_EQ(rows, 14);
}

TEST(ConvexVirial, UnlikeExcludedVolume) {
  const auto e1 = ref::ellipsoid_body(1, 0.6, 0.3), e2 = ref::ellipsoid_body(0.3, 0.6, 0.9);
  EXPECT_EQ(ref::excluded_volume(e1, e2), ref::excluded_volume(e2, e1));
  EXPECT_LT(rel(ref::excluded_volume(e1, e2), 7.43638510176283333553887), 1e-14);  // mpmath
  for (double r : {0.1, 0.5, 2.0}) {
    // a sphere, also written as an ellipsoid with equal axes, with an ellipsoid: Steiner formula
    const auto s = ref::sphere_body(r), s_as_e = ref::ellipsoid_body(r, r, r);
    const double vs = 4.0 / 3.0 * kPi * r * r * r;
    const double steiner = vs + e1.volume + r * e1.surface + e1.mean_radius * 4.0 * kPi * r * r;
    EXPECT_LT(rel(ref::excluded_volume(s, e1), steiner), 1e-15);
    EXPECT_LT(rel(ref::excluded_volume(e1, s), steiner), 1e-15);
    EXPECT_LT(rel(ref::excluded_volume(s_as_e, e1), steiner), 1e-14);
  }
  // unequal spheres: (4 pi / 3)(r1 + r2)^3
  EXPECT_LT(rel(ref::excluded_volume(ref::sphere_body(0.3), ref::sphere_body(1.1)),
                4.0 / 3.0 * kPi * std::pow(1.4, 3)),
            1e-15);
}

TEST(ConvexVirial, MixtureB2) {
  // binary spheres: B2 = (1/2) sum x_i x_j (4 pi / 3)(r_i + r_j)^3, B2* < 4
  const double r1 = 0.5, r2 = 0.35, x1 = 0.3, x2 = 0.7;
  const auto m = ref::mixture_b2({{ref::sphere_body(r1), x1}, {ref::sphere_body(r2), x2}});
  const double c = 4.0 / 3.0 * kPi;
  const double b2 = 0.5 * c *
                    (x1 * x1 * std::pow(2 * r1, 3) + 2 * x1 * x2 * std::pow(r1 + r2, 3) +
                     x2 * x2 * std::pow(2 * r2, 3));
  EXPECT_LT(rel(m.b2, b2), 1e-15);
  EXPECT_LT(rel(m.mean_volume, c * (x1 * r1 * r1 * r1 + x2 * r2 * r2 * r2)), 1e-15);
  EXPECT_LT(m.b2_star, 4.0);
  // counts and fractions give the same result; a component with zero amount drops out
  const auto s = ref::sphere_body(0.5), e = ref::ellipsoid_body(1.0, 0.5, 0.5);
  const auto eq = ref::mixture_b2({{s, 0.5}, {e, 0.5}});
  const auto counts = ref::mixture_b2({{s, 400}, {e, 400}});
  EXPECT_LT(rel(counts.b2_star, eq.b2_star), 1e-15);
  EXPECT_LT(rel(ref::mixture_b2({{s, 1}, {e, 0}}).b2_star, 4.0), 1e-15);
  // equimolar spheres r = 0.5 + prolate (1, 0.5, 0.5), and the 2:1 mixture of equal packing
  // fractions; mpmath (30 digits): 4.22418183888378168783879, 4.13443406301854544579313
  EXPECT_LT(rel(eq.b2_star, 4.22418183888378168783879), 1e-14);
  EXPECT_LT(rel(eq.b2, 3.31766465811617803949515), 1e-14);
  const auto eqphi = ref::mixture_b2({{s, 2}, {e, 1}});
  EXPECT_LT(rel(eqphi.b2_star, 4.13443406301854544579313), 1e-14);
  std::printf("sphere 0.5 + ellipsoid (1,.5,.5): V_ex ss=%.12f se=%.12f ee=%.12f\n"
              "  1:1  B2=%.12f <v>=%.12f B2*=%.12f\n  2:1  B2=%.12f <v>=%.12f B2*=%.12f\n",
              ref::excluded_volume(s, s), ref::excluded_volume(s, e), ref::excluded_volume(e, e),
              eq.b2, eq.mean_volume, eq.b2_star, eqphi.b2, eqphi.mean_volume, eqphi.b2_star);
  EXPECT_THROW(ref::mixture_b2({{s, -1}, {e, 1}}), std::invalid_argument);
  EXPECT_THROW(ref::mixture_b2({{s, 0}}), std::invalid_argument);
}

// Hit-or-miss Monte Carlo of the mean excluded volume of a sphere (r = 0.5) and the prolate
// ellipsoid (1, 0.5, 0.5) of the mixture test: the ellipsoid at the origin in a random
// orientation, the sphere's centre uniform in the cube that contains every overlapping position,
// overlap decided by the Perram–Wertheim function (the sphere as an ellipsoid with equal axes).
TEST(ConvexVirial, MonteCarloSphereEllipsoidExcludedVolume) {
  const double r = 0.5;
  const hb::Vec3 ax(1.0, 0.5, 0.5);
  const double L = ax.maxCoeff() + r, box = std::pow(2.0 * L, 3);
  Uniform u(20240611);
  const long n = 1'000'000;
  long hits = 0;
  hb::EllipsoidPose S{hb::Vec3::Constant(r)}, E{ax};
  for (long k = 0; k < n; ++k) {
    E.q = random_rotation(u);
    const double dx = L * (2.0 * u() - 1.0), dy = L * (2.0 * u() - 1.0), dz = L * (2.0 * u() - 1.0);
    const hb::Vec3 d(dx, dy, dz);
    hits += hb::ellipsoids_overlap(E, S, d);
  }
  const double p = static_cast<double>(hits) / n;
  const Estimate mc{box * p, box * std::sqrt(p * (1.0 - p) / (n - 1))};
  const double exact = ref::excluded_volume(ref::sphere_body(r), ref::ellipsoid_body(1.0, 0.5, 0.5));
  std::printf("sphere-ellipsoid V_ex: MC %.5f +- %.5f, exact %.9f, (MC - exact)/se = %.2f\n",
              mc.mean, mc.se, exact, (mc.mean - exact) / mc.se);
  EXPECT_LT(std::abs(mc.mean - exact), 4.0 * mc.se);
  EXPECT_LT(mc.se, 0.003 * exact);  // the check is sharp: 0.3 % (0.02 in V_ex)
}

// The general unlike-body formula, where the orientation average matters: two different
// triaxial ellipsoids, both randomly oriented.  Radial estimator: for fixed orientations the
// excluded region is star-shaped about the origin, V_ex = (1/3) integral d(u)^3 dOmega with d(u)
// the centre distance at contact along u (touching_scale), so (4 pi / 3) d^3 over random u and
// random orientations is an unbiased estimate with a much smaller variance than hit-or-miss.
TEST(ConvexVirial, MonteCarloEllipsoidPairExcludedVolume) {
  hb::EllipsoidPose A{hb::Vec3(1.0, 0.6, 0.3)}, B{hb::Vec3(0.3, 0.6, 0.9)};
  Uniform u(77);
  const long n = 200'000;
  double sum = 0.0, sum2 = 0.0;
  for (long k = 0; k < n; ++k) {
    A.q = random_rotation(u);
    B.q = random_rotation(u);
    const double d = hb::touching_scale(A, B, random_direction(u));
    const double v = 4.0 / 3.0 * kPi * d * d * d;
    sum += v, sum2 += v * v;
  }
  const double mean = sum / n, var = (sum2 / n - mean * mean) * n / (n - 1.0);
  const Estimate mc{mean, std::sqrt(var / n)};
  const auto e1 = ref::ellipsoid_body(1.0, 0.6, 0.3), e2 = ref::ellipsoid_body(0.3, 0.6, 0.9);
  const double exact = ref::excluded_volume(e1, e2);
  std::printf("ellipsoid pair V_ex: MC %.5f +- %.5f, exact %.9f, (MC - exact)/se = %.2f\n",
              mc.mean, mc.se, exact, (mc.mean - exact) / mc.se);
  EXPECT_LT(std::abs(mc.mean - exact), 4.0 * mc.se);
  EXPECT_LT(mc.se, 0.002 * exact);
  // and the same estimator with the sphere of the previous test (no orientation dependence)
  hb::EllipsoidPose S{hb::Vec3::Constant(0.5)}, E{hb::Vec3(1.0, 0.5, 0.5)};
  sum = sum2 = 0.0;
  for (long k = 0; k < n; ++k) {
    E.q = random_rotation(u);
    const double d = hb::touching_scale(E, S, random_direction(u));
    const double v = 4.0 / 3.0 * kPi * d * d * d;
    sum += v, sum2 += v * v;
  }
  const double m2 = sum / n, se2 = std::sqrt((sum2 / n - m2 * m2) / (n - 1.0));
  const double exact2 = ref::excluded_volume(ref::sphere_body(0.5), ref::ellipsoid_body(1, 0.5, 0.5));
  std::printf("sphere-ellipsoid V_ex (radial): MC %.5f +- %.5f, exact %.9f, (MC - exact)/se = %.2f\n",
              m2, se2, exact2, (m2 - exact2) / se2);
  EXPECT_LT(std::abs(m2 - exact2), 4.0 * se2);
}
