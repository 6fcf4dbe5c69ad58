// Pair model of hard rigid bodies of several species: any shapes of the registry, sizes
// (polydispersity), masses and principal moments of inertia (spherical, symmetric and asymmetric
// tops), optionally growing (Lubachevsky–Stillinger starts). The generic path of
// system/rigid_bodies.hpp: one species of identical bodies keeps RigidBodies<S>, and both give
// the same trajectory for one species (tests/system/test_rigid_mixture.cpp).
//
// Body i of species k is the species shape resized by scale_i (shapes/registry.hpp `resized`), of
// mass m_k scale_i^3 and principal moments I_k scale_i^5 (uniform density scaled about the
// centre). Every pair goes through the one generic contact-time solver, dispatched on the two
// shape types (every pair of engine shapes is compiled: contact/contact_time_*.cpp); impulses use
// the inertia tensors (collision/rigid.hpp), free flight the exact free rotation of each body's
// top (motion/motion.hpp; State::tops, set by prepare()).
//
// Growth. With law.growing(), every body is scaled by the common s(t) on top of its own scale
// (contact/contact_time.hpp ScaleLaw: a decorator of the two motions); the collision rule gets
// the outward surface speeds grow = (s'/s) n.r_AB (setup/growth.hpp derives it), and predictions
// stop at law.t_stop, where the law changes. Without growth (the default law) every prediction is
// the rigid one.
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <variant>
#include <vector>

#include "collision/rigid.hpp"
#include "contact/contact_time.hpp"
#include "core/species.hpp"
#include "geometry/distance.hpp"
#include "motion/growth_law.hpp"
#include "shapes/codec.hpp"
#include "shapes/registry.hpp"
#include "core/box.hpp"
#include "system/rigid_bodies.hpp"
#include "core/state.hpp"

namespace hb {

struct RigidMixture {
  static constexpr bool kWindowed = true;  // predictions only up to the body's next neighbour event
  static constexpr bool kRecheckInCollide = true;  // collide(..., recheck) (rigid_bodies.hpp recheck_moved)

  std::vector<AnyShape> shape;         // per species, at scale 1
  std::vector<double> mass;            // per species, at scale 1
  std::vector<Vec3> inertia;           // per species: principal moments at scale 1
  std::vector<double> max_scale;       // per species: bound of the body scales drawn
  double eps_d = 1e-5;
  ContactOptions options{};
  GrowthLaw law{};                     // default: no growth
  mutable SolverStats stats{};
  bool trim_horizons = true;           // as RigidBodies::trim_horizons
  // Reject candidates whose bounding spheres cannot meet in their window before a solver is set
  // up (window_radius below; false: every candidate goes to the solver, the slow twin of the
  // tests).
  bool position_prefilter = true;
  // Then rule out candidates by the gap along the line of centres (centre_line_clear; false:
  // every candidate that passes the bounding spheres goes to the solver, the slow twin).
  bool centre_line_test = true;
  bool order_by_bound = true;  // as RigidBodies::order_by_bound
  // Each pair's last separating axis (contact/axis_memo.hpp; memo.on = false: the slow twin).
  mutable AxisMemo memo{};

  static RigidMixture of(const SpeciesTable& species, double eps_d, GrowthLaw law = {}) {
    RigidMixture m;
    for (const Species& sp : species) {
      m.shape.push_back(sp.shape);
      m.mass.push_back(sp.mass);
      m.inertia.push_back(sp.inertia);
      m.max_scale.push_back(sp.poly.max_scale());
    }
    m.eps_d = eps_d;
    m.law = law;
    return m;
  }

  // Largest centre distance at contact over the run (the final size when growing).
  double interaction_range() const {
    double r = 0.0;
    for (std::size_t k = 0; k < shape.size(); ++k)
      r = std::max(r, bounding_radius(shape[k]) * max_scale[k]);
    const double smax = law.growing() ? std::max(law.s0, law.final_scale()) : law.s0;
    return 2.0 * r * smax;
  }
  void prepare(State& s) const {
    s.tops.resize(inertia.size());
    for (std::size_t k = 0; k < inertia.size(); ++k)
      s.tops[k] = spherical_top(inertia[k]) ? Vec3::Zero() : inertia[k];
  }

