// The overlap check of mixtures and polydisperse runs (observers/overlap_check.hpp,
// mixture_overlap_check) on configurations with known answers:
//  (a) unlike pairs (sphere-ellipsoid, unequal ellipsoids, superquadric-ellipsoid,
//      superquadric-sphere, unequal superquadrics, unequal spheres) placed at signed gaps of
//      +-1e-6 of the smaller inscribed radius by the independent support-function reference
//      (tests/geometry/reference_distance.hpp), and a body inside another;
//  (b) identical bodies: the same numbers as the identical-body checks on dense configurations;
//  (c) scale[]: pairs at +-1e-6 with scaled bodies, and a polydisperse configuration against
//      the same bodies given as pre-scaled species;
//  (d) periodic images: pairs across faces and corners, unwrapped positions, small boxes.
#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "geometry/random_pairs.hpp"
#include "geometry/reference_distance.hpp"
#include "observers/overlap_check.hpp"
#include "setup/init.hpp"

using namespace hb;
using hb::testing::Rng;

namespace {

// The body shape of species shape s at scale k (what the check must see).
Sphere scaled(const Sphere& s, double k) { return Sphere{s.radius * k}; }
Ellipsoid scaled(const Ellipsoid& e, double k) { return Ellipsoid{e.a * k, e.b * k, e.c * k}; }
Superquadric scaled(const Superquadric& q, double k) {
  return Superquadric{q.a * k, q.b * k, q.c * k, q.n, q.m, q.p};
}

Superquadric random_superquadric(Rng& rng) {
  return Superquadric{rng.log_uni(0.4, 1.2), rng.log_uni(0.4, 1.2), rng.log_uni(0.4, 1.2),
                      rng.uni(2.0, 12.0), rng.uni(2.0, 12.0), rng.uni(2.0, 12.0)};
}

// B's centre (A at the origin, rotations qa, qb) at which the reference signed distance of the
// pair equals `target`: testing::place_at_distance along u, then Newton along the reference's
// normal (the SAT gap grows by exactly the shift along it, to second order).
template <SupportShape SA, SupportShape SB>
Vec3 place_at_gap(const SA& a, const Quat& qa, const SB& b, const Quat& qb, const Vec3& u,
                  double target) {
  const Pose pa{Vec3::Zero(), qa.toRotationMatrix()};
  Vec3 r = hb::testing::place_at_distance(a, pa, b, qb.toRotationMatrix(), u, target).r;
  const double size = a.bounding_radius() + b.bounding_radius();
  for (int it = 0; it < 40; ++it) {
    const ref::RefDistance d = ref::reference_distance(a, pa, b, Pose{r, qb.toRotationMatrix()});
    const double err = target - d.distance;
    if (std::abs(err) < 1e-14 * size) return r;
    r += err * d.n;
  }
  ADD_FAILURE() << "placement did not converge";
  return r;
}

// A two-body state: species (ia, ib), scales (sa, sb), A at ra, B at ra + rab.
State two_bodies(std::uint16_t ia, std::uint16_t ib, double sa, double sb, const Quat& qa,
                 const Quat& qb, const Vec3& ra, const Vec3& rab) {
  State st;
  st.resize(2);
  st.species = {ia, ib};
  st.scale = {sa, sb};
  st.q = {qa, qb};
  st.r = {ra, Vec3(ra + rab)};
  return st;
}

struct GapStats {
  int pairs = 0;
  double worst_rel = 0.0;  // worst |min_distance - gap| / |gap| (exact and sampled pairs)
};

// Pairs of species shapes (a, b) at scales (sa, sb), placed at signed gaps of +-level times
// the smaller scaled inscribed radius; the check must give the verdict of the sign, decide
// exactly one pair, and (if `gap_is_distance`: spheres, sampling) report the gap itself.
// The state is placed at `origin` in `box` along the direction u (random unless given).
template <SupportShape SA, SupportShape SB>
void expect_verdicts(const SA& a, const SB& b, double sa, double sb, Rng& rng, const Box& box,
                     const Vec3& origin, const Vec3* direction, bool gap_is_distance,
                     GapStats& stats, const std::string& what, double level = 1e-6) {
  const OverlapCheck check = mixture_overlap_check({AnyShape(a), AnyShape(b)});
  const SA A = scaled(a, sa);
  const SB B = scaled(b, sb);
  const double ell = std::min(A.inscribed_radius(), B.inscribed_radius());
  const Quat qa = rng.quat(), qb = rng.quat();
  const Vec3 u = direction ? Vec3(direction->normalized()) : rng.unit();
  for (double sign : {-1.0, 1.0}) {
    const double g = sign * level * ell;
    const Vec3 rab = place_at_gap(A, qa, B, qb, u, g);
    for (int order = 0; order < 2; ++order) {  // A first, then B first
      const State st = order == 0 ? two_bodies(0, 1, sa, sb, qa, qb, origin, rab)
                                  : two_bodies(1, 0, sb, sa, qb, qa, origin, Vec3(-rab));
      State wrapped = st;
      for (Vec3& p : wrapped.r) box.wrap(p);
      const OverlapReport rep = check(wrapped, box);
      EXPECT_EQ(rep.pairs_checked, 1u) << what;
      EXPECT_EQ(rep.overlaps, sign < 0.0 ? 1u : 0u)
          << what << ": gap " << g << " order " << order << " reported " << rep.min_distance;
      EXPECT_EQ(rep.min_distance < 0.0, sign < 0.0) << what << ": gap " << g << " reported " << rep.min_distance;
      if (gap_is_distance) stats.worst_rel = std::max(stats.worst_rel, std::abs(rep.min_distance - g) / std::abs(g));
      ++stats.pairs;
    }
  }
}

Box cube(double L) {
  Box b;
  b.L = Vec3::Constant(L);
  return b;
}

}  // namespace

