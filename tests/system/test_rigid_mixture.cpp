// RigidMixture, the generic pair model of any species: for one species of identical bodies it
// runs the trajectory of RigidBodies<S> (the monomorphic fast path it generalises) event for
// event; mixtures of unlike shapes and asymmetric tops conserve energy, momentum and angular
// momentum at every collision; collisions of tops with their tensor impulse agree with a
// finite-difference check of the energy; polydisperse bodies get their own size and mass.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "geometry/random_pairs.hpp"
#include "neighbors/cell_neighbors.hpp"
#include "observers/overlap_check.hpp"
#include "setup/mixture_setup.hpp"
#include "setup/rigid_setup.hpp"
#include "system/rigid_bodies.hpp"
#include "system/rigid_mixture.hpp"
#include "system/simulation.hpp"

using namespace hb;

namespace {

RigidSystemSpec ellipsoid_spec(const Vec3& inertia) {
  RigidSystemSpec spec;
  spec.n = 108;
  spec.phi = 0.3;
  spec.semi_axes = Vec3(1.0, 0.5, 0.5);
  spec.inertia = inertia;
  spec.seed = 7;
  return spec;
}

SpeciesTable one_species(const RigidSystemSpec& spec) {
  Species sp{"E", spec.n, Ellipsoid{spec.semi_axes.x(), spec.semi_axes.y(), spec.semi_axes.z()},
             spec.mass, spec.inertia, {}};
  return {sp};
}

// Two simulations from the same start step `events` times side by side: the same event types,
// times and impulses, then the same positions, orientations and angular velocities, bit for bit.
template <class SimA, class SimB>
void expect_same_events(SimA& a, SimB& b, int events) {
  for (int k = 0; k < events; ++k) {
    const auto ea = a.step(kInf), eb = b.step(kInf);
    ASSERT_EQ(ea.type, eb.type) << k;
    ASSERT_EQ(a.now(), b.now()) << k;
    ASSERT_EQ(ea.record.J, eb.record.J) << k;
  }
  a.synchronize();
  b.synchronize();
  for (std::size_t i = 0; i < a.state().size(); ++i) {
    ASSERT_EQ(a.state().r[i], b.state().r[i]) << i;
    ASSERT_EQ(a.state().q[i].coeffs(), b.state().q[i].coeffs()) << i;
    ASSERT_EQ(a.state().w[i], b.state().w[i]) << i;
  }
}

// The same lattice start through RigidBodies<Ellipsoid> and RigidMixture: identical events and
// identical states (bit for bit: the same solver instantiation with the same inputs).
void check_same_trajectory(const Vec3& inertia) {
  const RigidSystemSpec spec = ellipsoid_spec(inertia);
  Box box;
  const State st = ellipsoid_start(spec, box);
  const RigidBodies<Ellipsoid> fast = ellipsoid_model(spec);
  const RigidMixture generic = RigidMixture::of(one_species(spec), spec.eps_d);
  ASSERT_DOUBLE_EQ(fast.interaction_range(), generic.interaction_range());
  Simulation<RigidBodies<Ellipsoid>, CellNeighbors> a(box, st, fast, CellNeighbors(fast.interaction_range()));
  Simulation<RigidMixture, CellNeighbors> b(box, st, generic, CellNeighbors(generic.interaction_range()));
  const double e0 = generic.kinetic_energy(b.state());
  expect_same_events(a, b, 3000);
  if (::testing::Test::HasFatalFailure()) return;
  const double e1 = generic.kinetic_energy(b.state());
  std::printf("  one species, inertia (%g, %g, %g): 3000 events identical, energy drift %.2e\n",
              inertia.x(), inertia.y(), inertia.z(), (e1 - e0) / e0);
  EXPECT_LT(std::abs(e1 - e0) / e0, 1e-13);
}

TEST(RigidMixture, OneSpeciesSphericalTopsRunTheFastPathTrajectory) { check_same_trajectory(Vec3::Constant(0.1)); }
TEST(RigidMixture, OneSpeciesAsymmetricTopsRunTheFastPathTrajectory) {
  check_same_trajectory(Vec3(0.1, 0.25, 0.22));
}

// A sphere–ellipsoid–superquadric mixture with asymmetric tops and polydispersity: grown to
// phi = 0.3 by the mixture start; then every collision conserves energy, momentum and angular
// momentum (about the origin, with the image-corrected lever arms of the impulse), and the final
// state has no overlap by the independent check.
// Spheres, polydisperse ellipsoids (asymmetric tops) and superquadrics (polydisperse when
// `poly_q`), grown to phi = 0.3.
SpeciesTable unlike_species(bool poly_q) {
  Species a{"S", 40, Sphere{0.4}, 0.5, Vec3::Constant(0.032), {}};
  Species b{"E", 40, Ellipsoid{1.0, 0.6, 0.4}, 1.0, Vec3(0.104, 0.232, 0.272), {}};
  b.poly.distribution = Polydispersity::Distribution::gaussian;
  b.poly.width = 0.05;
  Species c{"Q", 20, Superquadric(0.6, 0.5, 0.5, 4.0, 4.0, 4.0), 1.2, Vec3(0.1, 0.11, 0.11), {}};
  if (poly_q) c.poly = b.poly;
  return {a, b, c};
}
GrowthResult grow_unlike(const SpeciesTable& sp) {
  GrowthOptions go;
  go.rate = 0.1;
  go.phi0 = 0.05;
  return grow_rigid_mixture(sp, 0.3, 3, go, 1e-5);
}

TEST(RigidMixture, UnlikeShapesAndTopsConserveAndNeverOverlap) {
  const SpeciesTable sp = unlike_species(false);
  const GrowthResult g = grow_unlike(sp);
  EXPECT_NEAR(g.phi, 0.3, 1e-12);
  const RigidMixture m = RigidMixture::of(sp, 1e-5);
  const OverlapCheck check = mixture_overlap_check(m.shape);
  EXPECT_EQ(check(g.state, g.box).overlaps, 0u);
  Simulation<RigidMixture, CellNeighbors> sim(g.box, g.state, m, CellNeighbors(m.interaction_range()));
  const double e0 = m.kinetic_energy(sim.state());
  double worst = 0.0;
  int collisions = 0;
  for (int k = 0; k < 4000; ++k) {
    const auto ev = sim.step(kInf);
    if (ev.type != EventType::Collision) continue;
    ++collisions;
    worst = std::max(worst, std::abs(ev.record.dE) / e0);
  }
  sim.synchronize();
  const double e1 = m.kinetic_energy(sim.state());
  Vec3 p = Vec3::Zero();
  for (std::size_t i = 0; i < sim.state().size(); ++i) p += m.body_mass(sim.state(), i).mass * sim.state().v[i];
  std::printf("  mixture: %d collisions, max |dE|/E per collision %.2e, drift %.2e, |P| %.2e\n",
              collisions, worst, (e1 - e0) / e0, p.norm());
  EXPECT_GT(collisions, 1000);
  EXPECT_LT(std::abs(e1 - e0) / e0, 1e-12);
  EXPECT_LT(p.norm(), 1e-10 * std::sqrt(e0));
  EXPECT_EQ(check(sim.state(), sim.box()).overlaps, 0u);
}

// The pre-filters of the mixture against the mixture without them, on unlike, polydisperse
// shapes (superquadrics included, whose resized radius is found by a search of their own):
//  * the bounding spheres (RigidMixture::window_radius: each pair's, from the species radius
//    times the body's scale), alone and
//  * with the gap along the line of centres (centre_line_clear), on asymmetric tops, then on
//    spherical ones.
// Each gives the same 3000 events (900 in Debug) and states bit for bit, the same number of
// predictions, and answers some of them without a solver.
SolverStats compare_mixture_prefilter(const SpeciesTable& sp, bool centre_line) {
  const GrowthResult g = grow_unlike(sp);
  RigidMixture m = RigidMixture::of(sp, 1e-5);
  m.centre_line_test = centre_line;
  // A candidate the line of centres rules out is not solved, so its axis memo is not renewed
  // and later solves take other paths (their last bits): compared without the memo (the memo's
  // own test: test_axis_memo). The bounding spheres rule out only what the solver's first test
  // does, which leaves the memo alone: compared with it.
  m.memo.on = !centre_line;
  // The candidates in their own order: which are solved, and with what windows, would differ
  // with the pre-filters' bounds (ordered loop, RigidBodies::order_by_bound; its own twin:
  // test_obb_neighbors).
  m.order_by_bound = false;
  RigidMixture plain = m;
  plain.position_prefilter = plain.centre_line_test = false;
  Simulation<RigidMixture, CellNeighbors> a(g.box, g.state, m, CellNeighbors(m.interaction_range()));
  Simulation<RigidMixture, CellNeighbors> b(g.box, g.state, plain, CellNeighbors(plain.interaction_range()));
  expect_same_events(a, b, hb::testing::scaled_count(3000, 0.3));  // 900 events in Debug
  const SolverStats &fa = a.model().stats, &fb = b.model().stats;
  std::printf("  %llu predictions, %llu of them answered by the pre-filters\n",
              static_cast<unsigned long long>(fa.predictions),
              static_cast<unsigned long long>(fa.prefiltered));
  EXPECT_EQ(fa.predictions, fb.predictions);
  EXPECT_EQ(fa.hits, fb.hits);
  EXPECT_EQ(fb.prefiltered, 0u);
  EXPECT_GT(fa.prefiltered, fa.predictions / 10);
  return fa;
}

TEST(RigidMixture, PositionPrefilterGivesTheSameRun) {
  compare_mixture_prefilter(unlike_species(true), false);
}

TEST(RigidMixture, CentreLineTestGivesTheSameRun) {
  SpeciesTable sp = unlike_species(true);  // asymmetric and symmetric tops
  for (int spherical = 0; spherical < 2; ++spherical) {
    if (spherical)
      for (Species& x : sp) x.inertia = Vec3::Constant(x.inertia.x());
    const SolverStats with = compare_mixture_prefilter(sp, true);
    const SolverStats spheres_only = compare_mixture_prefilter(sp, false);
    EXPECT_GT(with.prefiltered, spheres_only.prefiltered);  // the line of centres rules out more
  }
}

// Body sizes and masses follow the scale: m s^3, I s^5, and the shape resized by s.
TEST(RigidMixture, PolydisperseBodiesScaleShapeMassAndInertia) {
  SpeciesTable sp{Species{"E", 2, Ellipsoid{1.0, 0.5, 0.4}, 2.0, Vec3(0.1, 0.2, 0.3), {}}};
  const RigidMixture m = RigidMixture::of(sp, 1e-5);
  State s;
  s.resize(2);
  s.scale = {1.0, 1.1};
  const MassProperties p = m.body_mass(s, 1);
  EXPECT_NEAR(p.mass, 2.0 * std::pow(1.1, 3), 1e-14);
  EXPECT_NEAR(p.inertia_body(2, 2), 0.3 * std::pow(1.1, 5), 1e-14);
  EXPECT_FALSE(p.spherical);
  const Ellipsoid e = std::get<Ellipsoid>(m.body_shape(s, 1));
  EXPECT_NEAR(e.a, 1.1, 1e-15);
  EXPECT_NEAR(e.c, 0.44, 1e-15);
  m.prepare(s);
  ASSERT_EQ(s.tops.size(), 1u);
  EXPECT_EQ(s.tops[0], Vec3(0.1, 0.2, 0.3));
}

}  // namespace

