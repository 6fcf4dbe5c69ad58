// Building a system of hard rigid bodies (spherical tops): ellipsoids and superquadrics.
// Lattice start: an FCC lattice of aligned bodies obtained from a lattice of aligned unit bodies
// K (semi-axes 1: the unit sphere for ellipsoids, |x|^n + |y|^m + |z|^p <= 1 for superquadrics)
// by the affine map diag(a, b, c), which maps touching unit bodies to touching bodies, so any
// packing fraction below the lattice's limit is overlap-free.  Aligned copies K and K + d of a
// centrally symmetric convex body overlap iff d lies inside 2K, so the unit-body lattice with
// constant a0 (neighbours at a0/2 (h, k, l), h + k + l even) is overlap-free iff
// a0 >= 4 s(h, k, l) for every lattice vector, s(v) = the ray scale with s v on the surface of K
// (K.ray_surface(v) = s v); the nearest vectors (1, 1, 0), ... bind (for the sphere a0 = 2 sqrt 2,
// for a cube-like p -> inf superquadric a0 -> 4).  Maxwell–Boltzmann velocities and spins; the
// lattice is melted by the run's equilibration.
//
// Inertia: every body is a spherical top with the scalar moment of inertia RigidSystemSpec::
// inertia; the config default (io/config.cpp) is the paper's convention I = 2/5 m r^2 with r the
// smallest semi-axis (ERRATA 8), for ellipsoids and superquadrics alike.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "math/morton.hpp"
#include "neighbors/cell_neighbors.hpp"
#include "neighbors/obb_neighbors.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"
#include "setup/init.hpp"
#include "system/rigid_bodies.hpp"
#include "system/simulation.hpp"

namespace hb {

struct RigidSystemSpec {
  std::size_t n = 256;
  double phi = 0.3;
  Vec3 semi_axes = Vec3(1.0, 0.5, 0.5);
  double mass = 1.0;
  Vec3 inertia = Vec3::Constant(0.1);  // principal moments along the body axes (equal: spherical top)
  double kT = 1.0;
  std::uint64_t seed = 1;
  double eps_d = 1e-5;
  Vec3 exponents = Vec3(2.0, 2.0, 2.0);  // superquadrics only
  bool cubic_start = false;  // builder: grow from a random placement in a cubic box (the stretched
                             // lattice of N bodies would be thinner than two body lengths)
};

using EllipsoidCellSim = Simulation<RigidBodies<Ellipsoid>, CellNeighbors>;
using EllipsoidListSim = Simulation<RigidBodies<Ellipsoid>, ObbNeighbors<Ellipsoid>>;
using SuperquadricCellSim = Simulation<RigidBodies<Superquadric>, CellNeighbors>;
using SuperquadricListSim = Simulation<RigidBodies<Superquadric>, ObbNeighbors<Superquadric>>;

// The unit body K of the lattice start: its volume and the smallest FCC lattice constant at which
// aligned copies do not overlap (see the header).  Default: the unit sphere.
struct UnitBody {
  double volume = 4.0 / 3.0 * kPi;
  double a0_min = 2.0 * std::sqrt(2.0);
};
template <Shape S>
UnitBody unit_body(const S& unit) {
  UnitBody u;
  u.volume = unit.volume();
  u.a0_min = 0.0;
  // every FCC vector (h, k, l) with h + k + l even in [-2, 2]^3 (the binding ones are nearest)
  for (int h = -2; h <= 2; ++h)
    for (int k = -2; k <= 2; ++k)
      for (int l = -2; l <= 2; ++l) {
        if ((h + k + l) % 2 != 0 || (h == 0 && k == 0 && l == 0)) continue;
        const Vec3 v(h, k, l);
        const double s = unit.ray_surface(v).norm() / v.norm();
        u.a0_min = std::max(u.a0_min, 4.0 * s * (1.0 + 1e-12));
      }
  return u;
}
inline Superquadric superquadric_shape(const RigidSystemSpec& s) {
  return Superquadric{s.semi_axes.x(), s.semi_axes.y(), s.semi_axes.z(),
                      s.exponents.x(), s.exponents.y(), s.exponents.z()};
}
inline UnitBody superquadric_unit_body(const RigidSystemSpec& s) {
  return unit_body(Superquadric{1.0, 1.0, 1.0, s.exponents.x(), s.exponents.y(), s.exponents.z()});
}

// FCC cell counts (mx, my, mz) with 4 mx my mz >= n that make the stretched box closest to a
// cube, and the largest packing fraction that lattice allows.
struct StretchedLattice {
  std::array<int, 3> m{1, 1, 1};
  double phi_max = 0.0;
};
inline StretchedLattice stretched_lattice(std::size_t n, const Vec3& s, const UnitBody& unit = {}) {
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
          // unit bodies touching at lattice constant a0_min (2 sqrt(2) for spheres)
          best.phi_max = double(n) * unit.volume / (std::pow(unit.a0_min, 3) * mx * my * mz);
        }
      }
  if (best_aniso == kInf) throw std::invalid_argument("no lattice for this number of bodies");
  return best;
}