// (a) ------------------------------------------------------------------------------------------

TEST(MixtureOverlapCheck, UnlikePairsAtKnownGaps) {
  Rng rng(20240611);
  const Box box = cube(20.0);
  const Vec3 mid = Vec3::Constant(10.0);
  const int n_exact = hb::testing::scaled_count(40, 0.25, 5), n_sampled = hb::testing::scaled_count(15, 0.2, 3);
  GapStats s_sph, s_se, s_ee, s_qe, s_qs, s_qq;
  for (int k = 0; k < n_exact; ++k) {
    expect_verdicts(Sphere{rng.uni(0.2, 1.0)}, Sphere{rng.uni(0.2, 1.0)}, 1.0, 1.0, rng, box, mid,
                    nullptr, true, s_sph, "sphere-sphere");
    expect_verdicts(Sphere{rng.uni(0.2, 1.0)}, rng.ellipsoid(5.0), 1.0, 1.0, rng, box, mid, nullptr,
                    false, s_se, "sphere-ellipsoid");
    expect_verdicts(rng.ellipsoid(5.0), rng.ellipsoid(5.0), 1.0, 1.0, rng, box, mid, nullptr, false,
                    s_ee, "ellipsoid-ellipsoid");
  }
  for (int k = 0; k < n_sampled; ++k) {
    expect_verdicts(random_superquadric(rng), rng.ellipsoid(4.0), 1.0, 1.0, rng, box, mid, nullptr,
                    true, s_qe, "superquadric-ellipsoid");
    expect_verdicts(random_superquadric(rng), Sphere{rng.uni(0.2, 1.0)}, 1.0, 1.0, rng, box, mid,
                    nullptr, true, s_qs, "superquadric-sphere");
    expect_verdicts(random_superquadric(rng), random_superquadric(rng), 1.0, 1.0, rng, box, mid,
                    nullptr, true, s_qq, "superquadric-superquadric");
  }
  std::printf("unlike pairs at +-1e-6: sphere-sphere %d (worst rel. gap error %.2g), sphere-ellipsoid %d, "
              "ellipsoid-ellipsoid %d, superquadric-ellipsoid %d (%.2g), superquadric-sphere %d (%.2g), "
              "superquadric-superquadric %d (%.2g)\n",
              s_sph.pairs, s_sph.worst_rel, s_se.pairs, s_ee.pairs, s_qe.pairs, s_qe.worst_rel, s_qs.pairs,
              s_qs.worst_rel, s_qq.pairs, s_qq.worst_rel);
  EXPECT_LT(s_sph.worst_rel, 1e-6);  // exact centre distances
  // the sampled gap estimate has the size of the gap, not only its sign
  EXPECT_LT(s_qe.worst_rel, 1e-2);
  EXPECT_LT(s_qs.worst_rel, 1e-2);
  EXPECT_LT(s_qq.worst_rel, 1e-2);
}

