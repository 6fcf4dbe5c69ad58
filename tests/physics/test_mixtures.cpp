// Hard-sphere mixtures and polydisperse hard spheres against the Boublik–Mansoori–Carnahan–
// Starling–Leland (BMCSL) equation of state and its contact values (fixed seeds; tolerances from
// the issue: 3 standard errors + 0.3 % for Z of binary mixtures, + 0.5 % for polydispersity, 2 %
// for the partial collision rates). BMCSL reduces to Carnahan–Starling for one component, which
// is 0.28 % low at phi = 0.4 (../shared/reference/README.md); the same-size mixture below is
// therefore held to Hansen-Goos instead, which is exact to ~1e-4.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "io/gsd_hoomd.hpp"
#include "run_helper.hpp"

using namespace hbtest;

namespace {

struct Bmcsl {
  double Z = 0.0;
  std::vector<std::vector<double>> rate;  // collisions per unit time of one body of a with b's
};

// BMCSL for bodies of diameters d (one entry per body or per component with weights x), masses m.
// xi_k = (pi/6) rho <d^k>; Z = [xi0/(1-xi3) + 3 xi1 xi2/(1-xi3)^2 + (3 - xi3) xi2^3/(1-xi3)^3]/xi0;
// contact value g_ab = 1/(1-xi3) + 3 xi2 q/(1-xi3)^2 + 2 xi2^2 q^2/(1-xi3)^3, q = d_a d_b/(d_a+d_b);
// Enskog rate of a with b: rho x_b d_ab^2 g_ab sqrt(8 pi kT / mu_ab), d_ab = (d_a + d_b)/2.
Bmcsl bmcsl(const std::vector<double>& x, const std::vector<double>& d, const std::vector<double>& m,
            double phi) {
  double m3 = 0.0;
  for (std::size_t k = 0; k < x.size(); ++k) m3 += x[k] * std::pow(d[k], 3);
  const double rho = phi / (M_PI / 6.0 * m3);
  double xi[4] = {0, 0, 0, 0};
  for (int p = 0; p < 4; ++p)
    for (std::size_t k = 0; k < x.size(); ++k) xi[p] += M_PI / 6.0 * rho * x[k] * std::pow(d[k], p);
  const double e = 1.0 - xi[3];
  Bmcsl out;
  out.Z = (xi[0] / e + 3.0 * xi[1] * xi[2] / (e * e) + (3.0 - xi[3]) * std::pow(xi[2], 3) / (e * e * e)) / xi[0];
  out.rate.assign(x.size(), std::vector<double>(x.size(), 0.0));
  for (std::size_t a = 0; a < x.size(); ++a)
    for (std::size_t b = 0; b < x.size(); ++b) {
      const double q = d[a] * d[b] / (d[a] + d[b]);
      const double g = 1.0 / e + 3.0 * xi[2] * q / (e * e) + 2.0 * xi[2] * xi[2] * q * q / (e * e * e);
      const double mu = m[a] * m[b] / (m[a] + m[b]);
      out.rate[a][b] = rho * x[b] * std::pow(0.5 * (d[a] + d[b]), 2) * g * std::sqrt(8.0 * M_PI / mu);
    }
  return out;
}

std::string binary_config(double phi, double d_small, double m_small, double teq, double t) {
  return "[system]\npacking_fraction = " + std::to_string(phi) +
         "\nseed = 5\n"
         "[[species]]\nname = \"A\"\ncount = 500\nshape = { type = \"sphere\", radius = 0.5 }\n"
         "[[species]]\nname = \"B\"\ncount = 500\nmass = " + std::to_string(m_small) +
         "\nshape = { type = \"sphere\", radius = " + std::to_string(0.5 * d_small) + " }\n"
         "[run]\nequilibrate_time = " + std::to_string(teq) + "\ntime = " + std::to_string(t) +
         "\n[output]\nlog_interval = 0.5\nsnapshot_interval = 1000\n";
}

}  // namespace

struct BinaryPoint {
  double phi, time;
};
class BinaryHardSpheres : public ::testing::TestWithParam<BinaryPoint> {};

