// Hard spheres between two hard walls (a slit 15 diameters wide, phi = 0.35): the contact theorem
// (beta P_wall = density of centres at contact) and the wall pressure against the bulk equation
// of state at the density of the middle of the slit. Hard spheres in a spherical container: the
// contact theorem at a curved wall. Superquadrics in a spherical container: no overlap, no body
// through the wall, energy conserved.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "physics/run_helper.hpp"

using hbtest::run_config;
using hbtest::z_hansen_goos;

namespace {

// Mean total density of the z profile over |z| <= half_width (density_profile.tsv).
double middle_density(const std::string& path, double half_width) {
  std::ifstream in(path);
  std::string line;
  double sum = 0.0;
  int n = 0;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.rfind("axis", 0) == 0) continue;
    std::stringstream ss(line);
    std::string axis;
    double pos, rho;
    ss >> axis >> pos >> rho;
    if (axis == "z" && std::abs(pos) <= half_width) sum += rho, ++n;
  }
  return n ? sum / n : 0.0;
}

TEST(WallPhysics, HardSpheresInASlitObeyTheContactTheoremAndTheBulkEquationOfState) {
  const std::string cfg =
      "[system]\nparticles = 1000\npacking_fraction = 0.35\nseed = 3\n"
      "[shape]\ntype = \"sphere\"\nradius = 0.5\n"
      "[box]\naspect = [1.0, 1.0, 1.5]\n[walls]\nplanes = [\"z\"]\n"
      "[run]\nequilibrate_time = 20.0\ntime = 1500.0\n"
      "[output]\nlog_interval = 10.0\nsnapshot_interval = 0.25\ntrajectory = false\n"
      "[observables]\ninterval = 0.0\ngr_interval = 0.0\n";
  const auto s = run_config("slit", cfg);
  const double p = s["wall_pressure"], pe = s["wall_pressure_error"];
  const double rc = s["wall_contact_density"], rce = s["wall_contact_density_error"];
  const double Lz = s["box"][2];
  // the middle of the slit: more than 4.5 diameters from both walls (|z| <= 3 for Lz = 15); the
  // layering next to the walls is still ~2 % at 3.5 diameters at phi = 0.35 (measured: the mean
  // over |z| <= 4.5 is 0.2 % low, which moves the Hansen-Goos pressure by 0.6 %)
  const std::string dir = (hbtest::test_dir("slit") / "out").string();
  const double rho_mid = middle_density(dir + "/density_profile.tsv", 0.5 * Lz - 4.5);
  const double phi_mid = M_PI / 6.0 * rho_mid;
  const double p_hg = rho_mid * z_hansen_goos(phi_mid);
  std::printf("  slit: beta P_wall = %.5f +- %.5f, contact density %.5f +- %.5f (%.2f sigma); "
              "middle rho = %.5f (phi %.4f), Hansen-Goos beta P = %.5f (%.2f %%)\n",
              p, pe, rc, rce, (p - rc) / std::hypot(pe, rce), rho_mid, phi_mid, p_hg,
              100.0 * (p - p_hg) / p_hg);
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_EQ(s["wall_penetrations"].get<int>(), 0);
  // ~1.1e7 collisions and 4.5e5 wall bounces: rounding-level drift (measured 2.0e-12)
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-11);
  EXPECT_LT(pe, 0.01 * p) << "the wall pressure is not measured well enough to test";
  // contact theorem: within 3 combined standard errors
  EXPECT_LT(std::abs(p - rc), 3.0 * std::hypot(pe, rce));
  // the bulk equation of state at the middle density: within 3 standard errors + 0.3 %
  EXPECT_LT(std::abs(p - p_hg), 3.0 * pe + 0.003 * p_hg);
}

