// Building a hard-sphere system: FCC lattice at a packing fraction, MB velocities.
#pragma once
#include <cmath>
#include <stdexcept>

#include "neighbors/cell_neighbors.hpp"
#include "neighbors/shell_neighbors.hpp"
#include "system/hard_spheres.hpp"
#include "setup/init.hpp"
#include "system/simulation.hpp"

namespace hb {

struct SphereSystemSpec {
  std::size_t n = 4000;
  double phi = 0.45;
  double sigma = 1.0;  // diameter
  double mass = 1.0;
  double kT = 1.0;
  std::uint64_t seed = 1;
  double shell = 0.0;  // neighbour-list shell delta; 0: cell lists
};

inline Box cubic_box_for(std::size_t n, double body_volume, double phi) {
  Box box;
  const double L = std::cbrt(double(n) * body_volume / phi);
  box.L = Vec3(L, L, L);
  return box;
}

using SphereCellSim = Simulation<HardSpheres, CellNeighbors>;
using SphereListSim = Simulation<HardSpheres, ShellNeighbors>;

// FCC lattice at the packing fraction, Maxwell–Boltzmann velocities.
inline State hard_sphere_start(const SphereSystemSpec& s, Box& box) {
  const double v = kPi / 6.0 * s.sigma * s.sigma * s.sigma;
  box = cubic_box_for(s.n, v, s.phi);
  State st;
  st.resize(s.n);
  double nn = 0.0;
  st.r = fcc_lattice(s.n, box.L.x(), &nn);
  if (nn < s.sigma) throw std::invalid_argument("packing fraction too high for the FCC lattice");
  maxwell_boltzmann(st, s.kT, s.mass, s.seed);
  return st;
}

inline SphereCellSim make_hard_sphere_cell_simulation(const SphereSystemSpec& s) {
  Box box;
  State st = hard_sphere_start(s, box);
  return SphereCellSim(box, std::move(st), HardSpheres{s.sigma, s.mass}, CellNeighbors(s.sigma));
}
inline SphereListSim make_hard_sphere_list_simulation(const SphereSystemSpec& s) {
  Box box;
  State st = hard_sphere_start(s, box);
  return SphereListSim(box, std::move(st), HardSpheres{s.sigma, s.mass},
                       ShellNeighbors(s.sigma, s.shell));
}

}  // namespace hb
