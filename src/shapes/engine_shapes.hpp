// The shapes `hardbody run` simulates (config shape.type). The distance and contact-time solvers
// are compiled once for every pair of them (the end of geometry/distance.hpp); any other shape
// model (test shapes, the scaled shapes of growth runs) is instantiated where it is used.
#pragma once

#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

// M(args..., S) for every engine shape S.
#define HB_FOR_EACH_ENGINE_SHAPE(M, ...) \
  M(__VA_ARGS__, Sphere)                  \
  M(__VA_ARGS__, Ellipsoid)               \
  M(__VA_ARGS__, Superquadric)
