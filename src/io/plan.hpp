// From a validated Config to the specification of the initial system, with the checks that
// need the geometry (the lattice start can hold the packing fraction; the box is at least two
// interaction ranges wide). Throws ConfigError naming the key. Used by `hardbody run` and the
// Python module.
#pragma once
#include "io/config.hpp"
#include "system/rigid_setup.hpp"
#include "system/sphere_setup.hpp"

namespace hb {

SphereSystemSpec plan_spheres(const Config& c);
RigidSystemSpec plan_ellipsoids(const Config& c);

}  // namespace hb