  AnyShape body_shape(const State& s, std::size_t i) const {
    const double sc = s.scale[i];
    return sc == 1.0 ? shape[s.species[i]] : resized(shape[s.species[i]], sc);
  }
  MassProperties body_mass(const State& s, std::size_t i) const {
    const double sc = s.scale[i], s3 = sc * sc * sc;
    return MassProperties::principal(mass[s.species[i]] * s3, inertia[s.species[i]] * (s3 * sc * sc));
  }

  void contact_times(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                     const Vec3* shifts, std::size_t n, double now, const double* horizons,
                     double* out) const {
    const AnyShape sa = body_shape(s, i);
    const ScaleLaw sl{law.scale_at(now), law.rate_at(now)};
    const double law_end = now < law.t_stop ? law.t_stop : kInf;  // the law changes there
    const RotationFrame fa(s.q[i]);  // body i at `now`: the axis tests' frame (centre_line_clear)
    predict_contacts(
        s, box, i, js, shifts, n, now, horizons, out, law_end, trim_horizons, stats,
        [&](const BodyState& a, const BodyState& b, std::uint32_t j, double horizon,
            const double* window) {
          return std::visit(
              [&](const auto& A, const auto& B) {
                using SA = std::decay_t<decltype(A)>;
                using SB = std::decay_t<decltype(B)>;
                // the ordered loop's lower bound of the contact time: the search starts there
                // (the solver runs its own bounding-sphere test; window_radius may be wider)
                ContactInput<SA, SB> in{A, B, a, b, now, window ? window[0] : now, horizon, eps_d};
                in.growth = sl;
                memo.find_either(i, j, in.axis_start);
                const ContactResult r = contact_time(in, options);
                memo.store_both(s.size(), i, j, r.status == ContactStatus::hit ? r.normal : r.axis);
                return r;
              },
              sa, body_shape(s, j));
        },
        [&](const BodyState& a, const BodyState& b, std::uint32_t j, double horizon) {
          return fmt::format(
              "contact-time solver failed for bodies {} and {} at t = {:.17g} (growth scale "
              "{:.17g}, rate {:.17g}); reproducer: {}",
              i, j, now, sl.s, sl.rate, reproducer(sa, a, body_shape(s, j), b, horizon - now));
        },
        [&, Li = bounding_radius(sa), off = sl.active() || !position_prefilter](std::uint32_t j) {
          return off ? 0.0 : window_radius(Li, s, j);
        },
        [&](const BodyState& a, std::uint32_t j, const Vec3& c, double horizon) {
          return centre_line_clear(s, i, sa, a, fa, j, c, now, horizon);
        },
        order_by_bound);
  }
  // The second pre-filter of predict_contacts, RigidBodies::centre_line_clear for unlike pairs
  // and any tops: how long after `now` body i (shape sa, state a at `now`) and candidate j are
  // proven not to touch, by the gap along the pair's last separating axis (the memo), or else
  // along their line of centres (memo_or_centres_clear_time, system/rigid_bodies.hpp), computed
  // with the shapes the solver gets. A resized superquadric is skipped (0: its construction
  // searches its farthest point; the solver builds it anyway if needed).
  double centre_line_clear(const State& s, std::uint32_t i, const AnyShape& sa, const BodyState& a,
                           const RotationFrame& fa, std::uint32_t j, const Vec3& c, double now,
                           double horizon) const {
    if (!centre_line_test) return 0.0;
    const AnyShape& base = shape[s.species[j]];
    AnyShape scaled;
    const AnyShape* sb = &base;
    if (s.scale[j] != 1.0) {
      if (std::holds_alternative<Superquadric>(base)) return 0.0;
      scaled = resized(base, s.scale[j]);
      sb = &scaled;
    }
    return std::visit(
        [&](const auto& A, const auto& B) {
          return memo_or_centres_clear_time(A, B, s, i, a, fa, j, c, now, horizon, memo,
                                            options.revolution_bounds);
        },
        sa, *sb);
  }
  // The radius of predict_contacts' bounding-sphere test for body i (bounding radius Li) and
  // candidate j: no smaller than the solver's own (contact_time.hpp: L_i + L_j plus its margin,
  // from the resized shapes), so a pair it rejects is one the solver's first test rejects too.
  // L_j is taken as the species' radius times scale_j, which is exact for spheres, ellipsoids
  // and any shape at scale 1; a superquadric's resized radius is found anew by a numerical
  // search (its farthest point), so there L_j carries a relative slack of 1e-6, far above that
  // search's error and far below anything that would let a pair through that the bounding
  // spheres rule out.
  double window_radius(double Li, const State& s, std::uint32_t j) const {
    const AnyShape& sj = shape[s.species[j]];
    const double Lj = bounding_radius(sj) * s.scale[j];
    // the solver's own radius where L_j is exact (so one species of spheres or ellipsoids runs
    // the single-shape model's trajectory, whose windows and order come from these numbers)
    const bool searched = s.scale[j] != 1.0 && std::holds_alternative<Superquadric>(sj);
    const double slack = searched ? 1.0 + 1e-6 : 1.0;
    return (Li + Lj) * slack + bounding_window_margin(std::max(Li, Lj) * slack, eps_d);
  }

