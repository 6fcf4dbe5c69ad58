// Building a hard-sphere system: FCC lattice at a packing fraction, MB velocities.
#pragma once
#include <cmath>
#include <stdexcept>

#include "system/hard_spheres.hpp"
#include "system/init.hpp"
#include "system/simulation.hpp"

namespace hb {

struct SphereSystemSpec {
  std::size_t n = 4000;
  double phi = 0.45;
  double sigma = 1.0;  // diameter
  double mass = 1.0;
  double kT = 1.0;
  std::uint64_t seed = 1;
};

inline Box cubic_box_for(std::size_t n, double body_volume, double phi) {
  Box box;
  const double L = std::cbrt(double(n) * body_volume / phi);
  box.L = Vec3(L, L, L);
  return box;
}

inline Simulation<HardSpheres> make_hard_sphere_simulation(const SphereSystemSpec& s) {
  const double v = kPi / 6.0 * s.sigma * s.sigma * s.sigma;
  const Box box = cubic_box_for(s.n, v, s.phi);
  State st;
  st.resize(s.n);
  double nn = 0.0;
  st.r = fcc_lattice(s.n, box.L.x(), &nn);
  if (nn < s.sigma) throw std::invalid_argument("packing fraction too high for the FCC lattice");
  maxwell_boltzmann(st, s.kT, s.mass, s.seed);
  return Simulation<HardSpheres>(box, std::move(st), HardSpheres{s.sigma, s.mass});
}

}  // namespace hb
