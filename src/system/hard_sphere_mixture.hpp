// Pair model of smooth hard spheres of several species and sizes (binary mixtures,
// polydispersity), optionally growing (Lubachevsky–Stillinger starts). Body i has the radius
// R_i = radius[species_i] scale_i s(t) and the mass m_i = mass[species_i] scale_i^3, with s(t) the
// common growth law (1 for a plain run). The one-species run keeps the faster HardSpheres
// (hard_spheres.hpp); both agree for one species (tests/system/test_hard_sphere_mixture.cpp).
//
// Contact time. With dr = r_j - r_i, dv = v_j - v_i at `now`, sigma0 = R_i + R_j at scale 1,
// sigma(now + t) = sigma0 (s + g t) (s = s(now), g = ds/dt), contact is |dr + dv t| = sigma:
//     A t^2 + 2 B t + C = 0,  A = dv.dv - (sigma0 g)^2,  B = dr.dv - sigma0^2 s g,
//     C = dr.dr - (sigma0 s)^2.
// The gap closes at t = 0 iff B < 0 (d/dt of |dr + dv t|^2 - sigma^2 is 2B). For C > 0 and B < 0
// the first root is t = C / (sqrt(B^2 - A C) - B) if B^2 >= A C (always when A <= 0; the classic
// rigid case is g = 0); for B >= 0 a root exists only if A < 0 (the pair recedes slower than it
// grows): t = (B + sqrt(B^2 - A C)) / (-A), the later root (also for a pair that touches to
// rounding, C <= 0, just after its collision). Both forms are free of cancellation. Contacts after t_stop (where the law changes) are not reported.
// Collision. The rule of collision/sphere.hpp with grow = sigma0 g (the sum of the two surfaces'
// outward speeds): the gap opens after the collision at the rate it closed.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "collision/sphere.hpp"
#include "core/species.hpp"
#include "collision/rigid.hpp"
#include "motion/growth_law.hpp"
#include "shapes/ellipsoid.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

struct HardSphereMixture {
  std::vector<double> radius;  // per species, at scale 1
  std::vector<double> mass;    // per species, at scale 1
  double max_body_radius = 0.0;  // bound of R_i at s = 1 (species radius x largest scale drawn)
  GrowthLaw law{};

  // The species must all be spheres.
  static HardSphereMixture of(const SpeciesTable& species, GrowthLaw law = {}) {
    HardSphereMixture m;
    for (const Species& sp : species) {
      m.radius.push_back(std::get<Sphere>(sp.shape).radius);
      m.mass.push_back(sp.mass);
      m.max_body_radius = std::max(m.max_body_radius, m.radius.back() * sp.poly.max_scale());
    }
    m.law = law;
    return m;
  }

  double body_radius(const State& s, std::size_t i) const { return radius[s.species[i]] * s.scale[i]; }
  double body_mass(const State& s, std::size_t i) const { return mass[s.species[i]] * sqr(s.scale[i]) * s.scale[i]; }
  double interaction_range() const {
    const double smax = law.growing() ? std::max(law.s0, law.final_scale()) : law.s0;
    return 2.0 * max_body_radius * smax;
  }

  void contact_times(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                     const Vec3* shifts, std::size_t n, double now, const double* /*horizons*/,
                     double* out) const {
    const double sc = law.scale_at(now), g = law.rate_at(now);
    const double window = now < law.t_stop ? law.t_stop - now : kInf;  // the law changes there
    const double Ri = body_radius(s, i);
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t j = js[k];
      out[k] = kInf;
      if (j == i) continue;
      const Vec3 rj = s.position_at(j, now);
      const Vec3 dr = shifts ? Vec3(rj + shifts[k] - s.r[i]) : box.near_image(rj - s.r[i]);
      const Vec3 dv = s.v[j] - s.v[i];
      const double sigma0 = Ri + body_radius(s, j);
      const double A = dv.squaredNorm() - sqr(sigma0 * g);
      const double B = dr.dot(dv) - sqr(sigma0) * sc * g;
      const double C = dr.squaredNorm() - sqr(sigma0 * sc);
      double t = kInf;
      if (B < 0.0) {
        if (C <= 0.0) {
          t = 0.0;  // touching (to rounding) and closing: collide now
        } else {
          const double disc = B * B - A * C;
          if (disc >= 0.0) t = C / (std::sqrt(disc) - B);
        }
      } else if (A < 0.0) {  // receding slower than growing: the later root
        const double disc = B * B - A * C;
        if (disc >= 0.0) t = (B + std::sqrt(disc)) / (-A);
      }
      if (t <= window) out[k] = t;
    }
  }

  // Body i for the single-body event sources (walls): a smooth sphere of radius body_radius
  // scaled by the growth law (its moment of inertia is never used).
  static constexpr bool kBodyEvents = true;
  template <class F>
  void visit_body(const State& s, std::uint32_t i, double now, F&& f) const {
    const double R = body_radius(s, i), m = body_mass(s, i);
    f(Sphere{R}, MassProperties::spherical_top(m, 0.4 * m * R * R),
      BodyGrowth{law.scale_at(now), law.rate_at(now)}, now < law.t_stop ? law.t_stop : kInf);
  }

  CollisionRecord collide(State& s, const Box& box, std::uint32_t i, std::uint32_t j, double now) const {
    CollisionRecord rec;
    rec.a = i;
    rec.b = j;
    rec.r_AB = box.minimum_image(s.r[j] - s.r[i]);
    rec.n = rec.r_AB.normalized();
    const double mi = body_mass(s, i), mj = body_mass(s, j);
    const double e0 = mi * s.v[i].squaredNorm() + mj * s.v[j].squaredNorm();
    const double grow = (body_radius(s, i) + body_radius(s, j)) * law.rate_at(now);
    rec.J = collide_spheres(s.v[i], s.v[j], rec.n, 1.0 / mi, 1.0 / mj, grow);
    rec.dE = 0.5 * (mi * s.v[i].squaredNorm() + mj * s.v[j].squaredNorm() - e0);
    return rec;
  }

  double kinetic_energy(const State& s) const {
    double k = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) k += body_mass(s, i) * s.v[i].squaredNorm();
    return 0.5 * k;
  }

};

}  // namespace hb