namespace {

// Every body of a running simulation of `model` (after 2000 events; the candidates each at their
// own time) predicted against all the others twice by run(s, box, now, i, js, horizons, out,
// stats, solve, fail, filtered), with and without a pre-filter of predict_contacts (with the
// position pre-filter, the solver takes its window from it): the answers must be the same bit
// for bit. horizon(i, j): the window lengths. The tallies of both passes.
struct PrefilterTally {
  long solved_with = 0, solved_without = 0, hits = 0;
  SolverStats with, without;
};
template <class Horizon, class Run>
PrefilterTally compare_prefilter(const RigidSystemSpec& spec, const RigidBodies<Ellipsoid>& model,
                                 Horizon&& horizon, Run&& run) {
  Box box;
  const State st = ellipsoid_start(spec, box);
  Simulation<RigidBodies<Ellipsoid>, CellNeighbors> sim(box, st, model, CellNeighbors(model.interaction_range()));
  for (int k = 0; k < 2000; ++k) sim.step(kInf);
  State s = sim.state();
  const double now = sim.now();
  const std::size_t n = s.size();
  std::vector<std::uint32_t> js(n);
  std::vector<double> horizons(n), with(n), without(n);
  PrefilterTally tally;
  auto fail = [](const BodyState&, const BodyState&, std::uint32_t, double) { return std::string("failed"); };
  for (std::uint32_t i = 0; i < n; ++i) {
    s.advance_to(i, now);
    for (std::uint32_t j = 0; j < n; ++j) js[j] = j, horizons[j] = now + horizon(i, j);
    auto solve = [&](long& count) {
      return [&](const BodyState& x, const BodyState& y, std::uint32_t, double h, const double* window) {
        ++count;
        ContactInput<Ellipsoid, Ellipsoid> in{model.shape, model.shape, x, y, now, now, h, model.eps_d};
        // the pre-filter's window handed on (ContactInput::window_given), as RigidBodies does
        if (window) in.window_given = true, in.window_lo = window[0], in.window_hi = window[1];
        return contact_time(in, model.options);
      };
    };
    run(s, box, now, i, js, horizons, with, tally.with, solve(tally.solved_with), fail, true);
    run(s, box, now, i, js, horizons, without, tally.without, solve(tally.solved_without), fail, false);
    for (std::size_t k = 0; k < n; ++k) {
      if (with[k] != without[k]) {
        ADD_FAILURE() << "bodies " << i << ", " << k << ": " << with[k] << " against " << without[k];
        return tally;
      }
      tally.hits += with[k] < kInf;
    }
  }
  return tally;
}

}  // namespace