// A small body wholly inside a large one: no surface crosses the other, only the way "small
// surface against the large inside" sees it.
TEST(MixtureOverlapCheck, BodyInsideAnotherOverlaps) {
  const Box box = cube(10.0);
  const Superquadric big{1.5, 1.2, 1.0, 6.0, 4.0, 8.0};
  Rng rng(5);
  for (const AnyShape& small : {AnyShape(Sphere{0.1}), AnyShape(Ellipsoid{0.2, 0.1, 0.05}),
                                AnyShape(Superquadric{0.2, 0.15, 0.1, 3.0, 3.0, 5.0})}) {
    const OverlapCheck check = mixture_overlap_check({AnyShape(big), small});
    for (int k = 0; k < 10; ++k) {
      const Vec3 off(rng.uni(-0.5, 0.5), rng.uni(-0.4, 0.4), rng.uni(-0.3, 0.3));
      const State st = two_bodies(0, 1, 1.0, 1.0, rng.quat(), rng.quat(), Vec3::Constant(5.0), off);
      const OverlapReport rep = check(st, box);
      EXPECT_EQ(rep.overlaps, 1u) << shape_name(small) << " at " << off.transpose();
      EXPECT_LT(rep.min_distance, -0.05) << shape_name(small);
    }
  }
}

// (b) ------------------------------------------------------------------------------------------

namespace {

// n bodies on an fcc lattice in a cube of side L, random orientations, a few moved next to
// others (overlaps); species split at random among `ns` species.
State dense_state(std::size_t n, double L, int ns, std::uint64_t seed, int movers, double reach) {
  Rng rng(seed);
  State st;
  st.resize(n);
  st.r = fcc_lattice(n, L);
  for (Quat& q : st.q) q = rng.quat();
  for (auto& s : st.species) s = static_cast<std::uint16_t>(rng.uni(0.0, double(ns)) ) % ns;
  for (int k = 0; k < movers; ++k) {
    const std::size_t i = std::size_t(rng.uni(0.0, double(n))) % n, j = std::size_t(rng.uni(0.0, double(n))) % n;
    if (i != j) st.r[i] = st.r[j] + reach * rng.unit();
  }
  return st;
}

}  // namespace

TEST(MixtureOverlapCheck, IdenticalSpheresAgreeWithIdenticalChecks) {
  const Sphere s{0.5};
  for (int rep = 0; rep < 4; ++rep) {
    const Box box = cube(8.0);
    const State st = dense_state(500, 8.0, 2, 100 + rep, 4 * rep, 0.6);  // fcc spacing 1.13
    const OverlapReport brute = sphere_overlaps(st.r, box, 2.0 * s.radius);  // all pairs
    const OverlapReport grid = sphere_overlaps_grid(st.r, box, 2.0 * s.radius);
    const OverlapReport mix = sphere_mixture_overlaps(st.r, std::vector<double>(st.size(), s.radius), box);
    // one species, and the same shape listed as two species
    State st1 = st;
    st1.species.assign(st.size(), 0);
    const OverlapReport one = mixture_overlap_check({AnyShape(s)})(st1, box);
    const OverlapReport two = mixture_overlap_check({AnyShape(s), AnyShape(s)})(st, box);
    for (const OverlapReport* r : {&one, &two}) {
      EXPECT_EQ(r->overlaps, brute.overlaps) << "rep " << rep;
      EXPECT_DOUBLE_EQ(r->min_distance, brute.min_distance) << "rep " << rep;
      EXPECT_EQ(r->overlaps, grid.overlaps) << "rep " << rep;
      EXPECT_EQ(r->pairs_checked, grid.pairs_checked) << "rep " << rep;
      EXPECT_DOUBLE_EQ(r->min_distance, grid.min_distance) << "rep " << rep;
      EXPECT_EQ(r->overlaps, mix.overlaps) << "rep " << rep;
    }
    if (rep > 0) {
      EXPECT_GT(brute.overlaps, 0u);
      EXPECT_DOUBLE_EQ(one.min_distance, mix.min_distance);  // the closest pair overlaps
    } else {
      EXPECT_EQ(brute.overlaps, 0u);
      EXPECT_GT(one.min_distance, 0.1);  // the lattice gap 0.13, found without any overlap
      EXPECT_LT(one.min_distance, 0.2);
    }
    std::printf("spheres rep %d: %llu overlaps, min gap %.6g, %llu pairs\n", rep,
                (unsigned long long)one.overlaps, one.min_distance, (unsigned long long)one.pairs_checked);
  }
}

