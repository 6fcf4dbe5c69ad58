// Pair model of identical hard rigid bodies of any convex shape (any top) for the event loop:
// contact times from the generic solver of contact/ (paper section 2.4) within a window that ends
// at the body's next neighbour event, and the rigid-body impulse of collision/.
//
// Growth (Lubachevsky–Stillinger starts, setup/growth.hpp) is the growth law `law`: with
// law.growing() every body is scaled by s(t) about its centre (the ScaleLaw decorator of the two
// motions in contact/contact_time.hpp), predictions stop at law.t_stop (where the law changes),
// and the collision rule gets the outward surface speed of motion/growth_law.hpp. The default
// law is the identity, and then every prediction and collision is the rigid one, bit for bit.
#pragma once
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "collision/rigid.hpp"
#include "contact/axis_memo.hpp"
#include "contact/contact_time.hpp"
#include "geometry/distance.hpp"
#include "motion/growth_law.hpp"
#include "shapes/codec.hpp"
#include "core/box.hpp"
#include "core/state.hpp"

namespace hb {

// Solver work and trouble, summed over a run (reported in summary.json).
struct SolverStats {
  std::uint64_t predictions = 0;       // contact-time solves
  std::uint64_t distance_evals = 0;    // distance solves inside them
  std::uint64_t axis_steps = 0;        // separating-axis gap evaluations inside them
  std::uint64_t axis_bounds = 0;       // affine gap bounds (flat-faced pairs)
  std::uint64_t distance_nr_iterations = 0;
  std::uint64_t contact_nr_iterations = 0;
  std::uint64_t grazing_searches = 0;
  std::uint64_t fallbacks = 0;         // contact NR rejected, bracket shrunk instead
  std::uint64_t distance_fallbacks = 0;
  std::uint64_t collision_distance_fallbacks = 0;
  std::uint64_t grazing_separations = 0;  // collisions given the minimum separation speed
  std::uint64_t hits = 0;                 // predictions that found a contact
  std::uint64_t hit_distance_evals = 0;   // distance solves inside those
  std::uint64_t prefiltered = 0;  // predictions answered by predict_contacts' pre-filters, no solver
  std::uint64_t centre_line_clears = 0;  // those of them answered by the line of centres
  std::uint64_t collision_touches = 0;   // collisions whose contact was read off the memo axis
  std::uint64_t ordered_skips = 0;  // predictions answered by predict_contacts' order: no contact
                                    // before the earliest found, no solver (in `prefiltered`)