TEST_P(BinaryHardSpheres, PressureAndPartialCollisionRatesMatchBmcsl) {
  const auto [phi, time] = GetParam();
  const auto s = run_config("binary-" + std::to_string(int(100 * phi)), binary_config(phi, 0.5, 1.0, 10.0, time));
  const Bmcsl ref = bmcsl({0.5, 0.5}, {1.0, 0.5}, {1.0, 1.0}, phi);
  const double z = s["Z"], ze = s["Z_error"];
  std::printf("binary d_B/d_A = 0.5, phi = %.2f: Z = %.4f +- %.4f, BMCSL %.4f (%+.2f %%, %.1f sigma), %llu collisions\n",
              phi, z, ze, ref.Z, 100.0 * (z / ref.Z - 1.0), (z - ref.Z) / ze,
              (unsigned long long)s["collisions"].get<std::uint64_t>());
  EXPECT_GT(ze, 0.0);
  EXPECT_LE(std::abs(z - ref.Z), 3.0 * ze + 0.003 * ref.Z);
  for (const auto& p : s["species_pairs"]) {
    const int a = p["a"] == "A" ? 0 : 1, b = p["b"] == "A" ? 0 : 1;
    const double r = p["collision_rate"];
    std::printf("  rate %s-%s %.4f, BMCSL-Enskog %.4f (%+.2f %%)\n", p["a"].get<std::string>().c_str(),
                p["b"].get<std::string>().c_str(), r, ref.rate[a][b], 100.0 * (r / ref.rate[a][b] - 1.0));
    EXPECT_LE(std::abs(r / ref.rate[a][b] - 1.0), 0.02) << p;
  }
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-12);
  EXPECT_LE(s["momentum_drift"].get<double>(), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(States, BinaryHardSpheres,
                         ::testing::Values(BinaryPoint{0.20, 100.0}, BinaryPoint{0.40, 40.0}));

// Two species of the same size and unequal masses are one hard-sphere fluid: the mixture engine
// (random placement, growth, per-body masses) must give the Hansen-Goos pressure, and the
// partial rates must follow the reduced masses.
TEST(MixturePhysics, SameSizeSpeciesGiveTheOneComponentFluid) {
  const double phi = 0.4;
  const auto s = run_config("same-size", binary_config(phi, 1.0, 4.0, 10.0, 40.0));
  const double z = s["Z"], ze = s["Z_error"], zhg = z_hansen_goos(phi);
  std::printf("same size, masses 1 and 4, phi = 0.4: Z = %.4f +- %.4f, Hansen-Goos %.4f (%.1f sigma)\n", z, ze,
              zhg, (z - zhg) / ze);
  EXPECT_LE(std::abs(z - zhg), 3.0 * ze + 0.001 * zhg);  // + finite-N (N = 1000) allowance
  const Bmcsl ref = bmcsl({0.5, 0.5}, {1.0, 1.0}, {1.0, 4.0}, phi);
  const double g_ratio = (zhg - 1.0) / (ref.Z - 1.0);  // Hansen-Goos over Carnahan–Starling contact value
  for (const auto& p : s["species_pairs"]) {
    const int a = p["a"] == "A" ? 0 : 1, b = p["b"] == "A" ? 0 : 1;
    EXPECT_LE(std::abs(p["collision_rate"].get<double>() / (ref.rate[a][b] * g_ratio) - 1.0), 0.02) << p;
  }
  // per-species temperatures are equal (equipartition across masses)
  const auto& sp = s["species"];
  EXPECT_NEAR(sp[0]["temperature_translational"].get<double>(), sp[1]["temperature_translational"].get<double>(), 0.1);
}

// Polydisperse hard spheres: gaussian sizes of width 0.1 at phi = 0.45, against BMCSL evaluated
// with the moments of the sampled diameters (the `scale` of every body in the trajectory).
TEST(MixturePhysics, PolydisperseSpheresMatchGeneralisedBmcsl) {
  const double phi = 0.45;
  const std::string cfg =
      "[system]\npacking_fraction = 0.45\nseed = 9\n"
      "[[species]]\nname = \"P\"\ncount = 1000\nshape = { type = \"sphere\", radius = 0.5 }\n"
      "polydispersity = { distribution = \"gaussian\", width = 0.1 }\n"
      "[run]\nequilibrate_time = 20\ntime = 30\n[output]\nlog_interval = 0.5\nsnapshot_interval = 10\n";
  const auto s = run_config("polydisperse", cfg);
  const auto dir = hbtest::test_dir("polydisperse") / "out";
  const auto frame = hb::gsd::read_last_frame(dir / "trajectory.gsd");
  const auto& scale = frame.log.at("particles/hardbody/scale").values;
  ASSERT_EQ(scale.size(), 1000u);
  std::vector<double> x(scale.size(), 1.0 / double(scale.size())), d(scale.size()), m(scale.size());
  for (std::size_t i = 0; i < scale.size(); ++i) d[i] = scale[i], m[i] = std::pow(scale[i], 3);
  const Bmcsl ref = bmcsl(x, d, m, phi);
  const double z = s["Z"], ze = s["Z_error"];
  std::printf("polydisperse 0.1, phi = 0.45: Z = %.4f +- %.4f, generalised BMCSL %.4f (%+.2f %%)\n", z, ze, ref.Z,
              100.0 * (z / ref.Z - 1.0));
  EXPECT_NEAR(s["packing_fraction"].get<double>(), phi, 1e-9);
  EXPECT_LE(std::abs(z - ref.Z), 3.0 * ze + 0.005 * ref.Z);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_EQ(s["snapshot_overlaps"].get<int>(), 0);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-12);
}