TEST(MixtureOverlapCheck, IdenticalEllipsoidsAgreeWithPerramWertheimCheck) {
  // 3:1.5:1 ellipsoids on a lattice whose spacing (1.06) is below the bounding diameter (1.5):
  // random orientations give both verdicts
  const Ellipsoid e{0.75, 0.375, 0.25};
  const Box box = cube(9.0);
  for (int rep = 0; rep < 3; ++rep) {
    const State st = dense_state(864, 9.0, 3, 200 + rep, 5 * rep, 0.5);
    const OverlapReport ref = ellipsoid_overlaps(st.r, st.q, box, e.half_extents());
    const OverlapReport got = mixture_overlap_check({AnyShape(e), AnyShape(e), AnyShape(e)})(st, box);
    EXPECT_EQ(got.overlaps, ref.overlaps) << "rep " << rep;
    EXPECT_EQ(got.pairs_checked, ref.pairs_checked) << "rep " << rep;
    EXPECT_DOUBLE_EQ(got.min_distance, ref.min_distance) << "rep " << rep;
    EXPECT_GT(ref.overlaps, 10u) << "rep " << rep;
    EXPECT_LT(ref.overlaps, ref.pairs_checked / 2) << "rep " << rep;
    std::printf("ellipsoids rep %d: %llu overlaps of %llu pairs, min gap %.6g\n", rep,
                (unsigned long long)got.overlaps, (unsigned long long)got.pairs_checked, got.min_distance);
  }
}

TEST(MixtureOverlapCheck, IdenticalSuperquadricsAgreeWithSamplingCheck) {
  const Superquadric q{0.7, 0.45, 0.35, 4.0, 6.0, 3.0};
  const Box box = cube(5.4);
  const std::size_t n = 108;  // fcc spacing 1.27 < bounding diameter
  const int reps = hb::testing::scaled_count(2, 0.5, 1);  // 1 under Debug/sanitizers
  for (int rep = 0; rep < reps; ++rep) {
    const State st = dense_state(n, 5.4, 2, 300 + rep, 3 * rep, 0.5);
    const OverlapReport ref = superquadric_overlaps(st.r, st.q, box, q);
    const OverlapReport got = mixture_overlap_check({AnyShape(q), AnyShape(q)})(st, box);
    EXPECT_EQ(got.overlaps, ref.overlaps) << "rep " << rep;
    EXPECT_EQ(got.pairs_checked, ref.pairs_checked) << "rep " << rep;
    EXPECT_DOUBLE_EQ(got.min_distance, ref.min_distance) << "rep " << rep;
    EXPECT_GT(ref.overlaps, 5u) << "rep " << rep;
    EXPECT_LT(ref.overlaps, ref.pairs_checked / 2) << "rep " << rep;
    std::printf("superquadrics rep %d: %llu overlaps of %llu pairs, min gap %.6g\n", rep,
                (unsigned long long)got.overlaps, (unsigned long long)got.pairs_checked, got.min_distance);
  }
  // the same through independent_overlap_check (the run's check for one species)
  const State st = dense_state(n, 5.4, 1, 310, 2, 0.5);
  const OverlapReport a = independent_overlap_check(q)(st, box);
  const OverlapReport b = mixture_overlap_check({AnyShape(q)})(st, box);
  EXPECT_EQ(a.overlaps, b.overlaps);
  EXPECT_DOUBLE_EQ(a.min_distance, b.min_distance);
}

// (c) ------------------------------------------------------------------------------------------