  void add(const ContactResult& r) {
    ++predictions;
    distance_evals += r.distance_evals;
    axis_steps += r.axis_steps;
    axis_bounds += r.axis_bounds;
    distance_nr_iterations += r.distance_nr_iterations;
    contact_nr_iterations += r.nr_iterations;
    grazing_searches += r.grazing_searches;
    fallbacks += r.fallbacks;
    distance_fallbacks += r.distance_fallbacks;
    if (r.status == ContactStatus::hit) ++hits, hit_distance_evals += r.distance_evals;
  }
  // add(ContactResult{}) without building one: a prediction answered "none" with no work.
  void add_none() { ++predictions; }
};

// A contact-time solve that failed (every fallback exhausted): carries a reproducer in the
// `hardbody contact-time` input format.
class SolverFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// One line of `hardbody contact-time` input for bodies a and b (shape JSON given) moving from
// their states over [0, t_max]: the reproducer of a failed solve. A body that is not a spherical
// top carries its principal moments ("inertia").
inline std::string contact_reproducer(const std::string& shape_a, const BodyState& a,
                                      const std::string& shape_b, const BodyState& b, double t_max) {
  auto body = [](const std::string& shape, const BodyState& x) {
    std::string top;
    if (!spherical_top(x.top))
      top = fmt::format(", \"inertia\": [{:.17g}, {:.17g}, {:.17g}]", x.top.x(), x.top.y(), x.top.z());
    return fmt::format(
        "{{\"shape\": {}, \"position\": [{:.17g}, {:.17g}, {:.17g}], \"orientation\": [{:.17g}, "
        "{:.17g}, {:.17g}, {:.17g}], \"velocity\": [{:.17g}, {:.17g}, {:.17g}], "
        "\"angular_velocity\": [{:.17g}, {:.17g}, {:.17g}]{}}}",
        shape, x.r.x(), x.r.y(), x.r.z(), x.q.w(), x.q.x(), x.q.y(), x.q.z(), x.v.x(), x.v.y(),
        x.v.z(), x.w.x(), x.w.y(), x.w.z(), top);
  };
  return fmt::format("{{\"a\": {}, \"b\": {}, \"t_max\": {:.17g}}}", body(shape_a, a),
                     body(shape_b, b), t_max);
}

// The contact of bodies i and j at a collision (states a, b at its time): the separation r_ab
// (B's image near A) and the closest points from dist(pose_a, pose_b), the distance solve of the
// pair's shapes; a failed solve throws, a fallback is counted.
struct CollisionContact {
  Vec3 r_ab;
  DistanceResult d;
};
// shapes() gives the JSON of both shapes as solved (at the growth scale): the failure message
// carries a `hardbody distance` reproducer.
template <class Dist, class Shapes>
CollisionContact collision_contact(const BodyState& a, const BodyState& b, const Box& box,
                                   std::uint32_t i, std::uint32_t j, SolverStats& stats, Dist&& dist,
                                   Shapes&& shapes) {
  CollisionContact c;
  c.r_ab = box.near_image(b.r - a.r);
  const Pose pa{a.r, a.q.toRotationMatrix()};
  const Pose pb{Vec3(a.r + c.r_ab), b.q.toRotationMatrix()};
  c.d = dist(pa, pb);
  if (c.d.status == DistanceStatus::failed) {
    const auto [ja, jb] = shapes();
    auto body = [](const std::string& shape, const Vec3& r, const Quat& q) {
      return fmt::format("{{\"shape\": {}, \"position\": [{:.17g}, {:.17g}, {:.17g}], \"orientation\": "
                         "[{:.17g}, {:.17g}, {:.17g}, {:.17g}]}}",
                         shape, r.x(), r.y(), r.z(), q.w(), q.x(), q.y(), q.z());
    };
    throw SolverFailure(fmt::format(
        "distance solver failed at the collision of {} and {}; reproducer (hardbody distance): "
        "{{\"a\": {}, \"b\": {}}}", i, j, body(ja, a.r, a.q), body(jb, pb.r, b.q)));
  }
  if (c.d.status == DistanceStatus::fallback) ++stats.collision_distance_fallbacks;
  if (c.d.attempt == 0) ++stats.collision_touches;  // touching_along: no solver stage
  return c;
}

// The contact of two bodies that touch, read off a lab axis n (from A to B) that is their
// contact normal: the support point p_A of A along n and p_B of B along -n (lab frame). A lies in
// the half-space n.x <= n.p_A and B in n.x >= n.p_B, so the distance is at least
// g = n.(p_B - p_A); both points lie in the bodies, so it is at most |p_B - p_A|. When
// |p_B - p_A| <= tol (a fraction of the bodies' size times their larger bounding radius) the
// bodies touch to that tolerance at p_A ~ p_B with normal n, the same contact a distance solve
// would find (to its own tolerance): `out` gets distance g, the two points and n, and true
// is returned. Otherwise (n is not the contact normal, or a flat face's support point is not
// the touching one): false, `out` untouched.
template <SupportShape SA, SupportShape SB>
bool touching_along(const SA& sa, const Quat& qa, const Pose& pa, const SB& sb, const Quat& qb,
                    const Pose& pb, const Vec3& axis, double tol, DistanceResult& out) {
  const double an = axis.norm();
  if (!(an > 0.0)) return false;
  const Vec3 n = axis / an;
  const Vec3 p_a = pa.r + pa.R * sa.support_point(qa.conjugate() * n);
  const Vec3 p_b = pb.r + pb.R * sb.support_point(-(qb.conjugate() * n));
  const Vec3 sep = p_b - p_a;
  if (!(sep.norm() <= tol * std::max(sa.bounding_radius(), sb.bounding_radius()))) return false;
  out = DistanceResult{};
  out.status = DistanceStatus::converged;
  out.distance = n.dot(sep);
  out.point_a = p_a;
  out.point_b = p_b;
  out.normal = n;
  out.attempt = 0;  // no solver stage: read off the axis (counted in SolverStats::collision_touches)
  return true;
}

// The distance solve at a collision of shapes sa, sb at poses pa, pb (orientations qa, qb):
// with `guess`, shapes with a support function (not two spheres: their distance is closed-form)
// start from the support points of the separating axis (touching_guess, contact_time.hpp)
// instead of the solver's cold guess: at X0 = 2 it costs half as much (NR+SD iterations
// 11 -> 3). Without, or if that start does not converge, the solver's own stages run as before.
// `start` (lab frame, from A to B), if given: where the guess's axis search starts (the pair's
// memo, contact/axis_memo.hpp) instead of the line of centres.
// `touch` > 0 (with `start`): first try the contact read off the start axis itself
// (touching_along), which is the pair's contact normal when the prediction that scheduled this
// collision stored it in the memo; no distance solve then.
template <Shape SA, Shape SB>
DistanceResult collision_distance(const SA& sa, const Quat& qa, const Pose& pa, const SB& sb,
                                  const Quat& qb, const Pose& pb, const DistanceOptions& o,
                                  bool guess, const Vec3* start = nullptr, double touch = 0.0) {
  if constexpr (SupportShape<SA> && SupportShape<SB> &&
                !(std::is_same_v<SA, Sphere> && std::is_same_v<SB, Sphere>)) {
    DistanceResult d;
    if (start && touch > 0.0 && touching_along(sa, qa, pa, sb, qb, pb, *start, touch, d)) return d;
    if (guess) {
      const DistanceWarmStart w = touching_guess(sa, qa, sb, qb, Vec3(pb.r - pa.r), 12, start);
      return distance(sa, pa, sb, pb, o, w.valid ? &w : nullptr);
    }
  }
  return distance(sa, pa, sb, pb, o);
}

// The no-op second pre-filter of predict_contacts (below): nothing proven clear.
struct NeverClear {
  double operator()(const BodyState&, std::uint32_t, const Vec3&, double) const { return 0.0; }
};

// A body's rotation for the pre-filters (SpinBound of contact/axis_gap.hpp): wmax = -1 for a
// spherical top (w constant: the tests use w itself), else the largest angular speed of its
// free rotation (the one the State caches and the solver evaluates) and the bound of |dW/dt|
// the solver's Motion takes from it.
inline SpinBound spin_bound(const FreeRotation& rot, const Vec3& top) {
  const double w = rot.max_angular_speed();
  return {w, angular_acceleration_bound(top, w)};
}
inline SpinBound spin_bound(const BodyState& a) {
  return a.rot ? spin_bound(*a.rot, a.top) : SpinBound{};
}
inline SpinBound spin_bound(const State& s, std::uint32_t j) {
  return spherical_top(s.top(j)) ? SpinBound{} : spin_bound(s.free_rotation(j), s.top(j));
}

// The second pre-filter of the rigid models (predict_contacts' `clear`): how long body i (shape
// A, state a at `now`) and candidate j (shape B, centre separation c at `now`, orientation at its
// own time) are proven not to touch, a duration from `now`, by the gap along one fixed axis
// (axis_clear_time, to first and second order; any fixed axis gives a valid bound): the pair's
// last separating axis in the memo, either side's slot (AxisMemo::find_near: the partner's only
// while the memo is small enough to stay in the cache), or, for a pair not found there, their
// line of centres (centres_clear_time).
// Measured (callgrind, docs/benchmarks/README.md, "Session of 2026-11-29, eighth part"):
// - the second order along the memo's axis clears half the candidates the first order leaves
//   to the solver at X0 = 10, phi = 0.4 (-9.4 % instructions there, -4.6 % at X0 = 2, phi = 0.5);
// - either side's slot instead of i's own: -6.6 % at X0 = 10, -3.0 % at X0 = 2;
// - with the second order along the memo's axis, the line of centres after it (first order;
//   it came second since the sixth part) clears too few to pay for itself: -2.7 % at X0 = 2
//   without it, no change at X0 = 10.
// fa: body i's rotation matrix, RotationFrame(a.q) (contact/axis_gap.hpp), formed once per
// prediction; the tests turn directions by products with it instead of quaternion rotations.
// Measured with the shape constants kept in Ellipsoid and support_point_given (callgrind, N =
// 1083, phi = 0.4, docs/benchmarks/README.md, "Session of 2026-12-02, second part"): -3.2 %
// instructions a collision at X0 = 10, -2.6 % at X0 = 1.
template <class SA, class SB>
double memo_or_centres_clear_time(const SA& A, const SB& B, const State& s, std::uint32_t i,
                                  const BodyState& a, const RotationFrame& fa, std::uint32_t j,
                                  const Vec3& c, double now, double horizon,
                                  const AxisMemo& memo, bool revolution = true) {
  const Vec3 dv = s.v[j] - a.v;
  SpinBound wa = spin_bound(a), wb = spin_bound(s, j);
  // Tops that are not spherical turn at up to wmax in every direction; a symmetric top of
  // revolution about its own axis moves its surface at its spin across that axis only, often
  // far less (SpinBound::across). Spherical tops keep |w x u|: at X0 = 10 with isotropic
  // inertia the bound cost more than it saved (docs/benchmarks/README.md, 2026-12-04).
  if (revolution) {
    if (wa.wmax >= 0.0) wa.across = spin_across_of(A, a.q, a.w, a.top, wa.wmax);
    if (wb.wmax >= 0.0) wb.across = spin_across_of(B, s.q[j], s.w[j], s.top(j), wb.wmax);
  }
  const double age = now - s.t[j], span = horizon - now;
  Vec3 u;
  if (memo.find_near(i, j, u))
    return axis_clear_time(A, fa, a.w, B, s.q[j], s.w[j], c, near_unit_normalized(u), dv, age, span,
                           wa, wb, /*second_order=*/true);
  return centres_clear_time(A, fa, a.w, B, s.q[j], s.w[j], c, dv, age, span, wa, wb,
                            /*second_order=*/true);
}

// The prediction loop of the rigid pair models (RigidBodies, RigidMixture): body i (at `now`)
// against the candidates js (at their images `shifts`, or the minimum image), each window cut at
// the candidate's horizon, at law_end (where the growth law changes) and, with `trim`, at the
// earliest contact found so far (later ones are not needed). solve(a, b, j, horizon, window)
// runs the pair's contact-time solver; a failed solve throws
// SolverFailure(fail(a, b, j, horizon)). window_radius > 0: the radius the solver's own first
// test uses (contact_time.hpp: the bounding spheres' sum plus its margin), a number for one
// shape (RigidBodies) or radius(j) for candidate j (RigidMixture: at least the solver's radius,
// see there). A candidate whose bounding spheres cannot meet within its window is then rejected
// here, from its position alone, before its orientation is streamed to `now` and a solver is
// set up: the same test on the same numbers (or on a radius no smaller), so the same result
// (counted as the prediction it replaces, and in stats.prefiltered). The test is first answered
// without the window's roots (bounding_spheres_may_meet: no square root, no division); a
// candidate that passes it is offered to clear(a, j, c, horizon) (c = r_j - r_i at `now`),
// which returns how long after `now` the pair is proven not to touch (a double, 0: nothing
// proven), without streaming j's orientation (the gap along one axis,
// memo_or_centres_clear_time above); if that covers the window, the solver, which would answer
// none, is not set up. Only the candidates left get the window itself (bounding_sphere_window,
// whose roots the test's answer agrees with up to rounding at the window's edges, where it
// rejects a candidate as before). Measured at X0 = 2, phi = 0.5 (docs/benchmarks/README.md,
// "Session of 2026-12-06, fifth part"): the window's test took 8.5 % of the run's time
// (a sampling profile), its square root and divisions formed for every candidate; root-free,
// the run takes 0.95 of the time (alternating builds) for 1.7 % fewer instructions, the same
// trajectory and counters. With a number (the solver's own radius) the window found, {lo, hi},
// is handed to solve as `window`, for ContactInput::window_given (the solver does not repeat
// the test); else window is null (but see `order` below).
//
// `order` (with `trim`): the candidates left after both pre-filters are solved in the order of
// their lower bounds of the contact time, t_lb = max(the bounding spheres' entry, now + the
// clear time), and the loop stops at the first whose t_lb is not before the earliest contact
// found: none of the rest can touch before it, and a contact after it is not needed (the
// windows are cut there anyway). Each solve's window ends at the earliest contact found before
// it, so the contacts found early shorten the later windows, and starts at the candidate's t_lb:
// solve gets window = {t_lb, its end} (with the solver's own radius, the bounding spheres'
// window cut to [t_lb, horizon]: ContactInput::window_given; with another radius, when
// t_lb > now, the search starts at t_lb, ContactInput::t_start, and the solver runs its own
// test from there). Measured
// at X0 = 10, phi = 0.4 (callgrind, docs/benchmarks/README.md, "Session of 2026-11-30"): solves
// per collision 8.6 -> 7.2, instructions -12 %. The earliest contact is the one
// the candidates' own order finds (a contact time to the solver's tolerance: the windows, and
// so the solves' last steps, differ); false: the candidates' order (the twin of the tests).
template <class Solve, class Fail, class Radius = double, class Clear = NeverClear>
void predict_contacts(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                      const Vec3* shifts, std::size_t n, double now, const double* horizons,
                      double* out, double law_end, bool trim, SolverStats& stats, Solve&& solve,
                      Fail&& fail, const Radius& window_radius = Radius{}, Clear&& clear = Clear{},
                      bool order = false) {
  static_assert(std::is_same_v<std::invoke_result_t<Clear&, const BodyState&, std::uint32_t,
                                                    const Vec3&, double>,
                               double>,
                "clear returns the duration proven clear (a double), not a bool");
  auto radius = [&window_radius](std::uint32_t j) {
    if constexpr (std::is_arithmetic_v<Radius>) {
      (void)j;
      return double(window_radius);
    } else {
      return double(window_radius(j));
    }
  };
  // A candidate for the solver: its index, position (image), window and lower bound.
  struct Pending {
    double t_lb;
    std::uint32_t k;
    bool window;  // lo, hi are the solver's own bounding-sphere window
    double lo, hi;
    Vec3 rb;
  };
  thread_local std::vector<Pending> pending;  // the ordered mode's candidates (scratch)
  order = order && trim;
  pending.clear();
  if (n > 0) s.prefetch(js[0]);
  const BodyState a = s.body(i);  // body i is at `now`
  double earliest = kInf;
  auto run = [&](const Pending& p, double horizon) {
    const std::uint32_t j = js[p.k];
    // The window handed to solve: the solver's own bounding-sphere window (p.window), and in
    // the ordered loop a search that starts at the candidate's bound (no contact before it).
    const double lohi[2] = {order ? p.t_lb : p.lo, std::min(p.hi, horizon)};
    const bool give = p.window || (order && p.t_lb > now);
    BodyState b = s.body_at(j, now);
    b.r = p.rb;
    const ContactResult r = solve(a, b, j, horizon, give ? lohi : nullptr);
    stats.add(r);
    if (r.status == ContactStatus::failed) throw SolverFailure(fail(a, b, j, horizon));
    if (r.status == ContactStatus::hit) {
      out[p.k] = std::max(0.0, r.time - now);
      earliest = std::min(earliest, r.time);
    }
  };
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t j = js[k];
    out[k] = kInf;
    if (k + 1 < n) s.prefetch(js[k + 1]);  // the next candidate's record, while this one is solved
    const double horizon = trim ? std::min({horizons ? horizons[k] : kInf, law_end, earliest}) : law_end;
    if (j == i || !(horizon > now)) continue;
    const Vec3 rj = s.r[j] + s.v[j] * (now - s.t[j]);  // as State::body_at streams it
    Pending p{now, static_cast<std::uint32_t>(k), false, now, horizon,
              shifts ? Vec3(rj + shifts[k]) : Vec3(a.r + box.near_image(rj - a.r))};
    if (const double R = radius(j); R > 0.0) {
      // The bounding spheres first by their answer alone (no roots), then the axis test, then
      // the window's roots for the few left (bounding_spheres_may_meet, contact/contact_time.hpp).
      if (!bounding_spheres_may_meet(Vec3(p.rb - a.r), Vec3(s.v[j] - a.v), R, horizon - now)) {
        stats.add_none();  // the solver's answer to this test: none
        ++stats.prefiltered;
        continue;
      }
      const double tau = clear(a, j, Vec3(p.rb - a.r), horizon);
      if (tau > horizon - now) {
        stats.add_none();  // no contact in the window: the solver's answer
        ++stats.prefiltered, ++stats.centre_line_clears;
        continue;
      }
      BodyState b0;
      b0.r = p.rb, b0.v = s.v[j];
      if (!bounding_sphere_window(a, b0, now, R, p.lo, p.hi) || !(p.lo <= p.hi)) {
        stats.add_none();  // the window's edge, at rounding level: none
        ++stats.prefiltered;
        continue;
      }
      p.t_lb = std::max(p.lo, now + tau);
      p.window = std::is_arithmetic_v<Radius>;  // the solver's own radius
    }
    if (order) pending.push_back(p);
    else run(p, horizon);
  }
  if (!order) return;
  std::sort(pending.begin(), pending.end(), [](const Pending& x, const Pending& y) {
    return x.t_lb < y.t_lb || (x.t_lb == y.t_lb && x.k < y.k);
  });
  for (const Pending& p : pending) {
    if (!(p.t_lb < earliest)) {  // this one and the rest: no contact before the earliest
      stats.add_none();
      ++stats.prefiltered, ++stats.ordered_skips;
      continue;
    }
    const double horizon = std::min({horizons ? horizons[p.k] : kInf, law_end, earliest});
    run(p, horizon);
  }
}