  // Body i for the single-body event sources (walls): its shape (scale_i) with the growth.
  static constexpr bool kBodyEvents = true;
  template <class F>
  void visit_body(const State& s, std::uint32_t i, double now, F&& f) const {
    const MassProperties m = body_mass(s, i);
    const BodyGrowth g{law.scale_at(now), law.rate_at(now)};
    const double law_end = now < law.t_stop ? law.t_stop : kInf;
    std::visit([&](const auto& shape) { f(shape, m, g, law_end); }, body_shape(s, i));
  }

  // recheck >= 0 (time units): the re-check of system/simulation.hpp, done on the distance this
  // collision computes anyway; see recheck_moved.
  CollisionRecord collide(State& s, const Box& box, std::uint32_t i, std::uint32_t j,
                          double now, double recheck = -1.0) const {
    BodyState a = s.body(i), b = s.body(j);  // both at `now`
    const double sc = law.scale_at(now), sdot = law.rate_at(now);
    const AnyShape sa = body_shape(s, i), sb = body_shape(s, j);
    Vec3 start;
    const Vec3* from = memo.find_either(i, j, start) ? &start : nullptr;
    const double touch = options.touch_from_memo ? options.accept_tol : 0.0;
    const auto [r_ab, d] = collision_contact(
        a, b, box, i, j, stats,
        [&](const Pose& pa, const Pose& pb) {
          return std::visit(
              [&](const auto& A, const auto& B) {
                const bool guess = options.separating_axis;
                if (sc == 1.0)
                  return collision_distance(A, a.q, pa, B, b.q, pb, options.distance, guess, from, touch);
                return collision_distance(resized(A, sc), a.q, pa, resized(B, sc), b.q, pb,
                                          options.distance, guess, from, touch);
              },
              sa, sb);
        },
        [&] {
          return std::pair{shape_json(resized(sa, sc)), shape_json(resized(sb, sc))};
        });
    const double grow = growth_normal_speed(sc, sdot, d.normal, r_ab);
    const double La = bounding_radius(sa) * sc, Lb = bounding_radius(sb) * sc;
    const double rate = (b.v - a.v).norm() + a.w.norm() * La + b.w.norm() * Lb +
                        (sdot / sc) * (La + Lb);
    if (recheck_moved(d.distance, recheck, rate, La + Lb)) return CollisionRecord{.moved = true};
    memo.store_both(s.size(), i, j, d.normal);
    return collide_separating(s, i, j, a, b, body_mass(s, i), body_mass(s, j), d, r_ab, grow,
                              rate, stats);
  }

  double kinetic_energy(const State& s) const {
    double k = 0.0;
    for (std::size_t i = 0; i < s.size(); ++i) k += hb::kinetic_energy(s.body(i), body_mass(s, i));
    return k;
  }

  static std::string reproducer(const AnyShape& sa, const BodyState& a, const AnyShape& sb,
                                const BodyState& b, double t_max) {
    return contact_reproducer(shape_json(sa), a, shape_json(sb), b, t_max);
  }
};

}  // namespace hb
