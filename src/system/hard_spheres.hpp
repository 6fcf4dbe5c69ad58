// Pair model of identical smooth hard spheres (mass m, diameter sigma) for Simulation.
#pragma once
#include "collision/rigid.hpp"
#include "collision/sphere.hpp"
#include "contact/hard_sphere_time.hpp"
#include "motion/growth_law.hpp"
#include "shapes/ellipsoid.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

struct HardSpheres {
  double sigma = 1.0;  // diameter
  double mass = 1.0;

  double interaction_range() const { return sigma; }

  double contact_time(const State& s, const Box& box, std::uint32_t i, std::uint32_t j,
                      double now) const {
    // body i is at `now`; j is streamed on the fly from its own time stamp.
    const Vec3 dr = box.near_image(s.position_at(j, now) - s.r[i]);
    return sphere_contact_time(dr, s.v[j] - s.v[i], sigma);
  }

  // Batch form used by the event loop: branch-free over the candidate list, so the CPU does not
  // mispredict on which pairs approach (about half of them).
  void contact_times(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                     const Vec3* shifts, std::size_t n, double now, const double* /*horizons*/,
                     double* out) const {
    const Vec3 ri = s.r[i], vi3 = s.v[i];
    const double xi = ri.x(), yi = ri.y(), zi = ri.z();
    const double ui = vi3.x(), vi = vi3.y(), wi = vi3.z();
    const double s2 = sigma * sigma;
    for (std::size_t k = 0; k < n; ++k) {
      const std::uint32_t j = js[k];
      const double dt = now - s.t[j];
      const Vec3& Rj = s.r[j];
      const Vec3& Vj = s.v[j];
      const double du = Vj.x() - ui, dv = Vj.y() - vi, dw = Vj.z() - wi;
      double dx = Rj.x() + Vj.x() * dt - xi;
      double dy = Rj.y() + Vj.y() * dt - yi;
      double dz = Rj.z() + Vj.z() * dt - zi;
      if (shifts) {
        dx += shifts[k].x(), dy += shifts[k].y(), dz += shifts[k].z();
      } else {
        const Vec3 d = box.near_image(Vec3(dx, dy, dz));
        dx = d.x(), dy = d.y(), dz = d.z();
      }
      const double b = dx * du + dy * dv + dz * dw;
      const double c = dx * dx + dy * dy + dz * dz - s2;
      const double a = du * du + dv * dv + dw * dw;
      const double disc = b * b - a * c;
      const double t = c / (std::sqrt(std::max(disc, 0.0)) - b);
      const double tc = c <= 0.0 ? 0.0 : t;
      out[k] = (b < 0.0 && disc >= 0.0 && j != i) ? tc : kInf;
    }
  }

  // Body i for the single-body event sources (walls): a smooth sphere (its moment of inertia is
  // never used: no impulse on a smooth sphere has a torque).
  static constexpr bool kBodyEvents = true;
  template <class F>
  void visit_body(const State&, std::uint32_t, double, F&& f) const {
    f(Sphere{0.5 * sigma}, MassProperties::spherical_top(mass, 0.1 * mass * sigma * sigma), BodyGrowth{}, kInf);
  }

  CollisionRecord collide(State& s, const Box& box, std::uint32_t i, std::uint32_t j,
                          double now) const {
    CollisionRecord rec;
    rec.a = i;
    rec.b = j;
    rec.r_AB = box.minimum_image(s.r[j] - s.r[i]);
    rec.n = rec.r_AB.normalized();
    const double e0 = s.v[i].squaredNorm() + s.v[j].squaredNorm();
    rec.J = collide_spheres(s.v[i], s.v[j], rec.n, 1.0 / mass, 1.0 / mass);
    rec.dE = 0.5 * mass * (s.v[i].squaredNorm() + s.v[j].squaredNorm() - e0);
    return rec;
  }
};

}  // namespace hb