inline double total_kinetic_energy(const State& s, const MassProperties& mass) {
  double k = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) k += hb::kinetic_energy(s.body(i), mass);
  return k;
}

// The impulse of a collision of bodies i and j (states a, b at the collision time, closest
// points and normal d, separation r_ab), written back into the State. `grow` is the sum of the
// surfaces' outward normal speeds at the contact (0 for rigid bodies), `rate` the pair's
// distance-rate bound.
// Grazing contacts: the contact-time solver and this impulse judge "approaching" from slightly
// different points (closest points vs their midpoint), so for a relative normal speed within
// rounding of zero they can disagree and the pair would be re-predicted to collide at this same
// instant forever. The bodies leave every collision separating at least at eps_v = 1e-8 rate
// (through the growth term of the impulse rule: the gap opens at max(closing, eps_v)); the
// energy change is of order eps_v^2, ~1e-16 relative.
inline CollisionRecord collide_separating(State& s, std::uint32_t i, std::uint32_t j, BodyState a,
                                          BodyState b, const MassProperties& mass_a,
                                          const MassProperties& mass_b, const DistanceResult& d,
                                          const Vec3& r_ab, double grow, double rate,
                                          SolverStats& stats) {
  const Vec3 x_c = 0.5 * (d.point_a + d.point_b);
  const double closing = contact_relative_velocity(a, b, x_c, r_ab).dot(d.normal) + grow;
  const double eps_v = 1e-8 * rate;
  double g_eff = grow;
  if (closing < eps_v) {
    g_eff = grow + 0.5 * (eps_v - closing);
    ++stats.grazing_separations;
  }
  CollisionRecord rec = hb::collide(a, mass_a, b, mass_b, x_c, d.normal, r_ab, g_eff);
  s.v[i] = a.v, s.w[i] = a.w;
  s.v[j] = b.v, s.w[j] = b.w;
  rec.a = i;
  rec.b = j;
  return rec;
}