// The position pre-filter of predict_contacts (the bounding-sphere test of contact_time.hpp run
// before a candidate's orientation is streamed and a solver set up; RigidBodies passes its
// radius, RigidMixture does not) against the loop without it: on the bodies of a running
// simulation (each at its own time; asymmetric tops), every candidate's answer is the same bit
// for bit, every candidate is counted as a prediction, and the filter does reject some.
TEST(RigidBodies, PositionPrefilterGivesTheSolverAnswers) {
  const RigidSystemSpec spec = ellipsoid_spec(Vec3(0.1, 0.25, 0.22));
  const RigidBodies<Ellipsoid> model = ellipsoid_model(spec);
  const double R = model.window_radius();
  const PrefilterTally t = compare_prefilter(
      spec, model, [](std::uint32_t i, std::uint32_t j) { return 0.02 * (1 + (i + j) % 7); },
      [&](const State& s, const Box& box, double now, std::uint32_t i, const auto& js,
          const auto& horizons, auto& out, SolverStats& stats, auto&& solve, auto&& fail,
          bool filtered) {
        predict_contacts(s, box, i, js.data(), nullptr, js.size(), now, horizons.data(), out.data(),
                         kInf, false, stats, solve, fail, filtered ? R : 0.0);
      });
  std::printf("  %llu predictions, %ld solved without the pre-filter, %ld with it, %ld hits\n",
              static_cast<unsigned long long>(t.with.predictions), t.solved_without, t.solved_with, t.hits);
  EXPECT_EQ(t.with.predictions, t.without.predictions);
  EXPECT_EQ(t.with.axis_steps, t.without.axis_steps);
  EXPECT_EQ(t.with.hits, t.without.hits);
  EXPECT_LT(t.solved_with, t.solved_without / 2);  // most candidates of a whole box are far away
  EXPECT_GT(t.solved_with, 0);
  EXPECT_GT(t.hits, 0);
}

