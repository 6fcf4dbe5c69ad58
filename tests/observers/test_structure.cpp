#include <gtest/gtest.h>

#include <cmath>
#include <pcg_random.hpp>
#include <random>
#include <sstream>

#include "observers/pair_twin.hpp"
#include "observers/structure.hpp"

using namespace hb;
using hb::test::all_pairs_histogram;

namespace {

std::vector<Vec3> uniform_points(std::size_t n, const Box& box, pcg32& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec3> p(n);
  for (auto& x : p) x = Vec3(u(rng), u(rng), u(rng)).cwiseProduct(box.L);
  return p;
}

State state_at(const std::vector<Vec3>& p) {
  State s;
  s.resize(p.size());
  s.r = p;
  return s;
}

Quat random_quat(pcg32& rng) {
  std::normal_distribution<double> g;
  Quat q(g(rng), g(rng), g(rng), g(rng));
  q.normalize();
  return q;
}

}  // namespace

TEST(RadialDistribution, UniformPointsGiveOne) {
  pcg32 rng(21);
  Box box;
  box.L = Vec3(10.0, 11.0, 12.0);
  const std::size_t n = 1500;
  RdfSpec spec;
  spec.bins = 40;
  RadialDistribution rdf(spec);
  const int samples = 20;
  for (int k = 0; k < samples; ++k) rdf.sample(0.0, state_at(uniform_points(n, box, rng)), box);
  EXPECT_DOUBLE_EQ(rdf.r_max(), 5.0);
  const auto g = rdf.g();
  const auto& pairs = rdf.pair_counts();
  double worst = 0.0, total = 0.0, expected_total = 0.0;
  for (std::size_t k = 0; k < g.size(); ++k) {
    // Binomial count: relative sd ~ 1 / sqrt(expected pairs in the bin).
    const double expected = double(pairs[k]) / g[k];
    ASSERT_GT(pairs[k], 0u);
    worst = std::max(worst, std::abs(g[k] - 1.0) * std::sqrt(expected));
    total += double(pairs[k]);
    expected_total += expected;
  }
  EXPECT_LT(worst, 4.5);  // in standard deviations, over 40 bins
  RecordProperty("gr_worst_bin_sigmas", std::to_string(worst));
  EXPECT_NEAR(total / expected_total, 1.0, 3.0 / std::sqrt(expected_total));
  // Mean neighbours within r_max: (N - 1) 4/3 pi r^3 / V, relative sd ~ 1 / sqrt(pairs).
  const double nc = (n - 1) * 4.0 / 3.0 * kPi * 125.0 / box.volume();
  EXPECT_NEAR(rdf.coordination().back(), nc, 5.0 * nc / std::sqrt(total));
}

TEST(RadialDistribution, ObserverMatchesTheAllPairsTwin) {
  // Through the observer, including bodies exactly on the box faces; the whole pair search is
  // compared with the all-pairs loop in test_pair_search.cpp.
  pcg32 rng(22);
  Box box;
  box.L = Vec3::Constant(12.0);
  auto p = uniform_points(4000, box, rng);
  p[0] = Vec3(0.0, 0.0, 0.0);
  p[1] = Vec3(11.9999999, 0.0, 6.0);
  RdfSpec spec;
  spec.r_max = 3.9;
  spec.bins = 200;
  RadialDistribution g1(spec);
  g1.sample(0.0, state_at(p), box);
  std::vector<std::uint64_t> ref(200, 0);
  all_pairs_histogram(p, box, 3.9, ref);
  EXPECT_EQ(g1.pair_counts(), ref);
}

TEST(RadialDistribution, SimpleCubicLatticeShells) {
  // Unit lattice in a 10^3 box: 6 neighbours at 1, 12 at sqrt 2, 8 at sqrt 3, 6 at 2.
  Box box;
  box.L = Vec3::Constant(10.0);
  std::vector<Vec3> p;
  for (int x = 0; x < 10; ++x)
    for (int y = 0; y < 10; ++y)
      for (int z = 0; z < 10; ++z) p.emplace_back(x + 0.5, y + 0.5, z + 0.5);
  RdfSpec spec;
  spec.r_max = 2.5;
  spec.bins = 250;  // bin width 0.01: the shells sit in the middle of bins
  RadialDistribution rdf(spec);
  rdf.sample(0.0, state_at(p), box);
  const auto r = rdf.r();
  const auto n = rdf.coordination();
  auto n_at = [&](double x) {
    std::size_t k = 0;
    while (k + 1 < r.size() && r[k] + 0.005 < x) ++k;
    return n[k];
  };
  EXPECT_DOUBLE_EQ(n_at(0.9), 0.0);
  EXPECT_DOUBLE_EQ(n_at(1.1), 6.0);
  EXPECT_DOUBLE_EQ(n_at(1.5), 18.0);
  EXPECT_DOUBLE_EQ(n_at(1.8), 26.0);
  EXPECT_DOUBLE_EQ(n_at(2.1), 32.0);
}