// The re-check of a rigid pair at its collision (system/simulation.hpp): the pair is in contact
// now when the gap d the collision's distance solve finds is within what the pair can close in the
// re-check tolerance (seconds x its distance-rate bound), or within rounding of the solvers
// (1e-9 of the pair's size; contacts are accepted at |d| <= 1e-10 L). A gap beyond both means the
// contact is still ahead: the prediction came up early. recheck < 0: no check.
inline bool recheck_moved(double gap, double recheck, double rate, double size) {
  return recheck >= 0.0 && gap > std::max(recheck * rate, 1e-9 * size);
}

template <Shape S>
struct RigidBodies {
  static constexpr bool kWindowed = true;  // predictions only up to the body's next neighbour event
  static constexpr bool kRecheckInCollide = true;  // collide(..., recheck) (recheck_moved)

  S shape;  // at scale 1 (the target size when growing)
  MassProperties mass;
  double eps_d = 1e-5;
  ContactOptions options{};
  mutable SolverStats stats{};
  // Use the loop's per-pair horizons and stop at the earliest contact found (false: every
  // candidate is solved without any horizon; the slow twin the tests compare against).
  bool trim_horizons = true;
  // Rule out candidates by the gap along one axis (the memo's, or the line of centres) before
  // streaming their orientation (centre_line_clear; false: every candidate that passes the
  // bounding spheres goes to the solver, the slow twin of the tests).
  bool centre_line_test = true;
  // Solve the candidates left in the order of their lower bounds of the contact time, up to the
  // earliest contact found (predict_contacts' `order`; false: the candidates' order, the twin).
  bool order_by_bound = true;
  GrowthLaw law{};  // default: no growth
  // Each pair's last separating axis (contact/axis_memo.hpp; memo.on = false: the slow twin).
  mutable AxisMemo memo{};

