#include "setup/box_setup.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "setup/mixture_setup.hpp"

namespace hb {

double total_body_volume(const Config& c) {
  const bool poly = std::any_of(c.species.begin(), c.species.end(), [](const Species& s) { return s.poly.active(); });
  if (poly) return body_volume(c.species, species_state(c.species, c.seed));
  double v = 0.0;
  for (const Species& s : c.species) v += double(s.count) * volume(s.shape);
  return v;
}

double body_length(const Config& c) {
  double d = 0.0;
  for (const Species& s : c.species) d = std::max(d, 2.0 * bounding_radius(s.shape) * s.poly.max_scale());
  return d;
}

double container_volume(double radius) { return 4.0 / 3.0 * kPi * radius * radius * radius; }

double container_radius_for(const Config& c, double phi) {
  return std::cbrt(total_body_volume(c) / phi / (4.0 / 3.0 * kPi));
}

double phi_volume(const Config& c, const Box& box) {
  return c.boundaries.walls.container() ? container_volume(c.boundaries.walls.sphere_radius) : box.volume();
}

double packing_fraction(const Config& c) {
  const WallSpec& w = c.boundaries.walls;
  if (w.container()) return total_body_volume(c) / container_volume(w.sphere_radius);
  return c.packing_fraction;
}

Box box_for(const Config& c) {
  Box box;
  const WallSpec& w = c.boundaries.walls;
  if (w.container()) {
    box.L = Vec3::Constant(2.0 * w.sphere_radius);
    box.periodic = {false, false, false};
    return box;
  }
  const Vec3& a = c.boundaries.aspect;
  const double V = total_body_volume(c) / c.packing_fraction;
  box.L = a * std::cbrt(V / (a.x() * a.y() * a.z()));
  for (int k = 0; k < 3; ++k) box.periodic[k] = !w.planes[k];
  return box;
}

std::optional<BoundaryProblem> boundary_problem(const Config& c) {
  const WallSpec& w = c.boundaries.walls;
  if (!w.any() && c.boundaries.aspect == Vec3::Ones()) return std::nullopt;  // the builder checks the cube
  const double d = body_length(c);
  if (w.container()) {
    if (w.sphere_radius < 2.0 * d)
      return BoundaryProblem{"walls.sphere", fmt::format("the container's radius {:.6g} is below two body lengths "
                                                         "({:.6g}: twice the largest bounding diameter {:.6g})",
                                                         w.sphere_radius, 2.0 * d, d)};
    return std::nullopt;
  }
  const Box box = box_for(c);
  static constexpr const char* kAxis[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    if (w.planes[k] && box.L[k] < 2.0 * d)
      return BoundaryProblem{
          "walls.planes",
          fmt::format("the box side along {} between the walls is {:.6g}, shorter than two body lengths ({:.6g}: "
                      "twice the largest bounding diameter {:.6g}); use more bodies, a lower packing fraction or "
                      "a larger box.aspect along {}", kAxis[k], box.L[k], 2.0 * d, d, kAxis[k])};
  if (c.boundaries.aspect != Vec3::Ones())
    for (int k = 0; k < 3; ++k)
      if (box.periodic[k] && box.L[k] < 2.0 * d)
        return BoundaryProblem{
            "box.aspect",
            fmt::format("the periodic box side along {} is {:.6g} (sides {:.6g} x {:.6g} x {:.6g}), shorter than two "
                        "body lengths ({:.6g}, the minimum image); use more bodies or a larger aspect along {}",
                        kAxis[k], box.L[k], box.L.x(), box.L.y(), box.L.z(), 2.0 * d, kAxis[k])};
  return std::nullopt;
}

void check_boundaries(const Config& c) {
  if (const auto p = boundary_problem(c))
    throw ConfigError(fmt::format("{}: key '{}': {}", c.source, p->key, p->what));
}

}  // namespace hb
