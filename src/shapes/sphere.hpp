// Sphere{radius}: defined with the ellipsoid (same quadratic form), see ellipsoid.hpp.
#pragma once
#include "shapes/ellipsoid.hpp"
