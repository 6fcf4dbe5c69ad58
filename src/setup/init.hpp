// Initial configurations: lattice positions and Maxwell–Boltzmann velocities.
#pragma once
#include <cstdint>
#include <vector>

#include "math/types.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

// n sites of a cubic FCC lattice of m^3 unit cells filling a cube of side L, m the smallest
// integer with 4 m^3 >= n; sites are taken in lattice order. Returns the nearest-neighbour
// distance through `nn_distance`.
std::vector<Vec3> fcc_lattice(std::size_t n, double L, double* nn_distance = nullptr);

// Largest packing fraction at which n spheres fit the lattice of fcc_lattice (touching).
double fcc_max_packing_fraction(std::size_t n);

// Gaussian velocities (mass m), zero total momentum, rescaled so that the translational
// temperature 2 K / (3 N) equals kT exactly. Deterministic for a given seed.
void maxwell_boltzmann(State& s, double kT, double mass, std::uint64_t seed);

// Random angular velocities for bodies with scalar moment of inertia I (spherical tops),
// rescaled so that the rotational temperature 2 K_rot / (3 N) equals kT.
void maxwell_boltzmann_spin(State& s, double kT, double inertia, std::uint64_t seed);
// Principal moments `inertia` along the body axes (s.q must be set): each body-frame component
// of the angular velocity drawn from N(0, kT / I_k), then turned to the lab; the total
// rotational kinetic energy rescaled to 3 N kT / 2. Equal moments: the spherical-top draw above.
void maxwell_boltzmann_spin(State& s, double kT, const Vec3& inertia, std::uint64_t seed);

double kinetic_energy(const State& s, double mass);
Vec3 total_momentum(const State& s, double mass);

}  // namespace hb
