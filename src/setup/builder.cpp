#include "setup/builder.hpp"

#include <fmt/format.h>

namespace hb {

SphereSystemSpec plan_spheres(const Config& c) {
  SphereSystemSpec p;
  p.n = c.particles;
  p.phi = c.packing_fraction;
  p.sigma = 2.0 * std::get<Sphere>(c.one().shape).radius;
  p.mass = c.one().mass;
  p.kT = c.temperature;
  p.seed = c.seed;
  p.shell = c.neighbors_method == "nnl" ? c.shell : 0.0;
  const Box box = cubic_box_for(c.particles, volume(c.one().shape), c.packing_fraction);
  const double phi_max = fcc_max_packing_fraction(c.particles);
  const bool grow = c.init_method == "grow" && c.packing_fraction > c.init_phi0;  // random start
  if (!grow && c.packing_fraction > phi_max * (1.0 - 1e-12))
    throw ConfigError(fmt::format(
        "{}: key 'system.packing_fraction': {} is too dense for an FCC start with {} particles "
        "(at most {:.4f}; use N = 4 m^3 for up to 0.74)",
        c.source, c.packing_fraction, c.particles, phi_max));
  const double reach = p.sigma + p.shell;
  if (box.L.minCoeff() < 2.0 * reach)
    throw ConfigError(fmt::format(
        "{}: key 'system.particles': {} particles at packing fraction {} give a box of side "
        "{:.3g}, less than two interaction ranges ({:.3g}); use more particles",
        c.source, c.particles, c.packing_fraction, box.L.x(), 2.0 * reach));
  return p;
}

namespace {
// The box of a mixture (of the mean body volume) must hold two interaction ranges.
void check_mixture_box(const Config& c, double range) {
  double v = 0.0;
  for (const Species& sp : c.species) v += double(sp.count) * volume(sp.shape);
  const double L = std::cbrt(v / c.packing_fraction);
  if (L < 2.0 * range)
    throw ConfigError(fmt::format(
        "{}: key 'species': {} bodies at packing fraction {} give a box of side {:.3g}, less than "
        "two interaction ranges ({:.3g}); use more bodies", c.source, c.particles, c.packing_fraction,
        L, 2.0 * range));
}
}  // namespace

HardSphereMixture plan_sphere_mixture(const Config& c) {
  if (c.neighbors_method != "cells")
    throw ConfigError(fmt::format("{}: key 'neighbors.method': sphere mixtures and polydisperse spheres "
                                  "use cell lists (\"cells\"); shell lists need one diameter", c.source));
  HardSphereMixture m = HardSphereMixture::of(c.species);
  check_mixture_box(c, m.interaction_range());
  return m;
}

RigidMixture plan_rigid_mixture(const Config& c) {
  RigidMixture m = RigidMixture::of(c.species, c.eps_d);
  check_mixture_box(c, m.interaction_range());
  return m;
}

RigidSystemSpec plan_rigid(const Config& c) {
  if (c.mixture())
    throw std::logic_error("plan_rigid: one species without polydispersity only");
  const Species& sp = c.one();
  RigidSystemSpec p;
  p.n = c.particles;
  p.phi = c.packing_fraction;
  p.semi_axes = half_extents(sp.shape);
  if (const auto* q = std::get_if<Superquadric>(&sp.shape)) p.exponents = q->exponents();
  p.mass = sp.mass;
  p.inertia = sp.inertia;
  p.kT = c.temperature;
  p.seed = c.seed;
  p.eps_d = c.eps_d;
  const UnitBody unit = std::visit(
      [](const auto& s) {
        if constexpr (std::is_same_v<std::decay_t<decltype(s)>, Sphere>) return UnitBody{};
        else return builder_detail::unit_body_of(s);
      },
      sp.shape);
  const StretchedLattice lat = stretched_lattice(c.particles, p.semi_axes, unit);
  const bool grow = c.init_method == "grow" && c.packing_fraction > c.init_phi0;
  if (grow && c.init_phi0 > lat.phi_max * (1.0 - 1e-12))
    throw ConfigError(fmt::format("{}: key 'init.phi0': {} is too dense for the lattice start",
                                  c.source, c.init_phi0));
  if (!grow && c.packing_fraction > lat.phi_max * (1.0 - 1e-12))
    throw ConfigError(fmt::format(
        "{}: key 'system.packing_fraction': {} is too dense for the lattice start with {} "
        "particles (at most {:.4f})", c.source, c.packing_fraction, c.particles, lat.phi_max));
  const double a0 = lattice_constant(c.particles, c.packing_fraction, lat.m, unit);
  const Vec3 L(p.semi_axes.x() * a0 * lat.m[0], p.semi_axes.y() * a0 * lat.m[1],
               p.semi_axes.z() * a0 * lat.m[2]);
  const double range = 2.0 * bounding_radius(sp.shape);  // the body length
  if (L.minCoeff() < 2.0 * range) {
    // The lattice of aligned bodies stretches the box along the long axis; a growth can start in a
    // cubic box instead (random placement), whose side is limited by the minimum image only.
    const double Lc = std::cbrt(double(c.particles) * volume(sp.shape) / c.packing_fraction);
    const double n_min = std::ceil(std::pow(2.0 * range, 3) * c.packing_fraction / volume(sp.shape));
    if (Lc < 2.0 * range)
      throw ConfigError(fmt::format(
          "{}: key 'system.particles': {} bodies at packing fraction {} fill a cubic box of side "
          "{:.3g}, less than two body lengths ({:.3g}, the minimum image); use at least {} bodies",
          c.source, c.particles, c.packing_fraction, Lc, 2.0 * range, n_min));
    if (c.init_method != "grow")
      throw ConfigError(fmt::format(
          "{}: key 'init.method': the lattice start of {} bodies at packing fraction {} is a box of "
          "sides {:.3g} x {:.3g} x {:.3g}, thinner than two body lengths ({:.3g}); \"grow\" starts in "
          "a cubic box of side {:.3g}", c.source, c.particles, c.packing_fraction, L.x(), L.y(), L.z(),
          2.0 * range, Lc));
    p.cubic_start = true;
  }
  return p;
}

}  // namespace hb