  // Largest centre distance at contact over the run (the final size when growing).
  double interaction_range() const {
    return 2.0 * shape.bounding_radius() * (law.growing() ? std::max(law.s0, law.final_scale()) : law.s0);
  }
  // Bodies rotate as the top their inertia makes (motion/motion.hpp).
  void prepare(State& s) const { s.tops.assign(1, mass.top()); }

  void contact_times(const State& s, const Box& box, std::uint32_t i, const std::uint32_t* js,
                     const Vec3* shifts, std::size_t n, double now, const double* horizons,
                     double* out) const {
    const ScaleLaw sl{law.scale_at(now), law.rate_at(now)};        // {1, 0} without growth
    const double law_end = now < law.t_stop ? law.t_stop : kInf;  // the law changes there
    const RotationFrame fa(s.q[i]);  // body i at `now`: the axis tests' frame (centre_line_clear)
    predict_contacts(
        s, box, i, js, shifts, n, now, horizons, out, law_end, trim_horizons, stats,
        [&](const BodyState& a, const BodyState& b, std::uint32_t j, double horizon, const double* window) {
          ContactInput<S, S> in{shape, shape, a, b, now, now, horizon, eps_d};
          in.growth = sl;
          if (window) in.window_given = true, in.window_lo = window[0], in.window_hi = window[1];
          memo.find_either(i, j, in.axis_start);
          const ContactResult r = contact_time(in, options);
          memo.store_both(s.size(), i, j, r.status == ContactStatus::hit ? r.normal : r.axis);
          return r;
        },
        [&](const BodyState& a, const BodyState& b, std::uint32_t j, double horizon) {
          return fmt::format(
              "contact-time solver failed for bodies {} and {} at t = {:.17g}{}; reproducer{}: {}",
              i, j, now,
              law.growing() ? fmt::format(" (growth scale {:.17g}, rate {:.17g})", sl.s, sl.rate) : "",
              law.growing() ? " at scale 1" : "", reproducer(a, b, horizon - now));
        },
        sl.active() ? 0.0 : window_radius(),
        [&](const BodyState& a, std::uint32_t j, const Vec3& c, double horizon) {
          return centre_line_clear(s, i, a, fa, j, c, now, horizon);
        },
        order_by_bound);
  }
  // The pre-filter of predict_contacts after the bounding spheres (no growth): how long after
  // `now` body i (state a at `now`) and candidate j (centre separation c at `now`, orientation at
  // its own time) are proven not to touch, by the gap along the pair's last separating axis (the
  // memo), or, for a pair not in it, along their line of centres (memo_or_centres_clear_time; for
  // tops that are not spherical with their largest angular speeds, from the free rotation the
  // solver uses); 0 when off (centre_line_test, the slow twin).
  double centre_line_clear(const State& s, std::uint32_t i, const BodyState& a,
                           const RotationFrame& fa, std::uint32_t j, const Vec3& c, double now,
                           double horizon) const {
    return centre_line_test
               ? memo_or_centres_clear_time(shape, shape, s, i, a, fa, j, c, now, horizon, memo,
                                            options.revolution_bounds)
               : 0.0;
  }
  // The radius of contact_time's bounding-sphere test for two bodies of this shape at scale 1
  // (no growth): L_A + L_B plus its margin.
  double window_radius() const {
    const double L = shape.bounding_radius();
    return (L + L) + bounding_window_margin(L, eps_d);
  }

