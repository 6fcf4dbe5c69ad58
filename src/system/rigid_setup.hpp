// Building a system of hard ellipsoids (spherical tops): an FCC lattice of aligned bodies,
// obtained from a lattice of unit spheres by the affine map diag(a, b, c) (which maps touching
// spheres to touching ellipsoids, so any packing fraction below the lattice's limit is
// overlap-free), Maxwell–Boltzmann velocities and spins. The lattice is melted by the run's
// equilibration.
#pragma once
#include <array>
#include <cmath>
#include <stdexcept>

#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "shapes/ellipsoid.hpp"
#include "system/init.hpp"
#include "system/rigid_bodies.hpp"
#include "system/simulation.hpp"

namespace hb {

struct RigidSystemSpec {
  std::size_t n = 256;
  double phi = 0.3;
  Vec3 semi_axes = Vec3(1.0, 0.5, 0.5);
  double mass = 1.0;
  double inertia = 0.1;  // scalar moment of inertia (spherical top)
  double kT = 1.0;
  std::uint64_t seed = 1;
  double eps_d = 1e-5;
};

using EllipsoidCellSim = Simulation<RigidBodies<Ellipsoid>, CellNeighbors>;
using EllipsoidListSim = Simulation<RigidBodies<Ellipsoid>, ObbNeighbors<Ellipsoid>>;

// FCC cell counts (mx, my, mz) with 4 mx my mz >= n that make the stretched box closest to a
// cube, and the largest packing fraction that lattice allows.
struct StretchedLattice {
  std::array<int, 3> m{1, 1, 1};
  double phi_max = 0.0;
};
inline StretchedLattice stretched_lattice(std::size_t n, const Vec3& s) {
  StretchedLattice best;
  double best_aniso = kInf;
  const int top = static_cast<int>(std::ceil(std::cbrt(double(n) / 4.0) * 4.0)) + 2;
  for (int mx = 1; mx <= top; ++mx)
    for (int my = 1; my <= top; ++my)
      for (int mz = 1; mz <= top; ++mz) {
        const double sites = 4.0 * mx * my * mz;
        if (sites < double(n) || sites > 2.0 * double(n) + 32.0) continue;
        const Vec3 side(s.x() * mx, s.y() * my, s.z() * mz);
        // prefer near-cubic boxes, then fewer empty sites
        const double aniso = side.maxCoeff() / side.minCoeff() + 0.5 * (sites - double(n)) / double(n);
        if (aniso < best_aniso) {
          best_aniso = aniso;
          best.m = {mx, my, mz};
          // unit spheres touching at lattice constant a0 = 2 sqrt(2)
          best.phi_max = double(n) * (4.0 / 3.0 * kPi) / (std::pow(2.0 * std::sqrt(2.0), 3) * mx * my * mz);
        }
      }
  if (best_aniso == kInf) throw std::invalid_argument("no lattice for this number of bodies");
  return best;
}

inline State ellipsoid_start(const RigidSystemSpec& s, Box& box) {
  const StretchedLattice lat = stretched_lattice(s.n, s.semi_axes);
  if (s.phi > lat.phi_max * (1.0 - 1e-12))
    throw std::invalid_argument("packing fraction too high for the lattice start");
  const auto& m = lat.m;
  // lattice constant of the unit-sphere lattice giving the packing fraction
  const double a0 = std::cbrt(double(s.n) * (4.0 / 3.0 * kPi) / (s.phi * m[0] * m[1] * m[2]));
  box.L = Vec3(s.semi_axes.x() * a0 * m[0], s.semi_axes.y() * a0 * m[1], s.semi_axes.z() * a0 * m[2]);
  static const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  State st;
  st.resize(s.n);
  std::size_t k = 0;
  for (int z = 0; z < m[2] && k < s.n; ++z)
    for (int y = 0; y < m[1] && k < s.n; ++y)
      for (int x = 0; x < m[0] && k < s.n; ++x)
        for (int b = 0; b < 4 && k < s.n; ++b, ++k)
          st.r[k] = Vec3(s.semi_axes.x() * a0 * (x + basis[b][0] + 0.25),
                         s.semi_axes.y() * a0 * (y + basis[b][1] + 0.25),
                         s.semi_axes.z() * a0 * (z + basis[b][2] + 0.25));
  maxwell_boltzmann(st, s.kT, s.mass, s.seed);
  maxwell_boltzmann_spin(st, s.kT, s.inertia, s.seed);
  return st;
}

inline RigidBodies<Ellipsoid> ellipsoid_model(const RigidSystemSpec& s) {
  RigidBodies<Ellipsoid> m{Ellipsoid{s.semi_axes.x(), s.semi_axes.y(), s.semi_axes.z()},
                           MassProperties::spherical_top(s.mass, s.inertia), s.eps_d};
  return m;
}

inline EllipsoidCellSim make_ellipsoid_cell_simulation(const RigidSystemSpec& s) {
  Box box;
  State st = ellipsoid_start(s, box);
  auto model = ellipsoid_model(s);
  const double range = model.interaction_range();
  return EllipsoidCellSim(box, std::move(st), std::move(model), CellNeighbors(range));
}

// Oriented-bounding-box neighbour lists with shell `shell` (paper section 3.3).
inline EllipsoidListSim make_ellipsoid_list_simulation(const RigidSystemSpec& s, double shell) {
  Box box;
  State st = ellipsoid_start(s, box);
  auto model = ellipsoid_model(s);
  ObbNeighbors<Ellipsoid> nb(model.shape, shell);
  return EllipsoidListSim(box, std::move(st), std::move(model), std::move(nb));
}

}  // namespace hb
