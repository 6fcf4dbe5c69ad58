// The sampling overlap check (observers/overlap_sampling.hpp) on pairs with known answers:
// near-cubes placed face to face, edge to face and corner to face at gaps of +-1e-6, random
// superquadric pairs placed at signed gaps of +-1e-6 of the size by the independent
// support-function reference (tests/geometry/reference_distance.hpp), and ellipsoids against the
// Perram–Wertheim check.
#include <gtest/gtest.h>

#include <cstdio>
#include <pcg_random.hpp>
#include <random>

#include "geometry/perram_wertheim.hpp"
#include "geometry/reference_distance.hpp"
#include "observers/overlap_sampling.hpp"
#include "shapes/ellipsoid.hpp"
#include "shapes/superquadric.hpp"
#include "setup/init.hpp"

using namespace hb;

namespace {

Quat random_quat(pcg32& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
}
Vec3 random_unit(pcg32& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  return Vec3(g(rng), g(rng), g(rng)).normalized();
}

// B's centre (A at the origin) at which the reference signed distance of the pair equals
// `target`, found along the direction u and then along the reference's normal.
template <SupportShape S>
Vec3 place_at_gap(const S& s, const Quat& qa, const Quat& qb, const Vec3& u, double target) {
  const Pose pa{Vec3::Zero(), qa.toRotationMatrix()};
  Vec3 r = 2.0 * s.bounding_radius() * u;
  for (int it = 0; it < 30; ++it) {
    const Pose pb{r, qb.toRotationMatrix()};
    const ref::RefDistance d = ref::reference_distance(s, pa, s, pb);
    const double err = target - d.distance;
    if (std::abs(err) < 1e-14 * s.bounding_radius()) break;
    r += err * d.n;  // the SAT gap along n grows by exactly the shift, to second order
  }
  return r;
}

template <SupportShape S>
void check_known_gaps(const S& s, const char* name, int pairs, std::uint64_t seed, double level) {
  const SurfaceSampling<S> check(s);
  const double ell = s.inscribed_radius();
  pcg32 rng(seed);
  int evals = 0, refined = 0, n = 0;
  double worst_rel = 0.0;
  for (int k = 0; k < pairs; ++k) {
    const Quat qa = random_quat(rng), qb = random_quat(rng);
    const Vec3 u = random_unit(rng);
    for (double sign : {-1.0, 1.0}) {
      const double g = sign * level * ell;
      const Vec3 r = place_at_gap(s, qa, qb, u, g);
      const SampledPair p = check.pair(qa, qb, r);
      EXPECT_EQ(p.overlap, sign < 0.0) << name << " pair " << k << " gap " << g << " estimate " << p.gap;
      // the reverse order gives the same verdict (the check is symmetric)
      const SampledPair q = check.pair(qb, qa, Vec3(-r));
      EXPECT_EQ(q.overlap, p.overlap) << name << " pair " << k;
      worst_rel = std::max(worst_rel, std::abs(p.gap - g) / std::abs(g));
      evals += p.ab.evaluations + p.ba.evaluations;
      refined += p.ab.refined + p.ba.refined;
      ++n;
    }
  }
  std::printf("%s: %d pairs at gaps +-%.0e of the inscribed radius, worst |estimate - gap| / "
              "|gap| = %.3g, %.0f f evaluations per pair, %d of %d ways refined\n",
              name, n, level, worst_rel, double(evals) / n, refined, 2 * n);
  EXPECT_LT(worst_rel, 1e-3) << name;  // the estimate has the right size, not only the sign
}

}  // namespace

TEST(OverlapSampling, NearCubesFaceEdgeCorner) {
  const Superquadric cube{1.0, 1.0, 1.0, 16.0, 16.0, 16.0};
  const SurfaceSampling<Superquadric> check(cube);
  const Quat id = Quat::Identity();
  // B rotated so that a face, an edge or a corner points at A along -x
  const Quat edge(Eigen::AngleAxisd(kPi / 4.0, Vec3::UnitZ()));
  const Quat corner = Quat(Eigen::AngleAxisd(std::atan(1.0 / std::sqrt(2.0)), Vec3::UnitY())) * edge;
  for (const Quat& qb : {id, edge, corner}) {
    // x-extent of B: the support of its body in the lab direction -x
    const double reach = cube.support(qb.conjugate() * Vec3(-1.0, 0.0, 0.0));
    for (double g : {-1e-6, 1e-6}) {
      for (const Vec3& off : {Vec3(0, 0, 0), Vec3(0, 0.3, -0.2)}) {
        const Vec3 r(1.0 + reach + g, off.y(), off.z());
        const SampledPair p = check.pair(id, qb, r);
        EXPECT_EQ(p.overlap, g < 0.0) << "reach " << reach << " gap " << g << " estimate " << p.gap;
        EXPECT_NEAR(p.gap, g, 0.2 * std::abs(g)) << "reach " << reach;
        EXPECT_EQ(check.pair(qb, id, Vec3(-r)).overlap, g < 0.0);
      }
    }
  }
}