// The second pre-filter of predict_contacts, the gap along the line of centres with the
// candidate's stored orientation (RigidBodies::centre_line_clear, clear_along_centres of
// contact/axis_gap.hpp), against the loop without it: on the bodies of a running simulation of
// spherical tops, then of asymmetric tops (whose turn the test bounds by their largest angular
// speed; the candidates at their own times, so the bound turns their stored orientations), with
// windows from short to long (cut at the earliest contact found, as the loop does), every
// candidate's answer is the same bit for bit and counted alike, and the test does rule
// candidates out. Then whole runs with and without it give the same events and states
// bit for bit (the solver answers none wherever it rules out).
void check_centre_line_test(const Vec3& inertia) {
  RigidSystemSpec spec = ellipsoid_spec(inertia);
  spec.phi = 0.45;
  RigidBodies<Ellipsoid> model = ellipsoid_model(spec);
  // Without the axis memo: what the solver is asked differs with the test, so the memos (and
  // the solvers' paths, in their last bits) would too (the memo's own test: test_axis_memo).
  model.memo.on = false;
  // The candidates in their own order, as in compare_mixture_prefilter.
  model.order_by_bound = false;
  RigidBodies<Ellipsoid> plain = model;
  plain.centre_line_test = false;
  const double R = model.window_radius();
  const PrefilterTally t = compare_prefilter(
      spec, model,
      [](std::uint32_t i, std::uint32_t j) { return 0.005 * (1 + (i + j) % 11) * (1 + (i + j) % 3); },
      [&](const State& s, const Box& box, double now, std::uint32_t i, const auto& js,
          const auto& horizons, auto& out, SolverStats& stats, auto&& solve, auto&& fail,
          bool filtered) {
        const RigidBodies<Ellipsoid>& m = filtered ? model : plain;
        predict_contacts(s, box, i, js.data(), nullptr, js.size(), now, horizons.data(), out.data(),
                         kInf, true, stats, solve, fail, R,
                         [&](const BodyState& a, std::uint32_t j, const Vec3& c, double horizon) {
                           return m.centre_line_clear(s, i, a, RotationFrame(a.q), j, c, now, horizon);
                         });
      });
  std::printf("  %llu predictions, %ld solved after the bounding spheres, %ld after the line of "
              "centres too, %ld hits\n",
              static_cast<unsigned long long>(t.with.predictions), t.solved_without, t.solved_with, t.hits);
  EXPECT_EQ(t.with.predictions, t.without.predictions);
  EXPECT_EQ(t.with.hits, t.without.hits);
  EXPECT_LT(t.solved_with, t.solved_without);
  EXPECT_GT(t.solved_with, 0);
  EXPECT_GT(t.hits, 0);

  Box box;
  const State st = ellipsoid_start(spec, box);
  Simulation<RigidBodies<Ellipsoid>, CellNeighbors> a(box, st, model, CellNeighbors(model.interaction_range()));
  Simulation<RigidBodies<Ellipsoid>, CellNeighbors> b(box, st, plain, CellNeighbors(plain.interaction_range()));
  expect_same_events(a, b, 3000);
  EXPECT_LT(a.model().stats.axis_steps, b.model().stats.axis_steps);  // the solver was spared work
}

TEST(RigidBodies, CentreLineTestGivesTheSolverAnswers) { check_centre_line_test(Vec3(0.1, 0.1, 0.1)); }
TEST(RigidBodies, CentreLineTestGivesTheSolverAnswersForAsymmetricTops) {
  check_centre_line_test(Vec3(0.1, 0.25, 0.22));
}