// In a spherical container of radius R the centres touch the wall at R_c = R - sigma / 2 and the
// total force on it is kT rho(R_c) 4 pi R_c^2 (observers/wall_observables.hpp): per unit wall area
// beta P_wall (R / R_c)^2 = rho(R_c).
TEST(WallPhysics, HardSpheresInASphericalContainerObeyTheContactTheorem) {
  const std::string cfg =
      "[system]\nparticles = 500\nseed = 5\n"
      "[shape]\ntype = \"sphere\"\nradius = 0.5\n"
      "[walls]\nsphere = 6.0\n"
      "[run]\nequilibrate_time = 20.0\ntime = 600.0\n"
      "[output]\nlog_interval = 10.0\nsnapshot_interval = 0.25\ntrajectory = false\n"
      "[observables]\ninterval = 0.0\ngr_interval = 0.0\n";
  const auto s = run_config("container-spheres", cfg);
  const double p = s["wall_pressure"], pe = s["wall_pressure_error"];
  const double rc = s["wall_contact_density"], rce = s["wall_contact_density_error"];
  const double f = std::pow(6.0 / 5.5, 2);  // (R / R_c)^2
  std::printf("  container: phi %.4f, beta P_wall = %.5f +- %.5f, x (R/R_c)^2 = %.5f; contact density "
              "%.5f +- %.5f (%.2f sigma); %g collisions, %g wall bounces, drift %.2e\n",
              s["packing_fraction"].get<double>(), p, pe, p * f, rc, rce,
              (p * f - rc) / std::hypot(pe * f, rce), s["events"]["collision"].get<double>(),
              s["events"]["wall"].get<double>(), s["energy_drift"].get<double>());
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_EQ(s["wall_penetrations"].get<int>(), 0);
  EXPECT_LE(s["max_wall_penetration"].get<double>(), 0.0);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-11);
  EXPECT_LT(pe, 0.01 * p) << "the wall pressure is not measured well enough to test";
  EXPECT_LT(std::abs(p * f - rc), 3.0 * std::hypot(pe * f, rce));
}

// Superquadrics (semi-axes [1.2, 0.6, 0.6], exponents [2, 2, 8]) in a spherical container at
// phi = 0.30, grown in it: every snapshot checked for overlaps (surface sampling) and for bodies
// through the wall (the farthest point's distance from the centre), energy conserved
// (examples/walls/superquadrics-container.toml runs the same for 10^6 events).
TEST(WallPhysics, SuperquadricsInASphericalContainerStayInsideWithoutOverlap) {
  const std::string cfg =
      "[system]\nparticles = 128\nseed = 2\n"
      "[shape]\ntype = \"superquadric\"\nsemi_axes = [1.2, 0.6, 0.6]\nexponents = [2.0, 2.0, 8.0]\n"
      "[walls]\nsphere = 6.27\n"
      "[init]\nmethod = \"grow\"\nphi0 = 0.05\ngrowth_rate = 0.05\n"
      "[run]\nequilibrate_time = 2.0\ntime = 30.0\n[neighbors]\nmethod = \"nnl\"\n"
      "[output]\nlog_interval = 1.0\nsnapshot_interval = 1.0\ntrajectory = false\n"
      "[observables]\ninterval = 0.0\ngr_interval = 0.0\n";
  const auto s = run_config("container-superquadrics", cfg);
  std::printf("  superquadrics in a container: phi %.4f, %g collisions, %g wall bounces, %g rebuilds, "
              "drift %.2e, deepest %.2e, beta P_wall %.4f\n",
              s["packing_fraction"].get<double>(), s["events"]["collision"].get<double>(),
              s["events"]["wall"].get<double>(), s["events"].value("nnl_rebuild", 0.0),
              s["energy_drift"].get<double>(), s["max_wall_penetration"].get<double>(),
              s["wall_pressure"].get<double>());
  EXPECT_EQ(s["overlaps"].get<int>(), 0);
  EXPECT_EQ(s["wall_penetrations"].get<int>(), 0);
  EXPECT_LE(s["max_wall_penetration"].get<double>(), 0.0);
  EXPECT_GT(s["events"]["wall"].get<double>(), 1000.0);
  EXPECT_LE(std::abs(s["energy_drift"].get<double>()), 1e-12);
}

}  // namespace