// Lattice constant of the unit-body lattice with cell counts m that gives packing fraction phi.
inline double lattice_constant(std::size_t n, double phi, const std::array<int, 3>& m,
                               const UnitBody& unit) {
  return std::cbrt(double(n) * unit.volume / (phi * m[0] * m[1] * m[2]));
}

inline State lattice_start(const RigidSystemSpec& s, const UnitBody& unit, Box& box) {
  const StretchedLattice lat = stretched_lattice(s.n, s.semi_axes, unit);
  if (s.phi > lat.phi_max * (1.0 - 1e-12))
    throw std::invalid_argument("packing fraction too high for the lattice start");
  const auto& m = lat.m;
  const double a0 = lattice_constant(s.n, s.phi, m, unit);
  box.L = Vec3(s.semi_axes.x() * a0 * m[0], s.semi_axes.y() * a0 * m[1], s.semi_axes.z() * a0 * m[2]);
  static const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  // The first n sites in row order (x fastest), numbered along the Morton curve of their
  // half-cell indices: neighbours get nearby numbers in all three directions, so the data of the
  // bodies a prediction reads sit close in memory (row order puts the neighbours along z
  // 4 mx my numbers apart).  At N = 256000 ellipsoids the gain is small: new / old 0.84-1.01 in
  // four alternating rounds, median 0.97 (docs/benchmarks/README.md).
  std::vector<Vec3> site;
  std::vector<std::uint64_t> key;
  site.reserve(s.n);
  key.reserve(s.n);
  for (int z = 0; z < m[2] && site.size() < s.n; ++z)
    for (int y = 0; y < m[1] && site.size() < s.n; ++y)
      for (int x = 0; x < m[0] && site.size() < s.n; ++x)
        for (int b = 0; b < 4 && site.size() < s.n; ++b) {
          site.emplace_back(s.semi_axes.x() * a0 * (x + basis[b][0] + 0.25),
                            s.semi_axes.y() * a0 * (y + basis[b][1] + 0.25),
                            s.semi_axes.z() * a0 * (z + basis[b][2] + 0.25));
          key.push_back(morton_code(std::uint32_t(2 * x + 2 * basis[b][0]),
                                    std::uint32_t(2 * y + 2 * basis[b][1]),
                                    std::uint32_t(2 * z + 2 * basis[b][2])));
        }
  const std::vector<std::uint32_t> order = sorting_permutation(key);
  State st;
  st.resize(s.n);
  for (std::size_t k = 0; k < s.n; ++k) st.r[k] = site[order[k]];
  maxwell_boltzmann(st, s.kT, s.mass, s.seed);
  maxwell_boltzmann_spin(st, s.kT, s.inertia, s.seed);
  return st;
}

inline State ellipsoid_start(const RigidSystemSpec& s, Box& box) { return lattice_start(s, UnitBody{}, box); }
inline State superquadric_start(const RigidSystemSpec& s, Box& box) {
  return lattice_start(s, superquadric_unit_body(s), box);
}

inline RigidBodies<Ellipsoid> ellipsoid_model(const RigidSystemSpec& s) {
  RigidBodies<Ellipsoid> m{Ellipsoid{s.semi_axes.x(), s.semi_axes.y(), s.semi_axes.z()},
                           MassProperties::principal(s.mass, s.inertia), s.eps_d};
  return m;
}

inline RigidBodies<Superquadric> superquadric_model(const RigidSystemSpec& s) {
  return RigidBodies<Superquadric>{superquadric_shape(s),
                                   MassProperties::principal(s.mass, s.inertia), s.eps_d};
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