TEST(MixtureOverlapCheck, ScaleIsHonouredAtKnownGaps) {
  Rng rng(77);
  const Box box = cube(20.0);
  const Vec3 mid = Vec3::Constant(10.0);
  const int n_exact = hb::testing::scaled_count(25, 0.25, 4), n_sampled = hb::testing::scaled_count(10, 0.2, 2);
  GapStats s_sph, s_se, s_ee, s_qe, s_qq;
  for (int k = 0; k < n_exact; ++k) {
    expect_verdicts(Sphere{0.5}, Sphere{0.5}, rng.uni(0.6, 1.5), rng.uni(0.6, 1.5), rng, box, mid,
                    nullptr, true, s_sph, "scaled spheres");
    expect_verdicts(Sphere{0.5}, rng.ellipsoid(4.0), rng.uni(0.6, 1.5), rng.uni(0.6, 1.5), rng, box,
                    mid, nullptr, false, s_se, "scaled sphere-ellipsoid");
    // the same ellipsoid species at two scales: only scale[] tells them apart
    const Ellipsoid e = rng.ellipsoid(4.0);
    expect_verdicts(e, e, rng.uni(0.6, 1.5), rng.uni(0.6, 1.5), rng, box, mid, nullptr, false, s_ee,
                    "scaled ellipsoids");
  }
  for (int k = 0; k < n_sampled; ++k) {
    expect_verdicts(random_superquadric(rng), rng.ellipsoid(4.0), rng.uni(0.6, 1.5), rng.uni(0.6, 1.5),
                    rng, box, mid, nullptr, true, s_qe, "scaled superquadric-ellipsoid");
    const Superquadric q = random_superquadric(rng);
    expect_verdicts(q, q, rng.uni(0.6, 1.5), rng.uni(0.6, 1.5), rng, box, mid, nullptr, true, s_qq,
                    "scaled superquadrics");
  }
  std::printf("scaled pairs at +-1e-6: spheres %d (%.2g), sphere-ellipsoid %d, ellipsoids %d, "
              "superquadric-ellipsoid %d (%.2g), superquadrics %d (%.2g)\n",
              s_sph.pairs, s_sph.worst_rel, s_se.pairs, s_ee.pairs, s_qe.pairs, s_qe.worst_rel, s_qq.pairs,
              s_qq.worst_rel);
  EXPECT_LT(s_sph.worst_rel, 1e-6);
  EXPECT_LT(s_qe.worst_rel, 1e-2);
  EXPECT_LT(s_qq.worst_rel, 1e-2);
}

// A polydisperse mixture (sphere, ellipsoid, superquadric species, each body at one of a few
// scales) gives the verdicts of the same bodies listed as pre-scaled species at scale 1; and
// ignoring scale[] would change them.
TEST(MixtureOverlapCheck, PolydisperseStateMatchesPrescaledSpecies) {
  const std::vector<AnyShape> base = {Sphere{0.4}, Ellipsoid{0.6, 0.35, 0.25},
                                      Superquadric{0.5, 0.4, 0.3, 4.0, 3.0, 6.0}};
  const std::vector<double> scales = {0.8, 0.95, 1.1, 1.25};
  std::vector<AnyShape> prescaled;
  for (const AnyShape& s : base)
    for (double k : scales) prescaled.push_back(std::visit([&](const auto& x) { return AnyShape(scaled(x, k)); }, s));
  const Box box = cube(6.0);
  const OverlapCheck poly = mixture_overlap_check(base), flat = mixture_overlap_check(prescaled);
  Rng rng(4242);
  std::uint64_t total = 0;
  const int reps = hb::testing::scaled_count(3, 0.34, 1);  // 1 under Debug/sanitizers
  for (int rep = 0; rep < reps; ++rep) {
    State st = dense_state(256, 6.0, 3, 400 + rep, 4, 0.6);  // fcc spacing 1.06
    State st_flat = st;
    for (std::size_t i = 0; i < st.size(); ++i) {
      const std::size_t k = std::size_t(rng.uni(0.0, double(scales.size()))) % scales.size();
      st.scale[i] = scales[k];
      st_flat.species[i] = static_cast<std::uint16_t>(st.species[i] * scales.size() + k);
    }
    const OverlapReport a = poly(st, box), b = flat(st_flat, box);
    EXPECT_EQ(a.overlaps, b.overlaps) << "rep " << rep;
    EXPECT_EQ(a.pairs_checked, b.pairs_checked) << "rep " << rep;
    // the two samplings of a scaled body differ by rounding; the refinement ends at 1e-7 rad
    EXPECT_NEAR(a.min_distance, b.min_distance, 1e-8 * (1.0 + std::abs(b.min_distance))) << "rep " << rep;
    EXPECT_GT(a.overlaps, 0u) << "rep " << rep;
    State unscaled = st;
    unscaled.scale.assign(st.size(), 1.0);
    const OverlapReport c = poly(unscaled, box);
    EXPECT_NE(c.overlaps, a.overlaps) << "rep " << rep << ": scale[] made no difference";
    total += a.overlaps;
    std::printf("polydisperse rep %d: %llu overlaps of %llu pairs (prescaled %llu, scale ignored %llu), "
                "min gap %.6g / %.6g\n", rep, (unsigned long long)a.overlaps,
                (unsigned long long)a.pairs_checked, (unsigned long long)b.overlaps,
                (unsigned long long)c.overlaps, a.min_distance, b.min_distance);
  }
  EXPECT_GT(total, 50u);
}

