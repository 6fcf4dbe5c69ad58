// One-line JSON description of a shape in the `hardbody contact-time` / `distance` input format
// (used in solver-failure reproducers).
#pragma once
#include <fmt/format.h>

#include <string>

#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"

namespace hb {

inline std::string shape_json(const Sphere& s) {
  return fmt::format("{{\"type\": \"sphere\", \"radius\": {:.17g}}}", s.radius);
}
inline std::string shape_json(const Ellipsoid& e) {
  return fmt::format("{{\"type\": \"ellipsoid\", \"semi_axes\": [{:.17g}, {:.17g}, {:.17g}]}}",
                     e.a, e.b, e.c);
}
inline std::string shape_json(const Superquadric& q) {
  return fmt::format(
      "{{\"type\": \"superquadric\", \"semi_axes\": [{:.17g}, {:.17g}, {:.17g}], "
      "\"exponents\": [{:.17g}, {:.17g}, {:.17g}]}}",
      q.a, q.b, q.c, q.n, q.m, q.p);
}

}  // namespace hb
