// Starts of mixtures and polydisperse systems (any shapes): each body's species and size scale,
// random placement of the bodies at a dilute packing fraction, Maxwell–Boltzmann velocities with
// per-body masses and spins per principal axis, and Lubachevsky–Stillinger growth to the target
// (docs/initial_states.md).
#pragma once
#include <cstdint>
#include <vector>

#include "core/species.hpp"
#include "setup/growth.hpp"
#include "core/box.hpp"
#include "system/hard_sphere_mixture.hpp"
#include "system/rigid_mixture.hpp"
#include "core/state.hpp"

namespace hb {

// A state of total_count(species) bodies in species order (all of species 0, then 1, ...), each
// with its size scale drawn from its species' polydispersity (a stream of its own of `seed`).
State species_state(const SpeciesTable& species, std::uint64_t seed);

// Sum of the body volumes: sum_i v(species_i) scale_i^3.
double body_volume(const SpeciesTable& species, const State& s);

// Places spheres of the given radii uniformly at random in the box, none overlapping an earlier
// one (random sequential addition, candidates from a cell grid); throws std::invalid_argument
// when a body finds no place in 10^4 attempts. Clear of the walls of the box's axes that are not
// periodic, or with container > 0 inside the sphere of that radius about the box centre.
std::vector<Vec3> random_sphere_placement(const std::vector<double>& radii, const Box& box,
                                          std::uint64_t seed, double container = 0.0);

// Gaussian velocities with per-body masses, zero total momentum, rescaled so that
// 2 K / (3 N) = kT exactly (deterministic for the seed).
void maxwell_boltzmann(State& s, double kT, const std::vector<double>& masses, std::uint64_t seed);

// Angular velocities with per-body principal moments `inertia` (body axes; s.q must be set): each
// body-frame component from N(0, kT / I_k), turned to the lab, the rotational kinetic energy
// rescaled to 3 N kT / 2 (deterministic for the seed).
void maxwell_boltzmann_spin(State& s, double kT, const std::vector<Vec3>& inertia, std::uint64_t seed);

// Uniformly random orientations (deterministic for the seed).
void random_orientations(State& s, std::uint64_t seed);

// Rescale the translational and the rotational kinetic energy of `model`'s bodies each to
// 3 N kT / 2; returns the kinetic energy removed (the growth thermostat).
double rescale_to_temperature(State& s, const RigidMixture& model, double kT);

// The dense start of a mixture of any shapes at packing fraction phi (of the target sizes):
// random placement of the bodies' bounding spheres, shrunk by s0, in the target box (s0 the
// smaller of (phi0 / phi)^(1/3) and the scale at which the bounding spheres fill a quarter of the
// box: random addition of spheres jams near 0.38), random orientations, then growth to s = 1 with
// the RigidMixture model and the thermostat at opt.kT. The state is synchronized, time stamps 0.
GrowthResult grow_rigid_mixture(const SpeciesTable& species, double phi, std::uint64_t seed,
                                const GrowthOptions& opt, double eps_d);

// The dense start of a sphere mixture at packing fraction phi (of the target sizes): random
// placement of bodies shrunk by s0 = (phi0 / phi)^(1/3) in the target box, then growth to s = 1
// with the thermostat at opt.kT. The result's state is synchronized, time stamps 0.
GrowthResult grow_sphere_mixture(const SpeciesTable& species, double phi, std::uint64_t seed,
                                 const GrowthOptions& opt);

}  // namespace hb