  // Body i for the single-body event sources (walls): the shape at scale 1 with the growth.
  static constexpr bool kBodyEvents = true;
  template <class F>
  void visit_body(const State&, std::uint32_t, double now, F&& f) const {
    f(shape, mass, BodyGrowth{law.scale_at(now), law.rate_at(now)}, now < law.t_stop ? law.t_stop : kInf);
  }

  // recheck >= 0 (time units): the re-check of system/simulation.hpp, done on the distance this
  // collision computes anyway; see recheck_moved.
  CollisionRecord collide(State& s, const Box& box, std::uint32_t i, std::uint32_t j,
                          double now, double recheck = -1.0) const {
    BodyState a = s.body(i), b = s.body(j);  // both at `now`
    const double sc = law.scale_at(now), sdot = law.rate_at(now);
    Vec3 start;
    const Vec3* from = memo.find_either(i, j, start) ? &start : nullptr;
    const double touch = options.touch_from_memo ? options.accept_tol : 0.0;
    const auto [r_ab, d] = collision_contact(
        a, b, box, i, j, stats,
        [&](const Pose& pa, const Pose& pb) {
          const bool guess = options.separating_axis;
          if (sc == 1.0)
            return collision_distance(shape, a.q, pa, shape, b.q, pb, options.distance, guess, from, touch);
          const auto shp = scaled_shape(shape, sc);
          return collision_distance(shp, a.q, pa, shp, b.q, pb, options.distance, guess, from, touch);
        },
        [&] {
          const std::string js = hb::shape_json(AnyShape(resized(shape, sc)));
          return std::pair{js, js};
        });
    const double grow = growth_normal_speed(sc, sdot, d.normal, r_ab);
    const double L = shape.bounding_radius() * sc;
    const double rate = (b.v - a.v).norm() + (a.w.norm() + b.w.norm()) * L + 2.0 * sdot / sc * L;
    if (recheck_moved(d.distance, recheck, rate, 2.0 * L)) return CollisionRecord{.moved = true};
    memo.store_both(s.size(), i, j, d.normal);
    return collide_separating(s, i, j, a, b, mass, mass, d, r_ab, grow, rate, stats);
  }

  double kinetic_energy(const State& s) const { return total_kinetic_energy(s, mass); }

  std::string reproducer(const BodyState& a, const BodyState& b, double t_max) const {
    return contact_reproducer(hb::shape_json(shape), a, hb::shape_json(shape), b, t_max);
  }
};

}  // namespace hb