// Gaps of +-1e-6 (the requirement) and +-1e-9 (the resolution: 10 x the tolerance 1e-10).
TEST(OverlapSampling, RandomSuperquadricsAtKnownGaps) {
  for (const double level : {1e-6, 1e-9}) {
    check_known_gaps(Superquadric{1.0, 1.0, 1.0, 16.0, 16.0, 16.0}, "p=16 cube", 25, 3, level);
    check_known_gaps(Superquadric{1.0, 0.5, 0.5, 4.0, 4.0, 4.0}, "p=4 X0=2", 25, 4, level);
    check_known_gaps(Superquadric{0.5, 1.0, 1.0, 8.0, 8.0, 8.0}, "p=8 X0=0.5", 25, 5, level);
    check_known_gaps(Superquadric{1.0, 0.7, 0.4, 2.0, 6.0, 3.0}, "mixed exponents", 25, 6, level);
    check_known_gaps(Superquadric{1.0, 0.5, 0.5, 2.0, 2.0, 2.0}, "p=2", 25, 7, level);
    check_known_gaps(Ellipsoid{1.0, 0.5, 0.5}, "ellipsoid", 25, 8, level);
  }
}

TEST(OverlapSampling, EllipsoidsAgreeWithPerramWertheim) {
  pcg32 rng(11);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (const Vec3& axes : {Vec3(1.0, 0.5, 0.5), Vec3(0.5, 1.0, 1.0), Vec3(1.0, 0.6, 0.3)}) {
    const Ellipsoid e{axes.x(), axes.y(), axes.z()};
    const Superquadric sq{axes.x(), axes.y(), axes.z(), 2.0, 2.0, 2.0};
    const SurfaceSampling<Ellipsoid> ce(e);
    const SurfaceSampling<Superquadric> cs(sq);
    int decided = 0, overlapping = 0;
    for (int k = 0; k < 300; ++k) {
      const Quat qa = random_quat(rng), qb = random_quat(rng);
      // centres around the contact distance along a random direction: a mix of both verdicts
      const Vec3 u = random_unit(rng);
      const EllipsoidPose A{axes, Vec3::Zero(), qa}, B{axes, Vec3::Zero(), qb};
      const double touch = touching_scale(A, B, u);
      const Vec3 r = touch * (1.0 + 1e-3 * uni(rng)) * u;
      const PerramWertheim pw = perram_wertheim(A, B, r);
      const double gap_pw = r.norm() * (1.0 - 1.0 / std::sqrt(pw.F));  // centre-line gap
      const SampledPair pe = ce.pair(qa, qb, r), ps = cs.pair(qa, qb, r);
      if (std::abs(gap_pw) < 1e-7) continue;  // too close to call for either method
      ++decided;
      overlapping += pw.overlap;
      EXPECT_EQ(pe.overlap, pw.overlap) << "ellipsoid f, pair " << k << " PW gap " << gap_pw;
      EXPECT_EQ(ps.overlap, pw.overlap) << "superquadric f, pair " << k << " PW gap " << gap_pw;
      // both parametrisations of the same surface give the same gap estimate (to the
      // difference of f/|grad f| between x^T X x - 1 and sqrt(x^T X x) - 1: second order)
      EXPECT_NEAR(pe.gap, ps.gap, 4.0 * ps.gap * ps.gap / axes.minCoeff() + 1e-9);
    }
    EXPECT_GT(decided, 250);
    EXPECT_GT(overlapping, 50);
    EXPECT_LT(overlapping, decided - 50);
  }
}

TEST(OverlapSampling, ConfigurationCountsMatchPairwiseReference) {
  // A lattice of rotated near-cubes (no overlaps), then bodies moved onto neighbours.
  const Superquadric s{0.5, 0.5, 0.5, 8.0, 8.0, 8.0};
  Box box;
  box.L = Vec3::Constant(7.0);
  // nearest neighbours at 1.65, more than the bounding diameter 1.51: no overlap at first
  std::vector<Vec3> r = fcc_lattice(108, 7.0);
  pcg32 rng(9);
  std::vector<Quat> q(r.size());
  for (auto& x : q) x = random_quat(rng);
  const SurfaceSampling<Superquadric> check(s);
  for (int rep = 0; rep < 3; ++rep) {
    if (rep > 0)
      for (int k = 0; k < 4; ++k) r[std::size_t(7 * k + rep)] = r[std::size_t(7 * k + rep + 1)] + 0.9 * random_unit(rng);
    const OverlapReport rep_s = sampled_overlaps(r, q, box, check);
    std::uint64_t expect = 0;
    for (std::size_t i = 0; i < r.size(); ++i)
      for (std::size_t j = i + 1; j < r.size(); ++j) {
        const Vec3 d = box.minimum_image(r[j] - r[i]);
        if (d.norm() > 2.0 * s.bounding_radius()) continue;
        const ref::RefDistance rd = ref::reference_distance(
            s, Pose{Vec3::Zero(), q[i].toRotationMatrix()}, s, Pose{d, q[j].toRotationMatrix()});
        expect += rd.distance < 0.0;
      }
    EXPECT_EQ(rep_s.overlaps, expect) << "rep " << rep;
    if (rep == 0) {
      EXPECT_EQ(rep_s.overlaps, 0u);
      EXPECT_GT(rep_s.min_distance, 0.0);
    } else {
      EXPECT_GT(rep_s.overlaps, 0u);
      EXPECT_LT(rep_s.min_distance, 0.0);
    }
  }
}