TEST(RadialDistribution, RejectsRmaxBeyondHalfBox) {
  RdfSpec spec;
  spec.r_max = 6.0;
  RadialDistribution rdf(spec);
  Box box;
  box.L = Vec3::Constant(10.0);
  pcg32 rng(23);
  EXPECT_THROW(rdf.sample(0.0, state_at(uniform_points(10, box, rng)), box), std::invalid_argument);
  spec.bins = 0;
  EXPECT_THROW(RadialDistribution{spec}, std::invalid_argument);
}

TEST(RadialDistribution, TsvHeaderAndRows) {
  Box box;
  box.L = Vec3::Constant(8.0);
  pcg32 rng(24);
  RdfSpec spec;
  spec.bins = 16;
  RadialDistribution rdf(spec);
  rdf.sample(0.0, state_at(uniform_points(200, box, rng)), box);
  std::istringstream in(rdf.to_tsv());
  std::string line;
  int rows = 0;
  bool header = false;
  while (std::getline(in, line)) {
    if (line.starts_with("#")) continue;
    if (!header) {
      EXPECT_EQ(line, "r\tg\tn_r\tpairs");
      header = true;
      continue;
    }
    ++rows;
  }
  EXPECT_EQ(rows, 16);
}

TEST(NematicOrder, AlignedBodiesGiveOneAndTheAxis) {
  pcg32 rng(25);
  const Vec3 d = Vec3(0.3, -0.8, 0.5).normalized();
  // Body x along d, random spin about it (a uniaxial body does not see the spin).
  const Quat align = Quat::FromTwoVectors(Vec3::UnitX(), d);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * kPi);
  std::vector<Quat> q(500);
  // Half of them flipped head-to-tail: u -> -u leaves Q unchanged.
  for (std::size_t i = 0; i < q.size(); ++i)
    q[i] = (i % 2 ? Quat(Eigen::AngleAxisd(kPi, d.unitOrthogonal())) : Quat::Identity()) * align *
           Quat(Eigen::AngleAxisd(angle(rng), Vec3::UnitX()));
  const NematicResult r = nematic_order(q);
  EXPECT_NEAR(r.S2, 1.0, 1e-12);
  EXPECT_NEAR(std::abs(r.director.dot(d)), 1.0, 1e-12);
  EXPECT_NEAR(r.eigenvalues[0], -0.5, 1e-12);
  EXPECT_NEAR(r.eigenvalues[1], -0.5, 1e-12);
  // The body y axes of the same bodies are spread in the plane normal to d: eigenvalue -1/2
  // along d, the director lies in that plane.
  const NematicResult ry = nematic_order(q, Vec3::UnitY());
  EXPECT_NEAR(ry.eigenvalues[0], -0.5, 1e-12);
  EXPECT_NEAR(std::abs(ry.director.dot(d)), 0.0, 1e-9);
}

TEST(NematicOrder, RandomOrientationsGiveSmallS2) {
  pcg32 rng(26);
  const std::size_t n = 10000;
  std::vector<Quat> q(n);
  for (auto& x : q) x = random_quat(rng);
  const NematicResult r = nematic_order(q);
  EXPECT_GT(r.S2, 0.0);
  EXPECT_LT(r.S2, 5.0 / std::sqrt(double(n)));
  RecordProperty("S2_random_10000", std::to_string(r.S2));
  EXPECT_NEAR(r.eigenvalues.sum(), 0.0, 1e-12);  // Q is traceless
}