// (d) ------------------------------------------------------------------------------------------

// Pairs straddling a face, an edge or a corner of the box (centres wrapped into [0, L)), in a
// large box (grid candidates) and a small one (brute-force candidates), for every pair type.
TEST(MixtureOverlapCheck, PeriodicImages) {
  Rng rng(99);
  GapStats st_s, st_e, st_q;
  for (double L : {4.5, 30.0}) {
    const Box box = cube(L);
    for (const Vec3& dir : {Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(1, 1, 0), Vec3(1, -1, 1)}) {
      // A just inside the faces the pair crosses: B's centre lies beyond them, wrapped back
      Vec3 origin = Vec3::Constant(0.5 * L);
      for (int k = 0; k < 3; ++k)
        if (dir[k] > 0) origin[k] = L - 0.05;
        else if (dir[k] < 0) origin[k] = 0.05;
      expect_verdicts(Sphere{0.4}, Sphere{0.7}, 1.0, 1.2, rng, box, origin, &dir, true, st_s, "periodic spheres");
      expect_verdicts(Ellipsoid{0.9, 0.3, 0.3}, Sphere{0.5}, 1.1, 0.9, rng, box, origin, &dir, false, st_e,
                      "periodic ellipsoid-sphere");
      expect_verdicts(Superquadric{0.6, 0.5, 0.4, 6.0, 6.0, 3.0}, Ellipsoid{0.7, 0.4, 0.3}, 1.0, 1.1, rng,
                      box, origin, &dir, true, st_q, "periodic superquadric-ellipsoid");
    }
  }
  EXPECT_LT(st_s.worst_rel, 1e-6);
  EXPECT_LT(st_q.worst_rel, 1e-2);
  // unwrapped positions (several box lengths away) give the same report as wrapped ones
  const Box box = cube(7.0);
  State st = dense_state(108, 7.0, 3, 500, 6, 0.5);
  const OverlapCheck check = mixture_overlap_check(
      {Sphere{0.6}, Ellipsoid{0.8, 0.4, 0.3}, Superquadric{0.6, 0.5, 0.4, 6.0, 6.0, 3.0}});
  const OverlapReport wrapped = check(st, box);
  for (std::size_t i = 0; i < st.size(); ++i)
    st.r[i] += box.L.cwiseProduct(Vec3(double(int(i % 5) - 2), double(int(i % 3) - 1), double(int(i % 7) - 3)));
  const OverlapReport unwrapped = check(st, box);
  EXPECT_GT(wrapped.overlaps, 0u);
  EXPECT_EQ(unwrapped.overlaps, wrapped.overlaps);
  EXPECT_EQ(unwrapped.pairs_checked, wrapped.pairs_checked);
  EXPECT_NEAR(unwrapped.min_distance, wrapped.min_distance, 1e-9);
}

// Malformed input is refused, not misread.
TEST(MixtureOverlapCheck, RejectsBadInput) {
  EXPECT_THROW(mixture_overlap_check({}), std::invalid_argument);
  const OverlapCheck check = mixture_overlap_check({Sphere{0.5}, Ellipsoid{0.5, 0.3, 0.3}});
  const Box box = cube(10.0);
  State st = two_bodies(0, 2, 1.0, 1.0, Quat::Identity(), Quat::Identity(), Vec3::Constant(5.0), Vec3(1.5, 0, 0));
  EXPECT_THROW(check(st, box), std::out_of_range);
  st.species[1] = 1;
  EXPECT_NO_THROW(check(st, box));
  st.scale[0] = 0.0;
  EXPECT_THROW(check(st, box), std::invalid_argument);
  st.scale.clear();  // no scale vector: scale 1
  EXPECT_EQ(check(st, box).overlaps, 0u);
  st.r[1] = st.r[0] + Vec3(0.7, 0.0, 0.0);
  EXPECT_EQ(check(st, box).overlaps, 1u);
}
