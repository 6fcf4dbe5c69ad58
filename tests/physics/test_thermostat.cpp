// The Andersen thermostat does not change the equilibrium: hard spheres at phi = 0.45 coupled to
// the bath all along have the pressure of the NVE fluid (Hansen-Goos, which the NVE runs of
// test_hard_spheres.cpp match within 3 standard errors) and the set temperature.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "physics/run_helper.hpp"

using hbtest::run_config;
using hbtest::sphere_config;
using hbtest::z_hansen_goos;

TEST(ThermostatPhysics, AndersenHardSpheresHaveTheNveEquationOfState) {
  const std::string cfg = sphere_config(2048, 0.45, 5.0, 60.0, 4, 0.25) +
                          "[thermostat]\ntype = \"andersen\"\nrate = 0.5\nduring = \"always\"\n"
                          "[observables]\ninterval = 0.0\ngr_interval = 0.0\n";
  const auto s = run_config("andersen", cfg, {"output.trajectory=false"});
  const double z = s["Z"], ze = s["Z_error"], zref = z_hansen_goos(0.45);
  const double T = s["temperature"], Te = s["temperature_error"];
  std::printf("  Andersen (rate 0.5): Z = %.5f +- %.5f (Hansen-Goos %.5f, %.2f sigma), T = %.5f +- %.5f, "
              "%g thermostat events\n", z, ze, zref, (z - zref) / ze, T, Te,
              s["events"]["thermostat"].get<double>());
  EXPECT_GT(s["events"]["thermostat"].get<double>(), 0.5 * 0.5 * 2048 * 60.0);
  EXPECT_LT(ze, 0.005 * zref);
  EXPECT_LT(std::abs(z - zref), 3.0 * ze);
  EXPECT_LT(std::abs(T - 1.0), 3.0 * Te);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
}
