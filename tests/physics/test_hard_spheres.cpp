// Hard-sphere physics checks (fixed seeds; tolerances from the measured error bars).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "physics/run_helper.hpp"

using hbtest::run_config;
using hbtest::sphere_config;
using hbtest::z_hansen_goos;

TEST(HardSpherePhysics, HansenGoosFormulaMatchesReferenceTable) {
  std::ifstream in(std::string(HB_SHARED_DIR) + "/reference/hs_eos_computed.csv");
  if (!in) GTEST_SKIP() << "reference table not found";
  std::string line;
  int rows = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line[0] == 'p') continue;
    std::stringstream ss(line);
    std::string phi, rho, zcs, zhg;
    std::getline(ss, phi, ',');
    std::getline(ss, rho, ',');
    std::getline(ss, zcs, ',');
    std::getline(ss, zhg, ',');
    EXPECT_NEAR(z_hansen_goos(std::stod(phi)), std::stod(zhg), 2e-6 * std::stod(zhg)) << phi;
    ++rows;
  }
  EXPECT_GT(rows, 10);
}

// 10^6 collisions: energy and total momentum conserved to 1e-12, no overlaps.
TEST(HardSpherePhysics, ConservesEnergyAndMomentumOverAMillionCollisions) {
  const auto s = run_config("conserve", sphere_config(4000, 0.45, 0.0, 1e6, 11, 1.0),
                            {"run.max_collisions=1000000", "output.trajectory=false"});
  EXPECT_EQ(s["collisions"].get<std::uint64_t>(), 1000000u);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-12);
  EXPECT_LE(s["momentum_drift"].get<double>(), 1e-12);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_GT(s["min_distance"].get<double>(), -1e-10);
}

struct EosCase {
  double phi;
  double time;
};

class HardSphereEos : public ::testing::TestWithParam<EosCase> {};

// Z within 3 standard errors of Hansen-Goos with standard error <= 0.3 %; collision rate
// within 0.5 % of the Enskog rate 24 phi g / sqrt(pi) with g = (Z_HG - 1) / (4 phi).
TEST_P(HardSphereEos, PressureAndCollisionRateMatchHansenGoos) {
  const auto [phi, time] = GetParam();
  const auto s = run_config("eos" + std::to_string(int(phi * 100)),
                            sphere_config(4000, phi, 5.0, time, 2, 0.05));
  const double z = s["Z"], ze = s["Z_error"], zref = z_hansen_goos(phi);
  RecordProperty("Z", std::to_string(z));
  std::printf("phi=%.2f Z=%.5f +- %.5f (HG %.5f, %.2f sigma) rate=%.4f overlaps=%d\n", phi, z, ze,
              zref, (z - zref) / ze, s["collision_rate"].get<double>(), s["overlaps"].get<int>());
  EXPECT_LE(ze / z, 0.003);
  EXPECT_GT(ze, 0.0);
  EXPECT_LE(std::abs(z - zref), 3.0 * ze);
  const double g = (zref - 1.0) / (4.0 * phi);
  const double rate_ref = 24.0 * phi * g / std::sqrt(M_PI);
  EXPECT_LE(std::abs(s["collision_rate"].get<double>() / rate_ref - 1.0), 0.005);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-12);
}

INSTANTIATE_TEST_SUITE_P(States, HardSphereEos,
                         ::testing::Values(EosCase{0.30, 40.0}, EosCase{0.45, 25.0}),
                         [](const auto& info) { return "phi" + std::to_string(int(info.param.phi * 100)); });

// The densest start the issue asks for: FCC at phi = 0.70 runs without overlaps.
TEST(HardSpherePhysics, DenseCrystalRunsWithoutOverlaps) {
  const auto s = run_config("dense", sphere_config(4000, 0.70, 0.5, 1.0, 5, 0.5));
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_GT(s["collisions"].get<std::uint64_t>(), 100000u);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-12);
}

// Dynamics (Lue 2005 via ../shared/reference/hs_dynamics_reference_points.csv): hard spheres
// at rho = 0.5 (phi = 0.2618), N = 1372: mean free time 0.13031 (1 %) and D = 0.247 (8 %).
TEST(HardSpherePhysics, MeanFreeTimeAndDiffusionMatchLue2005) {
  const double phi = M_PI / 6.0 * 0.5;
  std::string cfg = sphere_config(1372, phi, 10.0, 200.0, 21, 1.0);
  cfg += "[observables]\ninterval = 0.1\norigin_every = 10\nmax_lag = 10.0\ngr_interval = 0.0\n";
  const auto s = run_config("dynamics", cfg);
  const double mft = 1.0 / s["collision_rate"].get<double>();
  const double D = s["diffusion_coefficient"];
  std::printf("rho=0.5: mean free time %.5f (ref 0.13031), D %.4f (ref 0.247)\n", mft, D);
  EXPECT_LE(std::abs(mft / 0.13031 - 1.0), 0.01);
  EXPECT_LE(std::abs(D / 0.247 - 1.0), 0.08);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
}