TEST(NematicOrder, PartialOrderAndSeries) {
  // Axes drawn near z with a Gaussian tilt: director z, S2 = <P2(cos tilt)> of the sample.
  pcg32 rng(27);
  std::normal_distribution<double> g(0.0, 0.3);
  State s;
  s.resize(4000);
  double p2 = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Vec3 u = Vec3(g(rng), g(rng), 1.0).normalized();
    s.q[i] = Quat::FromTwoVectors(Vec3::UnitX(), u);
    p2 += 1.5 * u.z() * u.z() - 0.5;
  }
  p2 /= double(s.size());
  NematicOrder order;
  order.sample(0.0, s, Box{});
  order.sample(1.0, s, Box{});  // stored states at t = 0, w = 0: same orientations
  ASSERT_EQ(order.series().size(), 2u);
  const auto& r = order.series()[1];
  EXPECT_NEAR(r.director.z(), 1.0, 0.01);
  EXPECT_NEAR(r.S2, p2, 0.01);
  EXPECT_NEAR(order.S2().mean, r.S2, 1e-12);
  std::istringstream in(order.to_tsv());
  std::string line;
  while (std::getline(in, line) && line.starts_with("#")) {
  }
  EXPECT_EQ(line, "time\tS2\tdirector_x\tdirector_y\tdirector_z");
}

TEST(Structure, SaveLoadRoundTrip) {
  pcg32 rng(28);
  Box box;
  box.L = Vec3::Constant(9.0);
  RdfSpec spec;
  spec.bins = 30;
  RadialDistribution a(spec), b(spec);
  NematicOrder na, nb;
  State s = state_at(uniform_points(300, box, rng));
  for (auto& q : s.q) q = random_quat(rng);
  a.sample(0.0, s, box);
  na.sample(0.0, s, box);
  b.load(a.save());
  nb.load(na.save());
  s.r = uniform_points(300, box, rng);
  a.sample(1.0, s, box);
  b.sample(1.0, s, box);
  na.sample(1.0, s, box);
  nb.sample(1.0, s, box);
  EXPECT_EQ(a.to_tsv(), b.to_tsv());
  EXPECT_EQ(na.to_tsv(), nb.to_tsv());
  RdfSpec other = spec;
  other.bins = 31;
  RadialDistribution c(other);
  EXPECT_THROW(c.load(a.save()), std::invalid_argument);
}

// Partial g_ab(r) by histogram differences against a labelled all-pairs count (the slow twin).
TEST(PartialRdf, PairCountsMatchALabelledBruteForceCount) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Box box;
  box.L = Vec3(7.0, 8.0, 9.0);
  State s;
  s.resize(300);
  for (std::size_t i = 0; i < s.size(); ++i) {
    s.r[i] = Vec3(u(rng) * box.L.x(), u(rng) * box.L.y(), u(rng) * box.L.z());
    s.species[i] = static_cast<std::uint16_t>(i % 3 == 0 ? 0 : (i % 3 == 1 ? 1 : 2));
  }
  const int bins = 40;
  const double r_max = 3.5;
  PartialRadialDistribution p(3, bins);
  p.sample(0.0, s, box, r_max);
  std::vector<std::vector<std::uint64_t>> ref(6, std::vector<std::uint64_t>(bins, 0));
  std::vector<std::uint64_t> all(bins, 0);
  for (std::size_t i = 0; i < s.size(); ++i)
    for (std::size_t j = i + 1; j < s.size(); ++j) {
      const double d = box.minimum_image(s.r[j] - s.r[i]).norm();
      if (d >= r_max) continue;
      const int k = std::min(bins - 1, int(d / r_max * bins));
      ref[p.pair_index(s.species[i], s.species[j])][k] += 1;
      all[k] += 1;
    }
  std::vector<std::uint64_t> sum(bins, 0);
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t b = a; b < 3; ++b) {
      EXPECT_EQ(p.pair_counts(a, b), ref[p.pair_index(a, b)]) << a << b;
      for (int k = 0; k < bins; ++k) sum[k] += p.pair_counts(a, b)[k];
    }
  EXPECT_EQ(sum, all);
  // ideal gas: g_ab ~ 1 on average over the outer bins
  for (std::size_t a = 0; a < 3; ++a)
    for (std::size_t b = a; b < 3; ++b) {
      const auto g = p.g(a, b);
      double mean = 0.0;
      for (int k = bins / 2; k < bins; ++k) mean += g[k] / (bins / 2);
      EXPECT_NEAR(mean, 1.0, 0.15) << a << b;
    }
  // save/load round trip
  PartialRadialDistribution q(3, bins);
  q.load(p.save());
  EXPECT_EQ(q.to_tsv({"A", "B", "C"}), p.to_tsv({"A", "B", "C"}));
  EXPECT_NE(p.to_tsv({"A", "B", "C"}).find("r\tg_A_A\tg_A_B\tg_A_C\tg_B_B\tg_B_C\tg_C_C\n"), std::string::npos);
}
